// config/profile_keys.cpp -- the profile and hardware-file keys
// (profile_keys.h): every key with its section, kind, bounds and target,
// and the units each kind accepts with their factors to internal units.
#include "config/profile_keys.h"

#include <cmath>
#include <type_traits>

#include "timebase/written.h"

namespace simbot::config::keys {

using plant::Hardware;
using plant::kMaxBallsPerGun;
using plant::kMaxRefereeLimit;

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

namespace {
// A [battery] key: per robot, its section optional.
KeyDef BK(const char* key, Kind kind, Bounds bounds,
          std::function<Target(Profile&, plant::Hardware&)> target) {
  return KeyDef{"battery", key, kind, bounds, true, std::move(target), true};
}
}  // namespace

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
      // Obstacles taller than this hide the beacon (plant.h FieldParams).
      {"field", "beacon_height", Kind::Length, {0.05, 10}, false, D(p.field.beacon_height_ft)},
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
      // The wheels' Coulomb friction on the floor: traction = mass g times
      // it, what a robot pushes a deployed block with (docs/plant.md
      // "Deployables"). Rubber on a hard floor is about 0.5 to 1.
      {"robot", "wheel_friction", Kind::Ratio, {0.05, 2}, true, D(p.robot.wheel_friction)},
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
      // Standard deviations. At 5 deg the widest draw (8.6 sigmas, variation.cpp)
      // stays below 45 deg: still a gun that shoots forward.
      {"gun", "azimuth_sigma", Kind::Angle, {0, 5}, true, D(p.robot.azimuth_sigma_deg)},
      {"gun", "elevation_sigma", Kind::Angle, {0, 5}, true, D(p.robot.elevation_sigma_deg)},
      {"gun", "launch_height", Kind::Length, {0.05, 10}, true, D(p.robot.launch_height_ft)},
      {"gun", "balls_per_gun", Kind::Count, {0, kMaxBallsPerGun}, true, I(p.robot.balls_per_gun)},
      {"gun", "jam_probability", Kind::Probability, {0, 1}, true, D(p.robot.jam_probability)},
      {"gun",
       "misfire_probability",
       Kind::Probability,
       {0, 1},
       true,
       D(p.robot.misfire_probability)},
      // [battery] (optional: without it no battery runs down). Ranges span
      // any pack a 1996-97 student robot carried (docs/plant.md, "Batteries").
      BK("enabled", Kind::Bool, {0, 0}, B(p.robot.battery.enabled)),
      BK("capacity", Kind::Charge, {36, 360000}, D(p.robot.battery.capacity_c)),
      BK("voltage_full", Kind::Voltage, {1, 60}, D(p.robot.battery.voltage_full_v)),
      BK("voltage_empty", Kind::Voltage, {0.5, 60}, D(p.robot.battery.voltage_empty_v)),
      BK("nominal_voltage", Kind::Voltage, {1, 60}, D(p.robot.battery.nominal_v)),
      BK("internal_resistance", Kind::Resistance, {0, 10}, D(p.robot.battery.resistance_ohm)),
      BK("board_current", Kind::Current, {0, 5}, D(p.robot.battery.board_a)),
      BK("drive_current", Kind::Current, {0, 50}, D(p.robot.battery.drive_a)),
      BK("gun_motor_current", Kind::Current, {0, 50}, D(p.robot.battery.gun_motor_a)),
      BK("solenoid_current", Kind::Current, {0, 50}, D(p.robot.battery.solenoid_a)),
      BK("brownout_voltage", Kind::Voltage, {0.5, 60}, D(p.robot.battery.brownout_v)),
      BK("recovery_hysteresis", Kind::Voltage, {0, 10}, D(p.robot.battery.hysteresis_v)),
      BK("reset_hold", Kind::Time, {0, 10}, D(p.robot.battery.reset_hold_s)),
      {"controller", "random_memory", Kind::Bool, {0, 0}, true, B(p.controller.randomMemory)},
      {"controller",
       "timer_service",
       Kind::Choice,
       {0, 0},
       true,
       [](Profile& p, Hardware&) {
         Target t;
         t.choice = &p.controller.timerService;
         return t;
       }},
      {"controller", "fast_forward", Kind::Bool, {0, 0}, true, B(p.controller.fastForward)},
      {"controller",
       "cpu",
       Kind::Choice,
       {0, 0},
       true,
       [](Profile& p, Hardware&) {
         Target t;
         t.cpu = &p.controller.cpu;
         return t;
       }},
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
      {"match",
       "round_length",
       Kind::Time,
       {1, timebase::kMaxRunSeconds},
       false,
       D(p.round_length_s)},
      // At least the serial port's last two characters (2.1 ms): the port
      // is reset at the reload (scheduler kMinReloadDelay).
      {"match", "reload_delay", Kind::Time, {0.01, 3600}, false, D(p.reload_delay_s)},
  };
  return keys;
}

