// The typed trace (trace/records.def): what the new records and fields say,
// checked against closed forms and hand computations, and the order and
// encoding every sink relies on.
#include "trace/trace.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "config/config.h"
#include "plant/plant.h"
#include "scheduler/match.h"
#include "sinks/trace_jsonl.h"
#include "support/programs.h"
#include "support/records.h"
#include "support/test_host.h"

using namespace simbot;

namespace {

namespace rec = trace::rec;

config::Profile profile(const std::string& name) {
  return config::loadProfile(SIMBOT_SOURCE_DIR "/profiles/" + name + ".toml");
}

// A run with the typed trace collected.
struct Traced {
  scheduler::MatchResult result;
  std::vector<trace::Entry> entries;
  template <class R>
  std::vector<std::pair<trace::Tick, R>> all(int robot = -1) const {
    return testkit::recordsOf<R>(entries, robot);
  }
};

Traced run(scheduler::MatchConfig c) {
  trace::Collector collector;
  c.sinks.push_back(&collector);
  Traced t{scheduler::runMatch(c), {}};
  t.entries = std::move(collector.entries);
  return t;
}

scheduler::MatchConfig solo(const std::string& source, double seconds,
                            const std::string& profileName = "thesis-1997") {
  scheduler::MatchConfig c;
  c.arena = config::makeArenaConfig(profile(profileName), 1);
  c.robots.push_back({"A", "test.dc", testkit::compileOrDie(source)});
  c.endTick = timebase::ticksFromSeconds(seconds);
  return c;
}

// A shooter and a beacon (a program that returns at once).
scheduler::MatchConfig duel(const std::string& shooter, plant::Pose a, plant::Pose b,
                            double seconds) {
  scheduler::MatchConfig c;
  c.arena = config::makeArenaConfig(profile("thesis-1997"), 2);
  c.arena.robots[0].start = a;
  c.arena.robots[1].start = b;
  c.robots.push_back({"A", "shooter.dc", testkit::compileOrDie(shooter)});
  c.robots.push_back({"B", "beacon.dc", testkit::compileOrDie("main()\n{\n}\n")});
  c.endTick = timebase::ticksFromSeconds(seconds);
  return c;
}

constexpr scheduler::Tick kSample = scheduler::kTicksPerSecond / 20;  // 460,800

// Two delay loops, 30,000 passes each. A pass of `for(z=0;z<N;z++);` costs
// 252 T-states in a debug build (docs/cycle-model.md, "The cycle model"; pinned by
// tests/timing_test.cpp DelayLoop.PassCostIsTheSumOfItsSequences), so the
// first loop runs about 30,000 x 252 = 7,560,000 ticks and the second as
// long again (15,120,000); start-up and loop set-up add hundreds of ticks.
// Samples every 460,800 ticks: samples 1..16 (up to 7,372,800) fall in line
// 4, samples 17..32 (7,833,600 .. 14,745,600) in line 5, and from sample 33
// (15,206,400) main has returned.
const char* kTwoLoops =
    "int z;\n"
    "main()\n"
    "{\n"
    "    for (z = 0; z < 30000; z++);\n"
    "    for (z = 0; z < 30000; z++);\n"
    "}\n";

TEST(Trace, SamplesSayWhichLineTheProgramIsAt) {
  const Traced t = run(solo(kTwoLoops, 2));
  const auto samples = t.all<rec::Sample>();
  ASSERT_EQ(samples.size(), 41u);  // 0, 0.05, ..., 2.0 s
  for (size_t k = 1; k < samples.size(); ++k) {
    const auto& [tick, s] = samples[k];
    EXPECT_EQ(tick, static_cast<scheduler::Tick>(k) * kSample);
    const int want = k <= 16 ? 4 : k <= 32 ? 5 : -1;
    if (want > 0) {
      EXPECT_EQ(s.line, want) << "sample " << k;
      EXPECT_EQ(s.function, "main") << "sample " << k;
    } else {
      EXPECT_EQ(s.function, "") << "sample " << k << ": main has returned";
    }
    EXPECT_FALSE(s.in_handler);
  }
  EXPECT_TRUE(t.result.robots[0].exited);
  const double exit = static_cast<double>(t.result.robots[0].exitTick);
  EXPECT_NEAR(exit, 2 * 30000 * 252.0, 1000);  // the closed form, plus set-up
}

// An edge handler that runs 20,000 passes (20,000 x 252 = 5,040,000 ticks)
// injected at 0.2 s = 1,843,200 ticks, which is sample 4's tick: that sample
// is taken before the request (raised when the round ends there), samples
// 5..14 (2,304,000 .. 6,451,200) fall inside the handler, which ends near
// 1,843,200 + 5,040,000 = 6,883,200, and samples 15 and 16 (6,912,000 and
// 7,372,800) are back in main's loop, which has 30,000 x 252 - 1,843,200
// ticks of its own left.
const std::string kHandler =
    "#INT_VEC PIOA_VEC edge\n"
    "int z, w;\n"
    "interrupt reti edge()\n"
    "{\n"
    "    for (w = 0; w < 20000; w++);\n"
    "}\n"
    "main()\n"
    "{\n" +
    std::string(testkit::kArmPortA) +
    "    for (z = 0; z < 30000; z++);\n"
    "}\n";

TEST(Trace, SamplesSayWhenAHandlerIsInService) {
  auto c = solo(kHandler, 1);
  c.injections.push_back(config::parseInjection("A:edge_fore@0.2s", 1));
  const Traced t = run(c);
  const auto samples = t.all<rec::Sample>();
  ASSERT_GE(samples.size(), 17u);
  for (size_t k = 1; k <= 16; ++k) {
    const rec::Sample& s = samples[k].second;
    const bool inside = k >= 5 && k <= 14;
    EXPECT_EQ(s.in_handler, inside) << "sample " << k;
    EXPECT_EQ(s.function, inside ? "edge" : "main") << "sample " << k;
    EXPECT_EQ(s.line, inside ? 5 : 15) << "sample " << k;
  }
  // The acceptance names the handler; IFF1 falls with it and rises when its
  // RETI ends (the epilogue's EI), and port A shows the injected pulse.
  const auto accepted = t.all<rec::InterruptAccepted>();
  ASSERT_EQ(accepted.size(), 1u);
  EXPECT_EQ(accepted[0].second.handler, "edge");
  EXPECT_EQ(accepted[0].second.function, "main");
  EXPECT_EQ(accepted[0].second.line, 15);
  const auto returned = t.all<rec::InterruptReturned>();
  ASSERT_EQ(returned.size(), 1u);
  EXPECT_NEAR(static_cast<double>(returned[0].first - accepted[0].first), 20000 * 252.0, 1000);
  const auto iff = t.all<rec::Iff1>();
  ASSERT_EQ(iff.size(), 2u);
  EXPECT_EQ(iff[0].first, accepted[0].first);
  EXPECT_FALSE(iff[0].second.enabled);
  EXPECT_EQ(iff[1].first, returned[0].first);
  EXPECT_TRUE(iff[1].second.enabled);
  const auto portA = t.all<rec::PortA>();
  ASSERT_EQ(portA.size(), 2u);
  EXPECT_EQ(portA[0].first, 1'843'200);
  EXPECT_EQ(portA[0].second.value, 0xFD);                                  // fore (bit 1) low
  EXPECT_EQ(portA[1].first, 1'843'200 + scheduler::kTicksPerSecond / 20);  // 50 ms later
  EXPECT_EQ(portA[1].second.value, 0xFF);
}

// Each serial_send says where it came from. tests/programs/send_twice.dc
// (its header works the lines out) sends from main lines 24 and 27, then
// from platform()'s line 45 called from main lines 31 and 33, from spin()'s
// line 51 (spin called from main line 36) and from main line 37.
TEST(Trace, SendsSayWhereTheyCameFrom) {
  std::ifstream in(SIMBOT_SOURCE_DIR "/tests/programs/send_twice.dc");
  std::stringstream text;
  text << in.rdbuf();
  const Traced t = run(solo(text.str(), 0.5));
  struct Want {
    int line;
    const char* function;
    int callerLine;
    const char* callerFunction;
    const char* calls;
  };
  const Want want[] = {{24, "main", 0, "", "main:24"},
                       {27, "main", 0, "", "main:27"},
                       {45, "platform", 31, "main", "main:31 > platform:45"},
                       {45, "platform", 33, "main", "main:33 > platform:45"},
                       {45, "platform", 51, "spin", "main:36 > spin:51 > platform:45"},
                       {45, "platform", 37, "main", "main:37 > platform:45"}};
  const auto sends = t.all<rec::SerialSend>();
  ASSERT_EQ(sends.size(), std::size(want));
  for (size_t k = 0; k < sends.size(); ++k) {
    const rec::SerialSend& s = sends[k].second;
    EXPECT_EQ(s.count, 9) << k;
    EXPECT_EQ(s.line, want[k].line) << k;
    EXPECT_EQ(s.function, want[k].function) << k;
    EXPECT_EQ(s.caller_line, want[k].callerLine) << k;
    EXPECT_EQ(s.caller_function, want[k].callerFunction) << k;
    EXPECT_EQ(s.calls, want[k].calls) << k;
  }
  // Every second send of a pair overwrites the first: the record names both,
  // at the new send's tick.
  const auto over = t.all<rec::FrameOverwritten>();
  ASSERT_EQ(over.size(), 3u);
  for (size_t k = 0; k < over.size(); ++k) {
    const rec::FrameOverwritten& o = over[k].second;
    const Want& send = want[2 * k + 1];
    const Want& before = want[2 * k];
    EXPECT_EQ(over[k].first, sends[2 * k + 1].first) << k;
    EXPECT_EQ(o.previous_t, sends[2 * k].first) << k;
    EXPECT_EQ(o.line, send.line) << k;
    EXPECT_EQ(o.function, send.function) << k;
    EXPECT_EQ(o.caller_line, send.callerLine) << k;
    EXPECT_EQ(o.caller_function, send.callerFunction) << k;
    EXPECT_EQ(o.previous_line, before.line) << k;
    EXPECT_EQ(o.previous_function, before.function) << k;
    EXPECT_EQ(o.previous_caller_line, before.callerLine) << k;
    EXPECT_EQ(o.previous_caller_function, before.callerFunction) << k;
  }
  // They read back from JSONL field for field.
  for (const auto& e : t.entries) {
    const nlohmann::json j = sinks::traceJson(e);
    EXPECT_EQ(sinks::traceJson(sinks::traceEntry(j)), j);
  }
  // A trace from before the fields were recorded is refused, naming the
  // field (the reader requires every field of the definition).
  nlohmann::json old = sinks::traceJson(trace::Entry{sends[0].first, sends[0].second, {}});
  old.erase("line");
  try {
    sinks::traceEntry(old);
    FAIL() << "a serial_send without its line must be refused";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("\"line\""), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("older simbot"), std::string::npos) << e.what();
  }
}

