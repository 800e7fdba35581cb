// An independent oracle of a whole match's motion and root events, from
// the inputs a trace records (tests/match_oracle_test.cpp).
//
// Inputs: the start poses, each robot's parameters with the match's wheel
// trims, every latched motor frame (tick, robot, its 8 characters) and
// every edge-handler entry (a pio_a interrupt accepted: the referee counts
// them). Everything else that changes the motion the oracle decides
// itself, by the rules of DESIGN.md "Devices" and "Continuous motion":
// contacts and the bumper reflexes they start, reflex ends, the referee's
// 45-degree turns, and it reports every root event with its tick.
//
// Motion, in long double, with no code of the plant's integrator: between
// two changes each wheel's ground speed is a first-order lag toward its
// target, v(t) = vt + (v0 - vt) e^{-dt/tau}; its path length
// vt dt - (v0 - vt) tau expm1(-dt/tau) is exact, the heading is the
// difference of the two path lengths over the track, the odometer their
// mean. The centre moves at the mean speed along the heading, integrated
// by 15-point Gauss-Legendre quadrature from the last checkpoint (at most
// kMaxStep = 20 ms earlier: the integrand is analytic, the rule exact to
// long double's precision there). While a body pushes into a wall or a
// face of the divider, the normal component of its velocity is removed
// (frictionless slide; DESIGN.md, plant/contact.h), so that coordinate
// stays where the contact began; the contact ends when the free velocity's
// normal component stops pointing into the wall (its force reaches 0), or,
// for a touching contact that does not push at a change (the referee turned
// the body away), when its gap opens. A divider corner (a normal that
// turns) and robot-robot contact are not modelled: the oracle reports them
// as events the test then fails on.
//
// Root functions, as the plant defines them (arena_roots.cpp): per robot
// the two edge detectors' distance to the wire ring minus the sensitivity,
// the centre's distance inside the field (the referee's put-back), the gap
// to the east/west wall, the north/south wall and the divider (while a
// contact pushes: minus its force, the free velocity's component into the
// obstacle's normal), the reflex's distance left (signed odometer since the
// start minus reflex_distance); and the gap between the two bodies. Each
// is negative exactly when its discrete state says so (low, touching, the
// reflex still running). At every change each function that starts on the
// wrong side of zero by round-off is shifted to start on its state's side,
// as the plant's sideRoots() does.
//
// Scanning: from a time t the oracle steps to t + min(|g| / L) over every
// function g with L a bound of |dg/dt| over the segment (no crossing can
// hide inside such a step), at least kMinStep and at most kMaxStep, and
// when a function has crossed, brackets its zero with TOMS 748. The event
// tick is the first integer tick at which the function is on its new side,
// or the tick before when the crossing lies within 1/1024 of a tick after
// it (the plant's crossedTick() rule, DESIGN.md "Time"); the tick is decided
// from the function's values at the integer ticks, not from the root time.
// Events at a tick follow the plant's process() order: reflex ends,
// contacts (divider, then the walls) with their reflexes, edges, the
// referee's turn and the edges it moves.
//
// Following the plant: given the plant's events as hints (OracleHint), the
// oracle applies a change at the plant's tick of the same event (the next
// one of its kind, robot and detail, if within kFollowTicks), not at its
// own, which it still reports. So a one-tick disagreement stays one: the
// reflex, the referee's count and every later motion start from the same
// ticks as the plant's, and each event is checked on the same history.
#pragma once

#include <algorithm>
#include <array>
#include <boost/math/quadrature/gauss.hpp>
#include <boost/math/tools/toms748_solve.hpp>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "plant/plant.h"

