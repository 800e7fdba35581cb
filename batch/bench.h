// batch/ (namespace simbot::batch): many runs on worker threads and their
// statistics (stats/ has the maths): bench (this header, with its per-run
// metrics in bench_metrics.h), compare, tournament, sweep, and the CSV
// tables they write without losing a finished run (run_table.h). Each run
// is a runs/ run; parallel.h is private to the part.
//
// simbot bench: scenario families run over many seeds, measured per run by
// MetricsObserver, summarised with censoring (docs/tools.md, "Bench and tournament").
#pragma once
#include <atomic>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "batch/bench_metrics.h"
#include "batch/run_table.h"
#include "config/config.h"
#include "plant/plant.h"
#include "runs/play.h"
#include "runs/scenario.h"
#include "stats/stats.h"

namespace simbot::batch {

struct BenchConfig {
  std::vector<std::string> programs;  // each is robot A in its own runs
  // stationary, circle, head-to-head, edge; empty with a scenario: every run
  // is the scenario's own set-up (only the seeded streams differ).
  std::string family;
  // Profile, hardware, injections (and, alone, poses and B).
  std::optional<config::Scenario> scenario;
  int seeds = 0;  // runs per program
  double seconds = 60;
  uint64_t masterSeed = 1;
  int threads = 0;       // 0: hardware concurrency
  std::string opponent;  // head-to-head: B's program
  bool progress = true;
  MetricThresholds thresholds;  // what counts as acquired and aimed
  // The Kaplan-Meier median on an exact 0.5 plateau (stats.h): its upper
  // end (statsmodels), or its midpoint (SAS, R's survival): --median.
  stats::QuantileRule median = stats::QuantileRule::FirstBelow;
  // The seeds' key in place of each program's file name (simbot compare:
  // both sides play the very same seeded runs).
  std::string seedKey;
};

struct BenchRun {
  std::string program;
  int index = 0;
  uint64_t seed = 0;  // streamSeed(master, "<family>/<program file name>/<index>")
  plant::Pose startA;
  std::optional<plant::Pose> startB;  // absent in solo families
  bool done = false;                  // finished, now or in the batch this one resumes
  // "ok"; "fault" (a robot faulted, or the plant: the run still counts,
  // measured up to its end); "error" (simbot failed on it: no metrics).
  std::string outcome;
  std::string fault;  // what faulted or failed, one line; empty when ok
  RunMetrics metrics;
  // Head-to-head: robot B's metrics and who won ("A" or "B"; by the most
  // hits, a tie by the seeded coin).
  std::optional<RunMetrics> metricsB;
  std::string winner;
  bool coin = false;
  // The run's warnings (injections that never fired, ...): for stderr
  // only, not kept in runs.csv (a resumed run's are not shown again).
  std::vector<std::string> warnings;
};

struct BenchResult {
  BenchConfig config;
  std::vector<BenchRun> runs;  // program by program, each by run index
  bool stopped = false;        // a signal stopped the batch: some runs are not done
};

// Where a bench writes as it goes (the bench command): its table, and the
// flag that stops it. Without them everything stays in memory.
struct BenchIo {
  RunTable* table = nullptr;
  const std::atomic<bool>* stop = nullptr;
};

const std::vector<std::string>& benchFamilies();
// The circle family's opponent: a beacon driving clockwise round the
// field's centre on this circle, at this speed, for ever.
inline constexpr double kCircleRadiusFt = 3.0;
inline constexpr double kCircleSpeedFps = 0.5;
// The family's name in outputs: the family, or "scenario NAME".
std::string benchLabel(const BenchConfig& config);

// Run `index` of `program`: streamSeed(master, "<family>/<program's file
// name>/<index>"), the seed key in place of the file name when given.
uint64_t benchRunSeed(const BenchConfig& config, const std::string& program, int index);
// A bench's configuration from the run options of `simbot bench`,
// `simbot compare` and simbot.bench() (runs/run_options.def): --family,
// --seeds, --seconds (else BenchConfig's 60 s), --seed, --threads,
// --opponent, the thresholds, --median; with `scenario`, its seconds and
// seed where the options give none. The programs are the caller's.
BenchConfig benchConfig(const runs::RunOptions& o,
                        const std::optional<config::Scenario>& scenario = std::nullopt);
// UserError if the configuration cannot run (a family, the counts).
void checkBenchConfig(const BenchConfig& config);
// runs.csv's columns, and the settings that identify a bench (batch.json).
CsvRow benchHeader();
nlohmann::json benchSettings(const BenchConfig& config, const config::Profile& profile);
// Every file a bench reads: programs, opponent, profile, scenario and the
// files the scenario names.
std::vector<std::string> benchInputs(const BenchConfig& config, const config::Profile& profile);

// Runs every run not already in io.table (resume); each finished run goes
// to the table as it completes. The table begins (RunTable::begin) only
// once every program is compiled and the resumed rows are checked. A run
// that faults or fails is recorded as such; the others go on.
BenchResult runBench(const BenchConfig& config, const config::Profile& profile,
                     const BenchIo& io = {});

// The finished runs, in order (the final runs.csv).
std::string runsCsv(const BenchResult& result);

// The summary (batch/bench_summary.cpp): for each program, each metric with
// the estimator that suits it (Kaplan-Meier for times to an event, Wilson
// for the hit ratio, Garwood's exact Poisson interval for counts, a
// bootstrap for stall_s), robot B's too and the win rate in head-to-head.
struct MetricEstimate {
  std::string metric;
  std::string estimator;  // "Kaplan-Meier median", "Wilson", "exact Poisson", "bootstrap mean"
  int n = 0;              // runs in the estimate (at risk at 0 for a time)
  int events = 0;         // times: runs that got there; hit_ratio: hits; counts: their total
  int64_t trials = 0;     // hit_ratio: shots
  std::optional<double> estimate;
  // 95%; a KM quantile's upper limit may be +infinity (past the last event).
  std::optional<double> low, high;
  std::optional<double> reachedBy;  // times: the KM fraction reached by reachedByS
  double reachedByS = 0;
};
struct RobotSummary {
  std::string robot, program;  // "A"/"B"
  std::vector<MetricEstimate> metrics;
};
struct ProgramSummary {
  std::string program;
  int done = 0, faults = 0, errors = 0;
  std::vector<RobotSummary> robots;  // A, and B in head-to-head
  // Head-to-head: games A won of those played, and the Wilson interval.
  int games = 0, winsA = 0, coinWins = 0;
  std::optional<double> winRate, winLow, winHigh;
};
// The seconds at which times report the fraction reached: 60 or the runs'
// length if shorter.
double reachedByHorizon(const BenchConfig& config);
std::vector<ProgramSummary> summarize(const BenchResult& result);
nlohmann::json summaryJson(const BenchResult& result);
std::string summaryMarkdown(const BenchResult& result);
// An estimate or a limit as the summaries write it: JSON has no infinity,
// so an unbounded upper limit is null (with "ci95_high_unbounded": true);
// the tables give 4 significant digits, and nothing for no estimate.
nlohmann::json estimateJson(const std::optional<double>& v);
std::string estimateText(const std::optional<double>& v);
// The observations of one time metric over the runs given, censored at the
// runs' end (a leg of the edge sequence: only runs that began it, censored
// at the time left after it began).
std::vector<stats::Observation> timeObservations(const std::vector<const BenchRun*>& runs,
                                                 bool robotB, size_t metric, double seconds);
enum class MetricKind { Time, Ratio, Count, Continuous };
MetricKind metricKind(const std::string& name);
// Rewrites the table in order, and writes summary.json and summary.md
// beside it (each through a temporary file).
void writeBenchOutputs(const BenchResult& result, RunTable& table);
// One line per run that faulted or failed (at most `most`, then a count).
std::string benchFaults(const BenchResult& result, size_t most = 20);
// One line per warning of a run (at most `most`, then a count).
std::string benchWarnings(const BenchResult& result, size_t most = 20);

}  // namespace simbot::batch