// A send from a handler: the chain goes through the code the edge
// interrupted (main line 29 called wait(), whose loop is line 17), then the
// handler edge() on line 12 calls go(), which sends on line 8; the
// handler's own send on line 13 has no caller (nothing called edge()) and
// overwrites go()'s.
const std::string kHandlerSends =
    "#INT_VEC PIOA_VEC edge\n"
    "char buf[9];\n"
    "char cc;\n"
    "int z;\n"
    "go()\n"
    "{\n"
    "    cc = sizeof(buf);\n"
    "    ser_send_z1(buf, &cc);\n"
    "}\n"
    "interrupt reti edge()\n"
    "{\n"
    "    go();\n"
    "    ser_send_z1(buf, &cc);\n"
    "}\n"
    "wait()\n"
    "{\n"
    "    for (z = 0; z < 30000; z++);\n"
    "}\n"
    "main()\n"
    "{\n"
    "    ser_init_z1(0, 9600/1200);\n" +
    std::string(testkit::kArmPortA) +
    "    strcpy(buf, \"cfgrcfgr\");\n"
    "    wait();\n"
    "}\n";

TEST(Trace, SendsFromAHandlerSayWhatItInterrupted) {
  auto c = solo(kHandlerSends, 0.5);
  c.injections.push_back(config::parseInjection("A:edge_fore@0.2s", 1));
  const Traced t = run(c);
  const auto sends = t.all<rec::SerialSend>();
  ASSERT_EQ(sends.size(), 2u);
  EXPECT_EQ(sends[0].second.line, 8);
  EXPECT_EQ(sends[0].second.function, "go");
  EXPECT_EQ(sends[0].second.caller_line, 12);
  EXPECT_EQ(sends[0].second.caller_function, "edge");
  EXPECT_EQ(sends[0].second.calls, "main:29 > wait:17 > interrupt > edge:12 > go:8");
  EXPECT_EQ(sends[1].second.line, 13);
  EXPECT_EQ(sends[1].second.function, "edge");
  EXPECT_EQ(sends[1].second.caller_line, 0);
  EXPECT_EQ(sends[1].second.caller_function, "");
  EXPECT_EQ(sends[1].second.calls, "main:29 > wait:17 > interrupt > edge:13");
  const auto over = t.all<rec::FrameOverwritten>();
  ASSERT_EQ(over.size(), 1u);
  EXPECT_EQ(over[0].second.line, 13);
  EXPECT_EQ(over[0].second.previous_line, 8);
  EXPECT_EQ(over[0].second.previous_caller_line, 12);
}

