// One solo run or match from run options, and its JSON summary: the CLI's
// solo, match and profile commands and the Python module (python/) share
// these, so `simbot match A B --json` and simbot.match(A, B) give the same
// JSON.
#pragma once
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "scheduler/match.h"
#include "tools/scenario.h"
#include "trace/trace.h"

namespace simbot::tools {

// Where a run option is offered (tools/run_options.def).
enum RunOptionUse : unsigned { kSolo = 1, kMatch = 2, kProfile = 4, kPython = 8 };

struct RunOptions {
#define RUN_OPTION(member, Type, flag, keyword, where, help) Type member{};
#include "tools/run_options.def"
#undef RUN_OPTION
  // A run's length when neither the option nor a scenario gives one (0:
  // the profile's round_length; simbot profile: 60 s).
  double defaultSeconds = 0;
  // More sinks for the trace's records (the Python module's in-memory
  // trace); each counts as a trace for --watch and --trace-costate.
  std::vector<trace::Sink*> sinks;
};

// The run's configuration from the options and the scenario: the programs
// given (A, and B for match), then the scenario (start poses, hardware, B
// for solo and profile, injections), then --hw and --inject.
scheduler::MatchConfig buildConfig(const std::vector<std::string>& programs, const RunOptions& o,
                                   ScenarioUse use);

struct Played {
  scheduler::MatchResult result;
  double wallSeconds = 0;
  uint64_t seed = 0;  // the one used (--seed, the scenario's, or 1)
};

// A solo run (one program) or a match (two); ToolError on bad options.
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

}  // namespace simbot::tools
