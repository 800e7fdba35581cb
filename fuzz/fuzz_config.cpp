// libFuzzer target: the TOML loaders (profile, hardware file, scenario) on
// any bytes. Each input is accepted or rejected with a FILE:LINE:COL error
// (config::ConfigError); anything else is a bug.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "config/config.h"
#include "plant/plant.h"

using namespace simbot;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    config::parseProfile(text, "fuzz.toml");
  } catch (const config::ConfigError&) {
  }
  try {
    static const config::Profile profile = config::loadProfile(SIMBOT_PROFILES_DIR "/default.toml");
    plant::RobotParams params = profile.robot;
    scheduler::ControllerKnobs controller = profile.controller;
    config::parseHardware(text, "fuzz.toml", params, controller);
  } catch (const config::ConfigError&) {
  }
  try {
    config::parseScenario(text, "fuzz.toml", SIMBOT_SOURCE_DIR);
  } catch (const config::ConfigError&) {
  }
  return 0;
}
