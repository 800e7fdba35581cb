// plant/variation.cpp -- the seeded variation of one match (DESIGN.md:
// "default" is the real robots, and every seed is a different match).
//
// Three things differ between matches before anything moves: where a hand
// put each robot down (placeByHand), and each wheel's trim (drawWheelTrims);
// two differ per shot: the muzzle speed (muzzleFactor) and the ball's
// angular dispersion (drawDispersion), both drawn at the stroke that
// schedules the launch (arena.cpp). Eye noise and bad readings are drawn
// per A/D read in optics.cpp. The amounts are profile values; this file only
// turns a generator's raw words into them, with the plant's own arithmetic
// (never std::*_distribution, whose output differs between library
// versions). Every draw is bounded, so a pose, trim or speed can never leave
// the range the profile checks allow (a dispersion angle is at most 8.6
// sigmas: the largest Box-Muller radius from 53-bit words). A zero amount
// draws nothing, so a profile without variation (thesis-1997) is exactly the
// ideal match, and a stream left undrawn cannot shift another.
#include <cmath>

#include "plant/geometry.h"
#include "plant/plant.h"

namespace simbot::plant {
namespace {

// A factor uniform in [1 - spread, 1 + spread] from one word.
double spreadFactor(double spread, RandomBits& bits) {
  return 1.0 + spread * (2.0 * unit53(bits.next()) - 1.0);
}

}  // namespace

bool placementFits(double x, double y, double r, const FieldParams& field) {
  // Strictly inside: a body touching a field wall would trip its bumper at
  // the start (field_walls), which no hand placement does.
  const double half = field.size_ft / 2;
  if (!(std::abs(x) + r < half && std::abs(y) + r < half)) return false;
  if (!(dividerClearance(x, y, r, field) > 0)) return false;
  for (const Obstacle& o : field.obstacles)
    if (!(obstacleClearance(x, y, r, o) > 0)) return false;
  return true;
}

void placeByHand(ArenaConfig& config, const std::vector<RandomBits*>& streams) {
  const FieldParams& f = config.field;
  if (f.placement_radius_ft == 0 && f.placement_heading_deg == 0) return;
  if (streams.size() != config.robots.size())
    throw std::invalid_argument("placeByHand: one stream per robot");
  for (std::size_t i = 0; i < config.robots.size(); ++i) {
    RobotSetup& robot = config.robots[i];
    const Pose nominal = robot.start;
    const double r = robot.params.body_diameter_ft / 2;
    for (int attempt = 0; attempt < kPlacementAttempts; ++attempt) {
      // Uniform over the disc's area: the radius goes as the root of u.
      const double rho = f.placement_radius_ft * std::sqrt(unit53(streams[i]->next()));
      const double theta = 2.0 * geom::kPi * unit53(streams[i]->next());
      const double dh = f.placement_heading_deg * (2.0 * unit53(streams[i]->next()) - 1.0);
      Pose p;
      p.x_ft = nominal.x_ft + rho * std::cos(theta);
      p.y_ft = nominal.y_ft + rho * std::sin(theta);
      p.heading_deg = geom::wrap360(nominal.heading_deg + dh);
      bool fits = placementFits(p.x_ft, p.y_ft, r, f);
      for (std::size_t j = 0; fits && j < i; ++j) {
        const Pose& o = config.robots[j].start;
        const double apart = r + config.robots[j].params.body_diameter_ft / 2;
        const double dx = p.x_ft - o.x_ft, dy = p.y_ft - o.y_ft;
        fits = dx * dx + dy * dy > apart * apart;
      }
      if (fits) {
        robot.start = p;
        break;
      }
    }
  }
}

void drawWheelTrims(RobotParams& params, RandomBits& bits) {
  if (params.trim_spread == 0) return;
  params.left_trim *= spreadFactor(params.trim_spread, bits);
  params.right_trim *= spreadFactor(params.trim_spread, bits);
}

double muzzleFactor(const RobotParams& params, RandomBits* bits) {
  if (params.muzzle_speed_spread == 0 || !bits) return 1.0;
  return spreadFactor(params.muzzle_speed_spread, *bits);
}

// A circular normal (for equal sigmas): the usual law of small independent
// aiming errors. Box-Muller gives both axes from one pair of words, exactly
// normal, with the arithmetic optics.cpp's eye noise uses.
Dispersion drawDispersion(const RobotParams& params, RandomBits* bits) {
  if ((params.azimuth_sigma_deg == 0 && params.elevation_sigma_deg == 0) || !bits) return {};
  const double r = std::sqrt(-2.0 * std::log(unit53Open0(bits->next())));
  const double theta = 2.0 * geom::kPi * unit53(bits->next());
  return {params.azimuth_sigma_deg * r * std::cos(theta),
          params.elevation_sigma_deg * r * std::sin(theta)};
}

}  // namespace simbot::plant
