// simbot explain (reports/explain.h), checked against the raw trace records
// with the geometry computed here, independently of the report's code.
#include "reports/explain.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <string>
#include <tuple>

#include "batch/bench_metrics.h"
#include "config/config.h"
#include "plant/plant.h"
#include "reports/stall.h"
#include "runs/play.h"
#include "scheduler/match.h"
#include "sinks/trace_jsonl.h"
#include "sinks/user_error.h"
#include "support/records.h"
#include "support/test_host.h"

using namespace simbot;
namespace rec = trace::rec;
namespace ex = reports::explain;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTps = static_cast<double>(scheduler::kTicksPerSecond);

scheduler::MatchConfig config(const std::vector<std::string>& programs, double seconds,
                              const std::string& profile = "default") {
  scheduler::MatchConfig c;
  c.arena = config::makeArenaConfig(
      config::loadProfile(SIMBOT_SOURCE_DIR "/profiles/" + profile + ".toml"),
      static_cast<int>(programs.size()));
  c.profileName = profile;
  const char* names[] = {"A", "B"};
  for (size_t i = 0; i < programs.size(); ++i)
    c.robots.push_back({names[i], programs[i], runs::compileProgramFile(programs[i])});
  c.endTick = timebase::ticksFromSeconds(seconds);
  c.seed = 1;
  return c;
}

struct Traced {
  std::vector<trace::Entry> entries;
  ex::Report report;
  trace::Tick benchStallTicks = 0;  // simbot bench's stall_s of robot A, in ticks
  template <class R>
  std::vector<std::pair<trace::Tick, R>> all(int robot = -1) const {
    return testkit::recordsOf<R>(entries, robot);
  }
};

Traced run(scheduler::MatchConfig c) {
  trace::Collector collector;
  ex::Explainer explainer;
  batch::MetricsObserver bench;  // simbot bench's measurements of A
  c.sinks.push_back(&collector);
  c.sinks.push_back(&explainer);
  c.observer = &bench;
  scheduler::runMatch(c);
  bench.finish(c.endTick);
  return {std::move(collector.entries), explainer.report(), bench.stallTicks};
}

// The 180-s match of the issue, run once for all the tests here (~1 s).
// Seed 15: one of the default profile's seeds (its hand placement, trims and
// eye noise) in which ICEMAN meets thesis chapter X's one-eye dead-lock.
const Traced& icemanVsFig92() {
  static const Traced r = [] {
    auto c = config(
        {SIMBOT_SHARED_DIR "/programs/iceman.dc", SIMBOT_SHARED_DIR "/programs/fig92.dc"}, 180);
    c.seed = 15;
    return run(c);
  }();
  return r;
}

// Degrees in (-180, 180].
double wrap(double d) {
  while (d > 180) d -= 360;
  while (d <= -180) d += 360;
  return d;
}

TEST(Explain, IcemanShotsAgainstTheTraceRecords) {
  const Traced& r = icemanVsFig92();
  const auto launches = r.all<rec::BallLaunch>();
  const auto hits = r.all<rec::BallHit>();
  const auto misses = r.all<rec::BallMiss>();
  const auto results = r.all<rec::RobotResult>(0);
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].second.shots, 30);
  ASSERT_EQ(launches.size(), 30u);
  ASSERT_EQ(r.report.shots.size(), 30u);
  // Independently: the first ball_hit or ball_miss with the same ball number
  // after each launch ends it; a miss's distance is its closest_ft.
  int hitCount = 0;
  for (size_t i = 0; i < launches.size(); ++i) {
    // Not a structured binding: clang 14 (the sanitizer build's) cannot
    // capture one in the lambda below.
    const auto& t = launches[i].first;
    const auto& launch = launches[i].second;
    const ex::Shot& shot = r.report.shots[i];
    EXPECT_EQ(shot.t, t);
    EXPECT_EQ(shot.robot, 0);
    EXPECT_DOUBLE_EQ(shot.muzzle_fps, std::hypot(launch.vx_fps, launch.vy_fps, launch.vz_fps));
    auto ball = [&](const auto& e) { return e.first >= t && e.second.ball == launch.ball; };
    const auto hit = std::find_if(hits.begin(), hits.end(), ball);
    const auto miss = std::find_if(misses.begin(), misses.end(), ball);
    const bool isHit = hit != hits.end() && (miss == misses.end() || hit->first <= miss->first);
    EXPECT_EQ(shot.hit, isHit);
    if (isHit) {
      ++hitCount;
      EXPECT_EQ(*shot.end_t, hit->first);
      EXPECT_FALSE(shot.miss_ft);
    } else {
      ASSERT_NE(miss, misses.end());
      ASSERT_TRUE(shot.miss_ft && miss->second.closest_ft);
      EXPECT_EQ(*shot.miss_ft, *miss->second.closest_ft);
      EXPECT_EQ(shot.ended, miss->second.hit);
    }
  }
  EXPECT_EQ(hitCount, results[0].second.hits);
}

