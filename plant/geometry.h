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
#include <array>
#include <cmath>
#include <utility>

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
//
// fmod(deg, 360), which is exact, without the call below 2^52 degrees (a
// robot turning for a whole match is far below; glibc's fmod takes about
// 90 host instructions there, a quarter of a pose). k = trunc(deg / 360)
// is the exact quotient's integer part or one off it; 360 k is exact, and
// so is deg - 360 k: both are multiples of ulp(deg) (360 k of 8, and
// ulp(deg) <= 1/2) and the difference is smaller than |deg|. One step of
// 360 (exact for the same reason) brings it into (-360, 360) with deg's
// sign; a zero takes deg's sign, as fmod's does. That is fmod's result:
// the only value there congruent to deg modulo 360.
inline double remainder360(double deg) {
  const double k = std::trunc(deg / 360.0);
  double r = deg - k * 360.0;
  if (deg > 0) {
    if (r < 0) r += 360.0;
    if (r >= 360.0) r -= 360.0;
  } else {
    if (r > 0) r -= 360.0;
    if (r <= -360.0) r += 360.0;
  }
  return r == 0 ? std::copysign(0.0, deg) : r;
}
inline double wrap360(double deg) {
  // fmod gives back a deg of magnitude below 360 unchanged (its sign, -0
  // too): the remainder is needed only beyond.
  const double size = std::abs(deg);
  double w = size < 360.0 ? deg : size < 0x1p52 ? remainder360(deg) : std::fmod(deg, 360.0);
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

// Rays, for a disc's straight path (arena_discs.cpp): p + s u, s >= 0,
// u a unit vector. Each gives the smallest s >= 0 at which the ray is in
// the closed shape (0 if p is in it already), or +inf if it never is.

// A circle of radius r about c. With w = p - c: |w + s u|^2 = r^2, the
// smaller root s = -b - sqrt(b^2 - k), b = w.u, k = |w|^2 - r^2, written
// as k / (-b + sqrt(b^2 - k)) so that a far circle loses no digits.
inline double rayEntersCircle(const Vec2& p, const Vec2& u, const Vec2& c, double r) {
  const Vec2 w = p - c;
  const double b = w.dot(u), k = w.squaredNorm() - r * r;
  if (k <= 0) return 0.0;
  const double disc = b * b - k;
  if (b >= 0 || disc < 0) return HUGE_VAL;  // moving away, or passing by
  return k / (-b + std::sqrt(disc));
}

// An axis-aligned rectangle: slab clipping of [0, inf) against both axes.
inline double rayEntersRect(const Vec2& p, const Vec2& u, const Rect& r) {
  double lo = 0.0, hi = HUGE_VAL;
  const double mins[2] = {r.x0, r.y0}, maxs[2] = {r.x1, r.y1};
  for (int i = 0; i < 2; ++i) {
    if (u[i] == 0.0) {
      if (p[i] < mins[i] || p[i] > maxs[i]) return HUGE_VAL;
      continue;
    }
    double t0 = (mins[i] - p[i]) / u[i], t1 = (maxs[i] - p[i]) / u[i];
    if (t0 > t1) std::swap(t0, t1);
    lo = std::max(lo, t0);
    hi = std::min(hi, t1);
  }
  return lo <= hi ? lo : HUGE_VAL;
}

// Where a disc of radius r, its centre on the ray, first touches the
// rectangle: where the ray enters the rectangle grown by r (their
// Minkowski sum: the rectangle widened by r across x, across y, and a
// circle of radius r at each corner).
inline double discPathToRect(const Vec2& p, const Vec2& u, double r, const Rect& rect) {
  double s = std::min(rayEntersRect(p, u, Rect{rect.x0 - r, rect.y0, rect.x1 + r, rect.y1}),
                      rayEntersRect(p, u, Rect{rect.x0, rect.y0 - r, rect.x1, rect.y1 + r}));
  for (const Vec2& corner : {Vec2(rect.x0, rect.y0), Vec2(rect.x1, rect.y0), Vec2(rect.x0, rect.y1),
                             Vec2(rect.x1, rect.y1)})
    s = std::min(s, rayEntersCircle(p, u, corner, r));
  return s;
}

// Where a disc of radius r, its centre on the ray from inside the square
// |x|, |y| <= hw, first touches the square's edge (the field's walls): 0
// if it touches already.
inline double discPathToSquareEdge(const Vec2& p, const Vec2& u, double r, double hw) {
  const double inner = hw - r;
  if (std::abs(p.x()) >= inner || std::abs(p.y()) >= inner) return 0.0;
  double s = HUGE_VAL;
  for (int i = 0; i < 2; ++i) {
    if (u[i] > 0) s = std::min(s, (inner - p[i]) / u[i]);
    if (u[i] < 0) s = std::min(s, (-inner - p[i]) / u[i]);
  }
  return s;
}

// An obstacle's footprint as the plant evaluates it: a circle, or a convex
// polygon with its counter-clockwise vertices and each edge's outward unit
// normal (edge k runs from v[k] to v[k + 1]). Fixed size: nothing is
// allocated where a root function or an eye reads it.
struct Convex {
  bool circle = true;
  Vec2 c{0, 0};
  double r = 0;
  int n = 0;
  std::array<Vec2, kMaxObstacleVertices> v{}, normal{};
};

inline Convex convexOf(const Obstacle& o) {
  Convex s;
  s.circle = o.kind == Obstacle::Kind::Circle;
  s.c = Vec2(o.x_ft, o.y_ft);
  s.r = o.radius_ft;
  if (s.circle) return s;
  s.n = static_cast<int>(std::min<std::size_t>(o.points.size(), kMaxObstacleVertices));
  for (int k = 0; k < s.n; ++k)
    s.v[static_cast<std::size_t>(k)] = Vec2(o.points[static_cast<std::size_t>(k)].x_ft,
                                            o.points[static_cast<std::size_t>(k)].y_ft);
  for (int k = 0; k < s.n; ++k) {
    const Vec2 e = s.v[static_cast<std::size_t>((k + 1) % s.n)] - s.v[static_cast<std::size_t>(k)];
    // Counter-clockwise: the outside is to the right of each edge.
    s.normal[static_cast<std::size_t>(k)] = Vec2(e.y(), -e.x()).normalized();
  }
  return s;
}

// Signed distance from p to the shape's boundary (positive outside), and
// the outward unit normal there: outside, from the nearest boundary point
// towards p; inside, the nearest edge's. Continuous across the boundary,
// as a contact's root function must be.
inline double signedDistance(const Vec2& p, const Convex& s, Vec2* normal) {
  if (s.circle) {
    const Vec2 d = p - s.c;
    const double len = d.norm();
    if (normal) *normal = len > 0 ? Vec2(d / len) : Vec2(1.0, 0.0);
    return len - s.r;
  }
  // The largest signed distance past an edge's line: <= 0 exactly inside.
  double worst = -HUGE_VAL;
  int face = 0;
  for (int k = 0; k < s.n; ++k) {
    const double dk =
        s.normal[static_cast<std::size_t>(k)].dot(p - s.v[static_cast<std::size_t>(k)]);
    if (dk > worst) {
      worst = dk;
      face = k;
    }
  }
  if (worst <= 0) {
    if (normal) *normal = s.normal[static_cast<std::size_t>(face)];
    return worst;
  }
  // Outside: the nearest point of the nearest edge.
  double best = HUGE_VAL;
  Vec2 nearest = s.v[0];
  for (int k = 0; k < s.n; ++k) {
    const Vec2& a = s.v[static_cast<std::size_t>(k)];
    const Vec2 e = s.v[static_cast<std::size_t>((k + 1) % s.n)] - a;
    const double u = std::clamp((p - a).dot(e) / e.squaredNorm(), 0.0, 1.0);
    const Vec2 q = a + u * e;
    const double d2 = (p - q).squaredNorm();
    if (d2 < best) {
      best = d2;
      nearest = q;
    }
  }
  const double len = std::sqrt(best);
  if (normal) *normal = Vec2((p - nearest) / len);
  return len;
}

// The parameters [lo, hi] (clipped to [lo0, hi0]) at which p + s d lies
// in the closed shape; false when it never does. Cyrus-Beck clipping for a
// polygon, the quadratic's roots for a circle.
inline bool clipLine(const Vec2& p, const Vec2& d, const Convex& s, double lo0, double hi0,
                     double& lo, double& hi) {
  lo = lo0;
  hi = hi0;
  if (s.circle) {
    const Vec2 m = p - s.c;
    const double a = d.squaredNorm(), b = m.dot(d), c = m.squaredNorm() - s.r * s.r;
    if (a == 0) return c <= 0;
    const double disc = b * b - a * c;
    if (disc < 0) return false;
    const double root = std::sqrt(disc);
    // The stable pair of roots of a s^2 + 2 b s + c.
    const double q = b >= 0 ? -(b + root) : -(b - root);
    double s0 = q / a, s1 = q != 0 ? c / q : s0;
    if (s0 > s1) std::swap(s0, s1);
    lo = std::max(lo, s0);
    hi = std::min(hi, s1);
    return lo <= hi;
  }
  for (int k = 0; k < s.n; ++k) {
    const Vec2& nk = s.normal[static_cast<std::size_t>(k)];
    // Inside the edge's half-plane: nk . (p + s d - v_k) <= 0.
    const double num = nk.dot(p - s.v[static_cast<std::size_t>(k)]);
    const double den = nk.dot(d);
    if (den == 0) {
      if (num > 0) return false;
      continue;
    }
    const double t = -num / den;
    if (den > 0)
      hi = std::min(hi, t);
    else
      lo = std::max(lo, t);
    if (lo > hi) return false;
  }
  return true;
}

// Where a disc of radius r, its centre on the ray, first touches a convex
// shape: where the ray enters the shape grown by r. The grown shape is the
// union of the shape, a circle of radius r at each vertex and each edge's
// r-wide band outside it, so its entry is the least of theirs (a band by
// slab clipping in the edge's own frame).
inline double discPathToConvex(const Vec2& p, const Vec2& u, double r, const Convex& s) {
  if (s.circle) return rayEntersCircle(p, u, s.c, s.r + r);
  double best = HUGE_VAL, lo, hi;
  if (clipLine(p, u, s, 0.0, HUGE_VAL, lo, hi)) best = lo;
  for (int k = 0; k < s.n; ++k) {
    const Vec2& a = s.v[static_cast<std::size_t>(k)];
    const Vec2& n = s.normal[static_cast<std::size_t>(k)];
    const Vec2 e = s.v[static_cast<std::size_t>((k + 1) % s.n)] - a;
    const double length = e.norm();
    const Vec2 along = e / length;
    const Vec2 local((p - a).dot(along), (p - a).dot(n)), dir(u.dot(along), u.dot(n));
    best = std::min(
        {best, rayEntersCircle(p, u, a, r), rayEntersRect(local, dir, Rect{0.0, 0.0, length, r})});
  }
  return best;
}

}  // namespace simbot::plant::geom
