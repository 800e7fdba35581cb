// Continuous motion against closed forms: straight runs, spins, the motor
// lag's step response, the wire-detector crossing tick, projectile flight,
// a hit's tick, the bumper reflex, the referee, rewinds and determinism.
#include <bit>
#include <cmath>
#include <cstring>
#include <vector>

#include "plant/geometry.h"
#include "plant_support.h"

using namespace plant_test;

namespace {

constexpr double kPi = 3.14159265358979323846;

void expectRel(double actual, double expected, double rel, const char* what) {
  const double tol = rel * std::max(1.0, std::abs(expected));
  EXPECT_NEAR(actual, expected, tol) << what;
}

// Headings in degrees as poses and events report them: fmod(deg, 360),
// exact, moved into [0, 360). By hand: below 360 in magnitude fmod gives
// deg back (-0 too, which is not below 0); 725.5 - 2 x 360 = 5.5;
// -1e-300 + 360 rounds to 360, which wraps to 0.
TEST(Geometry, Wrap360IsTheExactRemainderInZeroTo360) {
  using simbot::plant::geom::wrap360;
  EXPECT_EQ(wrap360(359.75), 359.75);
  EXPECT_EQ(wrap360(-90.0), 270.0);
  EXPECT_EQ(wrap360(-359.75), 0.25);
  EXPECT_TRUE(std::signbit(wrap360(-0.0)));
  EXPECT_EQ(wrap360(360.0), 0.0);
  EXPECT_EQ(wrap360(725.5), 5.5);
  EXPECT_EQ(wrap360(-725.5), 354.5);
  EXPECT_EQ(wrap360(-1e-300), 0.0);
}

// remainder360 against the C library's fmod, which is exact: bit for bit
// (a zero's sign too) on random magnitudes from 360 to 2^52 degrees of
// both signs, and on multiples of 360 and their neighbours (where the
// quotient's integer part changes).
TEST(Geometry, Remainder360IsFmodBitForBit) {
  using simbot::plant::geom::remainder360;
  const auto same = [](double deg) {
    const double want = std::fmod(deg, 360.0);
    const double got = remainder360(deg);
    EXPECT_EQ(std::bit_cast<std::uint64_t>(got), std::bit_cast<std::uint64_t>(want))
        << std::hexfloat << deg << " -> " << got << ", fmod " << want;
  };
  SplitMix64 bits(360);
  for (int i = 0; i < 200000; ++i) {
    const std::uint64_t w = bits.next();
    // Exponents 8 to 51, any mantissa, either sign.
    const double size = std::ldexp(1.0 + unit53(w), 8 + static_cast<int>(w % 44));
    if (size < 360.0) continue;
    same(size);
    same(-size);
  }
  for (double k : {1.0, 2.0, 3.0, 1e3, 12345.0, 1e9, 4503599627370495.0 / 360.0}) {
    const double m = std::trunc(k) * 360.0;
    for (double d : {m, std::nextafter(m, 0.0), std::nextafter(m, 1e300)}) {
      same(d);
      same(-d);
    }
  }
}

TEST(Time, EventTickIsCeilingOfExactProduct) {
  for (std::int64_t k : {0LL, 1LL, 7LL, 9216000LL, 123456789LL, 1658880000LL, 1658879999LL}) {
    const double t = secondsFromTick(k);
    // t is k/N rounded; the exact product t*N is within an ulp of k on
    // either side, so the ceiling is k or k+1 depending on that side.
    const std::int64_t got = eventTickFromSeconds(t);
    const long double exact = static_cast<long double>(t) * 9216000.0L;
    const std::int64_t want = static_cast<std::int64_t>(std::ceil(exact));
    EXPECT_EQ(got, want) << k;
    EXPECT_TRUE(got == k || got == k + 1);
  }
  EXPECT_EQ(eventTickFromSeconds(1.0), 9216000);
  EXPECT_EQ(eventTickFromSeconds(std::nextafter(1.0, 2.0)), 9216001);
  EXPECT_EQ(eventTickFromSeconds(0.5), 4608000);
}

TEST(Motion, StraightRunMatchesClosedForm) {
  const Profile p = thesis();
  Arena a(config(p, {Pose{-6.5, -6.5, 0}}));
  const double v = p.robot.speed_table_fps[15];
  ASSERT_TRUE(a.setWheels(0, frame("ffg0ffg0"), 0));
  EXPECT_FALSE(a.setWheels(0, frame("ffg0ffg0"), 0));  // unchanged: no-op
  const auto stop = ticks(3.0);
  AdvanceResult r = a.advance(stop);
  ASSERT_EQ(r.tick, stop);
  EXPECT_TRUE(r.events.empty());
  for (double t : {0.0, 0.3, 1.234567, 2.5, 3.0}) {
    const Pose q = a.pose(0, ticks(t));
    const double tt = secondsFromTick(ticks(t));
    expectRel(q.x_ft, -6.5, 1e-6, "x");
    expectRel(q.y_ft, -6.5 + v * tt, 1e-6, "y");
    EXPECT_NEAR(q.heading_deg, 0.0, 1e-9);
  }
}

TEST(Motion, HeadingRunAndArc) {
  // Heading 60 deg: direction (sin 60, cos 60).
  const Profile p = thesis();
  Arena a(config(p, {Pose{-2, -2, 60}}));
  a.setWheels(0, frame("afg0afg0"), 0);
  a.advance(ticks(2));
  const double v = p.robot.speed_table_fps[10];
  const double t = secondsFromTick(ticks(2));
  const Pose q = a.pose(0, ticks(2));
  expectRel(q.x_ft, -2 + v * t * std::sin(kPi / 3), 1e-6, "x");
  expectRel(q.y_ft, -2 + v * t * std::cos(kPi / 3), 1e-6, "y");
}

TEST(Motion, SpinInPlaceMatchesClosedForm) {
  const Profile p = thesis();
  Arena a(config(p, {Pose{1, 1, 10}}));
  a.setWheels(0, frame("afg0arg0"), 0);  // left forward, right reverse: clockwise
  const double v = p.robot.speed_table_fps[10];
  const double omegaDeg = (2 * v / p.robot.track_ft) * 180 / kPi;
  a.advance(ticks(1.5));
  for (double t : {0.25, 0.7, 1.5}) {
    const double tt = secondsFromTick(ticks(t));
    const Pose q = a.pose(0, ticks(t));
    const double want = std::fmod(10 + omegaDeg * tt, 360.0);
    expectRel(q.heading_deg, want, 1e-6, "heading");
    EXPECT_NEAR(q.x_ft, 1, 1e-9);
    EXPECT_NEAR(q.y_ft, 1, 1e-9);
  }
}

// A scripted drive (a beacon on a path) follows its circle exactly:
// centre, radius and speed from the commanded wheel speeds alone; motor
// frames latched afterwards do not move it.
TEST(Motion, ScriptedDriveFollowsItsCircle) {
  Profile p = defaults();
  p.robot.motor_lag_s = 0;
  const double radius = 3, speed = 0.5, half = p.robot.track_ft / 2;
  const double omega = speed / radius;     // rad/s, clockwise
  Arena a(config(p, {Pose{0, -3, 270}}));  // on the circle about the origin, heading west
  ASSERT_TRUE(a.setDrive(0, speed + omega * half, speed - omega * half, 0));
  EXPECT_FALSE(a.setDrive(0, speed + omega * half, speed - omega * half, 0));
  EXPECT_TRUE(a.setWheels(0, frame("ffg0ffg0"), 0));  // latched, but the drive rules
  a.advance(ticks(40));
  for (double t : {1.0, 7.5, 20.0, 37.7, 40.0}) {
    const double tt = secondsFromTick(ticks(t));
    const double phase = kPi + omega * tt;  // from +y, clockwise; starts at the south point
    const Pose q = a.pose(0, ticks(t));
    EXPECT_NEAR(q.x_ft, radius * std::sin(phase), 1e-5) << t;
    EXPECT_NEAR(q.y_ft, radius * std::cos(phase), 1e-5) << t;
    EXPECT_NEAR(std::hypot(q.x_ft, q.y_ft), radius, 1e-5) << t;
  }
  const RobotState s = a.state(0, ticks(40));
  EXPECT_NEAR(s.odometer_ft, speed * secondsFromTick(ticks(40)), 1e-9);
}

TEST(Motion, WheelLagStepResponse) {
  Profile p = defaults();
  p.robot.motor_lag_s = 0.2;
  p.robot.left_trim = p.robot.right_trim = 1.0;
  Arena a(config(p, {Pose{0, 0, 0}}));
  const auto t0 = ticks(0.1);
  a.advance(t0);
  a.setWheels(0, frame("cfg0crg0"), t0);  // spin: stays far from everything
  const double vl = p.robot.speed_table_fps[12];
  a.advance(ticks(1.2));
  for (double t : {0.1, 0.15, 0.3, 0.5, 1.0, 1.2}) {
    const double dt = secondsFromTick(ticks(t)) - secondsFromTick(t0);
    const RobotState s = a.state(0, ticks(t));
    expectRel(s.left_fps, vl * (1 - std::exp(-dt / 0.2)), 1e-6, "left");
    expectRel(s.right_fps, -vl * (1 - std::exp(-dt / 0.2)), 1e-6, "right");
  }
}

// The step bound (arena_integrator.cpp stepBound). The default robot
// (top speed v = 1.45 ft/s, track 0.75 ft, body 12.75 in: radius 0.53125 ft)
// has a point speed of v + (2 v / 0.75) 0.53125 = 3.5042 ft/s, so while it
// touches something a step is at most (1/12) / 3.5042 = 0.023781 s: at least
// ceil(1 / 0.023781) = 43 steps for each second it pushes. At rest (wheels
// and targets 0, no ball) nothing can cross, the bound is off, and ARKODE's
// steps grow as fast as it allows: far fewer than 100 s / 0.023781 = 4,205
// steps for 100 s, and the pose is exactly the start. Far from everything
// (a spin at (1, 1): the nearest feature, the divider's tip, is 4.6 ft away)
// the bound is that distance over the point speed, and a spin, whose centre
// does not move, takes a handful of steps.
TEST(Motion, AtRestTheStepIsUnboundedAndTouchingItIsOneInch) {
  Profile p = defaults();
  p.robot.left_trim = p.robot.right_trim = 1.0;
  const double r = 12.75 / 24;
  Arena a(config(p, {Pose{8 - r, 1, 90}}));  // put down against the east wall, facing it
  const auto rest = ticks(100.0);
  a.advance(rest);
  const IntegratorStats atRest = a.stats();
  EXPECT_LT(atRest.steps, 100);
  const Pose q = a.pose(0, rest);
  EXPECT_EQ(q.x_ft, 8 - r);
  EXPECT_EQ(q.y_ft, 1.0);
  EXPECT_EQ(q.heading_deg, 90.0);
  ASSERT_TRUE(a.setWheels(0, frame("ffg0ffg0"), rest));  // full ahead into the wall
  a.advance(rest + ticks(1.0));
  EXPECT_GE(a.stats().steps - atRest.steps, 43);
  // Held by the wall all along: the centre has not moved.
  EXPECT_NEAR(a.pose(0, rest + ticks(1.0)).x_ft, 8 - r, 1e-12);

  Arena b(config(p, {Pose{1, 1, 10}}));
  b.advance(rest);
  const IntegratorStats spinStart = b.stats();
  ASSERT_TRUE(b.setWheels(0, frame("cfg0crg0"), rest));  // spin in place
  b.advance(rest + ticks(1.0));
  EXPECT_LT(b.stats().steps - spinStart.steps, 10);
}

TEST(Motion, ForeDetectorEntersWireRangeAtClosedFormTick) {
  const Profile p = thesis();
  Arena a(config(p, {Pose{-6.5, -6.5, 0}}));
  a.setWheels(0, frame("ffg0ffg0"), 0);
  const double v = p.robot.speed_table_fps[15];
  const double R = p.robot.body_diameter_ft / 2;
  const double wire = p.field.size_ft / 2 - p.field.wire_inset_ft;
  const double yd0 = -6.5 + R - p.robot.edge_detector_inset_ft;
  const double t = (wire - p.field.wire_sensitivity_ft - yd0) / v;
  const std::int64_t want = static_cast<std::int64_t>(std::ceil(t * kTicksPerSecond));
  auto f = runUntil(a, EventKind::EdgeEnter, ticks(20));
  ASSERT_TRUE(f.has_value());
  EXPECT_EQ(f->event.detector, Detector::Fore);
  EXPECT_NEAR(static_cast<double>(f->tick), static_cast<double>(want), 10.0);
  EXPECT_TRUE(a.edgeDetectorLow(0, Detector::Fore, f->tick));
  EXPECT_FALSE(a.edgeDetectorLow(0, Detector::Fore, f->tick - 1));
  EXPECT_FALSE(a.edgeDetectorLow(0, Detector::Aft, f->tick));
}

TEST(Motion, ProjectileFlightTimeAndRange) {
  Profile p = thesis();
  p.robot.muzzle_speed_fps = 10.0;  // lands inside the field
  Arena a(config(p, {Pose{-2, 0, 90}}));
  a.setPortB(0, 0x08, 0);  // gun 1 motor on (instant in thesis-1997)
  const auto fire = ticks(0.5);
  a.advance(fire);
  EventList ev = a.setPortB(0, 0x18, fire);  // solenoid rising edge
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].kind, EventKind::SolenoidStroke);
  auto launch = runUntil(a, EventKind::BallLaunch, ticks(5));
  ASSERT_TRUE(launch.has_value());
  EXPECT_EQ(launch->tick, fire);  // stroke time 0
  const double h = p.robot.launch_height_ft, g = p.field.gravity_fps2;
  const double tf = std::sqrt(2 * h / g);
  const auto miss = runUntil(a, EventKind::BallMiss, ticks(5));
  ASSERT_TRUE(miss.has_value());
  EXPECT_EQ(miss->event.miss, MissReason::Floor);
  const double tLaunch = secondsFromTick(fire);
  EXPECT_NEAR(static_cast<double>(miss->tick), std::ceil((tLaunch + tf) * kTicksPerSecond), 10.0);
  // Ball position at the tick before the floor: on the line, height ~0.
  const auto before = miss->tick - 1;
  const auto balls = a.balls(before);
  ASSERT_EQ(balls.size(), 1u);
  const double dt = secondsFromTick(before) - tLaunch;
  const double muzzleX = -2 + p.robot.body_diameter_ft / 2;
  expectRel(balls[0].x_ft, muzzleX + 10.0 * dt, 1e-6, "ball x");
  expectRel(balls[0].z_ft + 1.0, h - 0.5 * g * dt * dt + 1.0, 1e-6, "ball z");
  // Range at the floor: muzzle + v * sqrt(2h/g).
  EXPECT_NEAR(balls[0].x_ft, muzzleX + 10.0 * tf, 1e-4);
  EXPECT_EQ(a.shots(0), 1);
  EXPECT_EQ(a.ballsLeft(0, 0), 14);
  // In flight up to the floor, not once that tick has been passed.
  EXPECT_TRUE(a.ballsInFlight());
  a.advance(miss->tick + 1);
  EXPECT_FALSE(a.ballsInFlight());
}

