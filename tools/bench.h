// simbot bench: scenario families run over many seeds, measured per run by
// scheduler::MetricsObserver, summarised with censoring (README "bench").
#pragma once
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "plant/plant.h"
#include "scheduler/metrics.h"
#include "tools/scenario.h"

namespace simbot::tools {

struct BenchConfig {
  std::vector<std::string> programs;  // each is robot A in its own runs
  // stationary, circle, head-to-head, edge; empty with a scenario: every run
  // is the scenario's own set-up (only the seeded streams differ).
  std::string family;
  std::optional<Scenario> scenario;  // profile, hardware, injections (and, alone, poses and B)
  int seeds = 0;                     // runs per program
  double seconds = 60;
  uint64_t masterSeed = 1;
  int threads = 0;       // 0: hardware concurrency
  std::string opponent;  // head-to-head: B's program
  bool progress = true;
};

struct BenchRun {
  std::string program;
  int index = 0;
  uint64_t seed = 0;  // streamSeed(master, "<family>/<program file name>/<index>")
  plant::Pose startA;
  std::optional<plant::Pose> startB;  // absent in solo families
  scheduler::RunMetrics metrics;
};

struct BenchResult {
  BenchConfig config;
  std::vector<BenchRun> runs;  // program by program, each by run index
};

const std::vector<std::string>& benchFamilies();
// The circle family's opponent: a beacon driving clockwise round the
// field's centre on this circle, at this speed, for ever.
inline constexpr double kCircleRadiusFt = 3.0;
inline constexpr double kCircleSpeedFps = 0.5;
// The family's name in outputs: the family, or "scenario NAME".
std::string benchLabel(const BenchConfig& config);

BenchResult runBench(const BenchConfig& config, const plant::Profile& profile);

std::string runsCsv(const BenchResult& result);
nlohmann::json summaryJson(const BenchResult& result);
std::string summaryMarkdown(const BenchResult& result);
// Writes runs.csv, summary.json and summary.md into `dir` (created).
void writeBenchOutputs(const BenchResult& result, const std::string& dir);

}  // namespace simbot::tools
