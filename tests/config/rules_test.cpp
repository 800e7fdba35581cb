// Course rules (config/rules.cpp): the two shipped rule sets against the
// thesis's numbers, their checks, their application to a profile, and the
// refusal of what a run uses that they forbid (the RunUses struct filled
// directly, as the obstacles, deployables and secondary weapon will fill it).
#include <cmath>
#include <string>

#include "tests/plant/plant_support.h"

using namespace plant_test;
using simbot::config::checkRules;
using simbot::config::ConfigError;
using simbot::config::Course;
using simbot::config::loadRules;
using simbot::config::parseRules;
using simbot::config::RunUses;

namespace {

const std::string kRulesDir = SIMBOT_RULES_DIR;

Course winter1997() { return loadRules(kRulesDir + "/se3015-1997w.toml"); }
Course year1996() { return loadRules(kRulesDir + "/se3015-1996.toml"); }

// The message of the ConfigError `f` throws ("" if none).
template <class F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(Rules, Winter1997IsAppendixA) {
  const Course c = winter1997();
  EXPECT_TRUE(c.present);
  EXPECT_EQ(c.name, "se3015-1997w");
  EXPECT_DOUBLE_EQ(c.field_size_ft, 16);    // thesis line 253: 16' x 16'
  EXPECT_TRUE(c.divider);                   // line 914: a divider between the corners
  EXPECT_TRUE(std::isnan(c.divider_x_ft));  // its geometry is the profile's
  EXPECT_DOUBLE_EQ(c.round_length_s, 180);  // line 1121: three minutes
  EXPECT_EQ(c.gun_magazine, 15);            // line 244: Table 3.6, 15 (constant)
  // Line 1073: "did not allow for decoys or included mines but allowed
  // additional weapons".
  EXPECT_FALSE(c.mines);
  EXPECT_FALSE(c.decoy_lights);
  EXPECT_FALSE(c.decoy_screens);
  EXPECT_FALSE(c.blocks);
  EXPECT_TRUE(c.secondary_disc);
  EXPECT_EQ(c.secondary_magazine, 15);  // line 1103: limited to fifteen rounds
  EXPECT_TRUE(c.floor_skips);           // line 1125: strikes off floor skips are valid
  EXPECT_DOUBLE_EQ(c.detect_threshold, 48);
  EXPECT_FALSE(c.scatter_scores);  // line 1123: scatter mode not allowed
}

TEST(Rules, Year1996AllowsMinesAndDecoysNotASecondWeapon) {
  // Line 1073: "allowed for the mines and decoys but additional weapons,
  // other than the standard gun were not permitted".
  const Course c = year1996();
  EXPECT_EQ(c.name, "se3015-1996");
  EXPECT_TRUE(c.mines);
  EXPECT_TRUE(c.decoy_lights);
  EXPECT_TRUE(c.decoy_screens);
  EXPECT_FALSE(c.secondary_disc);
  EXPECT_EQ(c.secondary_magazine, 0);
  EXPECT_EQ(c.gun_magazine, 15);
  EXPECT_DOUBLE_EQ(c.round_length_s, 180);
}

const char* kSmall = R"(name = "small"
[course]
field_size         = { value = 12.0, unit = "ft", source = "t" }
divider            = { value = false, source = "t" }
round_length       = { value = 2, unit = "min", source = "t" }
gun_magazine       = { value = 10, unit = "count", source = "t" }
mines              = { value = false, source = "t" }
blocks             = { value = true, source = "t" }
decoy_lights       = { value = false, source = "t" }
decoy_screens      = { value = true, source = "t" }
secondary_disc     = { value = false, source = "t" }
secondary_magazine = { value = 0, unit = "count", source = "t" }
floor_skips        = { value = false, source = "t" }
detect_threshold   = { value = 100, unit = "reading", source = "t" }
scatter_scores     = { value = true, source = "t" }
)";

std::string withLine(std::string text, const std::string& key, const std::string& line) {
  const auto at = text.find(key);
  const auto end = text.find('\n', at);
  return text.replace(at, end - at, line);
}

TEST(Rules, KeysCheckedAsAProfilesAreAtTheirPlace) {
  // round_length in minutes is not a unit a time takes (s, ms). Columns
  // by hand: the unit's string starts at column 42 (19 for the padded key,
  // "= { value = 2, unit = " up to 41); secondary_magazine's value at 32.
  EXPECT_EQ(errorOf([] { parseRules(kSmall, "r.toml"); }),
            "r.toml:5:42: error: wrong unit 'min' for 'course.round_length' (expected one of: "
            "s, ms)");
  const std::string ok = withLine(kSmall, "round_length",
                                  "round_length = { value = 120, unit = \"s\", source = \"t\" }");
  EXPECT_EQ(errorOf([&] { parseRules(ok, "r.toml"); }), "");
  // Appendix A's fifteen rounds is the range's top.
  EXPECT_EQ(errorOf([&] {
              parseRules(withLine(ok, "secondary_magazine",
                                  "secondary_magazine = { value = 16, unit = \"count\", source = "
                                  "\"t\" }"),
                         "r.toml");
            }),
            "r.toml:12:32: error: 'course.secondary_magazine' must be in 0..15");
  // A magazine for a secondary weapon the rules do not allow.
  EXPECT_EQ(errorOf([&] {
              parseRules(withLine(ok, "secondary_magazine",
                                  "secondary_magazine = { value = 5, unit = \"count\", source = "
                                  "\"t\" }"),
                         "r.toml");
            }),
            "r.toml:12:1: error: 'course.secondary_magazine' must be 0 when no secondary weapon "
            "is allowed");
  EXPECT_EQ(errorOf([&] { parseRules(withLine(ok, "mines", ""), "r.toml"); }),
            "r.toml:2:1: error: missing key 'mines' in [course]");
  EXPECT_EQ(errorOf([&] {
              parseRules(withLine(ok, "mines", "mine = { value = true, source = \"t\" }"),
                         "r.toml");
            }),
            "r.toml:7:1: error: unknown key 'mine' in [course]");
}

