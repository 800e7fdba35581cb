// config/config.h -- the whole public interface of simbot's configuration
// layer: the one part that reads what a user writes to set up a run.
//
// It reads TOML profiles (profiles/*.toml), per-robot hardware files,
// scenario files, sweep files and --inject specifications, and turns each
// into the typed values the other parts take: the plant's field, referee
// and robot parameters, the scheduler's injections, and each robot's VM
// knobs (timer service, fast-forward). It includes their headers, never
// the other way round (plant/, vm/ and scheduler/ do not include config/);
// runs/ and batch/ apply what it reads to a run. Times written in these
// files are read by timebase/written.h's one grammar, not here.
//
// Every error in a file is a ConfigError whose what() is "FILE:LINE:COL:
// error: MESSAGE"; a file that is not there is "simbot: no ... 'PATH'"
// (scenarios, sweeps) or "PATH:1:1: error: cannot open file" (profiles,
// hardware). The --inject parser, which reads a command-line word, throws
// std::invalid_argument naming the word instead.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "plant/plant.h"
#include "scheduler/match.h"

namespace simbot::config {

// Any loader error; what() is "FILE:LINE:COL: error: MESSAGE".
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
  // The message at a place; a line or column below 1 is given as 1.
  ConfigError(const std::string& file, int line, int column, const std::string& message);
};

// ---------------------------------------------------------------- profiles
// A profile file, checked key by key and converted to internal units (ft,
// s, ft/s, ft/s^2, degrees, ratios, A/D readings).
struct Profile {
  std::string name;
  std::string file;  // where it was loaded from
  plant::FieldParams field;
  plant::RefereeParams referee;
  double round_length_s = 180;
  // --reload-on-fault: from a robot's fault to its program's restart (s).
  double reload_delay_s = 20;
  plant::RobotParams robot;
  // [controller] timer_service and fast_forward: the VM's, per robot
  // (scheduler::RobotSpec::controller).
  scheduler::ControllerKnobs controller;
};

Profile loadProfile(const std::string& path);
Profile parseProfile(std::string_view text, const std::string& sourceName);

// Reads a hardware file: port bindings, plus overrides of one robot's
// per-robot profile values (sections [robot], [bumper], [eyes], [gun],
// [controller]) applied to `params` and `controller`.
plant::Hardware loadHardware(const std::string& path, plant::RobotParams& params,
                             scheduler::ControllerKnobs& controller);
plant::Hardware parseHardware(std::string_view text, const std::string& sourceName,
                              plant::RobotParams& params, scheduler::ControllerKnobs& controller);

// The arena of one or two robots from one profile: default hardware and the
// profile's start poses. (The robots' controller knobs are the profile's
// `controller`, set on each scheduler::RobotSpec.)
plant::ArenaConfig makeArenaConfig(const Profile& profile, int robotCount);

// Checks a TOML file's text before toml++ (3.3.0) parses it: well-formed
// UTF-8, no non-ASCII character outside strings and comments (where TOML
// allows none anyway), and no line-ending backslash in a multi-line string
// followed by a non-ASCII character. toml++ 3.3.0 reaches an "unreachable"
// state (undefined behaviour) on the last two (toml++ issues 190 and 295).
// Throws ConfigError naming the place.
void checkTomlText(std::string_view text, const std::string& sourceName);

// The file of the shipped profile NAME (profiles/NAME.toml), if there is one.
std::optional<std::string> shippedProfilePath(const std::string& name);

// ---------------------------------------------------------------- scenarios
// A scenario file (--scenario FILE.toml): the set-up of a run that is not
// the programs themselves; docs/tools.md ("Scenarios") has the schema.
// runs/ applies it to a run (runs/scenario.h).

// Where something is in the scenario file, for the errors found when the
// run is set up.
struct SourcePos {
  int line = 0;
  int column = 0;
};

