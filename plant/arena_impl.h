// plant/arena_impl.h -- internal: Arena::Impl, shared by the arena's files.
//
// The arena's implementation is split by job (the design is in arena.cpp's
// header comment): arena.cpp is the protocol with the scheduler (the public
// Arena methods: inputs, advance/retreat, queries), arena_integrator.cpp the
// ARKODE set-up, right-hand side, re-initialisation, dense output and the
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

#include "plant/arena_journal.h"
#include "plant/arkode.h"
#include "plant/contact.h"
#include "plant/geometry.h"
#include "plant/last_call.h"
#include "plant/plant.h"

namespace simbot::plant {

using geom::Vec2;

namespace arena_detail {

// A robot's full state as the event rules, roots and queries see it. Only
// X and Y are integrated (kXY a robot); the rest is closed form (Motion).
constexpr int kPerRobot = 8;
enum : int { X = 0, Y = 1, H = 2, VL = 3, VR = 4, S = 5, G1 = 6, G2 = 7 };
constexpr int kXY = 2;
// Every ball two robots with two full magazines can have in flight: balls
// are never reloaded, so a launch always finds a free slot.
constexpr int kMaxBalls = 64;
static_assert(kMaxBalls >= 2 * 2 * kMaxBallsPerGun, "the ball table must hold every magazine");
// Every disc two launchers with full magazines can have in flight.
constexpr int kMaxDiscs = 2 * kMaxDiscsPerLauncher;
// Per robot 7, one per obstacle and one per block, the pair's contact, per
// ball 6, per disc 2, per block pushed 1.
constexpr int kMaxRoots =
    2 * (7 + kMaxObstacles + kMaxBlocks) + 1 + kMaxBalls * 6 + kMaxDiscs * 2 + kMaxBlocks;
constexpr int kRing = 16;
static_assert(kRing > kMaxRefereeLimit, "the referee must see one event more than its limit");
// ARKODE's tout in its one-step mode only bounds the first step's guess
// after creation; a fixed horizon keeps it independent of the caller.
constexpr double kFirstStepHorizon = 1.0;  // s
constexpr double kNoStopTime = 1e12;       // s, far beyond any match
// A crossing this close after a tick (in ticks) is taken as on the tick.
// Round-off in a root function is far smaller: an odometer of 300 ft has an
// ulp of 6e-14 ft, top speed moves 1.6e-7 ft per tick; ARKODE's root
// tolerance (100 ulp of t) is 3e-6 tick after 3 minutes.
constexpr double kOnTickFraction = 1.0 / 1024;

enum class RootKind : std::uint8_t {
  EdgeFore,
  EdgeAft,
  OutOfField,
  // Contacts (contact.h): while inactive the gap to the obstacle, while
  // active minus the contact's force; negative exactly while touching.
  WallX,
  WallY,
  Divider,
  ReflexEnd,
  RobotRobot,
  BallFloor,
  BallHit,
  BallOut,
  BallDivider,
  // A ball above the other robot's height: z - target height. Only for a
  // ball that rises above it (elevation dispersion): its descent through
  // that height over the body is a hit on the top of the cylinder.
  BallTop,
  // A disc (arena_discs.cpp): the path left to its end (sEnd - s(t)), and
  // the hit function of a ball with the target's radius grown by the
  // disc's.
  DiscEnd,
  DiscHit,
  // A robot against an obstacle (a contact, as WallX to Divider).
  Obstacle,
  // A ball that meets an obstacle: the time it does (closed form, found at
  // its launch) less t. Only for a ball that meets one.
  BallObstacle,
  // A robot and a block on the field (arena_blocks.cpp): as Obstacle while
  // the block rests (its gap, or minus the force of a rigid contact); while
  // the robot pushes it, the larger of the robot's free speed along the
  // push's normal and its gap less kPushSlipFt, negative while it pushes.
  Block,
  // A block being pushed: how far it can still go before it meets
  // something (its reach at the push's start less its travel).
  BlockStop,
};

struct RootDesc {
  RootKind kind;
  int robot;  // or ball slot for ball roots; for Obstacle obstacleRoot()
};
// The `robot` of robot i's root against obstacle o.
constexpr int obstacleRoot(int robot, int obstacle) { return robot * kMaxObstacles + obstacle; }
// The `robot` of robot i's root against block b.
constexpr int blockRoot(int robot, int block) { return robot * kMaxBlocks + block; }
// A block's rigid contact is contact.h's Obstacle constraint of this index.
constexpr int blockObstacle(int block) { return kMaxObstacles + block; }

// A block on the field (arena_blocks.cpp): a box that translates, never
// turns. Resting, its centre is (x, y); while robot `pusher` pushes it, it
// is (x, y) + n ((p - p0) . n), p the pusher's centre and p0 that centre at
// the push's start: it follows the pusher's motion along the contact
// normal n (unit, from the block towards the pusher) and nothing else.
struct Block {
  int item = 0;   // its index in ArenaState::deployed
  int robot = 0;  // who set it down
  double x = 0, y = 0;
  double ax = 1, ay = 0;  // its width axis (unit): the releasing robot's right
  double halfWidth = 0, halfDepth = 0, height = 0;
  double load = 0;  // mass (lb) times floor friction: F / g
  int pusher = -1;
  double nx = 0, ny = 0, px = 0, py = 0;
  // How far the push can move it (ft) before it touches a wall, the
  // divider, an obstacle or another block (`stopWith`, `stopIndex`).
  double reach = HUGE_VAL;
  ContactWith stopWith = ContactWith::None;
  int stopIndex = -1;
};

struct Ball {
  bool active = false;
  bool rolling = false;  // after the floor, only with count_floor_skips
  int shooter = 0, gun = 0;
  double t0 = 0;
  double x0 = 0, y0 = 0, z0 = 0, vx = 0, vy = 0, vz = 0;
  // Smallest distance to the other robot's body seen at an event tick or
  // at the closest-approach root of the hit function (for ball_miss).
  double closest = HUGE_VAL;
  // The first obstacle its flight meets below the obstacle's height and
  // when (s), from the closed form (ballMeetsObstacle); -1: none.
  int meetObstacle = -1;
  double meetT = HUGE_VAL;
};

// A disc in flight (arena_discs.cpp): its centre moves from (x0, y0) along
// the unit vector (ux, uy) by s(t) = v0 tau (1 - e^{-(t - t0)/tau}), flat
// at height z, and its flight ends at path length sEnd (a wall, the
// divider, or its stop speed: `end`) unless it hits a robot first.
struct Disc {
  bool active = false;
  int shooter = 0;
  double t0 = 0;
  double x0 = 0, y0 = 0, z = 0, ux = 0, uy = 0;
  double v0 = 0, tau = 1, radius = 0;
  double sEnd = 0;
  MissReason end = MissReason::None;
  std::int8_t obstacle = -1;  // the obstacle it ends on (end == Obstacle)
  // As Ball::closest.
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
  // Touching the east or west wall, the north or south wall, the divider:
  // the contact's constraint is active (contact.h).
  std::array<bool, 2> wallContact{};
  bool dividerContact = false;
  std::array<bool, kMaxObstacles> obstacleContact{};
  // Touching block b: pushing it (Block::pusher) or rigidly (a contact.h
  // Obstacle constraint, blockObstacle(b)).
  std::array<bool, kMaxBlocks> blockContact{};
  double pushedFt = 0;  // blocks pushed so far, ft
  Ring reflexTicks, eventTicks;
  std::uint8_t portB = 0;
  std::array<bool, 2> gunOn{};
  std::array<bool, 2> gunJammed{};
  // The battery's terminal voltage over the nominal one (Arena::setSupply):
  // scales the wheel and gun-wheel targets. Exactly 1 without a battery.
  double supply = 1;
  std::array<std::int64_t, 2> launchTick{-1, -1};
  std::array<double, 2> launchFactor{1, 1};      // muzzleFactor drawn at the stroke
  std::array<Dispersion, 2> launchDispersion{};  // drawDispersion, likewise
  std::array<int, 2> ballsLeft{};
  int shots = 0, hits = 0;
  int discsLeft = 0, discShots = 0, discHits = 0;
};

struct Discrete {
  std::array<RobotDisc, 2> r{};
  bool robotContact = false;
  // Balls and discs whose `active` is set: kept wherever one is set or
  // cleared, so that asking whether any flies (every round) does not scan
  // both tables.
  int inFlight = 0;
  std::array<Ball, kMaxBalls> balls{};
  std::array<Disc, kMaxDiscs> discs{};
  int blockCount = 0;  // blocks set down; 0: none of their rules run
  std::array<Block, kMaxBlocks> blocks{};
  // One past the highest ball and disc slot ever launched into (a launch
  // takes the lowest free slot): every slot from there on still holds its
  // default value, as does every block past blockCount (blocks are only
  // ever appended).
  int ballSlots = 0, discSlots = 0;