// Words chosen so that drawDispersion's Box-Muller pair gives a radius r
// (u1 = exp(-r^2 / 2)) at angle pi/2 (u2 = 1/4): elevation sigma r, azimuth
// ~0. The flight is then checked against the closed form of the velocity
// the launch reports, not against the draw.
class FixedWords final : public RandomBits {
 public:
  explicit FixedWords(double r)
      : u1_((static_cast<std::uint64_t>(std::exp(-r * r / 2) * 0x1.0p53) - 1) << 11) {}
  std::uint64_t next() override { return (n_++ % 2 == 0) ? u1_ : std::uint64_t{1} << 62; }

 private:
  std::uint64_t u1_;
  int n_ = 0;
};

// A ball raised by the elevation dispersion flies z = h + vz s - g s^2 / 2
// (muzzle 20 ft/s, elevation about 30 deg: vz = 10, across 17.3 ft/s, apex
// 3.05 ft at 5.4 ft). Alone it lands where that parabola meets the floor.
// A target whose body it passes entirely above 2.5 ft is not hit (it flies
// over); a target centred where it comes down through 2.5 ft is hit on the
// top, at that height, after it passed the body's side too high.
TEST(Motion, AnElevatedBallFollowsItsParabolaOverAndOntoTheTarget) {
  Profile p = thesis();
  p.robot.muzzle_speed_fps = 20.0;
  p.robot.elevation_sigma_deg = 5.0;
  const double h = p.robot.launch_height_ft, g = p.field.gravity_fps2;
  const double R = p.robot.body_diameter_ft / 2, top = p.robot.target_height_ft;
  const double muzzleX = -6 + R;
  struct Shot {
    std::optional<Found> launch, end;
  };
  const auto shoot = [&](std::initializer_list<Pose> poses) {
    Arena a(config(p, poses));
    FixedWords words(6.0);
    a.setPortB(0, 1u << 4, 0, nullptr, nullptr, &words);
    Shot s;
    s.launch = runUntil(a, EventKind::BallLaunch, ticks(2));
    while (a.now() < ticks(2) && !s.end) {
      const AdvanceResult r = a.advance(ticks(2));
      for (const Event& e : r.events)
        if (e.kind == EventKind::BallHit || e.kind == EventKind::BallMiss) s.end = Found{r.tick, e};
    }
    return s;
  };
  const Shot alone = shoot({Pose{-6, 0, 90}});
  ASSERT_TRUE(alone.launch && alone.end);
  const Event& l = alone.launch->event;
  const double vz = l.vz, across = std::hypot(l.vx, l.vy);
  ASSERT_NEAR(std::atan2(vz, across) * 180 / 3.14159265358979323846, 30, 1e-6);
  EXPECT_NEAR(l.vy, 0, 1e-12);
  // The floor: the positive root of h + vz s - g s^2 / 2.
  const double floorS = (vz + std::sqrt(vz * vz + 2 * g * h)) / g;
  EXPECT_EQ(alone.end->event.kind, EventKind::BallMiss);
  EXPECT_EQ(alone.end->event.miss, MissReason::Floor);
  EXPECT_NEAR(secondsFromTick(alone.end->tick), floorS, 2.0 / kTicksPerSecond);
  EXPECT_NEAR(alone.end->event.x, muzzleX + across * floorS, 1e-4);
  // Where it comes down through the target's height (the later root).
  const double downS = (vz + std::sqrt(vz * vz - 2 * g * (top - h))) / g;
  const double downX = muzzleX + across * downS;
  // The apex, over a body whose near and far sides the ball passes above 2.5.
  const double apexX = muzzleX + across * vz / g;
  const auto zAt = [&](double x) {
    const double s = (x - muzzleX) / across;
    return h + vz * s - g * s * s / 2;
  };
  ASSERT_GT(zAt(apexX - R), top);
  ASSERT_GT(zAt(apexX + R), top);
  const Shot over = shoot({Pose{-6, 0, 90}, Pose{apexX, 0, 270}});
  ASSERT_TRUE(over.end);
  EXPECT_EQ(over.end->event.kind, EventKind::BallMiss) << "flew over the target";
  ASSERT_GT(zAt(downX - R), top);  // too high at the body's side
  const Shot onTop = shoot({Pose{-6, 0, 90}, Pose{downX, 0, 270}});
  ASSERT_TRUE(onTop.end);
  EXPECT_EQ(onTop.end->event.kind, EventKind::BallHit);
  EXPECT_NEAR(onTop.end->event.z, top, 1e-3);
  EXPECT_NEAR(onTop.end->event.x, downX, 1e-3);
  EXPECT_NEAR(secondsFromTick(onTop.end->tick), downS, 2.0 / kTicksPerSecond);
}

