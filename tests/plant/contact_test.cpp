// Rigid contacts (plant/contact.h) against hand-worked closed forms.
//
// The default profile's robot: body radius r = 12.75 / 24 = 0.53125 ft,
// full speed V = 1.45 ft/s (speed 15, trims set to 1), motor lag tau =
// 0.15 s, reflex at full speed backwards (-V) for 1.75 ft of wheel travel.
// Started from rest with both wheels at +V its heading is constant and its
// path length is
//
//   s(t) = V (t - tau (1 - e^{-t/tau})),  speed v(t) = V (1 - e^{-t/tau}).
//
// A body whose centre must travel D along its heading reaches the obstacle
// when s(t_c) = D; the contact is the event at T_c = ceil(t_c * 9,216,000).
// There the reflex starts: the wheels' target becomes -V, so with te =
// T_c / 9,216,000 the speed is v(t) = -V + (v(te) + V) e^{-(t - te)/tau}.
// A rigid obstacle holds the normal speed at 0 while it points into it,
// and lets go when the wheel speed reaches 0:
//
//   t_end = te + tau ln((v(te) + V) / V)  (v(te) = V (1 - 9e-6): 0.103971 s)
//
// which is the contact_end at T_end = ceil(t_end * 9,216,000). Until then
// the body stays at the obstacle (to the documented tolerance, 1e-6 ft:
// the crossing lies less than a tick before T_c, and a tick at 1.45 ft/s
// is 1.6e-7 ft), sliding along a wall with the tangential part of v.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "plant_support.h"

