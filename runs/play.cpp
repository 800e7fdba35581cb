// Solo runs and matches from run options (play.h).
#include "runs/play.h"

#include <fmt/format.h>

#include <array>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <optional>

#include "config/config.h"
#include "plant/plant.h"
#include "reports/viewer.h"
#include "sinks/json_text.h"
#include "sinks/trace_jsonl.h"
#include "sinks/user_error.h"
#include "sinks/vcd.h"
#include "timebase/tick.h"

namespace simbot::runs {

using nlohmann::json;

namespace {

json poseJson(const plant::Pose& p) {
  return {{"x_ft", p.x_ft}, {"y_ft", p.y_ft}, {"heading_deg", p.heading_deg}};
}

// Console lines are bytes the robot printed: one character per byte.
json consoleJson(const std::vector<std::string>& lines) {
  json out = json::array();
  for (const auto& line : lines) out.push_back(sinks::jsonString(line, true));
  return out;
}

// Detect to Engage's count under the run's rules; null without rules.
json scatterJson(const scheduler::RobotResult& rr) {
  return rr.scatterShots ? json(*rr.scatterShots) : json(nullptr);
}

json faultsJson(const std::vector<scheduler::FaultInfo>& faults) {
  json out = json::array();
  for (const auto& f : faults) out.push_back(faultJson(f));
  return out;
}

// A robot's secondary weapon, only for a robot that carries one (so that
// the JSON of a run without one is as before): {"shots": n, "hits": n},
// hits apart from the guns' `hits` (docs/trace.md, "The JSON result").
void addSecondary(json& robot, const scheduler::RobotResult& rr) {
  if (rr.secondary)
    robot["secondary"] = {{"shots", rr.secondary->shots}, {"hits", rr.secondary->hits}};
}

}  // namespace

json faultJson(const std::optional<scheduler::FaultInfo>& f) {
  if (!f) return nullptr;
  return {{"message", f->message},
          {"time_s", f->timeS},
          {"line", f->line},
          {"depth", f->depth},
          {"calls", f->calls}};
}

// Findings that did not stop the run (injections that never fired, ...).
void reportWarnings(const scheduler::MatchResult& r) {
  for (const auto& w : r.warnings) std::cerr << "simbot: warning: " << w << '\n';
}

// A robot's fault in one line: robot, time, source line, message, and the
// calls under way (call depth 251: main:12 > deep:7 x 251).
std::string faultText(const scheduler::RobotResult& rr, const scheduler::FaultInfo& f) {
  return fmt::format(
      "{}:{}: fault: robot {} at {:.6f} s: {}{}", rr.program, f.line, rr.name, f.timeS, f.message,
      f.calls.empty() ? std::string() : fmt::format(" (call depth {}: {})", f.depth, f.calls));
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
    const size_t n = rr.faults.size();
    for (size_t k = 0; k < n; ++k) {
      any = true;
      if (!faultShown(k, n)) {
        if (k == kFaultsShownFirst)
          std::cerr << fmt::format("{}: robot {}: ... {} more faults (the JSON lists them all)\n",
                                   rr.program, rr.name, n - kFaultsShownFirst - kFaultsShownLast);
        continue;
      }
      std::cerr << faultText(rr, rr.faults[k])
                << (k < static_cast<size_t>(rr.reloads) ? " (reloaded)" : "") << '\n';
    }
  }
  return any;
}

// The run's configuration from the command line and the scenario: the
// programs given (A, and B for match), then the scenario (start poses,
// hardware, B for solo and profile, injections), then --hw and --inject.
void checkFiles(const std::vector<files::Named>& inputs, const std::vector<files::Named>& outputs) {
  try {
    files::checkDistinct(inputs, outputs);
  } catch (const files::Error& e) {
    throw sinks::UserError(fmt::format("simbot: {}\n", e.what()));
  }
}

