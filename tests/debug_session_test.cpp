// The debugger's sessions (debug/session.h), driven by scripted
// controllers: a place reached backwards is the place reached forwards,
// byte for byte (both boards, the plant's poses); a delay loop's counter
// at any tick is what the listing's T-states give; print reads any lvalue
// of any frame. Built into snapshot_test (a session is snapshots and
// replay).
#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "debug/session.h"
#include "runs/play.h"

using namespace simbot;

namespace {

const std::string kShared = SIMBOT_SHARED_DIR;
const std::string kSource = SIMBOT_SOURCE_DIR;

using Step = std::function<debug::Resume(debug::Session&, const debug::Stop&)>;

// Answers each stop with the next step of a script; quits after the last.
class Script final : public debug::Controller {
 public:
  explicit Script(std::vector<Step> steps) : steps_(std::move(steps)) {}
  debug::Resume stopped(debug::Session& s, const debug::Stop& why) override {
    if (next_ >= steps_.size()) return resume(debug::Resume::Kind::Quit);
    return steps_[next_++](s, why);
  }
  size_t done() const { return next_; }
  static debug::Resume resume(debug::Resume::Kind kind, timebase::Tick tick = 0) {
    debug::Resume r;
    r.kind = kind;
    r.tick = tick;
    return r;
  }

 private:
  std::vector<Step> steps_;
  size_t next_ = 0;
};

// A VM copied out of a session talks to nothing.
class NoBus final : public vm::Bus {
 public:
  void out(timebase::Tick, uint16_t, uint8_t) override {}
  uint8_t in(timebase::Tick, uint16_t) override { return 0xFF; }
  int adSample(timebase::Tick, int) override { return 0; }
};

// Everything of the match a stop shows: both machines and both poses.
struct Place {
  timebase::Tick tick = 0;
  std::vector<std::unique_ptr<vm::Vm>> machines;
  std::vector<plant::Pose> poses;
  std::string arena;
};

Place placeOf(debug::Session& s, NoBus& bus) {
  Place p;
  p.tick = s.now();
  for (int r = 0; r < s.robotCount(); ++r) {
    p.machines.push_back(std::make_unique<vm::Vm>(s.vm(r), bus));
    p.poses.push_back(s.view().pose(r, p.tick));
  }
  p.arena = s.view().describe(p.tick);
  return p;
}

bool samePose(const plant::Pose& a, const plant::Pose& b) {
  return std::memcmp(&a.x_ft, &b.x_ft, sizeof a.x_ft) == 0 &&
         std::memcmp(&a.y_ft, &b.y_ft, sizeof a.y_ft) == 0 &&
         std::memcmp(&a.heading_deg, &b.heading_deg, sizeof a.heading_deg) == 0;
}

void expectSamePlace(debug::Session& s, const Place& p) {
  EXPECT_EQ(s.now(), p.tick);
  for (int r = 0; r < s.robotCount(); ++r) {
    EXPECT_TRUE(s.vm(r).sameProgramState(*p.machines[static_cast<size_t>(r)])) << "robot " << r;
    EXPECT_TRUE(samePose(s.view().pose(r, p.tick), p.poses[static_cast<size_t>(r)]))
        << "robot " << r;
  }
  EXPECT_EQ(s.view().describe(p.tick), p.arena);
}

scheduler::MatchConfig icemanVsFig92() {
  runs::RunOptions o;
  o.length = 30 * timebase::kTicksPerSecond;
  o.profile = "default";
  o.seed = 3;
  return runs::buildConfig({kShared + "/programs/iceman.dc", kShared + "/programs/fig92.dc"}, o,
                           runs::ScenarioUse::Match);
}

int64_t integerOf(debug::Session& s, const std::string& expression) {
  const inspect::Scope scope = s.scope();
  int64_t i = 0;
  double r = 0;
  bool f = false;
  EXPECT_TRUE(inspect::scalar(scope, inspect::Expression(expression).evaluate(scope), i, r, f));
  return i;
}

std::string text(debug::Session& s, const std::string& expression) {
  const inspect::Scope scope = s.scope();
  return inspect::format(scope, inspect::Expression(expression).evaluate(scope));
}

using K = debug::Resume::Kind;

}  // namespace

