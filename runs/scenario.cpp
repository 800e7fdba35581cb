// Scenarios applied to a run (scenario.h): a beacon's path as wheel speeds,
// and the scenario's poses, hardware, B and injections put into a match's
// configuration. config/ reads and checks the file (config::loadScenario);
// what depends on the profile or the program (a start pose inside the
// field, a line that has code) is checked here, still naming the
// scenario's line.
#include "runs/scenario.h"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "config/config.h"
#include "runs/play.h"
#include "timebase/tick.h"

namespace simbot::runs {

namespace {

double radians(double deg) { return deg * std::numbers::pi / 180; }

}  // namespace

std::vector<scheduler::DriveLeg> driveLegs(const std::string& sourceName,
                                           const std::vector<PathLeg>& legs,
                                           const plant::RobotParams& params) {
  std::vector<scheduler::DriveLeg> out;
  const double half = params.track_ft / 2;
  for (const PathLeg& leg : legs) {
    double seconds = 0, left = 0, right = 0;
    const double sign = leg.turnDeg < 0 ? -1 : 1;
    switch (leg.kind) {
      case PathLeg::Kind::Forward:
        left = right = leg.forwardFt < 0 ? -leg.speedFps : leg.speedFps;
        seconds = std::fabs(leg.forwardFt) / leg.speedFps;
        break;
      case PathLeg::Kind::Arc: {
        // Centre speed v on radius R turns at v/R; the outer wheel is the left
        // one for a clockwise (positive) turn.
        const double omega = leg.speedFps / leg.radiusFt;
        left = leg.speedFps + sign * omega * half;
        right = leg.speedFps - sign * omega * half;
        seconds = radians(std::fabs(leg.turnDeg)) / omega;
        break;
      }
      case PathLeg::Kind::Spin:
        left = sign * leg.speedFps;
        right = -sign * leg.speedFps;
        seconds = radians(std::fabs(leg.turnDeg)) * half / leg.speedFps;
        break;
      case PathLeg::Kind::Wait:  // written as a time: a whole number of ticks
        seconds = timebase::secondsFromTicks(leg.wait);
        break;
    }
    // The range first: ticksFromSeconds refuses NaN and huge values.
    const scheduler::Tick ticks = leg.kind == PathLeg::Kind::Wait ? leg.wait
                                  : seconds >= 0 && seconds <= 1e8
                                      ? timebase::ticksFromSeconds(seconds)
                                      : 0;
    if (ticks < 1)
      throw config::ConfigError(
          sourceName, leg.pos.line, leg.pos.column,
          fmt::format("this leg lasts {} s, which is not between one tick and 1e8 s", seconds));
    out.push_back({ticks, left, right});
  }
  return out;
}

scheduler::RobotSpec beaconSpec(std::vector<scheduler::DriveLeg> legs, bool repeat) {
  static const vm::Image beacon = compileProgramText("main()\n{\n}\n", "beacon");
  scheduler::RobotSpec spec{"B", legs.empty() ? "(beacon)" : "(beacon on a path)", beacon};
  spec.path = std::move(legs);
  spec.repeatPath = repeat;
  return spec;
}

void applyScenario(const Scenario& s, ScenarioUse use, const config::Profile& profile,
                   scheduler::MatchConfig& config, std::array<bool, 2> keepHardware) {
  auto fail = [&](SourcePos at, const std::string& msg) {
    throw config::ConfigError(s.file, at.line, at.column, msg);
  };
  const bool bFromScenario = s.opponent != Scenario::Opponent::None;
  switch (use) {
    case ScenarioUse::Match:
      if (bFromScenario)
        fail(s.opponentPos,
             "match takes B's program from the command line; "
             "B.program and B.beacon are for solo, profile and bench");
      break;
    case ScenarioUse::Bench:
      if (bFromScenario || s.a.start || s.b.start)
        fail(bFromScenario ? s.opponentPos
             : s.a.start   ? s.a.startPos
                           : s.b.startPos,
             "a bench family places the robots and picks B; leave out --family to run "
             "this scenario's own poses and opponent");
      break;
    case ScenarioUse::Solo:
    case ScenarioUse::Profile:
    case ScenarioUse::BenchOwn:
      if (!bFromScenario && (s.b.start || !s.b.hardware.empty() || !s.b.inject.empty()))
        fail(s.opponentPos,
             "[B] sets up a robot B but names none: give B.program or B.beacon = true");
      break;
  }
  // B from the scenario.
  if (bFromScenario && use != ScenarioUse::Match && use != ScenarioUse::Bench) {
    const plant::ArenaConfig two = config::makeArenaConfig(profile, 2);
    config.arena.robots.resize(1);
    config.arena.robots.push_back(two.robots[1]);
    config.robots.resize(1);
    if (s.opponent == Scenario::Opponent::Program) {
      config.robots.push_back({"B", s.program, compileProgramFile(s.program)});
    } else {
      config.robots.push_back(beaconSpec({}, false));
    }
    config.robots.back().controller = profile.controller;
  }
  const size_t robots = config.robots.size();
  const ScenarioRobot* each[2] = {&s.a, &s.b};
  for (size_t i = 0; i < robots; ++i) {
    const ScenarioRobot& r = *each[i];
    plant::RobotSetup& setup = config.arena.robots[i];
    if (r.start) {
      const double half = profile.field.size_ft / 2, radius = setup.params.body_diameter_ft / 2;
      const double x = r.start->x_ft, y = r.start->y_ft;
      if (std::fabs(x) + radius > half || std::fabs(y) + radius > half)
        fail(r.startPos, fmt::format("start ({}, {}) ft puts the body outside the {}-ft field", x,
                                     y, profile.field.size_ft));
      if (plant::dividerClearance(x, y, radius, profile.field) <= 0)
        fail(r.startPos, fmt::format("start ({}, {}) ft puts the body on the divider", x, y));
      setup.start = *r.start;
    }
    if (!r.hardware.empty() && !keepHardware[i])
      setup.hardware = config::loadHardware(r.hardware, setup.params, config.robots[i].controller);
    for (const auto& in : r.inject) {
      scheduler::Injection injection =
          config::parseInjection(std::string(i == 0 ? "A:" : "B:") + in.what, 2);
      if (injection.line > 0) {
        const auto& lines = config.robots[i].image.lines;
        if (std::find(lines.begin(), lines.end(), injection.line) == lines.end())
          fail(in.pos,
               fmt::format("line {} of {} has no code", injection.line, config.robots[i].program));
      }
      config.injections.push_back(std::move(injection));
    }
  }
  if (robots == 2) {
    const plant::Pose& a = config.arena.robots[0].start;
    const plant::Pose& b = config.arena.robots[1].start;
    const double touch = (config.arena.robots[0].params.body_diameter_ft +
                          config.arena.robots[1].params.body_diameter_ft) /
                         2;
    if (std::hypot(a.x_ft - b.x_ft, a.y_ft - b.y_ft) <= touch)
      fail(s.b.start ? s.b.startPos : s.a.startPos, "the two robots' start poses overlap");
  }
  if (!s.obstacles.empty()) {
    config.arena.field.obstacles.clear();
    for (const config::ObstacleSpec& o : s.obstacles)
      config.arena.field.obstacles.push_back(o.obstacle);
    config::checkObstacles(s.obstacles, s.file, config.arena);
  }
  if (robots == 2 && s.opponent == Scenario::Opponent::Beacon && !s.path.empty()) {
    config.robots[1].path = driveLegs(s.file, s.path, config.arena.robots[1].params);
    config.robots[1].repeatPath = s.repeatPath;
    config.robots[1].program = "(beacon on a path)";
  }
}

}  // namespace simbot::runs