namespace oracle {

using OReal = long double;

struct OracleRobot {
  simbot::plant::RobotParams params;  // with the match's wheel trims
  simbot::plant::Pose start;
};

struct OracleInput {
  // Probe: no input, the oracle records both robots' poses at the tick.
  enum class Kind { Frame, HandlerEntry, Probe };
  Kind kind = Kind::Frame;
  std::int64_t tick = 0;
  int robot = 0;
  std::string bytes;  // a frame's 8 characters
};

// An event the plant recorded, as a hint of when to apply the oracle's own
// crossing of that function (see MatchOracle).
struct OracleHint {
  std::int64_t tick = 0;
  std::string kind;  // edge_enter, edge_leave, contact, contact_end, reflex_end
  int robot = 0;
  std::string detail;  // as OracleEvent::key() makes it
};

struct OracleSetup {
  simbot::plant::FieldParams field;
  simbot::plant::RefereeParams referee;
  std::vector<OracleRobot> robots;  // 2
  std::vector<OracleInput> inputs;  // any order
  std::vector<OracleHint> hints;    // tick order
  std::int64_t endTick = 0;
};

enum class OracleKind {
  EdgeEnter,
  EdgeLeave,
  Contact,
  ContactEnd,
  ReflexStart,
  ReflexEnd,
  RefereeTurn
};

inline const char* oracleKindName(OracleKind k) {
  switch (k) {
    case OracleKind::EdgeEnter:
      return "edge_enter";
    case OracleKind::EdgeLeave:
      return "edge_leave";
    case OracleKind::Contact:
      return "contact";
    case OracleKind::ContactEnd:
      return "contact_end";
    case OracleKind::ReflexStart:
      return "reflex_start";
    case OracleKind::ReflexEnd:
      return "reflex_end";
    case OracleKind::RefereeTurn:
      return "referee_turn";
  }
  return "?";
}

struct OracleEvent {
  std::int64_t tick = 0;
  OracleKind kind = OracleKind::EdgeEnter;
  int robot = 0;
  // fore/aft (edges), wall/divider/robot (contacts), front/back (reflexes);
  // empty for a turn.
  std::string detail;
  std::string bumper;  // a contact's bumper
  // A root function crossed (edge, contact start or end, reflex end); not
  // a consequence of one (reflex start, turn) or a detector a turn moved.
  bool crossing = false;
  std::string function;  // the root function, for reports
  // Crossing time in ticks minus (tick - 1): in (0, 1] unless the
  // 1/1024-tick rule put the event on the tick before (then just above 1).
  OReal fraction = 0;
  bool onTickRule = false;       // the 1/1024-tick rule decided the tick
  std::int64_t segmentTick = 0;  // the oracle's last change before it
  // The function (shifted as in its segment) at ticks tick-2 .. tick+1.
  std::array<OReal, 4> g{};
  // The same at the plant's tick-2 .. tick+1 when it applied elsewhere.
  std::array<OReal, 4> gPlant{};
  // The tick the oracle applied the change at: the plant's tick for the
  // same event when it is within kFollowTicks of the oracle's, else its own.
  std::int64_t applied = 0;
  // kind, robot and detail, as the test pairs events.
  std::string detail_key() const { return bumper.empty() ? detail : detail + "/" + bumper; }
  std::string describe() const {
    std::ostringstream s;
    s.precision(6);
    s << oracleKindName(kind) << ' ' << (robot == 0 ? 'A' : 'B') << ' ' << detail;
    if (!bumper.empty()) s << '/' << bumper;
    s << " at " << tick;
    if (applied != tick) s << " (applied at the plant's " << applied << ")";
    if (crossing)
      s << " (" << function << ", crossing at tick-1+" << static_cast<double>(fraction)
        << (onTickRule ? ", 1/1024-tick rule" : "")
        << "; g(tick-2..tick+1) = " << static_cast<double>(g[0]) << ' ' << static_cast<double>(g[1])
        << ' ' << static_cast<double>(g[2]) << ' ' << static_cast<double>(g[3]) << ")";
    if (crossing && applied != tick)
      s << "; at the plant's tick-2..tick+1: " << static_cast<double>(gPlant[0]) << ' '
        << static_cast<double>(gPlant[1]) << ' ' << static_cast<double>(gPlant[2]) << ' '
        << static_cast<double>(gPlant[3]);
    return s.str();
  }
};

class MatchOracle {
 public:
  static constexpr OReal kRate = 9216000.0L;  // ticks per second (timebase/tick.h)
  static constexpr OReal kMinStep = 1e-4L;    // s
  static constexpr OReal kMaxStep = 0.02L;    // s
  static constexpr OReal kOnTickFraction = 1.0L / 1024;
  // A crossing whose plant event (the next of its kind, robot and detail)
  // lies this close is applied at the plant's tick: one disagreement then
  // does not move every later event.
  static constexpr std::int64_t kFollowTicks = 10'000;

  explicit MatchOracle(OracleSetup setup) : s_(std::move(setup)) {
    const auto& f = s_.field;
    half_ = static_cast<OReal>(f.size_ft) / 2;
    wireHalf_ = half_ - static_cast<OReal>(f.wire_inset_ft);
    sens_ = f.wire_sensitivity_ft;
    divX0_ = static_cast<OReal>(f.divider_x_ft) - static_cast<OReal>(f.divider_thickness_ft) / 2;
    divX1_ = static_cast<OReal>(f.divider_x_ft) + static_cast<OReal>(f.divider_thickness_ft) / 2;
    divY0_ = f.divider_south_ft;
    divY1_ = f.divider_north_ft;
    for (std::size_t i = 0; i < 2; ++i) {
      Robot& r = r_[i];
      const auto& p = s_.robots[i].params;
      r.p = p;
      r.radius = static_cast<OReal>(p.body_diameter_ft) / 2;
      r.off = r.radius - static_cast<OReal>(p.edge_detector_inset_ft);
      r.track = p.track_ft;
      r.tau = p.motor_lag_s;
      r.seg.h0 = static_cast<OReal>(s_.robots[i].start.heading_deg) * kPi / 180;
      r.tc = 0;
      r.xc = s_.robots[i].start.x_ft;
      r.yc = s_.robots[i].start.y_ft;
    }
    std::stable_sort(s_.inputs.begin(), s_.inputs.end(),
                     [](const OracleInput& a, const OracleInput& b) { return a.tick < b.tick; });
  }

  // Problems the oracle cannot model (divider corners), for the test to
  // fail on.
  const std::vector<std::string>& problems() const { return problems_; }
  struct Probe {
    std::int64_t tick;
    int robot;
    OReal x, y, h;  // ft, ft, rad (unwrapped)
  };
  const std::vector<Probe>& probes() const { return probes_; }
  long steps() const { return steps_; }
  long rootSolves() const { return solves_; }

