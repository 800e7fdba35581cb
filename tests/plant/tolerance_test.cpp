// The integrator's documented accuracy (docs/plant.md, "The integrator")
// against an independent oracle: default-profile robots (motor lag 0.15 s)
// started from rest on 10-s arcs, straight runs and spins, compared every
// millisecond with the closed-form heading and the Boost.Math quadrature
// of x and y (lag_arc_oracle.h); and edge-wire crossings, whose tick must
// be the ceiling of the oracle's crossing time.
//
// The bounds are those docs/plant.md states for ARKODE at rtol = atol =
// 1e-9 with the quintic dense output: position within 1e-9 ft (1/380 of
// the 3.8e-7 ft a point at the top speed of 3.5 ft/s moves in a tick);
// the heading is a closed form, within 1e-12 rad (round-off of the
// degrees a pose reports). CVODE's plant, before, needed 1e-8 ft and
// 2.5e-9 rad here.
#include <cmath>
#include <numbers>

#include "lag_arc_oracle.h"
#include "plant_support.h"

using namespace plant_test;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kMaxPositionErrorFt = 1e-9;
constexpr double kMaxHeadingErrorRad = 1e-12;
constexpr std::int64_t kTicksPerSecond = 9'216'000;

struct Start {
  double x, y, headingDeg;
};

// Wheel targets: a motor frame's speed steps from the default profile's
// table (trims 1), or a scripted drive in ft/s.
struct Wheels {
  const char* frame = nullptr;
  double left = 0, right = 0;
};

struct Errors {
  double position = 0, heading = 0;
  int events = 0;
};

double tableSpeed(const Profile& p, char step, char dir) {
  const int i = step <= '9' ? step - '0' : step - 'a' + 10;
  return (dir == 'f' ? 1 : -1) * p.robot.speed_table_fps[static_cast<std::size_t>(i)];
}

// Sets the wheels at tick 0 and returns the oracle for that motion.
LagArcOracle drive(Arena& a, const Profile& p, const Start& s, const Wheels& w, double horizon) {
  EXPECT_EQ(p.robot.left_trim, 1.0);
  EXPECT_EQ(p.robot.right_trim, 1.0);
  double vl = w.left, vr = w.right;
  if (w.frame) {
    a.setWheels(0, frame(w.frame), 0);
    vl = tableSpeed(p, w.frame[0], w.frame[1]);
    vr = tableSpeed(p, w.frame[4], w.frame[5]);
  } else {
    a.setDrive(0, vl, vr, 0);
  }
  return LagArcOracle(s.x, s.y, s.headingDeg * kPi / 180, vl, vr, p.robot.motor_lag_s,
                      p.robot.track_ft, horizon);
}

// Largest errors over a 10-s run, sampled every millisecond.
Errors arcErrors(const Start& s, const Wheels& w) {
  const Profile p = defaults();
  Arena a(config(p, {Pose{s.x, s.y, s.headingDeg}}));
  const LagArcOracle o = drive(a, p, s, w, 10.1);
  Errors e;
  for (std::int64_t tick = 0; tick <= 10 * kTicksPerSecond; tick += kTicksPerSecond / 1000) {
    while (a.now() < tick) e.events += static_cast<int>(a.advance(tick).events.size());
    const Pose q = a.pose(0, tick);
    const LagArcOracle::Point want = o.at(secondsFromTick(tick));
    e.position = std::max(e.position, std::hypot(q.x_ft - want.x, q.y_ft - want.y));
    const double dh = std::remainder(q.heading_deg * kPi / 180 - want.h, 2 * kPi);
    e.heading = std::max(e.heading, std::abs(dh));
  }
  return e;
}

void expectWithinTolerance(const Start& s, const Wheels& w) {
  const Errors e = arcErrors(s, w);
  EXPECT_EQ(e.events, 0) << "the run must stay clear of the wire and walls";
  EXPECT_LE(e.position, kMaxPositionErrorFt);
  EXPECT_LE(e.heading, kMaxHeadingErrorRad);
}

