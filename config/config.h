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
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
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

// ---------------------------------------------------------------- course rules
// A rule set's [course] table (rules/NAME.toml, --rules; docs/rules.md):
// how one course's competition was run. Read by loadRules, applied to a
// profile by applyRules. The default (present = false) is no rule set: the
// profile as it is, nothing refused, no shot judged.
struct Course {
  bool present = false;
  std::string name;  // the rule set's `name`
  std::string file;  // where it was loaded from
  // Overrides of the profile's field and match values.
  double field_size_ft = 16;
  bool divider = true;
  // The divider's geometry where the rule set gives it (NaN: the profile's).
  double divider_x_ft = std::numeric_limits<double>::quiet_NaN();
  double divider_south_ft = std::numeric_limits<double>::quiet_NaN();
  double divider_north_ft = std::numeric_limits<double>::quiet_NaN();
  double divider_thickness_ft = std::numeric_limits<double>::quiet_NaN();
  double divider_height_ft = std::numeric_limits<double>::quiet_NaN();
  double round_length_s = 180;
  int gun_magazine = 15;  // the standard gun's, as issued: balls_per_gun
  // Countermeasures allowed.
  bool mines = false, blocks = false, decoy_lights = false, decoy_screens = false;
  // Secondary weapons allowed (kinds), and their magazine's maximum.
  bool secondary_disc = false;
  int secondary_magazine = 0;
  // The referee's counts: a hit off a floor skip is valid (the profile's
  // projectile.count_floor_skips), a scatter shot's hit scores.
  bool floor_skips = false;
  bool scatter_scores = false;
  // Detect to Engage: a shot launched while neither eye reads above this
  // is a scatter shot (A/D readings).
  double detect_threshold = 0;
  // Where each key is written ("course.mines" -> line, column), so that a
  // refusal names the rule's place.
  std::vector<std::pair<std::string, std::pair<int, int>>> keyPlaces;
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
  // The rule set applied (applyRules); none by default.
  Course course;
};

Profile loadProfile(const std::string& path);
Profile parseProfile(std::string_view text, const std::string& sourceName);

// Reads a hardware file: port bindings, plus overrides of one robot's
// per-robot profile values (sections [robot], [bumper], [eyes], [gun],
// [battery], [controller]) applied to `params` and `controller`.
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

// ---------------------------------------------------------------- rules
// A rule set (--rules, a scenario's `rules`): rules/NAME.toml for a
// shipped NAME, else a path. Its [course] table is checked key by key as a
// profile's (FILE:LINE:COL: error: ...).
Course loadRules(const std::string& path);
Course parseRules(std::string_view text, const std::string& sourceName);
// The file of the shipped rule set NAME (rules/NAME.toml), if there is one.
std::optional<std::string> shippedRulesPath(const std::string& name);
// The profile under the rules: field size, divider, round length, the
// standard gun's magazine and floor skips replaced by the rules' values,
// and `course` set. The result is checked as a profile is (the start
// poses inside the smaller field, ...): ConfigError at the rule set's
// [course].
void applyRules(const Course& rules, Profile& profile);

// What a run uses that a rule set may forbid, each with the file that put
// it there: filled before the match (runs/rules.cpp) and checked by
// checkRules.
struct RunUses {
  struct Mine {
    std::string name;  // the obstacle's name ("" if it has none)
    std::string file;  // the scenario or rules file that places it
  };
  struct Carried {
    int robot = 0;     // 0 = A, 1 = B
    std::string kind;  // deployables: "block", "decoy_light", "decoy_screen"; secondary: "disc"
    int magazine = 0;  // a secondary weapon's rounds (deployables: their count)
    std::string file;  // the hardware file
  };
  struct Magazine {
    int robot = 0;
    int balls = 0;     // the standard gun's magazine (balls_per_gun)
    std::string file;  // the file that set it (hardware file, or the profile)
  };
  std::vector<Mine> mines;
  std::vector<Carried> deployables;
  std::vector<Carried> secondaryWeapons;
  std::vector<Magazine> magazines;
};
// Refuses the first thing `uses` holds that `rules` forbid: ConfigError
// "RULES:LINE:COL: error: course.KEY = VALUE forbids ..." at the rule's
// place. Nothing is refused without rules (present = false).
void checkRules(const Course& rules, const RunUses& uses);

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
  std::optional<std::string> rules;       // a rule set's name, or a resolved path
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
  // Each grid point's profile, built once when the file is read (without
  // the rules: sweepProfile applies them).
  std::vector<Profile> pointProfiles;
  // `rules = NAME|FILE`, or sweep --rules: every run's rule set.
  Course rules;
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

// ---------------------------------------------------------------- checks
// An expectations file (simbot check; docs/check.md): what a program (robot
// A) must do over the runs the file names. check/ plays and judges them.

// A record the trace may hold, and the values some of its fields must
// have (compared with the record as its JSONL line has it: robots "A" or
// "B", numbers equal, strings and booleans equal).
struct RecordPattern {
  std::string kind;  // a trace record kind (trace/records.def)
  struct Field {
    std::string name;
    std::variant<std::int64_t, double, bool, std::string> value;
  };
  std::vector<Field> fields;
};

enum class CheckKind : std::uint8_t {
  NoFault,            // no_fault = true: A never faults, nor the plant
  HitsAtLeast,        // hits_at_least = N
  ShotsAtMost,        // shots_at_most = N
  NoScatterShot,      // no_scatter_shot = true (needs rules: they judge it)
  NoOverwrittenSend,  // no_overwritten_send = true
  FramesAtLeast,      // frames_at_least = N (frames latched)
  Step,               // after = {...}, within_s = S, expect = {...}
};

struct Check {
  std::string name;
  CheckKind kind = CheckKind::NoFault;
  std::int64_t count = 0;  // HitsAtLeast, ShotsAtMost, FramesAtLeast
  // Step: every record matching `after` must be followed, at its tick or
  // within `within` ticks after, by one matching `expect`.
  RecordPattern after, expect;
  scheduler::Tick within = 0;
  SourcePos pos;  // the [[check]] table
};

struct Expectations {
  std::string file;
  scheduler::Tick length = 0;        // `seconds` (default 60 s)
  std::vector<std::uint64_t> seeds;  // `seed`: one or a list (default 1)
  enum class Opponent : std::uint8_t { None, Program, Stationary } opponent = Opponent::None;
  std::string opponentProgram;  // resolved from the file's directory
  double stationaryFt = 0;      // "stationary:8ft": a beacon this far ahead of A's start
  std::optional<std::string> profile, rules;  // a name, or a resolved path
  std::vector<Check> checks;
};

// At most this many seeds and checks in one file: each seed is a run.
inline constexpr std::size_t kMaxCheckSeeds = 1000;
inline constexpr std::size_t kMaxChecks = 1000;

// Reads and checks an expectations file: ConfigError "FILE:LINE:COL:
// error: ..." at what is wrong (an unknown key or record kind, a field the
// record does not have, a missing name, a count out of range).
Expectations loadExpectations(const std::string& path);

// ---------------------------------------------------------------- injections
// Parses ROBOT:SOURCE@WHEN (WHEN: a time in timebase/written.h's grammar
// with its unit, 12.5s, 800ms, 300us or 115200000t, a whole number of
// ticks; or line:N#K, pass:N#K) for a run of `robotCount` robots.
// Throws std::invalid_argument with a message naming what is wrong.
scheduler::Injection parseInjection(const std::string& text, int robotCount);

}  // namespace simbot::config