scheduler::MatchConfig buildConfig(const std::vector<std::string>& programs, const RunOptions& o,
                                   ScenarioUse use, std::vector<files::Named>* inputs) {
  std::optional<Scenario> scenario;
  if (!o.scenario.empty()) scenario = config::loadScenario(o.scenario);
  const config::Profile profile = loadRunProfile(
      preferCommandLine(o.profile.has_value(), scenario ? scenario->profile : std::nullopt,
                        o.profile.value_or("default")),
      runRules(o, scenario));
  // Without --seconds or a scenario's, a run lasts its default: the
  // profile's round. Each was checked against the one run-length limit
  // where it was read (timebase/written.h; the profile's keys table).
  const timebase::Tick length = preferCommandLine(
      o.length.has_value(), scenario ? scenario->length : std::nullopt,
      o.length.value_or(o.defaultLength > 0 ? o.defaultLength
                                            : timebase::ticksFromSeconds(profile.round_length_s)));
  scheduler::MatchConfig config;
  config.arena = config::makeArenaConfig(profile, static_cast<int>(programs.size()));
  config.profileName = profile.name;
  config.rulesName = profile.course.name;
  config.rulesFile = profile.course.file;
  const char* names[] = {"A", "B"};
  for (size_t i = 0; i < programs.size(); ++i) {
    config.robots.push_back({names[i], programs[i], compileProgramFile(programs[i])});
    config.robots.back().controller = profile.controller;
  }
  std::array<bool, 2> hwGiven{};
  std::vector<std::pair<int, std::string>> hwFiles;
  for (const auto& spec : o.hw) {
    int robot = 0;
    std::string file = spec;
    if (use == ScenarioUse::Match) {
      const auto eq = spec.find('=');
      if (eq == std::string::npos || (spec.substr(0, eq) != "A" && spec.substr(0, eq) != "B"))
        throw sinks::UserError("simbot: --hw takes A=FILE or B=FILE\n");
      robot = spec[0] == 'A' ? 0 : 1;
      file = spec.substr(eq + 1);
    }
    hwGiven[static_cast<size_t>(robot)] = true;
    hwFiles.emplace_back(robot, file);
  }
  if (scenario) applyScenario(*scenario, use, profile, config, hwGiven);
  for (const auto& [robot, file] : hwFiles) {
    auto& setup = config.arena.robots[static_cast<size_t>(robot)];
    setup.hardware = config::loadHardware(file, setup.params,
                                          config.robots[static_cast<size_t>(robot)].controller);
  }
  // Each robot's hardware file: the command line's, else the scenario's.
  std::array<std::string, 2> hardwareFiles;
  if (scenario) hardwareFiles = {scenario->a.hardware, scenario->b.hardware};
  for (const auto& [robot, file] : hwFiles) hardwareFiles[static_cast<size_t>(robot)] = file;
  checkRunAgainstRules(profile, config, hardwareFiles, scenario ? scenario->file : "");
  for (const auto& text : o.injections) {
    try {
      config.injections.push_back(
          config::parseInjection(text, static_cast<int>(config.robots.size())));
    } catch (const std::invalid_argument& e) {
      throw sinks::UserError(fmt::format("simbot: --inject {}\n", e.what()));
    }
  }
  config.endTick = length;
  config.seed = preferCommandLine(o.seed.has_value(), scenario ? scenario->seed : std::nullopt,
                                  o.seed.value_or(1));
  config.reloadOnFault = o.reloadOnFault;
  config.reloadDelay = timebase::ticksFromSeconds(profile.reload_delay_s);
  if (inputs) {
    for (const auto& robot : config.robots)
      if (!robot.program.empty()) inputs->push_back({robot.program, "the program"});
    if (scenario) inputs->push_back({o.scenario, "the scenario"});
    inputs->push_back({profile.file, "the profile"});
    if (profile.course.present) inputs->push_back({profile.course.file, "the rules"});
    for (const auto& [robot, file] : hwFiles) inputs->push_back({file, "the hardware file"});
    if (scenario)
      for (const auto* r : {&scenario->a, &scenario->b})
        if (!r->hardware.empty()) inputs->push_back({r->hardware, "the hardware file"});
  }
  return config;
}