// thesis-1997 follows Appendix E: gun motors on at all times. ICEMAN's
// fire() strokes with 0x30, the motor bits already off again: the ball must
// still leave at full muzzle speed there, and fall at the muzzle when the
// motor bits rule and the wheel has no spin-down (lag 0).
TEST(Motion, GunMotorsAlwaysOnIgnoresTheMotorBits) {
  for (bool alwaysOn : {true, false}) {
    Profile p = thesis();
    ASSERT_TRUE(p.robot.gun_motors_always_on);
    p.robot.gun_motors_always_on = alwaysOn;
    Arena a(config(p, {Pose{-2, 0, 90}}));
    a.setPortB(0, 0x88, 0);
    const auto fire = ticks(0.5);
    a.advance(fire);
    a.setPortB(0, 0x30, fire);  // solenoids on, motors off
    ASSERT_TRUE(runUntil(a, EventKind::BallLaunch, ticks(1)).has_value());
    const auto later = fire + ticks(0.01);
    a.advance(later);
    const auto balls = a.balls(later);
    ASSERT_EQ(balls.size(), 2u);
    const double muzzleX = -2 + p.robot.body_diameter_ft / 2;
    const double flown = balls[0].x_ft - muzzleX;
    if (alwaysOn)
      expectRel(flown, p.robot.muzzle_speed_fps * (secondsFromTick(later) - secondsFromTick(fire)),
                1e-9, "full muzzle speed");
    else
      EXPECT_NEAR(flown, 0.0, 1e-12);
  }
}

