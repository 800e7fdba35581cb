// plant/arena_discs.cpp -- the disc launcher's discs (a secondary weapon:
// DESIGN.md "The wider competition", docs/plant.md "The disc launcher").
//
// A disc leaves the shooter's rim along its heading at the port B write's
// tick (no spin-up: a sprung launcher released by the bit), flat at its
// launch height, and slows by linear drag: v(t) = v0 e^{-t/tau}, so its
// centre has gone s(t) = v0 tau (1 - e^{-t/tau}) along a straight line.
// Everything fixed it can strike lies on that line, so where its flight
// ends is known at the launch in closed form (discStrike: the field's
// walls, the divider, the obstacles; the stop speed v_stop is reached after
// s = tau (v0 - v_stop)), and one root function, sEnd - s(t), puts that end
// on its exact tick. Robots move: a hit is the root of the ball's
// non-grazing hit function (arena_roots.cpp) with the target's radius grown
// by the disc's, if the disc flies no higher than the target is tall; its
// other roots (a miss's closest approach, a disc passing over the target)
// give the disc_miss its closest distance, as a ball's.
#include "plant/arena_impl.h"

namespace simbot::plant {

double Arena::Impl::discPath(const Disc& d, double t) const {
  return -d.v0 * d.tau * std::expm1(-(t - d.t0) / d.tau);
}

void Arena::Impl::discAt(const Disc& d, double t, double& x, double& yy) const {
  const double s = discPath(d, t);
  x = d.x0 + d.ux * s;
  yy = d.y0 + d.uy * s;
}

double Arena::Impl::discHitG(const Disc& d, double t, const double* y, double& perp2,
                             double& dist2) const {
  double x, yy;
  discAt(d, t, x, yy);
  const int tgt = 1 - d.shooter;
  const Vec2 rel = Vec2(x, yy) - centre(y, tgt);
  const double reach = radius(tgt) + d.radius;
  dist2 = rel.squaredNorm();
  const double a = rel.dot(Vec2(d.ux, d.uy));
  perp2 = std::max(dist2 - a * a, 0.0);
  return a + std::sqrt(std::max(reach * reach - perp2, 0.0));
}

// Distance from the disc's edge to the other robot's body, a cylinder of
// the target height (0 when they touch).
double Arena::Impl::discGap(const Disc& d, double t, const double* y) const {
  double x, yy;
  discAt(d, t, x, yy);
  const int tgt = 1 - d.shooter;
  const double across =
      std::max((Vec2(x, yy) - centre(y, tgt)).norm() - radius(tgt) - d.radius, 0.0);
  const double above = std::max(d.z - P(tgt).target_height_ft, 0.0);
  return std::hypot(across, above);
}

double Arena::Impl::discStrike(const Vec2& p, const Vec2& u, double z, double radius,
                               MissReason& what, int& obstacle) const {
  // The field's walls stop every disc (as they do a ball), at its edge.
  double best = geom::discPathToSquareEdge(p, u, radius, half);
  what = MissReason::LeftField;
  // The divider, if the disc flies no higher than it is tall.
  if (cfg.field.divider && z <= cfg.field.divider_height_ft) {
    const double s = geom::discPathToRect(p, u, radius, bodies.divider);
    if (s < best) {
      best = s;
      what = MissReason::Divider;
    }
  }
  // A fixed obstacle, like the divider: where the disc's circle first
  // touches the shape, if the disc flies no higher than it is tall.
  obstacle = -1;
  for (int k = 0; k < bodies.obstacleCount; ++k) {
    if (z > cfg.field.obstacles[static_cast<std::size_t>(k)].height_ft) continue;
    const double s =
        geom::discPathToConvex(p, u, radius, bodies.obstacles[static_cast<std::size_t>(k)]);
    if (s < best) {
      best = s;
      what = MissReason::Obstacle;
      obstacle = k;
    }
  }
  return best;
}

void Arena::Impl::addDiscRoots() {
  for (int k = 0; k < kMaxDiscs; ++k) {
    const Disc& d = D.discs[static_cast<std::size_t>(k)];
    if (!d.active) continue;
    roots[static_cast<std::size_t>(nRoots++)] = RootDesc{RootKind::DiscEnd, k};
    if (nR == 2) roots[static_cast<std::size_t>(nRoots++)] = RootDesc{RootKind::DiscHit, k};
  }
}

void Arena::Impl::launchDisc(Discrete& d, const std::vector<double>& y, int i, double te,
                             EventList& ev) {
  int slot = -1;
  for (int k = 0; k < kMaxDiscs && slot < 0; ++k)
    if (!d.discs[static_cast<std::size_t>(k)].active) slot = k;
  if (slot < 0) throw std::logic_error("plant: the disc table is full (see kMaxDiscs)");
  d.discSlots = std::max(d.discSlots, slot + 1);
  RobotDisc& r = d.r[static_cast<std::size_t>(i)];
  r.discsLeft--;
  r.discShots++;
  const SecondaryWeapon& w = cfg.robots[static_cast<std::size_t>(i)].hardware.secondary;
  const double h = heading(y.data(), i);
  const Vec2 u = geom::headingDir(h);
  const Vec2 rim = centre(y.data(), i) + radius(i) * u;  // the launcher on the body's edge
  Disc& c = d.discs[static_cast<std::size_t>(slot)];
  c = Disc{};
  c.active = true;
  ++d.inFlight;
  c.shooter = i;
  c.t0 = te;
  c.x0 = rim.x();
  c.y0 = rim.y();
  c.z = w.launch_height_ft;
  c.ux = u.x();
  c.uy = u.y();
  c.v0 = w.launch_speed_fps;
  c.tau = w.drag_time_s;
  c.radius = w.diameter_ft / 2;
  // v0 e^{-t/tau} falls to v_stop at t = tau ln(v0 / v_stop), when the
  // disc has gone v0 tau (1 - v_stop / v0) = tau (v0 - v_stop).
  MissReason what = MissReason::None;
  int obstacle = -1;
  double fixed = discStrike(rim, u, c.z, c.radius, what, obstacle);
  // The blocks where they stand now (arena_blocks.cpp, flightsSeeBlocks).
  for (int k = 0; k < d.blockCount; ++k) {
    if (c.z > d.blocks[static_cast<std::size_t>(k)].height) continue;
    const double s = geom::discPathToConvex(rim, u, c.radius, blockShape(d, k, y.data()));
    if (s < fixed) {
      fixed = s;
      what = MissReason::Block;
      obstacle = k;
    }
  }
  const double stop = c.tau * (c.v0 - w.stop_speed_fps);
  c.sEnd = stop <= fixed ? stop : fixed;
  c.end = stop <= fixed ? MissReason::Stopped : what;
  c.obstacle = static_cast<std::int8_t>(stop <= fixed ? -1 : obstacle);
  Event e{EventKind::DiscFire};
  e.robot = static_cast<std::int8_t>(i);
  e.ball = static_cast<std::int8_t>(slot);
  e.x = c.x0;
  e.y = c.y0;
  e.z = c.z;
  e.vx = c.v0 * c.ux;
  e.vy = c.v0 * c.uy;
  e.heading_deg = geom::wrap360(geom::radToDeg(h));
  ev.push(e);
  // Against a wall or the divider, or touching the target, already.
  discOutcome(slot, te, d, y.data(), nullptr, ev);
}

// Disc k's outcome at time te, in the ball's order: the end of its path
// (what it struck, or its stop), then a hit.
void Arena::Impl::discOutcome(int k, double te, Discrete& d, const double* ys, const int* found,
                              EventList& ev) {
  Disc& c = d.discs[static_cast<std::size_t>(k)];
  double x, yy;
  discAt(c, te, x, yy);
  if (nR == 2) c.closest = std::min(c.closest, discGap(c, te, ys));
  Event e{EventKind::DiscMiss};
  e.robot = static_cast<std::int8_t>(c.shooter);
  e.ball = static_cast<std::int8_t>(k);
  e.x = x;
  e.y = yy;
  e.z = c.z;
  e.closest_ft = nR == 2 ? c.closest : -1;
  if (reported(found, RootKind::DiscEnd, k) < 0 || discPath(c, te) >= c.sEnd) {
    e.miss = c.end;
    e.obstacle = c.obstacle;
    ev.push(e);
    c.active = false;
    --d.inFlight;
    return;
  }
  if (nR < 2) return;
  const int tgt = 1 - c.shooter;
  if (c.z > P(tgt).target_height_ft) return;
  double p2, d2;
  discHitG(c, te, ys, p2, d2);
  const double reach = radius(tgt) + c.radius;
  const bool crossed = reported(found, RootKind::DiscHit, k) > 0 && p2 <= reach * reach;
  if (crossed || d2 <= reach * reach) {
    e.kind = EventKind::DiscHit;
    e.other = static_cast<std::int8_t>(tgt);
    ev.push(e);
    d.r[static_cast<std::size_t>(c.shooter)].discHits++;
    c.active = false;
    --d.inFlight;
  }
}

}  // namespace simbot::plant