  std::vector<OracleEvent> run() {
    // The initial flags, from geometry, silently (the plant's constructor).
    const Snap s0 = snap(0);
    for (int i = 0; i < 2; ++i) {
      Robot& r = r_[static_cast<std::size_t>(i)];
      for (int k = 0; k < 2; ++k) r.edgeLow[static_cast<std::size_t>(k)] = edgeG(s0, i, k) < 0;
      r.touching[kWallX] = s_.field.field_walls && wallGap(s0, i, 0) <= 0;
      r.touching[kWallY] = s_.field.field_walls && wallGap(s0, i, 1) <= 0;
      r.touching[kDiv] = dividerGap(s0, i) <= 0;
    }
    reset(0);
    std::size_t next = 0;
    std::int64_t T = 0;
    for (;;) {
      const std::int64_t Tb =
          next < s_.inputs.size() ? std::min(s_.inputs[next].tick, s_.endTick) : s_.endTick;
      std::int64_t Te = 0;
      std::vector<Crossed> crossed;
      if (scan(T, Tb, Te, crossed)) {
        eventsAt(Te, crossed, Tb);
        T = applied_;
        continue;
      }
      T = Tb;
      if (next >= s_.inputs.size() || s_.inputs[next].tick > s_.endTick) break;
      bool changed = false;
      while (next < s_.inputs.size() && s_.inputs[next].tick == Tb) {
        const OracleInput& in = s_.inputs[next++];
        if (in.kind == OracleInput::Kind::Probe) {
          const Snap s = snap(timeOf(Tb));
          for (std::size_t i = 0; i < 2; ++i)
            probes_.push_back({Tb, static_cast<int>(i), s[i].x, s[i].y, s[i].h});
          continue;
        }
        applyInput(in);
        changed = true;
      }
      if (changed) reset(Tb);
    }
    return events_;
  }

 private:
  static constexpr OReal kPi = 3.141592653589793238462643383279502884L;
  enum { kWallX = 0, kWallY = 1, kDiv = 2 };
  // Root functions: per robot kPerRobot, then the robots' gap.
  enum Fn { EdgeFore, EdgeAft, Out, WallX, WallY, Divider, ReflexEnd, kPerRobot };
  static constexpr int kFns = 2 * kPerRobot + 1;
  static constexpr int kRobotGap = 2 * kPerRobot;

  struct Seg {
    OReal t0 = 0, h0 = 0, s0 = 0, vl0 = 0, vr0 = 0, tl = 0, tr = 0;
  };
  struct Robot {
    simbot::plant::RobotParams p;
    OReal radius = 0, off = 0, track = 1, tau = 0;
    Seg seg;
    OReal tc = 0, xc = 0, yc = 0;  // checkpoint: the centre at tc
    OReal latchL = 0, latchR = 0;  // the latched frame's targets (stopped at first)
    bool reflex = false, reflexBack = false;
    OReal reflexS0 = 0;
    std::array<bool, 2> edgeLow{};
    std::array<bool, 3> touching{};  // wall x, wall y, divider
    std::array<bool, 3> pushing{};   // the constraint is active in this segment
    int dividerAxis = 0;             // the divider contact's normal: 0 x, 1 y
    OReal dividerSign = 1;           // and its sign
    std::vector<std::int64_t> reflexTicks, eventTicks;
  };
  struct Wheels {
    OReal vl, vr, h, s, dv;
  };
  struct Pose2 {
    OReal x, y, h, s, vl, vr, dv;
  };
  using Snap = std::array<Pose2, 2>;
  struct Crossed {
    int fn;
    OReal root;  // crossing time (s)
    std::int64_t tick;
    bool onTickRule;
  };

  Wheels wheels(const Robot& r, OReal t) const {
    const Seg& g = r.seg;
    const OReal dt = t - g.t0;
    Wheels w{};
    if (r.tau > 0) {
      const OReal em1 = std::expm1(-dt / r.tau);
      const OReal e = 1 + em1;
      w.vl = g.tl + (g.vl0 - g.tl) * e;
      w.vr = g.tr + (g.vr0 - g.tr) * e;
      const OReal il = g.tl * dt - (g.vl0 - g.tl) * r.tau * em1;
      const OReal ir = g.tr * dt - (g.vr0 - g.tr) * r.tau * em1;
      w.h = g.h0 + (il - ir) / r.track;
      w.s = g.s0 + (il + ir) / 2;
      w.dv = ((g.tl - w.vl) + (g.tr - w.vr)) / (2 * r.tau);
    } else {
      w.vl = g.vl0;
      w.vr = g.vr0;
      w.h = g.h0 + (g.vl0 - g.vr0) * dt / r.track;
      w.s = g.s0 + (g.vl0 + g.vr0) * dt / 2;
      w.dv = 0;
    }
    return w;
  }

  // Is the centre's x (axis 0) or y (axis 1) held by an active contact?
  bool held(const Robot& r, int axis) const {
    if (r.pushing[static_cast<std::size_t>(axis)]) return true;
    return r.pushing[kDiv] && r.dividerAxis == axis;
  }

