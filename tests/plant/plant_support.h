// Shared helpers for the plant tests: shipped profiles (read by config/),
// small arenas, and driving an arena until a kind of event shows up.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>

#include "config/config.h"
#include "plant/plant.h"

namespace plant_test {

using namespace simbot::plant;
using simbot::config::ConfigError;
using simbot::config::loadProfile;
using simbot::config::makeArenaConfig;
using simbot::config::Profile;

inline std::string profilePath(const char* name) {
  return std::string(SIMBOT_PROFILES_DIR) + "/" + name + ".toml";
}
inline Profile thesis() { return loadProfile(profilePath("thesis-1997")); }
inline Profile defaults() { return loadProfile(profilePath("default")); }

inline std::int64_t ticks(double seconds) { return simbot::timebase::ticksFromSeconds(seconds); }

inline MotorFrame frame(const char* s) {
  auto f = parseMotorFrame(s);
  EXPECT_TRUE(f.has_value()) << s;
  return f.value_or(MotorFrame{});
}

// Solo or duel config from a profile, with explicit start poses.
inline ArenaConfig config(const Profile& p, std::initializer_list<Pose> starts) {
  ArenaConfig c = makeArenaConfig(p, static_cast<int>(starts.size()));
  int i = 0;
  for (const Pose& s : starts) c.robots[static_cast<std::size_t>(i++)].start = s;
  return c;
}

struct Found {
  std::int64_t tick;
  Event event;
};
// Advances until an event of `kind` (optionally for `robot`) or `limit`.
inline std::optional<Found> runUntil(Arena& a, EventKind kind, std::int64_t limit, int robot = -1) {
  while (a.now() < limit) {
    AdvanceResult r = a.advance(limit);
    for (const Event& e : r.events)
      if (e.kind == kind && (robot < 0 || e.robot == robot)) return Found{r.tick, e};
  }
  return std::nullopt;
}

}  // namespace plant_test
