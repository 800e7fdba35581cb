// plant/profile.cpp -- loading and checking TOML profiles and hardware files.
//
// Every physical number is an inline table { value, unit, source } so that a
// reader of the file sees where each number came from; options are
// { value = true/false, source = ... }. One table (kKeys) lists every key
// once: its section, kind (which fixes the accepted units and the range
// check), and where it lands in Profile. The loader walks the parsed
// document against that table, so an unknown key, a missing key, a wrong
// type or a unit that does not fit the kind is always caught, and reported
// as FILE:LINE:COL: error: MESSAGE with toml++'s source positions (parse
// errors from toml++ are formatted the same way). Values are converted to
// the internal units at load: ft, s, ft/s, ft/s^2, degrees for user-facing
// angles, plain ratios and A/D readings.
//
// A hardware file has an optional [ports] section (port B bit numbers) and
// may override the per-robot sections ([robot], [bumper], [eyes], [gun],
// [controller])
// with the same key names and the same checks; every key there is optional.
#include <fmt/format.h>
#include <toml++/toml.h>

#include <array>
#include <cmath>
#include <functional>
#include <optional>

#include "plant/plant.h"

namespace simbot::plant {
namespace {

enum class Kind {
  Length,       // ft, in, m, cm, mm
  Speed,        // ft/s, in/s, m/s
  Time,         // s, ms
  Angle,        // deg, rad  (stored in degrees)
  Accel,        // ft/s^2, m/s^2
  Mass,         // lb, kg
  Ratio,        // "1"
  Probability,  // "1", in [0, 1]
  Reading,      // "reading" (A/D reading units)
  Count,        // "count", integer >= 0
  Step,         // "step", integer 0..15
  Bit,          // "bit", integer 0..7
  Bool,         // no unit
  Choice,       // no unit; one of the words in kChoices, stored as its index
  SpeedTable,   // array of 16 speeds
};

// The physically sensible values of a key, in internal units (ft, s,
// ft/s, ft/s^2, deg, readings, counts): wide enough for any real robot of
// the kind, narrow enough that the integrator never meets a value that
// breaks it. `orZero`: 0 is allowed too (an instant motor or gun wheel),
// else the value must be at least `lo`.
struct Bounds {
  double lo, hi;
  bool orZero = false;
};

// The words a Choice key accepts (only [controller] timer_service): the
// index of the word is what lands in the target (plant.h TimerService).
constexpr std::array<const char*, 3> kChoices = {"auto", "always", "never"};

struct Target {
  double* d = nullptr;
  int* i = nullptr;
  bool* b = nullptr;
  std::array<double, 16>* table = nullptr;
};

struct KeyDef {
  const char* section;
  const char* key;
  Kind kind;
  Bounds bounds;
  bool perRobot;
  std::function<Target(Profile&, Hardware&)> target;
};

#define D(expr)                 \
  [](Profile& p, Hardware& h) { \
    (void)p;                    \
    (void)h;                    \
    Target t;                   \
    t.d = &(expr);              \
    return t;                   \
  }
#define I(expr)                 \
  [](Profile& p, Hardware& h) { \
    (void)p;                    \
    (void)h;                    \
    Target t;                   \
    t.i = &(expr);              \
    return t;                   \
  }
#define B(expr)                 \
  [](Profile& p, Hardware& h) { \
    (void)p;                    \
    (void)h;                    \
    Target t;                   \
    t.b = &(expr);              \
    return t;                   \
  }

const std::vector<KeyDef>& keyTable() {
  static const std::vector<KeyDef> keys = {
      {"field", "size", Kind::Length, {1, 100}, false, D(p.field.size_ft)},
      {"field", "wire_inset", Kind::Length, {0, 10}, false, D(p.field.wire_inset_ft)},
      {"field", "wire_sensitivity", Kind::Length, {0.01, 1}, false, D(p.field.wire_sensitivity_ft)},
      {"field", "field_walls", Kind::Bool, {0, 0}, false, B(p.field.field_walls)},
      {"field", "divider_x", Kind::Length, {-50, 50}, false, D(p.field.divider_x_ft)},
      {"field", "divider_south", Kind::Length, {-50, 50}, false, D(p.field.divider_south_ft)},
      {"field", "divider_north", Kind::Length, {-50, 50}, false, D(p.field.divider_north_ft)},
      {"field", "divider_thickness", Kind::Length, {0, 2}, false, D(p.field.divider_thickness_ft)},
      {"field", "divider_height", Kind::Length, {0, 20}, false, D(p.field.divider_height_ft)},
      {"start", "a_x", Kind::Length, {-50, 50}, false, D(p.field.start[0].x_ft)},
      {"start", "a_y", Kind::Length, {-50, 50}, false, D(p.field.start[0].y_ft)},
      {"start", "a_heading", Kind::Angle, {-360, 360}, false, D(p.field.start[0].heading_deg)},
      {"start", "b_x", Kind::Length, {-50, 50}, false, D(p.field.start[1].x_ft)},
      {"start", "b_y", Kind::Length, {-50, 50}, false, D(p.field.start[1].y_ft)},
      {"start", "b_heading", Kind::Angle, {-360, 360}, false, D(p.field.start[1].heading_deg)},
      // Hand placement: a few inches, a few degrees (profiles/default.toml);
      // placeByHand keeps every body inside the field whatever the radius.
      {"start", "placement_radius", Kind::Length, {0, 2}, false, D(p.field.placement_radius_ft)},
      {"start", "placement_heading", Kind::Angle, {0, 45}, false, D(p.field.placement_heading_deg)},
      {"robot", "body_diameter", Kind::Length, {0.1, 5}, true, D(p.robot.body_diameter_ft)},
      {"robot", "target_height", Kind::Length, {0.1, 10}, true, D(p.robot.target_height_ft)},
      {"robot",
       "edge_detector_inset",
       Kind::Length,
       {0, 2.5},
       true,
       D(p.robot.edge_detector_inset_ft)},
      {"robot", "wheel_diameter", Kind::Length, {0.05, 2}, true, D(p.robot.wheel_diameter_ft)},
      {"robot", "track", Kind::Length, {0.05, 5}, true, D(p.robot.track_ft)},
      {"robot",
       "speed_table",
       Kind::SpeedTable,
       {0, 20},
       true,
       [](Profile& p, Hardware&) {
         Target t;
         t.table = &p.robot.speed_table_fps;
         return t;
       }},
      {"robot", "left_trim", Kind::Ratio, {0.5, 2}, true, D(p.robot.left_trim)},
      {"robot", "right_trim", Kind::Ratio, {0.5, 2}, true, D(p.robot.right_trim)},
      // At most 0.25: a drawn trim stays within 0.75..1.25 of the given one
      // (crossChecks keeps it within left_trim/right_trim's own range).
      {"robot", "trim_spread", Kind::Ratio, {0, 0.25}, true, D(p.robot.trim_spread)},
      {"robot", "motor_lag", Kind::Time, {0.001, 10, true}, true, D(p.robot.motor_lag_s)},
      // Only the ratio of the two robots' masses matters (contact.h: how
      // one pushes the other); the range spans any robot a student builds.
      {"robot", "mass", Kind::Mass, {0.5, 500}, true, D(p.robot.mass_lb)},
      {"bumper", "reflex_distance", Kind::Length, {0.05, 20}, true, D(p.robot.reflex_distance_ft)},
      {"bumper", "reflex_speed_step", Kind::Step, {0, 15}, true, I(p.robot.reflex_speed_step)},
      {"eyes", "max", Kind::Reading, {16, 65535}, true, D(p.robot.eye_max)},
      {"eyes", "background", Kind::Reading, {0, 65535}, true, D(p.robot.eye_background)},
      {"eyes", "saturation_distance", Kind::Length, {0.1, 50}, true, D(p.robot.eye_saturation_ft)},
      {"eyes", "left_width", Kind::Length, {0.001, 1}, true, D(p.robot.left_eye_width)},
      {"eyes", "right_width", Kind::Length, {0.001, 1}, true, D(p.robot.right_eye_width)},
      {"eyes", "nose", Kind::Length, {0.001, 1}, true, D(p.robot.eye_nose)},
      {"eyes", "noise_sigma", Kind::Reading, {0, 4096}, true, D(p.robot.noise_sigma)},
      {"eyes",
       "bad_reading_probability",
       Kind::Probability,
       {0, 1},
       true,
       D(p.robot.bad_reading_probability)},
      {"eyes", "thesis_swapped_eyes", Kind::Bool, {0, 0}, true, B(p.robot.thesis_swapped_eyes)},
      {"gun", "wheel_lag", Kind::Time, {0.001, 10, true}, true, D(p.robot.gun_wheel_lag_s)},
      {"gun", "wheel_coast", Kind::Time, {0.001, 60, true}, true, D(p.robot.gun_wheel_coast_s)},
      {"gun", "motors_always_on", Kind::Bool, {0, 0}, true, B(p.robot.gun_motors_always_on)},
      {"gun", "stroke_time", Kind::Time, {0, 2}, true, D(p.robot.stroke_s)},
      {"gun", "muzzle_speed", Kind::Speed, {1, 1000}, true, D(p.robot.muzzle_speed_fps)},
      // Below 1, so every drawn speed is positive.
      {"gun", "muzzle_speed_spread", Kind::Ratio, {0, 0.5}, true, D(p.robot.muzzle_speed_spread)},
      {"gun", "launch_height", Kind::Length, {0.05, 10}, true, D(p.robot.launch_height_ft)},
      {"gun", "balls_per_gun", Kind::Count, {0, kMaxBallsPerGun}, true, I(p.robot.balls_per_gun)},
      {"gun", "jam_probability", Kind::Probability, {0, 1}, true, D(p.robot.jam_probability)},
      {"gun",
       "misfire_probability",
       Kind::Probability,
       {0, 1},
       true,
       D(p.robot.misfire_probability)},
      {"controller", "random_memory", Kind::Bool, {0, 0}, true, B(p.robot.random_memory)},
      {"controller", "timer_service", Kind::Choice, {0, 0}, true, I(p.robot.timer_service)},
      {"controller", "fast_forward", Kind::Bool, {0, 0}, true, B(p.robot.fast_forward)},
      {"projectile", "gravity", Kind::Accel, {1, 1000}, false, D(p.field.gravity_fps2)},
      {"projectile", "count_floor_skips", Kind::Bool, {0, 0}, false, B(p.field.count_floor_skips)},
      {"referee",
       "reflex_limit",
       Kind::Count,
       {0, kMaxRefereeLimit},
       false,
       I(p.referee.reflex_limit)},
      {"referee",
       "event_limit",
       Kind::Count,
       {0, kMaxRefereeLimit},
       false,
       I(p.referee.event_limit)},
      {"referee", "window", Kind::Time, {0.1, 3600}, false, D(p.referee.window_s)},
      {"referee", "putback", Kind::Length, {0, 10}, false, D(p.referee.putback_ft)},
      {"referee", "turn", Kind::Angle, {-360, 360}, false, D(p.referee.turn_deg)},
      {"match", "round_length", Kind::Time, {1, 1e6}, false, D(p.round_length_s)},
      // At least the serial port's last two characters (2.1 ms): the port
      // is reset at the reload (scheduler kMinReloadDelay).
      {"match", "reload_delay", Kind::Time, {0.01, 3600}, false, D(p.reload_delay_s)},
  };
  return keys;
}

const std::vector<KeyDef>& portTable() {
  static const std::vector<KeyDef> keys = {
      {"ports", "gun1_motor", Kind::Bit, {0, 7}, true, I(h.gun_motor_bit[0])},
      {"ports", "gun1_solenoid", Kind::Bit, {0, 7}, true, I(h.gun_solenoid_bit[0])},
      {"ports", "gun2_motor", Kind::Bit, {0, 7}, true, I(h.gun_motor_bit[1])},
      {"ports", "gun2_solenoid", Kind::Bit, {0, 7}, true, I(h.gun_solenoid_bit[1])},
      {"ports", "disc_shooter", Kind::Bit, {0, 7}, true, I(h.disc_shooter_bit)},
  };
  return keys;
}

#undef D
#undef I
#undef B

// Conversion factor to the internal unit, or NaN if the unit is not allowed.
double unitFactor(Kind k, std::string_view u) {
  switch (k) {
    case Kind::Length:
      if (u == "ft") return 1.0;
      if (u == "in") return 1.0 / 12.0;
      if (u == "m") return 1.0 / 0.3048;
      if (u == "cm") return 1.0 / 30.48;
      if (u == "mm") return 1.0 / 304.8;
      break;
    case Kind::Speed:
    case Kind::SpeedTable:
      if (u == "ft/s") return 1.0;
      if (u == "in/s") return 1.0 / 12.0;
      if (u == "m/s") return 1.0 / 0.3048;
      break;
    case Kind::Time:
      if (u == "s") return 1.0;
      if (u == "ms") return 1e-3;
      break;
    case Kind::Angle:
      if (u == "deg") return 1.0;
      if (u == "rad") return 180.0 / 3.14159265358979323846;
      break;
    case Kind::Accel:
      if (u == "ft/s^2") return 1.0;
      if (u == "m/s^2") return 1.0 / 0.3048;
      break;
    case Kind::Mass:
      if (u == "lb") return 1.0;
      if (u == "kg") return 1.0 / 0.45359237;
      break;
    case Kind::Ratio:
    case Kind::Probability:
      if (u == "1") return 1.0;
      break;
    case Kind::Reading:
      if (u == "reading") return 1.0;
      break;
    case Kind::Count:
      if (u == "count") return 1.0;
      break;
    case Kind::Step:
      if (u == "step") return 1.0;
      break;
    case Kind::Bit:
      if (u == "bit") return 1.0;
      break;
    case Kind::Bool:
    case Kind::Choice:
      break;
  }
  return std::nan("");
}

const char* allowedUnits(Kind k) {
  switch (k) {
    case Kind::Length:
      return "ft, in, m, cm, mm";
    case Kind::Speed:
    case Kind::SpeedTable:
      return "ft/s, in/s, m/s";
    case Kind::Time:
      return "s, ms";
    case Kind::Angle:
      return "deg, rad";
    case Kind::Accel:
      return "ft/s^2, m/s^2";
    case Kind::Mass:
      return "lb, kg";
    case Kind::Ratio:
    case Kind::Probability:
      return "1";
    case Kind::Reading:
      return "reading";
    case Kind::Count:
      return "count";
    case Kind::Step:
      return "step";
    case Kind::Bit:
      return "bit";
    case Kind::Bool:
    case Kind::Choice:
      return "(none)";
  }
  return "";
}

// The internal unit of a kind, for messages about its range.
const char* internalUnit(Kind k) {
  switch (k) {
    case Kind::Length:
      return "ft";
    case Kind::Speed:
    case Kind::SpeedTable:
      return "ft/s";
    case Kind::Time:
      return "s";
    case Kind::Angle:
      return "deg";
    case Kind::Accel:
      return "ft/s^2";
    case Kind::Mass:
      return "lb";
    default:
      return allowedUnits(k);
  }
}

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
    throw ConfigError(fmt::format("{}:{}:{}: error: {}", file_,
                                  where.begin.line == 0 ? 1 : where.begin.line,
                                  where.begin.column == 0 ? 1 : where.begin.column, msg));
  }