  // The centre at t, from the checkpoint.
  void centre(const Robot& r, OReal t, OReal& x, OReal& y) const {
    using GL = boost::math::quadrature::gauss<OReal, 15>;
    x = r.xc;
    y = r.yc;
    if (t == r.tc) return;
    if (!held(r, 0))
      x += GL::integrate(
          [&](OReal u) {
            const Wheels w = wheels(r, u);
            return (w.vl + w.vr) / 2 * std::sin(w.h);
          },
          r.tc, t);
    if (!held(r, 1))
      y += GL::integrate(
          [&](OReal u) {
            const Wheels w = wheels(r, u);
            return (w.vl + w.vr) / 2 * std::cos(w.h);
          },
          r.tc, t);
  }

  Snap snap(OReal t) const {
    Snap s{};
    for (std::size_t i = 0; i < 2; ++i) {
      const Wheels w = wheels(r_[i], t);
      centre(r_[i], t, s[i].x, s[i].y);
      s[i].h = w.h;
      s[i].s = w.s;
      s[i].vl = w.vl;
      s[i].vr = w.vr;
      s[i].dv = w.dv;
    }
    return s;
  }
  void checkpoint(OReal t, const Snap& s) {
    for (std::size_t i = 0; i < 2; ++i) {
      r_[i].tc = t;
      r_[i].xc = s[i].x;
      r_[i].yc = s[i].y;
    }
  }
  static OReal timeOf(std::int64_t tick) { return static_cast<OReal>(tick) / kRate; }

  // ---- geometry (plant/geometry.h, plant/contact.cpp's definitions)
  OReal edgeG(const Snap& s, int i, int k) const {
    const Pose2& q = s[static_cast<std::size_t>(i)];
    const OReal off = r_[static_cast<std::size_t>(i)].off * (k == 0 ? 1 : -1);
    const OReal x = q.x + off * std::sin(q.h), y = q.y + off * std::cos(q.h);
    const OReal ax = std::abs(x), ay = std::abs(y);
    OReal d;
    if (ax <= wireHalf_ && ay <= wireHalf_) {
      d = std::min(wireHalf_ - ax, wireHalf_ - ay);
    } else {
      const OReal dx = std::max(ax - wireHalf_, OReal(0)), dy = std::max(ay - wireHalf_, OReal(0));
      d = std::sqrt(dx * dx + dy * dy);
    }
    return d - sens_;
  }
  OReal wallGap(const Snap& s, int i, int axis) const {
    const Pose2& q = s[static_cast<std::size_t>(i)];
    return half_ - std::abs(axis == 0 ? q.x : q.y) - r_[static_cast<std::size_t>(i)].radius;
  }
  void dividerClosest(const Pose2& q, OReal& cx, OReal& cy) const {
    cx = std::clamp(q.x, divX0_, divX1_);
    cy = std::clamp(q.y, divY0_, divY1_);
  }
  OReal dividerGap(const Snap& s, int i) const {
    const Pose2& q = s[static_cast<std::size_t>(i)];
    OReal cx, cy;
    dividerClosest(q, cx, cy);
    return std::hypot(q.x - cx, q.y - cy) - r_[static_cast<std::size_t>(i)].radius;
  }
  // Contact c's outward unit normal for robot i at s; false at a corner.
  bool normal(const Snap& s, int i, int c, OReal& nx, OReal& ny) const {
    const Pose2& q = s[static_cast<std::size_t>(i)];
    nx = ny = 0;
    if (c == kWallX) {
      nx = q.x >= 0 ? -1 : 1;
      return true;
    }
    if (c == kWallY) {
      ny = q.y >= 0 ? -1 : 1;
      return true;
    }
    OReal cx, cy;
    dividerClosest(q, cx, cy);
    const bool face = q.y >= divY0_ && q.y <= divY1_, end = q.x >= divX0_ && q.x <= divX1_;
    if (face) nx = q.x >= cx ? 1 : -1;
    if (end) ny = q.y >= cy ? 1 : -1;
    return face != end;
  }
  // The free velocity of robot i's centre and its time derivative.
  void freeVelocity(const Pose2& q, const Robot& r, OReal& vx, OReal& vy, OReal& ax,
                    OReal& ay) const {
    const OReal v = (q.vl + q.vr) / 2, om = (q.vl - q.vr) / r.track;
    const OReal sh = std::sin(q.h), ch = std::cos(q.h);
    vx = v * sh;
    vy = v * ch;
    ax = q.dv * sh + v * om * ch;
    ay = q.dv * ch - v * om * sh;
  }
  // A contact's function while it pushes: the free velocity along its
  // normal (minus the force; negative while pushing).
  OReal pushG(const Snap& s, int i, int c) const {
    const Robot& r = r_[static_cast<std::size_t>(i)];
    OReal vx, vy, ax, ay, nx, ny;
    freeVelocity(s[static_cast<std::size_t>(i)], r, vx, vy, ax, ay);
    if (c == kDiv) {
      nx = r.dividerAxis == 0 ? r.dividerSign : 0;
      ny = r.dividerAxis == 1 ? r.dividerSign : 0;
    } else {
      normal(s, i, c, nx, ny);
    }
    return nx * vx + ny * vy;
  }