  Discrete() = default;
  Discrete(const Discrete&) = default;
  // Everything but the slots past both sides' high-water marks, which
  // hold the default value on both: copied at every plant event (pendingD
  // = D, then D = pendingD), where the tables are most of its 14.6 kB.
  // A member added to Discrete must be copied here too.
  Discrete& operator=(const Discrete& o) {
    if (this == &o) return *this;
    r = o.r;
    robotContact = o.robotContact;
    inFlight = o.inFlight;
    const int balls_ = std::max(ballSlots, o.ballSlots), discs_ = std::max(discSlots, o.discSlots);
    std::copy_n(o.balls.begin(), balls_, balls.begin());
    std::copy_n(o.discs.begin(), discs_, discs.begin());
    ballSlots = o.ballSlots;
    discSlots = o.discSlots;
    std::copy_n(o.blocks.begin(), std::max(blockCount, o.blockCount), blocks.begin());
    blockCount = o.blockCount;
    return *this;
  }
};

inline double expm1Of(double x) { return std::expm1(x); }
inline double expOf(double x) { return std::exp(x); }
using Expm1Memo = LastCall<&expm1Of>;
using ExpMemo = LastCall<&expOf>;

// The last heading whose unit vector (sin h, cos h) was computed, and it.
using HeadingMemo = LastCall<&geom::headingDir>;

// One robot's closed-form motion within a segment (DESIGN.md "Continuous
// motion"): each wheel's ground speed follows a first-order lag toward its
// target, v(t) = vt + (v0 - vt) e^{-dt/tau}, so its path length is
// vt dt - (v0 - vt) tau expm1(-dt/tau); the heading is the difference of
// the two path lengths over the track, the odometer their mean; each gun
// wheel follows its own lag. A zero time constant starts the segment at
// the target (applyJumps).
struct Motion {
  double t0 = 0;
  double h0 = 0, s0 = 0;
  double vl0 = 0, vr0 = 0, tl = 0, tr = 0;
  double tau = 0, track = 1;
  std::array<double, 2> g0{}, gt{}, gtau{};