// ICEMAN's edge handler, first entry (seed 3): reached by continuing, by
// going 5 s past it and back, and by stepping back into the delay loop it
// interrupted and forward again, the match is the same to the byte. A
// plain traced run (trace_test's oracle, independent of the debugger)
// puts that acceptance at tick 83,150,071 on line 220, in platform()'s
// `for (z = 0; z < 700; z++);`; the handler's first instruction starts
// the acceptance's cost later (CostTable::interruptAccept).
TEST(DebugSession, BackwardsReachesTheStateForwardsReached) {
  NoBus bus;
  Place atEntry, inLoop;
  const vm::CostTable costs = vm::makeCostTable(vm::calibratedKnobs());
  Script script({
      [](debug::Session& s, const debug::Stop& why) -> debug::Resume {
        EXPECT_EQ(why.kind, debug::Stop::Kind::Entry);
        s.breakAtFunction(0, "INT1");
        return Script::resume(K::Continue);
      },
      [&](debug::Session& s, const debug::Stop& why) {
        EXPECT_EQ(why.kind, debug::Stop::Kind::Breakpoint);
        EXPECT_EQ(s.now(), 83'150'071 + costs.interruptAccept);
        atEntry = placeOf(s, bus);
        return Script::resume(K::Goto, s.now() + 5 * timebase::kTicksPerSecond);
      },
      [&](debug::Session& s, const debug::Stop&) {
        EXPECT_GE(s.now(), atEntry.tick + 5 * timebase::kTicksPerSecond);
        return Script::resume(K::Goto, atEntry.tick);
      },
      [&](debug::Session& s, const debug::Stop&) {
        expectSamePlace(s, atEntry);
        return Script::resume(K::ReverseStep);
      },
      [&](debug::Session& s, const debug::Stop&) {
        EXPECT_EQ(s.now(), 83'150'071);
        EXPECT_EQ(s.vm(0).line(), 220);
        EXPECT_EQ(integerOf(s, "z"), integerOf(s, "platform::z"));
        inLoop = placeOf(s, bus);
        return Script::resume(K::Step);
      },
      [&](debug::Session& s, const debug::Stop&) {
        expectSamePlace(s, atEntry);
        return Script::resume(K::ReverseStepInstruction);
      },
      [&](debug::Session& s, const debug::Stop&) {
        expectSamePlace(s, inLoop);
        return Script::resume(K::Quit);
      },
  });
  debug::Session session(icemanVsFig92(), {"iceman.dc", "fig92.dc"});
  session.run(script);
  EXPECT_EQ(script.done(), 7u);
}

// Snapshots thin out with distance (Session::thinSnapshots): at 600 s the
// held robot has passed 1,201 half-second marks (keys 0..1200), and kept
// are key 0, every key within 16 of 1200 (1184..1200: 17), then 8 in each
// band where the spacing doubles: (16, 32] in 2s, (32, 64] in 4s,
// (64, 128] in 8s, (128, 256] in 16s, (256, 512] in 32s, (512, 1024] in
// 64s (192..640), and in (1024, 1200] the multiples of 128 (0 and 128):
// 17 + 6 * 8 + 2 = 67 snapshots, not 1,201. Going back to 10 s still lands
// where going forwards did.
TEST(DebugSession, SnapshotsThinOutWithDistanceFromThePresent) {
  Place at10s;
  NoBus bus;
  Script script({
      [](debug::Session&, const debug::Stop&) {
        return Script::resume(K::Goto, 10 * timebase::kTicksPerSecond);
      },
      [&](debug::Session& s, const debug::Stop&) {
        at10s = placeOf(s, bus);
        return Script::resume(K::Goto, 600 * timebase::kTicksPerSecond);
      },
      [&](debug::Session& s, const debug::Stop&) {
        EXPECT_EQ(s.snapshotsKept(), 67u);
        return Script::resume(K::Goto, 10 * timebase::kTicksPerSecond);
      },
      [&](debug::Session& s, const debug::Stop&) {
        expectSamePlace(s, at10s);
        return Script::resume(K::Quit);
      },
  });
  runs::RunOptions o;
  o.length = 601 * timebase::kTicksPerSecond;
  debug::Session session(
      runs::buildConfig({kShared + "/programs/iceman.dc"}, o, runs::ScenarioUse::Solo),
      {"iceman.dc"});
  session.run(script);
  EXPECT_EQ(script.done(), 4u);
}