// One shot's range and bearing error, from the records: the shooter's
// heading h is the launch record's heading_deg (the ball's velocity is
// turned from it by the gun's dispersion, so it is not the aim), and its
// centre is the muzzle less a body radius along it, C = M - (d / 2)
// (sin h, cos h) (the muzzle is flush with the body edge); the
// target's centre at the launch tick t is interpolated linearly between its
// samples at t0 <= t < t1: P = P0 + (t - t0) / (t1 - t0) (P1 - P0). Then
// range = |P - C| and bearing error = atan2(Px - Cx, Py - Cy) - h, wrapped
// to (-180, 180] (+ = target to the right).
TEST(Explain, OneShotsRangeAndBearingFromThePoses) {
  const Traced& r = icemanVsFig92();
  const auto launches = r.all<rec::BallLaunch>();
  const auto setups = r.all<rec::RobotSetup>();
  const auto targetSamples = r.all<rec::Sample>(1);
  const auto shooterSamples = r.all<rec::Sample>(0);
  ASSERT_EQ(setups.size(), 2u);
  const double radius = setups[0].second.body_diameter_ft / 2;
  // The seventh launch (any would do).
  const auto& [t, launch] = launches[6];
  const double heading = launch.heading_deg;
  const double cx = launch.x_ft - radius * std::sin(heading * kPi / 180);
  const double cy = launch.y_ft - radius * std::cos(heading * kPi / 180);
  size_t k = 0;
  while (k + 1 < targetSamples.size() && targetSamples[k + 1].first <= t) ++k;
  ASSERT_LT(k + 1, targetSamples.size());
  const auto& [t0, p0] = targetSamples[k];
  const auto& [t1, p1] = targetSamples[k + 1];
  ASSERT_LE(t0, t);
  ASSERT_GT(t1, t);
  const double f = static_cast<double>(t - t0) / static_cast<double>(t1 - t0);
  const double px = p0.x_ft + f * (p1.x_ft - p0.x_ft), py = p0.y_ft + f * (p1.y_ft - p0.y_ft);
  const double range = std::hypot(px - cx, py - cy);
  const double bearing = wrap(std::atan2(px - cx, py - cy) * 180 / kPi - heading);

  const ex::Shot& shot = r.report.shots[6];
  ASSERT_TRUE(shot.range_ft && shot.bearing_error_deg);
  EXPECT_NEAR(*shot.range_ft, range, 1e-9);
  EXPECT_NEAR(*shot.bearing_error_deg, bearing, 1e-9);
  // The shooter's own samples agree with the centre and heading taken from
  // the launch (within 50 ms of motion).
  size_t j = 0;
  while (j + 1 < shooterSamples.size() && shooterSamples[j + 1].first <= t) ++j;
  EXPECT_NEAR(shooterSamples[j].second.x_ft, cx, 0.2);
  EXPECT_NEAR(shooterSamples[j].second.y_ft, cy, 0.2);
  EXPECT_NEAR(wrap(shooterSamples[j].second.heading_deg - heading), 0, 5);
  // A sanity bound: inside the 16-ft field, and aimed roughly at it.
  EXPECT_GT(range, 1);
  EXPECT_LT(range, 23);
  EXPECT_LT(std::abs(bearing), 90);
}

// Stalls recomputed from the records, with the rule of reports/stall.h
// written out again here: ICEMAN's latest reading of either eye (its
// ad_read records: one whenever a reading differs from that eye's previous
// one) above 48 means it sees fig92; it stands still from a sample whose
// centre is within 0.02 ft/s times the 0.05 s since the previous sample
// (0.001 ft) of that sample's, and moves from one further; a fault or exit
// halts it, a reload resumes it with nothing read. A window opens when it
// sees, stands still and runs; it closes at the next latch (reopening there
// if all still hold), when one of them ends, or at the end; windows longer
// than 1 s (9,216,000 ticks) are the stalls. simbot bench's stall_s,
// measured on line by its observer during the same run, is their total.
std::vector<std::pair<trace::Tick, trace::Tick>> stallsFromRecords(
    const std::vector<trace::Entry>& entries, int robot) {
  std::vector<std::pair<trace::Tick, trace::Tick>> want;
  int left = -1, right = -1;  // no reading yet
  bool still = true, halted = false;
  std::optional<std::tuple<trace::Tick, double, double>> lastPose;
  trace::Tick opened = -1;  // -1: no window open
  auto close = [&](trace::Tick to) {
    if (opened >= 0 && to - opened > scheduler::kTicksPerSecond) want.emplace_back(opened, to);
    opened = -1;
  };
  auto check = [&](trace::Tick t) {
    if ((left > 48 || right > 48) && still && !halted) {
      if (opened < 0) opened = t;
    } else {
      close(t);
    }
  };
  for (const auto& e : entries) {
    const trace::Tick t = e.t;
    if (const auto* read = std::get_if<rec::AdRead>(&e.record); read && read->robot == robot) {
      if (read->channel > 1) continue;
      (read->channel == 0 ? left : right) = static_cast<int>(read->value);
      check(t);
    } else if (const auto* latch = std::get_if<rec::FrameLatched>(&e.record);
               latch && latch->robot == robot) {
      close(t);
      check(t);
    } else if (const auto* s = std::get_if<rec::Sample>(&e.record); s && s->robot == robot) {
      if (lastPose) {
        const auto [t0, x0, y0] = *lastPose;
        still = std::hypot(s->x_ft - x0, s->y_ft - y0) <= 0.02 * static_cast<double>(t - t0) / kTps;
      }
      lastPose = std::make_tuple(t, s->x_ft, s->y_ft);
      check(t);
    } else if (const auto* f = std::get_if<rec::Fault>(&e.record); f && f->robot == robot) {
      halted = true;
      check(t);
    } else if (const auto* x = std::get_if<rec::Exit>(&e.record); x && x->robot == robot) {
      halted = true;
      check(t);
    } else if (const auto* l = std::get_if<rec::Reload>(&e.record); l && l->robot == robot) {
      halted = false;
      left = right = -1;
      check(t);
    }
  }
  close(entries.back().t);
  return want;
}

