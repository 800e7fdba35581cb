// plant/deployables.cpp -- what a robot sets down behind it (DESIGN.md "The
// wider competition"; docs/plant.md "Deployables"): where an item lands,
// and what the eyes see among decoy lights and screens.
//
// The eyes with decoys. Each light source i (the opponent's beacon, and
// every decoy light the opponent set down) that an eye can see gives the
// near eye c_i = min(kappa_i / r_i^2, max - background), kappa_i = the
// light's intensity times the eye's own kappa ((max - background) r_sat^2:
// the robot's beacon has intensity 1, so its c_i is exactly chapter VII's
// S - background, saturated within r_sat), and the far eye c_i f_i. An eye
// reads background + the sum of its c_i, then the A/D's clamp: a
// photodiode's current is linear in the light that falls on it, so two
// sources add, and the circuit saturates at max whatever makes it (thesis
// VII.D: "a more intense signal ... can saturate the opponents optics").
// Taking the max instead would let a dim decoy beside the robot change
// nothing, which no photodetector does.
//
// A source is hidden from an eye (the segment between the centres, as
// chapter VII's eyes have it) by the divider, by an obstacle or block
// taller than the source, or by a decoy screen taller than the source that
// the segment crosses.
#include <cmath>

#include "plant/geometry.h"
#include "plant/plant.h"