  struct At {
    double vl, vr;  // wheel speeds, ft/s
    double h;       // heading, rad
    double s;       // odometer, ft
    double dv;      // d/dt of the mean wheel speed, ft/s^2
  };
  At at(double t, Expm1Memo& expm1) const {
    const double dt = t - t0;
    At a{};
    if (tau > 0) {
      const double em1 = expm1(-dt / tau);
      const double e = 1.0 + em1;
      a.vl = tl + (vl0 - tl) * e;
      a.vr = tr + (vr0 - tr) * e;
      const double il = tl * dt - (vl0 - tl) * tau * em1;
      const double ir = tr * dt - (vr0 - tr) * tau * em1;
      a.h = h0 + (il - ir) / track;
      a.s = s0 + 0.5 * (il + ir);
      a.dv = 0.5 * ((tl - a.vl) + (tr - a.vr)) / tau;
    } else {
      a.vl = vl0;
      a.vr = vr0;
      a.h = h0 + (vl0 - vr0) * dt / track;
      a.s = s0 + 0.5 * (vl0 + vr0) * dt;
      a.dv = 0;
    }
    return a;
  }
  double gun(int g, double t, ExpMemo& exp) const {
    const auto k = static_cast<std::size_t>(g);
    if (gtau[k] <= 0) return g0[k];
    return gt[k] + (g0[k] - gt[k]) * exp(-(t - t0) / gtau[k]);
  }
};

// Everything of an arena that changes as it runs, but the integrator itself
// (whose state SUNDIALS keeps private): a value, copied whole with
// `= default`, so that a member added later is copied too. A Checkpoint
// holds one, taken where ARKODE has just been reset and has not stepped
// (arena_journal.h): there this and the reset's arguments are the arena.
struct ArenaState {
  // ---- discrete state being integrated, and the pending prediction
  Discrete D;
  std::array<std::array<double, 2>, 2> wheelTarget{};
  std::array<std::array<double, 2>, 2> gunTarget{};
  std::array<Motion, 2> motion{};
  contact::Active active;  // the constraints of the segment (from D)
  bool pending = false;
  // The prediction came from a root (its crossing directions in
  // pendingFound), not from a scheduled launch; retreat() holds it again.
  bool pendingFromRoot = false;
  std::vector<int> pendingFound;
  std::int64_t pendingTick = 0;
  double pendingTime = 0;
  Discrete pendingD;
  std::vector<double> pendingY;