// Fires gun 1 once (thesis-1997: gun wheels always at full speed, no
// stroke time, 105 ft/s, launched 1.5 ft up from the body's edge).
const char* kShootOnce =
    "main()\n"
    "{\n"
    "    outport(PIOCB, 0xff);\n"
    "    outport(PIOCB, 0x00);\n"
    "    outport(PIODB, 0x18);\n"
    "    outport(PIODB, 0x00);\n"
    "}\n";

// A at the centre facing north, the beacon 5 ft ahead. Body radius
// 12.75 / 24 = 0.53125 ft: the ball leaves from y = 0.53125 and meets the
// beacon's body at y = 5 - 0.53125 = 4.46875 after 3.9375 ft, which at
// 105 ft/s is 0.0375 s = 345,600 ticks exactly; its height then is
// 1.5 - 32.174 / 2 x 0.0375^2 = 1.477378... ft, below the 2.5-ft target.
TEST(Trace, BallRecordsDrawTheFlightAndSayWhatItHit) {
  const Traced t = run(duel(kShootOnce, {0, 0, 0}, {0, 5, 0}, 1));
  const auto launches = t.all<rec::BallLaunch>();
  ASSERT_EQ(launches.size(), 1u);
  const auto& [t0, launch] = launches[0];
  EXPECT_EQ(launch.gun, 0);
  EXPECT_NEAR(launch.x_ft, 0.0, 1e-12);
  EXPECT_NEAR(launch.y_ft, 0.53125, 1e-12);
  EXPECT_DOUBLE_EQ(launch.z_ft, 1.5);
  EXPECT_NEAR(launch.vx_fps, 0.0, 1e-12);
  EXPECT_NEAR(launch.vy_fps, 105.0, 1e-12);
  const auto hits = t.all<rec::BallHit>();
  ASSERT_EQ(hits.size(), 1u);
  const auto& [t1, hit] = hits[0];
  EXPECT_EQ(hit.ball, launch.ball);
  EXPECT_EQ(hit.target, 1);
  EXPECT_EQ(hit.hit, "robot");
  EXPECT_GE(t1 - t0, 345'600);
  EXPECT_LE(t1 - t0, 345'601);
  EXPECT_NEAR(hit.y_ft, 4.46875, 2e-5);  // within one tick of travel (1.1e-5 ft)
  EXPECT_NEAR(hit.z_ft, 1.5 - 32.174 / 2 * 0.0375 * 0.0375, 1e-6);
  EXPECT_TRUE(t.all<rec::BallMiss>().empty());
}

// The beacon 1.5 ft to the side of the line of fire, 5 ft up the field: the
// ball passes it at a horizontal distance 1.5 - 0.53125 = 0.96875 ft from
// its body (at a height of about 1.47 ft, within the body's 2.5 ft), then
// flies on out of the field over the north wall.
TEST(Trace, AMissSaysWhereAndHowCloseItCame) {
  const Traced t = run(duel(kShootOnce, {0, 0, 0}, {1.5, 5, 0}, 1));
  const auto misses = t.all<rec::BallMiss>();
  ASSERT_EQ(misses.size(), 1u);
  const rec::BallMiss& miss = misses[0].second;
  EXPECT_EQ(miss.hit, "wall");
  ASSERT_TRUE(miss.closest_ft.has_value());
  EXPECT_NEAR(*miss.closest_ft, 0.96875, 1e-6);
  EXPECT_GE(miss.y_ft, 8.0);
  // Solo: there is no target, so no closest distance.
  const Traced alone = run(solo(kShootOnce, 1));
  const auto lone = alone.all<rec::BallMiss>();
  ASSERT_EQ(lone.size(), 1u);
  EXPECT_FALSE(lone[0].second.closest_ft.has_value());
}

// Drives forward at speed 8 (0.8 ft/s, thesis-1997) until something stops it.
const char* kDriveForward =
    "char buf[9];\n"
    "char cc;\n"
    "main()\n"
    "{\n"
    "    ser_init_z1(0, 9600/1200);\n"
    "    strcpy(buf, \"8fgr8fgr\");\n"
    "    cc = sizeof(buf);\n"
    "    ser_send_z1(buf, &cc);\n"
    "    while (1);\n"
    "}\n";

TEST(Trace, ContactsSayWhatTheBodyTouched) {
  struct Case {
    plant::Pose start;
    const char* with;
  } cases[] = {
      {{0, 6.5, 0}, "wall"},        // north, 1.5 ft from the wall
      {{-1.5, -6, 90}, "divider"},  // east, towards the divider at x = 0
  };
  for (const auto& k : cases) {
    auto c = solo(kDriveForward, 4);
    c.arena.robots[0].start = k.start;
    const Traced t = run(c);
    const auto contacts = t.all<rec::Contact>();
    ASSERT_FALSE(contacts.empty()) << k.with;
    EXPECT_EQ(contacts[0].second.with, k.with);
    EXPECT_EQ(contacts[0].second.bumper, "front");
    const auto ends = t.all<rec::ContactEnd>();
    ASSERT_FALSE(ends.empty()) << k.with;
    EXPECT_EQ(ends[0].second.with, k.with);
  }
  // Into a beacon 2 ft ahead: both robots touch the other robot; the
  // beacon (facing the same way) is hit from behind.
  const Traced t = run(duel(kDriveForward, {0, 0, 0}, {0, 2, 0}, 4));
  const auto a = t.all<rec::Contact>(0), b = t.all<rec::Contact>(1);
  ASSERT_FALSE(a.empty());
  ASSERT_FALSE(b.empty());
  EXPECT_EQ(a[0].second.with, "robot");
  EXPECT_EQ(a[0].second.bumper, "front");
  EXPECT_EQ(b[0].second.with, "robot");
  EXPECT_EQ(b[0].second.bumper, "back");
}

// Records reach the sinks in tick order, begin with the set-up and end
// with the result; the JSONL form reads back to the same JSON.
TEST(Trace, RecordsAreInTickOrderAndReadBack) {
  scheduler::MatchConfig c;
  c.arena = config::makeArenaConfig(profile("default"), 2);
  const std::string iceman = SIMBOT_SHARED_DIR "/programs/iceman.dc";
  const std::string fig92 = SIMBOT_SHARED_DIR "/programs/fig92.dc";
  auto read = [](const std::string& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  };
  c.robots.push_back({"A", iceman, testkit::compileOrDie(read(iceman), iceman)});
  c.robots.push_back({"B", fig92, testkit::compileOrDie(read(fig92), fig92)});
  c.endTick = 10 * scheduler::kTicksPerSecond;
  c.watches = {"count"};
  const Traced t = run(c);
  ASSERT_GT(t.entries.size(), 1000u);
  EXPECT_TRUE(std::holds_alternative<rec::Run>(t.entries[0].record));
  EXPECT_TRUE(std::holds_alternative<rec::RobotSetup>(t.entries[1].record));
  EXPECT_TRUE(std::holds_alternative<rec::RobotSetup>(t.entries[2].record));
  EXPECT_TRUE(std::holds_alternative<rec::End>(t.entries.back().record));
  EXPECT_EQ(std::get<rec::RobotSetup>(t.entries[1].record).source.substr(0, 2), "/*");
  for (size_t i = 1; i < t.entries.size(); ++i) ASSERT_LE(t.entries[i - 1].t, t.entries[i].t) << i;
  bool watched = false;
  for (const auto& e : t.entries) {
    const nlohmann::json j = sinks::traceJson(e);
    EXPECT_EQ(sinks::traceJson(sinks::traceEntry(j)), j);
    watched = watched || (trace::robotOf(e.record) == 0 && j.contains("watch"));
  }
  EXPECT_TRUE(watched);  // ICEMAN has a global `count`
}

TEST(Trace, BytesReadBackExactly) {
  trace::Entry e{7, rec::Console{0, std::string("\xff\x01 ok\x80", 6)}, {}};
  const std::string line = sinks::traceLine(e);
  EXPECT_NE(line.find("\"text\":\"\xc3\xbf\\u0001 ok\xc2\x80\""), std::string::npos) << line;
  const trace::Entry back = sinks::traceEntry(nlohmann::json::parse(line));
  EXPECT_EQ(std::get<rec::Console>(back.record).text, std::string("\xff\x01 ok\x80", 6));
  // A file name that is not UTF-8 is written as Latin-1 instead of failing.
  trace::Entry f{0, rec::Fault{0, std::string("bad \xff name"), 3}, {}};
  EXPECT_NO_THROW(sinks::traceLine(f));
}

// The manual lists the record kinds as trace/records.def defines them.
TEST(Trace, TheManualListsTheRecordKindsOfTheDefinition) {
  std::ifstream in(SIMBOT_SOURCE_DIR "/docs/trace.md");
  std::stringstream text;
  text << in.rdbuf();
  const std::string readme = text.str();
  const std::string begin = "<!-- trace-records:begin -->\n", end = "<!-- trace-records:end -->";
  const auto from = readme.find(begin), to = readme.find(end);
  ASSERT_NE(from, std::string::npos) << "docs/trace.md has no " << begin;
  ASSERT_NE(to, std::string::npos) << "docs/trace.md has no " << end;
  EXPECT_EQ(readme.substr(from + begin.size(), to - from - begin.size()), trace::recordsMarkdown())
      << "docs/trace.md's record list differs from trace/records.def; it should read:\n"
      << trace::recordsMarkdown();
}

}  // namespace
