// plant/arena_impl.h -- internal: Arena::Impl, shared by the arena's files.
//
// The arena's implementation is split by job (the design is in arena.cpp's
// header comment): arena.cpp is the protocol with the scheduler (the public
// Arena methods: inputs, advance/retreat, queries), arena_integrator.cpp the
// CVODE set-up, right-hand side, re-initialisation, dense output and the
// stepping loop, arena_roots.cpp the root functions and the geometry they
// evaluate on a state, arena_events.cpp the event rules applied at an
// event's tick. This header holds the state all of them share and the
// one-line helpers; nothing outside plant/ includes it.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "plant/cvode.h"
#include "plant/geometry.h"
#include "plant/plant.h"

namespace simbot::plant {

using geom::Vec2;

namespace arena_detail {

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

}  // namespace arena_detail

using namespace arena_detail;

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
  // The root functions whose crossings were events at tick firedTick (over
  // every re-initialisation at that tick): crossedTick() never puts
  // another crossing of one of them there.
  std::int64_t firedTick = -1;
  std::array<RootDesc, kMaxRoots> fired{};
  int nFired = 0;
  void noteFired(std::int64_t tick, const int* found);
  bool firedAt(std::int64_t tick, const RootDesc& rd) const;
  int nRoots = 0;
  int nRootsRegistered = -1;
  std::array<double, kMaxRoots> rootShift{};
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

  explicit Impl(const ArenaConfig& c);

  // ------------------------------------------------------------ parameters
  const RobotParams& P(int i) const { return cfg.robots[static_cast<std::size_t>(i)].params; }
  double radius(int i) const { return P(i).body_diameter_ft / 2; }

  double maxStep() const;
  bool atRest(const std::vector<double>& y) const;
  double maxStepSet = -1;  // the value last given to CVodeSetMaxStep

  // ------------------------------------------------------------ geometry on a
  // state
  static Vec2 centre(const double* y, int i) {
    return Vec2(y[i * kPerRobot + X], y[i * kPerRobot + Y]);
  }
  static double heading(const double* y, int i) { return y[i * kPerRobot + H]; }

  Vec2 detector(const double* y, int i, int k) const;
  double edgeG(const double* y, int i, int k) const;
  double outG(const double* y, int i) const;
  double wallG(const double* y, int i) const { return outG(y, i) - radius(i); }
  double dividerG(const double* y, int i) const;
  double robotG(const double* y) const;
  double reflexG(const double* y, int i, const Discrete& d) const;

  void ballAt(const Ball& b, double t, double& x, double& yy, double& z) const;
  double ballHitG(const Ball& b, double t, const double* y, double& perp2, double& dist2) const;
  double ballGap(const Ball& b, double t, const double* y) const;
  double ballOutG(const Ball& b, double t) const;
  double ballDividerG(const Ball& b, double t) const;

  double rootValue(const RootDesc& rd, double t, const double* y) const;
  // Root j of the list as CVODE, crossedTick() and the event rules see it
  // in this segment: shifted by rootShift[j] (arena_roots.cpp, "Sided
  // roots").
  double sidedValue(int j, double t, const double* y) const {
    return rootValue(roots[static_cast<std::size_t>(j)], t, y) -
           rootShift[static_cast<std::size_t>(j)];
  }
  // g, a value of root function (k, who), shifted as that root is in this
  // segment's list (unshifted if it is not listed).
  double sided(RootKind k, int who, double g) const;
  // Root function (k, who)'s index in this segment's list, or -1.
  int rootIndex(RootKind k, int who) const;
  void sideRoots(double t0, const std::vector<double>& y);

  // ------------------------------------------------------------ CVODE
  // callbacks
  static int rhsThunk(sunrealtype t, N_Vector y, N_Vector ydot, void* user) {
    static_cast<Impl*>(user)->rhs(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot));
    return 0;
  }
  static int rootThunk(sunrealtype t, N_Vector y, sunrealtype* g, void* user);

  void rhs(double, const double* y, double* f) const;

  // A gun wheel spins up under its motor and coasts down, more slowly,
  // when the motor is off (DESIGN.md "Guns"): the time constant follows
  // the motor, not the direction of change.
  static double gunTau(const RobotParams& p, double target) {
    return target > 0 ? p.gun_wheel_lag_s : p.gun_wheel_coast_s;
  }

  void computeTargets(const Discrete& d);
  void applyJumps(std::vector<double>& y) const;

  void buildRoots();

  void clearStopTime();

  void accumulateStats();

  void reinit(std::int64_t tick, double t0, std::vector<double>& y, bool first = false);

  void recordStep(double tret);

  // Time used for tick `tick` inside the current segment.
  double timeOfTick(std::int64_t tick) const { return std::max(secondsFromTick(tick), segT0); }

  const Rec& recordAt(double t) const;
  double component(const Rec& r, double t, int i) const;
  void evalAt(double t, std::vector<double>& out) const {
    const Rec& r = recordAt(t);
    for (int i = 0; i < n; ++i) out[static_cast<std::size_t>(i)] = component(r, t, i);
  }
  std::array<double, 3> poseAt(int robot, std::int64_t tick) const;

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
  void stateAt(std::int64_t tick, std::vector<double>& out) const;
  const Discrete& discreteAt(std::int64_t tick) const {
    return (pending && tick == pendingTick) ? pendingD : D;
  }

  static Bumper sideOf(double headingRad, const Vec2& towards);

  void startReflex(Discrete& d, const std::vector<double>& y, int i, Bumper side, std::int64_t T,
                   EventList& ev);

  int reported(const int* found, RootKind k, int who) const;

  void process(std::int64_t T, double te, Discrete& d, std::vector<double>& y, const int* found,
               EventList& ev);

  bool refereeDue(const RobotDisc& r, std::int64_t T) const;
  bool refereeTurn(std::int64_t T, Discrete& d, std::vector<double>& y, int i, EventList& ev);

  void contacts(std::int64_t T, Discrete& d, std::vector<double>& y, const int* found,
                EventList& ev);

  void edges(Discrete& d, std::vector<double>& y, const int* found, EventList& ev);

  void commit();

  void rewindTo(std::int64_t c);

  bool launchesDue(std::int64_t T) const;
  std::int64_t nextLaunch() const { return nextLaunchIn(D); }
  std::int64_t nextLaunchIn(const Discrete& d) const;

  std::int64_t crossedTick(std::int64_t T0);

  bool eventsAt(std::int64_t T, double te, const int* found, EventList& ev);

  bool predict(std::int64_t T, double te, const int* found, EventList& ev);

  void retreat(std::int64_t tick);

  AdvanceResult advance(std::int64_t stopTick);
};

}  // namespace simbot::plant