  // Root function fn, unshifted.
  OReal rawG(const Snap& s, int fn) const {
    if (fn == kRobotGap)
      return std::hypot(s[0].x - s[1].x, s[0].y - s[1].y) - r_[0].radius - r_[1].radius;
    const int i = fn / kPerRobot, k = fn % kPerRobot;
    const Robot& r = r_[static_cast<std::size_t>(i)];
    const Pose2& q = s[static_cast<std::size_t>(i)];
    switch (k) {
      case EdgeFore:
        return edgeG(s, i, 0);
      case EdgeAft:
        return edgeG(s, i, 1);
      case Out:
        return half_ - std::max(std::abs(q.x), std::abs(q.y));
      case WallX:
      case WallY:
      case Divider: {
        const int c = k == WallX ? kWallX : k == WallY ? kWallY : kDiv;
        if (r.pushing[static_cast<std::size_t>(c)]) return pushG(s, i, c);
        return c == kDiv ? dividerGap(s, i) : wallGap(s, i, c);
      }
      case ReflexEnd:
        return (r.reflexBack ? 1 : -1) * (q.s - r.reflexS0) -
               static_cast<OReal>(r.p.reflex_distance_ft);
      default:
        return 1;
    }
  }
  bool live(int fn) const {
    if (fn == kRobotGap) return true;
    const int i = fn / kPerRobot, k = fn % kPerRobot;
    const Robot& r = r_[static_cast<std::size_t>(i)];
    if ((k == WallX || k == WallY) && !s_.field.field_walls) return false;
    if (k == ReflexEnd) return r.reflex;
    return true;
  }
  // Does the discrete state say fn < 0?
  bool negative(int fn) const {
    if (fn == kRobotGap) return false;
    const int i = fn / kPerRobot, k = fn % kPerRobot;
    const Robot& r = r_[static_cast<std::size_t>(i)];
    switch (k) {
      case EdgeFore:
        return r.edgeLow[0];
      case EdgeAft:
        return r.edgeLow[1];
      case WallX:
        return r.touching[kWallX];
      case WallY:
        return r.touching[kWallY];
      case Divider:
        return r.touching[kDiv];
      case ReflexEnd:
        return true;  // running
      default:
        return false;
    }
  }
  bool sided(int fn) const {
    const int k = fn % kPerRobot;
    return fn == kRobotGap || k == EdgeFore || k == EdgeAft || k == WallX || k == WallY ||
           k == Divider;
  }
  OReal G(const Snap& s, int fn) const {
    return rawG(s, fn) - shift_[static_cast<std::size_t>(fn)];
  }
  bool crossedAt(const Snap& s, int fn) const { return (G(s, fn) < 0) != negative(fn); }

  // A bound of |dg/dt| over the segment.
  OReal lipschitz(int fn) const {
    auto vmax = [&](const Robot& r) {
      return std::max(
          {std::abs(r.seg.vl0), std::abs(r.seg.vr0), std::abs(r.seg.tl), std::abs(r.seg.tr)});
    };
    if (fn == kRobotGap) return vmax(r_[0]) + vmax(r_[1]);
    const int i = fn / kPerRobot, k = fn % kPerRobot;
    const Robot& r = r_[static_cast<std::size_t>(i)];
    const OReal v = vmax(r), om = 2 * v / r.track;
    switch (k) {
      case EdgeFore:
      case EdgeAft:
        return v + om * r.off;
      case WallX:
      case WallY:
      case Divider: {
        const int c = k == WallX ? kWallX : k == WallY ? kWallY : kDiv;
        if (!r.pushing[static_cast<std::size_t>(c)]) return v;
        const OReal dv =
            r.tau > 0
                ? (std::abs(r.seg.tl - r.seg.vl0) + std::abs(r.seg.tr - r.seg.vr0)) / (2 * r.tau)
                : 0;
        return dv + v * om;
      }
      default:
        return v;
    }
  }

  // ---- changes
  static OReal wheelTarget(const simbot::plant::RobotParams& p, char speed, bool forward, bool go,
                           bool left) {
    if (!go) return 0;
    const int step = speed >= '0' && speed <= '9' ? speed - '0' : speed - 'a' + 10;
    const OReal v = static_cast<OReal>(p.speed_table_fps[static_cast<std::size_t>(step & 15)] *
                                       (left ? p.left_trim : p.right_trim));
    return forward ? v : -v;
  }
  void setTargets(Robot& r) {
    if (r.reflex) {
      const int step = r.p.reflex_speed_step;
      const char c = static_cast<char>(step < 10 ? '0' + step : 'a' + step - 10);
      r.seg.tl = wheelTarget(r.p, c, r.reflexBack, true, true);
      r.seg.tr = wheelTarget(r.p, c, r.reflexBack, true, false);
    } else {
      r.seg.tl = r.latchL;
      r.seg.tr = r.latchR;
    }
  }

