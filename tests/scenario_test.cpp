// Scenario files: every key checked with FILE:LINE:COL: error: messages, and
// what a scenario does to a run (poses, a beacon on its path, injections).
#include "runs/scenario.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "batch/bench.h"
#include "config/config.h"
#include "runs/play.h"
#include "scheduler/match.h"
#include "support/traced.h"

namespace {

using namespace simbot;

const std::string kSource = SIMBOT_SOURCE_DIR;
const std::string kShared = SIMBOT_SHARED_DIR;

config::Scenario parse(const std::string& text) {
  return config::parseScenario(text, "s.toml", kSource);
}

// The message a scenario's text gets, or "" if it loads.
std::string errorOf(const std::string& text) {
  try {
    parse(text);
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(Scenario, LoadsEveryKey) {
  const auto s = parse(R"(profile = "thesis-1997"
seconds = 45
seed = 7
[A]
start = { x_ft = 1.5, y_ft = -6, heading_deg = -90 }
hardware = "profiles/hardware/swapped-guns.toml"
inject = ["edge_fore@12.5s", "bumper_front@line:220#3"]
[B]
beacon = true
start = { x_ft = -2, y_ft = 0, heading_deg = 0 }
path = [
  { forward_ft = 4, speed_fps = 0.5 },
  { arc_radius_ft = 3, turn_deg = -90, speed_fps = 0.5 },
  { spin_deg = 90, speed_fps = 0.3 },
  { wait_s = 1 },
]
repeat = true
)");
  EXPECT_EQ(*s.profile, "thesis-1997");
  EXPECT_EQ(*s.length, 414'720'000);  // 45 s * 9,216,000
  EXPECT_EQ(*s.seed, 7u);
  ASSERT_TRUE(s.a.start);
  EXPECT_EQ(s.a.start->x_ft, 1.5);
  EXPECT_EQ(s.a.start->heading_deg, 270);
  EXPECT_EQ(s.a.startPos.line, 5);
  EXPECT_EQ(s.a.hardware, kSource + "/profiles/hardware/swapped-guns.toml");
  ASSERT_EQ(s.a.inject.size(), 2u);
  EXPECT_EQ(s.a.inject[1].what, "bumper_front@line:220#3");
  EXPECT_EQ(s.a.inject[1].pos.line, 7);
  EXPECT_EQ(s.opponent, config::Scenario::Opponent::Beacon);
  ASSERT_EQ(s.path.size(), 4u);
  EXPECT_EQ(s.path[1].kind, config::PathLeg::Kind::Arc);
  EXPECT_EQ(s.path[1].turnDeg, -90);
  EXPECT_EQ(s.path[3].pos.line, 15);
  EXPECT_TRUE(s.repeatPath);
}

// A scenario's times are written as every time is (timebase/written.h): a
// number of seconds, or a string with a unit s, ms, us or t.
TEST(Scenario, TimesInTheOneGrammar) {
  EXPECT_EQ(parse("seconds = \"500ms\"\n").length, 4'608'000);  // 500 * 9,216
  EXPECT_EQ(parse("seconds = \"9216t\"\n").length, 9'216);
  EXPECT_EQ(parse("seconds = \"125us\"\n").length, 1'152);  // 125 * 9.216
  EXPECT_EQ(parse("seconds = 0.043\n").length, 396'288);    // 43 * 9,216
  const auto legs = [](const char* wait) {
    return parse(std::string("[B]\nbeacon = true\npath = [{ wait_s = ") + wait + " }]\n").path;
  };
  EXPECT_EQ(legs("0.5")[0].wait, 4'608'000);
  EXPECT_EQ(legs("\"2ms\"")[0].wait, 18'432);  // 2 * 9,216
  EXPECT_EQ(legs("\"1t\"")[0].wait, 1);
}

struct Bad {
  std::string text;
  std::string message;
};

// Seeds at or above 2^63 (runs.csv prints them) are written as strings:
// TOML's integers stop at 2^63 - 1.
TEST(Scenario, SeedsBeyondTomlIntegersAreStrings) {
  EXPECT_EQ(parse("seed = \"18446744073709551615\"\n").seed, UINT64_MAX);
  EXPECT_EQ(parse("seed = \"9223372036854775808\"\n").seed, uint64_t{1} << 63);
  EXPECT_EQ(parse("seed = 9223372036854775807\n").seed, (uint64_t{1} << 63) - 1);
}

TEST(Scenario, EveryMistakeNamesItsLine) {
  const Bad cases[] = {
      {"speed = 3\n",
       "s.toml:1:1: error: unknown key 'speed' in the scenario (expected one of: profile, rules, "
       "seconds, seed, A, B, obstacles)"},
      {"rules = \"no-such\"\n",
       "s.toml:1:9: error: 'rules': no rule set 'no-such' in rules/ (or give a path to a .toml)"},
      // Times in timebase/written.h's grammar: a number of seconds, or a
      // string with its unit; a whole number of ticks (300 us is 2,764.8).
      {"\nseconds = -1\n",
       "s.toml:2:11: error: 'seconds': '-1' is not a time (write 12.5s, 800ms, 300us or "
       "115200000t, at most 1e11 s; a number alone is seconds)"},
      {"seconds = \"ten\"\n",
       "s.toml:1:11: error: 'seconds': 'ten' is not a time (write 12.5s, 800ms, 300us or "
       "115200000t, at most 1e11 s; a number alone is seconds)"},
      {"seconds = true\n",
       "s.toml:1:11: error: 'seconds' must be a time: a number of seconds, or a string such as "
       "\"800ms\""},
      {"seconds = 2e6\n",
       "s.toml:1:11: error: 'seconds': '2000000' is not a run's length: more than 0 s and at "
       "most 1e6 s (9216000000000t)"},
      {"seconds = 0\n",
       "s.toml:1:11: error: 'seconds': '0' is not a run's length: more than 0 s and at most 1e6 "
       "s (9216000000000t)"},
      {"seconds = \"300us\"\n",
       "s.toml:1:11: error: 'seconds': '300us' is not a whole number of ticks of the 9.216 MHz "
       "clock: the nearest are 2764t and 2765t"},
      {"seconds = 0.0001\n",  // 921.6 ticks
       "s.toml:1:11: error: 'seconds': '0.0001' is not a whole number of ticks of the 9.216 MHz "
       "clock: the nearest are 921t and 922t"},
      {"seed = -3\n",
       "s.toml:1:8: error: 'seed' must be an integer from 0 to 2^63 - 1, or a "
       "string of digits"},
      // A string seed is digits and fits in 64 bits (2^64 is one too many).
      {"seed = \"18446744073709551616\"\n", "s.toml:1:8: error: 'seed' must be an integer"},
      {"seed = \"-1\"\n", "s.toml:1:8: error: 'seed' must be an integer"},
      {"seed = \" 7\"\n", "s.toml:1:8: error: 'seed' must be an integer"},
      {"profile = \"nosuch\"\n",
       "s.toml:1:11: error: 'profile': no profile 'nosuch' in profiles/ (or give a path to a "
       ".toml)"},
      {"profile = \"nosuch.toml\"\n",
       ("s.toml:1:11: error: 'profile': no file '" + kSource + "/nosuch.toml'")},
      {"seconds = [1\n", "s.toml:1:14: error: "},  // toml++'s own description follows
      {"A = 3\n", "s.toml:1:5: error: 'A' must be a table ([A])"},
      {"[A]\nspeed = 1\n",
       "s.toml:2:1: error: unknown key 'speed' in [A] (expected one of: start, hardware, inject)"},
      {"[A]\nstart = { x_ft = 1, y_ft = 2 }\n",
       "s.toml:2:9: error: 'A.start' has no 'heading_deg'"},
      {"[A]\nstart = { x_ft = 1, y_ft = 2, heading_deg = 0, z_ft = 1 }\n",
       "s.toml:2:48: error: unknown key 'z_ft' in 'A.start' (expected one of: x_ft, y_ft, "
       "heading_deg)"},
      {"[A]\nstart = { x_ft = 1, y_ft = \"2\", heading_deg = 0 }\n",
       "s.toml:2:28: error: 'A.start.y_ft' must be a number"},
      {"[A]\nstart = [1, 2, 3]\n",
       "s.toml:2:9: error: 'A.start' must be a table { x_ft = ..., y_ft = ..., heading_deg = ... "
       "}"},
      {"[A]\nhardware = \"missing.toml\"\n",
       ("s.toml:2:12: error: 'A.hardware': no file '" + kSource + "/missing.toml'")},
      {"[A]\ninject = \"edge_fore@1s\"\n",
       "s.toml:2:10: error: 'A.inject' must be an array of \"SOURCE@WHEN\" strings"},
      {"[A]\ninject = [\n  \"edge_fore@1s\",\n  \"edge_side@1s\",\n]\n",
       "s.toml:4:3: error: 'edge_side@1s': SOURCE must be edge_fore, edge_aft, bumper_front, "
       "bumper_back or reset"},
      {"[A]\ninject = [\"edge_fore@soon\"]\n",
       "s.toml:2:11: error: 'edge_fore@soon': WHEN must be a time (12.5s, 800ms, 300us, "
       "115200000t) or a program point (line:N#K, pass:N#K)"},
      {"[A]\ninject = [\"edge_fore@12.5\"]\n",  // a number alone is no time here
       "s.toml:2:11: error: 'edge_fore@12.5': WHEN must be a time (12.5s, 800ms, 300us, "
       "115200000t) or a program point (line:N#K, pass:N#K)"},
      {"[A]\ninject = [\"edge_fore@300us\"]\n",
       "s.toml:2:11: error: 'edge_fore@300us': '300us' is not a whole number of ticks of the "
       "9.216 MHz clock: the nearest are 2764t and 2765t"},
      {"[B]\nbeacon = true\npath = [{ wait_s = 1e-9 }]\n",  // 0.009216 ticks
       "s.toml:3:20: error: 'B.path[0].wait_s': '1e-09' is not a whole number of ticks of the "
       "9.216 MHz clock: the nearest are 0t and 1t"},
      {"[B]\nprogram = \"nope.dc\"\n",
       ("s.toml:2:11: error: 'B.program': no file '" + kSource + "/nope.dc'")},
      {"[B]\nprogram = \"programs/spiral.dc\"\nbeacon = true\n",
       "s.toml:3:10: error: [B] is either a program or a beacon, not both"},
      {"[B]\nbeacon = false\n",
       "s.toml:2:10: error: 'B.beacon' must be true (or leave it out and give B.program)"},
      {"[B]\nprogram = \"programs/spiral.dc\"\npath = [{ wait_s = 1 }]\n",
       "s.toml:3:8: error: only a beacon (B.beacon = true) drives a path"},
      {"[B]\nrepeat = true\n", "s.toml:2:10: error: only a beacon (B.beacon = true) drives a path"},
      {"[B]\nbeacon = true\ninject = [\"edge_fore@1s\"]\n",
       "s.toml:3:10: error: a beacon has no program to interrupt; B.inject needs B.program"},
      {"[B]\nbeacon = true\npath = []\n",
       "s.toml:3:8: error: 'B.path' must be a non-empty array of legs"},
      {"[B]\nbeacon = true\npath = [3]\n",
       "s.toml:3:9: error: 'B.path[0]' must be a table (forward_ft, arc_radius_ft, spin_deg or "
       "wait_s)"},
      {"[B]\nbeacon = true\npath = [\n { wait_s = 1 },\n { forward_ft = 1, spin_deg = 9, "
       "speed_fps = 1 },\n]\n",
       "s.toml:5:2: error: 'B.path[1]' must have exactly one of forward_ft, arc_radius_ft, "
       "spin_deg, wait_s"},
      {"[B]\nbeacon = true\npath = [{ forward_ft = 1, turn_deg = 9, speed_fps = 1 }]\n",
       "s.toml:3:38: error: 'B.path[0]': turn_deg belongs to an arc (arc_radius_ft)"},
      {"[B]\nbeacon = true\npath = [{ arc_radius_ft = 3, speed_fps = 1 }]\n",
       "s.toml:3:9: error: 'B.path[0]' has no 'turn_deg' (the arc's signed angle)"},
      {"[B]\nbeacon = true\npath = [{ arc_radius_ft = -3, turn_deg = 9, speed_fps = 1 }]\n",
       "s.toml:3:27: error: 'B.path[0].arc_radius_ft' must be greater than 0, got -3"},
      {"[B]\nbeacon = true\npath = [{ wait_s = 1, speed_fps = 1 }]\n",
       "s.toml:3:35: error: 'B.path[0]': a wait has no speed_fps"},
      {"[B]\nbeacon = true\npath = [{ spin_deg = 90 }]\n",
       "s.toml:3:9: error: 'B.path[0]' has no 'speed_fps'"},
      {"[B]\nbeacon = true\npath = [{ forward_ft = 0, speed_fps = 1 }]\n",
       "s.toml:3:24: error: 'B.path[0].forward_ft' must not be 0"},
      {"[B]\nbeacon = true\npath = [{ forward_ft = 2, speed_fps = 1, fast = true }]\n",
       "s.toml:3:42: error: unknown key 'fast' in 'B.path[0]' (expected one of: forward_ft, "
       "arc_radius_ft, turn_deg, spin_deg, wait_s, speed_fps)"},
      {"[B]\nbeacon = true\nrepeat = 1\n", "s.toml:3:10: error: 'B.repeat' must be true or false"},
      // Integers beyond 2^53 are read as integers and checked, numbers have ranges.
      {"[A]\nstart = { x_ft = 9223372036854775807, y_ft = 0, heading_deg = 0 }\n",
       "s.toml:2:18: error: 'A.start.x_ft' must be between -100 and 100, got "
       "9.223372036854776e+18"},
      {"[B]\nbeacon = true\npath = [{ forward_ft = 2, speed_fps = 1e300 }]\n",
       "s.toml:3:39: error: 'B.path[0].speed_fps' must be between"},
  };
  for (const Bad& c : cases) {
    const std::string got = errorOf(c.text);
    EXPECT_EQ(got.substr(0, c.message.size()), c.message) << c.text;
    EXPECT_EQ(got.find('\n'), std::string::npos) << got;
  }
}

scheduler::MatchConfig soloConfig(const std::string& program, const config::Profile& profile) {
  scheduler::MatchConfig c;
  c.arena = config::makeArenaConfig(profile, 1);
  c.robots.push_back({"A", program, runs::compileProgramFile(program)});
  return c;
}

config::Profile defaults() { return runs::loadNamedProfile("default"); }

std::string applyError(const std::string& text, runs::ScenarioUse use, int programs = 1) {
  const auto profile = defaults();
  auto c = soloConfig(kSource + "/programs/spiral.dc", profile);
  if (programs == 2) {
    c.arena = config::makeArenaConfig(profile, 2);
    c.robots.push_back({"B", "turret", runs::compileProgramFile(kSource + "/programs/turret.dc")});
  }
  try {
    runs::applyScenario(parse(text), use, profile, c);
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(Scenario, WhatDoesNotFitTheRunNamesItsLine) {
  EXPECT_EQ(applyError("\n[B]\nbeacon = true\n", runs::ScenarioUse::Match, 2),
            "s.toml:3:10: error: match takes B's program from the command line; B.program and "
            "B.beacon are for solo, profile and bench");
  EXPECT_EQ(
      applyError("[B]\nstart = { x_ft = 0, y_ft = 0, heading_deg = 0 }\n", runs::ScenarioUse::Solo),
      "s.toml:1:1: error: [B] sets up a robot B but names none: give B.program or B.beacon "
      "= true");
  EXPECT_EQ(
      applyError("[A]\nstart = { x_ft = 9, y_ft = 0, heading_deg = 0 }\n", runs::ScenarioUse::Solo),
      "s.toml:2:9: error: start (9, 0) ft puts the body outside the 16-ft field");
  EXPECT_EQ(applyError("[A]\nstart = { x_ft = 0.2, y_ft = -6, heading_deg = 0 }\n",
                       runs::ScenarioUse::Solo),
            "s.toml:2:9: error: start (0.2, -6) ft puts the body on the divider");
  EXPECT_EQ(applyError("[A]\nstart = { x_ft = 1, y_ft = 1, heading_deg = 0 }\n[B]\nstart = "
                       "{ x_ft = 1.5, y_ft = 1, heading_deg = 0 }\n",
                       runs::ScenarioUse::Match, 2),
            "s.toml:4:9: error: the two robots' start poses overlap");
  EXPECT_EQ(applyError("[A]\ninject = [\"edge_fore@line:1#1\"]\n", runs::ScenarioUse::Solo),
            "s.toml:2:11: error: line 1 of " + kSource + "/programs/spiral.dc has no code");
  EXPECT_EQ(applyError("[A]\nstart = { x_ft = 1, y_ft = 0, heading_deg = 0 }\n",
                       runs::ScenarioUse::Bench),
            "s.toml:2:9: error: a bench family places the robots and picks B; leave out --family "
            "to run this scenario's own poses and opponent");
  EXPECT_EQ(applyError("[B]\nbeacon = true\npath = [{ wait_s = 0 }]\n", runs::ScenarioUse::Solo),
            "s.toml:3:9: error: this leg lasts 0 s, which is not between one tick and 1e8 s");
  // The same B set-up is fine for a match when it names no program.
  EXPECT_EQ(applyError("[B]\nstart = { x_ft = 0, y_ft = 3, heading_deg = 0 }\n",
                       runs::ScenarioUse::Match, 2),
            "");
}

// A beacon on a scripted path, run by the scheduler: the poses the match
// ends with are the path's closed form, legs starting at exact ticks. Under
// thesis-1997: the default's hand placement would move the start.
TEST(Scenario, BeaconFollowsItsPathInAMatch) {
  const auto profile = runs::loadNamedProfile("thesis-1997");
  auto c = soloConfig(kSource + "/programs/spiral.dc", profile);
  c.robots[0].image = runs::compileProgramText("main()\n{\n}\n", "still");  // out of the way
  runs::applyScenario(parse(R"([B]
beacon = true
start = { x_ft = 0, y_ft = 3, heading_deg = 90 }
path = [ { arc_radius_ft = 3, turn_deg = 90, speed_fps = 0.5 },
         { forward_ft = -2, speed_fps = 0.25 },
         { spin_deg = -90, speed_fps = 0.2 } ]
)"),
                      runs::ScenarioUse::Solo, profile, c);
  ASSERT_EQ(c.robots.size(), 2u);
  ASSERT_EQ(c.robots[1].path.size(), 3u);
  const double quarter = 3 * std::numbers::pi / 2 / 0.5;  // seconds
  // 9.42477796076938 s * 9,216,000 = 86,858,753.686...: the nearest tick.
  EXPECT_EQ(c.robots[1].path[0].duration, 86'858'754);
  EXPECT_EQ(c.robots[1].path[0].duration, timebase::ticksFromSeconds(quarter));
  EXPECT_EQ(c.robots[1].path[1].duration, 8 * scheduler::kTicksPerSecond);
  c.endTick = 40 * scheduler::kTicksPerSecond;  // path over at about 9.4 + 8 + 3.5 s
  const auto r = testkit::runTraced(c);
  // A quarter circle clockwise from north to east (heading south), 2 ft
  // backwards (north), a quarter turn to the left: at (3, 2) heading east.
  const plant::Pose end = r.robots[1].finalPose;
  EXPECT_NEAR(end.x_ft, 3.0, 1e-5);
  EXPECT_NEAR(end.y_ft, 2.0, 1e-5);
  EXPECT_NEAR(end.heading_deg, 90.0, 1e-4);
  int legs = 0;
  for (const auto& line : r.trace) legs += line.find("\"path_leg\"") != std::string::npos;
  EXPECT_EQ(legs, 4);  // three legs and the stop
}

TEST(Scenario, BenchRunsItsOwnScenarioWhateverTheThreadCount) {
  batch::BenchConfig c;
  c.programs = {kShared + "/programs/iceman.dc"};
  c.scenario = config::loadScenario(kSource + "/scenarios/circle.toml");
  c.seeds = 3;
  c.seconds = 8;
  c.progress = false;
  auto profile = defaults();
  profile.robot.noise_sigma = 3;  // the seeds differ only in the noise
  c.threads = 1;
  const auto one = batch::runBench(c, profile);
  c.threads = 2;
  const auto two = batch::runBench(c, profile);
  EXPECT_EQ(batch::runsCsv(one), batch::runsCsv(two));
  EXPECT_EQ(batch::summaryJson(one)["family"], "scenario circle");
  for (const auto& run : one.runs) EXPECT_EQ(run.startA.x_ft, -5.0);
}

}  // namespace