Played play(const std::vector<std::string>& programs, const RunOptions& o, bool solo) {
  // Watched values are written only into trace records.
  if (!o.watches.empty() && o.trace.empty() && o.replay.empty() && o.sinks.empty())
    throw sinks::UserError(
        "simbot: --watch needs --trace FILE (or --replay FILE): watched values are written "
        "only into the trace's records\n");
  std::vector<files::Named> inputs;
  scheduler::MatchConfig config =
      buildConfig(programs, o, solo ? ScenarioUse::Solo : ScenarioUse::Match, &inputs);
  config.stopWhenAllExited = solo;
  config.watches = o.watches;
  if (o.traceCostate && o.trace.empty() && o.replay.empty() && o.sinks.empty())
    throw sinks::UserError("simbot: --trace-costate needs --trace FILE (or --replay FILE)\n");
  config.traceCostate = o.traceCostate;
  if (o.noFastForward) config.knobs.fastForward = false;
  // Every input is read now. No output may be one of them, or another
  // output; each sink opens a temporary file beside its output before the
  // run (a path that cannot be written costs nothing) and renames it into
  // place when the run is done, so a run refused later (a --watch name or
  // an --inject line that the run's start rejects) leaves old files alone.
  std::vector<files::Named> outputs;
  if (!o.trace.empty()) outputs.push_back({o.trace, "--trace"});
  if (!o.vcd.empty()) outputs.push_back({o.vcd, "--vcd"});
  if (!o.replay.empty()) outputs.push_back({o.replay, "--replay"});
  checkFiles(inputs, outputs);
  std::optional<sinks::JsonlSink> jsonl;
  std::optional<sinks::VcdSink> vcd;
  std::optional<reports::ReplaySink> replay;
  if (!o.trace.empty()) config.sinks.push_back(&jsonl.emplace(o.trace));
  if (!o.vcd.empty()) config.sinks.push_back(&vcd.emplace(o.vcd));
  if (!o.replay.empty()) config.sinks.push_back(&replay.emplace(o.replay));
  config.sinks.insert(config.sinks.end(), o.sinks.begin(), o.sinks.end());
  Played played;
  played.seed = config.seed;
  const auto start = std::chrono::steady_clock::now();
  try {
    played.result = scheduler::runMatch(config);
  } catch (const std::invalid_argument& e) {
    throw sinks::UserError(fmt::format("simbot: {}\n", e.what()));
  }
  played.wallSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return played;
}

namespace {
// Board resets by cause (scheduler/power.cpp), and the battery's last
// terminal voltage (null: no battery).
json resetsJson(const scheduler::RobotResult& r) {
  return {{"brown_out", r.resetsBrownOut}, {"injected", r.resetsInjected}};
}
json batteryJson(const scheduler::RobotResult& r) {
  return r.batteryVFinal ? json(*r.batteryVFinal) : json(nullptr);
}
// Items of [[deployables]] set down, by kind: always the three kinds.
json deployedJson(const scheduler::RobotResult& r) {
  return {
      {"block", r.deployed[0]}, {"decoy_light", r.deployed[1]}, {"decoy_screen", r.deployed[2]}};
}
}  // namespace

json soloJson(const Played& played) {
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
      {"resets", resetsJson(a)},
      {"battery_v_final", batteryJson(a)},
      {"plant_fault", faultJson(r.plantFault)},
      {"motor_frames_latched", a.framesLatched},
      {"motor_frames_rejected", a.framesRejected},
      {"motor_frames_overwritten", a.framesOverwritten},
      {"interrupts", a.interrupts},
      {"final_pose", poseJson(a.finalPose)},
      {"scatter_shots", scatterJson(a)},
      {"deployed", deployedJson(a)},
      {"block_push_ft", a.blockPushFt}};
  addSecondary(j, a);
  return j;
}

json matchJson(const Played& played) {
  const auto& r = played.result;
  const double wall = played.wallSeconds;
  json robots = json::array();
  for (const auto& rr : r.robots) {
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
                      {"console_lines", rr.console.size()},
                      {"scatter_shots", scatterJson(rr)},
                      {"resets", resetsJson(rr)},
                      {"battery_v_final", batteryJson(rr)},
                      {"deployed", deployedJson(rr)},
                      {"block_push_ft", rr.blockPushFt}});
    addSecondary(robots.back(), rr);
  }
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
  return j;
}

}  // namespace simbot::runs
