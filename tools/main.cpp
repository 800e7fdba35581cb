// simbot: the command line. Each subcommand is a thin layer over the parts
// (compiler/, vm/, plant/, scheduler/); DESIGN.md's tool contract says what
// tests and scripts rely on.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "compiler/compiler.h"
#include "plant/plant.h"
#include "scheduler/match.h"
#include "vm/vm.h"

namespace {

using namespace simbot;
using nlohmann::json;

// A user error: printed as is, exit status 1.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

int compileCommand(const std::string& file, bool disasm) {
  const auto result = compiler::compileFile(file);
  if (!result.image) {
    for (const auto& d : result.errors) std::cerr << d.format();
    return 1;
  }
  if (disasm) std::cout << vm::disassemble(*result.image);
  return 0;
}

vm::Image compileOrThrow(const std::string& file) {
  auto result = compiler::compileFile(file);
  if (!result.image) {
    std::string all;
    for (const auto& d : result.errors) all += d.format();
    throw UsageError(all);
  }
  return std::move(*result.image);
}

// A profile by name (profiles/NAME.toml) or by path.
plant::Profile loadProfile(const std::string& nameOrPath) {
  namespace fs = std::filesystem;
  fs::path p = nameOrPath;
  if (!fs::exists(p)) p = fs::path(SIMBOT_PROFILES_DIR) / (nameOrPath + ".toml");
  if (!fs::exists(p))
    throw UsageError(
        fmt::format("simbot: no profile '{}' (a file, or one of profiles/*.toml)\n", nameOrPath));
  return plant::loadProfile(p.string());
}

struct RunOptions {
  double seconds = 180;
  uint64_t seed = 1;
  std::string profile = "default";
  std::vector<std::string> hw;
  std::string trace;
  std::vector<std::string> injections;
  bool json = false;
};

json poseJson(const plant::Pose& p) {
  return {{"x_ft", p.x_ft}, {"y_ft", p.y_ft}, {"heading_deg", p.heading_deg}};
}

json faultJson(const std::optional<scheduler::FaultInfo>& f) {
  if (!f) return nullptr;
  return {{"message", f->message}, {"time_s", f->timeS}, {"line", f->line}};
}

scheduler::MatchResult play(const std::vector<std::string>& programs, const RunOptions& o,
                            bool solo, double& wallSeconds) {
  if (!(o.seconds > 0) || o.seconds > 1e6)
    throw UsageError(fmt::format("simbot: --seconds must be in (0, 1e6], got {}\n", o.seconds));
  const plant::Profile profile = loadProfile(o.profile);
  scheduler::MatchConfig config;
  config.arena = plant::makeArenaConfig(profile, static_cast<int>(programs.size()));
  const char* names[] = {"A", "B"};
  for (size_t i = 0; i < programs.size(); ++i)
    config.robots.push_back({names[i], programs[i], compileOrThrow(programs[i])});
  for (const auto& spec : o.hw) {
    int robot = 0;
    std::string file = spec;
    if (!solo) {
      const auto eq = spec.find('=');
      if (eq == std::string::npos || (spec.substr(0, eq) != "A" && spec.substr(0, eq) != "B"))
        throw UsageError("simbot: --hw takes A=FILE or B=FILE\n");
      robot = spec[0] == 'A' ? 0 : 1;
      file = spec.substr(eq + 1);
    }
    auto& setup = config.arena.robots[static_cast<size_t>(robot)];
    setup.hardware = plant::loadHardware(file, setup.params);
  }
  for (const auto& text : o.injections) {
    try {
      config.injections.push_back(
          scheduler::parseInjection(text, static_cast<int>(programs.size())));
    } catch (const std::invalid_argument& e) {
      throw UsageError(fmt::format("simbot: --inject {}\n", e.what()));
    }
  }
  config.endTick = static_cast<scheduler::Tick>(o.seconds * scheduler::kTicksPerSecond);
  config.seed = o.seed;
  config.stopWhenAllExited = solo;
  config.trace = !o.trace.empty();
  const auto start = std::chrono::steady_clock::now();
  scheduler::MatchResult result;
  try {
    result = scheduler::runMatch(config);
  } catch (const std::invalid_argument& e) {
    throw UsageError(fmt::format("simbot: {}\n", e.what()));
  }
  wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!o.trace.empty()) {
    std::ofstream out(o.trace);
    if (!out) throw UsageError(fmt::format("simbot: cannot write trace '{}'\n", o.trace));
    for (const auto& line : result.trace) out << line << '\n';
  }
  return result;
}