TEST(Motion, HitTickMatchesClosedForm) {
  const Profile p = thesis();
  Arena a(config(p, {Pose{-3, 0, 90}, Pose{3, 0, 270}}));
  a.setPortB(0, 0x08, 0);
  const auto fire = ticks(0.25);
  a.advance(fire);
  a.setPortB(0, 0x18, fire);
  const auto hit = runUntil(a, EventKind::BallHit, ticks(2));
  ASSERT_TRUE(hit.has_value());
  const double R = p.robot.body_diameter_ft / 2;
  const double flight = (6.0 - 2 * R) / p.robot.muzzle_speed_fps;
  const double want = std::ceil((secondsFromTick(fire) + flight) * kTicksPerSecond);
  EXPECT_NEAR(static_cast<double>(hit->tick), want, 10.0);
  EXPECT_EQ(hit->event.robot, 0);
  EXPECT_EQ(hit->event.other, 1);
  EXPECT_TRUE(a.ballsInFlight());
  a.advance(hit->tick + 1);
  EXPECT_EQ(a.hits(0), 1);
  EXPECT_FALSE(a.ballsInFlight());
}

TEST(Motion, FloorSkipsCountOnlyWithTheOption) {
  for (bool skips : {false, true}) {
    Profile p = thesis();
    p.robot.muzzle_speed_fps = 10.0;  // lands about 3 ft out, short of B
    p.field.count_floor_skips = skips;
    Arena a(config(p, {Pose{-3, 0, 90}, Pose{3, 0, 270}}));
    a.setPortB(0, 0x08, 0);
    a.setPortB(0, 0x18, 0);
    bool hit = false, miss = false;
    while (a.now() < ticks(2)) {
      AdvanceResult r = a.advance(ticks(2));
      for (const Event& e : r.events) {
        hit = hit || e.kind == EventKind::BallHit;
        miss = miss || e.kind == EventKind::BallMiss;
      }
    }
    EXPECT_EQ(hit, skips);
    EXPECT_EQ(miss, !skips);
  }
}