// tests/debug/inspect.dc's delay loop `for (count = 0; count < 30000;
// count++);` (line 55). From the listing (simbot compile --disasm): the
// line starts with DBG 68, PUSHW 22, STGW 28, so the loop's top (LDGW)
// first runs 118 T-states after the line's breakpoint; a pass is LDGW 29,
// PUSHW 22, LTUW 50 (count < 30000: its JR NC not taken, INC run), JZ 25
// (not taken), DBG 68, INCGW 39, JMP 10: 243 T-states, with boundaries at
// 0, 29, 51, 101, 126, 194 (INCGW) and 233 (JMP, count + 1 written). `goto`
// lands on the first boundary at or after its tick, fast-forward or not:
// at top + 243 k + d, on the boundary of pass k at or after d (the next
// pass's top past 233), where the counter reads k up to 194 and k + 1 after.
TEST(DebugSession, DelayLoopCounterFollowsFromTheListing) {
  runs::RunOptions o;
  o.length = 2 * timebase::kTicksPerSecond;
  const scheduler::MatchConfig config =
      runs::buildConfig({kSource + "/tests/debug/inspect.dc"}, o, runs::ScenarioUse::Solo);
  timebase::Tick top = 0;
  struct Probe {
    int64_t pass, offset, expected, landing;
  };
  // {pass, offset, count read, the boundary landed on (offset in the pass)}
  const std::vector<Probe> probes = {{0, 0, 0, 0},
                                     {0, 194, 0, 194},
                                     {0, 195, 1, 233},
                                     {12345, 0, 12345, 0},
                                     {12345, 194, 12345, 194},
                                     {12345, 195, 12346, 233},
                                     {12345, 233, 12346, 233},
                                     {12345, 234, 12346, 243},
                                     {100, 100, 100, 101}};
  std::vector<Step> steps = {
      [](debug::Session& s, const debug::Stop&) {
        s.breakAtLine(0, 55);
        return Script::resume(K::Continue);
      },
      [&](debug::Session& s, const debug::Stop& why) {
        EXPECT_EQ(why.kind, debug::Stop::Kind::Breakpoint);
        top = s.now() + 118;
        return Script::resume(K::StepInstruction);
      },
      [&](debug::Session& s, const debug::Stop&) {
        EXPECT_EQ(s.now(), top - 118 + 68);  // DBG's 68 T-states
        return Script::resume(K::Goto, top + probes[0].pass * 243 + probes[0].offset);
      },
  };
  for (size_t k = 0; k < probes.size(); ++k)
    steps.push_back([&, k](debug::Session& s, const debug::Stop&) {
      const Probe& p = probes[k];
      EXPECT_EQ(integerOf(s, "count"), p.expected) << "pass " << p.pass << " + " << p.offset;
      EXPECT_EQ(s.now(), top + p.pass * 243 + p.landing) << "pass " << p.pass << " + " << p.offset;
      if (k + 1 == probes.size()) return Script::resume(K::Quit);
      return Script::resume(K::Goto, top + probes[k + 1].pass * 243 + probes[k + 1].offset);
    });
  Script script(steps);
  debug::Session session(config, {"inspect.dc"});
  session.run(script);
  EXPECT_EQ(script.done(), steps.size());
}