// One leg of a beacon's path, as the scenario file states it.
struct PathLeg {
  enum class Kind : uint8_t { Forward, Arc, Spin, Wait } kind = Kind::Wait;
  double forwardFt = 0;      // Forward: signed distance (negative: backwards)
  double radiusFt = 0;       // Arc: radius of the centre's path
  double turnDeg = 0;        // Arc, Spin: signed turn, + clockwise (to the right)
  double speedFps = 0;       // Forward, Arc: centre speed; Spin: wheel speed
  scheduler::Tick wait = 0;  // Wait: its length
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

// One obstacle of a scenario's (or rules file's) [[obstacles]], with where
// it is written (config/obstacles.h reads them).
struct ObstacleSpec {
  plant::Obstacle obstacle;
  SourcePos pos;
};

// Checks obstacles against the field and the robots' start poses of a
// run's arena (`arena.field`'s size, `arena.robots`' starts and body
// radii): each must lie inside the field and clear of every start pose.
// Throws ConfigError "FILE:LINE:COL: error: ..." at the obstacle.
void checkObstacles(const std::vector<ObstacleSpec>& obstacles, const std::string& file,
                    const plant::ArenaConfig& arena);

struct Scenario {
  std::string file;
  std::optional<std::string> profile;     // a profile name, or a resolved path
  std::optional<scheduler::Tick> length;  // `seconds`: the run's length
  std::optional<uint64_t> seed;
  ScenarioRobot a, b;
  enum class Opponent : uint8_t { None, Program, Beacon } opponent = Opponent::None;
  SourcePos opponentPos;  // [B]'s program or beacon key
  std::string program;    // B's program (resolved path)
  std::vector<PathLeg> path;
  bool repeatPath = false;
  std::vector<ObstacleSpec> obstacles;  // [[obstacles]]
};

// Relative paths in the file (profile, hardware, program) are taken from
// the file's directory. A missing or unreadable file is "simbot: no
// scenario file 'PATH'" (or "cannot read scenario").
Scenario loadScenario(const std::string& path);
Scenario parseScenario(std::string_view text, const std::string& sourceName,
                       const std::string& baseDir);

// ---------------------------------------------------------------- sweeps
// A sweep file (simbot sweep): a grid of bench runs, programs x families x
// opponents x profile values x seeds. batch/ expands and runs it
// (batch/sweep.h).
struct SweepSpec {
  std::string file;                   // the sweep file; relative paths in it are from its directory
  std::vector<std::string> programs;  // as written (the table's program column)
  std::vector<std::string> opponents;  // head-to-head's robot B, as written
  std::vector<std::string> families;
  uint64_t firstSeed = 1;  // [seeds] first, count: each a bench master seed
  uint64_t seedCount = 1;
  double seconds = 60;
  std::string profile = "default";  // a shipped profile's name, or a file
  // [grid] "section.key" = [values]: each value's TOML text, keys in file order.
  std::vector<std::pair<std::string, std::vector<std::string>>> grid;
  // Each grid point's profile, built once when the file is read.
  std::vector<Profile> pointProfiles;
};

// A grid has at most this many points, and a sweep at most this many runs
// (points x programs x family pairs x seeds), counted without overflow
// before anything is built: a million 60-s runs is weeks of a cluster's
// time, and the run list alone takes about 100 MB.
inline constexpr std::size_t kMaxSweepPoints = 100'000;
inline constexpr std::size_t kMaxSweepRuns = 1'000'000;

// Reads and checks a sweep file; `families` are the bench families it may
// name. Every grid point's profile is built and checked too. Errors are
// "FILE:LINE:COL: error: ...", or "simbot: ..." for a file, program or
// profile key that is not there.
SweepSpec loadSweep(const std::string& path, const std::vector<std::string>& families);
// The file of the sweep's profile (a file named relative to the sweep, or
// a shipped profile's).
std::string sweepProfilePath(const SweepSpec& spec);
// The grid's points (saturating: SIZE_MAX when the product overflows).
size_t sweepPoints(const SweepSpec& spec);
// Grid point `point`'s value of each grid key, as an index into the key's
// values; the last key varies fastest.
std::vector<size_t> sweepPointValues(const SweepSpec& spec, size_t point);
// The profile of a grid point: the sweep's profile with the point's values.
Profile sweepProfile(const SweepSpec& spec, size_t point);
// A path as written in the sweep file, made usable from here (relative
// paths are from the file's directory).
std::string sweepPath(const SweepSpec& spec, const std::string& path);

// ---------------------------------------------------------------- injections
// Parses ROBOT:SOURCE@WHEN (WHEN: a time in timebase/written.h's grammar
// with its unit, 12.5s, 800ms, 300us or 115200000t, a whole number of
// ticks; or line:N#K, pass:N#K) for a run of `robotCount` robots.
// Throws std::invalid_argument with a message naming what is wrong.
scheduler::Injection parseInjection(const std::string& text, int robotCount);

}  // namespace simbot::config
