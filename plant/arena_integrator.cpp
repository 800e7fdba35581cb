// plant/arena_integrator.cpp -- ARKODE and dense output for the arena.
//
// Set-up of the integrator, the right-hand side (closed-form wheels, the
// contacts' projection), the reset at a discontinuity, the dense output
// records kept per step, and the stepping loop (advance, predict, retreat,
// commit) whose independence from the caller's stops arena.cpp's header
// comment ("Stepping", "Dense output") argues.
#include <cstring>

#include "plant/arena_impl.h"

namespace simbot::plant {

namespace {

// ARKODE's tolerances on x and y: absolute (ft) and relative. Against the
// exact motion (closed-form heading, Boost.Math quadrature of x and y;
// tests/plant/tolerance_test.cpp) the arcs, spins and straight runs of the
// default profile stay within 1e-9 ft over 10 s, 1/380 of the 3.8e-7 ft a
// point at top speed moves in a tick; at 1e-9 the straight run is 2.0e-9
// ft off. The relative one is ten times smaller because the centres sit
// up to 7.5 ft from the origin: at 3e-10 it let a whole match drift 8.2e-9
// ft from the exact motion and put 2 of its 139 root events a tick off
// (tests/plant/match_oracle_test.cpp); at 3e-11 the drift was 1.4e-9 ft.
// Since each reset starts the step controller afresh (reinit), which lets
// steps grow sooner, the absolute one is 1e-10: the match drifts 9.7e-10
// ft (3.2e-9 at 3e-10), in 10,672 steps (11,057 with the old controller
// and 3e-10).
constexpr double kAbsoluteTolerance = 1e-10;  // ft
constexpr double kRelativeTolerance = 3e-11;
// Step of the central difference that gives the curvature of x and y while
// a contact whose normal turns is active (the other robot, the divider's
// corner): its error, about 1e-9 ft/s^2, enters the quintic times h^2/120.
constexpr double kCurvatureStep = 1e-6;  // s
// The step while nothing moves: nothing can cross, but an unbounded step
// grows without limit (to 1e153 s in a port-B flood) and the step that
// the next reset keeps would then be meaningless.
constexpr double kRestStep = 10;  // s

}  // namespace

Arena::Impl::Impl(const ArenaConfig& c)
    : cfg(c),
      nR(static_cast<int>(c.robots.size())),
      n(kPerRobot * static_cast<int>(c.robots.size())),
      nx(kXY * static_cast<int>(c.robots.size())),
      ode(kXY * static_cast<int>(c.robots.size()), &Impl::rhsThunk, this) {
  if (nR < 1 || nR > 2) throw std::invalid_argument("Arena: 1 or 2 robots");
  half = cfg.field.size_ft / 2;
  wireHalf = half - cfg.field.wire_inset_ft;
  bodies.robots = nR;
  bodies.half = half;
  bodies.divider = geom::dividerRect(cfg.field);
  if (cfg.field.obstacles.size() > static_cast<std::size_t>(kMaxObstacles))
    throw std::invalid_argument("Arena: more than " + std::to_string(kMaxObstacles) + " obstacles");
  for (const Obstacle& o : cfg.field.obstacles) {
    if (o.kind != Obstacle::Kind::Circle &&
        (o.points.size() < 3 || o.points.size() > static_cast<std::size_t>(kMaxObstacleVertices)))
      throw std::invalid_argument("Arena: an obstacle's polygon has 3 to " +
                                  std::to_string(kMaxObstacleVertices) + " vertices");
    bodies.obstacles[static_cast<std::size_t>(bodies.obstacleCount++)] = geom::convexOf(o);
  }
  double massSum = 0;
  for (int i = 0; i < nR; ++i) massSum += P(i).mass_lb;
  for (int i = 0; i < nR; ++i) {
    bodies.radius[static_cast<std::size_t>(i)] = radius(i);
    bodies.invMass[static_cast<std::size_t>(i)] = massSum / nR / P(i).mass_lb;
  }
  pendingY.assign(static_cast<std::size_t>(n), 0.0);
  tmp.assign(static_cast<std::size_t>(n), 0.0);
  qtmp.assign(static_cast<std::size_t>(n), 0.0);
  rootY.assign(static_cast<std::size_t>(n), 0.0);
  blockY.assign(static_cast<std::size_t>(n), 0.0);
  segY.assign(static_cast<std::size_t>(n), 0.0);
  endY.assign(static_cast<std::size_t>(nx), 0.0);
  endF.assign(static_cast<std::size_t>(nx), 0.0);
  endA.assign(static_cast<std::size_t>(nx), 0.0);
  rootsFound.assign(kMaxRoots, 0);
  heldFound.assign(kMaxRoots, 0);
  pendingFound.assign(kMaxRoots, 0);
  recs.reserve(1024);
  coef.reserve(static_cast<std::size_t>(1024 * 6 * nx));

  std::vector<double>& y = tmp;
  for (int i = 0; i < nR; ++i) {
    const RobotSetup& rs = cfg.robots[static_cast<std::size_t>(i)];
    double* r = y.data() + i * kPerRobot;
    r[X] = rs.start.x_ft;
    r[Y] = rs.start.y_ft;
    r[H] = geom::degToRad(rs.start.heading_deg);
    r[VL] = r[VR] = r[S] = r[G1] = r[G2] = 0;
    RobotDisc& d = D.r[static_cast<std::size_t>(i)];
    d.latched = MotorFrame{};  // stopped until the first frame latches
    d.ballsLeft = {rs.params.balls_per_gun, rs.params.balls_per_gun};
    if (rs.hardware.secondary.kind == SecondaryKind::Disc)
      d.discsLeft = rs.hardware.secondary.magazine;
    int blocks = 0;
    for (std::size_t k = 0; k < rs.hardware.deployables.size() && k < kMaxDeployKinds; ++k) {
      deployLeft[static_cast<std::size_t>(i)][k] = rs.hardware.deployables[k].count;
      if (rs.hardware.deployables[k].kind == DeployKind::Block)
        blocks += rs.hardware.deployables[k].count;
    }
    if (blocks > kMaxBlocksPerRobot)
      throw std::invalid_argument("Arena: more than " + std::to_string(kMaxBlocksPerRobot) +
                                  " blocks on one robot");
    if (!rs.hardware.deployables.empty())
      eyeItems.reserve(static_cast<std::size_t>(2 * kMaxDeployKinds * kMaxDeployCount));
  }
  // Initial flags from geometry, silently (nothing has happened yet): a
  // body put down touching something starts in contact with it.
  for (int i = 0; i < nR; ++i) {
    RobotDisc& d = D.r[static_cast<std::size_t>(i)];
    for (int k = 0; k < 2; ++k) {
      d.edgeLow[static_cast<std::size_t>(k)] = edgeG(y.data(), i, k) < 0;
      d.wallContact[static_cast<std::size_t>(k)] =
          cfg.field.field_walls &&
          gapOf(k == 0 ? contact::Kind::WallX : contact::Kind::WallY, i, y.data()) <= 0;
    }
    d.dividerContact = cfg.field.divider && gapOf(contact::Kind::Divider, i, y.data()) <= 0;
    for (int k = 0; k < bodies.obstacleCount; ++k)
      d.obstacleContact[static_cast<std::size_t>(k)] =
          gapOf(contact::Kind::Obstacle, i, y.data(), k) <= 0;
  }
  D.robotContact = nR == 2 && gapOf(contact::Kind::Robot, 0, y.data()) <= 0;

  // Dormand-Prince 5(4): the fifth-order pair with the smallest error
  // constants ARKODE ships, its last stage reused as the next step's first.
  ode.useDormandPrince745();
  ode.setTolerances(kRelativeTolerance, kAbsoluteTolerance);
  // ARKODE's root finder locates a crossing on its own interpolant, the
  // quartic Hermite it uses with a fifth-order table (one more right-hand
  // side, only in a step with a sign change); crossedTick() then decides
  // the tick from the quintic dense output below.
  ode.setMaxNumSteps(100000);
  // ARKODE's own messages are silenced (arkode.cpp): a failure is reported
  // as the run's plant fault instead (SolverError).
  reinit(0, 0.0, tmp, /*first=*/true);
}

// The fastest any point of any robot can move (ft/s): the top of the speed
// table with the larger trim, plus the spin of the body's edge.
double Arena::Impl::pointSpeed() const {
  double best = 0;
  for (int i = 0; i < nR; ++i) {
    const RobotParams& p = P(i);
    double v = 0;
    for (double s : p.speed_table_fps) v = std::max(v, s);
    v *= std::max(p.left_trim, p.right_trim);
    const Motion& m = motion[static_cast<std::size_t>(i)];
    v = std::max({v, std::abs(m.tl), std::abs(m.tr), std::abs(m.vl0), std::abs(m.vr0)});
    const double omega = 2 * v / p.track_ft;
    best = std::max(best, v + omega * radius(i));
  }
  return best;
}

// Root finding only sees sign changes between step ends. The step never
// lets a point of a robot move more than 1 inch relative to another body
// (the guarantee CVODE's plant gave), and beyond that no farther than the
// nearest root function is from zero: no edge, wall, divider or robot can
// then be crossed and left again unseen inside a step. ARKODE chooses a
// step's size at the end of the step before it, so a bound set after step
// k applies from step k + 2: it is the distance at the end of step k less
// what step k + 1, already planned (`ahead`), can move.
// With no contact active the contacts' root functions are their gaps, so
// a root evaluation at y (`raw`) already holds every distance; each is
// read where buildRoots() put it, checked against the list.
double Arena::Impl::stepBound(const double* y, double ahead, const double* raw) const {
  const double v = segSpeed;
  if (v <= 0) return kRestStep;  // nothing can move
  const double floor = (1.0 / 12.0) / (nR * v);
  if (active.count > 0) return floor;
  const auto dist = [&](int j, RootKind k, int who, auto compute) {
    if (!raw) return std::abs(compute());
    if (j < 0 || j >= nRoots || roots[static_cast<std::size_t>(j)].kind != k ||
        roots[static_cast<std::size_t>(j)].robot != who)
      throw std::logic_error("plant: stepBound read the wrong root function");
    return std::abs(raw[j]);
  };
  double d = HUGE_VAL;
  for (int i = 0; i < nR; ++i) {
    const BoundRoots& at = boundRoots[static_cast<std::size_t>(i)];
    d = std::min({d, dist(at.edge[0], RootKind::EdgeFore, i, [&] { return edgeG(y, i, 0); }),
                  dist(at.edge[1], RootKind::EdgeAft, i, [&] { return edgeG(y, i, 1); })});
    if (cfg.field.divider)
      d = std::min(d, dist(at.divider, RootKind::Divider, i,
                           [&] { return gapOf(contact::Kind::Divider, i, y); }));
    for (int k = 0; k < bodies.obstacleCount; ++k)
      d = std::min(d, dist(at.obstacle0 + k, RootKind::Obstacle, obstacleRoot(i, k),
                           [&] { return gapOf(contact::Kind::Obstacle, i, y, k); }));
    if (cfg.field.field_walls)
      d = std::min(
          {d,
           dist(at.wall[0], RootKind::WallX, i, [&] { return gapOf(contact::Kind::WallX, i, y); }),
           dist(at.wall[1], RootKind::WallY, i,
                [&] { return gapOf(contact::Kind::WallY, i, y); })});
    else
      d = std::min(d, dist(at.out, RootKind::OutOfField, i, [&] { return outG(y, i); }));
  }
  if (nR == 2)
    d = std::min(d, dist(robotPairRoot, RootKind::RobotRobot, 0, [&] {
                      return gapOf(contact::Kind::Robot, 0, y);
                    }) / 2);
  return std::max(floor, d / v - ahead);
}

// Every wheel and its target at rest and no ball or disc in flight: the state and
// every root function are then constant until the next reset (nothing
// changes the right-hand side without one), so no crossing can hide inside
// a step and only kRestStep bounds it.
bool Arena::Impl::atRest() const {
  if (D.inFlight > 0) return false;
  for (int i = 0; i < nR; ++i) {
    const Motion& m = motion[static_cast<std::size_t>(i)];
    if (m.vl0 != 0 || m.vr0 != 0 || m.tl != 0 || m.tr != 0) return false;
  }
  return true;
}

void Arena::Impl::freeVelocities(double t, double* v, double* a) const {
  for (int i = 0; i < nR; ++i) {
    const Motion& m = motion[static_cast<std::size_t>(i)];
    const Motion::At w = m.at(t, wheelLag);
    const double sp = 0.5 * (w.vl + w.vr);
    const Vec2 dir = headingDirOf(i, w.h);
    const double sh = dir.x(), ch = dir.y();
    v[kXY * i + X] = sp * sh;
    v[kXY * i + Y] = sp * ch;
    if (a) {
      const double omega = (w.vl - w.vr) / m.track;  // clockwise when the left wheel is faster
      a[kXY * i + X] = w.dv * sh + sp * omega * ch;
      a[kXY * i + Y] = w.dv * ch - sp * omega * sh;
    }
  }
}

void Arena::Impl::rhs(double t, const double* xy, double* f, double* accel) const {
  freeVelocities(t, f, accel);
  if (segPushes) applyPushes(D, f, accel);
  if (active.count == 0) return;
  contact::project(bodies, active, xy, f, f);
  if (!accel) return;
  if (!active.turning()) {
    // Fixed normals: the projection is a constant linear map, so it maps
    // the free curvature to the constrained one.
    contact::project(bodies, active, xy, accel, accel);
    return;
  }
  // Normals that turn with the bodies: the derivative along the path by a
  // central difference of the right-hand side.
  std::array<double, 2 * kXY> qp{}, qm{}, fp{}, fm{};
  for (int j = 0; j < nx; ++j) {
    qp[static_cast<std::size_t>(j)] = xy[j] + kCurvatureStep * f[j];
    qm[static_cast<std::size_t>(j)] = xy[j] - kCurvatureStep * f[j];
  }
  rhs(t + kCurvatureStep, qp.data(), fp.data());
  rhs(t - kCurvatureStep, qm.data(), fm.data());
  for (int j = 0; j < nx; ++j)
    accel[j] =
        (fp[static_cast<std::size_t>(j)] - fm[static_cast<std::size_t>(j)]) / (2 * kCurvatureStep);
}

void Arena::Impl::fullState(double t, const double* xy, double* out) const {
  for (int i = 0; i < nR; ++i) {
    const Motion& m = motion[static_cast<std::size_t>(i)];
    const Motion::At w = m.at(t, wheelLag);
    double* r = out + i * kPerRobot;
    r[X] = xy[kXY * i + X];
    r[Y] = xy[kXY * i + Y];
    r[H] = w.h;
    r[VL] = w.vl;
    r[VR] = w.vr;
    r[S] = w.s;
    r[G1] = m.gun(0, t, gunLag);
    r[G2] = m.gun(1, t, gunLag);
  }
}

// ------------------------------------------------------------ targets and
// reset
std::array<double, 2> Arena::Impl::wheelTargetsOf(const Discrete& d, int i) const {
  const RobotParams& p = P(i);
  const RobotDisc& r = d.r[static_cast<std::size_t>(i)];
  std::array<double, 2> wt{};
  if (r.reflex) {
    WheelCommand c{p.reflex_speed_step, r.reflexSide == Bumper::Back, true, '0'};
    wt[0] = wheelSpeedFps(c, p, true);
    wt[1] = wheelSpeedFps(c, p, false);
  } else if (r.driven) {
    wt = r.drive;
  } else {
    wt[0] = wheelSpeedFps(r.latched.left, p, true);
    wt[1] = wheelSpeedFps(r.latched.right, p, false);
  }
  // A battery's voltage (setSupply); without one the targets stay as
  // they are, bit for bit.
  if (r.supply != 1) {
    wt[0] *= r.supply;
    wt[1] *= r.supply;
  }
  return wt;
}

void Arena::Impl::computeTargets(const Discrete& d) {
  for (int i = 0; i < nR; ++i) {
    const RobotParams& p = P(i);
    const RobotDisc& r = d.r[static_cast<std::size_t>(i)];
    wheelTarget[static_cast<std::size_t>(i)] = wheelTargetsOf(d, i);
    auto& gt = gunTarget[static_cast<std::size_t>(i)];
    gt[0] = r.gunOn[0] || p.gun_motors_always_on ? 1.0 : 0.0;
    gt[1] = r.gunOn[1] || p.gun_motors_always_on ? 1.0 : 0.0;
    if (r.supply != 1) {
      gt[0] *= r.supply;
      gt[1] *= r.supply;
    }
  }
}

// Zero time constants: the state jumps to its target.
void Arena::Impl::applyJumps(std::vector<double>& y) const {
  for (int i = 0; i < nR; ++i) {
    const RobotParams& p = P(i);
    double* r = y.data() + i * kPerRobot;
    if (p.motor_lag_s <= 0) {
      r[VL] = wheelTarget[static_cast<std::size_t>(i)][0];
      r[VR] = wheelTarget[static_cast<std::size_t>(i)][1];
    }
    for (int g = 0; g < 2; ++g) {
      const double target = gunTarget[static_cast<std::size_t>(i)][static_cast<std::size_t>(g)];
      if (gunTau(p, target) <= 0) r[G1 + g] = target;
    }
  }
}

void Arena::Impl::setMotion(double t0, const std::vector<double>& y) {
  for (int i = 0; i < nR; ++i) {
    const RobotParams& p = P(i);
    const double* r = y.data() + i * kPerRobot;
    Motion& m = motion[static_cast<std::size_t>(i)];
    m.t0 = t0;
    m.h0 = r[H];
    m.s0 = r[S];
    m.vl0 = r[VL];
    m.vr0 = r[VR];
    m.tl = wheelTarget[static_cast<std::size_t>(i)][0];
    m.tr = wheelTarget[static_cast<std::size_t>(i)][1];
    m.tau = p.motor_lag_s;
    m.track = p.track_ft;
    for (int g = 0; g < 2; ++g) {
      const auto k = static_cast<std::size_t>(g);
      m.g0[k] = r[G1 + g];
      m.gt[k] = gunTarget[static_cast<std::size_t>(i)][k];
      m.gtau[k] = gunTau(p, m.gt[k]);
    }
  }
}

// The contacts that push in this segment: of those the discrete state says
// are touching, the largest set whose forces are all positive at the
// segment's start (after the wheels' jumps), or zero and growing (a robot
// at rest against a wall that starts to drive into it: its speed, and so
// the force, is 0 at the start). The solve is repeated without the
// weakest force until none is left out. A touching contact left out (its
// body already moves away: an instant reflex, a new frame with no motor
// lag) ends when its gap opens (contactG).
void Arena::Impl::setActive(const Discrete& d) {
  segPushes = false;
  if (d.blockCount > 0) {
    refreshBlockShapes(d);
    for (int k = 0; k < d.blockCount; ++k)
      segPushes = segPushes || d.blocks[static_cast<std::size_t>(k)].pusher >= 0;
  }
  contact::Active cand;
  auto add = [&](contact::Kind k, int i) {
    cand.c[static_cast<std::size_t>(cand.count++)] = contact::Constraint{k, i};
  };
  for (int i = 0; i < nR; ++i) {
    const RobotDisc& r = d.r[static_cast<std::size_t>(i)];
    if (r.wallContact[0]) add(contact::Kind::WallX, i);
    if (r.wallContact[1]) add(contact::Kind::WallY, i);
    if (r.dividerContact) add(contact::Kind::Divider, i);
    int touching = 0;
    for (int k = 0; k < bodies.obstacleCount; ++k) {
      if (!r.obstacleContact[static_cast<std::size_t>(k)]) continue;
      // The constraint table is fixed (no allocation in the step): a body
      // wedged among more obstacles than it holds ends the run.
      if (++touching > kMaxObstacleContacts)
        throw SolverError("plant: robot " + std::string(1, static_cast<char>('A' + i)) +
                          " touches more than " + std::to_string(kMaxObstacleContacts) +
                          " obstacles at once");
      cand.c[static_cast<std::size_t>(cand.count++)] =
          contact::Constraint{contact::Kind::Obstacle, i, k};
    }
    // A block touched and not pushed by this robot: a fixed box, counted
    // with the obstacles.
    for (int k = 0; k < d.blockCount; ++k) {
      if (!r.blockContact[static_cast<std::size_t>(k)] ||
          d.blocks[static_cast<std::size_t>(k)].pusher == i)
        continue;
      if (++touching > kMaxObstacleContacts)
        throw SolverError("plant: robot " + std::string(1, static_cast<char>('A' + i)) +
                          " touches more than " + std::to_string(kMaxObstacleContacts) +
                          " obstacles and blocks at once");
      cand.c[static_cast<std::size_t>(cand.count++)] =
          contact::Constraint{contact::Kind::Obstacle, i, blockObstacle(k)};
    }
  }
  if (nR == 2 && d.robotContact) add(contact::Kind::Robot, 0);
  active = cand;
  if (cand.count == 0) return;
  std::array<double, 2 * kXY> xy{}, v{}, vf{}, af{};
  centresOf(segY.data(), xy.data());
  freeVelocities(segT0, vf.data(), af.data());
  if (segPushes) applyPushes(d, vf.data(), af.data());
  // A force this small is zero: round-off of speeds of order 1 ft/s.
  constexpr double kZeroForce = 1e-12;  // ft/s
  for (;;) {
    std::array<double, contact::kMaxActive> mu{}, dmu{};
    contact::project(bodies, active, xy.data(), vf.data(), v.data(), mu.data());
    contact::project(bodies, active, xy.data(), af.data(), v.data(), dmu.data());
    int worst = -1;
    auto weaker = [&](int a, int b) {
      const auto ka = static_cast<std::size_t>(a), kb = static_cast<std::size_t>(b);
      return mu[ka] != mu[kb] ? mu[ka] < mu[kb] : dmu[ka] < dmu[kb];
    };
    for (int j = 0; j < active.count; ++j) {
      const auto k = static_cast<std::size_t>(j);
      const bool pushes = mu[k] > kZeroForce || (mu[k] >= -kZeroForce && dmu[k] > 0);
      if (!pushes && (worst < 0 || weaker(j, worst))) worst = j;
    }
    if (worst < 0) break;
    for (int j = worst; j + 1 < active.count; ++j)
      active.c[static_cast<std::size_t>(j)] = active.c[static_cast<std::size_t>(j + 1)];
    if (--active.count == 0) break;
  }
}

void Arena::Impl::setMaxStep(double h) {
  if (h == maxStepSet) return;
  ode.setMaxStep(h);
  maxStepSet = h;
}

// (Re)starts the integration at tick `tick`, time t0, from state y, under
// the dynamics the discrete state D now selects.
void Arena::Impl::reinit(std::int64_t tick, double t0, std::vector<double>& y, bool first) {
  rootRawValid = false;
  computeTargets(D);
  applyJumps(y);
  // A reset at the tick of the last one, before any step, that leaves the
  // state and everything the right-hand side reads as they were: ARKODE is
  // already exactly where a reset would put it, so none is made. The root
  // set and stop time are rebuilt below as always.
  const bool same = fresh && tick == segTick && t0 == segT0 && wheelTarget == segWheel &&
                    gunTarget == segGun &&
                    std::memcmp(y.data(), segY.data(), y.size() * sizeof(double)) == 0;
  std::copy(y.begin(), y.end(), segY.begin());
  segTick = tick;
  segT0 = t0;
  setMotion(t0, y);
  segSpeed = pointSpeed();
  segRest = atRest();
  setActive(D);
  double* xy = ode.data(ark::Buffer::State);
  centresOf(y.data(), xy);
  if (!same) {
    const bool steppedSinceReset = !fresh;
    if (!first) {
      ++acc.reinits;
      clearRootFlag();
    }
    // The flag of a root at ARKODE's last return outlives the reset.
    rootFlagCarried = lastRoot || (!steppedSinceReset && rootFlagCarried);
    ode.reset(t0);
  }
  ++reinitSerial;
  fresh = true;
  segWheel = wheelTarget;
  segGun = gunTarget;
  // The new segment starts with the step ARKODE reported as its next after
  // the step that holds t0 (Rec::next; a one-step method restarts for free), within half the
  // distance to the nearest feature, and with its step controller afresh:
  // setting the initial step clears the error history that a reset keeps.
  // Both then depend on the steps up to t0 alone, never on steps taken past
  // it, which a caller that chops time otherwise may not have taken.
  const double bound = segRest ? kRestStep : 0.5 * stepBound(y.data(), 0.0);
  setMaxStep(bound);
  double initial = 0;
  if (!first) {
    const double planned = recordAt(t0).next;
    initial = planned > 0 ? std::min(planned, bound) : 0.0;
    ode.setInitStep(initial);
  }
  buildRoots();
  sideRoots(t0, y);
  if (nRoots != nRootsRegistered) {
    ode.setRoots(nRoots, &Impl::rootThunk);
    nRootsRegistered = nRoots;
  }
  now = tick;
  tReturned = t0;
  tStepEnd = t0;
  held = false;
  lastRoot = false;
  // The only discontinuity known in advance: the next ball launch. ARKODE
  // must not step across it; a stop time from the last segment (a launch
  // this reset came before) is moved out of reach.
  const std::int64_t nl = nextLaunch();
  if (nl > tick) {
    ode.setStopTime(secondsFromTick(nl));
    launchStop = nl;
  } else if (launchStop >= 0) {
    // Without a reset (nothing that moves changed) the old one is still
    // armed: it is moved out of reach, as every version allows (ARKODE
    // 6.4 has no call that clears it).
    ode.setStopTime(kNoStopTime);
    launchStop = -1;
  }
  recs.clear();
  coef.clear();
  // The segment's first record: the state at t0 alone.
  recs.push_back(Rec{t0, t0, 0, initial});
  for (int j = 0; j < nx; ++j) {
    coef.push_back(xy[j]);
    for (int k = 1; k < 6; ++k) coef.push_back(0.0);
    endY[static_cast<std::size_t>(j)] = xy[j];
  }
  rhs(t0, endY.data(), endF.data(), endA.data());
  ownRhs += active.turning() ? 3 : 1;
}

// ARKODE 6.4 keeps the flag of a root found at its last return across a
// reset (only a later return clears it), and while it is set every step
// evaluates all root functions once more, with an interpolation that costs
// a right-hand side. Before a reset that follows a root, the rest of that
// step is looked at (no new step is taken): that return clears it. The
// discrete state has already changed, so the root functions read as a
// constant 1 for it (no crossing, no zero; the reset follows).
void Arena::Impl::clearRootFlag() {
  if (!lastRoot || tReturned >= tStepEnd) return;
  rootsMuted = true;
  double tr = 0;
  try {
    ode.step(tStepEnd + kFirstStepHorizon, ark::Buffer::Scratch, tr);
  } catch (...) {
    rootsMuted = false;
    throw;
  }
  rootsMuted = false;
  lastRoot = false;
}

// ------------------------------------------------------------ dense output
// Each step [t0, t1] of ARKODE gets the quintic Hermite polynomial of x and
// y matching their values, slopes and curvatures at both ends (slope from
// the right-hand side, curvature its time derivative, from the closed
// forms): the polynomial is exact to O(h^6), where ARKODE's cubic is
// O(h^4) and put event ticks one off. With s = (t - t0), h = t1 - t0 and
// A, B, C the mismatches of the quadratic Taylor part at t1 in value,
// h * slope and h^2 * curvature, the coefficients of s^3..s^5 (times h^k)
// are 10A - 4B + C/2, -15A + 7B - C, 6A - 3B + C/2.
void Arena::Impl::recordStep(double tn, const double* ynew) {
  const Rec& last = recs.back();
  const double t0 = last.thi;
  const double h = tn - t0;
  Rec r{t0, tn, coef.size()};
  std::array<double, 2 * kXY> f1{}, a1{};
  rhs(tn, ynew, f1.data(), a1.data());
  ownRhs += active.turning() ? 3 : 1;
  for (int j = 0; j < nx; ++j) {
    const auto k = static_cast<std::size_t>(j);
    const double c0 = endY[k], c1 = h * endF[k], c2 = 0.5 * h * h * endA[k];
    const double A = ynew[j] - c0 - c1 - c2;
    const double B = h * f1[k] - c1 - 2 * c2;
    const double C = h * h * a1[k] - 2 * c2;
    const double c3 = 10 * A - 4 * B + 0.5 * C;
    const double c4 = -15 * A + 7 * B - C;
    const double c5 = 6 * A - 3 * B + 0.5 * C;
    const double h2 = h * h, h3 = h2 * h;
    coef.push_back(c0);
    coef.push_back(endF[k]);
    coef.push_back(0.5 * endA[k]);
    coef.push_back(c3 / h3);
    coef.push_back(c4 / (h3 * h));
    coef.push_back(c5 / (h3 * h2));
    endY[k] = ynew[j];
    endF[k] = f1[k];
    endA[k] = a1[k];
  }
  recs.push_back(r);
}

// First record whose interval reaches t; past the end, the last one
// (advance() steps until ARKODE has returned a time at or past now(), so
// at most a rounding of the tick's time).
// The record found last is tried first (the eyes' poses and the trace's
// samples come in time order, mostly within one step): it is the answer
// exactly when it reaches t and the one before it does not.
const Arena::Impl::Rec& Arena::Impl::recordAt(double t) const {
  const std::size_t h = recordHint;
  if (h < recs.size() && recs[h].thi >= t && (h == 0 || recs[h - 1].thi < t)) return recs[h];
  auto it = std::lower_bound(recs.begin(), recs.end(), t,
                             [](const Rec& r, double tt) { return r.thi < tt; });
  if (it == recs.end()) --it;
  recordHint = static_cast<std::size_t>(it - recs.begin());
  return *it;
}

// Component i (of x, y) of the dense output polynomial of record r at t.
double Arena::Impl::component(const Rec& r, double t, int i) const {
  const double s = t - r.tlo;
  const double* c = coef.data() + r.off + static_cast<std::size_t>(6 * i);
  return c[0] + s * (c[1] + s * (c[2] + s * (c[3] + s * (c[4] + s * c[5]))));
}

void Arena::Impl::evalAt(double t, std::vector<double>& out) const {
  const Rec& r = recordAt(t);
  std::array<double, 2 * kXY> xy{};
  for (int j = 0; j < nx; ++j) xy[static_cast<std::size_t>(j)] = component(r, t, j);
  fullState(t, xy.data(), out.data());
}

[[gnu::always_inline]] inline std::array<double, 3> Arena::Impl::pendingPose(int robot) const {
  const int base = robot * kPerRobot;
  return {pendingY[static_cast<std::size_t>(base + X)],
          pendingY[static_cast<std::size_t>(base + Y)],
          pendingY[static_cast<std::size_t>(base + H)]};
}

[[gnu::always_inline]] inline std::array<double, 3> Arena::Impl::poseIn(const Rec& r, double t,
                                                                        int robot) const {
  return {component(r, t, kXY * robot + X), component(r, t, kXY * robot + Y),
          motion[static_cast<std::size_t>(robot)].at(t, wheelLag).h};
}

// One robot's x, y and heading (rad) at a tick: what the eyes need, at a
// fraction of evaluating the whole state. Same arithmetic, same bits.
std::array<double, 3> Arena::Impl::poseAt(int robot, std::int64_t tick) const {
  checkQueryTick(tick);
  if (pending && tick == pendingTick) return pendingPose(robot);
  const double t = timeOfTick(tick);
  return poseIn(recordAt(t), t, robot);
}

std::array<std::array<double, 3>, 2> Arena::Impl::posesAt(std::int64_t tick) const {
  checkQueryTick(tick);
  if (pending && tick == pendingTick) return {pendingPose(0), pendingPose(1)};
  const double t = timeOfTick(tick);
  const Rec& r = recordAt(t);
  return {poseIn(r, t, 0), poseIn(r, t, 1)};
}

// State at a tick (after the events of that tick).
void Arena::Impl::stateAt(std::int64_t tick, std::vector<double>& out) const {
  checkQueryTick(tick);
  if (pending && tick == pendingTick) {
    out = pendingY;
    return;
  }
  evalAt(timeOfTick(tick), out);
}

// ------------------------------------------------------------ protocol
void Arena::Impl::commit() {
  if (!pending) return;
  pending = false;
  if (pendingFromRoot) noteFired(pendingTick, pendingFound.data());
  D = pendingD;
  reinit(pendingTick, pendingTime, pendingY);
}

// Brings the plant to tick c for an input that changes it; returns the
// state at c in tmp.
void Arena::Impl::rewindTo(std::int64_t c) {
  if (pending && c == pendingTick) {
    commit();
  } else {
    checkInputTick(c);
    pending = false;
  }
  evalAt(timeOfTick(c), tmp);
}

bool Arena::Impl::launchesDue(std::int64_t T) const {
  for (int i = 0; i < nR; ++i)
    for (std::int64_t lt : D.r[static_cast<std::size_t>(i)].launchTick)
      if (lt >= 0 && lt <= T) return true;
  return false;
}

std::int64_t Arena::Impl::nextLaunchIn(const Discrete& d) const {
  std::int64_t best = -1;
  for (int i = 0; i < nR; ++i)
    for (std::int64_t lt : d.r[static_cast<std::size_t>(i)].launchTick)
      if (lt >= 0 && (best < 0 || lt < best)) best = lt;
  return best;
}

// Computes the events at T (time te) from the current segment's state
// into pendingD/pendingY and ev; true if there are any. Does not make
// them pending.
bool Arena::Impl::eventsAt(std::int64_t T, double te, const int* found, EventList& ev) {
  evalAt(te, pendingY);
  pendingD = D;
  ev.clear();
  process(T, te, pendingD, pendingY, found, ev);
  if (ev.empty()) {  // nothing happens here, but a ball or disc may pass closest to its target
    for (int s = 0; s < kMaxBalls; ++s)
      D.balls[static_cast<std::size_t>(s)].closest =
          pendingD.balls[static_cast<std::size_t>(s)].closest;
    for (int k = 0; k < kMaxDiscs; ++k)
      D.discs[static_cast<std::size_t>(k)].closest =
          pendingD.discs[static_cast<std::size_t>(k)].closest;
  }
  return !ev.empty();
}

// Computes the events at T (time te) from the current segment's state;
// if there are any, keeps them pending and returns true.
bool Arena::Impl::predict(std::int64_t T, double te, const int* found, EventList& ev) {
  if (!eventsAt(T, te, found, ev)) return false;
  pending = true;
  pendingFromRoot = found != nullptr;
  if (found) std::copy(found, found + kMaxRoots, pendingFound.begin());
  pendingTick = T;
  pendingTime = te;
  now = T;
  return true;
}

// Back to `tick` (>= the last reset, < now): the caller stops there
// instead. A prediction from a root is held again, exactly as if advance()
// had been given `tick` as its stop (its root lay beyond it); one from a
// launch is predicted again by the advance() whose stop reaches the
// launch. No ARKODE call: the steps taken stay, as they would after an
// advance() that overshot.
void Arena::Impl::retreat(std::int64_t tick) {
  if (tick >= now || tick < segTick) return;
  if (pending && pendingFromRoot) {
    held = true;
    heldTick = pendingTick;
    heldTime = pendingTime;
    heldFound = pendingFound;
  }
  pending = false;
  now = tick;
}

AdvanceResult Arena::Impl::advance(std::int64_t stopTick) {
  AdvanceResult res;
  commit();
  res.tick = now;
  const bool due = launchesDue(now) || (pushEndDue && segTick == now);
  if (stopTick <= now) {
    if (due) predict(now, timeOfTick(now), nullptr, res.events);
    return res;
  }
  if (due && predict(now, timeOfTick(now), nullptr, res.events)) return res;
  std::int64_t stop = stopTick;
  const std::int64_t nl = nextLaunch();
  if (nl > now && nl < stop) stop = nl;  // ARKODE's stop time is set there
  const double tStop = secondsFromTick(stop);
  for (;;) {
    if (held) {
      if (heldTick > stop) break;  // still beyond: return at stop, keep it
      held = false;
      if (predict(heldTick, heldTime, heldFound.data(), res.events)) {
        res.tick = heldTick;
        return res;
      }
      continue;  // (cannot happen: it had events when found)
    }
    // Every root up to tReturned has been reported or held; all roots at
    // ticks <= stop lie before the first time ARKODE returns past tStop.
    if (tReturned >= tStop) break;
    double tret = 0;
    fresh = false;
    // tout matters only to the first step's size guess (after creation);
    // a fixed horizon past the current time keeps it independent of the
    // caller.
    const ark::StepEnd end = ode.step(tStepEnd + kFirstStepHorizon, ark::Buffer::State, tret);
    const double tn = ode.currentTime();
    if (tn > tStepEnd) {
      // A new internal step: its end state (at a root return ARKODE hands
      // back the root's state; its own interpolant gives the step's end,
      // exactly, at tn).
      const double* yn = ode.data(ark::Buffer::State);
      if (tret != tn) {
        ode.interpolate(tn, ark::Buffer::Scratch);
        yn = ode.data(ark::Buffer::Scratch);
      }
      recordStep(tn, yn);
      tStepEnd = tn;
      recs.back().thi = std::max(tn, tret);
      fullState(tn, yn, qtmp.data());
      const double ahead = ode.currentStep();
      recs.back().next = ahead;
      // ARKODE's root check at the step's end saw this very state.
      const bool rawHere = rootRawValid && std::memcmp(&rootRawT, &tn, sizeof tn) == 0 &&
                           std::memcmp(rootRawXY.data(), yn, sizeof(double) * nx) == 0;
      setMaxStep(segRest ? kRestStep
                         : stepBound(qtmp.data(), ahead, rawHere ? rootRaw.data() : nullptr));
    } else if (tret > recs.back().thi) {
      recs.back().thi = tret;
    }
    tReturned = tret;
    lastRoot = end == ark::StepEnd::Root;
    if (end == ark::StepEnd::StopTime) launchStop = -1;  // ARKODE disarms a reached stop time
    if (end != ark::StepEnd::Root) continue;
    ++acc.roots;
    ode.rootsFound(rootsFound.data());
    const std::int64_t T0 = eventTickFromSeconds(tret);
    const std::int64_t k = crossedTick(T0);
    std::int64_t T = std::max(k, now);
    if (launchStop >= 0) T = std::min(T, launchStop);  // tret <= the stop time
    // At the tick before ceil(tret) the state is taken at tret itself (a
    // hair later, within kOnTickFraction of a tick): it lies on the far
    // side of the crossing, so the new segment sees the root function
    // leave zero in the right direction.
    const double te = T < T0 ? tret : std::max(timeOfTick(T), tret);
    if (T <= stop) {
      if (predict(T, te, rootsFound.data(), res.events)) {
        res.tick = T;
        return res;
      }
      continue;  // nothing changed: integrate on without a reset
    }
    // Beyond the caller's stop. ARKODE stays where the root left it (the
    // next call looks at the rest of that step, as when a root with no
    // events is passed over); a later advance reports it at T.
    if (eventsAt(T, te, rootsFound.data(), res.events)) {
      held = true;
      heldTick = T;
      heldTime = te;
      std::copy(rootsFound.begin(), rootsFound.end(), heldFound.begin());
      res.events.clear();
    }
  }
  now = stop;
  res.tick = stop;
  if (launchesDue(stop)) predict(stop, timeOfTick(stop), nullptr, res.events);
  return res;
}

}  // namespace simbot::plant