  // ---- deployables (deployables.cpp): every item set down so far, in
  // tick order, and what each robot's tables have left. Empty without
  // [[deployables]].
  std::vector<Deployed> deployed;
  std::array<std::array<int, kMaxDeployKinds>, 2> deployLeft{};

  // ---- time
  std::int64_t now = 0;      // tick reached
  std::int64_t segTick = 0;  // tick of the last reset
  double segT0 = 0;          // its time in seconds
  // What the last reset gave ARKODE, and whether it has stepped since: a
  // reset at the same tick with the same state and dynamics before any
  // step would leave ARKODE exactly as it is.
  bool fresh = false;
  std::vector<double> segY;
  std::array<std::array<double, 2>, 2> segWheel{}, segGun{};

  // ---- the integrator's own position (see "Stepping" in arena.cpp)
  double tReturned = 0;          // time of ARKODE's last return: roots up to it are known
  double tStepEnd = 0;           // end of ARKODE's last internal step
  bool lastRoot = false;         // ARKODE's last return was a root
  bool rootsMuted = false;       // clearRootFlag(): every root function reads 1
  std::int64_t launchStop = -1;  // tick the stop time is set at (a launch), or -1
  // A root found beyond the caller's stop, with events: reported by a later
  // advance() whose stop reaches heldTick.
  bool held = false;
  std::int64_t heldTick = 0;
  double heldTime = 0;
  std::vector<int> heldFound;

  // ---- roots
  std::array<RootDesc, kMaxRoots> roots{};
  // The root functions whose crossings were events at tick firedTick (over
  // every reset at that tick): crossedTick() never puts another crossing
  // of one of them there.
  std::int64_t firedTick = -1;
  std::array<RootDesc, kMaxRoots> fired{};
  int nFired = 0;
  int nRoots = 0;
  int nRootsRegistered = -1;
  std::array<double, kMaxRoots> rootShift{};
  // Where buildRoots() put the root functions stepBound() reads.
  struct BoundRoots {
    std::array<int, 2> edge{}, wall{};
    int out = -1, divider = -1, obstacle0 = -1;
  };
  std::array<BoundRoots, 2> boundRoots{};
  int robotPairRoot = -1;
  // A push's end function is >= 0 as the segment starts (a wheel command
  // stopped or reversed its robot at once, without motor lag): no root
  // can cross, so the push ends at the segment's first tick.
  bool pushEndDue = false;
  std::vector<int> rootsFound;

  // ---- dense output: one quintic Hermite polynomial a step for x and y
  // (arena_integrator.cpp, "Dense output"); the rest is closed form.
  struct Rec {
    double tlo, thi;
    std::size_t off;  // 6 Taylor coefficients about tlo for each of nx components
    // The step ARKODE reported as its next after this one (its planned
    // step; after a root or stop-time return, the step just taken), or for
    // the segment's first record the step it started with (0: ARKODE's own
    // estimate). A reset inside this step starts from it (reinit).
    double next = 0;
  };
  std::vector<Rec> recs;
  std::vector<double> coef;
  // Slope and curvature of x, y at the end of ARKODE's last step.
  std::vector<double> endY, endF, endA;

  // ---- statistics
  IntegratorStats acc{};
  long ownRhs = 0;  // right-hand sides evaluated for the dense output

