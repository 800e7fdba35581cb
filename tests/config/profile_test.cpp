// The profile and hardware-file loaders (config/profile.cpp): the shipped
// profiles, errors at their place, units, hostile numbers, the text
// toml++ mishandles, hardware overrides, and the controller's knobs.
#include <fstream>
#include <numbers>
#include <regex>

#include "tests/plant/plant_support.h"

using namespace plant_test;
using simbot::config::checkTomlText;
using simbot::config::parseHardware;
using simbot::config::parseProfile;
using simbot::scheduler::ControllerKnobs;
using simbot::vm::CpuRevision;
using simbot::vm::TimerService;

namespace {

TEST(Profiles, BothShippedProfilesLoad) {
  const Profile t = thesis();
  EXPECT_EQ(t.name, "thesis-1997");
  EXPECT_DOUBLE_EQ(t.field.size_ft, 16.0);
  EXPECT_DOUBLE_EQ(t.field.wire_inset_ft, 0.5);  // the Simbot's 50 units (VI.C.4)
  EXPECT_DOUBLE_EQ(t.field.divider_thickness_ft, 0.75 / 12);
  EXPECT_DOUBLE_EQ(t.robot.body_diameter_ft, 12.75 / 12);
  // Effective track for Appendix C's 150 deg/s spin at 1.5 ft/s: 3.6 / pi ft.
  EXPECT_NEAR(t.robot.track_ft, 3.6 / std::numbers::pi, 1e-7);
  EXPECT_EQ(t.robot.motor_lag_s, 0.0);
  EXPECT_EQ(t.robot.eye_max, 4080);
  EXPECT_EQ(t.robot.balls_per_gun, 15);
  EXPECT_DOUBLE_EQ(t.robot.muzzle_speed_fps, 105);
  EXPECT_DOUBLE_EQ(t.field.gravity_fps2, 32.174);
  EXPECT_EQ(t.referee.reflex_limit, 3);
  EXPECT_EQ(t.referee.event_limit, 5);
  EXPECT_DOUBLE_EQ(t.round_length_s, 180);
  EXPECT_DOUBLE_EQ(t.field.start[1].x_ft, 6.5);
  EXPECT_FALSE(t.robot.thesis_swapped_eyes);
  EXPECT_FALSE(t.field.count_floor_skips);
  const Profile d = defaults();
  EXPECT_EQ(d.name, "default");
  EXPECT_GT(d.robot.motor_lag_s, 0);
  EXPECT_GT(d.robot.noise_sigma, 0);  // seeded variation (variation_test.cpp)
}

std::string shipped() {
  std::ifstream in(profilePath("thesis-1997"));
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Replaces the first occurrence of `from` in the shipped text.
std::string edit(const std::string& from, const std::string& to) {
  std::string s = shipped();
  const auto at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  s.replace(at, from.size(), to);
  return s;
}

int lineOf(const std::string& text, const std::string& needle) {
  const auto at = text.find(needle);
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

std::string errorOf(const std::string& text, const char* file = "test.toml") {
  try {
    parseProfile(text, file);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

const std::regex kFormat(R"(^test\.toml:(\d+):(\d+): error: .+$)");

int errLine(const std::string& msg) {
  std::smatch m;
  if (!std::regex_match(msg, m, kFormat)) return -1;
  return std::stoi(m[1]);
}

TEST(Profiles, UnknownKeyIsReportedAtItsPosition) {
  const std::string text =
      edit("[eyes]\n", "[eyes]\nsquint = { value = 1.0, unit = \"1\", source = \"x\" }\n");
  const std::string msg = errorOf(text);
  EXPECT_EQ(errLine(msg), lineOf(text, "squint")) << msg;
  EXPECT_NE(msg.find("unknown key 'squint'"), std::string::npos) << msg;
  EXPECT_NE(msg.find(":1: error"), std::string::npos) << msg;  // column 1
}

TEST(Profiles, WrongUnitIsReportedAtTheUnit) {
  const std::string text = edit("unit = \"in\", source = \"thesis Appendix C / VI.C.1",
                                "unit = \"s\", source = \"thesis Appendix C / VI.C.1");
  const std::string msg = errorOf(text);
  EXPECT_EQ(errLine(msg), lineOf(text, "track ")) << msg;
  EXPECT_NE(msg.find("wrong unit 's' for 'robot.track'"), std::string::npos) << msg;
}

TEST(Profiles, MalformedFileGivesAParseErrorPosition) {
  const std::string text = edit("[gun]\n", "[gun\n");
  const std::string msg = errorOf(text);
  EXPECT_EQ(errLine(msg), lineOf(text, "[gun")) << msg;
}

TEST(Profiles, MissingAndWrongTypeAndRange) {
  std::string text = shipped();
  const auto at = text.find("nose ");
  text.erase(at, text.find('\n', at) - at + 1);
  std::string msg = errorOf(text);
  EXPECT_GT(errLine(msg), 0) << msg;
  EXPECT_NE(msg.find("missing key 'nose' in [eyes]"), std::string::npos) << msg;

  text = edit("value = 15,  unit = \"step\"", "value = \"15\",  unit = \"step\"");
  msg = errorOf(text);
  EXPECT_EQ(errLine(msg), lineOf(text, "reflex_speed_step")) << msg;
  EXPECT_NE(msg.find("must be an integer"), std::string::npos) << msg;

  text = edit("value = 180.0, unit = \"s\"", "value = -1, unit = \"s\"");
  msg = errorOf(text);
  EXPECT_NE(msg.find("'match.round_length' must be between 1 and 1000000 s, got -1 s"),
            std::string::npos)
      << msg;

  text = edit("value = 0.0, unit = \"s\", source = \"thesis VI.C.1: acceleration ignored\"",
              "value = 0.0, unit = \"s\"");
  msg = errorOf(text);
  EXPECT_NE(msg.find("has no 'source'"), std::string::npos) << msg;

  text = edit("unit = \"ft/s\", source = \"thesis VI.C.1 linear",
              "unit = \"ft\", source = \"thesis VI.C.1 linear");
  msg = errorOf(text);
  EXPECT_NE(msg.find("wrong unit 'ft'"), std::string::npos) << msg;
}

// Numbers that parse but mean nothing physical (issue 9's audit: each of
// them once ended in a solver failure, a hang or gigabytes): every one is
// rejected at its place, with the key's range in the message.
TEST(Profiles, HostileNumbersAreRejectedWithTheirRange) {
  struct Case {
    const char* from;
    const char* to;
    const char* message;
  } cases[] = {
      {"value = [0.0, 0.1,", "value = [nan, 0.1,", "'robot.speed_table[0]' must be finite"},
      {"value = [0.0, 0.1,", "value = [inf, 0.1,", "'robot.speed_table[0]' must be finite"},
      {"value = [0.0, 0.1,", "value = [1e308, 0.1,",
       "'robot.speed_table[0]' must be between 0 and 20 ft/s"},
      {"left_trim  = { value = 1.0,", "left_trim  = { value = 1e300,",
       "'robot.left_trim' must be between 0.5 and 2"},
      {"left_trim  = { value = 1.0,", "left_trim  = { value = 1e6,",
       "'robot.left_trim' must be between 0.5 and 2"},
      {"motor_lag  = { value = 0.0,", "motor_lag  = { value = 1e-300,",
       "'robot.motor_lag' must be 0 or between 0.001 and 10 s"},
      {"body_diameter       = { value = 12.75,", "body_diameter       = { value = 1e300,",
       "'robot.body_diameter' must be between 0.1 and 5 ft"},
      // Integers beyond 2^53 have no exact double: read as integers, then checked.
      {"body_diameter       = { value = 12.75,",
       "body_diameter       = { value = 9223372036854775807,",
       "'robot.body_diameter' must be between 0.1 and 5 ft"},
      {"balls_per_gun = { value = 15,", "balls_per_gun = { value = 9223372036854775807,",
       "'gun.balls_per_gun' must be in 0..16"},
      {"balls_per_gun = { value = 15,", "balls_per_gun = { value = -1,",
       "'gun.balls_per_gun' must be in 0..16"},
  };
  for (const Case& c : cases) {
    const std::string text = edit(c.from, c.to);
    const std::string msg = errorOf(text);
    EXPECT_NE(msg.find(c.message), std::string::npos) << c.to << "\n" << msg;
    EXPECT_GT(errLine(msg), 0) << msg;
  }
}

// toml++ 3.3.0 reaches an "unreachable" state (undefined behaviour; an
// assertion or UBSan report in other builds) on these inputs, from its
// issues 190 and 295. The loaders stop them first, at their place.
TEST(Profiles, TextTomlPlusPlusMishandlesIsStoppedFirst) {
  struct Case {
    std::string text;
    const char* where;
    const char* message;
  } cases[] = {
      {"s = \"\"\"\\\n\xc2\xa7\"\"\"\n", ":1:8: error:",
       "a line-ending backslash in a multi-line string is followed by a non-ASCII character"},
      {"a\xcc\xaa = 1\n", ":1:2: error:", "a non-ASCII character outside a string or comment"},
      {"\xcc\xaa", ":1:1: error:", "a non-ASCII character outside a string or comment"},
      {"name = \"x\xff\"\n", ":1:10: error:", "the file is not valid UTF-8 (byte 0xff)"},
      {"name = \"x\xed\xa0\x80\"\n", ":1:10: error:", "the file is not valid UTF-8 (byte 0xed)"},
  };
  for (const Case& c : cases) {
    const std::string msg = errorOf(c.text);
    EXPECT_NE(msg.find(c.where), std::string::npos) << msg;
    EXPECT_NE(msg.find(c.message), std::string::npos) << msg;
  }
  // Non-ASCII where TOML allows it passes the check (and the parser).
  EXPECT_NO_THROW(
      checkTomlText("# \xc3\xa9t\xc3\xa9\nname = \"\xe2\x82\xac \\\" \xc2\xa7\"\n"
                    "s = '''\xf0\x9f\x98\x80'''\n",
                    "ok.toml"));
}

TEST(Profiles, UnitsAreConverted) {
  std::string text = edit("size              = { value = 16.0,  unit = \"ft\"",
                          "size              = { value = 4.8768,  unit = \"m\"");
  EXPECT_NEAR(parseProfile(text, "x.toml").field.size_ft, 16.0, 1e-12);
  text = edit("turn         = { value = 45.0, unit = \"deg\"",
              "turn         = { value = 0.7853981633974483, unit = \"rad\"");
  EXPECT_NEAR(parseProfile(text, "x.toml").referee.turn_deg, 45.0, 1e-12);
}

// Both robots on one mark: refused, as a scenario refuses it. thesis-1997's
// body is 12.75 in (1.0625 ft) across and its placement radius 0, so
// centres 1.0 ft apart overlap and 1.5 ft apart do not.
TEST(Profiles, StartPosesThatOverlapAreRefused) {
  const char* b = "b_x       = { value = 6.5,";
  for (const char* x : {"-6.5", "-5.5"}) {
    const std::string text = edit(b, std::string("b_x       = { value = ") + x + ",");
    EXPECT_NE(errorOf(text).find("the two start poses overlap"), std::string::npos) << x;
  }
  EXPECT_EQ(errorOf(edit(b, "b_x       = { value = -5.0,")), "");
}

TEST(Profiles, MissingFileIsAnError) {
  EXPECT_THROW(loadProfile("/nonexistent/profile.toml"), ConfigError);
}

TEST(Hardware, BindsPortsAndOverridesRobotValues) {
  RobotParams params = thesis().robot;
  ControllerKnobs controller;
  const Hardware h = parseHardware(R"(
[ports]
gun1_motor = { value = 0, unit = "bit", source = "our wiring" }
gun1_solenoid = { value = 1, unit = "bit", source = "our wiring" }

[gun]
muzzle_speed = { value = 30, unit = "m/s", source = "measured" }

[eyes]
max = { value = 2040, unit = "reading", source = "other circuit" }

[controller]
timer_service = { value = "never", source = "our BIOS" }
)",
                                   "hw.toml", params, controller);
  EXPECT_EQ(h.gun_motor_bit[0], 0);
  EXPECT_EQ(h.gun_solenoid_bit[0], 1);
  EXPECT_EQ(h.gun_motor_bit[1], 7);  // default kept
  EXPECT_EQ(h.disc_shooter_bit, 6);
  EXPECT_NEAR(params.muzzle_speed_fps, 30 / 0.3048, 1e-9);
  EXPECT_EQ(params.eye_max, 2040);
  EXPECT_EQ(params.balls_per_gun, 15);
  EXPECT_EQ(controller.timerService, TimerService::Never);
  EXPECT_TRUE(controller.fastForward);  // default kept
}

// [controller]'s knobs are the VM's, typed: the timer service's word and
// fast-forward's flag.
TEST(Profiles, ControllerKnobsAreTheVmsTyped) {
  EXPECT_EQ(thesis().controller.timerService, TimerService::Auto);
  EXPECT_TRUE(defaults().controller.fastForward);
  std::string text =
      edit("timer_service = { value = \"auto\"", "timer_service = { value = \"always\"");
  text.replace(text.find("fast_forward  = { value = true"), 30, "fast_forward  = { value = false");
  const Profile p = parseProfile(text, "x.toml");
  EXPECT_EQ(p.controller.timerService, TimerService::Always);
  EXPECT_FALSE(p.controller.fastForward);
  const std::string msg =
      errorOf(edit("timer_service = { value = \"auto\"", "timer_service = { value = \"often\""));
  EXPECT_NE(msg.find("'controller.timer_service' must be \"auto\", \"always\" or \"never\""),
            std::string::npos)
      << msg;
}

// [controller] cpu: the Z180 revision, the original Z80180 in both shipped
// profiles (the thesis's board predates the Z8S180); "z8s180" the later
// one; anything else is an error naming the two.
TEST(Profiles, ControllerCpuIsTheZ180Revision) {
  EXPECT_EQ(thesis().controller.cpu, CpuRevision::Z80180);
  EXPECT_EQ(defaults().controller.cpu, CpuRevision::Z80180);
  const Profile p = parseProfile(
      edit("cpu           = { value = \"z80180\"", "cpu = { value = \"z8s180\""), "x.toml");
  EXPECT_EQ(p.controller.cpu, CpuRevision::Z8S180);
  const std::string msg =
      errorOf(edit("cpu           = { value = \"z80180\"", "cpu = { value = \"z80\""));
  EXPECT_NE(msg.find("'controller.cpu' must be \"z80180\" or \"z8s180\""), std::string::npos)
      << msg;
  RobotParams params = thesis().robot;
  ControllerKnobs controller;
  parseHardware("[controller]\ncpu = { value = \"z8s180\", source = \"our board\" }\n", "hw.toml",
                params, controller);
  EXPECT_EQ(controller.cpu, CpuRevision::Z8S180);
}

TEST(Hardware, ErrorsArePositioned) {
  RobotParams params = thesis().robot;
  ControllerKnobs controller;
  auto err = [&](const char* text) {
    try {
      parseHardware(text, "hw.toml", params, controller);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(err("[ports]\ngun1_motor = { value = 9, unit = \"bit\", source = \"x\" }\n")
                .find("hw.toml:2:"),
            std::string::npos);
  EXPECT_NE(err("[field]\nsize = { value = 9, unit = \"ft\", source = \"x\" }\n")
                .find("hw.toml:1:2: error: [field] is arena-wide"),
            std::string::npos);
  EXPECT_NE(err("[ports]\ngun1_motor = { value = 5, unit = \"bit\", source = \"x\" }\n")
                .find("bound twice"),
            std::string::npos);
  EXPECT_NE(
      err("[gun]\nstroke_time = { value = 1, unit = \"ft\", source = \"x\" }\n").find("hw.toml:2:"),
      std::string::npos);
}

TEST(Hardware, GunBitsDriveTheArena) {
  Profile p = thesis();
  ArenaConfig c = makeArenaConfig(p, 1);
  c.robots[0].hardware.gun_motor_bit[0] = 0;
  c.robots[0].hardware.gun_solenoid_bit[0] = 1;
  Arena a(c);
  EventList ev = a.setPortB(0, 0x01, 0);
  EXPECT_TRUE(ev.empty());
  ev = a.setPortB(0, 0x03, 0);
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].kind, EventKind::SolenoidStroke);
  ev = a.setPortB(0, 0x43, 0);  // disc shooter: logged only
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].kind, EventKind::DiscShooter);
  AdvanceResult r = a.advance(1000);
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].kind, EventKind::BallLaunch);
  EXPECT_EQ(r.tick, 0);
}

