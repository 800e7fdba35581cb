// One solo run or match from run options, and its JSON summary: the CLI's
// solo, match and profile commands and the Python module (python/) share
// these, so `simbot match A B --json` and simbot.match(A, B) give the same
// JSON.
#pragma once
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "scheduler/match.h"
#include "tools/scenario.h"
#include "trace/trace.h"

namespace simbot::tools {

struct RunOptions {
  double seconds = 0;  // not given: the profile's [match] round_length
  uint64_t seed = 1;
  std::string profile = "default";
  std::vector<std::string> hw;
  std::string trace;
  std::string vcd;
  std::string replay;
  std::vector<std::string> injections;
  std::vector<std::string> watches;
  bool traceCostate = false;
  bool noFastForward = false;
  std::string scenario;
  bool json = false;
  bool reloadOnFault = false;
  // Options given explicitly win over the scenario's values.
  bool secondsGiven = false, seedGiven = false, profileGiven = false;
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
