// plant/arena_integrator.cpp -- CVODE and dense output for the arena.
//
// Set-up of the integrator, the right-hand side and its targets, the
// re-initialisation at a discontinuity, the dense output records kept per
// step, and the stepping loop (advance, predict, retreat, commit) whose
// independence from the caller's stops arena.cpp's header comment
// ("Stepping", "Dense output") argues.
#include <cstring>

#include "plant/arena_impl.h"

namespace simbot::plant {

Arena::Impl::Impl(const ArenaConfig& c)
    : cfg(c),
      nR(static_cast<int>(c.robots.size())),
      n(kPerRobot * static_cast<int>(c.robots.size())),
      yv(kPerRobot * static_cast<sunindextype>(c.robots.size()), ctx.get()),
      dky(kPerRobot * static_cast<sunindextype>(c.robots.size()), ctx.get()),
      nls(yv.get(), ctx.get()),
      mem(CV_ADAMS, ctx.get()) {
  if (nR < 1 || nR > 2) throw std::invalid_argument("Arena: 1 or 2 robots");
  half = cfg.field.size_ft / 2;
  wireHalf = half - cfg.field.wire_inset_ft;
  pendingY.assign(static_cast<std::size_t>(n), 0.0);
  tmp.assign(static_cast<std::size_t>(n), 0.0);
  qtmp.assign(static_cast<std::size_t>(n), 0.0);
  segY.assign(static_cast<std::size_t>(n), 0.0);
  rootsFound.assign(kMaxRoots, 0);
  heldFound.assign(kMaxRoots, 0);
  pendingFound.assign(kMaxRoots, 0);
  recs.reserve(1024);
  coef.reserve(static_cast<std::size_t>(1024 * 13 * n));

  double* y = yv.data();
  for (int i = 0; i < nR; ++i) {
    const RobotSetup& rs = cfg.robots[static_cast<std::size_t>(i)];
    double* r = y + i * kPerRobot;
    r[X] = rs.start.x_ft;
    r[Y] = rs.start.y_ft;
    r[H] = geom::degToRad(rs.start.heading_deg);
    r[VL] = r[VR] = r[S] = r[G1] = r[G2] = 0;
    RobotDisc& d = D.r[static_cast<std::size_t>(i)];
    d.latched = MotorFrame{};  // stopped until the first frame latches
    d.ballsLeft = {rs.params.balls_per_gun, rs.params.balls_per_gun};
  }
  // Initial flags from geometry, silently (nothing has happened yet).
  for (int i = 0; i < nR; ++i) {
    RobotDisc& d = D.r[static_cast<std::size_t>(i)];
    for (int k = 0; k < 2; ++k) d.edgeLow[static_cast<std::size_t>(k)] = edgeG(y, i, k) < 0;
    d.wallContact = cfg.field.field_walls && wallG(y, i) < 0;
    d.dividerContact = dividerG(y, i) < 0;
  }
  D.robotContact = nR == 2 && robotG(y) < 0;

  cv::check(CVodeInit(mem.get(), &Impl::rhsThunk, 0.0, yv.get()), "CVodeInit");
  cv::check(CVodeSetUserData(mem.get(), this), "CVodeSetUserData");
  // rtol = atol = 5e-10 (ft, rad, ft/s; issue 13 part 4, README "The
  // plant's integrator"). Against the exact motion from rest (closed-form
  // heading, Boost.Math quadrature; tests/plant/tolerance_test.cpp), 277
  // random 10-s arcs of the default profile stay within 9.5e-9 ft and
  // 2.2e-9 rad: 1/40 of the 3.8e-7 ft a point at top speed moves in a tick
  // (1e-10: 5.2e-9 ft, 11 % more steps in the 180-s match; 1e-9 puts an
  // edge crossing 0.08 tick past a tick boundary on the wrong tick).
  // Two crossings exactly on one tick may then fall in different steps:
  // crossedTick() keeps them on that tick.
  cv::check(CVodeSStolerances(mem.get(), 5e-10, 5e-10), "CVodeSStolerances");
  // Adams with functional iteration: the motion is not stiff (time
  // constants of 0.1 s and more against steps the roots and the maximum
  // step keep far shorter), so no Jacobian and no linear solve.
  cv::check(CVodeSetNonlinearSolver(mem.get(), nls.get()), "CVodeSetNonlinearSolver");
  cv::check(CVodeSetMaxNumSteps(mem.get(), 100000), "CVodeSetMaxNumSteps");
  cv::check(CVodeSetNoInactiveRootWarn(mem.get()), "CVodeSetNoInactiveRootWarn");
  // CVODE's own messages would go to stderr: a failure is reported as the
  // run's plant fault instead (SolverError).
  cv::check(CVodeSetErrFile(mem.get(), nullptr), "CVodeSetErrFile");
  std::copy(y, y + n, tmp.begin());
  reinit(0, 0.0, tmp, /*first=*/true);
}

double Arena::Impl::maxStep() const {
  double pointSpeed = 0;
  for (int i = 0; i < nR; ++i) {
    const RobotParams& p = P(i);
    double v = 0;
    for (double s : p.speed_table_fps) v = std::max(v, s);
    v *= std::max(p.left_trim, p.right_trim);
    const double omega = 2 * v / p.track_ft;
    pointSpeed = std::max(pointSpeed, v + omega * radius(i));
  }
  if (pointSpeed <= 0) return 0.0;  // nothing moves: no limit
  return (1.0 / 12.0) / (nR * pointSpeed);
}

// Every wheel and its target at rest and no ball in flight: the state and
// every root function are then constant until the next re-initialisation
// (nothing changes the right-hand side without one), so no crossing can
// hide inside a step and maxStep() need not bound it.
bool Arena::Impl::atRest(const std::vector<double>& y) const {
  for (const Ball& b : D.balls)
    if (b.active) return false;
  for (int i = 0; i < nR; ++i) {
    const double* r = y.data() + i * kPerRobot;
    const auto& wt = wheelTarget[static_cast<std::size_t>(i)];
    if (r[VL] != 0 || r[VR] != 0 || wt[0] != 0 || wt[1] != 0) return false;
  }
  return true;
}

void Arena::Impl::rhs(double, const double* y, double* f) const {
  for (int i = 0; i < nR; ++i) {
    const RobotParams& p = P(i);
    const double* r = y + i * kPerRobot;
    double* d = f + i * kPerRobot;
    const double v = 0.5 * (r[VL] + r[VR]);
    d[X] = v * std::sin(r[H]);
    d[Y] = v * std::cos(r[H]);
    d[H] = (r[VL] - r[VR]) / p.track_ft;  // clockwise when the left wheel is faster
    const auto& wt = wheelTarget[static_cast<std::size_t>(i)];
    d[VL] = p.motor_lag_s > 0 ? (wt[0] - r[VL]) / p.motor_lag_s : 0.0;
    d[VR] = p.motor_lag_s > 0 ? (wt[1] - r[VR]) / p.motor_lag_s : 0.0;
    d[S] = v;
    const auto& gt = gunTarget[static_cast<std::size_t>(i)];
    for (int g = 0; g < 2; ++g) {
      const double target = gt[static_cast<std::size_t>(g)];
      const double tau = gunTau(p, target);
      d[G1 + g] = tau > 0 ? (target - r[G1 + g]) / tau : 0.0;
    }
  }
}

// ------------------------------------------------------------ targets and
// reinit
void Arena::Impl::computeTargets(const Discrete& d) {
  for (int i = 0; i < nR; ++i) {
    const RobotParams& p = P(i);
    const RobotDisc& r = d.r[static_cast<std::size_t>(i)];
    auto& wt = wheelTarget[static_cast<std::size_t>(i)];
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
    auto& gt = gunTarget[static_cast<std::size_t>(i)];
    gt[0] = r.gunOn[0] || p.gun_motors_always_on ? 1.0 : 0.0;
    gt[1] = r.gunOn[1] || p.gun_motors_always_on ? 1.0 : 0.0;
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

void Arena::Impl::clearStopTime() {
#if SUNDIALS_VERSION_MAJOR > 6 || (SUNDIALS_VERSION_MAJOR == 6 && SUNDIALS_VERSION_MINOR >= 5)
  cv::check(CVodeClearStopTime(mem.get()), "CVodeClearStopTime");
#else
  // No CVodeClearStopTime before SUNDIALS 6.5: a stop time no step ever
  // comes near changes nothing (CVODE only shortens a step that would
  // pass it, and uses it for the first step's guess only if it is closer
  // than tout).
  cv::check(CVodeSetStopTime(mem.get(), kNoStopTime), "CVodeSetStopTime");
#endif
}

void Arena::Impl::accumulateStats() {
  long v = 0;
  CVodeGetNumSteps(mem.get(), &v);
  acc.steps += v;
  CVodeGetNumRhsEvals(mem.get(), &v);
  acc.rhs_evals += v;
  CVodeGetNumLinRhsEvals(mem.get(), &v);
  acc.rhs_evals += v;
}

// (Re)starts the integration at tick `tick`, time t0, from state y, under
// the dynamics the discrete state D now selects.
void Arena::Impl::reinit(std::int64_t tick, double t0, std::vector<double>& y, bool first) {
  computeTargets(D);
  applyJumps(y);
  std::copy(y.begin(), y.end(), yv.data());
  // An input at the tick of the last re-initialisation, before any step,
  // that leaves the state and everything the right-hand side reads as
  // they were: CVODE is already exactly where CVodeReInit would put it
  // (no step, no RHS evaluation since), so it is not called. The root set
  // and stop time are rebuilt below as always.
  const bool same = fresh && tick == segTick && t0 == segT0 && wheelTarget == segWheel &&
                    gunTarget == segGun &&
                    std::memcmp(y.data(), segY.data(), y.size() * sizeof(double)) == 0;
  if (!first && !same) {
    accumulateStats();
    cv::check(CVodeReInit(mem.get(), t0, yv.get()), "CVodeReInit");
    ++acc.reinits;
  }
  // At rest the steps grow as fast as CVODE allows (a solo program that
  // never drives: a few steps instead of one per maxStep()); the dense
  // output is the same constant state either way.
  const double hmax = atRest(y) ? 0.0 : maxStep();  // 0: no bound
  if (hmax != maxStepSet) {
    cv::check(CVodeSetMaxStep(mem.get(), hmax), "CVodeSetMaxStep");
    maxStepSet = hmax;
  }
  fresh = true;
  std::copy(y.begin(), y.end(), segY.begin());
  segWheel = wheelTarget;
  segGun = gunTarget;
  buildRoots();
  sideRoots(t0, y);
  if (nRoots != nRootsRegistered) {
    cv::check(CVodeRootInit(mem.get(), nRoots, nRoots > 0 ? &Impl::rootThunk : nullptr),
              "CVodeRootInit");
    nRootsRegistered = nRoots;
  }
  segTick = tick;
  segT0 = t0;
  now = tick;
  tOut = t0 + kFirstStepHorizon;
  tReturned = t0;
  held = false;
  // The only discontinuity known in advance: the next ball launch. CVODE
  // must not step across it; any other stop time from the last segment
  // (a launch this re-initialisation came before) is cleared.
  const std::int64_t nl = nextLaunch();
  if (nl > tick) {
    cv::check(CVodeSetStopTime(mem.get(), secondsFromTick(nl)), "CVodeSetStopTime");
    launchStop = nl;
  } else {
    clearStopTime();
    launchStop = -1;
  }
  recs.clear();
  coef.clear();
  recs.push_back(Rec{t0, t0, t0, 0, 0});
  coef.insert(coef.end(), y.begin(), y.end());
}

// ------------------------------------------------------------ dense output
void Arena::Impl::recordStep(double tret) {
  double tn = 0;
  CVodeGetCurrentTime(mem.get(), &tn);
  Rec& last = recs.back();
  if (tn <= last.tn) {
    last.thi = std::max(last.thi, tret);
    return;
  }
  int q = 0;
  CVodeGetLastOrder(mem.get(), &q);
  Rec r{last.thi, std::max(tn, tret), tn, 0, coef.size()};
  double fact = 1.0;
  for (int k = 0; k <= q; ++k) {
    if (k > 0) fact *= k;
    if (CVodeGetDky(mem.get(), tn, k, dky.get()) < 0) break;
    const double* d = dky.data();
    for (int i = 0; i < n; ++i) coef.push_back(d[i] / fact);
    r.q = k;
  }
  recs.push_back(r);
}

// First record whose interval reaches t; past the end, the last one
// (advance() steps until CVODE has returned a time at or past now(), so
// at most a rounding of the tick's time).
const Arena::Impl::Rec& Arena::Impl::recordAt(double t) const {
  auto it = std::lower_bound(recs.begin(), recs.end(), t,
                             [](const Rec& r, double tt) { return r.thi < tt; });
  if (it == recs.end()) --it;
  return *it;
}

// Component i of the dense output polynomial of record r at time t.
double Arena::Impl::component(const Rec& r, double t, int i) const {
  const double dt = t - r.tn;
  double sum = coef[r.off + static_cast<std::size_t>(r.q * n + i)];
  for (int k = r.q - 1; k >= 0; --k)
    sum = sum * dt + coef[r.off + static_cast<std::size_t>(k * n + i)];
  return sum;
}

// One robot's x, y and heading (rad) at a tick: what the eyes need, at a
// fraction of evaluating the whole state. Same arithmetic, same bits.
std::array<double, 3> Arena::Impl::poseAt(int robot, std::int64_t tick) const {
  checkQueryTick(tick);
  const int base = robot * kPerRobot;
  if (pending && tick == pendingTick)
    return {pendingY[static_cast<std::size_t>(base + X)],
            pendingY[static_cast<std::size_t>(base + Y)],
            pendingY[static_cast<std::size_t>(base + H)]};
  const double t = timeOfTick(tick);
  const Rec& r = recordAt(t);
  return {component(r, t, base + X), component(r, t, base + Y), component(r, t, base + H)};
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
  if (ev.empty())  // nothing happens here, but a ball may pass closest to its
                   // target
    for (int s = 0; s < kMaxBalls; ++s)
      D.balls[static_cast<std::size_t>(s)].closest =
          pendingD.balls[static_cast<std::size_t>(s)].closest;
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

// Back to `tick` (>= the last re-initialisation, < now): the caller stops
// there instead. A prediction from a root is held
// again, exactly as if advance() had been given `tick` as its stop (its
// root lay beyond it); one from a launch is predicted again by the
// advance() whose stop reaches the launch. No CVODE call: the steps
// taken stay, as they would after an advance() that overshot.
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
  if (stopTick <= now) {
    if (launchesDue(now)) predict(now, timeOfTick(now), nullptr, res.events);
    return res;
  }
  if (launchesDue(now) && predict(now, timeOfTick(now), nullptr, res.events)) return res;
  std::int64_t stop = stopTick;
  const std::int64_t nl = nextLaunch();
  if (nl > now && nl < stop) stop = nl;  // CVODE's stop time is set there
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
    // ticks <= stop lie before the first time CVODE returns past tStop.
    if (tReturned >= tStop) break;
    double tret = 0;
    fresh = false;
    const int flag = CVode(mem.get(), tOut, yv.get(), &tret, CV_ONE_STEP);
    cv::check(flag, "CVode");
    recordStep(tret);
    tReturned = tret;
    if (flag == CV_TSTOP_RETURN) launchStop = -1;  // CVODE disarms a reached stop time
    if (flag != CV_ROOT_RETURN) continue;
    ++acc.roots;
    cv::check(CVodeGetRootInfo(mem.get(), rootsFound.data()), "CVodeGetRootInfo");
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
      continue;  // nothing changed: integrate on without a reinit
    }
    // Beyond the caller's stop. CVODE stays where the root left it (the
    // next CVode call looks at the rest of that step, as when a root with
    // no events is passed over); a later advance reports it at T.
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