// print reads any lvalue: members, elements, slices, through pointers, the
// autos and parameters of each frame of a recursion. depth(3, 1) calls
// depth(2, 1 + 6), depth(1, 7 + 4), depth(0, 11 + 2), which returns 13
// (by hand: step + 2n at each level).
TEST(DebugSession, PrintReadsAnyLvalueOfAnyFrame) {
  runs::RunOptions o;
  o.length = 1 * timebase::kTicksPerSecond;
  const scheduler::MatchConfig config =
      runs::buildConfig({kSource + "/tests/debug/inspect.dc"}, o, runs::ScenarioUse::Solo);
  Script script({
      [](debug::Session& s, const debug::Stop&) {
        const debug::Breakpoint& b = s.breakAtFunction(0, "depth");
        s.setCondition(b.id, "n == 0");
        return Script::resume(K::Continue);
      },
      [](debug::Session& s, const debug::Stop& why) -> debug::Resume {
        EXPECT_EQ(why.kind, debug::Stop::Kind::Breakpoint);
        EXPECT_EQ(text(s, "bot.trail[2]"), "{x = 4, y = -4}");
        EXPECT_EQ(text(s, "bot.peer->at.x"), "7");
        EXPECT_EQ(text(s, "grid[1]@3"), "{0, -4, 0}");
        EXPECT_EQ(text(s, "bot.name"), "\"ice\" {0x69 0x63 0x65 0x00 0x00 0x00}");
        EXPECT_EQ(text(s, "bot.heading"), "1.5");
        EXPECT_EQ(text(s, "buf"), "\"4fgr4rgr\" {0x34 0x66 0x67 0x72 0x34 0x72 0x67 0x72 0x00}");
        EXPECT_EQ(integerOf(s, "n"), 0);
        EXPECT_EQ(integerOf(s, "step"), 13);
        const std::vector<debug::FrameInfo> frames = s.backtrace(0);
        if (frames.size() < 5) {
          ADD_FAILURE() << "only " << frames.size() << " frames";
          return Script::resume(K::Quit);
        }
        EXPECT_EQ(frames[0].arguments, "n=0, step=13");
        EXPECT_EQ(frames[1].arguments, "n=1, step=11");
        EXPECT_EQ(frames[2].arguments, "n=2, step=7");
        EXPECT_EQ(frames[3].arguments, "n=3, step=1");
        EXPECT_EQ(frames[4].function, "main");
        s.selectFrame(1);
        EXPECT_EQ(integerOf(s, "twice"), 2);
        s.selectFrame(4);
        EXPECT_EQ(integerOf(s, "i"), 3);
        EXPECT_EQ(text(s, "*p"), "{x = 3, y = -4}");
        EXPECT_EQ(text(s, "p->y * 2 + 1"), "-7");
        EXPECT_THROW(inspect::Expression("bot.nosuch").evaluate(s.scope()), inspect::Error);
        EXPECT_THROW(inspect::Expression("sq").evaluate(s.scope()),
                     inspect::Error);  // out of scope
        s.selectFrame(0);              // finish applies to the selected frame, as gdb's does
        return Script::resume(K::Finish);
      },
      [](debug::Session& s, const debug::Stop& why) -> debug::Resume {
        EXPECT_EQ(why.kind, debug::Stop::Kind::Step);
        EXPECT_EQ(s.backtrace(0)[0].arguments, "n=1, step=11");
        return Script::resume(K::Quit);
      },
  });
  debug::Session session(config, {"inspect.dc"});
  session.run(script);
  EXPECT_EQ(script.done(), 3u);
}