// Thesis chapter X: the one-eye dead-lock (one eye at background, 16, the
// other above ICEMAN's own threshold: `if (x>48 && y>48)`, one eye past 48
// is not enough to move) is a stall once the robot stands still. Seed 28
// has one from 131.059 s, on ICEMAN's stop command (its motors' lag has
// decayed: it stands still), with the program in fire()'s delay loops.
// (Seed 10's from 55.627 s moved with issue 38's RETI timing, which
// changes every match a little: the Z80180's RETI is 10 T-states longer.
// Seed 15's window at 3.194..4.308 s, which the old rule called a one-eye
// stall, is none: ICEMAN drove 1.36 ft through it under cfgrcfgr.)
TEST(Explain, TheOneEyeDeadLockIsAStall) {
  auto c = config({SIMBOT_SHARED_DIR "/programs/iceman.dc", SIMBOT_SHARED_DIR "/programs/fig92.dc"},
                  180);
  c.seed = 28;
  const Traced r = run(c);
  EXPECT_EQ(stallsFromRecords(r.entries, 0).size(),
            static_cast<size_t>(std::count_if(r.report.stalls.begin(), r.report.stalls.end(),
                                              [](const ex::Stall& s) { return s.robot == 0; })));
  const ex::Stall* oneEye = nullptr;
  for (const auto& s : r.report.stalls)
    if (s.robot == 0 && s.one_eye && s.eye_left_median == 16) oneEye = &s;
  ASSERT_NE(oneEye, nullptr);
  EXPECT_GT(oneEye->from / kTps, 131.0);
  EXPECT_LT(oneEye->from / kTps, 132.0);
  EXPECT_GT(oneEye->eye_right_median, 48);
  ASSERT_FALSE(oneEye->lines.empty());
  EXPECT_EQ(oneEye->lines[0].function, "fire");
  EXPECT_NE(ex::text(r.report).find("one-eye dead-lock"), std::string::npos);
}

TEST(Explain, IcemanStallsAgainstTheRecords) {
  const Traced& r = icemanVsFig92();
  const auto want = stallsFromRecords(r.entries, 0);
  std::vector<std::pair<trace::Tick, trace::Tick>> got;
  trace::Tick total = 0;
  for (const auto& s : r.report.stalls)
    if (s.robot == 0) {
      got.emplace_back(s.from, s.to);
      total += s.to - s.from;
    }
  EXPECT_EQ(got, want);
  EXPECT_FALSE(want.empty());
  EXPECT_EQ(r.benchStallTicks, total);

  const std::string text = ex::text(r.report);
  EXPECT_NE(text.find("Shots (30)"), std::string::npos);
  EXPECT_NE(ex::markdown(r.report).find("## Shots (30)"), std::string::npos);
}

// The same report from the JSONL file as from the records; bad files are one
// FILE:LINE: error: line.
TEST(Explain, FromTheJsonlFile) {
  const Traced& r = icemanVsFig92();
  const std::string path = ::testing::TempDir() + "explain_test.jsonl";
  {
    sinks::JsonlSink sink(path);
    for (const auto& e : r.entries) sink.write(e);
    sink.close();
  }
  EXPECT_EQ(ex::text(ex::explainFile(path)), ex::text(r.report));
  EXPECT_EQ(ex::json(ex::explainFile(path)), ex::json(r.report));
  const auto onlyB = ex::onlyRobot(r.report, 1);
  EXPECT_TRUE(onlyB.shots.empty());
  EXPECT_TRUE(onlyB.stalls.empty() || onlyB.stalls[0].robot == 1);

  const std::string bad = ::testing::TempDir() + "explain_bad.jsonl";
  {
    std::ofstream out(bad);
    out << sinks::traceLine(r.entries[0]) << "\n{\"type\": \"sample\"\n";
  }
  try {
    ex::explainFile(bad);
    FAIL() << "a malformed trace must be an error";
  } catch (const sinks::UserError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(bad + ":2: error: ", 0), 0u) << e.what();
  }
  std::remove(path.c_str());
  std::remove(bad.c_str());
}

