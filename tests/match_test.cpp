// The match engine end to end: determinism, trace independence, serial
// timing in co-simulation, edge interrupts through the PIO.
#include "scheduler/match.h"

#include <gtest/gtest.h>

#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <variant>

#include "compiler/compiler.h"
#include "config/config.h"
#include "plant/plant.h"
#include "support/programs.h"
#include "support/records.h"
#include "support/traced.h"
#include "vm/bytecode.h"

using namespace simbot;

namespace {

vm::Image compileFile(const std::string& path) {
  auto r = compiler::compileFile(path);
  if (!r.image) throw std::runtime_error(r.errors[0].format());
  return std::move(*r.image);
}

vm::Image compileSource(const std::string& source) {
  auto r = compiler::compile(source, "test.dc");
  if (!r.image) throw std::runtime_error(r.errors[0].format());
  return std::move(*r.image);
}

const std::string kIceman = SIMBOT_SHARED_DIR "/programs/iceman.dc";
const std::string kFig92 = SIMBOT_SHARED_DIR "/programs/fig92.dc";

scheduler::MatchConfig matchConfig(std::vector<scheduler::RobotSpec> robots, double seconds,
                                   const std::string& profile = "default") {
  scheduler::MatchConfig c;
  c.arena = config::makeArenaConfig(
      config::loadProfile(SIMBOT_SOURCE_DIR "/profiles/" + profile + ".toml"),
      static_cast<int>(robots.size()));
  c.robots = std::move(robots);
  c.endTick = timebase::ticksFromSeconds(seconds);
  return c;
}

std::string summary(const scheduler::MatchResult& r) {
  std::ostringstream s;
  s.precision(17);
  s << r.endTick << ' ' << r.winner << ' ' << r.tieBrokenByCoin << ' ' << r.integrator.steps << ' '
    << r.integrator.rhs_evals << ' ' << r.integrator.reinits << ' ' << r.integrator.roots;
  for (const auto& rr : r.robots) {
    s << ' ' << rr.hits << ' ' << rr.shots << ' ' << rr.framesLatched << ' ' << rr.framesRejected
      << ' ' << rr.cycles << ' ' << rr.finalPose.x_ft << ' ' << rr.finalPose.y_ft << ' '
      << rr.finalPose.heading_deg;
    for (const auto& [k, v] : rr.interrupts) s << ' ' << k << '=' << v;
  }
  return s.str();
}

TEST(Match, IcemanAgainstFig92IsDeterministicAndTraceDoesNotChangeIt) {
  auto make = [] {
    return matchConfig({{"A", kIceman, compileFile(kIceman)}, {"B", kFig92, compileFile(kFig92)}},
                       60);
  };
  auto plain = make();
  auto traced = make();
  const auto r1 = scheduler::runMatch(plain);
  const auto r2 = testkit::runTraced(traced);
  const auto r3 = testkit::runTraced(traced);
  EXPECT_EQ(summary(r1), summary(r2));
  EXPECT_EQ(r2.trace, r3.trace);
  EXPECT_FALSE(r2.trace.empty());
  EXPECT_GT(r1.robots[0].framesLatched, 0);
  EXPECT_GT(r1.robots[1].framesLatched, 0);
  // fig92 never arms port A: its detectors cross the wire, no interrupt.
  int fig92EdgeCrossings = 0;
  for (const auto& line : r2.trace)
    if (line.find("\"edge_enter\"") != std::string::npos &&
        line.find("\"robot\":\"B\"") != std::string::npos)
      ++fig92EdgeCrossings;
  EXPECT_GT(fig92EdgeCrossings, 0);
  EXPECT_EQ(r1.robots[1].interrupts.at("pio_a"), 0u);
  EXPECT_GT(r1.integrator.steps, 0);
}

struct TraceRecord {
  long long t;
  std::string type;
  nlohmann::json json;
};

std::vector<TraceRecord> parse(const std::vector<std::string>& lines) {
  std::vector<TraceRecord> out;
  for (const auto& line : lines) {
    auto j = nlohmann::json::parse(line);
    out.push_back({j.at("t").get<long long>(), j.at("type").get<std::string>(), j});
  }
  return out;
}

TEST(Match, IcemanAloneTakesEdgeInterruptsAtTheWire) {
  auto config = matchConfig({{"A", kIceman, compileFile(kIceman)}}, 12);
  const auto r = testkit::runTraced(config);
  EXPECT_GE(r.robots[0].interrupts.at("pio_a"), 1u);
  const auto trace = parse(r.trace);
  auto find = [&](const std::string& type, long long after) {
    for (const auto& rec : trace)
      if (rec.type == type && rec.t >= after) return rec;
    throw std::runtime_error("no " + type);
  };
  const auto enter = find("edge_enter", 0);
  const auto accepted = find("interrupt_accepted", enter.t);
  EXPECT_EQ(accepted.json.at("source"), "pio_a");
  // Accepted at the next boundary: within one instruction or library step.
  EXPECT_LE(accepted.t - enter.t, 100);
  // The handler's first platform() sends "crgrcrgr"; it latches 9 characters
  // after the send ends.
  const auto send = find("serial_send", accepted.t);
  const auto latched = find("frame_latched", send.t);
  EXPECT_EQ(latched.json.at("bytes"), "crgrcrgr");
  EXPECT_EQ(latched.t - send.t, 9 * 9600);
}

// platform() twice in a row: the second send restarts the first midway.
const char* kTwoSends = R"(char buf[9];
char cc;
int z;
platform()
{
    cc = sizeof(buf);
    outport(ENB485, 1);
    ser_send_z1(buf, &cc);
}
main()
{
    ser_init_z1(0, 9600/1200);
    strcpy(buf, "4fgr4rgr");
    platform();
    for (z = 0; z < 100; z++);
    strcpy(buf, "cfgrcfgr");
    platform();
    for (z = 0; z < 2000; z++);
}
)";

