// plant/arena_roots.cpp -- the arena's root functions.
//
// Every discrete change of the arena is the zero of one of these functions
// of time and state (arena.cpp, "Events"): edge detectors, walls, divider,
// obstacles, field, reflex end, robot-robot contact and the balls' and
// discs' closed-form flights (the discs' in arena_discs.cpp). buildRoots()
// lists the ones the current discrete state needs; ARKODE evaluates them
// through rootThunk; crossedTick() decides the tick of
// a crossing ARKODE reported. They only read the state: the rules that act
// on a crossing are in arena_events.cpp.
#include "plant/arena_impl.h"

namespace simbot::plant {

namespace {
constexpr double kMinSide = 1e-150;
}  // namespace

Vec2 Arena::Impl::detector(const double* y, int i, int k) const {
  const double off = radius(i) - P(i).edge_detector_inset_ft;
  const Vec2 dir = headingDirOf(i, heading(y, i));
  return k == 0 ? Vec2(centre(y, i) + off * dir) : Vec2(centre(y, i) - off * dir);
}

double Arena::Impl::edgeG(const double* y, int i, int k) const {
  return geom::squareRingDistance(detector(y, i, k), wireHalf) - cfg.field.wire_sensitivity_ft;
}

double Arena::Impl::outG(const double* y, int i) const {
  const Vec2 c = centre(y, i);
  return half - std::max(std::abs(c.x()), std::abs(c.y()));
}

void Arena::Impl::centresOf(const double* y, double* q) const {
  for (int r = 0; r < nR; ++r) {
    q[kXY * r + X] = y[r * kPerRobot + X];
    q[kXY * r + Y] = y[r * kPerRobot + Y];
  }
}

double Arena::Impl::gapOf(contact::Kind k, int i, const double* y, int obstacle) const {
  std::array<double, 2 * kXY> q{};
  centresOf(y, q.data());
  return contact::gap(bodies, contact::Constraint{k, i, obstacle}, q.data());
}

double Arena::Impl::contactG(contact::Kind k, int i, const double* y, int obstacle) const {
  std::array<double, 2 * kXY> q{};
  centresOf(y, q.data());
  for (int j = 0; j < active.count; ++j) {
    const contact::Constraint& c = active.c[static_cast<std::size_t>(j)];
    if (c.kind != k || c.robot != i || c.obstacle != obstacle) continue;
    // Pushing in this segment: minus its force, which reaches 0 when the
    // body would start to move away. (The free velocities only here: most
    // calls are gaps, and a root evaluation makes seven.)
    std::array<double, 2 * kXY> v{}, vf{};
    for (int r = 0; r < nR; ++r) {
      const double* s = y + r * kPerRobot;
      const double sp = 0.5 * (s[VL] + s[VR]);
      vf[static_cast<std::size_t>(kXY * r + X)] = sp * std::sin(s[H]);
      vf[static_cast<std::size_t>(kXY * r + Y)] = sp * std::cos(s[H]);
    }
    if (segPushes) applyPushes(D, vf.data());
    std::array<double, contact::kMaxActive> mu{};
    contact::project(bodies, active, q.data(), vf.data(), v.data(), mu.data());
    return -mu[static_cast<std::size_t>(j)];
  }
  return contact::gap(bodies, contact::Constraint{k, i, obstacle}, q.data());
}

double Arena::Impl::reflexG(const double* y, int i, const Discrete& d) const {
  const RobotDisc& r = d.r[static_cast<std::size_t>(i)];
  const double sign = r.reflexSide == Bumper::Front ? -1.0 : 1.0;
  return sign * (y[i * kPerRobot + S] - r.reflexS0) - P(i).reflex_distance_ft;
}

// Ball position at time t (closed form).
void Arena::Impl::ballAt(const Ball& b, double t, double& x, double& yy, double& z) const {
  const double dt = t - b.t0;
  x = b.x0 + b.vx * dt;
  yy = b.y0 + b.vy * dt;
  z = b.rolling ? 0.0 : b.z0 + b.vz * dt - 0.5 * cfg.field.gravity_fps2 * dt * dt;
}

// The non-grazing hit function: along-track offset plus half-chord.
double Arena::Impl::ballHitG(const Ball& b, double t, const double* y, double& perp2,
                             double& dist2) const {
  double x, yy, z;
  ballAt(b, t, x, yy, z);
  const int tgt = 1 - b.shooter;
  const Vec2 rel = Vec2(x, yy) - centre(y, tgt);
  const double R = radius(tgt);
  dist2 = rel.squaredNorm();
  const double sp = std::sqrt(b.vx * b.vx + b.vy * b.vy);
  if (sp == 0.0) {
    perp2 = dist2;
    return R - std::sqrt(dist2);
  }
  const Vec2 u(b.vx / sp, b.vy / sp);
  const double a = rel.dot(u);
  perp2 = std::max(dist2 - a * a, 0.0);
  return a + std::sqrt(std::max(R * R - perp2, 0.0));
}

// Distance from the ball to the other robot's body, a cylinder of the
// target height (0 when inside it).
double Arena::Impl::ballGap(const Ball& b, double t, const double* y) const {
  double x, yy, z;
  ballAt(b, t, x, yy, z);
  const int tgt = 1 - b.shooter;
  const double across = std::max((Vec2(x, yy) - centre(y, tgt)).norm() - radius(tgt), 0.0);
  const double above = std::max(z - P(tgt).target_height_ft, 0.0);
  return std::hypot(across, above);
}

// The field walls stop a ball (DESIGN.md: a ball reaching a field wall
// is a miss), at the field's edge.
double Arena::Impl::ballOutG(const Ball& b, double t) const {
  double x, yy, z;
  ballAt(b, t, x, yy, z);
  return half - std::max(std::abs(x), std::abs(yy));
}

// Signed distance past the divider's near face along the ball's x
// travel: linear in t, so a thin wall cannot be stepped over unnoticed.
double Arena::Impl::ballDividerG(const Ball& b, double t) const {
  double x, yy, z;
  ballAt(b, t, x, yy, z);
  const double dir = b.vx > 0 ? 1.0 : b.vx < 0 ? -1.0 : 0.0;
  if (dir == 0.0) return 1.0;
  return dir * (x - cfg.field.divider_x_ft) + cfg.field.divider_thickness_ft / 2;
}

// The ball's straight horizontal path p0 + v s (s >= 0, until the floor or
// forever while rolling) meets obstacle k's footprint over [s_in, s_out]
// (geom::clipLine); within it the ball is below the obstacle's height
// first at s_in if it is low enough there, else where its concave height
// z0 + vz s - g s^2 / 2 comes down through that height, if it does before
// s_out. The earliest over all obstacles is the ball's meeting: a known
// time, so its root function t_meet - t is linear and no step can pass
// over it.
double Arena::Impl::ballMeetsShape(const Ball& b, const geom::Convex& shape, double height,
                                   double from) const {
  const double g = cfg.field.gravity_fps2;
  double lo = 0, hi = 0;
  if (!geom::clipLine(Vec2(b.x0, b.y0), Vec2(b.vx, b.vy), shape, from, HUGE_VAL, lo, hi))
    return HUGE_VAL;
  if (b.rolling) return lo;
  const auto z = [&](double u) { return b.z0 + b.vz * u - 0.5 * g * u * u; };
  if (z(lo) <= height) return lo;
  // z(u) = height on the way down: the larger root of
  // g/2 u^2 - vz u + (height - z0) = 0 (real: z(lo) > height).
  const double disc = b.vz * b.vz + 2 * g * (b.z0 - height);
  const double down = (b.vz + std::sqrt(std::max(disc, 0.0))) / g;
  return down >= lo && down <= hi ? down : HUGE_VAL;
}

void Arena::Impl::ballMeetsObstacle(Ball& b) const {
  b.meetObstacle = -1;
  b.meetT = HUGE_VAL;
  for (int k = 0; k < bodies.obstacleCount; ++k) {
    const double s =
        ballMeetsShape(b, bodies.obstacles[static_cast<std::size_t>(k)],
                       cfg.field.obstacles[static_cast<std::size_t>(k)].height_ft, 0.0);
    if (b.t0 + s < b.meetT) {
      b.meetT = b.t0 + s;
      b.meetObstacle = k;
    }
  }
}

double Arena::Impl::rootValue(const RootDesc& rd, double t, const double* y) const {
  switch (rd.kind) {
    case RootKind::EdgeFore:
      return edgeG(y, rd.robot, 0);
    case RootKind::EdgeAft:
      return edgeG(y, rd.robot, 1);
    case RootKind::OutOfField:
      return outG(y, rd.robot);
    case RootKind::WallX:
      return contactG(contact::Kind::WallX, rd.robot, y);
    case RootKind::WallY:
      return contactG(contact::Kind::WallY, rd.robot, y);
    case RootKind::Divider:
      return contactG(contact::Kind::Divider, rd.robot, y);
    case RootKind::ReflexEnd:
      return reflexG(y, rd.robot, D);
    case RootKind::RobotRobot:
      return contactG(contact::Kind::Robot, 0, y);
    case RootKind::BallFloor: {
      double x, yy, z;
      ballAt(D.balls[static_cast<std::size_t>(rd.robot)], t, x, yy, z);
      return z;
    }
    case RootKind::BallHit: {
      double p2, d2;
      return ballHitG(D.balls[static_cast<std::size_t>(rd.robot)], t, y, p2, d2);
    }
    case RootKind::BallOut:
      return ballOutG(D.balls[static_cast<std::size_t>(rd.robot)], t);
    case RootKind::BallDivider:
      return ballDividerG(D.balls[static_cast<std::size_t>(rd.robot)], t);
    case RootKind::Obstacle:
      return contactG(contact::Kind::Obstacle, rd.robot / kMaxObstacles, y,
                      rd.robot % kMaxObstacles);
    case RootKind::BallObstacle:
      return D.balls[static_cast<std::size_t>(rd.robot)].meetT - t;
    case RootKind::Block:
      return blockRootValue(rd.robot, y);
    case RootKind::BlockStop:
      return blockStopValue(D, rd.robot, y);
    case RootKind::BallTop: {
      const Ball& b = D.balls[static_cast<std::size_t>(rd.robot)];
      double x, yy, z;
      ballAt(b, t, x, yy, z);
      return z - P(1 - b.shooter).target_height_ft;
    }
    case RootKind::DiscEnd: {
      const Disc& d = D.discs[static_cast<std::size_t>(rd.robot)];
      return d.sEnd - discPath(d, t);
    }
    case RootKind::DiscHit: {
      double p2, d2;
      return discHitG(D.discs[static_cast<std::size_t>(rd.robot)], t, y, p2, d2);
    }
  }
  return 1.0;
}

void Arena::Impl::rootThunk(double t, const double* y, double* g, void* user) {
  const Impl* self = static_cast<const Impl*>(user);
  if (self->rootsMuted) {
    self->rootRawValid = false;
    for (int i = 0; i < self->nRoots; ++i) g[i] = 1.0;
    return;
  }
  double* full = self->rootY.data();
  self->fullState(t, y, full);
  // sidedValue(), keeping the unshifted values for stepBound().
  for (int i = 0; i < self->nRoots; ++i) {
    const auto j = static_cast<std::size_t>(i);
    self->rootRaw[j] = self->rootValue(self->roots[j], t, full);
    g[i] = self->rootRaw[j] - self->rootShift[j];
  }
  self->rootRawValid = true;
  self->rootRawT = t;
  std::copy(y, y + self->nx, self->rootRawXY.begin());
}

// Sided roots. A contact or edge function's sign is the discrete state
// (touching, or the detector low, exactly when g < 0), but at the tick of
// a crossing the rules decide by the direction ARKODE reported, and there
// the function can be exactly 0 (a crossing exactly on a tick) or on the
// old side by round-off (the dense output is not ARKODE's own
// interpolation to the last bit). ARKODE ignores a root function that
// starts a segment at exactly 0, and one that starts on the wrong side
// crosses the wrong way or not at all: a reflex backing off a wall at
// once ended the contact only at the next event (rules_test.cpp,
// ExactTicks.WallContactEndsTheTickAfterItBegins). So each such function
// starts the segment strictly on the side its discrete state says: where
// it does not, it is shifted by its start value plus as much again (at
// least the smallest normal double). The shift is round-off sized, far
// below the distance a robot moves in a tick; it holds for the whole
// segment, in ARKODE's root finding, crossedTick() and the event rules.
void Arena::Impl::sideRoots(double t0, const std::vector<double>& y) {
  pushEndDue = false;
  for (int j = 0; j < nRoots; ++j) {
    const RootDesc& rd = roots[static_cast<std::size_t>(j)];
    auto robot = [&]() -> const RobotDisc& { return D.r[static_cast<std::size_t>(rd.robot)]; };
    int side = 0;  // -1: the state says g < 0, +1: g >= 0, 0: no state
    switch (rd.kind) {
      case RootKind::EdgeFore:
        side = robot().edgeLow[0] ? -1 : 1;
        break;
      case RootKind::EdgeAft:
        side = robot().edgeLow[1] ? -1 : 1;
        break;
      case RootKind::WallX:
        side = robot().wallContact[0] ? -1 : 1;
        break;
      case RootKind::WallY:
        side = robot().wallContact[1] ? -1 : 1;
        break;
      case RootKind::Divider:
        side = robot().dividerContact ? -1 : 1;
        break;
      case RootKind::RobotRobot:
        side = D.robotContact ? -1 : 1;
        break;
      case RootKind::Obstacle:
        side = D.r[static_cast<std::size_t>(rd.robot / kMaxObstacles)]
                       .obstacleContact[static_cast<std::size_t>(rd.robot % kMaxObstacles)]
                   ? -1
                   : 1;
        break;
      case RootKind::Block:
        // Touching as a fixed box, or pushing it: negative.
        side = D.r[static_cast<std::size_t>(rd.robot / kMaxBlocks)]
                           .blockContact[static_cast<std::size_t>(rd.robot % kMaxBlocks)] ||
                       D.blocks[static_cast<std::size_t>(rd.robot % kMaxBlocks)].pusher ==
                           rd.robot / kMaxBlocks
                   ? -1
                   : 1;
        break;
      default:
        break;
    }
    double shift = 0;
    if (side != 0) {
      const double g0 = rootValue(rd, t0, y.data());
      const bool pushEnds =
          rd.kind == RootKind::Block && g0 >= 0 &&
          D.blocks[static_cast<std::size_t>(rd.robot % kMaxBlocks)].pusher == rd.robot / kMaxBlocks;
      if (pushEnds)
        pushEndDue = true;  // unshifted: the event rules see it ended
      else if (side * g0 <= 0)
        shift = g0 - side * std::max(std::abs(g0), kMinSide);
    }
    rootShift[static_cast<std::size_t>(j)] = shift;
  }
}

int Arena::Impl::rootIndex(RootKind k, int who) const {
  for (int j = 0; j < nRoots; ++j)
    if (roots[static_cast<std::size_t>(j)].kind == k &&
        roots[static_cast<std::size_t>(j)].robot == who)
      return j;
  return -1;
}

double Arena::Impl::sided(RootKind k, int who, double g) const {
  const int j = rootIndex(k, who);
  return j < 0 ? g : g - rootShift[static_cast<std::size_t>(j)];
}

void Arena::Impl::buildRoots() {
  nRoots = 0;
  auto add = [&](RootKind k, int who) {
    roots[static_cast<std::size_t>(nRoots++)] = RootDesc{k, who};
  };
  for (int i = 0; i < nR; ++i) {
    BoundRoots& at = boundRoots[static_cast<std::size_t>(i)];
    at.edge = {nRoots, nRoots + 1};
    add(RootKind::EdgeFore, i);
    add(RootKind::EdgeAft, i);
    at.out = nRoots;
    add(RootKind::OutOfField, i);
    if (cfg.field.field_walls) {
      at.wall = {nRoots, nRoots + 1};
      add(RootKind::WallX, i);
      add(RootKind::WallY, i);
    }
    at.divider = nRoots;
    if (cfg.field.divider) add(RootKind::Divider, i);
    if (D.r[static_cast<std::size_t>(i)].reflex) add(RootKind::ReflexEnd, i);
    at.obstacle0 = nRoots;
    for (int k = 0; k < bodies.obstacleCount; ++k) add(RootKind::Obstacle, obstacleRoot(i, k));
    for (int k = 0; k < D.blockCount; ++k) add(RootKind::Block, blockRoot(i, k));
  }
  for (int k = 0; k < D.blockCount; ++k)
    if (D.blocks[static_cast<std::size_t>(k)].pusher >= 0) add(RootKind::BlockStop, k);
  robotPairRoot = nRoots;
  if (nR == 2) add(RootKind::RobotRobot, 0);
  for (int b = 0; b < kMaxBalls; ++b) {
    const Ball& ball = D.balls[static_cast<std::size_t>(b)];
    if (!ball.active) continue;
    if (!ball.rolling) add(RootKind::BallFloor, b);
    if (nR == 2) add(RootKind::BallHit, b);
    add(RootKind::BallOut, b);
    if (cfg.field.divider) add(RootKind::BallDivider, b);
    if (ball.meetObstacle >= 0) add(RootKind::BallObstacle, b);
    // Only a ball whose apex, z0 + vz^2 / 2g, clears the other robot's
    // height can come down on its top; no other ball pays for the root.
    if (nR == 2 && !ball.rolling && ball.vz > 0 &&
        ball.z0 + ball.vz * ball.vz / (2 * cfg.field.gravity_fps2) >
            P(1 - ball.shooter).target_height_ft)
      add(RootKind::BallTop, b);
  }
  addDiscRoots();
}

// DESIGN.md: an event happens at the first integer tick at which its root
// function has crossed. ARKODE returns the right end of its root bracket,
// a hair past the crossing, so T0 = ceil(tret) is one tick late when the
// crossing falls exactly on tick T0 - 1 (a contact at constant speed, a
// reflex of exactly 1.5 ft at 1.5 ft/s). Decide from dense output at the
// two neighbouring ticks: T0 - 1 if a reported root function is already
// on its new side there, or within kOnTickFraction of a tick of it
// (linearly between the ticks), which round-off cannot tell from zero.
// At the segment's first tick only the round-off case counts, and only for
// a function that has not fired there already: two crossings exactly on
// one tick (both reflexes of a head-on contact ending) are found in one
// step, or, as the steps fall, the second in the segment that the first
// one's re-initialisation starts; both are events of that tick. A sided
// root (see above) is on its old side at the segment's first tick by
// construction: it does not cross there.
std::int64_t Arena::Impl::crossedTick(std::int64_t T0) {
  const std::int64_t k = T0 - 1;
  if (k < segTick) return T0;
  const bool first = k == segTick;
  const double tk = secondsFromTick(k), tT = secondsFromTick(T0);
  evalAt(tk, tmp);
  evalAt(tT, qtmp);
  for (int j = 0; j < nRoots; ++j) {
    const int dir = rootsFound[static_cast<std::size_t>(j)];
    if (dir == 0) continue;
    const RootDesc& rd = roots[static_cast<std::size_t>(j)];
    if (first && (firedAt(k, rd) || rootShift[static_cast<std::size_t>(j)] != 0)) continue;
    const double gk = sidedValue(j, tk, tmp.data());
    const double gT = sidedValue(j, tT, qtmp.data());
    if ((!first && dir * gk >= 0) || std::abs(gk) <= kOnTickFraction * std::abs(gT - gk)) return k;
  }
  return T0;
}

// Each root function at most once per tick through crossedTick()'s first
// tick rule, over any number of re-initialisations there.
void Arena::Impl::noteFired(std::int64_t tick, const int* found) {
  if (tick != firedTick) {
    firedTick = tick;
    nFired = 0;
  }
  for (int j = 0; j < nRoots; ++j)
    if (found[j] != 0 && !firedAt(tick, roots[static_cast<std::size_t>(j)]) && nFired < kMaxRoots)
      fired[static_cast<std::size_t>(nFired++)] = roots[static_cast<std::size_t>(j)];
}

bool Arena::Impl::firedAt(std::int64_t tick, const RootDesc& rd) const {
  if (tick != firedTick) return false;
  for (int i = 0; i < nFired; ++i) {
    const RootDesc& f = fired[static_cast<std::size_t>(i)];
    if (f.kind == rd.kind && f.robot == rd.robot) return true;
  }
  return false;
}

}  // namespace simbot::plant
