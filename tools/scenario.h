// Scenario files (--scenario FILE.toml on solo, match, bench and profile):
// the set-up of a run that is not the programs themselves. A scenario gives
// the profile, the run's length and seed, robot A's start pose, hardware
// file and injections, and robot B: another program, or a beacon that
// stands still or drives a scripted path. The schema is in docs/tools.md
// ("Scenarios"); every key is checked, and every error is reported as
// FILE:LINE:COL: error: MESSAGE.
//
// What the command line says explicitly wins over the scenario (--profile,
// --seconds, --seed, --hw); --inject adds to the scenario's injections.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "plant/plant.h"
#include "scheduler/match.h"

namespace simbot::tools {

// Where something is in the scenario file, for the errors found when the
// run is set up.
struct SourcePos {
  int line = 0;
  int column = 0;
};

// One leg of a beacon's path, as the scenario file states it.
struct PathLeg {
  enum class Kind : uint8_t { Forward, Arc, Spin, Wait } kind = Kind::Wait;
  double forwardFt = 0;  // Forward: signed distance (negative: backwards)
  double radiusFt = 0;   // Arc: radius of the centre's path
  double turnDeg = 0;    // Arc, Spin: signed turn, + clockwise (to the right)
  double speedFps = 0;   // Forward, Arc: centre speed; Spin: wheel speed
  double waitS = 0;      // Wait
  SourcePos pos;
};

struct ScenarioRobot {
  std::optional<plant::Pose> start;
  SourcePos startPos;
  std::string hardware;  // resolved path; empty: the default bindings
  struct Inject {
    std::string what;  // SOURCE@WHEN as written
    SourcePos pos;
  };
  std::vector<Inject> inject;
};

struct Scenario {
  std::string file;
  std::optional<std::string> profile;  // a profile name, or a resolved path
  std::optional<double> seconds;
  std::optional<uint64_t> seed;
  ScenarioRobot a, b;
  enum class Opponent : uint8_t { None, Program, Beacon } opponent = Opponent::None;
  SourcePos opponentPos;  // [B]'s program or beacon key
  std::string program;    // B's program (resolved path)
  std::vector<PathLeg> path;
  bool repeatPath = false;
};

// A run's setting: the command line's value if the option was given there,
// else the scenario's if it sets one, else the command's default.
template <typename T>
T preferCommandLine(bool givenOnCommandLine, const std::optional<T>& fromScenario,
                    const T& fromCommand) {
  return !givenOnCommandLine && fromScenario ? *fromScenario : fromCommand;
}

// Throws plant::ConfigError ("FILE:LINE:COL: error: ..."). Relative paths in the
// file (profile, hardware, program) are taken from the file's directory.
Scenario loadScenario(const std::string& path);
Scenario parseScenario(std::string_view text, const std::string& sourceName,
                       const std::string& baseDir);

// A beacon's path as wheel speeds and exact tick durations, with the
// beacon's own track (the scheduler follows a path exactly: no motor lag). Throws
// plant::ConfigError naming the leg's place if a leg is shorter than a tick.
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
// plant::ConfigError naming the place in the scenario of anything that does
// not fit.
void applyScenario(const Scenario& s, ScenarioUse use, const plant::Profile& profile,
                   scheduler::MatchConfig& config, std::array<bool, 2> keepHardware = {});

}  // namespace simbot::tools