TEST(Match, SecondPlatformBeforeTheFirstFinishesWins) {
  auto config = matchConfig({{"A", "two.dc", compileSource(kTwoSends)}}, 1);
  const auto r = testkit::runTraced(config);
  const auto trace = parse(r.trace);
  std::vector<TraceRecord> sends, frames;
  for (const auto& rec : trace) {
    if (rec.type == "serial_send") sends.push_back(rec);
    if (rec.type == "frame_latched" || rec.type == "frame_rejected") frames.push_back(rec);
  }
  ASSERT_EQ(sends.size(), 2u);
  ASSERT_EQ(frames.size(), 1u);  // the first string is never latched
  EXPECT_EQ(frames[0].type, "frame_latched");
  EXPECT_EQ(frames[0].json.at("bytes"), "cfgrcfgr");
  // The bytes already in the shift and data registers still went out: the
  // NUL of the second string ends at a whole number of characters from T0.
  const long long first = sends[0].t;
  EXPECT_EQ((frames[0].t - first) % 9600, 0);
  EXPECT_GT(frames[0].t, sends[1].t + 9 * 9600 - 1);
  EXPECT_EQ(r.robots[0].framesLatched, 1);
}

// A beacon that never moves: a program that sends nothing.
const char* kBeacon = "main()\n{\n    while (1);\n}\n";

// Thesis chapter X: with the opponent where only one of ICEMAN's eyes sees
// it, ICEMAN sends no motor string (its main loop has no one-eye case).
// The thesis's ideal eyes (thesis-1997): the default's occasional bad
// reading on the right eye would send ICEMAN off.
TEST(Match, IcemanSendsNothingWhileOnlyOneEyeSeesTheOpponent) {
  auto run = [](double bearingDeg) {
    auto config = matchConfig(
        {{"A", kIceman, compileFile(kIceman)}, {"B", "beacon.dc", compileSource(kBeacon)}}, 20,
        "thesis-1997");
    const double range = 4, rad = bearingDeg * 3.14159265358979323846 / 180;
    config.arena.robots[0].start = {0, 1, 0};
    config.arena.robots[1].start = {range * std::sin(rad), 1 + range * std::cos(rad), 0};
    return testkit::runTraced(config);
  };
  const auto oneEye = run(-50);  // left of ICEMAN, beyond the far eye's cone
  int sends = 0;
  bool leftSees = false, rightSees = false;
  for (const auto& rec : parse(oneEye.trace)) {
    if (rec.type == "serial_send" && rec.json.at("robot") == "A") ++sends;
    if (rec.type == "sample" && rec.json.at("robot") == "A") {
      leftSees = leftSees || rec.json.at("eye_left").get<int>() > 48;
      rightSees = rightSees || rec.json.at("eye_right").get<int>() > 48;
    }
  }
  EXPECT_TRUE(leftSees);
  EXPECT_FALSE(rightSees);
  EXPECT_EQ(sends, 0);
  EXPECT_EQ(oneEye.robots[0].framesLatched, 0);
  // Control: dead ahead, both eyes see it and ICEMAN drives.
  EXPECT_GT(run(0).robots[0].framesLatched, 0);
}

// With interrupts disabled the send stalls once the byte the library loaded
// has gone; EI() lets the transmit interrupt finish it.
const char* kStall = R"(char buf[9];
char cc;
int z;
main()
{
    ser_init_z1(0, 9600/1200);
    strcpy(buf, "4fgr4rgr");
    cc = sizeof(buf);
    DI();
    ser_send_z1(buf, &cc);
    for (z = 0; z < 2000; z++);
    EI();
    for (z = 0; z < 2000; z++);
}
)";

TEST(Match, SendStallsWhileInterruptsAreDisabledAndResumesOnEi) {
  auto config = matchConfig({{"A", "stall.dc", compileSource(kStall)}}, 1);
  const auto r = testkit::runTraced(config);
  const auto trace = parse(r.trace);
  long long send = -1, latched = -1;
  for (const auto& rec : trace) {
    if (rec.type == "serial_send") send = rec.t;
    if (rec.type == "frame_latched") latched = rec.t;
  }
  ASSERT_GE(send, 0);
  ASSERT_GE(latched, 0);
  // 2000 delay passes with interrupts off last far longer than 9 characters.
  EXPECT_GT(latched - send, 2000LL * 100);
  EXPECT_EQ(r.robots[0].framesLatched, 1);
}

}  // namespace