int soloCommand(const std::string& program, const RunOptions& o) {
  double wall = 0;
  const auto r = play({program}, o, true, wall);
  const auto& a = r.robots[0];
  json j = {
      {"exited", a.exited},
      {"exit_time_s", a.exited ? json(static_cast<double>(a.exitTick) / scheduler::kTicksPerSecond)
                               : json(nullptr)},
      {"cycles", a.cycles},
      {"sim_seconds", static_cast<double>(r.endTick) / scheduler::kTicksPerSecond},
      {"wall_seconds", wall},
      {"console", a.console},
      {"fault", faultJson(a.fault)},
      {"motor_frames_latched", a.framesLatched},
      {"motor_frames_rejected", a.framesRejected},
      {"interrupts", a.interrupts},
      {"final_pose", poseJson(a.finalPose)}};
  if (o.json) {
    std::cout << j.dump(2) << '\n';
  } else {
    for (const auto& line : a.console) std::cout << line << '\n';
    std::cerr << fmt::format("simbot: {} {} at {:.3f} s; {} frames latched, {} rejected\n", program,
                             a.fault    ? "faulted"
                             : a.exited ? "exited"
                                        : "ran",
                             static_cast<double>(r.endTick) / scheduler::kTicksPerSecond,
                             a.framesLatched, a.framesRejected);
    if (a.fault)
      std::cerr << fmt::format("{}:{}: fault: {}\n", program, a.fault->line, a.fault->message);
  }
  return 0;
}

int matchCommand(const std::string& a, const std::string& b, const RunOptions& o) {
  double wall = 0;
  const auto r = play({a, b}, o, false, wall);
  json robots = json::array();
  for (const auto& rr : r.robots)
    robots.push_back({{"name", rr.name},
                      {"program", rr.program},
                      {"hits", rr.hits},
                      {"shots", rr.shots},
                      {"motor_frames_latched", rr.framesLatched},
                      {"motor_frames_rejected", rr.framesRejected},
                      {"interrupts", rr.interrupts},
                      {"cycles", rr.cycles},
                      {"fault", faultJson(rr.fault)},
                      {"final_pose", poseJson(rr.finalPose)},
                      {"console_lines", rr.console.size()}});
  json j = {{"sim_seconds", static_cast<double>(r.endTick) / scheduler::kTicksPerSecond},
            {"wall_seconds", wall},
            {"seed", o.seed},
            {"winner", r.winner},
            {"tie_broken_by_coin", r.tieBrokenByCoin},
            {"integrator",
             {{"steps", r.integrator.steps},
              {"rhs_evals", r.integrator.rhs_evals},
              {"reinits", r.integrator.reinits},
              {"roots", r.integrator.roots}}},
            {"robots", robots}};
  if (o.json) {
    std::cout << j.dump(2) << '\n';
  } else {
    for (const auto& rr : r.robots)
      std::cout << fmt::format("{} {:<24} hits {:>2}  shots {:>2}  frames {:>5} (+{} rejected)\n",
                               rr.name, rr.program, rr.hits, rr.shots, rr.framesLatched,
                               rr.framesRejected);
    std::cout << fmt::format("winner: {}{}  ({:.1f} s simulated in {:.2f} s)\n", r.winner,
                             r.tieBrokenByCoin ? " (coin flip)" : "",
                             static_cast<double>(r.endTick) / scheduler::kTicksPerSecond, wall);
  }
  return 0;
}

void addRunOptions(CLI::App* cmd, RunOptions& o, bool solo) {
  cmd->add_option("--seconds", o.seconds, "simulated seconds (default 180)");
  cmd->add_option("--seed", o.seed, "master seed (default 1)");
  cmd->add_option("--profile", o.profile, "profile name or file (default: default)");
  cmd->add_option("--hw", o.hw,
                  solo ? "hardware file" : "hardware file for a robot: A=FILE or B=FILE");
  cmd->add_option("--trace", o.trace, "write the trace (JSONL) to this file");
  cmd->add_option("--inject", o.injections,
                  "ROBOT:SOURCE@WHEN, SOURCE edge_fore|edge_aft|bumper_front|bumper_back, "
                  "WHEN 12.5s|800ms|115200000t|line:N#K (repeatable)");
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

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    if (*compile) return compileCommand(compileFile, disasm);
    if (*solo) return soloCommand(soloProgram, soloOptions);
    if (*match) return matchCommand(programA, programB, matchOptions);
  } catch (const UsageError& e) {
    std::cerr << e.what();
    return 1;
  } catch (const plant::ConfigError& e) {
    std::cerr << e.what() << '\n';
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "simbot: internal error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