TEST(Motion, UnchangedInputsDoNotReinitialise) {
  const Profile p = thesis();
  Arena a(config(p, {Pose{0, 0, 0}}));
  a.setWheels(0, frame("5fg05fg0"), 0);
  a.advance(ticks(0.5));
  const long before = a.stats().reinits;
  EXPECT_FALSE(a.setWheels(0, frame("5fg05fg0"), ticks(0.5)));
  EXPECT_TRUE(a.setWheels(0, frame("5fgx5fgy"), ticks(0.5)));  // counter bytes only
  EXPECT_TRUE(a.setPortB(0, 0x40, ticks(0.5)).size() == 1);    // disc shooter: logged only
  EXPECT_EQ(a.stats().reinits, before);
  EXPECT_EQ(a.now(), ticks(0.5));
  a.setWheels(0, frame("9fg05fg0"), ticks(0.5));
  EXPECT_EQ(a.stats().reinits, before + 1);
}

TEST(Motion, DividerStopsLowBall) {
  Profile p = thesis();
  p.robot.launch_height_ft = 0.5;  // below the divider's top
  Arena a(config(p, {Pose{-3, -6, 90}, Pose{3, -6, 270}}));
  a.setPortB(0, 0x08, 0);
  a.setPortB(0, 0x18, 0);
  const auto miss = runUntil(a, EventKind::BallMiss, ticks(2));
  ASSERT_TRUE(miss.has_value());
  EXPECT_EQ(miss->event.miss, MissReason::Divider);
  EXPECT_EQ(a.hits(0), 0);
  EXPECT_TRUE(a.ballsInFlight());
  a.advance(miss->tick + 1);
  EXPECT_FALSE(a.ballsInFlight());
}

