// simbot: the command line. Each subcommand is a thin layer over the parts
// (compiler/, vm/, plant/, scheduler/, and above them runs/, batch/,
// reports/, sinks/); DESIGN.md's tool contract says what tests and scripts
// rely on.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "batch/sweep.h"
#include "cli/commands.h"
#include "cli/version.h"
#include "compiler/compiler.h"
#include "config/config.h"
#include "files/files.h"
#include "plant/plant.h"
#include "reports/viewer.h"
#include "runs/play.h"
#include "runs/scenario.h"
#include "scheduler/match.h"
#include "sinks/json_text.h"
#include "sinks/trace_jsonl.h"
#include "sinks/user_error.h"
#include "sinks/vcd.h"
#include "timebase/tick.h"
#include "vm/vm.h"

namespace {

using namespace simbot;
using nlohmann::json;

// simbot compile FILE [--disasm] [-Wno-NAME ...] [-Werror]: the -W words
// come through CLI11 as extras (it has no multi-letter single-dash options).
int compileCommand(const std::string& file, bool disasm, const std::vector<std::string>& extras) {
  compiler::Options options;
  runs::parseWarningOptions(extras, options, "compile");
  const auto result = compiler::compileFile(file, options);
  // Errors and warnings together, in source order (each list already is).
  std::vector<compiler::Diagnostic> all = result.warnings;
  all.insert(all.end(), result.errors.begin(), result.errors.end());
  std::stable_sort(all.begin(), all.end(), [](const auto& a, const auto& b) {
    return a.line != b.line ? a.line < b.line : a.column < b.column;
  });
  for (const auto& d : all) std::cerr << d.format();
  if (!result.image) return 1;
  if (disasm) std::cout << vm::disassemble(*result.image);
  return 0;
}

// simbot view TRACE.jsonl [-o FILE.html]: the replay page of a recorded
// run, by default beside the trace (TRACE with .html for its extension).
int viewCommand(const std::string& tracePath, std::string out) {
  if (out.empty()) out = std::filesystem::path(tracePath).replace_extension(".html").string();
  runs::checkFiles({{tracePath, "the trace"}}, {{out, "the page"}});
  reports::ReplaySink page(out);
  const sinks::TraceRead read =
      sinks::readTrace(tracePath, [&](const trace::Entry& e) { page.write(e); });
  std::cerr << sinks::cutShortWarning(tracePath, read);
  page.close();
  std::cerr << "simbot: wrote " << out << '\n';
  return 0;
}

// Exit statuses (README, "Options, time, exit statuses, errors").
constexpr int kExitBadInput = 1;
constexpr int kExitInternalError = 2;
constexpr int kExitRobotFault = 3;

int soloCommand(const std::string& program, const runs::RunOptions& o) {
  const runs::Played played = runs::play({program}, o, true);
  const auto& r = played.result;
  const auto& a = r.robots[0];
  if (o.json) {
    std::cout << sinks::dumpJson(runs::soloJson(played), 2) << '\n';
  } else {
    for (const auto& line : a.console) std::cout << line << '\n';
    std::cerr << fmt::format(
        "simbot: {} {} at {:.3f} s; {} frames latched, {} rejected, {} frames overwritten{}\n",
        program,
        a.fault    ? "faulted"
        : a.exited ? "exited"
                   : "ran",
        timebase::secondsFromTicks(r.endTick), a.framesLatched, a.framesRejected,
        a.framesOverwritten, a.reloads ? fmt::format(", {} reloads", a.reloads) : "");
  }
  runs::reportWarnings(r);
  return runs::reportFaults(r) ? kExitRobotFault : 0;
}

int matchCommand(const std::string& a, const std::string& b, const runs::RunOptions& o) {
  const runs::Played played = runs::play({a, b}, o, false);
  const auto& r = played.result;
  const double wall = played.wallSeconds;
  if (o.json) {
    std::cout << sinks::dumpJson(runs::matchJson(played), 2) << '\n';
  } else {
    for (const auto& rr : r.robots) {
      std::cout << fmt::format(
          "{} {:<24} hits {:>2}  shots {:>2}  frames {:>5} (+{} rejected, {} frames "
          "overwritten){}{}\n",
          rr.name, rr.program, rr.hits, rr.shots, rr.framesLatched, rr.framesRejected,
          rr.framesOverwritten, rr.reloads ? fmt::format("  reloads {}", rr.reloads) : "",
          rr.secondary ? fmt::format("  discs {} ({} hits, not scored)", rr.secondary->shots,
                                     rr.secondary->hits)
                       : "");
      // As many as stderr's report shows (runs::reportFaults), no more.
      const size_t n = rr.faults.size();
      for (size_t k = 0; k < n; ++k) {
        if (runs::faultShown(k, n))
          std::cout << "  " << runs::faultText(rr, rr.faults[k]) << '\n';
        else if (k == runs::kFaultsShownFirst)
          std::cout << fmt::format("  ... {} more faults\n",
                                   n - runs::kFaultsShownFirst - runs::kFaultsShownLast);
      }
    }
    std::cout << fmt::format("winner: {}{}  ({:.1f} s simulated in {:.2f} s)\n", r.winner,
                             r.tieBrokenByCoin ? " (coin flip)" : "",
                             timebase::secondsFromTicks(r.endTick), wall);
  }
  runs::reportWarnings(r);
  return runs::reportFaults(r) ? kExitRobotFault : 0;
}

// Cycles per source line and per function of a solo run, largest first.
int profileCommand(const std::string& program, runs::RunOptions o) {
  const int top = o.top;
  o.trace.clear();
  scheduler::MatchConfig config = runs::buildConfig({program}, o, runs::ScenarioUse::Profile);
  config.stopWhenAllExited = true;
  config.profile = true;
  const vm::Image& image = config.robots[0].image;
  scheduler::MatchResult r;
  try {
    r = scheduler::runMatch(config);
  } catch (const std::invalid_argument& e) {
    throw sinks::UserError(fmt::format("simbot: {}\n", e.what()));
  }
  runs::reportWarnings(r);
  // A faulted run is profiled up to the fault, and said so (exit status 3).
  const int status = runs::reportFaults(r) ? kExitRobotFault : 0;
  const auto& robot = r.robots[0];
  std::map<int, uint64_t> byLine;
  std::map<std::string, uint64_t> byFunction;
  uint64_t busy = robot.serialIsrCycles + robot.timerIsrCycles;
  for (uint32_t at = 0; at < robot.profile.size(); ++at) {
    const uint64_t cycles = robot.profile[at];
    if (cycles == 0) continue;
    busy += cycles;
    byLine[image.lineAt(at)] += cycles;
    const vm::Symbol* fn = image.functionAt(at);
    byFunction[fn ? fn->name : "(start-up)"] += cycles;
  }
  const uint64_t total = robot.vmClock;  // everything the profile counts
  const uint64_t idle = total > busy ? total - busy : 0;
  auto functionOf = [&](int line) {
    for (uint32_t at = 0; at < image.lines.size(); ++at)
      if (image.lines[at] == line)
        if (const vm::Symbol* fn = image.functionAt(at)) return fn->name;
    return std::string();
  };
  auto sorted = [](const auto& m) {
    std::vector<std::pair<typename std::decay_t<decltype(m)>::key_type, uint64_t>> v(m.begin(),
                                                                                     m.end());
    std::stable_sort(v.begin(), v.end(),
                     [](const auto& a, const auto& b) { return a.second > b.second; });
    return v;
  };
  const auto functions = sorted(byFunction);
  const auto lines = sorted(byLine);
  const double tps = static_cast<double>(scheduler::kTicksPerSecond);
  auto pct = [&](uint64_t c) { return total ? 100.0 * static_cast<double>(c) / total : 0.0; };
  if (o.json) {
    json j = {{"program", program},
              {"sim_seconds", static_cast<double>(total) / tps},
              {"cycles", total},
              {"serial_isr_cycles", robot.serialIsrCycles},
              {"timer_isr_cycles", robot.timerIsrCycles},
              {"idle_cycles", idle},
              {"fault", runs::faultJson(robot.fault)},
              {"functions", json::array()},
              {"lines", json::array()}};
    for (const auto& [name, cycles] : functions)
      j["functions"].push_back({{"function", name},
                                {"cycles", cycles},
                                {"seconds", static_cast<double>(cycles) / tps},
                                {"percent", pct(cycles)}});
    for (const auto& [line, cycles] : lines)
      j["lines"].push_back(
          {{"line", line},
           {"function", functionOf(line)},
           {"cycles", cycles},
           {"seconds", static_cast<double>(cycles) / tps},
           {"percent", pct(cycles)},
           {"source", line > 0 && line <= static_cast<int>(image.sourceLines.size())
                          ? image.sourceLines[static_cast<size_t>(line - 1)]
                          : ""}});
    std::cout << sinks::dumpJson(j, 2) << '\n';
    return status;
  }
  std::cout << fmt::format("{}: {:.3f} simulated seconds, {} T-states{}\n\n", program,
                           static_cast<double>(total) / tps, total,
                           robot.exited ? " (main returned)" : "");
  std::cout << fmt::format("{:>12} {:>9} {:>6}  {}\n", "T-states", "seconds", "%", "function");
  for (const auto& [name, cycles] : functions)
    std::cout << fmt::format("{:>12} {:>9.3f} {:>6.2f}  {}\n", cycles,
                             static_cast<double>(cycles) / tps, pct(cycles), name);
  // Time spent outside the program's own code, each on a row when there is any.
  for (const auto& [cycles, what] :
       {std::pair{robot.serialIsrCycles, "(serial transmit interrupts)"},
        std::pair{robot.timerIsrCycles, "(timer service, PRT0 at 1,024 Hz)"},
        std::pair{idle, "(halted)"}})
    if (cycles)
      std::cout << fmt::format("{:>12} {:>9.3f} {:>6.2f}  {}\n", cycles,
                               static_cast<double>(cycles) / tps, pct(cycles), what);
  std::cout << fmt::format("\n{:>12} {:>9} {:>6}  {:>5}  {}\n", "T-states", "seconds", "%", "line",
                           "source");
  int shown = 0;
  for (const auto& [line, cycles] : lines) {
    if (shown++ == top) break;
    std::string text = line > 0 && line <= static_cast<int>(image.sourceLines.size())
                           ? image.sourceLines[static_cast<size_t>(line - 1)]
                           : "";
    std::cout << fmt::format("{:>12} {:>9.3f} {:>6.2f}  {:>5}  {}\n", cycles,
                             static_cast<double>(cycles) / tps, pct(cycles), line, text);
  }
  return status;
}

// -W words come through CLI11 as extras (it has no multi-letter
// single-dash options); main() checks them.
void addWarningOptions(CLI::App* cmd) {
  cmd->allow_extras();
  cmd->footer(
      "Warnings: -Wno-NAME turns one off, -Werror makes every warning an error (docs/language.md "
      "lists the names).");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"simbot: a timing-faithful simulator of the 1997 NPS Robot Wars"};
  app.set_version_flag("--version", cli::simbotVersion());
  app.require_subcommand(1);

