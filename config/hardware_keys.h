// config/hardware_keys.h -- inside config/: what simbot hardware lists,
// every key a hardware file may set with its units, range and value. Apart
// from config.h, which nearly every file includes, so that only the two
// files that use it compile it.
#pragma once

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "config/config.h"

namespace simbot::config {

// One value as a file writes it or as the loader leaves it: nothing, an
// integer, a number, a boolean, a word, or a speed table's 16 numbers.
using KeyValue =
    std::variant<std::monostate, std::int64_t, double, bool, std::string, std::vector<double>>;

// One key a hardware file may set (simbot hardware, docs/plant.md "What
// a hardware file may set"): what it accepts, and its value for a robot.
struct HardwareKey {
  std::string section, key;
  std::string kind;                  // "length", "speed_table", "bool", "choice", ...
  std::vector<std::string> units;    // the units it accepts; none for a bool or a choice
  std::vector<std::string> choices;  // a choice's words
  std::string internalUnit;          // "" for a bool or a choice
  // The valid range in the internal unit (a speed table's: each entry's);
  // `orZero`: 0 is valid too. None for a bool or a choice.
  bool ranged = false;
  double lo = 0, hi = 0;
  bool orZero = false;
  bool integral = false;  // a count, step or bit: an integer, its range too
  // The same range in `shownUnit` (the unit written, else the internal
  // unit), rounded to 12 significant digits (0.1 ft is 1.2 in, not
  // 1.2000000000000002).
  std::string shownUnit;
  double shownLo = 0, shownHi = 0;
  // What must be written: Required (every profile gives it),
  // OptionalSection (its section may be left out; where it is there, every
  // key but [secondary] bit is required) or Optional.
  enum class Presence : std::uint8_t { Required, OptionalSection, Optional };
  Presence presence = Presence::Required;
  // Who sets it: the hardware file, else the profile, else nobody (BuiltIn).
  enum class From : std::uint8_t { Profile, Hardware, BuiltIn };
  From from = From::BuiltIn;
  // As written where it is set; nothing and "" for BuiltIn (`unit` is ""
  // for a bool or a choice too).
  KeyValue value;
  std::string unit, source;
  // What the loader leaves for the robot, in the internal unit: for
  // BuiltIn the built-in value ([ports]: 3, 4, 7, 5, 6; without
  // [secondary]: kind "none" and zeros, no secondary weapon).
  KeyValue loaded;
};

// Every key a hardware file may set, for one robot under `profile`: the
// per-robot keys of the profile in its key table's order, then [ports],
// then [secondary]. `hardwareFile` (empty: none) is read by loadHardware,
// the loader of --hw, over the profile's values: its errors are --hw's.
// The values as written are read again from `profile.file` and the
// hardware file.
std::vector<HardwareKey> hardwareKeys(const Profile& profile, const std::string& hardwareFile);

}  // namespace simbot::config
