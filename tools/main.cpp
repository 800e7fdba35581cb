// simbot: the command line. Each subcommand is a thin layer over the parts
// (compiler/, vm/, plant/, scheduler/); DESIGN.md's tool contract says what
// tests and scripts rely on.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "compiler/compiler.h"
#include "plant/plant.h"
#include "scheduler/match.h"
#include "timebase/tick.h"
#include "tools/commands.h"
#include "tools/json_text.h"
#include "tools/runner.h"
#include "tools/scenario.h"
#include "tools/trace_jsonl.h"
#include "tools/vcd.h"
#include "tools/viewer.h"
#include "vm/vm.h"

namespace {

using namespace simbot;
using nlohmann::json;

// simbot compile FILE [--disasm] [-Wno-NAME ...] [-Werror]: the -W words
// come through CLI11 as extras (it has no multi-letter single-dash options).
int compileCommand(const std::string& file, bool disasm, const std::vector<std::string>& extras) {
  compiler::Options options;
  for (const std::string& w : extras) {
    if (w == "-Werror") {
      options.werror = true;
    } else if (w.rfind("-Wno-", 0) == 0 && compiler::isWarningName(w.substr(5))) {
      options.disabledWarnings.insert(w.substr(5));
    } else {
      std::string names;
      for (const auto& info : compiler::warningList())
        names += (names.empty() ? "" : ", ") + std::string(info.name);
      std::cerr << "simbot: compile: unknown option '" << w << "' (warnings: " << names
                << "; simbot compile --help lists the options)\n";
      return 1;
    }
  }
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

// simbot view TRACE.jsonl -o FILE.html: the replay page of a recorded run.
int viewCommand(const std::string& tracePath, const std::string& out) {
  tools::ReplaySink page(out);
  tools::readTrace(tracePath, [&](const trace::Entry& e) { page.write(e); });
  page.close();
  return 0;
}

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
  CLI::Option *secondsOption = nullptr, *seedOption = nullptr, *profileOption = nullptr;
};

bool given(const CLI::Option* option) { return option && option->count() > 0; }

json poseJson(const plant::Pose& p) {
  return {{"x_ft", p.x_ft}, {"y_ft", p.y_ft}, {"heading_deg", p.heading_deg}};
}

// Console lines are bytes the robot printed: one character per byte.
json consoleJson(const std::vector<std::string>& lines) {
  json out = json::array();
  for (const auto& line : lines) out.push_back(tools::jsonString(line, true));
  return out;
}

// Exit statuses (README, "Exit statuses").
constexpr int kExitBadInput = 1;
constexpr int kExitInternalError = 2;
constexpr int kExitRobotFault = 3;

// Findings that did not stop the run (injections that never fired, ...).
void reportWarnings(const scheduler::MatchResult& r) {
  for (const auto& w : r.warnings) std::cerr << "simbot: warning: " << w << '\n';
}

// A robot's fault in one line: robot, time, source line, message.
std::string faultText(const scheduler::RobotResult& rr, const scheduler::FaultInfo& f) {
  return fmt::format("{}:{}: fault: robot {} at {:.6f} s: {}", rr.program, f.line, rr.name, f.timeS,
                     f.message);
}

// One loud line per fault, on stderr; true if any robot faulted.
bool reportFaults(const scheduler::MatchResult& r) {
  bool any = false;
  if (r.plantFault) {
    any = true;
    std::cerr << fmt::format(
        "simbot: fault: the plant's integrator failed at {:.6f} s: {}; the "
        "run ended there\n",
        r.plantFault->timeS, r.plantFault->message);
  }
  for (const auto& rr : r.robots) {
    for (size_t k = 0; k < rr.faults.size(); ++k) {
      any = true;
      std::cerr << faultText(rr, rr.faults[k])
                << (k < static_cast<size_t>(rr.reloads) ? " (reloaded)" : "") << '\n';
    }
  }
  return any;
}

json faultJson(const std::optional<scheduler::FaultInfo>& f) {
  if (!f) return nullptr;
  return {{"message", f->message}, {"time_s", f->timeS}, {"line", f->line}};
}

json faultsJson(const std::vector<scheduler::FaultInfo>& faults) {
  json out = json::array();
  for (const auto& f : faults) out.push_back(faultJson(f));
  return out;
}

// The run's configuration from the command line and the scenario: the
// programs given (A, and B for match), then the scenario (start poses,
// hardware, B for solo and profile, injections), then --hw and --inject.
scheduler::MatchConfig buildConfig(const std::vector<std::string>& programs, const RunOptions& o,
                                   tools::ScenarioUse use) {
  std::optional<tools::Scenario> scenario;
  if (!o.scenario.empty()) scenario = tools::loadScenario(o.scenario);
  const plant::Profile profile = tools::loadNamedProfile(tools::preferCommandLine(
      given(o.profileOption), scenario ? scenario->profile : std::nullopt, o.profile));
  // Without --seconds or a scenario's, a run lasts the profile's round.
  const double seconds = tools::preferCommandLine(
      given(o.secondsOption), scenario ? scenario->seconds : std::nullopt,
      given(o.secondsOption) || o.seconds > 0 ? o.seconds : profile.round_length_s);
  if (!(seconds > 0) || seconds > 1e6)
    throw tools::ToolError(fmt::format("simbot: --seconds must be in (0, 1e6], got {}\n", seconds));
  scheduler::MatchConfig config;
  config.arena = plant::makeArenaConfig(profile, static_cast<int>(programs.size()));
  config.profileName = profile.name;
  const char* names[] = {"A", "B"};
  for (size_t i = 0; i < programs.size(); ++i)
    config.robots.push_back({names[i], programs[i], tools::compileProgramFile(programs[i])});
  std::array<bool, 2> hwGiven{};
  std::vector<std::pair<int, std::string>> hwFiles;
  for (const auto& spec : o.hw) {
    int robot = 0;
    std::string file = spec;
    if (use == tools::ScenarioUse::Match) {
      const auto eq = spec.find('=');
      if (eq == std::string::npos || (spec.substr(0, eq) != "A" && spec.substr(0, eq) != "B"))
        throw tools::ToolError("simbot: --hw takes A=FILE or B=FILE\n");
      robot = spec[0] == 'A' ? 0 : 1;
      file = spec.substr(eq + 1);
    }
    hwGiven[static_cast<size_t>(robot)] = true;
    hwFiles.emplace_back(robot, file);
  }
  if (scenario) tools::applyScenario(*scenario, use, profile, config, hwGiven);
  for (const auto& [robot, file] : hwFiles) {
    auto& setup = config.arena.robots[static_cast<size_t>(robot)];
    setup.hardware = plant::loadHardware(file, setup.params);
  }
  for (const auto& text : o.injections) {
    try {
      config.injections.push_back(
          scheduler::parseInjection(text, static_cast<int>(config.robots.size())));
    } catch (const std::invalid_argument& e) {
      throw tools::ToolError(fmt::format("simbot: --inject {}\n", e.what()));
    }
  }
  config.endTick = timebase::ticksFromSeconds(seconds);
  config.seed = tools::preferCommandLine(given(o.seedOption),
                                         scenario ? scenario->seed : std::nullopt, o.seed);
  config.reloadOnFault = o.reloadOnFault;
  config.reloadDelay = timebase::ticksFromSeconds(profile.reload_delay_s);
  return config;
}

struct Played {
  scheduler::MatchResult result;
  double wallSeconds = 0;
  uint64_t seed = 0;  // the one used (--seed, the scenario's, or 1)
};

Played play(const std::vector<std::string>& programs, const RunOptions& o, bool solo) {
  // Watched values are written only into trace records.
  if (!o.watches.empty() && o.trace.empty() && o.replay.empty())
    throw tools::ToolError(
        "simbot: --watch needs --trace FILE (or --replay FILE): watched values are written "
        "only into the trace's records\n");
  scheduler::MatchConfig config =
      buildConfig(programs, o, solo ? tools::ScenarioUse::Solo : tools::ScenarioUse::Match);
  config.stopWhenAllExited = solo;
  config.watches = o.watches;
  if (o.traceCostate && o.trace.empty() && o.replay.empty())
    throw tools::ToolError("simbot: --trace-costate needs --trace FILE (or --replay FILE)\n");
  config.traceCostate = o.traceCostate;
  if (o.noFastForward) config.knobs.fastForward = false;
  // Sinks open their files before the run: a bad path costs nothing.
  std::optional<tools::JsonlSink> jsonl;
  std::optional<tools::VcdSink> vcd;
  std::optional<tools::ReplaySink> replay;
  if (!o.trace.empty()) config.sinks.push_back(&jsonl.emplace(o.trace));
  if (!o.vcd.empty()) config.sinks.push_back(&vcd.emplace(o.vcd));
  if (!o.replay.empty()) config.sinks.push_back(&replay.emplace(o.replay));
  Played played;
  played.seed = config.seed;
  const auto start = std::chrono::steady_clock::now();
  try {
    played.result = scheduler::runMatch(config);
  } catch (const std::invalid_argument& e) {
    throw tools::ToolError(fmt::format("simbot: {}\n", e.what()));
  }
  played.wallSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return played;
}

int soloCommand(const std::string& program, const RunOptions& o) {
  const Played played = play({program}, o, true);
  const auto& r = played.result;
  const double wall = played.wallSeconds;
  const auto& a = r.robots[0];
  json j = {
      {"exited", a.exited},
      {"exit_time_s", a.exited ? json(timebase::secondsFromTicks(a.exitTick)) : json(nullptr)},
      {"cycles", a.cycles},
      {"vm_instructions", a.vmInstructions},
      {"sim_seconds", timebase::secondsFromTicks(r.endTick)},
      {"wall_seconds", wall},
      {"console", consoleJson(a.console)},
      {"fault", faultJson(a.fault)},
      {"faults", faultsJson(a.faults)},
      {"reloads", a.reloads},
      {"plant_fault", faultJson(r.plantFault)},
      {"motor_frames_latched", a.framesLatched},
      {"motor_frames_rejected", a.framesRejected},
      {"motor_frames_overwritten", a.framesOverwritten},
      {"interrupts", a.interrupts},
      {"final_pose", poseJson(a.finalPose)}};
  if (o.json) {
    std::cout << tools::dumpJson(j, 2) << '\n';
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
  reportWarnings(r);
  return reportFaults(r) ? kExitRobotFault : 0;
}

int matchCommand(const std::string& a, const std::string& b, const RunOptions& o) {
  const Played played = play({a, b}, o, false);
  const auto& r = played.result;
  const double wall = played.wallSeconds;
  json robots = json::array();
  for (const auto& rr : r.robots)
    robots.push_back({{"name", rr.name},
                      {"program", rr.program},
                      {"hits", rr.hits},
                      {"shots", rr.shots},
                      {"motor_frames_latched", rr.framesLatched},
                      {"motor_frames_rejected", rr.framesRejected},
                      {"motor_frames_overwritten", rr.framesOverwritten},
                      {"interrupts", rr.interrupts},
                      {"cycles", rr.cycles},
                      {"vm_instructions", rr.vmInstructions},
                      {"fault", faultJson(rr.fault)},
                      {"faults", faultsJson(rr.faults)},
                      {"reloads", rr.reloads},
                      {"final_pose", poseJson(rr.finalPose)},
                      {"console_lines", rr.console.size()}});
  json j = {{"sim_seconds", timebase::secondsFromTicks(r.endTick)},
            {"wall_seconds", wall},
            {"seed", played.seed},
            {"winner", r.winner},
            {"tie_broken_by_coin", r.tieBrokenByCoin},
            {"plant_fault", faultJson(r.plantFault)},
            {"integrator",
             {{"steps", r.integrator.steps},
              {"rhs_evals", r.integrator.rhs_evals},
              {"reinits", r.integrator.reinits},
              {"roots", r.integrator.roots}}},
            {"robots", robots}};
  if (o.json) {
    std::cout << tools::dumpJson(j, 2) << '\n';
  } else {
    for (const auto& rr : r.robots) {
      std::cout << fmt::format(
          "{} {:<24} hits {:>2}  shots {:>2}  frames {:>5} (+{} rejected, {} frames "
          "overwritten){}\n",
          rr.name, rr.program, rr.hits, rr.shots, rr.framesLatched, rr.framesRejected,
          rr.framesOverwritten, rr.reloads ? fmt::format("  reloads {}", rr.reloads) : "");
      for (const auto& f : rr.faults) std::cout << "  " << faultText(rr, f) << '\n';
    }
    std::cout << fmt::format("winner: {}{}  ({:.1f} s simulated in {:.2f} s)\n", r.winner,
                             r.tieBrokenByCoin ? " (coin flip)" : "",
                             timebase::secondsFromTicks(r.endTick), wall);
  }
  reportWarnings(r);
  return reportFaults(r) ? kExitRobotFault : 0;
}

// Cycles per source line and per function of a solo run, largest first.
int profileCommand(const std::string& program, RunOptions o, int top) {
  o.trace.clear();
  scheduler::MatchConfig config = buildConfig({program}, o, tools::ScenarioUse::Profile);
  config.stopWhenAllExited = true;
  config.profile = true;
  const vm::Image& image = config.robots[0].image;
  scheduler::MatchResult r;
  try {
    r = scheduler::runMatch(config);
  } catch (const std::invalid_argument& e) {
    throw tools::ToolError(fmt::format("simbot: {}\n", e.what()));
  }
  reportWarnings(r);
  // A faulted run is profiled up to the fault, and said so (exit status 3).
  const int status = reportFaults(r) ? kExitRobotFault : 0;
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
              {"fault", faultJson(robot.fault)},
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
    std::cout << tools::dumpJson(j, 2) << '\n';
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

void addRunOptions(CLI::App* cmd, RunOptions& o, bool solo) {
  o.secondsOption = cmd->add_option("--seconds", o.seconds,
                                    "simulated seconds (default: the profile's round_length)");
  o.seedOption =
      cmd->add_option("--seed", o.seed, "master seed (default 1)")->check(tools::seedValidator());
  o.profileOption =
      cmd->add_option("--profile", o.profile, "profile name or file (default: default)");
  cmd->add_option("--scenario", o.scenario,
                  "scenario file (TOML): start poses, profile, hardware, injections, robot B");
  cmd->add_option("--hw", o.hw,
                  solo ? "hardware file" : "hardware file for a robot: A=FILE or B=FILE");
  cmd->add_option("--trace", o.trace, "write the trace (JSONL) to this file");
  cmd->add_option("--replay", o.replay,
                  "write a replay page (one self-contained HTML file) to this file");
  cmd->add_option("--vcd", o.vcd,
                  "write the digital signals (serial TXD, ports, IFF1, handlers, motor commands, "
                  "eye readings) as a value change dump for GTKWave and sigrok");
  cmd->add_option("--inject", o.injections,
                  "ROBOT:SOURCE@WHEN, SOURCE edge_fore|edge_aft|bumper_front|bumper_back, "
                  "WHEN 12.5s|800ms|115200000t|line:N#K (K-th entry into line N)|pass:N#K "
                  "(K-th pass of the loop on line N) (repeatable)");
  cmd->add_option("--watch", o.watches,
                  "add a global or static variable (FUNCTION.NAME) to every trace record "
                  "(repeatable; needs --trace or --replay)");
  cmd->add_flag("--no-fast-forward", o.noFastForward,
                "step every pass of every delay loop (the result is the same, slower: for "
                "checking)");
  cmd->add_flag("--trace-costate", o.traceCostate,
                "add a record each time a costatement is entered, gives way or ends (needs "
                "--trace or --replay)");
  cmd->add_flag("--reload-on-fault", o.reloadOnFault,
                "reload a faulted program after the profile's [match] reload_delay: it starts "
                "again from main with its memory as at load (thesis Appendix A)");
  cmd->add_flag("--json", o.json, "print the summary as JSON");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"simbot: a timing-faithful simulator of the 1997 NPS Robot Wars"};
  app.require_subcommand(1);

  std::string compileFile;
  bool disasm = false;
  auto* compile = app.add_subcommand("compile", "compile a Dynamic C program");
  compile->add_option("FILE", compileFile, "program (.dc)")->required();
  compile->add_flag("--disasm", disasm, "print the bytecode, interleaved with the source");
  compile->allow_extras();
  compile->footer(
      "Warnings: -Wno-NAME turns one off, -Werror makes every warning an error (see the README "
      "for the names).");

  RunOptions soloOptions;
  std::string soloProgram;
  auto* solo = app.add_subcommand("solo", "run one robot alone in the arena");
  solo->add_option("FILE", soloProgram, "program (.dc)")->required();
  addRunOptions(solo, soloOptions, true);

  RunOptions matchOptions;
  std::string programA, programB;
  auto* match = app.add_subcommand("match", "play a match between two programs");
  match->add_option("A", programA, "robot A's program")->required();
  match->add_option("B", programB, "robot B's program")->required();
  addRunOptions(match, matchOptions, false);

  RunOptions profileOptions;
  profileOptions.seconds = 60;
  std::string profileProgram;
  int profileTop = 20;
  auto* profile =
      app.add_subcommand("profile", "cycles and time per source line and function of a solo run");
  profile->add_option("FILE", profileProgram, "program (.dc)")->required();
  profileOptions.secondsOption =
      profile->add_option("--seconds", profileOptions.seconds, "simulated seconds (default 60)");
  profileOptions.seedOption =
      profile->add_option("--seed", profileOptions.seed, "master seed (default 1)")
          ->check(tools::seedValidator());
  profileOptions.profileOption = profile->add_option("--profile", profileOptions.profile,
                                                     "physical profile (default: default)");
  profile->add_option("--scenario", profileOptions.scenario,
                      "scenario file (TOML): start pose, profile, hardware, injections, robot B");
  profile->add_option("--inject", profileOptions.injections, "as for solo (repeatable)");
  profile->add_option("--top", profileTop, "source lines to list (default 20)")
      ->check(CLI::Range(1, 1'000'000));
  profile->add_flag("--json", profileOptions.json, "print the profile as JSON");

  std::string viewTrace, viewOut;
  auto* view = app.add_subcommand("view", "write the replay page (HTML) of a recorded trace");
  view->add_option("TRACE", viewTrace, "trace file (.jsonl) written with --trace")->required();
  view->add_option("-o,--output", viewOut, "the page to write (.html)")->required();

  const auto bench = simbot::tools::addBenchCommand(app);
  const auto compare = simbot::tools::addCompareCommand(app);
  const auto tournament = simbot::tools::addTournamentCommand(app);
  const auto explain = simbot::tools::addExplainCommand(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // A usage error: one line, exit status 1.
    std::string message = e.what();
    std::replace(message.begin(), message.end(), '\n', ' ');
    std::cerr << "simbot: " << message << " (simbot --help lists the options)\n";
    return kExitBadInput;
  }
  try {
    if (*compile) return compileCommand(compileFile, disasm, compile->remaining());
    if (*solo) return soloCommand(soloProgram, soloOptions);
    if (*match) return matchCommand(programA, programB, matchOptions);
    if (*profile) return profileCommand(profileProgram, profileOptions, profileTop);
    if (*view) return viewCommand(viewTrace, viewOut);
    if (*bench.app) return bench.run();
    if (*compare.app) return compare.run();
    if (*tournament.app) return tournament.run();
    if (*explain.app) return explain.run();
  } catch (const tools::ToolError& e) {
    std::cerr << e.what();
    return kExitBadInput;
  } catch (const plant::ConfigError& e) {
    std::cerr << e.what() << '\n';
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << "simbot: internal error: " << e.what() << "\n";
    return kExitInternalError;
  }
  return 0;
}