  // A new segment for both robots at tick T (the state is continuous but
  // for a turn's heading, applied by the caller through turn_).
  void reset(std::int64_t T) {
    const OReal t = timeOf(T);
    const Snap s = snap(t);
    checkpoint(t, s);
    for (std::size_t i = 0; i < 2; ++i) {
      Robot& r = r_[i];
      r.seg.t0 = t;
      r.seg.h0 = s[i].h + turn_[i];
      turn_[i] = 0;
      r.seg.s0 = s[i].s;
      r.seg.vl0 = s[i].vl;
      r.seg.vr0 = s[i].vr;
      setTargets(r);
    }
    const Snap s1 = snap(t);  // the turned headings, the new targets
    // The constraints that push (the plant's setActive): touching, and the
    // free velocity into the obstacle, or zero and turning into it.
    constexpr OReal kZeroForce = 1e-12L;
    for (std::size_t i = 0; i < 2; ++i) {
      Robot& r = r_[i];
      for (int c = 0; c < 3; ++c) {
        const auto ck = static_cast<std::size_t>(c);
        r.pushing[ck] = false;
        if (!r.touching[ck]) continue;
        OReal nx, ny, vx, vy, ax, ay;
        if (c == kDiv) {
          nx = r.dividerAxis == 0 ? r.dividerSign : 0;
          ny = r.dividerAxis == 1 ? r.dividerSign : 0;
        } else {
          normal(s1, static_cast<int>(i), c, nx, ny);
        }
        freeVelocity(s1[i], r, vx, vy, ax, ay);
        const OReal mu = -(nx * vx + ny * vy), dmu = -(nx * ax + ny * ay);
        r.pushing[ck] = mu > kZeroForce || (mu >= -kZeroForce && dmu > 0);
      }
    }
    segTick_ = T;
    // Sided roots (the plant's sideRoots): start on the state's side.
    shift_.fill(0);
    for (int fn = 0; fn < kFns; ++fn) {
      if (!live(fn) || !sided(fn)) continue;
      const OReal g0 = rawG(s1, fn);
      const OReal side = negative(fn) ? -1 : 1;
      if (side * g0 <= 0)
        shift_[static_cast<std::size_t>(fn)] =
            g0 - side * std::max(std::abs(g0), std::numeric_limits<OReal>::min());
    }
  }

  bool refereeDue(const Robot& r, std::int64_t T) const {
    const std::int64_t from = T - simbot::timebase::ticksFromSeconds(s_.referee.window_s);
    auto since = [&](const std::vector<std::int64_t>& v) {
      return static_cast<int>(std::count_if(v.begin(), v.end(), [&](auto t) { return t > from; }));
    };
    return since(r.reflexTicks) > s_.referee.reflex_limit ||
           since(r.eventTicks) > s_.referee.event_limit;
  }
  // The referee's turn of robot i at T (if due), and the edges it moves.
  bool refereeTurns(std::int64_t T) {
    bool any = false;
    for (int i = 0; i < 2; ++i) {
      Robot& r = r_[static_cast<std::size_t>(i)];
      if (!refereeDue(r, T)) continue;
      turn_[static_cast<std::size_t>(i)] += static_cast<OReal>(s_.referee.turn_deg) * kPi / 180;
      r.reflexTicks.clear();
      r.eventTicks.clear();
      emit(T, OracleKind::RefereeTurn, i, "", "");
      any = true;
    }
    if (!any) return false;
    Snap s = snap(timeOf(T));
    for (std::size_t i = 0; i < 2; ++i) s[i].h += turn_[i];
    for (int i = 0; i < 2; ++i)
      for (int k = 0; k < 2; ++k) {
        const int fn = i * kPerRobot + k;
        const bool low = G(s, fn) < 0;
        Robot& r = r_[static_cast<std::size_t>(i)];
        if (low == r.edgeLow[static_cast<std::size_t>(k)]) continue;
        r.edgeLow[static_cast<std::size_t>(k)] = low;
        emit(T, low ? OracleKind::EdgeEnter : OracleKind::EdgeLeave, i, k == 0 ? "fore" : "aft",
             "");
      }
    return true;
  }

  void applyInput(const OracleInput& in) {
    Robot& r = r_[static_cast<std::size_t>(in.robot)];
    applied_ = in.tick;
    if (in.kind == OracleInput::Kind::Frame) {
      const std::string& b = in.bytes;
      r.latchL = wheelTarget(r.p, b[0], b[1] == 'f', b[2] == 'g', true);
      r.latchR = wheelTarget(r.p, b[4], b[5] == 'f', b[6] == 'g', false);
      return;  // the reset that follows applies it (unless a reflex runs)
    }
    r.eventTicks.push_back(in.tick);
    refereeTurns(in.tick);
  }

  OracleEvent& emit(std::int64_t T, OracleKind k, int robot, std::string detail,
                    std::string bumper) {
    OracleEvent e;
    e.tick = T;
    e.kind = k;
    e.robot = robot;
    e.detail = std::move(detail);
    e.bumper = std::move(bumper);
    e.segmentTick = segTick_;
    e.applied = applied_;
    events_.push_back(e);
    return events_.back();
  }
  static const char* fnName(int fn) {
    if (fn == kRobotGap) return "robot gap";
    static const char* names[] = {"edge fore", "edge aft", "out of field", "wall x",
                                  "wall y",    "divider",  "reflex end"};
    return names[fn % kPerRobot];
  }

  // The events of the functions that crossed at tick T, in process()'s
  // order, then the new segment.
  // The plant's tick for an event of this key near Te (consumed), or Te.
  std::int64_t follow(std::int64_t Te, const std::string& kind, int robot,
                      const std::string& detail) {
    for (std::size_t j = 0; j < s_.hints.size(); ++j) {
      const OracleHint& h = s_.hints[j];
      if (used_.size() < s_.hints.size()) used_.resize(s_.hints.size());
      if (used_[j] || h.kind != kind || h.robot != robot || h.detail != detail) continue;
      if (h.tick < Te - kFollowTicks) continue;
      if (h.tick > Te + kFollowTicks) break;
      used_[j] = true;
      return h.tick;
    }
    return Te;
  }

