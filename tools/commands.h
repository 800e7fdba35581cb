// The bench and tournament subcommands, kept out of main.cpp.
#pragma once
#include <CLI/CLI.hpp>
#include <functional>

#include "tools/bench_metrics.h"

namespace simbot::tools {

struct Subcommand {
  CLI::App* app = nullptr;
  std::function<int()> run;  // prints its own errors; returns the exit status
};

// Runs a subcommand's body: a ToolError or a profile's ConfigError is
// printed on stderr and gives exit status 1.
int guarded(const std::function<int()>& body);

// A seed: a decimal integer from 0 to 2^64 - 1 (not wrapped, not signed).
CLI::Validator seedValidator();

Subcommand addBenchCommand(CLI::App& app);
// simbot compare (tools/compare.cpp): the same seeded runs for two programs
// or two profiles, and a test of each metric.
Subcommand addCompareCommand(CLI::App& app);
// --seen-threshold, --aim-max-diff, --aim-min-sum (bench and compare).
void addThresholdOptions(CLI::App& cmd, MetricThresholds& thresholds);
Subcommand addTournamentCommand(CLI::App& app);
Subcommand addExplainCommand(CLI::App& app);  // tools/explain_command.cpp

}  // namespace simbot::tools