TEST(Tolerance, StraightRun) {
  // Speed step a (1.06 ft/s) north from (3, -6): 10.4 ft, ending at y 4.4.
  expectWithinTolerance({3, -6, 0}, {"afg0afg0"});
}

TEST(Tolerance, SpinInPlace) {
  // Step f forward and reverse: 2 * 1.45 / 0.75 = 3.87 rad/s, 38 rad in 10 s.
  expectWithinTolerance({0, 2, 10}, {"ffg0frg0"});
}

TEST(Tolerance, Arcs) {
  // Radii from 0.38 to 2.4 ft, forward and reverse, turning both ways.
  expectWithinTolerance({-2, 2, 90}, {"ffg0afg0"});
  expectWithinTolerance({2, 2, 30}, {nullptr, 1.45, 1.0});
  expectWithinTolerance({3, -1, 300}, {nullptr, -0.5, -1.2});
  expectWithinTolerance({-2.1688, 3.8873, 76.242}, {nullptr, -0.00331, -0.77296});
  expectWithinTolerance({1.9204, 1.6144, 69.226}, {nullptr, 1.38062, -0.48153});
  expectWithinTolerance({-2.8931, 1.5505, 355.742}, {nullptr, 1.32440, 0.65488});
}

// The fore detector's first crossing into the wire's sensitive band: the
// arena's EdgeEnter tick against ceil(t* x 9,216,000), t* the oracle's
// root of (distance from the detector to the wire ring) - sensitivity.
void expectCrossingTick(const Start& s, const Wheels& w) {
  const Profile p = defaults();
  Arena a(config(p, {Pose{s.x, s.y, s.headingDeg}}));
  const LagArcOracle o = drive(a, p, s, w, 20.1);
  const double off = p.robot.body_diameter_ft / 2 - p.robot.edge_detector_inset_ft;
  const double hw = p.field.size_ft / 2 - p.field.wire_inset_ft;
  const auto g = [&](const LagArcOracle::Point& q) {
    const double ax = std::abs(q.x + off * std::sin(q.h)), ay = std::abs(q.y + off * std::cos(q.h));
    const double d = ax <= hw && ay <= hw
                         ? std::min(hw - ax, hw - ay)
                         : std::hypot(std::max(ax - hw, 0.0), std::max(ay - hw, 0.0));
    return d - p.field.wire_sensitivity_ft;
  };
  double lo = 0;
  while (lo < 20 && g(o.at(lo + 0.001)) >= 0) lo += 0.001;
  ASSERT_LT(lo, 20) << "no crossing";
  const long double exact = static_cast<long double>(o.root(g, lo, lo + 0.001)) * kTicksPerSecond;
  // Well-posed only if the crossing is farther from a tick boundary than
  // the position bound moves it: 1e-8 ft at the >= 1 ft/s these detectors
  // approach the wire is under 0.1 tick.
  const double frac = static_cast<double>(exact - std::floor(exact));
  ASSERT_GT(frac, 0.1);
  ASSERT_LT(frac, 0.9);
  const auto got = runUntil(a, EventKind::EdgeEnter, 20 * kTicksPerSecond, 0);
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(got->event.detector, Detector::Fore);
  EXPECT_EQ(got->tick, static_cast<std::int64_t>(std::ceil(exact)));
}

TEST(Tolerance, EdgeCrossingTicks) {
  // Straight north at step f from (3, 0): t* = 4.933046 s.
  expectCrossingTick({3, 0, 0}, {"ffg0ffg0"});
  // A 6.9-ft arc to the east wire: t* = 3.874951 s.
  expectCrossingTick({2, 1, 60}, {nullptr, 1.45, 1.3});
  // Steps c and d, a wide arc to the west wire: t* = 4.356668 s.
  expectCrossingTick({-2, 2, 265}, {"cfg0dfg0"});
}

}  // namespace