// A rule set's [course] (rules/*.toml; config.h Course). Bounds as the
// profile's keys they override; the divider's geometry is optional.
const std::vector<KeyDef>& courseTable() {
  static const std::vector<KeyDef> keys = {
      {"course", "field_size", Kind::Length, {1, 100}, false, D(p.course.field_size_ft)},
      {"course", "divider", Kind::Bool, {0, 0}, false, B(p.course.divider)},
      {"course", "divider_x", Kind::Length, {-50, 50}, false, D(p.course.divider_x_ft)},
      {"course", "divider_south", Kind::Length, {-50, 50}, false, D(p.course.divider_south_ft)},
      {"course", "divider_north", Kind::Length, {-50, 50}, false, D(p.course.divider_north_ft)},
      {"course",
       "divider_thickness",
       Kind::Length,
       {0, 2},
       false,
       D(p.course.divider_thickness_ft)},
      {"course", "divider_height", Kind::Length, {0, 20}, false, D(p.course.divider_height_ft)},
      {"course",
       "round_length",
       Kind::Time,
       {1, timebase::kMaxRunSeconds},
       false,
       D(p.course.round_length_s)},
      {"course",
       "gun_magazine",
       Kind::Count,
       {0, kMaxBallsPerGun},
       false,
       I(p.course.gun_magazine)},
      {"course", "mines", Kind::Bool, {0, 0}, false, B(p.course.mines)},
      {"course", "blocks", Kind::Bool, {0, 0}, false, B(p.course.blocks)},
      {"course", "decoy_lights", Kind::Bool, {0, 0}, false, B(p.course.decoy_lights)},
      {"course", "decoy_screens", Kind::Bool, {0, 0}, false, B(p.course.decoy_screens)},
      {"course", "secondary_disc", Kind::Bool, {0, 0}, false, B(p.course.secondary_disc)},
      // Appendix A (thesis line 1103): a secondary weapon's magazine is at
      // most fifteen rounds, under any rules that allow one.
      {"course", "secondary_magazine", Kind::Count, {0, 15}, false, I(p.course.secondary_magazine)},
      {"course", "floor_skips", Kind::Bool, {0, 0}, false, B(p.course.floor_skips)},
      {"course", "scatter_scores", Kind::Bool, {0, 0}, false, B(p.course.scatter_scores)},
      {"course",
       "detect_threshold",
       Kind::Reading,
       {0, 65535},
       false,
       D(p.course.detect_threshold)},
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

const std::vector<KeyDef>& secondaryTable() {
  using plant::kMaxDiscsPerLauncher;
  static const std::vector<KeyDef> keys = {
      {"secondary",
       "kind",
       Kind::Choice,
       {0, 0},
       true,
       [](Profile&, Hardware& h) {
         Target t;
         t.secondary = &h.secondary.kind;
         return t;
       }},
      // The disc shooter's bit, as [ports] disc_shooter (one of the two).
      {"secondary", "bit", Kind::Bit, {0, 7}, true, I(h.disc_shooter_bit)},
      // The arena's disc table holds two full magazines (a rules file
      // refuses more than its own limit, Appendix A's fifteen).
      {"secondary",
       "magazine",
       Kind::Count,
       {0, kMaxDiscsPerLauncher},
       true,
       I(h.secondary.magazine)},
      // Thesis VIII.B: a weapon "must be safe enough for a person to take a
      // hit"; the standard gun's ball leaves at 105 ft/s.
      {"secondary", "launch_speed", Kind::Speed, {1, 150}, true, D(h.secondary.launch_speed_fps)},
      // Appendix A: a robot at most 4.0 ft tall.
      {"secondary",
       "launch_height",
       Kind::Length,
       {0.05, 4},
       true,
       D(h.secondary.launch_height_ft)},
      {"secondary", "drag_time", Kind::Time, {0.01, 60}, true, D(h.secondary.drag_time_s)},
      // Below launch_speed (checked with it in parseHardware).
      {"secondary", "stop_speed", Kind::Speed, {0.01, 150}, true, D(h.secondary.stop_speed_fps)},
      // Up to 2 ft: no wider than a robot.
      {"secondary", "diameter", Kind::Length, {0.01, 2}, true, D(h.secondary.diameter_ft)},
  };
  return keys;
}

const std::vector<KeyDef>& deployableTable() {
  // Each lands in the last of h.deployables: the loader appends one per
  // [[deployables]] table before walking its keys.
  const auto last = [](auto member) {
    return [member](Profile&, Hardware& h) {
      Target t;
      using M = std::remove_reference_t<decltype(h.deployables.back().*member)>;
      if constexpr (std::is_same_v<M, int>)
        t.i = &(h.deployables.back().*member);
      else
        t.d = &(h.deployables.back().*member);
      return t;
    };
  };
  using plant::Deployable;
  static const std::vector<KeyDef> keys = {
      {"deployables", "bit", Kind::Bit, {0, 7}, true, last(&Deployable::bit)},
      {"deployables",
       "count",
       Kind::Count,
       {1, plant::kMaxDeployCount},
       true,
       last(&Deployable::count)},
      // Appendix A: a robot at most 4.0 ft tall and, with what it carries,
      // 35 lb; a block or screen no bigger than the robot.
      {"deployables", "width", Kind::Length, {0.05, 4}, true, last(&Deployable::width_ft)},
      {"deployables", "depth", Kind::Length, {0.05, 4}, true, last(&Deployable::depth_ft)},
      {"deployables", "height", Kind::Length, {0.02, 4}, true, last(&Deployable::height_ft)},
      {"deployables", "mass", Kind::Mass, {0.01, 35}, true, last(&Deployable::mass_lb)},
      // Thesis IX.C (line 1033): blocks "wrapped in non skid material";
      // any Coulomb coefficient a floor and a wrapping can have.
      {"deployables",
       "floor_friction",
       Kind::Ratio,
       {0, 3},
       true,
       last(&Deployable::floor_friction)},
      // Its kappa over the standard beacon's: thesis VII.D (line 930) has
      // decoys "not at the same ... intensity of the robot beacon".
      {"deployables", "intensity", Kind::Ratio, {0.01, 100}, true, last(&Deployable::intensity)},
  };
  return keys;
}

#undef D
#undef I
#undef B

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
    case Kind::Charge:
      if (u == "Ah") return 3600.0;
      if (u == "mAh") return 3.6;
      if (u == "C") return 1.0;
      break;
    case Kind::Voltage:
      if (u == "V") return 1.0;
      if (u == "mV") return 1e-3;
      break;
    case Kind::Current:
      if (u == "A") return 1.0;
      if (u == "mA") return 1e-3;
      break;
    case Kind::Resistance:
      if (u == "ohm") return 1.0;
      if (u == "mohm") return 1e-3;
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
    case Kind::Charge:
      return "Ah, mAh, C";
    case Kind::Voltage:
      return "V, mV";
    case Kind::Current:
      return "A, mA";
    case Kind::Resistance:
      return "ohm, mohm";
    case Kind::Bool:
    case Kind::Choice:
      return "(none)";
  }
  return "";
}

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
    case Kind::Charge:
      return "C";
    case Kind::Voltage:
      return "V";
    case Kind::Current:
      return "A";
    case Kind::Resistance:
      return "ohm";
    default:
      return allowedUnits(k);
  }
}

const char* kindName(Kind k) {
  switch (k) {
    case Kind::Length:
      return "length";
    case Kind::Speed:
      return "speed";
    case Kind::Time:
      return "time";
    case Kind::Angle:
      return "angle";
    case Kind::Accel:
      return "acceleration";
    case Kind::Mass:
      return "mass";
    case Kind::Ratio:
      return "ratio";
    case Kind::Probability:
      return "probability";
    case Kind::Reading:
      return "reading";
    case Kind::Count:
      return "count";
    case Kind::Step:
      return "step";
    case Kind::Bit:
      return "bit";
    case Kind::Bool:
      return "bool";
    case Kind::Choice:
      return "choice";
    case Kind::SpeedTable:
      return "speed_table";
    case Kind::Charge:
      return "charge";
    case Kind::Voltage:
      return "voltage";
    case Kind::Current:
      return "current";
    case Kind::Resistance:
      return "resistance";
  }
  return "";
}

}  // namespace simbot::config::keys