  // The key of the event fn's crossing makes, at the state s.
  void keyOf(const Snap& s, int fn, std::string& kind, int& robot, std::string& detail) const {
    robot = fn == kRobotGap ? 0 : fn / kPerRobot;
    const int k = fn % kPerRobot;
    const Robot& r = r_[static_cast<std::size_t>(robot)];
    if (fn == kRobotGap) {
      kind = "contact";
      detail = "robot";
    } else if (k == EdgeFore || k == EdgeAft) {
      kind = r.edgeLow[static_cast<std::size_t>(k)] ? "edge_leave" : "edge_enter";
      detail = k == EdgeFore ? "fore" : "aft";
    } else if (k == ReflexEnd) {
      kind = "reflex_end";
      detail = r.reflexBack ? "back" : "front";
    } else if (k == WallX || k == WallY || k == Divider) {
      const int c = k == WallX ? kWallX : k == WallY ? kWallY : kDiv;
      detail = c == kDiv ? "divider" : "wall";
      if (r.touching[static_cast<std::size_t>(c)]) {
        kind = "contact_end";
      } else {
        kind = "contact";
        OReal nx, ny;
        normal(s, robot, c, nx, ny);
        const Pose2& q = s[static_cast<std::size_t>(robot)];
        detail += std::sin(q.h) * -nx + std::cos(q.h) * -ny >= 0 ? "/front" : "/back";
      }
    } else {
      kind = "out_of_field";
      detail = "";
    }
  }

  void eventsAt(std::int64_t Te, const std::vector<Crossed>& crossed, std::int64_t Tb) {
    // Apply at the plant's tick of the first crossing's event if it is near.
    std::int64_t T = Te;
    {
      const Snap se = snap(timeOf(Te));
      std::vector<std::int64_t> ticks;
      for (const Crossed& c : crossed) {
        std::string kind, detail;
        int robot = 0;
        keyOf(se, c.fn, kind, robot, detail);
        ticks.push_back(follow(Te, kind, robot, detail));
      }
      T = std::clamp(ticks.front(), segTick_, Tb);  // not past the next input
    }
    applied_ = T;
    const OReal t = timeOf(T);
    const Snap s = snap(t);
    auto found = [&](int fn) -> const Crossed* {
      for (const Crossed& c : crossed)
        if (c.fn == fn) return &c;
      return nullptr;
    };
    auto note = [&](OracleEvent& e, const Crossed& c) {
      e.tick = Te;
      e.crossing = true;
      e.function = fnName(c.fn);
      e.fraction = c.root * kRate - static_cast<OReal>(Te - 1);
      e.onTickRule = c.onTickRule;
      for (int j = 0; j < 4; ++j)
        e.g[static_cast<std::size_t>(j)] = G(snap(timeOf(Te - 2 + j)), c.fn);
      if (T != Te)
        for (int j = 0; j < 4; ++j)
          e.gPlant[static_cast<std::size_t>(j)] = G(snap(timeOf(T - 2 + j)), c.fn);
    };
    // Reflex ends.
    for (int i = 0; i < 2; ++i) {
      Robot& r = r_[static_cast<std::size_t>(i)];
      const Crossed* c = found(i * kPerRobot + ReflexEnd);
      if (!r.reflex || !c) continue;
      OracleEvent& e = emit(T, OracleKind::ReflexEnd, i, r.reflexBack ? "back" : "front", "");
      note(e, *c);
      r.reflex = false;
    }
    if (const Crossed* c = found(kRobotGap)) {
      problems_.push_back("the robots touch at tick " + std::to_string(T) +
                          ": robot-robot contact is not modelled");
      OracleEvent& e = emit(T, OracleKind::Contact, 0, "robot", "");
      note(e, *c);
    }
    // Contacts: the divider, then the walls (x, y).
    for (int i = 0; i < 2; ++i) {
      Robot& r = r_[static_cast<std::size_t>(i)];
      for (int c : {kDiv, kWallX, kWallY}) {
        const int fn = i * kPerRobot + (c == kDiv ? Divider : c == kWallX ? WallX : WallY);
        const Crossed* cr = found(fn);
        if (!cr) continue;
        const auto ck = static_cast<std::size_t>(c);
        const char* with = c == kDiv ? "divider" : "wall";
        if (!r.touching[ck]) {
          OReal nx, ny;
          if (!normal(s, i, c, nx, ny))
            problems_.push_back("robot " + std::to_string(i) +
                                " touches a divider corner at tick " + std::to_string(T) +
                                ": not modelled");
          if (c == kDiv) {
            r.dividerAxis = nx != 0 ? 0 : 1;
            r.dividerSign = nx != 0 ? nx : ny;
          }
          const Pose2& q = s[static_cast<std::size_t>(i)];
          const bool front = std::sin(q.h) * -nx + std::cos(q.h) * -ny >= 0;
          OracleEvent& e = emit(T, OracleKind::Contact, i, with, front ? "front" : "back");
          note(e, *cr);
          r.touching[ck] = true;
          r.reflex = true;
          r.reflexBack = !front;
          r.reflexS0 = q.s;
          r.reflexTicks.push_back(T);
          r.eventTicks.push_back(T);
          emit(T, OracleKind::ReflexStart, i, front ? "front" : "back", "");
        } else {
          OracleEvent& e = emit(T, OracleKind::ContactEnd, i, with, "");
          note(e, *cr);
          r.touching[ck] = false;
        }
      }
    }
    // Edges.
    for (int i = 0; i < 2; ++i)
      for (int k = 0; k < 2; ++k) {
        const Crossed* c = found(i * kPerRobot + k);
        if (!c) continue;
        Robot& r = r_[static_cast<std::size_t>(i)];
        const bool low = !r.edgeLow[static_cast<std::size_t>(k)];
        r.edgeLow[static_cast<std::size_t>(k)] = low;
        OracleEvent& e = emit(T, low ? OracleKind::EdgeEnter : OracleKind::EdgeLeave, i,
                              k == 0 ? "fore" : "aft", "");
        note(e, *c);
      }
    for (int i = 0; i < 2; ++i)
      if (const Crossed* c = found(i * kPerRobot + Out)) {
        problems_.push_back("robot " + std::to_string(i) + "'s centre leaves the field at tick " +
                            std::to_string(T));
        (void)c;
      }
    refereeTurns(T);
    // Functions that fired at T do not fire there again (noteFired).
    if (firedTick_ != T) fired_.clear();
    firedTick_ = T;
    for (const Crossed& c : crossed) fired_.push_back(c.fn);
    reset(T);
  }