TEST(Motion, BumperReflexBacksOffProfileDistance) {
  const Profile p = thesis();
  Arena a(config(p, {Pose{2, 0, 90}}));  // east, towards the wall
  a.setWheels(0, frame("ffg0ffg0"), 0);
  const double R = p.robot.body_diameter_ft / 2, v = p.robot.speed_table_fps[15];
  auto contact = runUntil(a, EventKind::Contact, ticks(20));
  ASSERT_TRUE(contact.has_value());
  EXPECT_EQ(contact->event.with, ContactWith::Wall);
  EXPECT_EQ(contact->event.bumper, Bumper::Front);
  const double tContact = (8 - R - 2) / v;
  EXPECT_NEAR(static_cast<double>(contact->tick), std::ceil(tContact * kTicksPerSecond), 10.0);
  const Pose atContact = a.pose(0, contact->tick);
  EXPECT_NEAR(atContact.x_ft, 8 - R, 1e-6);
  a.advance(contact->tick + 1);
  EXPECT_TRUE(a.inReflex(0));
  // A frame latched during the reflex takes effect at its end.
  EXPECT_TRUE(a.setWheels(0, frame("0fs00fs0"), a.now()));
  auto end = runUntil(a, EventKind::ReflexEnd, ticks(30));
  ASSERT_TRUE(end.has_value());
  const Pose atEnd = a.pose(0, end->tick);
  EXPECT_NEAR(atContact.x_ft - atEnd.x_ft, p.robot.reflex_distance_ft, 1e-6);
  EXPECT_NEAR(atEnd.heading_deg, 90, 1e-9);
  EXPECT_NEAR(static_cast<double>(end->tick - contact->tick),
              p.robot.reflex_distance_ft / v * kTicksPerSecond, 10.0);
  a.advance(end->tick + ticks(1));
  EXPECT_FALSE(a.inReflex(0));
  EXPECT_NEAR(a.pose(0, a.now()).x_ft, atEnd.x_ft, 1e-9);  // stopped
}