// A send that restarts the previous one: the first frame never latches.
TEST(Explain, OverwrittenSend) {
  const std::string source =
      "#include \"serial.lib\"\n"
      "char buf[9];\n"
      "char cc;\n"
      "main()\n"
      "{\n"
      "int i;\n"
      "  ser_init_z1(0, 9600/1200);\n"
      "  for (i = 0; i < 5000; i++);\n"
      "  outport(ENB485, 1);\n"
      "  strcpy(buf, \"cfgrcfgr\");\n"
      "  cc = sizeof(buf);\n"
      "  ser_send_z1(buf, &cc);\n"
      "  strcpy(buf, \"8fgr8rgr\");\n"
      "  cc = sizeof(buf);\n"
      "  ser_send_z1(buf, &cc);\n"
      "}\n";
  scheduler::MatchConfig c;
  c.arena = config::makeArenaConfig(
      config::loadProfile(SIMBOT_SOURCE_DIR "/profiles/thesis-1997.toml"), 1);
  c.robots.push_back({"A", "twice.dc", testkit::compileOrDie(source)});
  c.endTick = scheduler::kTicksPerSecond / 2;  // 0.5 s
  const Traced r = run(c);
  const auto sends = r.all<rec::SerialSend>(0);
  const auto latched = r.all<rec::FrameLatched>(0);
  ASSERT_EQ(sends.size(), 2u);
  // Only the second frame reaches the controller.
  ASSERT_EQ(latched.size(), 1u);
  EXPECT_EQ(latched[0].second.bytes, "8fgr8rgr");
  ASSERT_EQ(r.report.overwritten.size(), 1u);
  const auto& o = r.report.overwritten[0];
  EXPECT_EQ(o.t, sends[1].first);
  EXPECT_EQ(o.previous_t, sends[0].first);
  EXPECT_EQ(o.previous_count, 9);
  // The second send comes less than a character time (9,600 ticks) after
  // the first, so the port has taken two bytes of it: buf[0], which the
  // library loaded itself and went straight to the idle shift register,
  // and buf[1], which the first transmit interrupt put in the TDR, full
  // until buf[0] is out.
  ASSERT_LT(sends[1].first - sends[0].first, 9600);
  EXPECT_EQ(o.previous_bytes_fetched, 2);
  // The sends' own lines (12 and 15 of the source above), not where a
  // sample last found the program.
  EXPECT_EQ(o.send.line, 15);
  EXPECT_EQ(o.send.function, "main");
  EXPECT_EQ(o.send.caller_line, 0);
  EXPECT_EQ(o.previous.line, 12);
  EXPECT_EQ(o.previous.function, "main");
  // The trace records it at the new send, as the report does.
  const auto records = r.all<rec::FrameOverwritten>(0);
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0].first, sends[1].first);
  EXPECT_EQ(records[0].second.previous_t, sends[0].first);
  EXPECT_EQ(records[0].second.previous_count, 9);
  EXPECT_EQ(records[0].second.fetched, 2);
  EXPECT_EQ(records[0].second.line, 15);
  EXPECT_EQ(records[0].second.previous_line, 12);
  // Solo: no opponent, so no range, no stall.
  EXPECT_TRUE(r.report.stalls.empty());
}

// tests/programs/send_twice.dc sends three pairs back to back (its header
// works the lines out): line 27 overwrites line 24 in main(); platform()'s
// send on line 45 called from main line 33 overwrites it called from line
// 31; and called from main line 37 overwrites it called from line 51 in
// spin() (main line 36). explain names each send with its caller, in the
// text, the JSON and from the JSONL file alike.
TEST(Explain, NamesBothSendsAndTheirCallers) {
  auto c = config({SIMBOT_SOURCE_DIR "/tests/programs/send_twice.dc"}, 0.5, "thesis-1997");
  const Traced r = run(c);
  ASSERT_EQ(r.all<rec::SerialSend>(0).size(), 6u);
  // Each pair's second frame latches, its first never does.
  const auto latched = r.all<rec::FrameLatched>(0);
  ASSERT_EQ(latched.size(), 3u);
  EXPECT_EQ(latched[0].second.bytes, "8fgr8rgr");
  EXPECT_EQ(latched[1].second.bytes, "afgrargr");
  EXPECT_EQ(latched[2].second.bytes, "4fgr4rgr");
  struct Want {
    int line;
    const char* function;
    int callerLine;
    const char* callerFunction;
    const char* calls;
  };
  const Want sends[3][2] = {// {the send that overwrote, the send overwritten}
                            {{27, "main", 0, "", "main:27"}, {24, "main", 0, "", "main:24"}},
                            {{45, "platform", 33, "main", "main:33 > platform:45"},
                             {45, "platform", 31, "main", "main:31 > platform:45"}},
                            {{45, "platform", 37, "main", "main:37 > platform:45"},
                             {45, "platform", 51, "spin", "main:36 > spin:51 > platform:45"}}};
  auto expectSite = [](const ex::SendSite& got, const Want& want, const std::string& what) {
    EXPECT_EQ(got.line, want.line) << what;
    EXPECT_EQ(got.function, want.function) << what;
    EXPECT_EQ(got.caller_line, want.callerLine) << what;
    EXPECT_EQ(got.caller_function, want.callerFunction) << what;
    EXPECT_EQ(got.calls, want.calls) << what;
  };
  ASSERT_EQ(r.report.overwritten.size(), 3u);
  ASSERT_EQ(r.report.overwrite_groups.size(), 3u);
  for (size_t k = 0; k < 3; ++k) {
    const std::string pair = "pair " + std::to_string(k + 1);
    expectSite(r.report.overwritten[k].send, sends[k][0], pair + ", the send");
    expectSite(r.report.overwritten[k].previous, sends[k][1], pair + ", the send overwritten");
    EXPECT_TRUE(r.report.overwritten[k].handler.empty());
    // One of each pair: the groups keep the order they first happened in.
    const ex::OverwriteGroup& g = r.report.overwrite_groups[k];
    EXPECT_EQ(g.count, 1);
    EXPECT_EQ(g.first, r.report.overwritten[k].t);
    expectSite(g.send, sends[k][0], pair + ", its group");
    expectSite(g.previous, sends[k][1], pair + ", its group");
  }
  const std::string text = ex::text(r.report);
  for (const char* line :
       {"  A: 1 send from line 27 in main() overwrote the send from line 24 in main(); ",
        "  A: 1 send from line 45 in platform() (called from line 33 in main()) overwrote the "
        "send from line 45 in platform() (called from line 31 in main()); ",
        "  A: 1 send from line 45 in platform() (called from line 37 in main()) overwrote the "
        "send from line 45 in platform() (called from line 51 in spin()); "})
    EXPECT_NE(text.find(line), std::string::npos) << line << "\nin\n" << text;
  const nlohmann::json j = ex::json(r.report);
  EXPECT_EQ(j["overwritten_sends"][2]["caller_line"], 37);
  EXPECT_EQ(j["overwritten_sends"][2]["previous_caller_function"], "spin");
  EXPECT_EQ(j["overwritten_sends"][2]["previous_calls"], "main:36 > spin:51 > platform:45");
  EXPECT_EQ(j["overwrite_groups"][1]["count"], 1);
  // The JSONL trace reads back to the same report.
  const std::string path = ::testing::TempDir() + "explain_send_twice.jsonl";
  {
    sinks::JsonlSink sink(path);
    for (const auto& e : r.entries) sink.write(e);
    sink.close();
  }
  EXPECT_EQ(ex::text(ex::explainFile(path)), text);
  std::remove(path.c_str());
}