TEST(Rules, OverrideTheProfilesFieldRoundAndMagazine) {
  const std::string text = withLine(kSmall, "round_length",
                                    "round_length = { value = 120, unit = \"s\", source = \"t\" }");
  const Course c = parseRules(text, "r.toml");
  Profile p = thesis();
  // The thesis profile's start poses, (+-6.5, -6.5), leave 12.75 / 24 ft
  // of body inside a 16-ft field; a 12-ft field's half is 6 ft.
  EXPECT_EQ(errorOf([&] { simbot::config::applyRules(c, p); }),
            "r.toml:3:1: error: under these rules robot A's start pose puts its body outside the "
            "field (profile " +
                p.file + ")");
  Profile q = thesis();
  q.field.start[0] = {-4, -4, 0};
  q.field.start[1] = {4, -4, 0};
  simbot::config::applyRules(c, q);
  EXPECT_DOUBLE_EQ(q.field.size_ft, 12);
  EXPECT_FALSE(q.field.divider);
  EXPECT_EQ(q.field.divider_height_ft, 0);
  EXPECT_DOUBLE_EQ(q.round_length_s, 120);
  EXPECT_EQ(q.robot.balls_per_gun, 10);
  EXPECT_FALSE(q.field.count_floor_skips);
  EXPECT_TRUE(q.referee.judge_scatter);
  EXPECT_DOUBLE_EQ(q.referee.detect_threshold, 100);
  EXPECT_TRUE(q.referee.scatter_scores);
  EXPECT_EQ(q.course.name, "small");
  // se3015-1997w keeps the thesis profile's field; floor skips now count.
  Profile w = thesis();
  simbot::config::applyRules(winter1997(), w);
  EXPECT_DOUBLE_EQ(w.field.size_ft, 16);
  EXPECT_TRUE(w.field.divider);
  EXPECT_DOUBLE_EQ(w.field.divider_north_ft, -4);  // the profile's
  EXPECT_TRUE(w.field.count_floor_skips);
}

TEST(Rules, WhatTheyForbidIsRefusedAtTheRule) {
  const Course w = winter1997(), y = year1996();
  const std::string file = kRulesDir + "/se3015-1997w.toml";
  const std::string file96 = kRulesDir + "/se3015-1996.toml";
  RunUses mine;
  mine.mines.push_back({"NAME", "scenarios/x.toml"});
  // Lines of the keys in rules/se3015-1997w.toml: mines 15, decoy_lights
  // 17, gun_magazine 14, secondary_magazine 20; se3015-1996.toml's
  // secondary_disc 20.
  EXPECT_EQ(errorOf([&] { checkRules(w, mine); }),
            file +
                ":15:1: error: course.mines = false forbids the mine 'NAME' placed by "
                "scenarios/x.toml");
  EXPECT_EQ(errorOf([&] { checkRules(y, mine); }), "");
  RunUses decoy;
  decoy.deployables.push_back({1, "decoy_light", 2, "hw/b.toml"});
  EXPECT_EQ(errorOf([&] { checkRules(w, decoy); }),
            file +
                ":17:1: error: course.decoy_lights = false forbids robot B's decoy_light "
                "(deployables in hw/b.toml)");
  EXPECT_EQ(errorOf([&] { checkRules(y, decoy); }), "");
  RunUses disc;
  disc.secondaryWeapons.push_back({0, "disc", 15, "hw/a.toml"});
  EXPECT_EQ(errorOf([&] { checkRules(w, disc); }), "");
  EXPECT_EQ(errorOf([&] { checkRules(y, disc); }),
            file96 +
                ":20:1: error: course.secondary_disc = false forbids robot A's secondary "
                "weapon 'disc' bound in hw/a.toml");
  disc.secondaryWeapons[0].magazine = 16;
  EXPECT_EQ(errorOf([&] { checkRules(w, disc); }),
            file +
                ":20:1: error: course.secondary_magazine = 15 forbids robot A's disc "
                "magazine of 16 rounds set by hw/a.toml");
  RunUses magazine;
  magazine.magazines.push_back({0, 15, "profiles/thesis-1997.toml"});
  magazine.magazines.push_back({1, 16, "hw/b.toml"});
  EXPECT_EQ(errorOf([&] { checkRules(w, magazine); }),
            file +
                ":14:1: error: course.gun_magazine = 15 forbids robot B's gun magazine of "
                "16 balls set by hw/b.toml (the standard gun's magazine remains as issued)");
  // No rules: nothing refused.
  EXPECT_EQ(errorOf([&] { checkRules(Course{}, mine); }), "");
  EXPECT_EQ(errorOf([&] { checkRules(Course{}, magazine); }), "");
}

}  // namespace