  // The first tick, after the segment's, at which fn has crossed, given a
  // crossing at time `root`; the plant's crossedTick() rule.
  std::int64_t tickOf(int fn, OReal root, bool& onTickRule) const {
    auto at = [&](std::int64_t k) { return G(snap(timeOf(k)), fn); };
    auto crossed = [&](std::int64_t k) { return (at(k) < 0) != negative(fn); };
    auto K = static_cast<std::int64_t>(std::ceil(root * kRate));
    if (K <= segTick_) K = segTick_ + 1;
    while (!crossed(K)) ++K;
    while (K - 1 > segTick_ && crossed(K - 1)) --K;
    onTickRule = false;
    const std::int64_t k = K - 1;
    const bool first = k == segTick_;
    const bool firedHere =
        firedTick_ == k && std::find(fired_.begin(), fired_.end(), fn) != fired_.end();
    if (first && (firedHere || shift_[static_cast<std::size_t>(fn)] != 0)) return K;
    const OReal gk = at(k), gK = at(K);
    if (std::abs(gk) <= kOnTickFraction * std::abs(gK - gk)) {
      onTickRule = true;
      return k;
    }
    return K;
  }

  // Scans (tick Ta, tick Tb] for the first crossing: true and the tick and
  // functions crossing there if there is one; else the checkpoints are at
  // Tb.
  bool scan(std::int64_t Ta, std::int64_t Tb, std::int64_t& Te, std::vector<Crossed>& out) {
    OReal t = timeOf(Ta);
    const OReal tb = timeOf(Tb);
    std::array<OReal, kFns> L{};
    for (int fn = 0; fn < kFns; ++fn)
      L[static_cast<std::size_t>(fn)] = live(fn) ? lipschitz(fn) : 0;
    Snap s = snap(t);
    while (t < tb) {
      ++steps_;
      OReal step = kMaxStep;
      for (int fn = 0; fn < kFns; ++fn) {
        const OReal l = L[static_cast<std::size_t>(fn)];
        if (l > 0) step = std::min(step, std::abs(G(s, fn)) / l);
      }
      step = std::max(step, kMinStep);
      const OReal t1 = std::min(t + step, tb);
      const Snap s1 = snap(t1);
      out.clear();
      for (int fn = 0; fn < kFns; ++fn) {
        if (!live(fn) || !crossedAt(s1, fn)) continue;
        ++solves_;
        std::uintmax_t iters = 200;
        const auto f = [&](OReal u) { return G(snap(u), fn); };
        const auto r = boost::math::tools::toms748_solve(
            f, t, t1, G(s, fn), G(s1, fn), boost::math::tools::eps_tolerance<OReal>(60), iters);
        Crossed c{fn, (r.first + r.second) / 2, 0, false};
        c.tick = tickOf(fn, c.root, c.onTickRule);
        out.push_back(c);
      }
      if (!out.empty()) {
        Te = out.front().tick;
        for (const Crossed& c : out) Te = std::min(Te, c.tick);
        out.erase(
            std::remove_if(out.begin(), out.end(), [&](const Crossed& c) { return c.tick != Te; }),
            out.end());
        return true;
      }
      checkpoint(t1, s1);
      t = t1;
      s = s1;
    }
    return false;
  }

  OracleSetup s_;
  std::array<Robot, 2> r_{};
  OReal half_ = 0, wireHalf_ = 0, sens_ = 0, divX0_ = 0, divX1_ = 0, divY0_ = 0, divY1_ = 0;
  std::array<OReal, kFns> shift_{};
  std::array<OReal, 2> turn_{};
  std::int64_t segTick_ = 0;
  std::int64_t applied_ = 0;
  std::vector<bool> used_;
  std::int64_t firedTick_ = -1;
  std::vector<int> fired_;
  std::vector<OracleEvent> events_;
  std::vector<std::string> problems_;
  std::vector<Probe> probes_;
  long steps_ = 0, solves_ = 0;
};

}  // namespace oracle
