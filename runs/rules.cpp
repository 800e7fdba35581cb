// Course rules applied to one run (play.h): which rule set it plays
// under, and what its robots use checked against it before the match.
#include <fmt/format.h>

#include "config/config.h"
#include "runs/play.h"

namespace simbot::runs {

std::string runRules(const RunOptions& o, const std::optional<config::Scenario>& scenario) {
  return preferCommandLine(o.rules.has_value(), scenario ? scenario->rules : std::nullopt,
                           o.rules.value_or(""));
}

void checkRunAgainstRules(const config::Profile& profile, const scheduler::MatchConfig& config,
                          const std::array<std::string, 2>& hardwareFiles,
                          const std::string& obstaclesFile) {
  if (!profile.course.present) return;
  config::RunUses uses;
  for (size_t i = 0; i < config.arena.robots.size() && i < 2; ++i) {
    const plant::RobotParams& params = config.arena.robots[i].params;
    uses.magazines.push_back({static_cast<int>(i), params.balls_per_gun,
                              hardwareFiles[i].empty() ? profile.file : hardwareFiles[i]});
    const plant::SecondaryWeapon& secondary = config.arena.robots[i].hardware.secondary;
    if (secondary.kind != plant::SecondaryKind::None)
      uses.secondaryWeapons.push_back({static_cast<int>(i),
                                       plant::secondaryKindName(secondary.kind), secondary.magazine,
                                       hardwareFiles[i]});
  }
  // The arena's obstacles with mine = true, with the file that places them.
  for (const plant::Obstacle& o : config.arena.field.obstacles)
    if (o.mine) uses.mines.push_back({o.name, obstaclesFile});
  // Each robot's hardware [[deployables]]: kind and count.
  for (size_t i = 0; i < config.arena.robots.size() && i < 2; ++i)
    for (const plant::Deployable& d : config.arena.robots[i].hardware.deployables)
      uses.deployables.push_back(
          {static_cast<int>(i), plant::deployKindName(d.kind), d.count, hardwareFiles[i]});
  config::checkRules(profile.course, uses);
}

}  // namespace simbot::runs
