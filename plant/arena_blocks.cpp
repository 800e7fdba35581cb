// plant/arena_blocks.cpp -- blocks set down on the field as bodies of the
// arena (DESIGN.md "The wider competition"; docs/plant.md "Deployables").
//
// A block is a box that translates and never turns. Resting, it is a fixed
// box for everything: a robot touching it is a contact at its exact tick
// (contact.h's Obstacle constraint, index blockObstacle(k)), a ball or disc
// meeting it below its height ends there, and it hides what is lower.
//
// A push. A robot of traction T = M g mu_w meeting a block that resists
// with F = m g mu_b pushes it when T > F, the robot drives into it, the
// block can move along the push (nothing touches it there) and the other
// robot does not touch it. A push is no contact (DESIGN.md: the robot is
// only slowed by the friction): no contact record, no bumper. From the
// touch's tick the block follows the robot's motion along the contact
// normal n (Block), and the robot's velocity loses F / T of its normal
// part, v - (F / T)(v . n) n: the quasi-static drive under a load, whose
// force-speed line runs from the free speed at no load to a stall at T.
// The tangential part stays (the robot slides along the block's face, as
// along a wall). The push ends at the exact tick of one of its root
// functions: the robot's free velocity along n reaches 0 (it no longer
// drives into the block) or the robot slides off the block's face or
// round its corner (its gap exceeds kPushSlipFt) -- then the robot is free
// of the block, no contact -- or the block has gone its reach, the
// distance it can translate along -n before it touches a wall, the
// divider, an obstacle or another block (computed at the push's start in
// closed form: a convex shape swept along a line) -- then the block stands
// there and the robot meets it as a fixed box at that tick: a contact, its
// bumper trips. A block that cannot be pushed is met so at once.
#include "plant/arena_impl.h"

