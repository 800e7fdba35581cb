// config/rules.cpp -- course rules (config.h "rules"): a rule set's
// [course] table read and checked as a profile's keys are
// (profile_keys.cpp courseTable), applied to a profile, and what a run
// uses refused where the rules forbid it. docs/rules.md describes the
// keys and the two shipped sets.
#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "config/config.h"
#include "config/profile_keys.h"
#include "config/text.h"

namespace simbot::config {
namespace {

// The place of `key` ("course.mines") in the rule set, else its first line.
std::pair<int, int> placeOf(const Course& rules, const std::string& key) {
  for (const auto& [name, place] : rules.keyPlaces)
    if (name == key) return place;
  for (const auto& [name, place] : rules.keyPlaces)
    if (name == "course") return place;
  return {1, 1};
}

[[noreturn]] void refuse(const Course& rules, const std::string& key, const std::string& message) {
  const auto [line, column] = placeOf(rules, key);
  throw ConfigError(rules.file, line, column, message);
}

const char* robotName(int robot) { return robot == 1 ? "B" : "A"; }

// Checks between the rules and the profile they are applied to: what a
// profile's own checks (profile.cpp crossChecks) say of its field.
void checkApplied(const Course& rules, const Profile& p) {
  const double half = p.field.size_ft / 2 + 1e-9;  // units converted to ft round a little
  const auto fail = [&](const std::string& what) {
    refuse(rules, "course.field_size",
           fmt::format("under these rules {} (profile {})", what, p.file));
  };
  if (p.field.wire_inset_ft * 2 >= p.field.size_ft) fail("the wire leaves no field inside it");
  if (std::abs(p.field.divider_x_ft) > half || std::abs(p.field.divider_south_ft) > half ||
      std::abs(p.field.divider_north_ft) > half)
    fail("the divider does not lie inside the field");
  if (p.field.divider_north_ft < p.field.divider_south_ft)
    fail("divider_north is south of divider_south");
  for (size_t i = 0; i < p.field.start.size(); ++i) {
    const plant::Pose& start = p.field.start[i];
    if (std::abs(start.x_ft) + p.robot.body_diameter_ft / 2 > half ||
        std::abs(start.y_ft) + p.robot.body_diameter_ft / 2 > half)
      fail(fmt::format("robot {}'s start pose puts its body outside the field",
                       robotName(static_cast<int>(i))));
  }
  if (p.referee.putback_ft * 2 >= p.field.size_ft - 2 * p.field.wire_inset_ft)
    fail("the referee's putback leaves no room inside the wire");
}

}  // namespace

Course parseRules(std::string_view text, const std::string& sourceName) {
  const toml::table doc = parseToml(text, sourceName);
  std::vector<const keys::KeyDef*> defs;
  for (const keys::KeyDef& d : keys::courseTable()) defs.push_back(&d);
  Profile p;
  keys::walkKeys(doc, defs, sourceName, {"name", "description"}, p);
  Course c = p.course;
  c.present = true;
  c.file = sourceName;
  if (!doc.get("name")) throw ConfigError(sourceName, 1, 1, "missing key 'name'");
  c.name = p.name;
  const toml::table* course = doc.get("course") ? doc.get("course")->as_table() : nullptr;
  if (!course) throw ConfigError(sourceName, 1, 1, "missing table [course]");
  const auto at = [](const toml::source_region& r) {
    return std::pair<int, int>(static_cast<int>(r.begin.line), static_cast<int>(r.begin.column));
  };
  c.keyPlaces.emplace_back("course", at(course->source()));
  for (auto&& [k, v] : *course)
    c.keyPlaces.emplace_back("course." + std::string(k.str()), at(k.source()));
  // Every key but the divider's geometry (the profile's where not given).
  for (const keys::KeyDef& d : keys::courseTable()) {
    const std::string key = d.key;
    if (key.rfind("divider_", 0) == 0 || course->get(key)) continue;
    const auto [line, column] = at(course->source());
    throw ConfigError(sourceName, line, column, fmt::format("missing key '{}' in [course]", key));
  }
  if (!c.secondary_disc && c.secondary_magazine != 0)
    refuse(c, "course.secondary_magazine",
           "'course.secondary_magazine' must be 0 when no secondary weapon is allowed");
  return c;
}

Course loadRules(const std::string& path) { return parseRules(readFile(path), path); }

std::optional<std::string> shippedRulesPath(const std::string& name) {
  const std::filesystem::path p = std::filesystem::path(SIMBOT_RULES_DIR) / (name + ".toml");
  std::error_code ec;
  if (!std::filesystem::is_regular_file(p, ec)) return std::nullopt;
  return p.string();
}

void applyRules(const Course& rules, Profile& profile) {
  plant::FieldParams& f = profile.field;
  f.size_ft = rules.field_size_ft;
  f.divider = rules.divider;
  const auto given = [](double v, double& into) {
    if (!std::isnan(v)) into = v;
  };
  given(rules.divider_x_ft, f.divider_x_ft);
  given(rules.divider_south_ft, f.divider_south_ft);
  given(rules.divider_north_ft, f.divider_north_ft);
  given(rules.divider_thickness_ft, f.divider_thickness_ft);
  given(rules.divider_height_ft, f.divider_height_ft);
  if (!rules.divider)  // the trace's run record then shows no divider
    f.divider_x_ft = f.divider_south_ft = f.divider_north_ft = f.divider_thickness_ft =
        f.divider_height_ft = 0;
  f.count_floor_skips = rules.floor_skips;
  profile.round_length_s = rules.round_length_s;
  profile.robot.balls_per_gun = rules.gun_magazine;
  profile.referee.judge_scatter = true;
  profile.referee.detect_threshold = rules.detect_threshold;
  profile.referee.scatter_scores = rules.scatter_scores;
  profile.course = rules;
  checkApplied(rules, profile);
}

void checkRules(const Course& rules, const RunUses& uses) {
  if (!rules.present) return;
  for (const RunUses::Mine& m : uses.mines)
    if (!rules.mines)
      refuse(
          rules, "course.mines",
          fmt::format("course.mines = false forbids the mine '{}' placed by {}", m.name, m.file));
  for (const RunUses::Carried& d : uses.deployables) {
    const std::string key = d.kind == "block"         ? "blocks"
                            : d.kind == "decoy_light" ? "decoy_lights"
                                                      : "decoy_screens";
    const bool allowed = key == "blocks"         ? rules.blocks
                         : key == "decoy_lights" ? rules.decoy_lights
                                                 : rules.decoy_screens;
    if (!allowed)
      refuse(rules, "course." + key,
             fmt::format("course.{} = false forbids robot {}'s {} (deployables in {})", key,
                         robotName(d.robot), d.kind, d.file));
  }
  for (const RunUses::Carried& w : uses.secondaryWeapons) {
    const bool allowed = w.kind == "disc" && rules.secondary_disc;
    if (!allowed)
      refuse(rules, "course.secondary_disc",
             fmt::format("course.secondary_disc = false forbids robot {}'s secondary weapon "
                         "'{}' bound in {}",
                         robotName(w.robot), w.kind, w.file));
    if (w.magazine > rules.secondary_magazine)
      refuse(rules, "course.secondary_magazine",
             fmt::format("course.secondary_magazine = {} forbids robot {}'s {} magazine of {} "
                         "rounds set by {}",
                         rules.secondary_magazine, robotName(w.robot), w.kind, w.magazine, w.file));
  }
  for (const RunUses::Magazine& m : uses.magazines)
    if (m.balls > rules.gun_magazine)
      refuse(rules, "course.gun_magazine",
             fmt::format("course.gun_magazine = {} forbids robot {}'s gun magazine of {} balls "
                         "set by {} (the standard gun's magazine remains as issued)",
                         rules.gun_magazine, robotName(m.robot), m.balls, m.file));
}

}  // namespace simbot::config
