// simbot compare: the very same seeded runs (a family's poses and the
// seeded streams, keyed by run index, not by program) for two programs or
// two profiles, and for each metric whether the two differ: the log-rank
// test for times to an event (right-censored at the run's end), Fisher's
// exact test for the pooled hit ratio and for head-to-head wins, the
// conditional exact test of two Poisson rates for counts, a permutation
// test for stall_s. Each p-value is two-sided and unadjusted for the number
// of metrics.
#pragma once
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "batch/bench.h"

namespace simbot::batch {

struct CompareRow {
  std::string metric;
  std::string test;  // "log-rank", "Fisher exact", "exact Poisson rates", "permutation"
  MetricEstimate a, b;
  std::optional<double> statistic, p;  // none: the test does not apply (no events)
  // What each side's estimate stands on, so that a blank estimate (a median
  // fewer than half the runs reached, a mean of no values) is explained:
  // times: runs that got there of the runs measured; the hit ratio: hits of
  // shots; counts: runs with at least one of the runs measured; stall_s:
  // runs with a value of the runs measured; win_rate: games won of games.
  int64_t reachedA = 0, totalA = 0, reachedB = 0, totalB = 0;
};

struct CompareResult {
  BenchResult a, b;
  std::string profileA, profileB;  // the profiles' names
  std::vector<CompareRow> rows;
};

// Both benches must have one program each, the same family, seeds, seconds
// and master seed (simbot compare sets their seedKey).
std::vector<CompareRow> compareRuns(const BenchResult& a, const BenchResult& b);
nlohmann::json compareJson(const CompareResult& result);
std::string compareMarkdown(const CompareResult& result);

}  // namespace simbot::batch
