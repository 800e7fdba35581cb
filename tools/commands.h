// The bench and tournament subcommands, kept out of main.cpp.
#pragma once
#include <CLI/CLI.hpp>
#include <functional>

namespace simbot::tools {

struct Subcommand {
  CLI::App* app = nullptr;
  std::function<int()> run;  // prints its own errors; returns the exit status
};

// A seed: a decimal integer from 0 to 2^64 - 1 (not wrapped, not signed).
CLI::Validator seedValidator();

Subcommand addBenchCommand(CLI::App& app);
Subcommand addTournamentCommand(CLI::App& app);
Subcommand addExplainCommand(CLI::App& app);  // tools/explain_command.cpp

}  // namespace simbot::tools