namespace plant_test {
namespace {

constexpr double kTicks = 9'216'000.0;
constexpr double kR = 12.75 / 24;
constexpr double kV = 1.45;
constexpr double kTau = 0.15;
// How far a body may be inside what it touches (docs/plant.md).
constexpr double kTolerance = 1e-6;  // ft

double pathLength(double t) { return kV * (t + kTau * std::expm1(-t / kTau)); }
double speed(double t) { return -kV * std::expm1(-t / kTau); }

// t_c with s(t_c) = d, by bisection on the closed form (s is increasing).
double reachTime(double d) {
  double lo = 0, hi = 100;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (pathLength(mid) < d ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

std::int64_t tickAfter(double t) { return static_cast<std::int64_t>(std::ceil(t * kTicks)); }

// The contact's event ticks worked from t_c as the header comment says:
// start at T_c, the reflex from te = T_c / 9,216,000 at speed v(te), the
// end at T_end.
struct ContactTicks {
  std::int64_t start;
  double te, ve, tEnd;
  std::int64_t end;
};
ContactTicks expectedTicks(double tc) {
  ContactTicks k{};
  k.start = tickAfter(tc);
  k.te = static_cast<double>(k.start) / kTicks;
  k.ve = speed(k.te);
  k.tEnd = k.te + kTau * std::log((k.ve + kV) / kV);
  k.end = tickAfter(k.tEnd);
  return k;
}

// How far robots A and B overlap at a tick (negative: the gap between them).
double overlap(const Arena& a, std::int64_t tick) {
  const Pose qa = a.pose(0, tick), qb = a.pose(1, tick);
  return 2 * kR - std::hypot(qa.x_ft - qb.x_ft, qa.y_ft - qb.y_ft);
}

Profile rigid() {
  Profile p = defaults();
  p.robot.left_trim = p.robot.right_trim = 1.0;
  p.robot.trim_spread = 0;
  return p;
}

struct Contact {
  std::int64_t start = -1, end = -1;
};

// Runs the arena to `limit`, recording the first contact and contact end
// of `robot` with `with`, and calling probe(tick) at every tick a query
// can see (every event tick and every 1/1000 s in between).
template <class Probe>
Contact run(Arena& a, int robot, ContactWith with, std::int64_t limit, Probe probe) {
  Contact c;
  const std::int64_t stride = 9216;
  while (a.now() < limit) {
    const std::int64_t next = std::min(limit, (a.now() / stride + 1) * stride);
    AdvanceResult r = a.advance(next);
    for (const Event& e : r.events) {
      if (e.robot != robot || e.with != with) continue;
      if (e.kind == EventKind::Contact && c.start < 0) c.start = r.tick;
      if (e.kind == EventKind::ContactEnd && c.end < 0) c.end = r.tick;
    }
    probe(r.tick);
  }
  return c;
}

// Heading 60 deg (clockwise from north) from 2 ft west of the east wall's
// contact position: the centre travels D = 2 / sin 60 = 2.3094011 ft,
// t_c = D / V + tau (1 - e^{-t_c/tau}) = 1.592690 + 0.15 - 1.4e-6 =
// 1.742689 s; the contact lasts tau ln((v(te) + V) / V) = 0.103971 s; the
// centre slides north by cos 60 times the path length over the contact,
// -V (t_end - te) + (v(te) + V) tau (1 - V / (v(te) + V)) = -V (t_end - te)
// + v(te) tau: 0.5 (-0.150759 + 0.217498) = 0.033370 ft.
TEST(RigidContact, WallAtSixtyDegreesHoldsTheBodyAndEndsWhenTheWheelsReverse) {
  const Profile p = rigid();
  const double x0 = 8 - kR - 2;
  const double ang = 60 * M_PI / 180;
  Arena a(config(p, {Pose{x0, 0, 60}}));
  ASSERT_TRUE(a.setWheels(0, frame("ffg0ffg0"), 0));
  const double tc = reachTime(2 / std::sin(ang));
  EXPECT_NEAR(tc, 1.742689, 1e-6);
  const ContactTicks k = expectedTicks(tc);
  EXPECT_NEAR(k.tEnd - k.te, 0.103971, 1e-6);
  double deepest = -1, yAtEnd = 0, yAtStart = 0;
  const Contact c = run(a, 0, ContactWith::Wall, ticks(3.0), [&](std::int64_t tick) {
    const Pose q = a.pose(0, tick);
    deepest = std::max(deepest, q.x_ft + kR - 8);
    if (tick == k.start) yAtStart = q.y_ft;
    if (tick == k.end) yAtEnd = q.y_ft;
  });
  EXPECT_EQ(c.start, k.start);
  EXPECT_EQ(c.end, k.end);
  EXPECT_LE(deepest, kTolerance);
  EXPECT_GE(deepest, -kTolerance);  // it did reach the wall
  const double slide = std::cos(ang) * (-kV * (k.tEnd - k.te) + k.ve * kTau);
  EXPECT_NEAR(slide, 0.033370, 1e-6);
  // The 1/1000-s probes include both event ticks (events stop advance()).
  EXPECT_NEAR(yAtEnd - yAtStart, slide, 1e-7);
}

// Straight east at the divider's west face (x = -0.375 in = -0.03125 ft)
// from (-3, -6): D = 3 - 0.03125 - 0.53125 = 2.4375 ft, t_c = 1.831034 s.
TEST(RigidContact, DividerHoldsTheBodyOnItsNearSide) {
  const Profile p = rigid();
  Arena a(config(p, {Pose{-3, -6, 90}}));
  ASSERT_TRUE(a.setWheels(0, frame("ffg0ffg0"), 0));
  const double tc = reachTime(2.4375);
  EXPECT_NEAR(tc, 1.831034, 1e-6);
  const ContactTicks k = expectedTicks(tc);
  double deepest = -1;
  const Contact c = run(a, 0, ContactWith::Divider, ticks(3.0), [&](std::int64_t tick) {
    deepest = std::max(deepest, a.pose(0, tick).x_ft + kR + 0.03125);
  });
  EXPECT_EQ(c.start, k.start);
  EXPECT_EQ(c.end, k.end);
  EXPECT_LE(deepest, kTolerance);
  EXPECT_GE(deepest, -kTolerance);
}

// Head on: A from (-3, 0) east, B from (3, 0) west, both from rest. Each
// centre travels (6 - 2 r) / 2 = 2.46875 ft: t_c = 1.852586 s. Equal
// masses and opposite equal speeds: the common normal speed is 0, both stop
// at the contact and back off when their wheels reverse, at the same t_end.
TEST(RigidContact, HeadOnRobotsDoNotOverlap) {
  const Profile p = rigid();
  Arena a(config(p, {Pose{-3, 0, 90}, Pose{3, 0, 270}}));
  ASSERT_TRUE(a.setWheels(0, frame("ffg0ffg0"), 0));
  ASSERT_TRUE(a.setWheels(1, frame("ffg0ffg0"), 0));
  const double tc = reachTime(2.46875);
  EXPECT_NEAR(tc, 1.852586, 1e-6);
  const ContactTicks k = expectedTicks(tc);
  double deepest = -1;
  const Contact c = run(a, 0, ContactWith::Robot, ticks(3.0),
                        [&](std::int64_t tick) { deepest = std::max(deepest, overlap(a, tick)); });
  EXPECT_EQ(c.start, k.start);
  EXPECT_EQ(c.end, k.end);
  EXPECT_LE(deepest, kTolerance);
  EXPECT_GE(deepest, -kTolerance);
}

// A drives east at full speed into B, which stands still, 2.5 ft ahead
// (gap 2.5 - 2 r = 1.4375 ft, t_c = 0.991379 + 0.15 - 7.5e-5 = 1.141305
// s). From the contact on they share the normal speed: B, whose wheels do
// not turn, moves east at half of A's wheel speed (equal masses,
// contact.h) while they touch. B's own reflex (forward: its back bumper
// was hit) then drives it away.
TEST(RigidContact, APushedRobotMovesAtHalfThePushersSpeed) {
  const Profile p = rigid();
  Arena a(config(p, {Pose{-3, 0, 90}, Pose{-0.5, 0, 90}}));
  ASSERT_TRUE(a.setWheels(0, frame("ffg0ffg0"), 0));
  const double tc = reachTime(1.4375);
  EXPECT_NEAR(tc, 1.141305, 1e-6);
  double deepest = -1;
  const Contact c = run(a, 0, ContactWith::Robot, ticks(3.0),
                        [&](std::int64_t tick) { deepest = std::max(deepest, overlap(a, tick)); });
  EXPECT_EQ(c.start, expectedTicks(tc).start);
  ASSERT_GT(c.end, c.start);
  EXPECT_LE(deepest, kTolerance);
  // Right after the contact both centres move east at the mean of A's
  // speed v(te) and B's 0: over one 1/1000 s, B moves v(te)/2 * 0.001 to
  // within the change of the speeds over that time (|dv/dt| <= 2V/tau).
  Arena b(config(p, {Pose{-3, 0, 90}, Pose{-0.5, 0, 90}}));
  ASSERT_TRUE(b.setWheels(0, frame("ffg0ffg0"), 0));
  const auto found = runUntil(b, EventKind::Contact, ticks(3.0));
  ASSERT_TRUE(found.has_value());
  const double te = static_cast<double>(found->tick) / kTicks;
  const double xb0 = b.pose(1, found->tick).x_ft;
  b.advance(found->tick + 9216);
  const double moved = b.pose(1, found->tick + 9216).x_ft - xb0;
  EXPECT_NEAR(moved, 0.5 * speed(te) * 0.001, 2 * kV / kTau * 1e-6);
}

}  // namespace
}  // namespace plant_test
