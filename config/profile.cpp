// config/profile.cpp -- loading and checking TOML profiles and hardware files.
//
// Every physical number is an inline table { value, unit, source } so that a
// reader of the file sees where each number came from; options are
// { value = true/false, source = ... }. The key table (profile_keys.h) lists
// every key once; the loader walks the parsed document against it, so an
// unknown key, a missing key, a wrong type or a unit that does not fit the
// kind is always caught, and reported as FILE:LINE:COL: error: MESSAGE with
// toml++'s source positions (parse errors from toml++ are formatted the
// same way). Values are converted to the internal units at load: ft, s,
// ft/s, ft/s^2, degrees for user-facing angles, plain ratios and A/D
// readings; [controller]'s timer service, fast-forward and CPU revision
// become the VM's typed knobs (Profile::controller).
//
// A hardware file has an optional [ports] section (port B bit numbers), an
// optional [secondary] section (a secondary weapon: the disc launcher,
// all its keys but `bit` required) and may override the per-robot
// sections ([robot], [bumper], [eyes], [gun], [controller])
// with the same key names and the same checks; every key there is optional.
#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <optional>

#include "config/config.h"
#include "config/profile_keys.h"
#include "config/text.h"

namespace simbot::config {
namespace {

using keys::allowedUnits;
using keys::Bounds;
using keys::internalUnit;
using keys::KeyDef;
using keys::Kind;
using keys::Target;
using keys::unitFactor;
using plant::Hardware;
using plant::kMaxBallsPerGun;
using plant::kMaxRefereeLimit;

// A TOML number as a double. toml++ gives no double for an integer it
// cannot represent exactly (beyond 2^53), so integers are converted here.
std::optional<double> numberOf(const toml::node& n) {
  if (const auto* i = n.as_integer()) return static_cast<double>(i->get());
  if (const auto* f = n.as_floating_point()) return f->get();
  return std::nullopt;
}

class Checker {
 public:
  explicit Checker(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const toml::source_region& where, const std::string& msg) const {
    failAt(file_, where, msg);
  }

  toml::table parse(std::string_view text) const { return parseToml(text, file_); }
  const std::string& file() const { return file_; }
  // A hardware file's walk leaves [[deployables]] to readDeployables.
  void skipDeployables() { skipDeployables_ = true; }

  // Fails unless v (internal units) is within the key's bounds.
  void checkBounds(const KeyDef& def, const toml::node& at, const std::string& name,
                   double v) const {
    const Bounds& b = def.bounds;
    if (!std::isfinite(v)) fail(at.source(), fmt::format("'{}' must be finite", name));
    if (b.orZero && v == 0) return;
    if (v >= b.lo && v <= b.hi) return;
    fail(at.source(), fmt::format("'{}' must be {}between {} and {} {}, got {} {}", name,
                                  b.orZero ? "0 or " : "", b.lo, b.hi, internalUnit(def.kind), v,
                                  internalUnit(def.kind)));
  }