  toml::table parse(std::string_view text) const {
    checkTomlText(text, file_);
    try {
      return toml::parse(text, file_);
    } catch (const toml::parse_error& e) {
      fail(e.source(), std::string(e.description()));
    }
  }

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
        for (size_t i = 0; word && i < kChoices.size(); ++i)
          if (*word == kChoices[i]) {
            *t.i = static_cast<int>(i);
            return;
          }
        fail(value->source(), fmt::format("'{}' must be \"{}\", \"{}\" or \"{}\"", name,
                                          kChoices[0], kChoices[1], kChoices[2]));
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
      fail(sec ? sec->source() : doc.source(),
           fmt::format("missing key '{}' in [{}]", d->key, d->section));
    }
  }

 private:
  std::string file_;
};

std::string readFile(const std::string& path) {
  FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw ConfigError(fmt::format("{}:1:1: error: cannot open file", path));
  std::string s;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) s.append(buf, n);
  std::fclose(f);
  return s;
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
  for (const Pose& start : p.field.start)
    if (std::abs(start.x_ft) + p.robot.body_diameter_ft / 2 > half ||
        std::abs(start.y_ft) + p.robot.body_diameter_ft / 2 > half)
      c.fail(where("start"), "a start pose puts the body outside the field");
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
}

}  // namespace