  // Both fixed for a segment (they read its motion and balls): set at
  // each reset, read at every step.
  double segSpeed = 0;     // pointSpeed()
  bool segRest = false;    // atRest()
  bool segPushes = false;  // a block is being pushed (arena_blocks.cpp)
  double maxStepSet = -1;  // the value last given to ARKODE's maximum step
};

// An arena's state where it can be rebuilt without replaying what came
// before: ARKODE freshly reset at segT0 from the segment's start (segY),
// with the reset's initial step (recs.front().next), maximum step, root
// functions and stop time all read from `state`. `steps` and `rhsEvals`
// are ARKODE's counters then (a new integrator's start from 0).
struct Checkpoint {
  ArenaState state;
  long steps = 0, rhsEvals = 0;
};

}  // namespace arena_detail

using namespace arena_detail;

struct Arena::Impl : ArenaState {
  // ---- configuration
  ArenaConfig cfg;
  int nR = 0;
  int n = 0;   // full state size (kPerRobot a robot)
  int nx = 0;  // integrated state size (kXY a robot)
  double half = 0, wireHalf = 0;
  contact::Bodies bodies;  // radii and masses for the contact solve

  // ---- the integrator of the centres (arkode.h): its state vector holds
  // x, y at the end of each step, its scratch vector interpolations
  ark::Integrator ode;

  // The arena's step counts less ARKODE's (a restored arena's integrator
  // is new; stats() adds these): 0 unless restored from a checkpoint.
  long stepsOffset = 0, rhsEvalsOffset = 0;
  // ARKODE's steps and right-hand sides as this arena's own: over every
  // reset, and over a restore (what stats() and checkpoints count).
  long arenaSteps() const { return ode.steps() + stepsOffset; }
  long arenaRhsEvals() const { return ode.rhsEvals() + rhsEvalsOffset; }
  // ARKODE 6.4 keeps a root's flag across a reset that clearRootFlag()
  // could not clear (the root was at its step's end): a checkpoint is not
  // taken then, as a new integrator would not have it.
  bool rootFlagCarried = false;
  // Resets made (reinit(), `same` or not), and the count at the last
  // checkpoint: one checkpoint a reset is enough.
  std::uint64_t reinitSerial = 0, checkpointSerial = 0;

  void noteFired(std::int64_t tick, const int* found);
  bool firedAt(std::int64_t tick, const RootDesc& rd) const;

  // ---- the calls that changed the arena since its last checkpoint, when
  // it keeps them (a copy restores the checkpoint and makes them again:
  // arena_journal.h)
  std::shared_ptr<Journal> journal;              // shared with Arena::Mark
  std::shared_ptr<const ArenaConfig> sharedCfg;  // cfg, for the journals
  // Opens a public call's journal entry; first, if ARKODE has just been
  // reset (and has stepped before, as a new integrator will have: see
  // restore()), starts a new journal from a checkpoint of this state.
  Journal::Entry enter(const Journal::Call& call);
  // Makes this new arena (constructed from the same configuration) the one
  // checkpoint `cp` was taken of.
  void restore(const Checkpoint& cp);

  // ---- scratch
  // The lag terms and headings last evaluated (see LastCall): a robot's
  // heading memo is its own, as both robots' alternate.
  mutable Expm1Memo wheelLag;
  mutable ExpMemo gunLag;
  mutable std::array<HeadingMemo, 2> headingMemo;
  Vec2 headingDirOf(int robot, double h) const {
    return headingMemo[static_cast<std::size_t>(robot)](h);
  }
  std::vector<double> tmp;
  mutable std::vector<double> qtmp;    // for const queries
  mutable std::vector<double> rootY;   // the full state inside the root function
  mutable std::vector<double> blockY;  // the state for the blocks' queries

  explicit Impl(const ArenaConfig& c);

  // ------------------------------------------------------------ parameters
  const RobotParams& P(int i) const { return cfg.robots[static_cast<std::size_t>(i)].params; }
  double radius(int i) const { return P(i).body_diameter_ft / 2; }

  double pointSpeed() const;
  // `raw`, if given, holds this segment's root functions (unshifted) at
  // y: the distances are read from it instead of computed again.
  double stepBound(const double* y, double ahead, const double* raw = nullptr) const;
  // The root functions' last evaluation by ARKODE (rootThunk), unshifted,
  // and the time and centres it was made at: at the end of a step, where
  // stepBound() is evaluated next on the same state. Cleared by reinit()
  // and restore().
  mutable bool rootRawValid = false;
  mutable double rootRawT = 0;
  mutable std::array<double, 2 * kXY> rootRawXY{};
  mutable std::array<double, kMaxRoots> rootRaw{};
  bool atRest() const;