  // Applies one entry (an inline table) to its target.
  void apply(const KeyDef& def, const toml::node& node, Target t) const {
    const std::string name = fmt::format("{}.{}", def.section, def.key);
    const toml::table* tbl = node.as_table();
    if (!tbl)
      fail(node.source(),
           fmt::format(
               "'{}' must be a table {{ value = ..., {}source = \"...\" }}", name,
               def.kind == Kind::Bool || def.kind == Kind::Choice ? "" : "unit = \"...\", "));
    const toml::node* value = nullptr;
    const toml::node* unit = nullptr;
    const toml::node* source = nullptr;
    for (auto&& [k, v] : *tbl) {
      if (k.str() == "value") {
        value = &v;
      } else if (k.str() == "unit" && def.kind != Kind::Bool && def.kind != Kind::Choice) {
        unit = &v;
      } else if (k.str() == "source") {
        source = &v;
      } else {
        fail(k.source(), fmt::format("unknown field '{}' in '{}'", k.str(), name));
      }
    }
    if (!value) fail(node.source(), fmt::format("'{}' has no 'value'", name));
    if (!source) fail(node.source(), fmt::format("'{}' has no 'source'", name));
    if (!source->is_string())
      fail(source->source(), fmt::format("'{}.source' must be a string", name));

    double factor = 1.0;
    if (def.kind != Kind::Bool && def.kind != Kind::Choice) {
      if (!unit)
        fail(node.source(),
             fmt::format("'{}' has no 'unit' (one of: {})", name, allowedUnits(def.kind)));
      if (!unit->is_string()) fail(unit->source(), fmt::format("'{}.unit' must be a string", name));
      const std::string u = *unit->value<std::string>();
      factor = unitFactor(def.kind, u);
      if (std::isnan(factor))
        fail(unit->source(), fmt::format("wrong unit '{}' for '{}' (expected one of: {})", u, name,
                                         allowedUnits(def.kind)));
    }

    switch (def.kind) {
      case Kind::Bool:
        if (!value->is_boolean())
          fail(value->source(), fmt::format("'{}' must be true or false", name));
        *t.b = *value->value<bool>();
        return;
      case Kind::Choice: {
        const auto word = value->value<std::string>();
        // One of `words` into `out`, or an error listing them.
        const auto pick = [&](const auto& words, auto* out) {
          std::string listed;
          for (size_t w = 0; w < words.size(); ++w) {
            if (word && *word == words[w].first) {
              *out = words[w].second;
              return;
            }
            listed += fmt::format("{}\"{}\"",
                                  w == 0                  ? ""
                                  : w + 1 == words.size() ? " or "
                                                          : ", ",
                                  words[w].first);
          }
          fail(value->source(), fmt::format("'{}' must be {}", name, listed));
        };
        if (t.cpu)
          pick(keys::kCpuChoices, t.cpu);
        else if (t.secondary)
          pick(keys::kSecondaryChoices, t.secondary);
        else
          pick(keys::kChoices, t.choice);
        return;
      }
      case Kind::Count:
      case Kind::Step:
      case Kind::Bit: {
        const auto* integer = value->as_integer();
        if (!integer) fail(value->source(), fmt::format("'{}' must be an integer", name));
        const std::int64_t v = integer->get();
        if (v < static_cast<std::int64_t>(def.bounds.lo) ||
            v > static_cast<std::int64_t>(def.bounds.hi))
          fail(value->source(),
               fmt::format("'{}' must be in {}..{}", name, def.bounds.lo, def.bounds.hi));
        *t.i = static_cast<int>(v);
        return;
      }
      case Kind::SpeedTable: {
        const toml::array* arr = value->as_array();
        if (!arr) fail(value->source(), fmt::format("'{}' must be an array of 16 numbers", name));
        if (arr->size() != 16)
          fail(value->source(),
               fmt::format("'{}' must have 16 entries (steps 0..f), has {}", name, arr->size()));
        for (std::size_t i = 0; i < 16; ++i) {
          const toml::node& e = *arr->get(i);
          const auto number = numberOf(e);
          if (!number) fail(e.source(), fmt::format("'{}[{}]' must be a number", name, i));
          const double v = *number * factor;
          checkBounds(def, e, fmt::format("{}[{}]", name, i), v);
          (*t.table)[i] = v;
        }
        return;
      }
      default: {
        const auto number = numberOf(*value);
        if (!number) fail(value->source(), fmt::format("'{}' must be a number", name));
        const double v = *number * factor;
        checkBounds(def, *value, name, v);
        *t.d = v;
        return;
      }
    }
  }