void checkTomlText(std::string_view text, const std::string& sourceName) {
  int line = 1, column = 1;
  const auto fail = [&](const std::string& msg) {
    throw ConfigError(fmt::format("{}:{}:{}: error: {}", sourceName, line, column, msg));
  };
  enum class In : std::uint8_t { Code, Comment, Basic, Literal, MultiBasic, MultiLiteral };
  In in = In::Code;
  bool escaped = false;  // the character after a backslash in a basic string
  const auto at = [&](std::size_t i) { return i < text.size() ? text[i] : '\0'; };
  const auto starts = [&](std::size_t i, std::string_view s) {
    return text.substr(i, s.size()) == s;
  };
  for (std::size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    // A UTF-8 sequence: its length, checked strictly (no overlongs, no surrogates).
    std::size_t len = 1;
    if (c >= 0x80) {
      unsigned lo = 0x80, hi = 0xBF;
      if (c >= 0xC2 && c <= 0xDF) {
        len = 2;
      } else if (c >= 0xE0 && c <= 0xEF) {
        len = 3;
        if (c == 0xE0) lo = 0xA0;
        if (c == 0xED) hi = 0x9F;
      } else if (c >= 0xF0 && c <= 0xF4) {
        len = 4;
        if (c == 0xF0) lo = 0x90;
        if (c == 0xF4) hi = 0x8F;
      } else {
        fail(fmt::format("the file is not valid UTF-8 (byte 0x{:02x})", c));
      }
      for (std::size_t k = 1; k < len; ++k) {
        const auto b = static_cast<unsigned char>(at(i + k));
        if (k == 1 ? (b < lo || b > hi) : (b & 0xC0) != 0x80)
          fail(fmt::format("the file is not valid UTF-8 (byte 0x{:02x})", c));
      }
      if (in == In::Code)
        fail("a non-ASCII character outside a string or comment (TOML allows none there)");
    }
    std::size_t next = i + len;
    switch (in) {
      case In::Code:
        if (c == '#') in = In::Comment;
        if (c == '"') in = starts(i, "\"\"\"") ? In::MultiBasic : In::Basic;
        if (c == '\'') in = starts(i, "'''") ? In::MultiLiteral : In::Literal;
        if (in == In::MultiBasic || in == In::MultiLiteral) next = i + 3;
        break;
      case In::Comment:
        if (c == '\n') in = In::Code;
        break;
      case In::Basic:
        if (escaped)
          escaped = false;
        else if (c == '\\')
          escaped = true;
        else if (c == '"' || c == '\n')
          in = In::Code;
        break;
      case In::Literal:
        if (c == '\'' || c == '\n') in = In::Code;
        break;
      case In::MultiBasic:
        if (escaped) {
          escaped = false;
        } else if (c == '\\') {
          // A line-ending backslash: what follows the blank space after it
          // must be ASCII.
          std::size_t k = i + 1;
          while (at(k) == ' ' || at(k) == '\t') ++k;
          if (at(k) == '\r' || at(k) == '\n') {
            while (at(k) == ' ' || at(k) == '\t' || at(k) == '\r' || at(k) == '\n') ++k;
            if (static_cast<unsigned char>(at(k)) >= 0x80)
              fail(
                  "a line-ending backslash in a multi-line string is followed by a non-ASCII "
                  "character, which toml++ 3.3.0 cannot parse safely: put the character on "
                  "the backslash's line");
          }
          escaped = true;
        } else if (starts(i, "\"\"\"")) {
          in = In::Code;
          next = i + 3;
        }
        break;
      case In::MultiLiteral:
        if (starts(i, "'''")) {
          in = In::Code;
          next = i + 3;
        }
        break;
    }
    for (; i < next && i < text.size(); ++i) {
      if (text[i] == '\n') {
        ++line;
        column = 1;
      } else if ((static_cast<unsigned char>(text[i]) & 0xC0) != 0x80) {
        ++column;  // columns count characters, as toml++'s do
      }
    }
  }
}