// Jams and misfires (DESIGN.md: an option): one draw per stroke that would
// launch. A misfire keeps the ball chambered; a jam ends the gun's match.
TEST(Hardware, GunsJamAndMisfireOnlyAsTheProfileSays) {
  Profile p = thesis();
  const auto strokes = [&](double jam, double misfire, RandomBits* luck) {
    p.robot.jam_probability = jam;
    p.robot.misfire_probability = misfire;
    Arena a(makeArenaConfig(p, 1));
    std::string kinds;
    for (int k = 0; k < 3; ++k) {
      for (const Event& e : a.setPortB(0, 0x18, a.now(), luck))
        kinds += eventKindName(e.kind) + std::string(" ");
      a.setPortB(0, 0x08, a.now());
      a.advance(a.now() + 1000);
    }
    return kinds + std::to_string(a.shots(0)) + " " + std::to_string(a.ballsLeft(0, 0));
  };
  SplitMix64 luck(5);
  EXPECT_EQ(strokes(0, 0, &luck), "solenoid_stroke solenoid_stroke solenoid_stroke 3 12");
  EXPECT_EQ(strokes(0, 1, &luck), "gun_misfire gun_misfire gun_misfire 0 15");
  EXPECT_EQ(strokes(1, 0, &luck), "gun_jammed gun_jammed gun_jammed 0 15");
  EXPECT_EQ(strokes(1, 0, nullptr), "solenoid_stroke solenoid_stroke solenoid_stroke 3 12");
  // Half and half: the same stream gives the same outcomes.
  SplitMix64 l1(9), l2(9);
  EXPECT_EQ(strokes(0.25, 0.25, &l1), strokes(0.25, 0.25, &l2));
}

