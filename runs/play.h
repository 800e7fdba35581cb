// runs/ (namespace simbot::runs): one run set up and played. Programs
// are compiled, a profile found, a scenario applied (scenario.h), the
// trace's sinks attached (sinks/, and reports/' replay page), the match
// played and summarised. batch/ runs many of these; cli/ and the Python
// module are its two front ends.
//
// One solo run or match from run options, and its JSON summary: the CLI's
// solo, match and profile commands and the Python module (python/) share
// these, so `simbot match A B --json` and simbot.match(A, B) give the same
// JSON.
#pragma once
#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "compiler/compiler.h"
#include "config/config.h"
#include "files/files.h"
#include "runs/scenario.h"
#include "scheduler/match.h"
#include "timebase/tick.h"
#include "trace/trace.h"
#include "vm/image.h"

namespace simbot::runs {

// A program compiled for a run; its warnings go to stderr once per program
// per process (bench and tournament compile each program many times).
// UserError with the compiler's diagnostics if it does not compile.
vm::Image compileProgramFile(const std::string& path);
// The compiler options every later compileProgramFile and
// compileProgramText of this process use: -Wno-NAME and -Werror given to
// solo, match, profile, bench, tournament (the debug setting is kept).
void setCompileOptions(const compiler::Options& options);
// The -W words of a command line into `options`; UserError for a word
// that is not -Werror or -Wno-NAME with a known NAME.
void parseWarningOptions(const std::vector<std::string>& words, compiler::Options& options,
                         const std::string& command);
vm::Image compileProgramText(const std::string& source, const std::string& name);
// A profile by name (profiles/NAME.toml) or by path.
config::Profile loadNamedProfile(const std::string& nameOrPath);
// A rule set by name (rules/NAME.toml) or by path; UserError if neither.
config::Course loadNamedRules(const std::string& nameOrPath);
// The profile a run plays under: loadNamedProfile, then the rules (a
// name or path; empty: none) applied (config::applyRules).
config::Profile loadRunProfile(const std::string& profile, const std::string& rules);

// Where a run option is offered (runs/run_options.def): the commands, and
// the Python module's simbot.solo and simbot.match (kPython) and
// simbot.bench (kPythonBench).
enum RunOptionUse : unsigned {
  kSolo = 1 << 0,
  kMatch = 1 << 1,
  kProfile = 1 << 2,
  kPython = 1 << 3,
  kDebug = 1 << 4,
  kBench = 1 << 5,
  kCompare = 1 << 6,
  kTournament = 1 << 7,
  kSweep = 1 << 8,
  kPythonBench = 1 << 9,
  kHardware = 1 << 10,
};

// What a run option's value must be beyond its type: anything, an integer
// in [lo, hi], or one of the words of "A|B".
struct OptionCheck {
  std::int64_t lo = 0, hi = -1;  // a range when lo <= hi
  std::string_view words;
};
constexpr OptionCheck anything() { return {}; }
constexpr OptionCheck range(std::int64_t lo, std::int64_t hi) { return {lo, hi, {}}; }
constexpr OptionCheck oneOf(std::string_view words) { return {0, -1, words}; }
// "" if `text` passes `check`, else why not: one line, the option's name
// left to the caller.
std::string checkOption(const OptionCheck& check, const std::string& text);
// The run's length from `--seconds TEXT` (or the Python keyword): the
// grammar of a written time (timebase/written.h), a number alone in
// seconds, within the one run-length limit; UserError naming --seconds.
timebase::Tick parseLengthOption(const std::string& text);

struct RunOptions {
#define RUN_OPTION(member, Type, initial, flag, keyword, where, check, help) Type member{initial};
#include "runs/run_options.def"
#undef RUN_OPTION
  // A run's length when neither the option nor a scenario gives one (0:
  // the profile's round_length; simbot profile: 60 s).
  timebase::Tick defaultLength = 0;
  // More sinks for the trace's records (the Python module's in-memory
  // trace); each counts as a trace for --watch and --trace-costate.
  std::vector<trace::Sink*> sinks;
};

// The rule set a run plays under: --rules if given, else the scenario's,
// else none ("").
std::string runRules(const RunOptions& o, const std::optional<config::Scenario>& scenario);

// What a run's robots use that a rule set may forbid (config::RunUses),
// each with the file that put it there: `hardwareFiles[i]` is robot i's
// hardware file ("" when none), `obstaclesFile` the file that placed the
// field's obstacles (the scenario's). Then refused where the profile's rules
// forbid it (config::checkRules; a ConfigError at the rule).
void checkRunAgainstRules(const config::Profile& profile, const scheduler::MatchConfig& config,
                          const std::array<std::string, 2>& hardwareFiles,
                          const std::string& obstaclesFile = "");

// A run's fault lines shown (reportFaults, match's table): the first ten
// and the last three, the others counted (a reload storm faults thousands
// of times; the JSON lists them all).
inline constexpr size_t kFaultsShownFirst = 10, kFaultsShownLast = 3;
// Whether the k-th of n faults is one of those shown.
inline bool faultShown(size_t k, size_t n) {
  return n <= kFaultsShownFirst + kFaultsShownLast || k < kFaultsShownFirst ||
         k >= n - kFaultsShownLast;
}

// The run's configuration from the options and the scenario: the programs
// given (A, and B for match), then the scenario (start poses, hardware, B
// for solo and profile, injections), then --hw and --inject. With
// `inputs`, every file it read is added there (for checkFiles).
scheduler::MatchConfig buildConfig(const std::vector<std::string>& programs, const RunOptions& o,
                                   ScenarioUse use, std::vector<files::Named>* inputs = nullptr);

// UserError "simbot: ..." when an output is the same file as an input or
// as another output (files::checkDistinct).
void checkFiles(const std::vector<files::Named>& inputs, const std::vector<files::Named>& outputs);

struct Played {
  scheduler::MatchResult result;
  double wallSeconds = 0;
  uint64_t seed = 0;  // the one used (--seed, the scenario's, or 1)
};

// A solo run (one program) or a match (two); UserError on bad options.
Played play(const std::vector<std::string>& programs, const RunOptions& o, bool solo);

// `simbot solo --json` and `simbot match --json`.
nlohmann::json soloJson(const Played& played);
nlohmann::json matchJson(const Played& played);
// A fault as JSON (null when there is none).
nlohmann::json faultJson(const std::optional<scheduler::FaultInfo>& f);

// Findings that did not stop the run (injections that never fired, ...),
// one line each, on stderr.
void reportWarnings(const scheduler::MatchResult& r);
// A robot's fault in one line: robot, time, source line, message.
std::string faultText(const scheduler::RobotResult& rr, const scheduler::FaultInfo& f);
// One loud line per fault, on stderr; true if any robot faulted.
bool reportFaults(const scheduler::MatchResult& r);

}  // namespace simbot::runs
