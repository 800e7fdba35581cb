// The match the snapshot and copy tests play: the `default` profile, seed
// 3, a length in seconds, and reloading a faulted program or not.
#pragma once
#include <string>
#include <vector>

#include "runs/play.h"
#include "scheduler/match.h"
#include "timebase/tick.h"

namespace simbot::testkit {

inline scheduler::MatchConfig seededMatch(const std::vector<std::string>& programs, double seconds,
                                          bool reload) {
  runs::RunOptions o;
  o.length = timebase::ticksFromSeconds(seconds);
  o.profile = "default";
  o.seed = 3;
  o.reloadOnFault = reload;
  return runs::buildConfig(programs, o, runs::ScenarioUse::Match);
}

}  // namespace simbot::testkit
