// Scenario files (--scenario FILE.toml on solo, match, bench and profile):
// the set-up of a run that is not the programs themselves. A scenario gives
// the profile, the run's length and seed, robot A's start pose, hardware
// file and injections, and robot B: another program, or a beacon that
// stands still or drives a scripted path. The schema is in docs/tools.md
// ("Scenarios"). config/ reads and checks the file (config::loadScenario);
// this part applies it to a run. Every error is reported as
// FILE:LINE:COL: error: MESSAGE.
//
// What the command line says explicitly wins over the scenario (--profile,
// --seconds, --seed, --hw); --inject adds to the scenario's injections.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "config/config.h"
#include "plant/plant.h"
#include "scheduler/match.h"

namespace simbot::runs {

// The scenario file as config/ reads it (config.h).
using config::PathLeg;
using config::Scenario;
using config::ScenarioRobot;
using config::SourcePos;

// A run's setting: the command line's value if the option was given there,
// else the scenario's if it sets one, else the command's default.
template <typename T>
T preferCommandLine(bool givenOnCommandLine, const std::optional<T>& fromScenario,
                    const T& fromCommand) {
  return !givenOnCommandLine && fromScenario ? *fromScenario : fromCommand;
}

// A beacon's path as wheel speeds and exact tick durations, with the
// beacon's own track (the scheduler follows a path exactly: no motor lag). Throws
// config::ConfigError naming the leg's place if a leg is shorter than a tick.
std::vector<scheduler::DriveLeg> driveLegs(const std::string& sourceName,
                                           const std::vector<PathLeg>& legs,
                                           const plant::RobotParams& params);

// B as a beacon: a program whose main returns at once (so its VM halts and
// costs nothing) driven along `legs` (none: it stands still).
scheduler::RobotSpec beaconSpec(std::vector<scheduler::DriveLeg> legs, bool repeat);

// Which command applies the scenario; it decides where B may come from.
enum class ScenarioUse : uint8_t {
  Solo,      // A from the command line; B (program or beacon) may come from the scenario
  Match,     // A and B from the command line; the scenario may not name B's program
  Profile,   // as Solo
  Bench,     // as Solo; a bench family supplies poses and B, so the scenario may not
  BenchOwn,  // bench with the scenario as its family: poses and B from the scenario
};

// Applies the scenario to a run whose robots (A, and B for Match) are in
// `config` and whose arena was made from `profile` for those robots: start
// poses, hardware (unless `keepHardware[i]`: given on the command line),
// B when the scenario adds one, and injections (appended). Throws
// config::ConfigError naming the place in the scenario of anything that does
// not fit.
void applyScenario(const Scenario& s, ScenarioUse use, const config::Profile& profile,
                   scheduler::MatchConfig& config, std::array<bool, 2> keepHardware = {});

}  // namespace simbot::runs