// Overwritten sends group by robot and the two sends' sites, the most
// frequent first, whatever the order they came in: from hand-made records
// (ticks apart, so each frame_overwritten follows its own serial_send).
TEST(Explain, OverwrittenSendsGroupByTheirTwoLines) {
  ex::Explainer e;
  rec::Run run;
  run.robots = 1;
  run.ticks_per_second = scheduler::kTicksPerSecond;
  e.write({0, run, {}});
  auto overwrite = [&](trace::Tick t, int line, int callerLine) {
    const std::string calls =
        "main:" + std::to_string(callerLine) + " > platform:" + std::to_string(line);
    e.write({t, rec::SerialSend{0, 9, line, "platform", callerLine, "main", calls}, {}});
    e.write({t,
             rec::FrameOverwritten{0, t - 100, 9, 2, line, "platform", callerLine, "main", line,
                                   "platform", 66, "main"},
             {}});
  };
  overwrite(1000, 78, 71);
  overwrite(2000, 78, 93);
  overwrite(3000, 78, 71);
  overwrite(4000, 78, 71);
  const ex::Report r = e.report();
  ASSERT_EQ(r.overwritten.size(), 4u);
  ASSERT_EQ(r.overwrite_groups.size(), 2u);
  EXPECT_EQ(r.overwrite_groups[0].count, 3);
  EXPECT_EQ(r.overwrite_groups[0].send.caller_line, 71);
  EXPECT_EQ(r.overwrite_groups[0].previous.caller_line, 66);
  EXPECT_EQ(r.overwrite_groups[0].first, 1000);
  EXPECT_EQ(r.overwrite_groups[0].last, 4000);
  EXPECT_EQ(r.overwrite_groups[0].send.calls, "main:71 > platform:78");
  EXPECT_EQ(r.overwrite_groups[1].count, 1);
  EXPECT_EQ(r.overwrite_groups[1].send.caller_line, 93);
  // The overwritten send's chain is known only from its own serial_send
  // record, which these hand-made ones leave out.
  EXPECT_EQ(r.overwritten[0].previous.calls, "");
  EXPECT_NE(ex::text(r).find("  A: 3 sends from line 78 in platform() (called from line 71 in "
                             "main()) overwrote the send from line 78 in platform() (called from "
                             "line 66 in main())"),
            std::string::npos)
      << ex::text(r);
}

// An injected edge runs ICEMAN's handler: its run is acceptance to RETI,
// with the frames latched in between.
TEST(Explain, HandlerRunFromAnInjectedEdge) {
  auto c = config({SIMBOT_SHARED_DIR "/programs/iceman.dc"}, 12);
  c.injections.push_back(config::parseInjection("A:edge_fore@5s", 1));
  const Traced r = run(c);
  const auto accepted = r.all<rec::InterruptAccepted>(0);
  const auto returned = r.all<rec::InterruptReturned>(0);
  ASSERT_FALSE(accepted.empty());
  ASSERT_FALSE(returned.empty());
  ASSERT_FALSE(r.report.handler_runs.empty());
  const ex::HandlerRun& h = r.report.handler_runs[0];
  EXPECT_EQ(h.from, accepted[0].first);
  ASSERT_TRUE(h.to);
  EXPECT_EQ(*h.to, returned[0].first);
  EXPECT_EQ(h.handler, accepted[0].second.handler);
  std::vector<std::string> frames;
  for (const auto& [t, f] : r.all<rec::FrameLatched>(0))
    if (t >= h.from && t <= *h.to) frames.push_back(f.bytes);
  EXPECT_EQ(h.frames, frames);
  EXPECT_FALSE(frames.empty());
  ASSERT_FALSE(r.report.handler_totals.empty());
  // The total is every run of the handler: within the 12 s ICEMAN may also
  // reach the wire itself (with the issue-11 cycle model it does, at about
  // 9 s, and that run is as long as the injected one).
  trace::Tick total = 0;
  for (const auto& run : r.report.handler_runs)
    if (run.robot == 0 && run.handler == h.handler && run.to) total += *run.to - run.from;
  EXPECT_EQ(r.report.handler_totals[0].total, total);
}

