// plant/arena.cpp -- the arena: continuous motion with CVODE, discrete events.
//
// One CVODE instance (Adams-Moulton, Newton iteration with a dense linear
// solver and a difference-quotient Jacobian; the problem is small and not
// stiff) integrates, per robot, x, y, heading (radians, unwrapped), the two
// wheel ground speeds (first-order lag toward the commanded speed), a signed
// odometer (for the bumper reflex distance) and the two gun-wheel speeds
// (fraction of full speed, first-order spin-up with the motor on, coast-down
// with its own time constant with it off). Balls in flight are
// closed forms of time (straight line at the muzzle speed, z = h - g t^2 / 2)
// that live only in the root functions, so a launch does not grow the state.
// A zero time constant is handled by holding that state constant in the RHS
// and setting it to the commanded value at every re-initialisation.
//
// Events. Every discrete change (edge detector entering or leaving the wire's
// range, bumper contact, reflex end, ball hit or miss, centre leaving the
// field) is the zero of a root function; CVODE locates it (CV_ROOT_RETURN)
// at t, and it happens at tick T = ceil(t * 9,216,000) (time.cpp). At T we
// evaluate every root function again on the state at T and compare with the
// discrete flags: a function CVODE reported takes its new side from the
// reported crossing direction (immune to round-off at T), every other one
// from its sign at T, which also catches a second crossing inside the same
// tick. A root that changes nothing (a ball passing the divider's plane
// beside the wall, the closest approach of a ball that misses) lets
// integration go on without a re-initialisation; it only updates the
// ball's closest distance to its target, which its ball_miss reports.
//
// The events at T are a prediction (DESIGN.md "co-simulation"): advance()
// returns them and keeps the post-event state aside; they are applied (and
// CVODE re-initialised with CVodeReInit, as in sundials' cvRocket example)
// when the scheduler proceeds, or discarded if an input at an earlier tick
// changes the plant. Hence an input can re-initialise at any tick between the
// last re-initialisation and now().
//
// Stepping is independent of how the caller chops time. advance(stop) does
// not stop CVODE at `stop`: it takes whole internal steps until CVODE has
// returned a time at or past the stop (the last step may overshoot it; the
// segments keep the overshoot for the next advance(), which steps only if
// they do not reach its stop yet). CVODE is given a stop time only at a
// discontinuity known when the segment starts: the next ball launch, set at
// every re-initialisation (an input that schedules a launch re-initialises).
// A root whose tick lies beyond the caller's stop is held, not reported: the
// call returns at its stop, and a later advance() whose stop reaches the
// root's tick reports it there, with the same events, exactly as a single
// long advance() would have. A re-initialisation drops a held root (it lies
// past the input's tick). Between re-initialisations the sequence of CVode
// calls is therefore the same whatever the stops were, and so are the steps,
// the segments, the roots and every query; the only CVode argument that is
// not a state of the plant, tout, matters only on the first call after a
// (re)initialisation (CVODE's initial step guess) and is a fixed horizon.
//
// Dense output. CVODE runs in CV_ONE_STEP mode; after every internal step
// we store the step's Nordsieck data as Taylor coefficients c_k =
// y^(k)(t_n) / k! from CVodeGetDky(t_n, k) for k = 0..q. On the step's
// interval [t_{n-1}, t_n] that polynomial is exactly CVODE's own interpolant,
// so a query at any tick since the last re-initialisation evaluates it
// without touching the integrator: results never depend on whether (or how
// often) anyone queried. The buffers are cleared, not freed, at each
// re-initialisation, so after warm-up nothing is allocated per step.
//
// Root finding only sees sign changes between step ends, so the maximum
// step is bounded such that no point of a robot moves more than 1 inch per
// step: an edge detector cannot cross the 4-inch band around the wire
// unnoticed, nor two bodies graze unnoticed by more than that. Balls move
// 100 times faster, so their root functions are built not to graze: the hit
// function is the along-track offset to the opponent's centre plus the
// half-chord (zero at the entry point of a hit and at the closest approach
// of a miss), the divider function the signed distance past the wall's near
// face along the ball's travel, the floor a concave parabola, the field's
// boundary a convex function the ball starts inside of.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "plant/cvode.h"
#include "plant/geometry.h"
#include "plant/plant.h"

namespace simbot::plant {

using geom::Vec2;

namespace {

constexpr int kPerRobot = 8;
enum : int { X = 0, Y = 1, H = 2, VL = 3, VR = 4, S = 5, G1 = 6, G2 = 7 };
// Every ball two robots with two full magazines can have in flight: balls
// are never reloaded, so a launch always finds a free slot.
constexpr int kMaxBalls = 64;
static_assert(kMaxBalls >= 2 * 2 * kMaxBallsPerGun, "the ball table must hold every magazine");
constexpr int kMaxRoots = 2 * 6 + 1 + kMaxBalls * 4;
constexpr int kRing = 16;
static_assert(kRing > kMaxRefereeLimit, "the referee must see one event more than its limit");
// CVode's tout in CV_ONE_STEP mode only bounds the first step's guess after a
// (re)initialisation; a fixed horizon keeps it independent of the caller.
constexpr double kFirstStepHorizon = 1.0;  // s
constexpr double kNoStopTime = 1e12;       // s, far beyond any match
// A crossing this close after a tick (in ticks) is taken as on the tick.
// Round-off in a root function is far smaller: an odometer of 300 ft has an
// ulp of 6e-14 ft, top speed moves 1.6e-7 ft per tick; CVODE's root
// tolerance (100 ulp of t) is 3e-6 tick after 3 minutes.
constexpr double kOnTickFraction = 1.0 / 1024;

enum class RootKind : std::uint8_t {
  EdgeFore,
  EdgeAft,
  OutOfField,
  Wall,
  Divider,
  ReflexEnd,
  RobotRobot,
  BallFloor,
  BallHit,
  BallOut,
  BallDivider,
};

struct RootDesc {
  RootKind kind;
  int robot;  // or ball slot for ball roots
};

struct Ball {
  bool active = false;
  bool rolling = false;  // after the floor, only with count_floor_skips
  int shooter = 0, gun = 0;
  double t0 = 0;
  double x0 = 0, y0 = 0, z0 = 0, vx = 0, vy = 0;
  // Smallest distance to the other robot's body seen at an event tick or
  // at the closest-approach root of the hit function (for ball_miss).
  double closest = HUGE_VAL;
};

struct Ring {
  std::array<std::int64_t, kRing> t{};
  int n = 0;
  void push(std::int64_t tick) {
    if (n == kRing) {
      std::copy(t.begin() + 1, t.end(), t.begin());
      --n;
    }
    t[static_cast<std::size_t>(n++)] = tick;
  }
  int countSince(std::int64_t from) const {
    int c = 0;
    for (int i = 0; i < n; ++i) c += t[static_cast<std::size_t>(i)] > from ? 1 : 0;
    return c;
  }
};

struct RobotDisc {
  MotorFrame latched{};
  bool driven = false;            // a scripted drive overrides the frame
  std::array<double, 2> drive{};  // its wheel ground speeds, ft/s
  bool reflex = false;
  Bumper reflexSide = Bumper::Front;
  double reflexS0 = 0;
  std::array<bool, 2> edgeLow{};
  bool wallContact = false, dividerContact = false;
  Ring reflexTicks, eventTicks;
  std::uint8_t portB = 0;
  std::array<bool, 2> gunOn{};
  std::array<bool, 2> gunJammed{};
  std::array<std::int64_t, 2> launchTick{-1, -1};
  std::array<double, 2> launchFactor{1, 1};  // muzzleFactor drawn at the stroke
  std::array<int, 2> ballsLeft{};
  int shots = 0, hits = 0;
};

struct Discrete {
  std::array<RobotDisc, 2> r{};
  bool robotContact = false;
  std::array<Ball, kMaxBalls> balls{};
};

}  // namespace

struct Arena::Impl {
  // ---- configuration
  ArenaConfig cfg;
  int nR = 0;
  int n = 0;  // state size
  double half = 0, wireHalf = 0;