  // ------------------------------------------------------------ geometry on a
  // full state
  static Vec2 centre(const double* y, int i) {
    return Vec2(y[i * kPerRobot + X], y[i * kPerRobot + Y]);
  }
  static double heading(const double* y, int i) { return y[i * kPerRobot + H]; }

  Vec2 detector(const double* y, int i, int k) const;
  double edgeG(const double* y, int i, int k) const;
  double outG(const double* y, int i) const;
  // The centres (kXY a robot) of a full state.
  void centresOf(const double* y, double* q) const;
  // Gap (ft) between robot i's body and a wall, the divider or (i = 0) the
  // other robot: contact.h's, on a full state.
  double gapOf(contact::Kind k, int i, const double* y, int obstacle = 0) const;
  double reflexG(const double* y, int i, const Discrete& d) const;
  // The contact functions: the gap while inactive, minus the force while
  // active (contact.h); negative exactly while touching.
  double contactG(contact::Kind k, int i, const double* y, int obstacle = 0) const;

  void ballAt(const Ball& b, double t, double& x, double& yy, double& z) const;
  double ballHitG(const Ball& b, double t, const double* y, double& perp2, double& dist2) const;
  double ballGap(const Ball& b, double t, const double* y) const;
  double ballOutG(const Ball& b, double t) const;
  double ballDividerG(const Ball& b, double t) const;
  // Where (s after b.t0, from s = from on) the flight first meets `shape`
  // below `height` (closed form); HUGE_VAL: not at all.
  double ballMeetsShape(const Ball& b, const geom::Convex& shape, double height, double from) const;
  // Sets b.meetObstacle and b.meetT: the first obstacle its flight from
  // b.t0 meets below the obstacle's height (closed form), if any.
  void ballMeetsObstacle(Ball& b) const;
  // Then the blocks of d (at state y) where the flight is at tFrom or
  // later: meetObstacle blockObstacle(k) for block k, if it meets one first.
  void ballMeetsBlocks(Ball& b, const Discrete& d, const double* y, double tFrom) const;
  // Both, as a launch or a skip needs them.
  void ballMeetings(Ball& b, const Discrete& d, const double* y, double tFrom) const;

  // ---- blocks (arena_blocks.cpp)
  // Block k's footprint at full state y (where its pusher has taken it).
  geom::Convex blockShape(const Discrete& d, int k, const double* y) const;
  Vec2 blockAt(const Discrete& d, int k, const double* y) const;
  // Gap (ft) between robot i's body and block k at state y, and the
  // normal from the block towards the robot.
  double blockGap(const Discrete& d, int i, int k, const double* y, Vec2* normal = nullptr) const;
  // Robot i's free velocity (the wheels' alone) at full state y.
  Vec2 freeVelocityOf(const double* y, int i) const;
  double blockRootValue(int who, const double* y) const;
  double blockStopValue(const Discrete& d, int k, const double* y) const;
  // The resting blocks of d as contact.h's obstacles (their rigid contacts).
  void refreshBlockShapes(const Discrete& d);
  // The pushes of d slow their pushers' velocities v (and accelerations a).
  void applyPushes(const Discrete& d, double* v, double* a = nullptr) const;
  // Pushes ending at tick T, contacts with blocks starting (and pushes
  // with them) or ending: process()'s blocks, into ev.
  void blockContacts(std::int64_t T, double te, Discrete& d, std::vector<double>& y,
                     const int* found, EventList& ev);
  // Robot i meets block k as a fixed box: a contact, its bumper and reflex.
  void meetBlock(Discrete& d, std::vector<double>& y, int i, int k, std::int64_t T, EventList& ev);
  // Robot i, just touching block k, starts pushing it if it can (traction
  // above the block's friction, driving into it, not held, room to move).
  bool startPush(Discrete& d, const double* ys, int i, int k, EventList& ev) const;
  // Block k's push ends at time te (state y), stopped by `with`.
  void endPush(Discrete& d, int k, const double* y, double te, ContactWith with, int index,
               EventList& ev);
  // How far block k (resting) can move along u before it touches
  // something fixed or another block.
  double blockReach(const Discrete& d, int k, const Vec2& u, const double* y, ContactWith& with,
                    int& index) const;
  // Whether a block of footprint `s` fits on the field of d at state y.
  bool blockFits(const Discrete& d, const geom::Convex& s, const double* y) const;
  // A block set down (or moved) in d: balls and discs in flight meet it.
  void flightsSeeBlocks(Discrete& d, const double* y, double te) const;
  mutable std::vector<Deployed> eyeItems;  // the eyes' scene, blocks where they are

