// config/obstacles.h -- inside config/: the [[obstacles]] array of a
// scenario (and of a rules file), read and checked into the plant's
// obstacles. Shared by every loader that places obstacles on the field;
// the checks against a field and the start poses are config.h's
// checkObstacles, made when the run is set up.
#pragma once

#include <toml++/toml.h>

#include <string>
#include <vector>

#include "config/config.h"

namespace simbot::config {

// Reads `node`, the value of an `obstacles` key: an array of tables, each
//   kind = "circle"  x_ft, y_ft, radius_ft, height_ft
//   kind = "box"     x_ft, y_ft, width_ft, depth_ft, height_ft, angle_deg (default 0)
//   kind = "polygon" points_ft = [[x, y], ...] (3 to 16, convex), height_ft
// with an optional `name` and `mine = true|false`. Sizes and the height
// must be greater than 0. Throws ConfigError "FILE:LINE:COL: error: ..."
// at the offending key or table.
std::vector<ObstacleSpec> parseObstacles(const toml::node& node, const std::string& file);

}  // namespace simbot::config
