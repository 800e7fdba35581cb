#include "cli/version.h"

#include <fmt/format.h>

#include "plant/plant.h"
#include "simbot_version.h"

namespace simbot::cli {

std::string simbotVersion() {
  return fmt::format("simbot {} (commit {}, {} build, SUNDIALS {})", SIMBOT_VERSION, SIMBOT_COMMIT,
                     SIMBOT_BUILD_TYPE, plant::sundialsVersion());
}

}  // namespace simbot::cli