// Two robots 4 ft apart on the field's south-west, A facing B (east), so
// that A's eyes see B from the start: no search, no divider between them.
Traced facing(const std::string& a, const std::string& b, double seconds, bool reload = false) {
  auto c = config({a, b}, seconds);
  c.arena.robots[0].start = {-6.0, -2.0, 90.0};
  c.arena.robots[1].start = {-2.0, -2.0, 270.0};
  c.reloadOnFault = reload;
  c.reloadDelay = scheduler::kTicksPerSecond / 2;
  return run(c);
}

trace::Tick stallTotal(const ex::Report& r, int robot) {
  trace::Tick total = 0;
  for (const auto& s : r.stalls)
    if (s.robot == robot) total += s.to - s.from;
  return total;
}

// Issue 25: a robot that drives slowly (speed step 1, 0.05 ft/s, a frame
// latched once) while it sees the opponent is not stalled; under the rule
// without movement (any speed still) the same records are one stall from
// the latch to the end.
TEST(Explain, SlowSteadyDriveWhileSeeingIsNoStall) {
  const Traced r = facing(SIMBOT_SOURCE_DIR "/tests/explain/slow_drive.dc",
                          SIMBOT_SOURCE_DIR "/tests/explain/slow_drive.dc", 20);
  const auto samples = r.all<rec::Sample>(0);
  ASSERT_GT(samples.size(), 100u);
  // Hand computation: 0.05 ft/s for about 20 s less the motor lag: ~1 ft.
  const double moved = std::hypot(samples.back().second.x_ft - samples.front().second.x_ft,
                                  samples.back().second.y_ft - samples.front().second.y_ft);
  EXPECT_GT(moved, 0.8);
  EXPECT_LT(moved, 1.1);
  bool sees = false;
  for (const auto& [t, x] : r.all<rec::AdRead>(0)) sees = sees || (x.channel < 2 && x.value > 48);
  EXPECT_TRUE(sees);
  EXPECT_EQ(r.all<rec::FrameLatched>(0).size(), 1u);
  EXPECT_EQ(stallTotal(r.report, 0), 0);
  EXPECT_EQ(r.benchStallTicks, 0);
  EXPECT_TRUE(stallsFromRecords(r.entries, 0).empty());
  // The rule without movement: a window from the latch to the end.
  reports::StallWatch old(reports::StallRule{.still_fps = 1e9});
  for (const auto& e : r.entries) {
    if (const auto* x = std::get_if<rec::AdRead>(&e.record); x && x->robot == 0)
      old.eyeRead(e.t, static_cast<int>(x->channel), static_cast<int>(x->value));
    if (const auto* x = std::get_if<rec::FrameLatched>(&e.record); x && x->robot == 0)
      old.frameLatched(e.t);
  }
  old.finish(r.entries.back().t);
  EXPECT_GT(old.total(), 15 * scheduler::kTicksPerSecond);
}

// Issue 25: a robot that stands still seeing the opponent and then faults
// (stack overflow) has its stall end at the fault's tick and none after it
// (20 s run); bench's stall_s agrees to the tick. The fault names its call
// chain: main's call of deep() (line 30) and deep()'s calls of itself
// (line 15), one entry per call under way, so the repeat count is the depth
// less main's call, or the depth itself when the faulting instruction is
// the call on line 15 (counted in the repeat, not in the depth).
TEST(Explain, NoStallAfterAFaultAndTheFaultsCallChain) {
  const Traced r = facing(SIMBOT_SOURCE_DIR "/tests/explain/stall_then_fault.dc",
                          SIMBOT_SOURCE_DIR "/tests/explain/slow_drive.dc", 20);
  const auto faults = r.all<rec::Fault>(0);
  ASSERT_EQ(faults.size(), 1u);
  const trace::Tick tf = faults[0].first;
  const rec::Fault& f = faults[0].second;
  EXPECT_NE(f.message.find("stack overflow"), std::string::npos) << f.message;
  for (const auto& s : r.report.stalls) {
    if (s.robot == 0) {
      EXPECT_LE(s.to, tf);
    }
  }
  ASSERT_FALSE(r.report.stalls.empty());
  EXPECT_EQ(r.report.stalls.back().robot == 0 ? r.report.stalls.back().to : tf, tf);
  EXPECT_GT(tf, 2 * scheduler::kTicksPerSecond);
  EXPECT_EQ(r.benchStallTicks, stallTotal(r.report, 0));
  trace::Tick want = 0;
  for (const auto& [from, to] : stallsFromRecords(r.entries, 0)) want += to - from;
  EXPECT_EQ(want, r.benchStallTicks);
  // The chain: "main:30 > deep:15 x K", K calls of deep under way.
  const std::string head = "main:30 > deep:15 x ";
  ASSERT_EQ(f.calls.rfind(head, 0), 0u) << f.calls;
  const int k = std::stoi(f.calls.substr(head.size()));
  EXPECT_GT(k, 10);
  EXPECT_TRUE(f.depth == k || f.depth == k + 1) << f.depth << " " << f.calls;
  const std::string text = ex::text(r.report);
  EXPECT_NE(text.find(fmt::format("(line {}; call depth {}: {})", f.line, f.depth, f.calls)),
            std::string::npos)
      << text;
}

