// plant/geometry.h -- internal: plane geometry of the field (not public).
//
// Coordinates are feet with the origin at the field's centre, +x east,
// +y north; headings are clockwise from +y, so the unit vector of heading h
// is (sin h, cos h). The field edge, the wire ring and the put-back square
// are all axis-aligned squares centred at the origin; the divider is an
// axis-aligned rectangle. Eigen's fixed-size 2-vectors keep the formulas
// short and allocate nothing.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "plant/plant.h"

namespace simbot::plant::geom {

using Vec2 = Eigen::Vector2d;

inline constexpr double kPi = 3.14159265358979323846;
inline double degToRad(double d) { return d * (kPi / 180.0); }
inline double radToDeg(double r) { return r * (180.0 / kPi); }

// Heading unit vector (clockwise from +y).
inline Vec2 headingDir(double headingRad) {
  return Vec2(std::sin(headingRad), std::cos(headingRad));
}

// Degrees in [0, 360).
inline double wrap360(double deg) {
  double w = std::fmod(deg, 360.0);
  if (w < 0) w += 360.0;
  if (w >= 360.0) w = 0.0;  // fmod of a tiny negative number plus 360
  return w;
}
// Degrees in (-180, 180].
inline double wrap180(double deg) {
  double w = wrap360(deg);
  return w > 180.0 ? w - 360.0 : w;
}

// Distance from p to the boundary of the square |x|,|y| <= hw (the wire).
// Inside: distance to the nearest side; outside: Euclidean distance to the
// square. Continuous everywhere, which is all ARKODE's root finder needs.
inline double squareRingDistance(const Vec2& p, double hw) {
  const double ax = std::abs(p.x()), ay = std::abs(p.y());
  if (ax <= hw && ay <= hw) return std::min(hw - ax, hw - ay);
  const double dx = std::max(ax - hw, 0.0), dy = std::max(ay - hw, 0.0);
  return std::sqrt(dx * dx + dy * dy);
}

struct Rect {
  double x0, y0, x1, y1;  // x0 < x1, y0 < y1
};
inline Rect dividerRect(const FieldParams& f) {
  const double h = f.divider_thickness_ft / 2;
  return Rect{f.divider_x_ft - h, f.divider_south_ft, f.divider_x_ft + h, f.divider_north_ft};
}
inline Vec2 closestPointOnRect(const Vec2& p, const Rect& r) {
  return Vec2(std::clamp(p.x(), r.x0, r.x1), std::clamp(p.y(), r.y0, r.y1));
}

// Does segment a-b meet the closed rectangle r? Slab clipping of the
// parameter interval [0, 1] against both axis slabs.
inline bool segmentHitsRect(const Vec2& a, const Vec2& b, const Rect& r) {
  double lo = 0.0, hi = 1.0;
  const Vec2 d = b - a;
  const double mins[2] = {r.x0, r.y0}, maxs[2] = {r.x1, r.y1};
  for (int i = 0; i < 2; ++i) {
    if (d[i] == 0.0) {
      if (a[i] < mins[i] || a[i] > maxs[i]) return false;
    } else {
      double t0 = (mins[i] - a[i]) / d[i], t1 = (maxs[i] - a[i]) / d[i];
      if (t0 > t1) std::swap(t0, t1);
      lo = std::max(lo, t0);
      hi = std::min(hi, t1);
      if (lo > hi) return false;
    }
  }
  return true;
}

}  // namespace simbot::plant::geom