  std::string compileFile;
  bool disasm = false;
  auto* compile = app.add_subcommand("compile", "compile a Dynamic C program");
  compile->add_option("FILE", compileFile, "program (.dc)")->required();
  compile->add_flag("--disasm", disasm, "print the bytecode, interleaved with the source");
  addWarningOptions(compile);

  runs::RunOptions soloOptions;
  std::string soloProgram;
  auto* solo = app.add_subcommand("solo", "run one robot alone in the arena");
  solo->add_option("FILE", soloProgram, "program (.dc)")->required();
  cli::addRunOptions(solo, soloOptions, runs::kSolo);
  addWarningOptions(solo);

  runs::RunOptions matchOptions;
  std::string programA, programB;
  auto* match = app.add_subcommand("match", "play a match between two programs");
  match->add_option("A", programA, "robot A's program")->required();
  match->add_option("B", programB, "robot B's program")->required();
  cli::addRunOptions(match, matchOptions, runs::kMatch);
  addWarningOptions(match);

  runs::RunOptions profileOptions;
  profileOptions.defaultLength = 60 * timebase::kTicksPerSecond;
  std::string profileProgram;
  auto* profile =
      app.add_subcommand("profile", "cycles and time per source line and function of a solo run");
  profile->add_option("FILE", profileProgram, "program (.dc)")->required();
  cli::addRunOptions(profile, profileOptions, runs::kProfile);
  addWarningOptions(profile);