  // ---- SUNDIALS objects, in creation order (destroyed in reverse)
  cv::Context ctx;
  cv::Vector yv;
  cv::Vector dky;
  cv::FixedPointSolver nls;
  cv::Memory mem;

  // ---- discrete state being integrated, and the pending prediction
  Discrete D;
  std::array<std::array<double, 2>, 2> wheelTarget{};
  std::array<std::array<double, 2>, 2> gunTarget{};
  bool pending = false;
  // The prediction came from a root (its crossing directions in
  // pendingFound), not from a scheduled launch; retreat() holds it again.
  bool pendingFromRoot = false;
  std::vector<int> pendingFound;
  std::int64_t pendingTick = 0;
  double pendingTime = 0;
  Discrete pendingD;
  std::vector<double> pendingY;

  // ---- time
  std::int64_t now = 0;      // tick reached
  std::int64_t segTick = 0;  // tick of the last (re)initialisation
  double segT0 = 0;          // its time in seconds
  // What the last (re)initialisation gave CVODE, and whether CVode has been
  // called since: a re-initialisation at the same tick with the same state
  // and dynamics before any step would leave CVODE exactly as it is.
  bool fresh = false;
  std::vector<double> segY;
  std::array<std::array<double, 2>, 2> segWheel{}, segGun{};

  // ---- the integrator's own position (see "Stepping" above)
  double tOut = 0;               // tout for CVode: segT0 + kFirstStepHorizon
  double tReturned = 0;          // time of CVode's last return: roots up to it are known
  std::int64_t launchStop = -1;  // tick CVODE's stop time is set at (a launch), or -1
  // A root found beyond the caller's stop, with events: reported by a later
  // advance() whose stop reaches heldTick.
  bool held = false;
  std::int64_t heldTick = 0;
  double heldTime = 0;
  std::vector<int> heldFound;

  // ---- roots
  std::array<RootDesc, kMaxRoots> roots{};
  int nRoots = 0;
  int nRootsRegistered = -1;
  std::vector<int> rootsFound;

  // ---- dense output records
  struct Rec {
    double tlo, thi, tn;
    int q;
    std::size_t off;
  };
  std::vector<Rec> recs;
  std::vector<double> coef;

  // ---- statistics
  IntegratorStats acc{};

  // ---- scratch
  std::vector<double> tmp;
  mutable std::vector<double> qtmp;  // for const queries

  explicit Impl(const ArenaConfig& c)
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
    cv::check(CVodeSStolerances(mem.get(), 1e-10, 1e-10), "CVodeSStolerances");
    // Adams with functional iteration: the motion is not stiff (time
    // constants of 0.1 s and more against steps the roots and the maximum
    // step keep far shorter), so no Jacobian and no linear solve.
    cv::check(CVodeSetNonlinearSolver(mem.get(), nls.get()), "CVodeSetNonlinearSolver");
    cv::check(CVodeSetMaxNumSteps(mem.get(), 100000), "CVodeSetMaxNumSteps");
    cv::check(CVodeSetNoInactiveRootWarn(mem.get()), "CVodeSetNoInactiveRootWarn");
    // CVODE's own messages would go to stderr: a failure is reported as the
    // run's plant fault instead (SolverError).
    cv::check(CVodeSetErrFile(mem.get(), nullptr), "CVodeSetErrFile");
    cv::check(CVodeSetMaxStep(mem.get(), maxStep()), "CVodeSetMaxStep");
    std::copy(y, y + n, tmp.begin());
    reinit(0, 0.0, tmp, /*first=*/true);
  }

  // ------------------------------------------------------------ parameters
  const RobotParams& P(int i) const { return cfg.robots[static_cast<std::size_t>(i)].params; }
  double radius(int i) const { return P(i).body_diameter_ft / 2; }