Profile parseProfile(std::string_view text, const std::string& sourceName) {
  Checker c(sourceName);
  const toml::table doc = c.parse(text);
  Profile p;
  Hardware h;
  std::vector<const KeyDef*> defs;
  for (const KeyDef& d : keyTable()) defs.push_back(&d);
  std::vector<std::string> strings;
  c.walk(doc, defs, true, {"name", "description"}, p, h, &strings);
  if (std::find(strings.begin(), strings.end(), "name") == strings.end())
    c.fail(doc.source(), "missing key 'name'");
  crossChecks(p, c, doc);
  p.file = sourceName;
  return p;
}

Profile loadProfile(const std::string& path) { return parseProfile(readFile(path), path); }

Hardware parseHardware(std::string_view text, const std::string& sourceName, RobotParams& params) {
  Checker c(sourceName);
  const toml::table doc = c.parse(text);
  Profile p;
  p.robot = params;
  Hardware h;
  std::vector<const KeyDef*> defs;
  for (const KeyDef& d : portTable()) defs.push_back(&d);
  for (const KeyDef& d : keyTable())
    if (d.perRobot) defs.push_back(&d);
  // Field-wide keys are not per robot: name them in the error.
  for (auto&& [sk, sv] : doc) {
    for (const KeyDef& d : keyTable())
      if (!d.perRobot && sk.str() == d.section)
        c.fail(sk.source(),
               fmt::format("[{}] is arena-wide and cannot be overridden per robot", d.section));
  }
  c.walk(doc, defs, false, {"name", "description"}, p, h, nullptr);
  std::array<int, 5> bits = {h.gun_motor_bit[0], h.gun_solenoid_bit[0], h.gun_motor_bit[1],
                             h.gun_solenoid_bit[1], h.disc_shooter_bit};
  for (std::size_t i = 0; i < bits.size(); ++i)
    for (std::size_t j = i + 1; j < bits.size(); ++j)
      if (bits[i] == bits[j]) {
        const toml::node* n = doc.get("ports");
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
  params = p.robot;
  return h;
}

Hardware loadHardware(const std::string& path, RobotParams& params) {
  return parseHardware(readFile(path), path, params);
}

ArenaConfig makeArenaConfig(const Profile& profile, int robotCount) {
  ArenaConfig c;
  c.field = profile.field;
  c.referee = profile.referee;
  for (int i = 0; i < robotCount && i < 2; ++i)
    c.robots.push_back(
        RobotSetup{profile.robot, Hardware{}, profile.field.start[static_cast<std::size_t>(i)]});
  return c;
}

}  // namespace simbot::plant
