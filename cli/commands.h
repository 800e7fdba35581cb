// The subcommands kept out of main.cpp, and the run options every command
// takes from one table (runs/run_options.def). Private to
// cli/ (namespace simbot::cli, the simbot executable), the top of the
// parts: it uses batch/, runs/, reports/ and sinks/; nothing uses it.
#pragma once
#include <CLI/CLI.hpp>
#include <functional>

#include "batch/bench_metrics.h"
#include "runs/play.h"

namespace simbot::cli {

struct Subcommand {
  CLI::App* app = nullptr;
  std::function<int()> run;  // prints its own errors; returns the exit status
};

// Runs a subcommand's body: a UserError or a profile's ConfigError is
// printed on stderr and gives exit status 1.
int guarded(const std::function<int()>& body);

// Replaces this process with the build's Python (SIMBOT_PYTHON, where the
// build has the Python module) running `args`, with `pythonPath` put before
// PYTHONPATH's entries: simbot sweep --dask and simbot serve. UserError
// "simbot: WHAT: cannot run ..." when it cannot start.
[[noreturn]] void execPython(const std::string& pythonPath, std::vector<std::string> args,
                             const std::string& what);

// Where the Python module `simbot` is: beside an installed simbot
// (PREFIX/bin/../SITE), else the build tree's (SIMBOT_PYTHON builds only).
std::string pythonModuleDir();

// A seed: a decimal integer from 0 to 2^64 - 1 (not wrapped, not signed).
CLI::Validator seedValidator();

// The options of runs/run_options.def that `command` (runs::kSolo,
// kBench, ...) offers, into `o` (cli/options.cpp).
void addRunOptions(CLI::App* cmd, runs::RunOptions& o, unsigned command);

Subcommand addBenchCommand(CLI::App& app);
// simbot compare (batch/compare.cpp): the same seeded runs for two programs
// or two profiles, and a test of each metric.
Subcommand addCompareCommand(CLI::App& app);
Subcommand addTournamentCommand(CLI::App& app);
Subcommand addExplainCommand(CLI::App& app);  // cli/explain_command.cpp
Subcommand addSweepCommand(CLI::App& app);    // cli/sweep_command.cpp
Subcommand addCheckCommand(CLI::App& app);    // cli/check_command.cpp
Subcommand addServeCommand(CLI::App& app);    // cli/serve_command.cpp
// simbot hardware (cli/hardware_command.cpp): the values a hardware file
// may set for one robot, and a hardware file checked.
Subcommand addHardwareCommand(CLI::App& app);
// simbot debug (cli/debug_command.cpp): commands from --batch FILE, the
// terminal or stdin; --robot the one held first ("A" or "B").
int debugCommand(const std::vector<std::string>& programs, const runs::RunOptions& o);
// simbot dap (cli/dap_command.cpp): the debugger over the Debug Adapter
// Protocol on stdin and stdout.
int dapCommand();

}  // namespace simbot::cli