// Issue 25: explain reports a reload (when, which fault, when it restarted),
// and the reloaded program's stalls count again (bench agrees).
TEST(Explain, ReportsReloads) {
  const Traced r = facing(SIMBOT_SOURCE_DIR "/tests/explain/stall_then_fault.dc",
                          SIMBOT_SOURCE_DIR "/tests/explain/slow_drive.dc", 20, true);
  const auto faults = r.all<rec::Fault>(0);
  const auto reloads = r.all<rec::Reload>(0);
  ASSERT_GE(faults.size(), 2u);
  ASSERT_GE(reloads.size(), 1u);
  EXPECT_EQ(reloads[0].first - faults[0].first, scheduler::kTicksPerSecond / 2);
  const std::string text = ex::text(r.report);
  const std::string want = fmt::format(
      "A {:.3f} s reloaded (--reload-on-fault, reload 1): main started again 0.500 s after the "
      "fault at {:.3f} s ({})",
      reloads[0].first / kTps, faults[0].first / kTps, faults[0].second.message);
  EXPECT_NE(text.find(want), std::string::npos) << text;
  EXPECT_EQ(r.benchStallTicks, stallTotal(r.report, 0));
  int after = 0;  // stalls between the reload and the second fault
  for (const auto& s : r.report.stalls)
    if (s.robot == 0 && s.from >= reloads[0].first && s.to <= faults[1].first) ++after;
  EXPECT_EQ(after, 1);
}

// A handler that never returns: its run is reported with its time in
// service to the end of the records (hand-made: accepted at 2 s, the last
// record at 5 s: 3.000 s).
TEST(Explain, AHandlerThatNeverReturnsHasItsDuration) {
  ex::Explainer e;
  constexpr trace::Tick s = scheduler::kTicksPerSecond;
  e.write({2 * s, rec::InterruptAccepted{0, "pio_a", 40, "main", "edge"}, {}});
  e.write({5 * s, rec::Console{0, "x"}, {}});
  const std::string text = ex::text(e.report());
  EXPECT_NE(text.find("A 2.000 s edge for 3.000 s (still in service at the end, 5.000 s: it "
                      "never returned)"),
            std::string::npos)
      << text;
}

}  // namespace

// The stall rule itself (reports/stall.h) on hand-made timelines, in ticks
// (1 s = 9,216,000).
// Pushes (plant/arena_blocks.cpp's push_end records) in one sentence each,
// from the record's own fields: "pushed block N D ft, to (X, Y) ft" with D
// to 0.001 ft (a push stopped soon by something is hundredths), X, Y to
// 0.01 ft, then what stopped the block if something did. Records made
// here: A pushes block 1 by 0.8049 ft (0.805) to (-6.4182, -6.7361), a drive's
// end; B pushes block 2 by 0.05 ft to (7.4, 0) where the wall stops it; A
// pushes block 3 0.1251 ft (0.125) into "obstacle 2 (mountain)"; B's push
// of block 1 ends when A touches it (0.004); a block that
// did not fit, with its bit and where.
TEST(Explain, NamesPushesAndBlocks) {
  ex::Explainer e;
  e.write({100, rec::PushStart{0, 1, -7.2231, -6.7361}, {}});
  e.write({200, rec::PushEnd{0, 1, -6.4182, -6.7361, 0.8049, "drive"}, {}});
  e.write({300, rec::PushEnd{1, 2, 7.4, 0.0, 0.05, "wall"}, {}});
  e.write({400, rec::PushEnd{0, 3, 1.0, 2.0, 0.1251, "obstacle 2 (mountain)"}, {}});
  e.write({500, rec::PushEnd{1, 1, -6.4182, -6.7321, 0.004, "robot"}, {}});
  e.write({600, rec::DeployBlocked{1, "block", 2, 2.0, -8.20125}, {}});
  const ex::Report r = e.report();
  ASSERT_EQ(r.course.size(), 5u);
  EXPECT_EQ(r.course[0].what, "pushed block 1 0.805 ft, to (-6.42, -6.74) ft");
  EXPECT_EQ(r.course[0].robot, 0);
  EXPECT_EQ(r.course[0].t, 200);
  EXPECT_EQ(r.course[1].what, "pushed block 2 0.050 ft, to (7.40, 0.00) ft; stopped by the wall");
  EXPECT_EQ(r.course[1].robot, 1);
  EXPECT_EQ(r.course[2].what,
            "pushed block 3 0.125 ft, to (1.00, 2.00) ft; stopped by obstacle 2 (mountain)");
  EXPECT_EQ(r.course[3].what,
            "pushed block 1 0.004 ft, to (-6.42, -6.73) ft; the other robot held it");
  EXPECT_EQ(r.course[4].what, "could not set down a block (bit 2): no room at (2.00, -8.20) ft");
}