TEST(Motion, RobotsBumpingBothReflex) {
  const Profile p = thesis();
  Arena a(config(p, {Pose{-2, 2, 90}, Pose{2, 2, 270}}));
  a.setWheels(0, frame("ffg0ffg0"), 0);
  auto c = runUntil(a, EventKind::Contact, ticks(10));
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->event.with, ContactWith::Robot);
  AdvanceResult r = a.advance(c->tick);  // applies the pending events
  (void)r;
  EXPECT_TRUE(a.inReflex(0));
  EXPECT_TRUE(a.inReflex(1));
  const double R = p.robot.body_diameter_ft / 2;
  EXPECT_NEAR(a.pose(0, c->tick).x_ft, 2 - 2 * R, 1e-6);
}

TEST(Motion, RefereePutsBackARobotThatLeftTheField) {
  Profile p = thesis();
  p.field.field_walls = false;
  Arena a(config(p, {Pose{5, 0, 90}}));
  a.setWheels(0, frame("ffg0ffg0"), 0);
  auto f = runUntil(a, EventKind::RefereePutBack, ticks(20));
  ASSERT_TRUE(f.has_value());
  const double wire = p.field.size_ft / 2 - p.field.wire_inset_ft;
  const Pose q = a.pose(0, f->tick);
  EXPECT_NEAR(q.x_ft, wire - p.referee.putback_ft, 1e-12);
  EXPECT_NEAR(q.y_ft, 0, 1e-9);
  EXPECT_NEAR(q.heading_deg, 90, 1e-9);
  EXPECT_NEAR(static_cast<double>(f->tick), std::ceil(3.0 / 1.5 * kTicksPerSecond), 10.0);
}

TEST(Motion, RefereeTurnsARobotStuckOnTheWall) {
  const Profile p = thesis();
  Arena a(config(p, {Pose{5, 0, 90}}));
  a.setWheels(0, frame("ffg0ffg0"), 0);
  auto f = runUntil(a, EventKind::RefereeTurn, ticks(30));
  ASSERT_TRUE(f.has_value());
  a.advance(f->tick);
  EXPECT_NEAR(a.pose(0, f->tick).heading_deg, 135, 1e-6);
}

TEST(Motion, RewindToAnEarlierTickMatchesInOrderInputs) {
  const Profile p = thesis();
  Arena ahead(config(p, {Pose{0, 0, 0}}));
  Arena inOrder(config(p, {Pose{0, 0, 0}}));
  for (Arena* a : {&ahead, &inOrder}) a->setWheels(0, frame("afg0ffg0"), 0);
  ahead.advance(ticks(1.0));
  inOrder.advance(ticks(0.5));
  ahead.setWheels(0, frame("ffg0afg0"), ticks(0.5));  // earlier than now()
  inOrder.setWheels(0, frame("ffg0afg0"), ticks(0.5));
  EXPECT_EQ(ahead.now(), ticks(0.5));
  ahead.advance(ticks(2));
  inOrder.advance(ticks(2));
  const Pose x = ahead.pose(0, ticks(2)), y = inOrder.pose(0, ticks(2));
  EXPECT_NEAR(x.x_ft, y.x_ft, 1e-8);
  EXPECT_NEAR(x.y_ft, y.y_ft, 1e-8);
  EXPECT_NEAR(x.heading_deg, y.heading_deg, 1e-7);
}

// One scripted match; `query` adds sensor reads at many ticks.
std::vector<double> scripted(bool query, IntegratorStats* stats) {
  const Profile p = defaults();
  Arena a(makeArenaConfig(p, 2));
  std::vector<double> out;
  const char* frames[] = {"ffg0cfg0", "8rg08fg0", "ffg0ffg0", "3fg0frg0", "ffg0ffg0"};
  std::int64_t t = 0;
  a.setPortB(0, 0x08, 0);
  a.setPortB(1, 0x88, 0);
  for (int step = 0; step < 40; ++step) {
    const std::int64_t next = t + ticks(0.73);
    while (a.now() < next) {
      a.advance(next);
      if (query)
        for (std::int64_t q = a.lastReinitTick(); q <= a.now(); q += 99991) {
          (void)a.eyeReadings(0, q);
          (void)a.pose(1, q);
        }
    }
    t = next;
    a.setWheels(step % 2, frame(frames[step % 5]), t);
    if (step % 7 == 3) a.setPortB(step % 2, static_cast<std::uint8_t>(step % 2 ? 0x98 : 0x18), t);
    if (step % 7 == 4) a.setPortB(step % 2, static_cast<std::uint8_t>(step % 2 ? 0x88 : 0x08), t);
    for (int r = 0; r < 2; ++r) {
      const Pose q = a.pose(r, t);
      out.insert(out.end(), {q.x_ft, q.y_ft, q.heading_deg});
    }
  }
  *stats = a.stats();
  return out;
}