namespace {

// Power-on memory (DESIGN.md): zero by default; with the profile's
// random_memory, uninitialised globals, statics and the stack hold bytes
// from the robot's seeded stream, while initialised ones (and string
// literals) keep their values.
TEST(Match, RandomPowerOnMemoryLeavesInitialisedDataAlone) {
  const char* kProgram =
      "int set = 1234;\n"
      "int unset;\n"
      "long lunset;\n"
      "char text[] = \"ok\";\n"
      "main()\n"
      "{\n"
      "    int a;\n"
      "    printf(\"%d %d %ld %s\\n\", set, unset, lunset, text);\n"
      "}\n";
  auto run = [&](bool random, uint64_t seed) {
    auto c = matchConfig({{"A", "mem.dc", compileSource(kProgram)}}, 1);
    c.robots[0].controller.randomMemory = random;
    c.stopWhenAllExited = true;
    c.seed = seed;
    const auto r = scheduler::runMatch(c);
    EXPECT_TRUE(r.robots[0].exited);
    return r.robots[0].console.at(0);
  };
  EXPECT_EQ(run(false, 1), "1234 0 0 ok");
  const std::string one = run(true, 1);
  EXPECT_EQ(one, run(true, 1));
  EXPECT_NE(one, run(true, 2));
  EXPECT_EQ(one.rfind("1234 ", 0), 0u) << one;
  EXPECT_EQ(one.substr(one.size() - 3), " ok") << one;
  EXPECT_NE(one, "1234 0 0 ok");
}

}  // namespace

