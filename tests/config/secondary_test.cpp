// A hardware file's [secondary] table (config/profile.cpp, checkSecondary):
// the shipped disc launcher in internal units, and each bad value refused
// at its place.
#include <fstream>
#include <regex>

#include "tests/plant/plant_support.h"

using namespace plant_test;
using simbot::config::loadHardware;
using simbot::config::parseHardware;
using simbot::scheduler::ControllerKnobs;

namespace {

std::string hardwarePath(const char* name) {
  return std::string(SIMBOT_PROFILES_DIR) + "/hardware/" + name + ".toml";
}

// profiles/hardware/disc-launcher.toml: 15 discs on bit 6, 25 ft/s from
// 1.25 ft, tau 0.6 s, stopped below 4 ft/s, 4 in across (1/3 ft).
TEST(Secondary, TheShippedDiscLauncherLoadsInInternalUnits) {
  RobotParams params = thesis().robot;
  const RobotParams before = params;
  ControllerKnobs controller;
  const Hardware h = loadHardware(hardwarePath("disc-launcher"), params, controller);
  EXPECT_EQ(h.secondary.kind, SecondaryKind::Disc);
  EXPECT_EQ(h.disc_shooter_bit, 6);
  EXPECT_EQ(h.secondary.magazine, 15);
  EXPECT_EQ(h.secondary.launch_speed_fps, 25);
  EXPECT_EQ(h.secondary.launch_height_ft, 1.25);
  EXPECT_EQ(h.secondary.drag_time_s, 0.6);
  EXPECT_EQ(h.secondary.stop_speed_fps, 4);
  EXPECT_NEAR(h.secondary.diameter_ft, 1.0 / 3, 1e-15);
  EXPECT_EQ(h.gun_motor_bit[0], 3);  // the guns' defaults kept
  EXPECT_EQ(params.muzzle_speed_fps, before.muzzle_speed_fps);
  EXPECT_STREQ(secondaryKindName(h.secondary.kind), "disc");
  // Without the table: no secondary weapon, bit 6 logged only.
  const Hardware none = parseHardware("", "hw.toml", params, controller);
  EXPECT_EQ(none.secondary.kind, SecondaryKind::None);
  EXPECT_EQ(none.secondary.magazine, 0);
}

std::string shippedText() {
  std::ifstream in(hardwarePath("disc-launcher"));
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// The shipped file with the line that starts with `key` replaced.
std::string withLine(const std::string& key, const std::string& line) {
  std::string s = shippedText();
  const auto at = s.find("\n" + key + " ");
  EXPECT_NE(at, std::string::npos) << key;
  const auto end = s.find('\n', at + 1);
  s.replace(at + 1, end - at - 1, line);
  return s;
}

std::string errorOf(const std::string& text) {
  RobotParams params = thesis().robot;
  ControllerKnobs controller;
  try {
    parseHardware(text, "hw.toml", params, controller);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

// One line, FILE:LINE:COL, naming the problem.
void expectError(const std::string& text, int line, const std::string& says) {
  const std::string msg = errorOf(text);
  std::smatch m;
  ASSERT_TRUE(std::regex_match(msg, m, std::regex(R"(^hw\.toml:(\d+):(\d+): error: (.+)$)")))
      << msg;
  EXPECT_EQ(std::stoi(m[1]), line) << msg;
  EXPECT_NE(msg.find(says), std::string::npos) << msg;
}

int lineOfKey(const std::string& text, const std::string& key) {
  const auto at = text.find("\n" + key + " ");
  return 2 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

TEST(Secondary, BadValuesAreRefusedAtTheirPlace) {
  const std::string base = shippedText();
  auto at = [&](const std::string& key) { return lineOfKey(base, key); };
  expectError(withLine("magazine", R"(magazine = { value = 17, unit = "count", source = "x" })"),
              at("magazine"), "'secondary.magazine' must be in 0..16");
  expectError(
      withLine("launch_speed", R"(launch_speed = { value = 0.5, unit = "ft/s", source = "x" })"),
      at("launch_speed"), "'secondary.launch_speed' must be between 1 and 150 ft/s");
  expectError(
      withLine("launch_height", R"(launch_height = { value = 5, unit = "ft", source = "x" })"),
      at("launch_height"), "'secondary.launch_height' must be between 0.05 and 4 ft");
  expectError(withLine("drag_time", R"(drag_time = { value = 0, unit = "s", source = "x" })"),
              at("drag_time"), "'secondary.drag_time' must be between 0.01 and 60 s");
  expectError(withLine("diameter", R"(diameter = { value = 30, unit = "in", source = "x" })"),
              at("diameter"), "'secondary.diameter' must be between 0.01 and 2 ft");
  expectError(withLine("diameter", R"(diameter = { value = 4, unit = "s", source = "x" })"),
              at("diameter"), "wrong unit 's' for 'secondary.diameter'");
  expectError(withLine("bit", R"(bit = { value = 8, unit = "bit", source = "x" })"), at("bit"),
              "'secondary.bit' must be in 0..7");
  expectError(withLine("kind", R"(kind = { value = "net", source = "x" })"), at("kind"),
              "'secondary.kind' must be \"disc\"");
  expectError(withLine("stop_speed", R"(stop_speed = { value = 25, unit = "ft/s", source = "x" })"),
              at("stop_speed"), "secondary.stop_speed must be below secondary.launch_speed");
  expectError(withLine("stop_speed", R"(stop_speed = { value = 3, unit = "ft/s" })"),
              at("stop_speed"), "'secondary.stop_speed' has no 'source'");
  expectError(withLine("diameter", "# no diameter"), lineOfKey(base, "kind") - 1,
              "missing key 'diameter' in [secondary]");
  expectError(withLine("bit", R"(bit = { value = 4, unit = "bit", source = "x" })"),
              lineOfKey(base, "kind") - 1, "port B bit 4 is bound twice");
  // The bit once: [ports] disc_shooter or [secondary] bit.
  expectError("[ports]\ndisc_shooter = { value = 2, unit = \"bit\", source = \"x\" }\n" + base,
              2 + lineOfKey(base, "bit"), "the disc shooter's bit is given twice");
  expectError(withLine("magazine", R"(magazines = { value = 15, unit = "count", source = "x" })"),
              at("magazine"), "unknown key 'magazines' in [secondary]");
  EXPECT_EQ(errorOf(base), "");
}

// Without [secondary] bit the launcher fires on [ports] disc_shooter.
TEST(Secondary, TheBitMayComeFromPorts) {
  std::string text = withLine("bit", "# the bit from [ports]");
  text = "[ports]\ndisc_shooter = { value = 2, unit = \"bit\", source = \"x\" }\n" + text;
  RobotParams params = thesis().robot;
  ControllerKnobs controller;
  const Hardware h = parseHardware(text, "hw.toml", params, controller);
  EXPECT_EQ(h.disc_shooter_bit, 2);
  EXPECT_EQ(h.secondary.kind, SecondaryKind::Disc);
}

// A profile holds no robot's weapon: [secondary] belongs to a hardware file.
TEST(Secondary, AProfileHasNoSecondaryTable) {
  std::ifstream in(profilePath("thesis-1997"));
  std::string text(std::istreambuf_iterator<char>(in), {});
  text += "\n[secondary]\nkind = { value = \"disc\", source = \"x\" }\n";
  try {
    simbot::config::parseProfile(text, "p.toml");
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown section or key 'secondary'"), std::string::npos)
        << e.what();
  }
}

}  // namespace