namespace simbot::plant {
namespace {

using geom::Vec2;

// Across the heading, to the robot's right: heading h (clockwise from +y)
// points along (sin h, cos h), its right along (cos h, -sin h).
Vec2 rightOf(double headingDeg) {
  const double h = geom::degToRad(headingDeg);
  return Vec2(std::cos(h), -std::sin(h));
}

// Whether segments [a, b] and [c, d] share a point (touching counts).
bool segmentsCross(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const auto cross = [](const Vec2& u, const Vec2& v) { return u.x() * v.y() - u.y() * v.x(); };
  const Vec2 r = b - a, s = d - c;
  const double den = cross(r, s);
  if (den == 0) return false;  // parallel: a screen edge-on hides nothing
  const double t = cross(c - a, s) / den, u = cross(c - a, r) / den;
  // t < 1: a source standing on the screen's line (one set down with it) is not hidden.
  return t >= 0 && t < 1 && u >= 0 && u <= 1;
}

bool hiddenBy(const Deployed& item, const Vec2& a, const Vec2& b, double sourceHeight) {
  if (!(item.height_ft > sourceHeight)) return false;
  const Vec2 c(item.x_ft, item.y_ft), w = rightOf(item.heading_deg) * (item.width_ft / 2);
  if (item.kind == DeployKind::DecoyScreen) return segmentsCross(a, b, c - w, c + w);
  if (item.kind == DeployKind::Block) {
    const Vec2 f = geom::headingDir(geom::degToRad(item.heading_deg)) * (item.depth_ft / 2);
    // Counter-clockwise: back-right, front-right, front-left, back-left;
    // built as convexOf() builds a box's, without allocating (the eyes
    // read at every sample).
    geom::Convex s;
    s.circle = false;
    s.c = c;
    s.n = 4;
    s.v = {Vec2(c - f + w), Vec2(c + f + w), Vec2(c + f - w), Vec2(c - f - w)};
    for (int k = 0; k < 4; ++k) {
      const Vec2 e = s.v[static_cast<std::size_t>((k + 1) % 4)] - s.v[static_cast<std::size_t>(k)];
      s.normal[static_cast<std::size_t>(k)] = Vec2(e.y(), -e.x()).normalized();
    }
    double lo = 0, hi = 0;
    return geom::clipLine(a, b - a, s, 0.0, 1.0, lo, hi);
  }
  return false;
}

bool obstacleHides(const Vec2& a, const Vec2& b, const FieldParams& field, double sourceHeight) {
  for (const Obstacle& o : field.obstacles) {
    if (!(o.height_ft > sourceHeight)) continue;
    double lo = 0, hi = 0;
    if (geom::clipLine(a, b - a, geom::convexOf(o), 0.0, 1.0, lo, hi)) return true;
  }
  return false;
}

// One source's share of each eye's signal: adds c to the near eye and
// c f to the far one (optics.cpp's geometry, with the source's kappa).
// Returns the index of the scene's item that hid it (a screen before any
// other), or -1: seen, behind the eyes, or hidden by the divider or an
// obstacle.
int addSource(const Pose& self, const Vec2& at, double sourceHeight, double intensity,
              const RobotParams& p, const FieldParams& field, const EyeScene& scene, double& left,
              double& right) {
  const Vec2 a(self.x_ft, self.y_ft);
  const double dx = at.x() - a.x(), dy = at.y() - a.y();
  const double r = std::sqrt(dx * dx + dy * dy);
  const double gamma = geom::wrap180(geom::radToDeg(std::atan2(dx, dy)) - self.heading_deg);
  if (!(std::abs(gamma) < 90.0)) return -1;
  if (dividerBlocks(a.x(), a.y(), at.x(), at.y(), field)) return -1;
  if (obstacleHides(a, at, field, sourceHeight)) return -1;
  int hider = -1;
  for (int k = 0; k < scene.count; ++k) {
    if (!hiddenBy(scene.items[k], a, at, sourceHeight)) continue;
    if (scene.items[k].kind == DeployKind::DecoyScreen) return k;
    if (hider < 0) hider = k;
  }
  if (hider >= 0) return hider;
  const double kappa =
      intensity * (p.eye_max - p.eye_background) * p.eye_saturation_ft * p.eye_saturation_ft;
  const double c = std::min(kappa / (r * r), p.eye_max - p.eye_background);
  const double farWidth = gamma < 0 ? p.right_eye_width : p.left_eye_width;
  const double phi = geom::radToDeg(std::atan(farWidth / p.eye_nose));
  const double f = std::max(0.0, 1.0 - std::abs(gamma) / phi);
  double nearS = c, farS = c * f;
  if (p.thesis_swapped_eyes) std::swap(nearS, farS);
  if (gamma < 0) {
    left += nearS;
    right += farS;
  } else if (gamma > 0) {
    right += nearS;
    left += farS;
  } else {
    left += c;
    right += c;
  }
  return -1;
}

}  // namespace

const char* deployKindName(DeployKind k) {
  switch (k) {
    case DeployKind::Block:
      return "block";
    case DeployKind::DecoyLight:
      return "decoy_light";
    case DeployKind::DecoyScreen:
      return "decoy_screen";
  }
  return "?";
}

Deployed placeDeployable(const Deployable& d, int robot, int table, std::int64_t tick,
                         const Pose& pose, double bodyRadius) {
  Deployed item;
  item.kind = d.kind;
  item.robot = robot;
  item.table = table;
  item.tick = tick;
  item.heading_deg = pose.heading_deg;
  item.width_ft = d.width_ft;
  item.depth_ft = d.kind == DeployKind::Block ? d.depth_ft : 0;
  item.height_ft = d.height_ft;
  item.intensity = d.intensity;
  const double back = bodyRadius + kDeployClearanceFt + item.depth_ft / 2;
  const Vec2 c =
      Vec2(pose.x_ft, pose.y_ft) - back * geom::headingDir(geom::degToRad(pose.heading_deg));
  item.x_ft = c.x();
  item.y_ft = c.y();
  return item;
}

void eyeSignalsAmong(const Pose& self, int selfRobot, const Pose* opponent, const RobotParams& p,
                     const FieldParams& field, const EyeScene& scene, double& left, double& right,
                     int* beaconScreen) {
  double cl = 0, cr = 0;
  int hider = -1;
  if (opponent)
    hider = addSource(self, Vec2(opponent->x_ft, opponent->y_ft), field.beacon_height_ft, 1.0, p,
                      field, scene, cl, cr);
  if (beaconScreen)
    *beaconScreen = hider >= 0 && scene.items[hider].kind == DeployKind::DecoyScreen ? hider : -1;
  for (int k = 0; k < scene.count; ++k) {
    const Deployed& item = scene.items[k];
    if (item.kind != DeployKind::DecoyLight || item.robot == selfRobot) continue;
    addSource(self, Vec2(item.x_ft, item.y_ft), item.height_ft, item.intensity, p, field, scene, cl,
              cr);
  }
  left = p.eye_background + cl;
  right = p.eye_background + cr;
}

}  // namespace simbot::plant
