// A run with its trace as JSONL lines in memory, as `simbot --trace` would
// write them.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "scheduler/match.h"
#include "sinks/trace_jsonl.h"

namespace simbot::testkit {

struct TracedRun : scheduler::MatchResult {
  std::vector<std::string> trace;
};

inline TracedRun runTraced(scheduler::MatchConfig config) {
  sinks::JsonlLines lines;
  config.sinks.push_back(&lines);
  TracedRun run{scheduler::runMatch(config), {}};
  run.trace = std::move(lines.lines);
  return run;
}

}  // namespace simbot::testkit