  std::string viewTrace, viewOut;
  auto* view = app.add_subcommand("view", "write the replay page (HTML) of a recorded trace");
  view->add_option("TRACE", viewTrace, "trace file (.jsonl) written with --trace")->required();
  view->add_option("-o,--output", viewOut,
                   "the page to write (default: beside the trace, with .html for its extension)");

  runs::RunOptions debugOptions;
  std::vector<std::string> debugPrograms;
  auto* debugCmd = app.add_subcommand(
      "debug",
      "stop a robot and look at it: breakpoints, stepping both ways in simulated time, any "
      "variable (gdb's commands; README \"Debugging\")");
  debugCmd->add_option("PROGRAMS", debugPrograms, "robot A's program, and B's for a match")
      ->required()
      ->expected(1, 2);
  cli::addRunOptions(debugCmd, debugOptions, runs::kDebug);
  addWarningOptions(debugCmd);
  auto* dapCmd = app.add_subcommand(
      "dap",
      "the debugger for VS Code: the Debug Adapter Protocol on stdin and stdout (the launch "
      "request names the programs; docs/vscode.md)");

  const auto bench = simbot::cli::addBenchCommand(app);
  const auto compare = simbot::cli::addCompareCommand(app);
  const auto tournament = simbot::cli::addTournamentCommand(app);
  addWarningOptions(bench.app);
  addWarningOptions(tournament.app);
  addWarningOptions(compare.app);
  const auto explain = simbot::cli::addExplainCommand(app);
  const auto sweep = simbot::cli::addSweepCommand(app);
  addWarningOptions(sweep.app);
  const auto check = simbot::cli::addCheckCommand(app);
  addWarningOptions(check.app);
  const auto serve = simbot::cli::addServeCommand(app);
  const auto hardware = simbot::cli::addHardwareCommand(app);