  // Walks the document. `required`: every listed key must be present.
  // `allowed` filters which keys may appear at all.
  void walk(const toml::table& doc, const std::vector<const KeyDef*>& defs, bool required,
            const std::vector<std::string>& plainStrings, Profile& p, Hardware& h,
            std::vector<std::string>* seenStrings) const {
    std::vector<const KeyDef*> seen;
    for (auto&& [sk, sv] : doc) {
      const std::string section(sk.str());
      if (skipDeployables_ && section == "deployables") continue;
      if (std::find(plainStrings.begin(), plainStrings.end(), section) != plainStrings.end()) {
        if (!sv.is_string()) fail(sv.source(), fmt::format("'{}' must be a string", section));
        if (seenStrings) seenStrings->push_back(section);
        if (section == "name") p.name = *sv.value<std::string>();
        continue;
      }
      bool known = false;
      for (const KeyDef* d : defs) known = known || section == d->section;
      if (!known) fail(sk.source(), fmt::format("unknown section or key '{}'", section));
      const toml::table* st = sv.as_table();
      if (!st) fail(sv.source(), fmt::format("'{}' must be a table", section));
      for (auto&& [k, v] : *st) {
        const KeyDef* def = nullptr;
        for (const KeyDef* d : defs)
          if (section == d->section && k.str() == d->key) def = d;
        if (!def) fail(k.source(), fmt::format("unknown key '{}' in [{}]", k.str(), section));
        apply(*def, v, def->target(p, h));
        seen.push_back(def);
      }
    }
    if (!required) return;
    for (const KeyDef* d : defs) {
      if (std::find(seen.begin(), seen.end(), d) != seen.end()) continue;
      const toml::node* sec = doc.get(d->section);
      if (d->optionalSection && !sec) continue;
      fail(sec ? sec->source() : doc.source(),
           fmt::format("missing key '{}' in [{}]", d->key, d->section));
    }
  }