  // ---- discs (arena_discs.cpp)
  double discPath(const Disc& d, double t) const;
  void discAt(const Disc& d, double t, double& x, double& yy) const;
  double discHitG(const Disc& d, double t, const double* y, double& perp2, double& dist2) const;
  double discGap(const Disc& d, double t, const double* y) const;
  // Path length along which a disc of `radius` at height z, its centre
  // leaving p along the unit vector u, first touches something fixed
  // (field walls, divider: the one place a fixed shape is added), and
  // what; +inf and None if nothing.
  double discStrike(const Vec2& p, const Vec2& u, double z, double radius, MissReason& what,
                    int& obstacle) const;
  // Appends the root functions of the discs in flight to `roots`.
  void addDiscRoots();
  // A disc leaves robot i's rim at tick T (time te), state y; its events
  // into ev, and its strike there if it touches something at once.
  void launchDisc(Discrete& d, const std::vector<double>& y, int i, double te, EventList& ev);
  // Disc k's outcome at time te: the end of its path, then a hit.
  void discOutcome(int k, double te, Discrete& d, const double* ys, const int* found,
                   EventList& ev);

  double rootValue(const RootDesc& rd, double t, const double* y) const;
  // Root j of the list as ARKODE, crossedTick() and the event rules see it
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

  // ------------------------------------------------------------ ARKODE
  // callbacks (ark::RhsFn, ark::RootFn)
  static void rhsThunk(double t, const double* y, double* ydot, void* user) {
    static_cast<Impl*>(user)->rhs(t, y, ydot);
  }
  static void rootThunk(double t, const double* y, double* g, void* user);

  // Velocities of x, y (nx values) at t with positions xy, after the
  // active contacts' projection; `accel`, if given, their time derivative.
  void rhs(double t, const double* xy, double* f, double* accel = nullptr) const;
  // The full state at t from positions xy and the closed forms.
  void fullState(double t, const double* xy, double* out) const;
  // The centres' velocities at t as the wheels alone would give them (no
  // contact), and, if `a` is given, their time derivatives.
  void freeVelocities(double t, double* v, double* a) const;

  // A gun wheel spins up under its motor and coasts down, more slowly,
  // when the motor is off (DESIGN.md "Guns"): the time constant follows
  // the motor, not the direction of change.
  static double gunTau(const RobotParams& p, double target) {
    return target > 0 ? p.gun_wheel_lag_s : p.gun_wheel_coast_s;
  }

  // Robot i's wheel targets (ft/s) under d: reflex, drive or frame, supply.
  std::array<double, 2> wheelTargetsOf(const Discrete& d, int i) const;
  void computeTargets(const Discrete& d);
  void applyJumps(std::vector<double>& y) const;
  void setMotion(double t0, const std::vector<double>& y);
  void setActive(const Discrete& d);

  void buildRoots();

  void reinit(std::int64_t tick, double t0, std::vector<double>& y, bool first = false);

  void clearRootFlag();
  void recordStep(double tn, const double* ynew);
  void setMaxStep(double h);

  // Time used for tick `tick` inside the current segment.
  double timeOfTick(std::int64_t tick) const { return std::max(secondsFromTick(tick), segT0); }

  const Rec& recordAt(double t) const;
  mutable std::size_t recordHint = 0;  // the record recordAt() found last
  double component(const Rec& r, double t, int i) const;
  void evalAt(double t, std::vector<double>& out) const;
  std::array<double, 3> poseAt(int robot, std::int64_t tick) const;
  // Both robots' poses at one tick (an eye read's): poseAt's arithmetic,
  // the tick's time and dense-output record found once.
  std::array<std::array<double, 3>, 2> posesAt(std::int64_t tick) const;
  // One robot's pose in the pending state (at pendingTick), and from
  // record r's dense output at time t.
  std::array<double, 3> pendingPose(int robot) const;
  std::array<double, 3> poseIn(const Rec& r, double t, int robot) const;

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
