// config/profile_keys.h -- inside config/: the table of every profile and
// hardware-file key, and the units each kind of value accepts.
//
// One table lists every key once: its section, kind (which fixes the
// accepted units and the range check), bounds, whether a hardware file may
// override it per robot, and where it lands in a Profile or Hardware. The
// loader (profile.cpp) walks a parsed document against it; this file only
// describes the keys, so a key is added in one place.
#pragma once

#include <toml++/toml.h>

#include <array>
#include <functional>
#include <string_view>
#include <utility>
#include <vector>

#include "config/config.h"

namespace simbot::config::keys {

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
  Choice,       // no unit; one of the words in kChoices
  SpeedTable,   // array of 16 speeds
  Charge,       // Ah, mAh, C (stored in coulombs)
  Voltage,      // V, mV
  Current,      // A, mA
  Resistance,   // ohm, mohm
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

// The words a Choice key accepts and what each one means: [controller]
// timer_service's timer service, and [controller] cpu's Z180 revision.
inline constexpr std::array<std::pair<const char*, vm::TimerService>, 3> kChoices = {{
    {"auto", vm::TimerService::Auto},
    {"always", vm::TimerService::Always},
    {"never", vm::TimerService::Never},
}};
inline constexpr std::array<std::pair<const char*, vm::CpuRevision>, 2> kCpuChoices = {{
    {"z80180", vm::CpuRevision::Z80180},
    {"z8s180", vm::CpuRevision::Z8S180},
}};
// A hardware file's [secondary] kind.
inline constexpr std::array<std::pair<const char*, plant::SecondaryKind>, 1> kSecondaryChoices = {{
    {"disc", plant::SecondaryKind::Disc},
}};

// Where one key's value lands: exactly one pointer is set, by the kind (a
// Choice key's: `choice`, `cpu` or `secondary`).
struct Target {
  double* d = nullptr;
  int* i = nullptr;
  bool* b = nullptr;
  vm::TimerService* choice = nullptr;
  vm::CpuRevision* cpu = nullptr;
  plant::SecondaryKind* secondary = nullptr;
  std::array<double, 16>* table = nullptr;
};

struct KeyDef {
  const char* section;
  const char* key;
  Kind kind;
  Bounds bounds;
  bool perRobot;
  std::function<Target(Profile&, plant::Hardware&)> target;
  // A key of a section a profile may leave out as a whole ([battery]: no
  // battery); when the section is there, every key of it is required.
  bool optionalSection = false;
};

// Every profile key, in file order.
const std::vector<KeyDef>& keyTable();
// A hardware file's [ports] keys.
const std::vector<KeyDef>& portTable();
// A rule set's [course] keys.
const std::vector<KeyDef>& courseTable();

// Walks a parsed document's sections against `defs` as a profile is read:
// an unknown section or key, a wrong type, unit or range is a ConfigError
// at its place; `plainStrings` are the top-level keys that are plain
// strings (`name`: into p.name). Keys that are absent are left as they
// are (the caller checks the ones it requires).
void walkKeys(const toml::table& doc, const std::vector<const KeyDef*>& defs,
              const std::string& file, const std::vector<std::string>& plainStrings, Profile& p);
// A hardware file's [secondary] keys (a secondary weapon: the disc
// launcher). When the table is there, every key but `bit` must be.
const std::vector<KeyDef>& secondaryTable();
// A hardware file's [[deployables]] keys (every kind's; the loader says
// which a kind needs).
const std::vector<KeyDef>& deployableTable();

// Conversion factor to the internal unit, or NaN if the unit is not allowed.
double unitFactor(Kind k, std::string_view u);
// The units a kind accepts, for messages.
const char* allowedUnits(Kind k);
// The internal unit of a kind, for messages about its range.
const char* internalUnit(Kind k);
// The kind's name for a reader ("length", "speed_table", "bool", ...):
// simbot hardware's listing.
const char* kindName(Kind k);

}  // namespace simbot::config::keys