TEST(StallWatch, AWindowLongerThanASecondIsAStallCountedWhole) {
  reports::StallWatch w;
  constexpr trace::Tick s = scheduler::kTicksPerSecond;
  EXPECT_FALSE(w.eyeRead(10, 0, 16));  // background: sees nothing
  EXPECT_FALSE(w.windowStart());
  EXPECT_FALSE(w.eyeRead(100, 1, 49));  // one eye above 48: sees
  EXPECT_EQ(w.windowStart(), 100);
  EXPECT_FALSE(w.eyeRead(200, 1, 300));  // still sees: the window runs on
  // A latch 2 s after the window opened ends a stall of 2 s and, still
  // seeing, opens the next window there.
  const auto first = w.frameLatched(100 + 2 * s);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->from, 100);
  EXPECT_EQ(first->to, 100 + 2 * s);
  EXPECT_EQ(w.windowStart(), 100 + 2 * s);
  // Exactly 1 s later the eye falls to 48 (not above): a window of exactly
  // 1 s is not a stall.
  EXPECT_FALSE(w.eyeRead(100 + 3 * s, 1, 48));
  EXPECT_FALSE(w.windowStart());
  // Seeing again from 5 s to the run's end at 6.5 s: a stall of 1.5 s.
  EXPECT_FALSE(w.eyeRead(5 * s, 0, 400));
  const auto last = w.finish(6 * s + s / 2);
  ASSERT_TRUE(last);
  EXPECT_EQ(last->from, 5 * s);
  EXPECT_EQ(last->to, 6 * s + s / 2);
  EXPECT_EQ(w.total(), 2 * s + s + s / 2);
}

// Movement, halts and reloads (hand-made, samples every 0.05 s = 460,800
// ticks; the threshold 0.02 ft/s is 0.001 ft per sample).
TEST(StallWatch, MovingHaltedOrExitedIsNoStall) {
  constexpr trace::Tick s = scheduler::kTicksPerSecond, dt = s / 20;
  reports::StallWatch w;
  EXPECT_FALSE(w.eyeRead(0, 0, 300));  // sees, at rest: opens
  EXPECT_EQ(w.windowStart(), 0);
  EXPECT_FALSE(w.pose(0, 0, 0));
  EXPECT_FALSE(w.pose(dt, 0.0009, 0));  // 0.0009 ft in 0.05 s: 0.018 ft/s, still
  EXPECT_EQ(w.windowStart(), 0);
  // 0.0011 ft more at 2 s: 0.022 ft/s, moving: closes a 2-s stall.
  EXPECT_FALSE(w.pose(2 * s - dt, 0.0009, 0));
  const auto moved = w.pose(2 * s, 0.0020, 0);
  ASSERT_TRUE(moved);
  EXPECT_EQ(moved->to - moved->from, 2 * s);
  EXPECT_FALSE(w.windowStart());
  EXPECT_FALSE(w.pose(2 * s + dt, 0.0020, 0));  // still again: opens there
  EXPECT_EQ(w.windowStart(), 2 * s + dt);
  // A fault at 4 s closes it (1.95 s) and nothing opens after it, seeing
  // and still as the robot is, until the reload at 10 s.
  const auto halted = w.halted(4 * s);
  ASSERT_TRUE(halted);
  EXPECT_EQ(halted->from, 2 * s + dt);
  EXPECT_EQ(halted->to, 4 * s);
  EXPECT_FALSE(w.eyeRead(5 * s, 1, 400));
  EXPECT_FALSE(w.frameLatched(6 * s));
  EXPECT_FALSE(w.windowStart());
  EXPECT_FALSE(w.reloaded(10 * s));  // has read nothing: sees nothing
  EXPECT_FALSE(w.windowStart());
  EXPECT_FALSE(w.eyeRead(11 * s, 0, 400));
  EXPECT_EQ(w.windowStart(), 11 * s);
  EXPECT_FALSE(w.finish(11 * s + s / 2));
  EXPECT_EQ(w.total(), 2 * s + 2 * s - dt);
}

TEST(StallWatch, LatchesWithinASecondAndOtherChannelsAreNoStall) {
  reports::StallWatch w;
  constexpr trace::Tick s = scheduler::kTicksPerSecond;
  EXPECT_FALSE(w.eyeRead(0, 0, 500));
  for (trace::Tick t = s / 2; t <= 10 * s; t += s / 2) EXPECT_FALSE(w.frameLatched(t));
  EXPECT_FALSE(w.eyeRead(10 * s + 1, 2, 0));  // channel 2 is no eye
  EXPECT_EQ(w.windowStart(), 10 * s);
  EXPECT_FALSE(w.finish(10 * s + s / 2));
  EXPECT_EQ(w.total(), 0);
  // A latch while seeing nothing opens no window.
  reports::StallWatch blind;
  EXPECT_FALSE(blind.frameLatched(5));
  EXPECT_FALSE(blind.windowStart());
  // A threshold of bench's --seen-threshold.
  reports::StallWatch strict(reports::StallRule{.seen = 600});
  EXPECT_FALSE(strict.eyeRead(0, 0, 500));
  EXPECT_FALSE(strict.windowStart());
}
