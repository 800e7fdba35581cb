// libFuzzer target: the TOML loaders (profile, hardware file, scenario) on
// any bytes. Each input is accepted or rejected with a FILE:LINE:COL error
// (plant::ConfigError); anything else is a bug.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "plant/plant.h"
#include "tools/scenario.h"

using namespace simbot;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    plant::parseProfile(text, "fuzz.toml");
  } catch (const plant::ConfigError&) {
  }
  try {
    static const plant::Profile profile = plant::loadProfile(SIMBOT_PROFILES_DIR "/default.toml");
    plant::RobotParams params = profile.robot;
    plant::parseHardware(text, "fuzz.toml", params);
  } catch (const plant::ConfigError&) {
  }
  try {
    tools::parseScenario(text, "fuzz.toml", SIMBOT_SOURCE_DIR);
  } catch (const plant::ConfigError&) {
  }
  return 0;
}