namespace simbot::plant {

namespace {

// A push ends when its robot has slid off the block by this much: far
// below a tick's travel at top speed (1.6e-7 ft), far above round-off of
// a gap (1e-15 ft).
constexpr double kPushSlipFt = 1e-9;
// A block that can move less than this along a push is held (ft).
constexpr double kMinReachFt = 1e-9;
// An entry into a shape shorter than this is a touch, not a meeting (a
// vertex on a face, moving away from it).
constexpr double kMinOverlap = 1e-12;

geom::Convex rectShape(const geom::Rect& r) {
  geom::Convex s;
  s.circle = false;
  s.n = 4;
  s.c = Vec2(0.5 * (r.x0 + r.x1), 0.5 * (r.y0 + r.y1));
  s.v[0] = Vec2(r.x0, r.y0);
  s.v[1] = Vec2(r.x1, r.y0);
  s.v[2] = Vec2(r.x1, r.y1);
  s.v[3] = Vec2(r.x0, r.y1);
  s.normal[0] = Vec2(0, -1);
  s.normal[1] = Vec2(1, 0);
  s.normal[2] = Vec2(0, 1);
  s.normal[3] = Vec2(-1, 0);
  return s;
}

// How far polygon b moves along the unit vector u before it touches
// convex s (+inf: never): the first vertex of one that enters the other.
double sweep(const geom::Convex& b, const Vec2& u, const geom::Convex& s) {
  if (s.circle) return geom::discPathToConvex(s.c, -u, s.r, b);
  double best = HUGE_VAL, lo = 0, hi = 0;
  for (int k = 0; k < b.n; ++k)
    if (geom::clipLine(b.v[static_cast<std::size_t>(k)], u, s, 0.0, HUGE_VAL, lo, hi) &&
        hi - lo > kMinOverlap)
      best = std::min(best, lo);
  for (int k = 0; k < s.n; ++k)
    if (geom::clipLine(s.v[static_cast<std::size_t>(k)], -u, b, 0.0, HUGE_VAL, lo, hi) &&
        hi - lo > kMinOverlap)
      best = std::min(best, lo);
  return best;
}

// Whether polygon a and convex s overlap (touching is not overlapping):
// no edge of either separates them.
bool overlaps(const geom::Convex& a, const geom::Convex& s) {
  if (s.circle) return geom::signedDistance(s.c, a, nullptr) < s.r;
  auto separates = [](const geom::Convex& p, const geom::Convex& q) {
    for (int k = 0; k < p.n; ++k) {
      bool all = true;
      for (int j = 0; j < q.n && all; ++j)
        all = p.normal[static_cast<std::size_t>(k)].dot(q.v[static_cast<std::size_t>(j)] -
                                                        p.v[static_cast<std::size_t>(k)]) >= 0;
      if (all) return true;
    }
    return false;
  };
  return !separates(a, s) && !separates(s, a);
}

}  // namespace

Vec2 Arena::Impl::blockAt(const Discrete& d, int k, const double* y) const {
  const Block& b = d.blocks[static_cast<std::size_t>(k)];
  if (b.pusher < 0) return Vec2(b.x, b.y);
  const Vec2 nrm(b.nx, b.ny);
  return Vec2(b.x, b.y) + nrm * (centre(y, b.pusher) - Vec2(b.px, b.py)).dot(nrm);
}

geom::Convex Arena::Impl::blockShape(const Discrete& d, int k, const double* y) const {
  const Block& b = d.blocks[static_cast<std::size_t>(k)];
  const Vec2 c = blockAt(d, k, y);
  // The width axis is the releasing robot's right, (cos h, -sin h); its
  // heading (sin h, cos h) is a turned a quarter counter-clockwise.
  const Vec2 a(b.ax, b.ay), f(-b.ay, b.ax);
  const Vec2 w = a * b.halfWidth, h = f * b.halfDepth;
  geom::Convex s;
  s.circle = false;
  s.c = c;
  s.n = 4;
  // Counter-clockwise: back-right, front-right, front-left, back-left;
  // edge k's outward normal: right, front, left, back.
  s.v[0] = c - h + w;
  s.v[1] = c + h + w;
  s.v[2] = c + h - w;
  s.v[3] = c - h - w;
  s.normal[0] = a;
  s.normal[1] = f;
  s.normal[2] = -a;
  s.normal[3] = -f;
  return s;
}

double Arena::Impl::blockGap(const Discrete& d, int i, int k, const double* y, Vec2* normal) const {
  return geom::signedDistance(centre(y, i), blockShape(d, k, y), normal) - radius(i);
}

Vec2 Arena::Impl::freeVelocityOf(const double* y, int i) const {
  const double* s = y + i * kPerRobot;
  const double sp = 0.5 * (s[VL] + s[VR]);
  return Vec2(sp * std::sin(s[H]), sp * std::cos(s[H]));
}

double Arena::Impl::blockRootValue(int who, const double* y) const {
  const int i = who / kMaxBlocks, k = who % kMaxBlocks;
  const Block& b = D.blocks[static_cast<std::size_t>(k)];
  if (b.pusher == i)
    return std::max(freeVelocityOf(y, i).dot(Vec2(b.nx, b.ny)), blockGap(D, i, k, y) - kPushSlipFt);
  if (D.r[static_cast<std::size_t>(i)].blockContact[static_cast<std::size_t>(k)])
    return contactG(contact::Kind::Obstacle, i, y, blockObstacle(k));
  return blockGap(D, i, k, y);
}

double Arena::Impl::blockStopValue(const Discrete& d, int k, const double* y) const {
  const Block& b = d.blocks[static_cast<std::size_t>(k)];
  const Vec2 nrm(b.nx, b.ny);
  return b.reach + (centre(y, b.pusher) - Vec2(b.px, b.py)).dot(nrm);
}

void Arena::Impl::refreshBlockShapes(const Discrete& d) {
  for (int k = 0; k < d.blockCount; ++k)
    if (d.blocks[static_cast<std::size_t>(k)].pusher < 0)
      bodies.obstacles[static_cast<std::size_t>(blockObstacle(k))] = blockShape(d, k, segY.data());
}

void Arena::Impl::applyPushes(const Discrete& d, double* v, double* a) const {
  for (int k = 0; k < d.blockCount; ++k) {
    const Block& b = d.blocks[static_cast<std::size_t>(k)];
    if (b.pusher < 0) continue;
    const int i = b.pusher;
    const double ratio = b.load / (P(i).mass_lb * P(i).wheel_friction);
    const Vec2 nrm(b.nx, b.ny);
    const double vn = v[kXY * i + X] * nrm.x() + v[kXY * i + Y] * nrm.y();
    if (vn >= 0) continue;
    v[kXY * i + X] -= ratio * vn * nrm.x();
    v[kXY * i + Y] -= ratio * vn * nrm.y();
    if (a) {
      const double an = a[kXY * i + X] * nrm.x() + a[kXY * i + Y] * nrm.y();
      a[kXY * i + X] -= ratio * an * nrm.x();
      a[kXY * i + Y] -= ratio * an * nrm.y();
    }
  }
}

double Arena::Impl::blockReach(const Discrete& d, int k, const Vec2& u, const double* y,
                               ContactWith& with, int& index) const {
  const geom::Convex b = blockShape(d, k, y);
  double best = HUGE_VAL;
  with = ContactWith::None;
  index = -1;
  // The field's edge (assumption: a block stays on the field, walls or not).
  for (int j = 0; j < b.n; ++j)
    for (int axis = 0; axis < 2; ++axis) {
      const double p = b.v[static_cast<std::size_t>(j)][axis], du = u[axis];
      const double s = du > 0 ? (half - p) / du : du < 0 ? (-half - p) / du : HUGE_VAL;
      if (s < best) {
        best = s;
        with = ContactWith::Wall;
      }
    }
  auto take = [&](double s, ContactWith w, int i) {
    if (s < best) {
      best = s;
      with = w;
      index = i;
    }
  };
  if (cfg.field.divider) take(sweep(b, u, rectShape(bodies.divider)), ContactWith::Divider, -1);
  for (int o = 0; o < bodies.obstacleCount; ++o)
    take(sweep(b, u, bodies.obstacles[static_cast<std::size_t>(o)]), ContactWith::Obstacle, o);
  for (int j = 0; j < d.blockCount; ++j)
    if (j != k) take(sweep(b, u, blockShape(d, j, y)), ContactWith::Block, j);
  return std::max(best, 0.0);
}

bool Arena::Impl::blockFits(const Discrete& d, const geom::Convex& s, const double* y) const {
  for (int j = 0; j < s.n; ++j)
    if (std::abs(s.v[static_cast<std::size_t>(j)].x()) > half ||
        std::abs(s.v[static_cast<std::size_t>(j)].y()) > half)
      return false;
  if (cfg.field.divider && overlaps(s, rectShape(bodies.divider))) return false;
  for (int o = 0; o < bodies.obstacleCount; ++o)
    if (overlaps(s, bodies.obstacles[static_cast<std::size_t>(o)])) return false;
  for (int j = 0; j < d.blockCount; ++j)
    if (overlaps(s, blockShape(d, j, y))) return false;
  for (int i = 0; i < nR; ++i)
    if (geom::signedDistance(centre(y, i), s, nullptr) < radius(i)) return false;
  return true;
}

// The ball's flight meets block k's footprint over [lo, hi] of its path
// from tFrom on (ballMeetsShape): below the block's height at lo or
// where it comes down through that height before hi.
void Arena::Impl::ballMeetsBlocks(Ball& b, const Discrete& d, const double* y, double tFrom) const {
  const double from = std::max(0.0, tFrom - b.t0);
  for (int k = 0; k < d.blockCount; ++k) {
    const double s =
        ballMeetsShape(b, blockShape(d, k, y), d.blocks[static_cast<std::size_t>(k)].height, from);
    if (b.t0 + s < b.meetT) {
      b.meetT = b.t0 + s;
      b.meetObstacle = blockObstacle(k);
    }
  }
}

void Arena::Impl::ballMeetings(Ball& b, const Discrete& d, const double* y, double tFrom) const {
  if (bodies.obstacleCount > 0) {
    ballMeetsObstacle(b);
  } else {
    b.meetObstacle = -1;
    b.meetT = HUGE_VAL;
  }
  if (d.blockCount > 0) ballMeetsBlocks(b, d, y, tFrom);
}

// Assumption: a flight sees a block where it stands when the flight
// starts, when the block is set down and when a push of it ends (a push
// moves a block at a robot's slowed speed, a ball flies at tens of ft/s).
void Arena::Impl::flightsSeeBlocks(Discrete& d, const double* y, double te) const {
  for (Ball& b : d.balls)
    if (b.active) ballMeetings(b, d, y, te);
  for (Disc& c : d.discs) {
    if (!c.active) continue;
    const double gone = discPath(c, te);
    const Vec2 u(c.ux, c.uy), p = Vec2(c.x0, c.y0) + gone * u;
    for (int k = 0; k < d.blockCount; ++k) {
      if (c.z > d.blocks[static_cast<std::size_t>(k)].height) continue;
      const double s = gone + geom::discPathToConvex(p, u, c.radius, blockShape(d, k, y));
      if (s < c.sEnd) {
        c.sEnd = s;
        c.end = MissReason::Block;
        c.obstacle = static_cast<std::int8_t>(k);
      }
    }
  }
}

void Arena::Impl::endPush(Discrete& d, int k, const double* y, double te, ContactWith with,
                          int index, EventList& ev) {
  Block& b = d.blocks[static_cast<std::size_t>(k)];
  const int i = b.pusher;
  // Stopped by what it met: exactly at its reach (the event's tick is at
  // most one tick's travel past the crossing).
  const bool reached = with != ContactWith::None && with != ContactWith::Robot;
  const Vec2 c = reached ? Vec2(Vec2(b.x, b.y) - b.reach * Vec2(b.nx, b.ny)) : blockAt(d, k, y);
  const double pushed = (c - Vec2(b.x, b.y)).norm();
  b.x = c.x();
  b.y = c.y();
  b.pusher = -1;
  b.reach = HUGE_VAL;
  d.r[static_cast<std::size_t>(i)].pushedFt += pushed;
  Event e{EventKind::PushEnd};
  e.robot = static_cast<std::int8_t>(i);
  e.ball = static_cast<std::int8_t>(k);
  e.x = c.x();
  e.y = c.y();
  e.z = pushed;
  e.with = with;
  e.obstacle = static_cast<std::int8_t>(
      with == ContactWith::Obstacle || with == ContactWith::Block ? index : -1);
  e.other = static_cast<std::int8_t>(with == ContactWith::Robot ? index : -1);
  ev.push(e);
  flightsSeeBlocks(d, y, te);
}

void Arena::Impl::blockContacts(std::int64_t T, double te, Discrete& d, std::vector<double>& y,
                                const int* found, EventList& ev) {
  if (d.blockCount == 0) return;
  const double* ys = y.data();
  // Pushes that end here: their robots' contacts are decided with them.
  std::array<int, kMaxBlocks> ended{};
  ended.fill(-1);
  for (int k = 0; k < d.blockCount; ++k) {
    Block& b = d.blocks[static_cast<std::size_t>(k)];
    if (b.pusher < 0) continue;
    const int i = b.pusher;
    const int who = blockRoot(i, k);
    ended[static_cast<std::size_t>(k)] = i;
    if (reported(found, RootKind::BlockStop, k) < 0 || blockStopValue(d, k, ys) <= 0) {
      // The block stands at what stopped it: the robot meets a fixed box.
      endPush(d, k, ys, te, b.stopWith, b.stopIndex, ev);
      meetBlock(d, y, i, k, T, ev);
      continue;
    }
    const int rep = reported(found, RootKind::Block, who);
    const double g =
        std::max(freeVelocityOf(ys, i).dot(Vec2(b.nx, b.ny)), blockGap(d, i, k, ys) - kPushSlipFt);
    if (rep != 0 ? rep < 0 : sided(RootKind::Block, who, g) < 0) {
      ended[static_cast<std::size_t>(k)] = -1;
      continue;
    }
    // The robot no longer drives into the block or has slid off it: the
    // block rests and the robot is free of it (no contact); driving into it
    // again is a new meeting, pushed or met as a fixed box.
    endPush(d, k, ys, te, ContactWith::None, -1, ev);
  }
  for (int i = 0; i < nR; ++i) {
    RobotDisc& r = d.r[static_cast<std::size_t>(i)];
    for (int k = 0; k < d.blockCount; ++k) {
      Block& b = d.blocks[static_cast<std::size_t>(k)];
      // Its push's robot: decided above, or pushing on.
      if (b.pusher == i || ended[static_cast<std::size_t>(k)] == i) continue;
      const int who = blockRoot(i, k);
      bool& touching = r.blockContact[static_cast<std::size_t>(k)];
      const int rep = reported(found, RootKind::Block, who);
      const bool c =
          rep != 0 ? rep < 0
                   : sided(RootKind::Block, who,
                           touching ? contactG(contact::Kind::Obstacle, i, ys, blockObstacle(k))
                                    : blockGap(d, i, k, ys)) < 0;
      if (c == touching) continue;
      if (!c) {
        Event e{EventKind::ContactEnd};
        e.robot = static_cast<std::int8_t>(i);
        e.with = ContactWith::Block;
        e.obstacle = static_cast<std::int8_t>(k);
        touching = false;
        ev.push(e);
        continue;
      }
      if (b.pusher >= 0) {
        // The other robot touches a block being pushed: it holds it, and
        // both meet it as a fixed box.
        const int pusher = b.pusher;
        meetBlock(d, y, i, k, T, ev);
        endPush(d, k, ys, te, ContactWith::Robot, i, ev);
        meetBlock(d, y, pusher, k, T, ev);
        ended[static_cast<std::size_t>(k)] = pusher;
        continue;
      }
      if (!startPush(d, ys, i, k, ev)) meetBlock(d, y, i, k, T, ev);
    }
  }
}

void Arena::Impl::meetBlock(Discrete& d, std::vector<double>& y, int i, int k, std::int64_t T,
                            EventList& ev) {
  Event e{EventKind::Contact};
  e.robot = static_cast<std::int8_t>(i);
  e.with = ContactWith::Block;
  e.obstacle = static_cast<std::int8_t>(k);
  d.r[static_cast<std::size_t>(i)].blockContact[static_cast<std::size_t>(k)] = true;
  Vec2 normal;
  blockGap(d, i, k, y.data(), &normal);
  e.bumper = sideOf(heading(y.data(), i), -normal);
  ev.push(e);
  startReflex(d, y, i, e.bumper, T, ev);
}

bool Arena::Impl::startPush(Discrete& d, const double* ys, int i, int k, EventList& ev) const {
  Block& b = d.blocks[static_cast<std::size_t>(k)];
  Vec2 normal;
  blockGap(d, i, k, ys, &normal);
  // The robot's speed as the next segment starts: the wheels' targets at
  // once without a motor lag, else the speed they have now.
  const RobotParams& p = P(i);
  const std::array<double, 2> wt = wheelTargetsOf(d, i);
  const double sp = p.motor_lag_s <= 0 ? 0.5 * (wt[0] + wt[1])
                                       : 0.5 * (ys[i * kPerRobot + VL] + ys[i * kPerRobot + VR]);
  const double into = sp * geom::headingDir(heading(ys, i)).dot(normal);
  const bool heldByOther =
      nR == 2 && d.r[static_cast<std::size_t>(1 - i)].blockContact[static_cast<std::size_t>(k)];
  if (!(p.mass_lb * p.wheel_friction > b.load) || heldByOther || !(into < 0)) return false;
  ContactWith with = ContactWith::None;
  int index = -1;
  const double reach = blockReach(d, k, -normal, ys, with, index);
  if (!(reach > kMinReachFt)) return false;
  b.pusher = i;
  b.nx = normal.x();
  b.ny = normal.y();
  b.px = ys[i * kPerRobot + X];
  b.py = ys[i * kPerRobot + Y];
  b.reach = reach;
  b.stopWith = with;
  b.stopIndex = index;
  Event s{EventKind::PushStart};
  s.robot = static_cast<std::int8_t>(i);
  s.ball = static_cast<std::int8_t>(k);
  s.x = b.x;
  s.y = b.y;
  s.vx = b.px;  // the pusher's centre (plant.h Event)
  s.vy = b.py;
  ev.push(s);
  return true;
}

}  // namespace simbot::plant