  files::removeTemporariesOnSignals();
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // A usage error: one line, exit status 1.
    std::string message = e.what();
    std::replace(message.begin(), message.end(), '\n', ' ');
    std::cerr << "simbot: " << message << " (simbot --help lists the options)\n";
    return kExitBadInput;
  }
  try {
    // -Wno-NAME and -Werror, on every command that compiles a program.
    for (CLI::App* cmd : {solo, match, profile, debugCmd, bench.app, tournament.app, compare.app,
                          sweep.app, check.app})
      if (*cmd) {
        compiler::Options options;
        runs::parseWarningOptions(cmd->remaining(), options, cmd->get_name());
        runs::setCompileOptions(options);
      }
    if (*compile) return compileCommand(compileFile, disasm, compile->remaining());
    if (*solo) return soloCommand(soloProgram, soloOptions);
    if (*match) return matchCommand(programA, programB, matchOptions);
    if (*profile) return profileCommand(profileProgram, profileOptions);
    if (*debugCmd) return cli::debugCommand(debugPrograms, debugOptions);
    if (*dapCmd) return cli::dapCommand();
    if (*view) return viewCommand(viewTrace, viewOut);
    if (*bench.app) return bench.run();
    if (*compare.app) return compare.run();
    if (*tournament.app) return tournament.run();
    if (*explain.app) return explain.run();
    if (*sweep.app) return sweep.run();
    if (*check.app) return check.run();
    if (*serve.app) return serve.run();
    if (*hardware.app) return hardware.run();
  } catch (const sinks::UserError& e) {
    std::cerr << e.what();
    return kExitBadInput;
  } catch (const config::ConfigError& e) {
    std::cerr << e.what() << '\n';
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << "simbot: internal error: " << e.what() << "\n";
    return kExitInternalError;
  }
  return 0;
}