TEST(Determinism, SameCallsGiveBitIdenticalPosesWhetherQueriedOrNot) {
  IntegratorStats s1, s2, s3;
  const auto a = scripted(false, &s1);
  const auto b = scripted(false, &s2);
  const auto c = scripted(true, &s3);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), c.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0);
  EXPECT_EQ(std::memcmp(a.data(), c.data(), a.size() * sizeof(double)), 0);
  EXPECT_EQ(s1.steps, s3.steps);
  EXPECT_EQ(s1.rhs_evals, s3.rhs_evals);
  EXPECT_EQ(s1.reinits, s3.reinits);
  EXPECT_EQ(s1.roots, s3.roots);
  EXPECT_GT(s1.steps, 0);
  EXPECT_GT(s1.reinits, 0);
}

// Two robots driving from opposite corners, one of them turning: the
// arena the query tests ask poses of.
Arena turningPair(const Profile& p) {
  Arena a(config(p, {Pose{-6.5, -6.5, 30}, Pose{6, 6, 200}}));
  a.setWheels(0, frame("cfg0afg0"), 0);
  a.setWheels(1, frame("ffg0ffg0"), 0);
  return a;
}

// pose() evaluates only x, y and heading; it must give the very bits of
// state().pose, inside a segment and at a tick with pending events.
TEST(Queries, PoseIsTheStatesPoseBitForBit) {
  const Profile p = defaults();
  Arena a = turningPair(p);
  int checked = 0;
  while (a.now() < ticks(12)) {
    const std::int64_t from = a.lastReinitTick();
    const AdvanceResult r = a.advance(ticks(12));
    for (int robot = 0; robot < 2; ++robot)
      for (std::int64_t t : {from, (from + r.tick) / 2, r.tick}) {
        if (t < a.lastReinitTick()) continue;
        const Pose q = a.pose(robot, t), s = a.state(robot, t).pose;
        EXPECT_EQ(std::memcmp(&q, &s, sizeof q), 0) << robot << " " << t;
        ++checked;
      }
  }
  EXPECT_GT(checked, 10);
}

// The dense output's record for a tick is found from the one found last
// (recordAt): the poses of ticks asked in rising, falling and alternating
// order are the same bits, each from the step that holds its tick.
TEST(Queries, APoseDoesNotDependOnTheTicksAskedBefore) {
  const Profile p = defaults();
  Arena a = turningPair(p);
  int checked = 0;
  while (a.now() < ticks(12)) {
    const AdvanceResult r = a.advance(ticks(12));
    const std::int64_t from = a.lastReinitTick();
    if (r.tick - from < 16) continue;
    std::vector<std::int64_t> at;
    for (int k = 0; k <= 16; ++k) at.push_back(from + (r.tick - from) * k / 16);
    std::vector<Pose> rising, falling(at.size()), alternating(at.size());
    for (std::int64_t t : at) rising.push_back(a.pose(0, t));
    for (std::size_t k = at.size(); k-- > 0;) falling[k] = a.pose(0, at[k]);
    for (std::size_t k = 0; k < at.size(); ++k) {
      const std::size_t j = k % 2 == 0 ? k / 2 : at.size() - 1 - k / 2;
      alternating[j] = a.pose(0, at[j]);
    }
    for (std::size_t k = 0; k < at.size(); ++k) {
      EXPECT_EQ(std::memcmp(&rising[k], &falling[k], sizeof(Pose)), 0) << at[k];
      EXPECT_EQ(std::memcmp(&rising[k], &alternating[k], sizeof(Pose)), 0) << at[k];
      ++checked;
    }
  }
  EXPECT_GT(checked, 50);
}

TEST(Queries, OutsideTheWindowThrow) {
  const Profile p = thesis();
  Arena a(config(p, {Pose{0, 0, 0}}));
  a.advance(ticks(1));
  EXPECT_THROW(a.pose(0, ticks(2)), std::out_of_range);
  a.setWheels(0, frame("ffg0ffg0"), ticks(1));
  EXPECT_THROW(a.pose(0, ticks(0.5)), std::out_of_range);
  EXPECT_NO_THROW(a.pose(0, ticks(1)));
}

}  // namespace