namespace {

// Two port B writes in one round that both change the plant (a gun motor,
// then a solenoid stroke): the first re-initialises the integrator at its
// tick, and the plant must be brought up to the second before it applies.
TEST(Match, TwoPlantChangingPortBWritesInOneRound) {
  const char* kProgram =
      "main()\n"
      "{\n"
      "    outport(PIODB, 0x08);\n"
      "    outport(PIODB, 0x88);\n"
      "    outport(PIODB, 0x98);\n"
      "    while (1);\n"
      "}\n";
  for (const char* profile : {"default", "thesis-1997"}) {
    auto c = matchConfig({{"A", "guns.dc", compileSource(kProgram)}}, 1, profile);
    testkit::TracedRun r;
    ASSERT_NO_THROW(r = testkit::runTraced(c)) << profile;
    int writes = 0, strokes = 0;
    for (const auto& line : r.trace) {
      writes += line.find("\"port_b\"") != std::string::npos;
      strokes += line.find("\"solenoid_stroke\"") != std::string::npos;
    }
    EXPECT_EQ(writes, 3) << profile;
    EXPECT_EQ(strokes, 1) << profile;
    EXPECT_EQ(r.robots[0].shots, 1) << profile;
  }
}

// DESIGN.md's rules: a robot that faulted loses a tied round; the coin is
// for ties between robots that both ran (or both faulted).
// cycles: the robot's clock when main returned, or at the end of the run,
// never the end of the co-simulation round it happened in.
TEST(Match, CyclesAreTheClockAtMainsReturnOrTheEnd) {
  scheduler::MatchConfig quick = matchConfig(
      {{"A", "quick.dc", compileSource("main()\n{\n  int i;\n  for (i = 0; i < 10; i++);\n}\n")}},
      1.0);
  quick.stopWhenAllExited = true;
  const auto q = scheduler::runMatch(quick);
  ASSERT_TRUE(q.robots[0].exited);
  // main returns within the first round (9,600 ticks); the run ends there.
  EXPECT_LT(q.robots[0].exitTick, 9'600);
  EXPECT_EQ(q.robots[0].cycles, static_cast<uint64_t>(q.robots[0].exitTick));

  // A program that never returns, stopped at 0.043 s = tick 396,288.
  const auto r = scheduler::runMatch(
      matchConfig({{"A", "spin.dc", compileSource("main()\n{\n  for (;;);\n}\n")}}, 0.043));
  EXPECT_FALSE(r.robots[0].exited);
  EXPECT_EQ(r.endTick, 396'288);
  EXPECT_EQ(r.robots[0].cycles, 396'288u);
}

// Larger rounds (match.cpp, "Larger rounds"): with no ball in flight and
// no queued event before the end, a round lets the plant run eight
// character times (76,800 ticks) ahead, sixty-four (614,400) in a solo
// run, and ends there unless a robot acts on the plant. A
// program whose main returns at once idles from then on (its clock stands
// at each horizon), so the 1-s run (9,216,000 ticks) is, for two such
// robots, 9,216,000 / 76,800 = 120 rounds, where one-character rounds took
// 9,216,000 / 9,600 = 960: each round holds eight sub-rounds, and only the
// last of the 120 ends at the end-of-run event. For one, solo, it is
// 9,216,000 / 614,400 = 15.
TEST(Match, IdleRobotsSecondIs120RoundsAndASoloOnesIs15) {
  const auto idle = compileSource("main()\n{\n}\n");
  const auto two =
      scheduler::runMatch(matchConfig({{"A", "idle.dc", idle}, {"B", "idle.dc", idle}}, 1.0));
  ASSERT_TRUE(two.robots[0].exited);
  ASSERT_TRUE(two.robots[1].exited);
  EXPECT_EQ(two.endTick, 9'216'000);
  EXPECT_EQ(two.rounds, 120u);
  const auto one = scheduler::runMatch(matchConfig({{"A", "idle.dc", idle}}, 1.0));
  ASSERT_TRUE(one.robots[0].exited);
  EXPECT_EQ(one.endTick, 9'216'000);
  EXPECT_EQ(one.rounds, 15u);
}

// Larger rounds, rule (d) (match.cpp): a frame's bytes are taken inside
// a round, and only the latch of new wheel speeds by its NUL ends it. The
// robot, solo, sends one 9-byte string at T0 (a few hundred ticks in)
// and returns; byte k finishes at T0 + 9,600 (k + 1), the NUL (k = 8) at
// the latch L = T0 + 86,400. Round 1 would run to 614,400 (sixty-four
// characters: a solo run); bytes 0-7 finish inside it without
// ending it, and the latch ends it at L. From L the robot is idle and
// rounds are 614,400 ticks long up to the end at 9,216,000:
// 1 + ceil((9,216,000 - L) / 614,400) rounds (16). Before rule (d), when
// every byte ended its round, the same run (with eight-character rounds)
// took 128 (at d73b409), and 121 after it.
TEST(Match, AFramesBytesDoNotCutRoundsOnlyItsLatchDoes) {
  const char* kSendOnce =
      "char buf[9];\nchar cc;\n"
      "main()\n{\n    ser_init_z1(0,9600/1200);\n    strcpy(buf,\"8fgr8fgr\");\n"
      "    cc = sizeof(buf);\n    ser_send_z1(buf,&cc);\n}\n";
  const auto r = testkit::runTraced(matchConfig({{"A", "send.dc", compileSource(kSendOnce)}}, 1.0));
  ASSERT_EQ(r.robots[0].framesLatched, 1);
  long long latch = -1;
  for (const auto& rec : parse(r.trace))
    if (rec.type == "frame_latched") latch = rec.t;
  ASSERT_GT(latch, 86'400);
  ASSERT_LT(latch, 614'400);
  EXPECT_EQ(r.endTick, 9'216'000);
  EXPECT_EQ(r.rounds, static_cast<uint64_t>(1 + (9'216'000 - latch + 614'400 - 1) / 614'400));
}

TEST(Match, AFaultedRobotLosesATiedRound) {
  const char* kFaults = "int *p;\nmain()\n{\n    *p = 1;\n}\n";  // null pointer at once
  for (uint64_t seed = 1; seed <= 8; ++seed) {
    auto c = matchConfig(
        {{"A", "faults.dc", compileSource(kFaults)}, {"B", "beacon.dc", compileSource(kBeacon)}},
        1);
    c.seed = seed;
    const auto r = scheduler::runMatch(c);
    ASSERT_TRUE(r.robots[0].fault.has_value());
    EXPECT_EQ(r.robots[0].hits, r.robots[1].hits);
    EXPECT_EQ(r.winner, "B") << "seed " << seed;
    EXPECT_FALSE(r.tieBrokenByCoin);
  }
}

// A value the profile loader would refuse (a motor lag of 1e-300 s), put
// straight into the arena: the integrator fails, and the run ends there
// with a fault of the plant, its time, and the rest of the result intact.
TEST(Match, AnIntegratorFailureEndsTheRunWithAPlantFault) {
  const char* kDrive =
      "char buf[9];\nchar cc;\nmain()\n{\n    ser_init_z1(0, 9600/1200);\n"
      "    strcpy(buf, \"8fgr8fgr\");\n    cc = sizeof(buf);\n    ser_send_z1(buf, &cc);\n"
      "    while (1);\n}\n";
  auto c = matchConfig({{"A", "drive.dc", compileSource(kDrive)}}, 5);
  c.arena.robots[0].params.motor_lag_s = 1e-300;
  scheduler::MatchResult r;
  ASSERT_NO_THROW(r = scheduler::runMatch(c));
  ASSERT_TRUE(r.plantFault.has_value());
  EXPECT_NE(r.plantFault->message.find("SUNDIALS"), std::string::npos) << r.plantFault->message;
  EXPECT_LT(r.endTick, 5 * scheduler::kTicksPerSecond);
  EXPECT_EQ(r.plantFault->timeS, static_cast<double>(r.endTick) / scheduler::kTicksPerSecond);
  EXPECT_GT(r.robots[0].framesLatched, 0);  // the frame that made the plant fail
  EXPECT_TRUE(std::isfinite(r.robots[0].finalPose.x_ft));
}

// programs/costate_hunter.dc, the costatement-style robot, against ICEMAN
// for a full 180-s round: its steering costatement sends a frame only once
// the previous one has gone (cc back at 0), so it latches frames all round
// and overwrites none; it finds ICEMAN and shoots; a rerun is identical.
TEST(Match, CostateHunterPlaysIcemanAndLatchesFrames) {
  const std::string hunter = SIMBOT_SOURCE_DIR "/programs/costate_hunter.dc";
  auto make = [&] {
    return matchConfig({{"A", hunter, compileFile(hunter)}, {"B", kIceman, compileFile(kIceman)}},
                       180);
  };
  const auto r1 = testkit::runTraced(make());
  const auto r2 = testkit::runTraced(make());
  EXPECT_EQ(summary(r1), summary(r2));
  EXPECT_EQ(r1.trace, r2.trace);
  ASSERT_EQ(r1.robots.size(), 2u);
  const auto& a = r1.robots[0];
  const auto& b = r1.robots[1];
  EXPECT_FALSE(a.fault.has_value());
  EXPECT_FALSE(b.fault.has_value());
  EXPECT_GT(a.framesLatched, 50);
  EXPECT_GT(b.framesLatched, 0);
  EXPECT_EQ(a.framesOverwritten, 0);
  EXPECT_EQ(a.framesRejected, 0);
  EXPECT_GT(a.shots, 0);
  EXPECT_GT(a.hits, 0);
}

// The same robot with power-on RAM randomised (the profile's random_memory):
// it sets cc and every other flag it reads before the loop first reads them,
// so it still latches frames from the start (issue 25: it used to wait for
// a cc that the random fill had left non-zero, and sent nothing in 180 s).
TEST(Match, CostateHunterLatchesFramesWithRandomPowerOnMemory) {
  const std::string hunter = SIMBOT_SOURCE_DIR "/programs/costate_hunter.dc";
  for (const uint64_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE(seed);
    auto c = matchConfig({{"A", hunter, compileFile(hunter)}}, 5);
    c.robots[0].controller.randomMemory = true;
    c.seed = seed;
    const auto r = scheduler::runMatch(c);
    const auto& a = r.robots[0];
    EXPECT_FALSE(a.fault.has_value());
    EXPECT_GT(a.framesLatched, 50);
    EXPECT_EQ(a.framesOverwritten, 0);
  }
}

// Issue 24's student program: the bearing to a remembered point with atan2
// and sqrt, steered through a table of function pointers. It compiles with
// no warning, its code calls through pointers and reaches the math
// routines, and it plays a whole match against fig92 without a fault,
// every frame latched (it waits for cc before each send).
TEST(Match, BearingStudentProgramPlaysFig92) {
  const std::string bearing = SIMBOT_SOURCE_DIR "/programs/bearing.dc";
  const auto compiled = compiler::compileFile(bearing);
  ASSERT_TRUE(compiled.image.has_value());
  EXPECT_TRUE(compiled.warnings.empty())
      << (compiled.warnings.empty() ? "" : compiled.warnings[0].format());
  std::set<std::string> reached;
  const auto& code = compiled.image->code;
  for (uint32_t at = 0; at < code.size();) {
    const auto op = static_cast<vm::Op>(code[at]);
    if (op == vm::Op::CALLI) reached.insert("CALLI");
    if (op == vm::Op::LIB) reached.insert(std::string(vm::kLibInfo[code[at + 1]].name));
    at += static_cast<uint32_t>(vm::instructionSize(op));
  }
  EXPECT_TRUE(reached.count("CALLI") && reached.count("atan2") && reached.count("sqrt"));
  const auto r = testkit::runTraced(
      matchConfig({{"A", bearing, *compiled.image}, {"B", kFig92, compileFile(kFig92)}}, 180));
  ASSERT_EQ(r.robots.size(), 2u);
  const auto& a = r.robots[0];
  EXPECT_FALSE(a.fault.has_value());
  EXPECT_GT(a.framesLatched, 1000);
  EXPECT_EQ(a.framesOverwritten, 0);
  EXPECT_EQ(a.framesRejected, 0);
  EXPECT_GT(a.shots, 0);
}

// Keeps only the trace records of the kinds listed (a 180-s match writes
// some 100,000 records; the tests below need a few hundred).
template <class... Kinds>
class KeepSink final : public trace::Sink {
 public:
  void write(const trace::Entry& e) override {
    if ((std::holds_alternative<Kinds>(e.record) || ...)) entries.push_back(e);
  }
  std::vector<trace::Entry> entries;
};

// Thesis VI.D: more than event_limit (5) edge-handler entries within the
// window (10 s) make the referee turn the robot by turn_deg (45). The
// entries are counted at the tick their PIO interrupt is accepted
// (Robot::interruptAccepted records it during the round, the arena applies
// it after the round at that tick: Arena::edgeHandlerEntered rewinds the
// plant to it). So the turn must be at the sixth acceptance's tick, not
// at the end of the round it fell in. The program keeps interrupts off
// most of the time, so that each request waits for an EI and is accepted
// in the middle of a round; six edges are injected 1.2 s apart.
TEST(Match, RefereeTurnsAtTheTickOfTheCountedHandlerEntry) {
  const std::string kEdgy = R"(#INT_VEC PIOA_VEC edge
int z, hits;
interrupt reti edge()
{
    hits++;
}
main()
{
)" + std::string(testkit::kArmPortA) +
                            R"(    while (1) {
        DI();
        for (z = 0; z < 37; z++)
            ;
        EI();
    }
}
)";
  auto run = [&](bool inject) {
    auto c = matchConfig({{"A", "edgy.dc", compileSource(kEdgy)}}, 9);
    if (inject)
      for (int k = 1; k <= 6; ++k)
        c.injections.push_back(
            config::parseInjection("A:edge_fore@" + std::to_string(1.2 * k) + "s", 1));
    KeepSink<trace::rec::InterruptAccepted, trace::rec::RefereeTurn> keep;
    c.sinks.push_back(&keep);
    auto r = scheduler::runMatch(c);
    return std::make_pair(r, keep.entries);
  };
  const auto [plain, plainTrace] = run(false);
  const auto [turned, trace] = run(true);
  ASSERT_EQ(matchConfig({}, 1).arena.referee.event_limit, 5);
  const auto accepted = testkit::recordsOf<trace::rec::InterruptAccepted>(trace, 0);
  const auto turns = testkit::recordsOf<trace::rec::RefereeTurn>(trace, 0);
  ASSERT_EQ(accepted.size(), 6u);
  for (size_t k = 0; k < accepted.size(); ++k) {
    EXPECT_EQ(accepted[k].second.source, "pio_a");
    // Mid-round: not at the injection's tick (a round's end) but at the
    // EI that lets it in, later in the round.
    const timebase::Tick injected = timebase::ticksFromSeconds(1.2 * static_cast<double>(k + 1));
    EXPECT_GT(accepted[k].first - injected, 100) << k;
    EXPECT_LT(accepted[k].first - injected, timebase::kTicksPerChar) << k;
  }
  ASSERT_EQ(turns.size(), 1u);
  EXPECT_EQ(turns[0].first, accepted[5].first);
  // The robot stands still: the turn is all its heading changed by.
  EXPECT_NEAR(turned.robots[0].finalPose.heading_deg,
              std::fmod(plain.robots[0].finalPose.heading_deg + 45.0, 360.0), 1e-9);
  EXPECT_TRUE(testkit::recordsOf<trace::rec::RefereeTurn>(plainTrace).empty());
}

// The 180-s ICEMAN vs fig92 match (`simbot match iceman.dc fig92.dc`:
// default profile, seed 1, the profile's 180-s round). The counts and ticks
// below are REGRESSION values read from the run, not an oracle: a change
// to the cost table, the plant or the scheduler that moves them must say
// why. Two relations are checked as an oracle:
//
// - ICEMAN's first send, by hand from the cost table (calibrated, the
//   figures `simbot compile --disasm` prints; no interrupt can come before
//   it, as nothing moves yet): CALL main 18; ser_init_z1's line DBG 68 +
//   2 PUSHW 22 + 196 = 308; hv_enb's 68 + 50 = 118; 8 outport lines of
//   68 + 2 x 22 + 67 = 179 each = 1432; cnt=0 and shcnt=0, 68 + 22 + 28 =
//   118 each; read(); = DBG 68 + CALL 18 + POP 10 + read's two lines of
//   DBG 68 + PUSHW 22 + ad_rd8 163 + the 276-T-state conversion + STGW 28
//   = 557 and its return 68 + 22 + RET 10 = 1310; the delay loop of line 44,
//   DBG 68 + PUSHL 44 + STGL 58 = 170, then 50,000 passes of LDGL 61 +
//   PUSHL 44 + LTUL 94 + JZ not taken 25 + DBG 68 + INCGL 92 + JMP 10 = 394
//   = 19,700,000, and the exit LDGL 61 + PUSHL 44 + LTUL 94 + JZ taken 29
//   = 228; search(); DBG 68 + CALL 18; search's test x<=48 && y<=48 (both
//   eyes at background): DBG 68 + 2 x (LDGW 29 + PUSHW 22 + LEW 56, no
//   overflow and true + JZ not taken 25) = 332; strcpy(buf,"cfgrcfgr"):
//   DBG 68 + 2 PUSHW 22 + strcpy 59 + 8 bytes x 36 (each loops back) +
//   the NUL's 34 + POP 10 = 503;
//   platform(); DBG 68 + CALL 18; cc = sizeof(buf): 68 + 22 + STGB 29 =
//   119; outport(ENB485,1): 179; ser_send_z1(buf,&cc): 68 + 2 x 22 + 189
//   = 301. In all 19,705,426: the send returns (T0) at that tick.
// - The frame latches when the NUL's stop bit ends: 8 characters and the
//   NUL, 9 character times of kTicksPerChar = 9,600 ticks (10 bits at 9,600
//   baud, 960 characters a second) after T0: 19,705,426 + 86,400 =
//   19,791,826.
TEST(Match, IcemanAgainstFig92For180SecondsPinsItsKeyFigures) {
  auto c =
      matchConfig({{"A", kIceman, compileFile(kIceman)}, {"B", kFig92, compileFile(kFig92)}},
                  config::loadProfile(SIMBOT_SOURCE_DIR "/profiles/default.toml").round_length_s);
  ASSERT_EQ(c.seed, 1u);  // simbot match's default
  ASSERT_EQ(c.endTick, 180 * timebase::kTicksPerSecond);
  KeepSink<trace::rec::SerialSend, trace::rec::FrameLatched, trace::rec::SolenoidStroke,
           trace::rec::BallLaunch>
      keep;
  c.sinks.push_back(&keep);
  const auto r = scheduler::runMatch(c);
  ASSERT_EQ(r.robots.size(), 2u);
  // Regression values (default profile, seed 1: its hand placement, trims,
  // eye noise and muzzle speeds). Issue 22 moved them (918 and 8,620
  // frames, 5 hits before): bodies stopped at walls and at each other
  // instead of sinking in until the reflex reversed them, so every contact
  // ends about 0.14 s sooner and the robots are elsewhere afterwards. The
  // first frame, the first stroke and the first launch come before the
  // first contact and did not move. Issue 24 moved them again (969 frames):
  // string routines charge their loop's branch taken on every byte but the
  // last (strcpy +2 T-states a byte), an interrupt acknowledge 18 T-states,
  // and the plant's resets no longer carry the step controller's history.
  // Issue 25's gun dispersion moved none of them: it turns only the balls,
  // and ICEMAN's two hits still hit. Issue 38 moved them again (from 1,029
  // and 8,621 frames; the first stroke and launch are 12,907 ticks later):
  // RETI is the Z80180's 22 T-states, not the Z8S180's 12, and ends every
  // serial transmit interrupt (one a byte sent) and handler. The first
  // send and frame come before any RETI and did not move.
  EXPECT_EQ(r.robots[0].framesLatched, 953);
  EXPECT_EQ(r.robots[1].framesLatched, 8616);
  EXPECT_EQ(r.robots[0].shots, 30);
  EXPECT_EQ(r.robots[1].shots, 0);
  EXPECT_EQ(r.robots[0].hits, 2);
  EXPECT_EQ(r.robots[1].hits, 0);
  EXPECT_EQ(r.winner, "A");
  const auto sends = testkit::recordsOf<trace::rec::SerialSend>(keep.entries, 0);
  const auto frames = testkit::recordsOf<trace::rec::FrameLatched>(keep.entries, 0);
  const auto strokes = testkit::recordsOf<trace::rec::SolenoidStroke>(keep.entries, 0);
  const auto launches = testkit::recordsOf<trace::rec::BallLaunch>(keep.entries, 0);
  ASSERT_FALSE(sends.empty());
  ASSERT_FALSE(frames.empty());
  ASSERT_FALSE(strokes.empty());
  ASSERT_FALSE(launches.empty());
  EXPECT_EQ(static_cast<int>(frames.size()), r.robots[0].framesLatched);
  EXPECT_EQ(static_cast<int>(launches.size()), r.robots[0].shots);
  // The oracle: T0 summed by hand above, the latch 9 characters later.
  EXPECT_EQ(sends[0].first, 19'705'426);
  EXPECT_EQ(frames[0].first - sends[0].first, 9 * timebase::kTicksPerChar);
  EXPECT_EQ(frames[0].first, 19'791'826);
  EXPECT_EQ(frames[0].second.bytes, "cfgrcfgr");
  // Regression values: the first fire()'s solenoids (port B 0x30, both
  // guns), and its launch one stroke (0.03 s = 276,480 ticks) later.
  EXPECT_EQ(strokes[0].first, 95'273'762);
  EXPECT_EQ(launches[0].first, 95'550'242);
  EXPECT_EQ(launches[0].first - strokes[0].first, 276'480);
  // Issue 25: every ball carries its dispersion. The angles recovered from
  // the ball_launch records (velocity against the record's heading) are
  // standard normals once divided by the profile's sigmas, so over the 30
  // launches the sum of their squares is chi-square with 60 degrees of
  // freedom (Boost's quantiles: outside 0.05% .. 99.95% fails).
  constexpr double kPi = 3.14159265358979323846;
  const config::Profile prof = config::loadProfile(SIMBOT_SOURCE_DIR "/profiles/default.toml");
  double sumSquares = 0;
  for (const auto& [tick, launch] : launches) {
    const double across = std::hypot(launch.vx_fps, launch.vy_fps);
    double az = std::atan2(launch.vx_fps, launch.vy_fps) * 180 / kPi - launch.heading_deg;
    az = std::remainder(az, 360.0);
    const double el = std::atan2(launch.vz_fps, across) * 180 / kPi;
    EXPECT_NE(az, 0.0) << "a launch without azimuth dispersion at tick " << tick;
    EXPECT_NE(el, 0.0) << "a launch without elevation dispersion at tick " << tick;
    sumSquares += std::pow(az / prof.robot.azimuth_sigma_deg, 2) +
                  std::pow(el / prof.robot.elevation_sigma_deg, 2);
  }
  const boost::math::chi_squared law(2.0 * static_cast<double>(launches.size()));
  EXPECT_GT(sumSquares, boost::math::quantile(law, 0.0005));
  EXPECT_LT(sumSquares, boost::math::quantile(law, 0.9995));
}

// Issue 22: bodies are rigid. In four seeded 180-s matches every 20-Hz
// sample has both bodies inside the field, clear of the divider and of
// each other, to the tolerance docs/plant.md documents (1e-6 ft: a
// contact's crossing lies less than a tick before its event, 1.6e-7 ft at
// top speed). The plant before rigid contacts failed this at seed 1 (B
// 0.75 in inside the north wall at 9.85 s) and seed 7 (A and B overlapping
// by 0.062 ft).
TEST(Match, NoBodyEntersAWallTheDividerOrTheOtherRobot) {
  const config::Profile prof = config::loadProfile(SIMBOT_SOURCE_DIR "/profiles/default.toml");
  const double r = prof.robot.body_diameter_ft / 2, half = prof.field.size_ft / 2;
  constexpr double kTolerance = 1e-6;  // ft
  for (const std::uint64_t seed : {1u, 7u, 11u, 19u}) {
    auto c = matchConfig({{"A", kIceman, compileFile(kIceman)}, {"B", kFig92, compileFile(kFig92)}},
                         prof.round_length_s);
    c.seed = seed;
    KeepSink<trace::rec::Sample> keep;
    c.sinks.push_back(&keep);
    scheduler::runMatch(c);
    const auto a = testkit::recordsOf<trace::rec::Sample>(keep.entries, 0);
    const auto b = testkit::recordsOf<trace::rec::Sample>(keep.entries, 1);
    ASSERT_EQ(a.size(), b.size());
    ASSERT_GT(a.size(), 3000u);
    double wall = -1, divider = -1, overlap = -1;
    for (std::size_t k = 0; k < a.size(); ++k) {
      ASSERT_EQ(a[k].first, b[k].first);
      for (const auto* s : {&a[k].second, &b[k].second}) {
        wall = std::max({wall, std::abs(s->x_ft) + r - half, std::abs(s->y_ft) + r - half});
        divider = std::max(divider, -plant::dividerClearance(s->x_ft, s->y_ft, r, prof.field));
      }
      overlap = std::max(overlap, 2 * r - std::hypot(a[k].second.x_ft - b[k].second.x_ft,
                                                     a[k].second.y_ft - b[k].second.y_ft));
    }
    EXPECT_LE(wall, kTolerance) << "seed " << seed;
    EXPECT_LE(divider, kTolerance) << "seed " << seed;
    EXPECT_LE(overlap, kTolerance) << "seed " << seed;
  }
}

}  // namespace

namespace {

// ICEMAN vs fig92 for `seconds` under `profile` with `seed`, traced.
testkit::TracedRun icemanFig92(const std::string& profile, uint64_t seed, double seconds) {
  auto c = matchConfig({{"A", kIceman, compileFile(kIceman)}, {"B", kFig92, compileFile(kFig92)}},
                       seconds, profile);
  c.seed = seed;
  return testkit::runTraced(c);
}

}  // namespace

// Issue 14: under `default` every seed is another match (hand placement,
// wheel trims, eye noise, muzzle speed); the same seed is the same match.
TEST(Match, DefaultProfileGivesEachSeedItsOwnMatchAndTheSameSeedTheSameOne) {
  std::vector<std::vector<std::string>> traces;
  for (uint64_t seed = 1; seed <= 4; ++seed)
    traces.push_back(icemanFig92("default", seed, 20).trace);
  for (size_t i = 0; i < traces.size(); ++i)
    for (size_t j = i + 1; j < traces.size(); ++j)
      EXPECT_NE(traces[i], traces[j]) << "seeds " << i + 1 << " and " << j + 1;
  EXPECT_EQ(icemanFig92("default", 1, 20).trace, traces[0]);
  // The trace's set-up records give the poses the hand chose: within the
  // profile's radius and heading spread of the marks, and not the marks.
  const config::Profile d = config::loadProfile(SIMBOT_SOURCE_DIR "/profiles/default.toml");
  for (const auto& trace : traces) {
    int setups = 0;
    // The set-up records lead the trace: parse up to the second robot's.
    for (size_t line = 0; line < trace.size() && setups < 2; ++line) {
      const auto rec = nlohmann::json::parse(trace[line]);
      if (rec.at("type") != "robot") continue;
      const auto& mark = d.field.start[static_cast<size_t>(setups++)];
      const double dx = rec.at("x_ft").get<double>() - mark.x_ft;
      const double dy = rec.at("y_ft").get<double>() - mark.y_ft;
      double dh = rec.at("heading_deg").get<double>() - mark.heading_deg;
      if (dh > 180) dh -= 360;
      EXPECT_LE(std::hypot(dx, dy), d.field.placement_radius_ft);
      EXPECT_GT(std::hypot(dx, dy), 0);
      EXPECT_LE(std::abs(dh), d.field.placement_heading_deg);
    }
    EXPECT_EQ(setups, 2);
  }
}

// Under thesis-1997 (no variation) the seed decides only a tied round's
// coin: traces differ in the run record's seed and, where the coin
// decided, the end record's winner; nothing else.
TEST(Match, Thesis1997SeedChangesOnlyTheCoin) {
  // Only the run and end records are parsed (the others compare as lines:
  // parsing 16 traces took most of this test's 80 s under ASan). Were the
  // lines' layout to change, the run records would differ and fail.
  const auto strip = [](const testkit::TracedRun& run) {
    std::vector<std::string> out;
    for (const std::string& line : run.trace) {
      const bool isRun = line.find(R"("type":"run")") != std::string::npos;
      const bool isEnd = line.find(R"("type":"end")") != std::string::npos;
      if (!isRun && !isEnd) {
        out.push_back(line);
        continue;
      }
      auto rec = nlohmann::json::parse(line);
      if (isRun) rec.erase("seed");
      if (isEnd && rec.at("tie_broken_by_coin").get<bool>()) rec.erase("winner");
      out.push_back(rec.dump());
    }
    return out;
  };
  for (const double seconds : {20.0, 2.0}) {  // 20 s: ICEMAN hits; 2 s: a 0-0 tie
    const auto first = icemanFig92("thesis-1997", 1, seconds);
    std::set<std::string> winners{first.winner};
    for (uint64_t seed = 2; seed <= 8; ++seed) {
      const auto run = icemanFig92("thesis-1997", seed, seconds);
      EXPECT_EQ(strip(run), strip(first)) << seconds << " s, seed " << seed;
      EXPECT_EQ(run.tieBrokenByCoin, first.tieBrokenByCoin);
      winners.insert(run.winner);
    }
    // The 0-0 tie goes to the coin, which both sides win over 8 seeds
    // (all 8 flips alike: probability 2^-7, and the seeds are fixed).
    if (first.tieBrokenByCoin)
      EXPECT_EQ(winners.size(), 2u) << seconds;
    else
      EXPECT_EQ(winners.size(), 1u) << seconds;
    EXPECT_EQ(first.tieBrokenByCoin, seconds == 2.0);
  }
}