 private:
  std::string file_;
  bool skipDeployables_ = false;
};

// [battery]'s values against each other (a profile's, or a hardware
// file's after its overrides), reported at the [battery] table.
void batteryChecks(const plant::BatteryParams& b, const Checker& c, const toml::table& doc) {
  const toml::node* n = doc.get("battery");
  if (!n) return;
  if (b.voltage_empty_v >= b.voltage_full_v)
    c.fail(n->source(), "battery.voltage_empty must be below battery.voltage_full");
  if (b.brownout_v >= b.voltage_full_v)
    c.fail(n->source(), "battery.brownout_voltage must be below battery.voltage_full");
}

void crossChecks(const Profile& p, const Checker& c, const toml::table& doc) {
  // Checks between keys; reported at the section that holds the second key.
  auto where = [&](const char* section) {
    const toml::node* n = doc.get(section);
    return n ? n->source() : doc.source();
  };
  const double half = p.field.size_ft / 2 + 1e-9;  // units converted to ft round a little
  if (p.field.wire_inset_ft * 2 >= p.field.size_ft)
    c.fail(where("field"), "wire_inset leaves no field inside the wire");
  if (std::abs(p.field.divider_x_ft) > half || std::abs(p.field.divider_south_ft) > half ||
      std::abs(p.field.divider_north_ft) > half)
    c.fail(where("field"), "the divider must lie inside the field");
  for (const plant::Pose& start : p.field.start)
    if (std::abs(start.x_ft) + p.robot.body_diameter_ft / 2 > half ||
        std::abs(start.y_ft) + p.robot.body_diameter_ft / 2 > half)
      c.fail(where("start"), "a start pose puts the body outside the field");
  // Two bodies on one mark (a scenario refuses the same; a match always
  // places both robots). The placement spread may move them a few inches.
  if (p.field.start.size() >= 2 && std::hypot(p.field.start[0].x_ft - p.field.start[1].x_ft,
                                              p.field.start[0].y_ft - p.field.start[1].y_ft) <=
                                       p.robot.body_diameter_ft + 2 * p.field.placement_radius_ft)
    c.fail(where("start"),
           "the two start poses overlap (their centres must be more than the body's diameter "
           "plus twice placement_radius apart)");
  if (p.robot.eye_background >= p.robot.eye_max)
    c.fail(where("eyes"), "background must be below max");
  if (p.field.divider_north_ft < p.field.divider_south_ft)
    c.fail(where("field"), "divider_north must not be south of divider_south");
  if (p.robot.edge_detector_inset_ft * 2 >= p.robot.body_diameter_ft)
    c.fail(where("robot"), "edge_detector_inset puts the detectors past the centre");
  if (p.referee.reflex_limit > kMaxRefereeLimit || p.referee.event_limit > kMaxRefereeLimit)
    c.fail(where("referee"),
           fmt::format("reflex_limit and event_limit must be at most {}", kMaxRefereeLimit));
  if (p.robot.balls_per_gun > kMaxBallsPerGun)
    c.fail(where("gun"), fmt::format("balls_per_gun must be at most {}", kMaxBallsPerGun));
  if (p.robot.jam_probability + p.robot.misfire_probability > 1)
    c.fail(where("gun"), "jam_probability + misfire_probability must be at most 1");
  for (const double trim : {p.robot.left_trim, p.robot.right_trim})
    if (trim * (1 - p.robot.trim_spread) < 0.5 || trim * (1 + p.robot.trim_spread) > 2)
      c.fail(where("robot"), "trim_spread takes a wheel's trim outside 0.5..2");
  if (p.referee.putback_ft * 2 >= p.field.size_ft - 2 * p.field.wire_inset_ft)
    c.fail(where("referee"), "putback leaves no room inside the wire");
  batteryChecks(p.robot.battery, c, doc);
}

// A hardware file's [secondary] table, once walked: every key but `bit`
// given, the bit given once, and a disc that flies.
void checkSecondary(const toml::table& doc, const Checker& c, const Hardware& h) {
  const toml::node* node = doc.get("secondary");
  if (!node) return;
  const toml::table& sec = *node->as_table();  // walk() checked it is a table
  for (const KeyDef& d : keys::secondaryTable())
    if (std::string_view(d.key) != "bit" && !sec.contains(d.key))
      c.fail(node->source(), fmt::format("missing key '{}' in [secondary]", d.key));
  const toml::table* ports = doc.get("ports") ? doc.get("ports")->as_table() : nullptr;
  if (ports && ports->contains("disc_shooter") && sec.contains("bit"))
    c.fail(sec.get("bit")->source(),
           "the disc shooter's bit is given twice: [ports] disc_shooter and [secondary] bit");
  if (h.secondary.stop_speed_fps >= h.secondary.launch_speed_fps)
    c.fail(sec.get("stop_speed")->source(),
           "secondary.stop_speed must be below secondary.launch_speed");
}

// A hardware file's [[deployables]]: each table's `kind` (a plain
// string), then the keys that kind needs, all of them and no other, each
// a { value, unit, source } entry checked as a profile's. Appended to
// h.deployables in file order.
void readDeployables(const toml::table& doc, const Checker& c, Profile& p, Hardware& h) {
  const toml::node* node = doc.get("deployables");
  if (!node) return;
  const toml::array* arr = node->as_array();
  if (!arr || !arr->is_array_of_tables())
    c.fail(node->source(), "'deployables' must be an array of tables ([[deployables]])");
  struct KindKeys {
    const char* word;
    plant::DeployKind kind;
    std::vector<std::string> keys;
  };
  static const std::array<KindKeys, 3> kinds = {{
      {"block",
       plant::DeployKind::Block,
       {"bit", "count", "width", "depth", "height", "mass", "floor_friction"}},
      {"decoy_light", plant::DeployKind::DecoyLight, {"bit", "count", "intensity", "height"}},
      {"decoy_screen", plant::DeployKind::DecoyScreen, {"bit", "count", "width", "height"}},
  }};
  for (const toml::node& e : *arr) {
    const toml::table& t = *e.as_table();
    const toml::node* kindNode = t.get("kind");
    if (!kindNode) c.fail(t.source(), "[[deployables]] has no 'kind'");
    const auto word = kindNode->value<std::string>();
    const KindKeys* kk = nullptr;
    for (const KindKeys& k : kinds)
      if (word && *word == k.word) kk = &k;
    if (!kk)
      c.fail(kindNode->source(),
             "'deployables.kind' must be \"block\", \"decoy_light\" or \"decoy_screen\"");
    if (h.deployables.size() >= static_cast<std::size_t>(plant::kMaxDeployKinds))
      c.fail(t.source(), fmt::format("at most {} [[deployables]]", plant::kMaxDeployKinds));
    h.deployables.push_back(plant::Deployable{});
    h.deployables.back().kind = kk->kind;
    for (auto&& [k, v] : t) {
      if (k.str() == "kind") continue;
      const KeyDef* def = nullptr;
      for (const KeyDef& d : keys::deployableTable())
        if (k.str() == d.key) def = &d;
      if (!def || std::find(kk->keys.begin(), kk->keys.end(), k.str()) == kk->keys.end()) {
        std::string list;
        for (const std::string& w : kk->keys) list += (list.empty() ? "" : ", ") + w;
        failAt(c.file(), k.source(),
               fmt::format("unknown key '{}' in a {} [[deployables]] (expected one of: kind, {})",
                           k.str(), kk->word, list));
      }
      c.apply(*def, v, def->target(p, h));
    }
    for (const std::string& key : kk->keys)
      if (!t.contains(key))
        c.fail(t.source(), fmt::format("missing key '{}' in a {} [[deployables]]", key, kk->word));
    // The plant's block table is fixed (plant.h kMaxBlocks).
    int blocks = 0;
    for (const plant::Deployable& d : h.deployables)
      if (d.kind == plant::DeployKind::Block) blocks += d.count;
    if (blocks > plant::kMaxBlocksPerRobot)
      c.fail(t.source(), fmt::format("at most {} blocks in a robot's [[deployables]], {} here",
                                     plant::kMaxBlocksPerRobot, blocks));
  }
}

}  // namespace

Profile parseProfile(std::string_view text, const std::string& sourceName) {
  Checker c(sourceName);
  const toml::table doc = c.parse(text);
  Profile p;
  Hardware h;
  std::vector<const KeyDef*> defs;
  for (const KeyDef& d : keys::keyTable()) defs.push_back(&d);
  std::vector<std::string> strings;
  c.walk(doc, defs, true, {"name", "description"}, p, h, &strings);
  if (std::find(strings.begin(), strings.end(), "name") == strings.end())
    c.fail(doc.source(), "missing key 'name'");
  crossChecks(p, c, doc);
  p.file = sourceName;
  return p;
}

Profile loadProfile(const std::string& path) { return parseProfile(readFile(path), path); }

void keys::walkKeys(const toml::table& doc, const std::vector<const KeyDef*>& defs,
                    const std::string& file, const std::vector<std::string>& plainStrings,
                    Profile& p) {
  Hardware h;
  Checker(file).walk(doc, defs, false, plainStrings, p, h, nullptr);
}

std::optional<std::string> shippedProfilePath(const std::string& name) {
  const std::filesystem::path p = std::filesystem::path(SIMBOT_PROFILES_DIR) / (name + ".toml");
  std::error_code ec;
  if (!std::filesystem::is_regular_file(p, ec)) return std::nullopt;
  return p.string();
}

Hardware parseHardware(std::string_view text, const std::string& sourceName,
                       plant::RobotParams& params, scheduler::ControllerKnobs& controller) {
  Checker c(sourceName);
  const toml::table doc = c.parse(text);
  Profile p;
  p.robot = params;
  p.controller = controller;
  Hardware h;
  std::vector<const KeyDef*> defs;
  for (const KeyDef& d : keys::portTable()) defs.push_back(&d);
  for (const KeyDef& d : keys::secondaryTable()) defs.push_back(&d);
  for (const KeyDef& d : keys::keyTable())
    if (d.perRobot) defs.push_back(&d);
  // Field-wide keys are not per robot: name them in the error.
  for (auto&& [sk, sv] : doc) {
    for (const KeyDef& d : keys::keyTable())
      if (!d.perRobot && sk.str() == d.section)
        c.fail(sk.source(),
               fmt::format("[{}] is arena-wide and cannot be overridden per robot", d.section));
  }
  c.skipDeployables();  // [[deployables]] is read apart (readDeployables)
  c.walk(doc, defs, false, {"name", "description"}, p, h, nullptr);
  checkSecondary(doc, c, h);
  readDeployables(doc, c, p, h);
  std::array<int, 5> bits = {h.gun_motor_bit[0], h.gun_solenoid_bit[0], h.gun_motor_bit[1],
                             h.gun_solenoid_bit[1], h.disc_shooter_bit};
  // A deployable's bit may be no weapon's and no other deployable's.
  for (std::size_t k = 0; k < h.deployables.size(); ++k) {
    const int b = h.deployables[k].bit;
    const toml::node& at = *doc.get("deployables")->as_array()->get(k)->as_table()->get("bit");
    for (std::size_t j = 0; j < bits.size(); ++j)
      if (bits[j] == b)
        c.fail(at.source(), fmt::format("port B bit {} is bound twice: a [[deployables]] "
                                        "and {}",
                                        b,
                                        std::array<const char*, 5>{
                                            "gun 1's motor", "gun 1's solenoid", "gun 2's motor",
                                            "gun 2's solenoid", "the disc shooter"}[j]));
    for (std::size_t j = 0; j < k; ++j)
      if (h.deployables[j].bit == b)
        c.fail(at.source(), fmt::format("port B bit {} is bound twice: two [[deployables]]", b));
  }
  for (std::size_t i = 0; i < bits.size(); ++i)
    for (std::size_t j = i + 1; j < bits.size(); ++j)
      if (bits[i] == bits[j]) {
        const toml::node* n = doc.get("ports") ? doc.get("ports") : doc.get("secondary");
        c.fail(n ? n->source() : doc.source(),
               fmt::format("port B bit {} is bound twice", bits[i]));
      }
  if (p.robot.balls_per_gun > kMaxBallsPerGun) {
    const toml::node* n = doc.get("gun");
    c.fail(n ? n->source() : doc.source(),
           fmt::format("balls_per_gun must be at most {}", kMaxBallsPerGun));
  }
  if (p.robot.jam_probability + p.robot.misfire_probability > 1) {
    const toml::node* n = doc.get("gun");
    c.fail(n ? n->source() : doc.source(),
           "jam_probability + misfire_probability must be at most 1");
  }
  for (const double trim : {p.robot.left_trim, p.robot.right_trim})
    if (trim * (1 - p.robot.trim_spread) < 0.5 || trim * (1 + p.robot.trim_spread) > 2) {
      const toml::node* n = doc.get("robot");
      c.fail(n ? n->source() : doc.source(), "trim_spread takes a wheel's trim outside 0.5..2");
    }
  // A hardware file that enables a battery the profile has no [battery]
  // for (capacity 0) gives all of it (every key required, as in a profile).
  if (const toml::node* n = doc.get("battery"); n && p.robot.battery.enabled) {
    const toml::table* t = n->as_table();
    for (const KeyDef& d : keys::keyTable())
      if (d.optionalSection && params.battery.capacity_c == 0 && t && !t->contains(d.key))
        c.fail(n->source(), fmt::format("missing key '{}' in [battery] (the profile has no "
                                        "battery, so the hardware file gives all of it)",
                                        d.key));
  }
  batteryChecks(p.robot.battery, c, doc);
  params = p.robot;
  controller = p.controller;
  return h;
}

Hardware loadHardware(const std::string& path, plant::RobotParams& params,
                      scheduler::ControllerKnobs& controller) {
  return parseHardware(readFile(path), path, params, controller);
}

plant::ArenaConfig makeArenaConfig(const Profile& profile, int robotCount) {
  plant::ArenaConfig c;
  c.field = profile.field;
  c.referee = profile.referee;
  for (int i = 0; i < robotCount && i < 2; ++i)
    c.robots.push_back(plant::RobotSetup{profile.robot, Hardware{},
                                         profile.field.start[static_cast<std::size_t>(i)]});
  return c;
}

}  // namespace simbot::config