  double maxStep() const {
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

  // ------------------------------------------------------------ geometry on a state
  static Vec2 centre(const double* y, int i) {
    return Vec2(y[i * kPerRobot + X], y[i * kPerRobot + Y]);
  }
  static double heading(const double* y, int i) { return y[i * kPerRobot + H]; }

  Vec2 detector(const double* y, int i, int k) const {
    const double off = radius(i) - P(i).edge_detector_inset_ft;
    const Vec2 dir = geom::headingDir(heading(y, i));
    return k == 0 ? Vec2(centre(y, i) + off * dir) : Vec2(centre(y, i) - off * dir);
  }
  double edgeG(const double* y, int i, int k) const {
    return geom::squareRingDistance(detector(y, i, k), wireHalf) - cfg.field.wire_sensitivity_ft;
  }
  double outG(const double* y, int i) const {
    const Vec2 c = centre(y, i);
    return half - std::max(std::abs(c.x()), std::abs(c.y()));
  }
  double wallG(const double* y, int i) const { return outG(y, i) - radius(i); }
  double dividerG(const double* y, int i) const {
    const Vec2 c = centre(y, i);
    return dividerClearance(c.x(), c.y(), radius(i), cfg.field);
  }
  double robotG(const double* y) const {
    return (centre(y, 0) - centre(y, 1)).norm() - radius(0) - radius(1);
  }
  double reflexG(const double* y, int i, const Discrete& d) const {
    const RobotDisc& r = d.r[static_cast<std::size_t>(i)];
    const double sign = r.reflexSide == Bumper::Front ? -1.0 : 1.0;
    return sign * (y[i * kPerRobot + S] - r.reflexS0) - P(i).reflex_distance_ft;
  }

  // Ball position at time t (closed form).
  void ballAt(const Ball& b, double t, double& x, double& yy, double& z) const {
    const double dt = t - b.t0;
    x = b.x0 + b.vx * dt;
    yy = b.y0 + b.vy * dt;
    z = b.rolling ? 0.0 : b.z0 - 0.5 * cfg.field.gravity_fps2 * dt * dt;
  }
  // The non-grazing hit function: along-track offset plus half-chord.
  double ballHitG(const Ball& b, double t, const double* y, double& perp2, double& dist2) const {
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
  double ballGap(const Ball& b, double t, const double* y) const {
    double x, yy, z;
    ballAt(b, t, x, yy, z);
    const int tgt = 1 - b.shooter;
    const double across = std::max((Vec2(x, yy) - centre(y, tgt)).norm() - radius(tgt), 0.0);
    const double above = std::max(z - P(tgt).target_height_ft, 0.0);
    return std::hypot(across, above);
  }
  // The field walls stop a ball (DESIGN.md: a ball reaching a field wall
  // is a miss), at the field's edge.
  double ballOutG(const Ball& b, double t) const {
    double x, yy, z;
    ballAt(b, t, x, yy, z);
    return half - std::max(std::abs(x), std::abs(yy));
  }
  // Signed distance past the divider's near face along the ball's x
  // travel: linear in t, so a thin wall cannot be stepped over unnoticed.
  double ballDividerG(const Ball& b, double t) const {
    double x, yy, z;
    ballAt(b, t, x, yy, z);
    const double dir = b.vx > 0 ? 1.0 : b.vx < 0 ? -1.0 : 0.0;
    if (dir == 0.0) return 1.0;
    return dir * (x - cfg.field.divider_x_ft) + cfg.field.divider_thickness_ft / 2;
  }

  double rootValue(const RootDesc& rd, double t, const double* y) const {
    switch (rd.kind) {
      case RootKind::EdgeFore:
        return edgeG(y, rd.robot, 0);
      case RootKind::EdgeAft:
        return edgeG(y, rd.robot, 1);
      case RootKind::OutOfField:
        return outG(y, rd.robot);
      case RootKind::Wall:
        return wallG(y, rd.robot);
      case RootKind::Divider:
        return dividerG(y, rd.robot);
      case RootKind::ReflexEnd:
        return reflexG(y, rd.robot, D);
      case RootKind::RobotRobot:
        return robotG(y);
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
    }
    return 1.0;
  }

  // ------------------------------------------------------------ CVODE callbacks
  static int rhsThunk(sunrealtype t, N_Vector y, N_Vector ydot, void* user) {
    static_cast<Impl*>(user)->rhs(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot));
    return 0;
  }
  static int rootThunk(sunrealtype t, N_Vector y, sunrealtype* g, void* user) {
    const Impl* self = static_cast<const Impl*>(user);
    const double* yy = N_VGetArrayPointer(y);
    for (int i = 0; i < self->nRoots; ++i)
      g[i] = self->rootValue(self->roots[static_cast<std::size_t>(i)], t, yy);
    return 0;
  }

  void rhs(double, const double* y, double* f) const {
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

  // A gun wheel spins up under its motor and coasts down, more slowly,
  // when the motor is off (DESIGN.md "Guns"): the time constant follows
  // the motor, not the direction of change.
  static double gunTau(const RobotParams& p, double target) {
    return target > 0 ? p.gun_wheel_lag_s : p.gun_wheel_coast_s;
  }

  // ------------------------------------------------------------ targets and reinit
  void computeTargets(const Discrete& d) {
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
  void applyJumps(std::vector<double>& y) const {
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

  void buildRoots() {
    nRoots = 0;
    auto add = [&](RootKind k, int who) {
      roots[static_cast<std::size_t>(nRoots++)] = RootDesc{k, who};
    };
    for (int i = 0; i < nR; ++i) {
      add(RootKind::EdgeFore, i);
      add(RootKind::EdgeAft, i);
      add(RootKind::OutOfField, i);
      if (cfg.field.field_walls) add(RootKind::Wall, i);
      add(RootKind::Divider, i);
      if (D.r[static_cast<std::size_t>(i)].reflex) add(RootKind::ReflexEnd, i);
    }
    if (nR == 2) add(RootKind::RobotRobot, 0);
    for (int b = 0; b < kMaxBalls; ++b) {
      const Ball& ball = D.balls[static_cast<std::size_t>(b)];
      if (!ball.active) continue;
      if (!ball.rolling) add(RootKind::BallFloor, b);
      if (nR == 2) add(RootKind::BallHit, b);
      add(RootKind::BallOut, b);
      add(RootKind::BallDivider, b);
    }
  }

  void clearStopTime() {
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

  void accumulateStats() {
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
  void reinit(std::int64_t tick, double t0, std::vector<double>& y, bool first = false) {
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
    fresh = true;
    std::copy(y.begin(), y.end(), segY.begin());
    segWheel = wheelTarget;
    segGun = gunTarget;
    buildRoots();
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
  void recordStep(double tret) {
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

  // Time used for tick `tick` inside the current segment.
  double timeOfTick(std::int64_t tick) const { return std::max(secondsFromTick(tick), segT0); }

  // First record whose interval reaches t; past the end, the last one
  // (advance() steps until CVODE has returned a time at or past now(), so
  // at most a rounding of the tick's time).
  const Rec& recordAt(double t) const {
    auto it = std::lower_bound(recs.begin(), recs.end(), t,
                               [](const Rec& r, double tt) { return r.thi < tt; });
    if (it == recs.end()) --it;
    return *it;
  }
  // Component i of the dense output polynomial of record r at time t.
  double component(const Rec& r, double t, int i) const {
    const double dt = t - r.tn;
    double sum = coef[r.off + static_cast<std::size_t>(r.q * n + i)];
    for (int k = r.q - 1; k >= 0; --k)
      sum = sum * dt + coef[r.off + static_cast<std::size_t>(k * n + i)];
    return sum;
  }
  void evalAt(double t, std::vector<double>& out) const {
    const Rec& r = recordAt(t);
    for (int i = 0; i < n; ++i) out[static_cast<std::size_t>(i)] = component(r, t, i);
  }
  // One robot's x, y and heading (rad) at a tick: what the eyes need, at a
  // fraction of evaluating the whole state. Same arithmetic, same bits.
  std::array<double, 3> poseAt(int robot, std::int64_t tick) const {
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

  void checkRobot(int robot) const {
    if (robot < 0 || robot >= nR) throw std::out_of_range("plant: robot index");
  }
  void checkInputTick(std::int64_t tick) const {
    if (tick < segTick || tick > now)
      throw std::out_of_range("plant: input tick outside [last reinit, now]");
  }
  void checkQueryTick(std::int64_t tick) const {
    if (tick < segTick || tick > now)
      throw std::out_of_range("plant: query tick outside [last reinit, now]");
  }
  // State at a tick (after the events of that tick).
  void stateAt(std::int64_t tick, std::vector<double>& out) const {
    checkQueryTick(tick);
    if (pending && tick == pendingTick) {
      out = pendingY;
      return;
    }
    evalAt(timeOfTick(tick), out);
  }
  const Discrete& discreteAt(std::int64_t tick) const {
    return (pending && tick == pendingTick) ? pendingD : D;
  }

  // ------------------------------------------------------------ event processing
  static Bumper sideOf(double headingRad, const Vec2& towards) {
    return geom::headingDir(headingRad).dot(towards) >= 0 ? Bumper::Front : Bumper::Back;
  }

  void startReflex(Discrete& d, const std::vector<double>& y, int i, Bumper side, std::int64_t T,
                   EventList& ev) {
    RobotDisc& r = d.r[static_cast<std::size_t>(i)];
    r.reflex = true;
    r.reflexSide = side;
    r.reflexS0 = y[static_cast<std::size_t>(i * kPerRobot + S)];
    r.reflexTicks.push(T);
    r.eventTicks.push(T);
    Event e{EventKind::ReflexStart};
    e.robot = static_cast<std::int8_t>(i);
    e.bumper = side;
    ev.push(e);
  }

  // Finds the reported crossing direction of a root, 0 if not reported.
  int reported(const int* found, RootKind k, int who) const {
    if (!found) return 0;
    for (int j = 0; j < nRoots; ++j)
      if (roots[static_cast<std::size_t>(j)].kind == k &&
          roots[static_cast<std::size_t>(j)].robot == who)
        return found[j];
    return 0;
  }

  // Applies everything that happens at tick T (time te) to (d, y) and lists
  // the events, in this fixed order: ball launches; ball outcomes (floor,
  // divider, hit, leaving the field -- the floor first, so a ball reaching
  // floor and robot together is a miss, thesis VIII.H); per robot: referee
  // put-back, reflex end; contacts (robot-robot, divider, wall) and the
  // reflexes they start; edge detectors; the referee's turn. A put-back or a
  // turn moves a robot, so contacts and edges are reconciled again after it.
  void process(std::int64_t T, double te, Discrete& d, std::vector<double>& y, const int* found,
               EventList& ev) {
    double* ys = y.data();
    // -- launches
    for (int i = 0; i < nR; ++i) {
      RobotDisc& r = d.r[static_cast<std::size_t>(i)];
      for (int g = 0; g < 2; ++g) {
        if (r.launchTick[static_cast<std::size_t>(g)] < 0 ||
            r.launchTick[static_cast<std::size_t>(g)] > T)
          continue;
        r.launchTick[static_cast<std::size_t>(g)] = -1;
        if (r.ballsLeft[static_cast<std::size_t>(g)] <= 0) continue;
        int slot = -1;
        for (int b = 0; b < kMaxBalls && slot < 0; ++b)
          if (!d.balls[static_cast<std::size_t>(b)].active) slot = b;
        if (slot < 0) throw std::logic_error("plant: the ball table is full (see kMaxBalls)");
        r.ballsLeft[static_cast<std::size_t>(g)]--;
        r.shots++;
        const RobotParams& p = P(i);
        const Vec2 dir = geom::headingDir(heading(ys, i));
        const Vec2 muzzle = centre(ys, i) + radius(i) * dir;  // flush with the body edge (VIII.C)
        const double speed = p.muzzle_speed_fps * ys[i * kPerRobot + (g == 0 ? G1 : G2)] *
                             r.launchFactor[static_cast<std::size_t>(g)];
        Ball& b = d.balls[static_cast<std::size_t>(slot)];
        b = Ball{true,
                 false,
                 i,
                 g,
                 te,
                 muzzle.x(),
                 muzzle.y(),
                 p.launch_height_ft,
                 speed * dir.x(),
                 speed * dir.y()};
        Event e{EventKind::BallLaunch};
        e.robot = static_cast<std::int8_t>(i);
        e.gun = static_cast<std::int8_t>(g);
        e.ball = static_cast<std::int8_t>(slot);
        e.x = b.x0;
        e.y = b.y0;
        e.z = b.z0;
        e.vx = b.vx;
        e.vy = b.vy;
        ev.push(e);
      }
    }
    // -- balls
    for (int s = 0; s < kMaxBalls; ++s) {
      Ball& b = d.balls[static_cast<std::size_t>(s)];
      if (!b.active) continue;
      double x, yy, z;
      ballAt(b, te, x, yy, z);
      if (nR == 2) b.closest = std::min(b.closest, ballGap(b, te, ys));
      Event e{EventKind::BallMiss};
      e.robot = static_cast<std::int8_t>(b.shooter);
      e.gun = static_cast<std::int8_t>(b.gun);
      e.ball = static_cast<std::int8_t>(s);
      e.x = x;
      e.y = yy;
      e.z = z;
      e.closest_ft = nR == 2 ? b.closest : -1;
      if (!b.rolling && (reported(found, RootKind::BallFloor, s) < 0 || z <= 0)) {
        if (cfg.field.count_floor_skips) {
          // Appendix A counts skips: the ball goes on along the floor
          // (assumption) and can still hit.
          const double dt = std::sqrt(2 * b.z0 / cfg.field.gravity_fps2);
          b.x0 += b.vx * dt;
          b.y0 += b.vy * dt;
          b.t0 += dt;
          b.rolling = true;
          z = 0;
          Event skip = e;
          skip.kind = EventKind::BallSkip;
          skip.x = b.x0;
          skip.y = b.y0;
          skip.z = 0;
          ev.push(skip);
        } else {
          e.miss = MissReason::Floor;
          ev.push(e);
          b.active = false;
          continue;
        }
      }
      const bool inSlab =
          std::abs(x - cfg.field.divider_x_ft) <= cfg.field.divider_thickness_ft / 2 ||
          reported(found, RootKind::BallDivider, s) > 0;
      if (inSlab && yy >= cfg.field.divider_south_ft && yy <= cfg.field.divider_north_ft &&
          z <= cfg.field.divider_height_ft) {
        e.miss = MissReason::Divider;
        ev.push(e);
        b.active = false;
        continue;
      }
      if (nR == 2) {
        double p2, d2;
        ballHitG(b, te, ys, p2, d2);
        const int tgt = 1 - b.shooter;
        const double R = radius(tgt);
        const bool crossed = reported(found, RootKind::BallHit, s) > 0 && p2 <= R * R;
        if ((crossed || d2 <= R * R) && z <= P(tgt).target_height_ft) {
          Event h = e;
          h.kind = EventKind::BallHit;
          h.other = static_cast<std::int8_t>(tgt);
          ev.push(h);
          d.r[static_cast<std::size_t>(b.shooter)].hits++;
          b.active = false;
          continue;
        }
      }
      if (reported(found, RootKind::BallOut, s) < 0 || ballOutG(b, te) < 0) {
        e.miss = MissReason::LeftField;
        ev.push(e);
        b.active = false;
      }
    }
    // -- robots
    bool moved = false;
    for (int i = 0; i < nR; ++i) {
      RobotDisc& r = d.r[static_cast<std::size_t>(i)];
      double* ry = ys + i * kPerRobot;
      if (reported(found, RootKind::OutOfField, i) < 0 || outG(ys, i) < 0) {
        const double hb = wireHalf - cfg.referee.putback_ft;
        ry[X] = std::clamp(ry[X], -hb, hb);
        ry[Y] = std::clamp(ry[Y], -hb, hb);
        Event e{EventKind::RefereePutBack};
        e.robot = static_cast<std::int8_t>(i);
        ev.push(e);
        moved = true;
      }
      if (r.reflex && (reported(found, RootKind::ReflexEnd, i) > 0 || reflexG(ys, i, d) >= 0)) {
        r.reflex = false;
        Event e{EventKind::ReflexEnd};
        e.robot = static_cast<std::int8_t>(i);
        e.bumper = r.reflexSide;
        ev.push(e);
      }
    }
    for (int pass = 0; pass < 3; ++pass) {
      const int* f = pass == 0 ? found : nullptr;
      contacts(T, d, y, f, ev);
      edges(d, y, f, ev);
      bool turned = false;
      for (int i = 0; i < nR; ++i) turned = refereeTurn(T, d, y, i, ev) || turned;
      if (!turned && !(moved && pass == 0)) break;
      moved = false;
    }
  }

  // Thesis VI.D auto_ref: more than reflex_limit bumper reflexes, or more
  // than event_limit reflexes and edge-handler entries, within the window
  // turn the robot by turn_deg and start the count again.
  bool refereeDue(const RobotDisc& r, std::int64_t T) const {
    const std::int64_t from = T - timebase::ticksFromSeconds(cfg.referee.window_s);
    return r.reflexTicks.countSince(from) > cfg.referee.reflex_limit ||
           r.eventTicks.countSince(from) > cfg.referee.event_limit;
  }
  bool refereeTurn(std::int64_t T, Discrete& d, std::vector<double>& y, int i, EventList& ev) {
    RobotDisc& r = d.r[static_cast<std::size_t>(i)];
    if (!refereeDue(r, T)) return false;
    y[static_cast<std::size_t>(i * kPerRobot + H)] += geom::degToRad(cfg.referee.turn_deg);
    r.reflexTicks.n = 0;
    r.eventTicks.n = 0;
    Event e{EventKind::RefereeTurn};
    e.robot = static_cast<std::int8_t>(i);
    ev.push(e);
    return true;
  }

  void contacts(std::int64_t T, Discrete& d, std::vector<double>& y, const int* found,
                EventList& ev) {
    const double* ys = y.data();
    auto contactEvent = [&](EventKind k, int i, Bumper b, ContactWith w, int other) {
      Event e{k};
      e.robot = static_cast<std::int8_t>(i);
      e.bumper = b;
      e.with = w;
      e.other = static_cast<std::int8_t>(other);
      ev.push(e);
    };
    if (nR == 2) {
      const int rep = reported(found, RootKind::RobotRobot, 0);
      const bool c = rep != 0 ? rep < 0 : robotG(ys) < 0;
      if (c && !d.robotContact) {
        for (int i = 0; i < 2; ++i) {
          const Bumper side = sideOf(heading(ys, i), centre(ys, 1 - i) - centre(ys, i));
          contactEvent(EventKind::Contact, i, side, ContactWith::Robot, 1 - i);
          startReflex(d, y, i, side, T, ev);
        }
      } else if (!c && d.robotContact) {
        for (int i = 0; i < 2; ++i)
          contactEvent(EventKind::ContactEnd, i, Bumper::Front, ContactWith::Robot, 1 - i);
      }
      d.robotContact = c;
    }
    // A robot against a fixed obstacle: contact starts (the bumper on the
    // side facing `towards`, and its reflex) or ends where g changes sign.
    auto obstacle = [&](int i, RootKind k, double g, bool& touching, ContactWith with,
                        const Vec2& towards) {
      const int rep = reported(found, k, i);
      const bool c = rep != 0 ? rep < 0 : g < 0;
      if (c && !touching) {
        const Bumper side = sideOf(heading(ys, i), towards);
        contactEvent(EventKind::Contact, i, side, with, -1);
        startReflex(d, y, i, side, T, ev);
      } else if (!c && touching) {
        contactEvent(EventKind::ContactEnd, i, Bumper::Front, with, -1);
      }
      touching = c;
    };
    for (int i = 0; i < nR; ++i) {
      RobotDisc& r = d.r[static_cast<std::size_t>(i)];
      const Vec2 cc = centre(ys, i);
      obstacle(i, RootKind::Divider, dividerG(ys, i), r.dividerContact, ContactWith::Divider,
               geom::closestPointOnRect(cc, geom::dividerRect(cfg.field)) - cc);
      if (cfg.field.field_walls) {
        const Vec2 normal = std::abs(cc.x()) >= std::abs(cc.y()) ? Vec2(cc.x() >= 0 ? 1 : -1, 0)
                                                                 : Vec2(0, cc.y() >= 0 ? 1 : -1);
        obstacle(i, RootKind::Wall, wallG(ys, i), r.wallContact, ContactWith::Wall, normal);
      }
    }
  }

  void edges(Discrete& d, std::vector<double>& y, const int* found, EventList& ev) {
    for (int i = 0; i < nR; ++i) {
      RobotDisc& r = d.r[static_cast<std::size_t>(i)];
      for (int k = 0; k < 2; ++k) {
        const int rep = reported(found, k == 0 ? RootKind::EdgeFore : RootKind::EdgeAft, i);
        const bool low = rep != 0 ? rep < 0 : edgeG(y.data(), i, k) < 0;
        if (low == r.edgeLow[static_cast<std::size_t>(k)]) continue;
        r.edgeLow[static_cast<std::size_t>(k)] = low;
        Event e{low ? EventKind::EdgeEnter : EventKind::EdgeLeave};
        e.robot = static_cast<std::int8_t>(i);
        e.detector = k == 0 ? Detector::Fore : Detector::Aft;
        ev.push(e);
        // Not counted for the referee: a crossing counts only when the
        // program's edge handler is entered (edgeHandlerEntered).
      }
    }
  }

  // ------------------------------------------------------------ protocol
  void commit() {
    if (!pending) return;
    pending = false;
    D = pendingD;
    reinit(pendingTick, pendingTime, pendingY);
  }

  // Brings the plant to tick c for an input that changes it; returns the
  // state at c in tmp.
  void rewindTo(std::int64_t c) {
    if (pending && c == pendingTick) {
      commit();
    } else {
      checkInputTick(c);
      pending = false;
    }
    evalAt(timeOfTick(c), tmp);
  }

  bool launchesDue(std::int64_t T) const {
    for (int i = 0; i < nR; ++i)
      for (std::int64_t lt : D.r[static_cast<std::size_t>(i)].launchTick)
        if (lt >= 0 && lt <= T) return true;
    return false;
  }
  std::int64_t nextLaunch() const { return nextLaunchIn(D); }
  std::int64_t nextLaunchIn(const Discrete& d) const {
    std::int64_t best = -1;
    for (int i = 0; i < nR; ++i)
      for (std::int64_t lt : d.r[static_cast<std::size_t>(i)].launchTick)
        if (lt >= 0 && (best < 0 || lt < best)) best = lt;
    return best;
  }

  // DESIGN.md: an event happens at the first integer tick at which its root
  // function has crossed. CVODE returns the right end of its root bracket,
  // a hair past the crossing, so T0 = ceil(tret) is one tick late when the
  // crossing falls exactly on tick T0 - 1 (a contact at constant speed, a
  // reflex of exactly 1.5 ft at 1.5 ft/s). Decide from dense output at the
  // two neighbouring ticks: T0 - 1 if a reported root function is already
  // on its new side there, or within kOnTickFraction of a tick of it
  // (linearly between the ticks), which round-off cannot tell from zero.
  std::int64_t crossedTick(std::int64_t T0) {
    const std::int64_t k = T0 - 1;
    if (k <= segTick) return T0;  // the segment's first tick is not a crossing
    const double tk = secondsFromTick(k), tT = secondsFromTick(T0);
    evalAt(tk, tmp);
    evalAt(tT, qtmp);
    for (int j = 0; j < nRoots; ++j) {
      const int dir = rootsFound[static_cast<std::size_t>(j)];
      if (dir == 0) continue;
      const RootDesc& rd = roots[static_cast<std::size_t>(j)];
      const double gk = rootValue(rd, tk, tmp.data());
      const double gT = rootValue(rd, tT, qtmp.data());
      if (dir * gk >= 0 || std::abs(gk) <= kOnTickFraction * std::abs(gT - gk)) return k;
    }
    return T0;
  }

  // Computes the events at T (time te) from the current segment's state
  // into pendingD/pendingY and ev; true if there are any. Does not make
  // them pending.
  bool eventsAt(std::int64_t T, double te, const int* found, EventList& ev) {
    evalAt(te, pendingY);
    pendingD = D;
    ev.clear();
    process(T, te, pendingD, pendingY, found, ev);
    if (ev.empty())  // nothing happens here, but a ball may pass closest to its target
      for (int s = 0; s < kMaxBalls; ++s)
        D.balls[static_cast<std::size_t>(s)].closest =
            pendingD.balls[static_cast<std::size_t>(s)].closest;
    return !ev.empty();
  }

  // Computes the events at T (time te) from the current segment's state;
  // if there are any, keeps them pending and returns true.
  bool predict(std::int64_t T, double te, const int* found, EventList& ev) {
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
  void retreat(std::int64_t tick) {
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

  AdvanceResult advance(std::int64_t stopTick) {
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
};

// ---------------------------------------------------------------- Arena

Arena::Arena(const ArenaConfig& config) : impl_(std::make_unique<Impl>(config)) {}
Arena::~Arena() = default;

int Arena::robotCount() const { return impl_->nR; }
std::int64_t Arena::now() const { return impl_->now; }
std::int64_t Arena::lastReinitTick() const { return impl_->segTick; }

bool Arena::setWheels(int robot, const MotorFrame& frame, std::int64_t tick) {
  Impl& m = *impl_;
  m.checkRobot(robot);
  m.checkInputTick(tick);
  const bool committedAtTick = m.pending && tick == m.pendingTick;
  const Discrete& cur = committedAtTick ? m.pendingD : m.D;
  const RobotDisc& r = cur.r[static_cast<std::size_t>(robot)];
  if (r.latched == frame) return false;
  const RobotParams& p = m.P(robot);
  const bool sameSpeeds =
      wheelSpeedFps(r.latched.left, p, true) == wheelSpeedFps(frame.left, p, true) &&
      wheelSpeedFps(r.latched.right, p, false) == wheelSpeedFps(frame.right, p, false);
  if (r.reflex || r.driven || sameSpeeds) {
    // The reflex overrides motor strings, and the frame takes effect when it
    // ends; a scripted drive overrides them for good. Either way the
    // right-hand side is unchanged: no reinit.
    m.D.r[static_cast<std::size_t>(robot)].latched = frame;
    if (m.pending) m.pendingD.r[static_cast<std::size_t>(robot)].latched = frame;
    return true;
  }
  m.rewindTo(tick);
  m.D.r[static_cast<std::size_t>(robot)].latched = frame;
  m.reinit(tick, m.timeOfTick(tick), m.tmp);
  return true;
}

bool Arena::setDrive(int robot, double leftFps, double rightFps, std::int64_t tick) {
  Impl& m = *impl_;
  m.checkRobot(robot);
  m.checkInputTick(tick);
  const bool committedAtTick = m.pending && tick == m.pendingTick;
  const RobotDisc& r = (committedAtTick ? m.pendingD : m.D).r[static_cast<std::size_t>(robot)];
  const std::array<double, 2> drive{leftFps, rightFps};
  if (r.driven && r.drive == drive) return false;
  if (r.reflex) {
    // The reflex overrides the drive as it does motor strings.
    for (Discrete* d : {&m.D, &m.pendingD}) {
      d->r[static_cast<std::size_t>(robot)].driven = true;
      d->r[static_cast<std::size_t>(robot)].drive = drive;
    }
    return true;
  }
  m.rewindTo(tick);
  m.D.r[static_cast<std::size_t>(robot)].driven = true;
  m.D.r[static_cast<std::size_t>(robot)].drive = drive;
  m.reinit(tick, m.timeOfTick(tick), m.tmp);
  return true;
}

EventList Arena::setPortB(int robot, std::uint8_t value, std::int64_t tick, RandomBits* gunLuck,
                          RandomBits* muzzle) {
  Impl& m = *impl_;
  EventList ev;
  m.checkRobot(robot);
  m.checkInputTick(tick);
  if (m.pending && tick == m.pendingTick) m.commit();
  const RobotDisc& old = m.D.r[static_cast<std::size_t>(robot)];
  if (old.portB == value) return ev;
  const Hardware& hw = m.cfg.robots[static_cast<std::size_t>(robot)].hardware;
  const RobotParams& p = m.P(robot);
  auto bit = [](std::uint8_t v, int b) { return ((v >> b) & 1) != 0; };

  RobotDisc next = old;
  next.portB = value;
  bool rhsChanges = false, scheduleChanges = false;
  for (int g = 0; g < 2; ++g) {
    const bool on = bit(value, hw.gun_motor_bit[static_cast<std::size_t>(g)]);
    if (on != old.gunOn[static_cast<std::size_t>(g)] && !p.gun_motors_always_on) rhsChanges = true;
    next.gunOn[static_cast<std::size_t>(g)] = on;
    const int sb = hw.gun_solenoid_bit[static_cast<std::size_t>(g)];
    if (bit(value, sb) && !bit(old.portB, sb)) {
      Event e{EventKind::SolenoidStroke};
      e.robot = static_cast<std::int8_t>(robot);
      e.gun = static_cast<std::int8_t>(g);
      const double jam = p.jam_probability, misfire = p.misfire_probability;
      if (old.ballsLeft[static_cast<std::size_t>(g)] <= 0) {
        e.kind = EventKind::GunEmpty;
      } else if (old.gunJammed[static_cast<std::size_t>(g)]) {
        e.kind = EventKind::GunJammed;
      } else if (old.launchTick[static_cast<std::size_t>(g)] >= 0) {
        // A stroke already under way ignores the new edge.
      } else if (const double u = gunLuck && (jam > 0 || misfire > 0) ? unit53(gunLuck->next()) : 1;
                 u < jam) {
        e.kind = EventKind::GunJammed;
        next.gunJammed[static_cast<std::size_t>(g)] = true;
      } else if (u < jam + misfire) {
        e.kind = EventKind::GunMisfire;
      } else {
        next.launchTick[static_cast<std::size_t>(g)] =
            tick + timebase::ticksFromSeconds(p.stroke_s);
        next.launchFactor[static_cast<std::size_t>(g)] = muzzleFactor(p, muzzle);
        scheduleChanges = true;
      }
      ev.push(e);
    }
  }
  if (bit(value, hw.disc_shooter_bit) && !bit(old.portB, hw.disc_shooter_bit)) {
    Event e{EventKind::DiscShooter};
    e.robot = static_cast<std::int8_t>(robot);
    ev.push(e);
  }
  if (!rhsChanges && !scheduleChanges) {
    // Nothing that moves changes: the prediction stays valid.
    for (Discrete* d : {&m.D, &m.pendingD}) {
      d->r[static_cast<std::size_t>(robot)].portB = value;
      d->r[static_cast<std::size_t>(robot)].gunJammed = next.gunJammed;
    }
    return ev;
  }
  m.rewindTo(tick);
  m.D.r[static_cast<std::size_t>(robot)] = next;
  m.reinit(tick, m.timeOfTick(tick), m.tmp);
  return ev;
}

EventList Arena::triggerReflex(int robot, Bumper side, std::int64_t tick) {
  Impl& m = *impl_;
  EventList ev;
  m.checkRobot(robot);
  m.rewindTo(tick);
  m.startReflex(m.D, m.tmp, robot, side, tick, ev);
  m.reinit(tick, m.timeOfTick(tick), m.tmp);
  return ev;
}

EventList Arena::edgeHandlerEntered(int robot, std::int64_t tick) {
  Impl& m = *impl_;
  EventList ev;
  m.checkRobot(robot);
  m.checkInputTick(tick);
  if (m.pending && tick == m.pendingTick) m.commit();
  const auto i = static_cast<std::size_t>(robot);
  RobotDisc& r = m.D.r[i];
  // The prediction at a later tick stays valid unless it counted events of
  // this robot itself (its referee check there did not see this entry).
  const bool keep = !m.pending || (m.pendingD.r[i].eventTicks.n == r.eventTicks.n &&
                                   m.pendingD.r[i].eventTicks.t == r.eventTicks.t);
  r.eventTicks.push(tick);
  if (!m.refereeDue(r, tick)) {
    if (m.pending) {
      if (keep) {
        m.pendingD.r[i].eventTicks.push(tick);
      } else {
        m.rewindTo(tick);
        m.reinit(tick, m.timeOfTick(tick), m.tmp);
      }
    }
    return ev;
  }
  m.rewindTo(tick);
  m.refereeTurn(tick, m.D, m.tmp, robot, ev);
  // The turn moves the robot: contacts and edges are reconciled after it,
  // as after a turn at a plant event (process()).
  for (int pass = 0; pass < 3; ++pass) {
    m.contacts(tick, m.D, m.tmp, nullptr, ev);
    m.edges(m.D, m.tmp, nullptr, ev);
    bool turned = false;
    for (int j = 0; j < m.nR; ++j) turned = m.refereeTurn(tick, m.D, m.tmp, j, ev) || turned;
    if (!turned) break;
  }
  m.reinit(tick, m.timeOfTick(tick), m.tmp);
  return ev;
}

AdvanceResult Arena::advance(std::int64_t stopTick) { return impl_->advance(stopTick); }
void Arena::retreat(std::int64_t tick) { impl_->retreat(tick); }

bool Arena::ballsInFlight() const {
  const Impl& m = *impl_;
  for (const Discrete* d : {&m.D, &m.pendingD}) {
    if (d == &m.pendingD && !m.pending) break;
    for (const Ball& b : d->balls)
      if (b.active) return true;
    if (m.nextLaunchIn(*d) >= 0) return true;
  }
  return false;
}

RobotState Arena::state(int robot, std::int64_t tick) const {
  const Impl& m = *impl_;
  m.checkRobot(robot);
  std::vector<double>& y = m.qtmp;
  m.stateAt(tick, y);
  const double* r = y.data() + robot * kPerRobot;
  RobotState s;
  s.pose = Pose{r[X], r[Y], geom::wrap360(geom::radToDeg(r[H]))};
  s.left_fps = r[VL];
  s.right_fps = r[VR];
  s.odometer_ft = r[S];
  s.gun_wheel = {r[G1], r[G2]};
  return s;
}

Pose Arena::pose(int robot, std::int64_t tick) const {
  const Impl& m = *impl_;
  m.checkRobot(robot);
  const auto [x, y, h] = m.poseAt(robot, tick);
  return Pose{x, y, geom::wrap360(geom::radToDeg(h))};
}

bool Arena::edgeDetectorLow(int robot, Detector d, std::int64_t tick) const {
  const Impl& m = *impl_;
  m.checkQueryTick(tick);
  return m.discreteAt(tick).r[static_cast<std::size_t>(robot)].edgeLow[static_cast<std::size_t>(d)];
}

EyeReadings Arena::eyeReadings(int robot, std::int64_t tick, RandomBits* noise,
                               EyeChannels channels) const {
  const Impl& m = *impl_;
  const Pose self = pose(robot, tick);
  if (m.nR < 2) return computeEyes(self, nullptr, m.P(robot), m.cfg.field, noise, channels);
  const Pose other = pose(1 - robot, tick);
  return computeEyes(self, &other, m.P(robot), m.cfg.field, noise, channels);
}

std::vector<BallView> Arena::balls(std::int64_t tick) const {
  const Impl& m = *impl_;
  m.checkQueryTick(tick);
  const Discrete& d = m.discreteAt(tick);
  const double t = (m.pending && tick == m.pendingTick) ? m.pendingTime : m.timeOfTick(tick);
  std::vector<BallView> out;
  for (int s = 0; s < kMaxBalls; ++s) {
    const Ball& b = d.balls[static_cast<std::size_t>(s)];
    if (!b.active) continue;
    BallView v;
    v.shooter = b.shooter;
    v.gun = b.gun;
    v.slot = s;
    m.ballAt(b, t, v.x_ft, v.y_ft, v.z_ft);
    out.push_back(v);
  }
  return out;
}

bool Arena::inReflex(int robot) const {
  const Impl& m = *impl_;
  return m.discreteAt(m.now).r[static_cast<std::size_t>(robot)].reflex;
}
int Arena::ballsLeft(int robot, int gun) const {
  const Impl& m = *impl_;
  return m.discreteAt(m.now)
      .r[static_cast<std::size_t>(robot)]
      .ballsLeft[static_cast<std::size_t>(gun)];
}
int Arena::shots(int robot) const {
  const Impl& m = *impl_;
  return m.discreteAt(m.now).r[static_cast<std::size_t>(robot)].shots;
}
int Arena::hits(int robot) const {
  const Impl& m = *impl_;
  return m.discreteAt(m.now).r[static_cast<std::size_t>(robot)].hits;
}

IntegratorStats Arena::stats() const {
  Impl& m = *impl_;
  IntegratorStats s = m.acc;
  long v = 0;
  CVodeGetNumSteps(m.mem.get(), &v);
  s.steps += v;
  CVodeGetNumRhsEvals(m.mem.get(), &v);
  s.rhs_evals += v;
  CVodeGetNumLinRhsEvals(m.mem.get(), &v);
  s.rhs_evals += v;
  return s;
}

const char* eventKindName(EventKind k) {
  switch (k) {
    case EventKind::EdgeEnter:
      return "edge_enter";
    case EventKind::EdgeLeave:
      return "edge_leave";
    case EventKind::Contact:
      return "contact";
    case EventKind::ContactEnd:
      return "contact_end";
    case EventKind::ReflexStart:
      return "reflex_start";
    case EventKind::ReflexEnd:
      return "reflex_end";
    case EventKind::BallLaunch:
      return "ball_launch";
    case EventKind::BallHit:
      return "ball_hit";
    case EventKind::BallMiss:
      return "ball_miss";
    case EventKind::BallSkip:
      return "ball_skip";
    case EventKind::RefereePutBack:
      return "referee_put_back";
    case EventKind::RefereeTurn:
      return "referee_turn";
    case EventKind::SolenoidStroke:
      return "solenoid_stroke";
    case EventKind::GunEmpty:
      return "gun_empty";
    case EventKind::GunMisfire:
      return "gun_misfire";
    case EventKind::GunJammed:
      return "gun_jammed";
    case EventKind::DiscShooter:
      return "disc_shooter";
  }
  return "?";
}

}  // namespace simbot::plant