TEST(Profile, JamAndMisfireTogetherAtMostOne) {
  std::string text =
      edit("jam_probability     = { value = 0.0", "jam_probability     = { value = 0.6");
  const std::string mis = "misfire_probability = { value = 0.0";
  ASSERT_NE(text.find(mis), std::string::npos);
  text.replace(text.find(mis), mis.size(), "misfire_probability = { value = 0.6");
  try {
    parseProfile(text, "p.toml");
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("jam_probability + misfire_probability must be at most 1"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace

// The variation amounts are checked like every value: a spread that could
// draw a trim outside 0.5..2, or a placement radius beyond its range.
TEST(Profiles, VariationAmountsAreChecked) {
  std::string msg = errorOf(edit("trim_spread = { value = 0.0,", "trim_spread = { value = 0.3,"));
  EXPECT_NE(msg.find("'robot.trim_spread' must be between 0 and 0.25"), std::string::npos) << msg;
  msg = errorOf(edit("right_trim = { value = 1.0,", "right_trim = { value = 1.9,"));
  EXPECT_EQ(msg, "");  // 1.9 alone is fine
  std::string text = edit("right_trim = { value = 1.0,", "right_trim = { value = 1.9,");
  text.replace(text.find("trim_spread = { value = 0.0,"), 28, "trim_spread = { value = 0.1, ");
  msg = errorOf(text);
  EXPECT_NE(msg.find("trim_spread takes a wheel's trim outside 0.5..2"), std::string::npos) << msg;
  msg = errorOf(edit("placement_radius  = { value = 0.0, unit = \"in\"",
                     "placement_radius  = { value = 30.0, unit = \"in\""));
  EXPECT_NE(msg.find("'start.placement_radius' must be between 0 and 2 ft"), std::string::npos)
      << msg;
  msg =
      errorOf(edit("muzzle_speed_spread = { value = 0.0,", "muzzle_speed_spread = { value = 0.6,"));
  EXPECT_NE(msg.find("'gun.muzzle_speed_spread' must be between 0 and 0.5"), std::string::npos)
      << msg;
}
