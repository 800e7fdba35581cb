// libFuzzer target: programs that compile run as robot A alone in the
// arena (the default profile) for 20 simulated milliseconds, through the
// whole scheduler: VM, serial link, PIO, plant. A robot may fault; the host
// must not crash, hang or throw.
#include <cstddef>
#include <cstdint>
#include <string>

#include "compiler/compiler.h"
#include "config/config.h"
#include "plant/plant.h"
#include "scheduler/match.h"

using namespace simbot;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const config::Profile profile = config::loadProfile(SIMBOT_PROFILES_DIR "/default.toml");
  const std::string source(reinterpret_cast<const char*>(data), size);
  compiler::Result compiled = compiler::compile(source, "fuzz.dc");
  if (!compiled.image) return 0;
  scheduler::MatchConfig config;
  config.arena = config::makeArenaConfig(profile, 1);
  config.robots.push_back({"A", "fuzz.dc", std::move(*compiled.image)});
  config.endTick = scheduler::kTicksPerSecond / 50;
  config.stopWhenAllExited = true;
  const scheduler::MatchResult r = scheduler::runMatch(config);
  return r.robots.size() == 1 ? 0 : 1;
}