// A place reached one instruction at a time is the place `goto` reaches,
// also where a step ends past a round's horizon: the events due there
// (serial bytes, interrupt requests) come first either way. ICEMAN from
// 5 s, some hundreds of stepi to tick 46,115,570, a boundary just past a
// horizon where the serial port's transmit request is due (the plain
// trace's send at 46,105,944, its byte 1 due a character time, 9,600
// ticks, later: 46,115,544; found by review: a stepped arrival there once
// showed no request pending), and two places on the way, against goto to
// each.
TEST(DebugSession, SteppedAndGoneToAreTheSamePlace) {
  constexpr timebase::Tick kPastHorizon = 46'115'570;
  NoBus bus;
  std::vector<Place> stepped;
  int steps = 0;
  Step step = [&](debug::Session& s, const debug::Stop&) {
    ++steps;
    if (steps == 250 || steps == 500 || s.now() == kPastHorizon) stepped.push_back(placeOf(s, bus));
    if (s.now() >= kPastHorizon || steps > 10000) {
      EXPECT_EQ(s.now(), kPastHorizon);
      return Script::resume(K::Goto, stepped.front().tick);
    }
    return Script::resume(K::StepInstruction);
  };
  size_t compared = 0;
  Step compare = [&](debug::Session& s, const debug::Stop&) {
    expectSamePlace(s, stepped[compared]);
    EXPECT_TRUE(s.vm(0).pending(vm::Irq::SerialTx) ==
                stepped[compared].machines[0]->pending(vm::Irq::SerialTx));
    if (++compared == stepped.size()) return Script::resume(K::Quit);
    return Script::resume(K::Goto, stepped[compared].tick);
  };
  class Loop final : public debug::Controller {
   public:
    Loop(Step& first, Step& then) : first_(first), then_(then) {}
    debug::Resume stopped(debug::Session& s, const debug::Stop& why) override {
      if (!started_) {
        started_ = true;
        return Script::resume(K::Goto, 5 * timebase::kTicksPerSecond);
      }
      if (!stepping_done_) {
        const debug::Resume r = first_(s, why);
        stepping_done_ = r.kind == K::Goto;
        return r;
      }
      return then_(s, why);
    }

   private:
    Step& first_;
    Step& then_;
    bool started_ = false, stepping_done_ = false;
  } controller(step, compare);
  debug::Session session(icemanVsFig92(), {"iceman.dc", "fig92.dc"});
  session.run(controller);
  EXPECT_EQ(stepped.size(), 3u);
  EXPECT_EQ(compared, stepped.size());
}

// reverse-continue goes back to the last place a breakpoint stopped, a
// time breakpoint included (the first boundary at or after its tick), and
// `run` starts over with every breakpoint armed again.
TEST(DebugSession, ReverseContinueAndRunFindTimeBreakpoints) {
  timebase::Tick first = 0;
  Script script({
      [](debug::Session& s, const debug::Stop&) {
        s.breakAtTick(timebase::kTicksPerSecond);
        return Script::resume(K::Continue);
      },
      [&](debug::Session& s, const debug::Stop& why) {
        EXPECT_EQ(why.kind, debug::Stop::Kind::Breakpoint);
        EXPECT_GE(s.now(), timebase::kTicksPerSecond);
        EXPECT_LT(s.now(), timebase::kTicksPerSecond + 1000);  // a boundary, not a round, later
        first = s.now();
        return Script::resume(K::Goto, 3 * timebase::kTicksPerSecond);
      },
      [&](debug::Session&, const debug::Stop&) { return Script::resume(K::ReverseContinue); },
      [&](debug::Session& s, const debug::Stop&) {
        EXPECT_EQ(s.now(), first);
        return Script::resume(K::Restart);
      },
      [&](debug::Session& s, const debug::Stop& why) {
        EXPECT_EQ(why.kind, debug::Stop::Kind::Breakpoint);
        EXPECT_EQ(s.now(), first);
        return Script::resume(K::Quit);
      },
  });
  debug::Session session(icemanVsFig92(), {"iceman.dc", "fig92.dc"});
  session.run(script);
  EXPECT_EQ(script.done(), 5u);
}
