// Fixed obstacles against closed forms worked here, independently of the
// plant's geometry (plant/geometry.h): a robot driven straight into a
// circle, a box and a polygon from 14 directions touches at the tick the
// ray cast of its centre against the obstacle grown by the body's radius
// gives, and never sinks in; a ball meets an obstacle at the tick its
// ballistic flight gives; an obstacle taller than the beacon hides it, a
// lower one does not.
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "plant_support.h"

namespace {

using namespace plant_test;
using LD = long double;

constexpr std::int64_t kStart = 777'777;  // an odd tick: no answer is a round number
constexpr LD kPiL = 3.141592653589793238462643383279502884L;

struct P2 {
  LD x, y;
};
P2 operator-(P2 a, P2 b) { return {a.x - b.x, a.y - b.y}; }
P2 operator+(P2 a, P2 b) { return {a.x + b.x, a.y + b.y}; }
P2 operator*(LD s, P2 a) { return {s * a.x, s * a.y}; }
LD dot(P2 a, P2 b) { return a.x * b.x + a.y * b.y; }
LD cross(P2 a, P2 b) { return a.x * b.y - a.y * b.x; }

// Smallest s >= 0 with |c + s u - q| = R (u a unit vector), or -1.
LD rayCircle(P2 c, P2 u, P2 q, LD R) {
  const P2 m = c - q;
  const LD b = dot(m, u), cc = dot(m, m) - R * R, disc = b * b - cc;
  if (disc < 0) return -1;
  const LD s = -b - std::sqrt(disc);
  return s >= 0 ? s : -1;
}

// The body's centre c moves along the unit vector u; it first touches the
// convex polygon v (counter-clockwise) when it reaches the polygon grown by
// the body's radius r: a face moved out by r along its outward normal
// (the crossing must fall within the face's length), or a circle of
// radius r about a corner. The smallest such s >= 0.
LD rayGrownPolygon(P2 c, P2 u, const std::vector<P2>& v, LD r) {
  LD best = -1;
  auto take = [&](LD s) {
    if (s >= 0 && (best < 0 || s < best)) best = s;
  };
  for (std::size_t k = 0; k < v.size(); ++k) {
    const P2 a = v[k], b = v[(k + 1) % v.size()];
    const P2 e = b - a;
    const LD len = std::sqrt(dot(e, e));
    const P2 n{e.y / len, -e.x / len};  // outward: the inside is to the left
    const LD den = dot(n, u);
    if (den < 0) {  // moving towards the face
      const LD s = (r - dot(n, c - a)) / den;
      const LD along = dot(c + s * u - a, e) / len;
      if (along >= 0 && along <= len) take(s);
    }
    take(rayCircle(c, u, a, r));
  }
  return best;
}

// Distance from p to the convex polygon (0 inside), for the sinking check.
LD distanceToPolygon(P2 p, const std::vector<P2>& v) {
  bool inside = true;
  LD best = 1e30L;
  for (std::size_t k = 0; k < v.size(); ++k) {
    const P2 a = v[k], b = v[(k + 1) % v.size()];
    const P2 e = b - a;
    inside = inside && cross(e, p - a) >= 0;
    const LD t = std::clamp(dot(p - a, e) / dot(e, e), 0.0L, 1.0L);
    const P2 d = p - (a + t * e);
    best = std::min(best, std::sqrt(dot(d, d)));
  }
  return inside ? 0 : best;
}

// The test's own shapes: a circle (radius > 0) or a polygon.
struct Shape {
  Obstacle obstacle;
  P2 centre;
  LD radius = 0;
  std::vector<P2> corners;
};

Shape circle(LD x, LD y, LD r, LD height) {
  Obstacle o;
  o.kind = Obstacle::Kind::Circle;
  o.x_ft = static_cast<double>(x);
  o.y_ft = static_cast<double>(y);
  o.radius_ft = static_cast<double>(r);
  o.height_ft = static_cast<double>(height);
  return {o, {x, y}, r, {}};
}

// A 2.2 x 1.2 ft box about (x, y) turned 25 degrees clockwise: its
// corners worked here from the rotation (cos a, -sin a), (sin a, cos a).
Shape box(LD x, LD y, LD height) {
  const LD w = 2.2L, d = 1.2L, a = 25 * kPiL / 180;
  const P2 ux{std::cos(a), -std::sin(a)}, uy{std::sin(a), std::cos(a)};
  Shape s{makeBox(static_cast<double>(x), static_cast<double>(y), 2.2, 1.2, 25,
                  static_cast<double>(height)),
          {x, y},
          0,
          {}};
  for (const auto& [i, j] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}})
    s.corners.push_back(P2{x, y} + (i * w / 2) * ux + (j * d / 2) * uy);
  return s;
}

// A convex pentagon about (x, y), given clockwise (the plant takes either
// order); the test keeps its own counter-clockwise copy.
Shape pentagon(LD x, LD y, LD height) {
  const std::vector<P2> ccw = {{x - 1.0L, y - 0.7L},
                               {x + 0.8L, y - 0.9L},
                               {x + 1.2L, y + 0.3L},
                               {x + 0.1L, y + 1.1L},
                               {x - 1.1L, y + 0.4L}};
  std::vector<ObstaclePoint> cw;
  for (auto it = ccw.rbegin(); it != ccw.rend(); ++it)
    cw.push_back({static_cast<double>(it->x), static_cast<double>(it->y)});
  return {makePolygon(cw, static_cast<double>(height)), {x, y}, 0, ccw};
}

LD firstTouch(const Shape& s, P2 c, P2 u, LD r) {
  return s.radius > 0 ? rayCircle(c, u, s.centre, s.radius + r)
                      : rayGrownPolygon(c, u, s.corners, r);
}
LD clearance(const Shape& s, P2 c, LD r) {
  if (s.radius > 0) {
    const P2 d = c - s.centre;
    return std::sqrt(dot(d, d)) - s.radius - r;
  }
  return distanceToPolygon(c, s.corners) - r;
}

// The tick of an event s seconds after tick `from`: the first tick at or
// after it, ceil((from / N + s) N) = from + ceil(s N) with N timebase's
// 9,216,000 ticks a second (DESIGN.md "Time and determinism").
std::int64_t tickAfter(std::int64_t from, LD seconds) {
  return from + static_cast<std::int64_t>(std::ceil(seconds * simbot::timebase::kTicksPerSecond));
}

// thesis-1997: speed 15 is 1.5 ft/s on both wheels at once (no motor lag),
// the body 12.75 in across (r = 0.53125 ft). From 14 headings 360/14 deg
// apart, the robot starts 3.4 ft from the obstacle's centre, moved 0.3 ft
// to the side of the line through it (so it meets faces, corners and the
// circle off-centre), and drives straight from kStart: its centre moves
// c0 + s u (u = (sin h, cos h)); the contact is at tick kStart + ceil(s* /
// 1.5 N) with s* the ray cast above. At that tick the front bumper trips
// (the obstacle is ahead), and until the reflex has backed it off 0.5 ft
// every 500th tick's pose keeps the body outside the obstacle to within
// 1e-6 ft.
void driveInto(const Shape& s, const char* what) {
  const Profile p = thesis();
  ASSERT_EQ(p.robot.speed_table_fps[15], 1.5);
  ASSERT_EQ(p.robot.motor_lag_s, 0.0);
  const LD r = p.robot.body_diameter_ft / 2;
  for (int j = 0; j < 14; ++j) {
    const LD h = j * 2 * kPiL / 14;
    const P2 u{std::sin(h), std::cos(h)}, side{u.y, -u.x};
    const P2 c0 = s.centre - 3.4L * u + 0.3L * side;
    const LD sTouch = firstTouch(s, c0, u, r);
    ASSERT_GT(sTouch, 0) << what << " heading " << j;
    const std::int64_t want = tickAfter(kStart, sTouch / 1.5L);
    ArenaConfig cfg = config(p, {Pose{static_cast<double>(c0.x), static_cast<double>(c0.y),
                                      static_cast<double>(h * 180 / kPiL)}});
    cfg.field.obstacles = {s.obstacle};
    Arena a(cfg);
    a.advance(kStart);
    a.setWheels(0, frame("ffg0ffg0"), kStart);
    const auto c = runUntil(a, EventKind::Contact, kStart + 40'000'000);
    ASSERT_TRUE(c.has_value()) << what << " heading " << j;
    EXPECT_EQ(c->tick, want) << what << " heading " << j << ": s* " << static_cast<double>(sTouch);
    EXPECT_EQ(c->event.with, ContactWith::Obstacle);
    EXPECT_EQ(c->event.obstacle, 0);
    EXPECT_EQ(c->event.bumper, Bumper::Front);
    // The reflex backs off 1.5 ft in 1 s; look at its first third.
    const std::int64_t until = c->tick + 3'072'000;
    std::int64_t t = c->tick - 2'000;
    while (t <= until) {
      while (a.now() < t) a.advance(t);
      const Pose q = a.pose(0, t);
      EXPECT_GE(clearance(s, P2{q.x_ft, q.y_ft}, r), -1e-6L) << what << " heading " << j;
      t += 500;
    }
  }
}

TEST(Obstacles, RobotTouchesACircleAtTheClosedFormTick) {
  driveInto(circle(2, 3, 0.8L, 1), "circle");
}
TEST(Obstacles, RobotTouchesABoxAtTheClosedFormTick) { driveInto(box(-2.5L, 2, 2), "box"); }
TEST(Obstacles, RobotTouchesAPolygonAtTheClosedFormTick) {
  driveInto(pentagon(3, 1, 0.5L), "polygon");
}

// The default profile's motor lag (0.25 s) keeps the wheels driving into
// the obstacle for a while after the reflex reverses them: the body is
// held against the box, sliding along its south face (it drives 15 deg
// off that face's normal),
// and the contact ends only when the wheels take it away. Every 100th
// tick of the contact the body is outside the box to within 1e-6 ft.
TEST(Obstacles, ABodyPushingAgainstABoxIsHeldOutside) {
  Profile p = defaults();
  p.robot.trim_spread = 0;
  const LD r = p.robot.body_diameter_ft / 2;
  const Shape s = box(1, 2, 2);
  Arena a([&] {
    ArenaConfig c = config(p, {Pose{1.0 - 2.2 * std::sin(0.7), 2.0 - 2.2 * std::cos(0.7), 40}});
    c.field.obstacles = {s.obstacle};
    return c;
  }());
  a.advance(kStart);
  a.setWheels(0, frame("ffg0ffg0"), kStart);
  const auto c = runUntil(a, EventKind::Contact, kStart + 60'000'000);
  ASSERT_TRUE(c.has_value());
  const auto end = runUntil(a, EventKind::ContactEnd, c->tick + 20'000'000);
  ASSERT_TRUE(end.has_value());
  EXPECT_GT(end->tick - c->tick, 100'000);  // held for more than 10 ms
  Arena b([&] {
    ArenaConfig cfg = config(p, {Pose{1.0 - 2.2 * std::sin(0.7), 2.0 - 2.2 * std::cos(0.7), 40}});
    cfg.field.obstacles = {s.obstacle};
    return cfg;
  }());
  b.advance(kStart);
  b.setWheels(0, frame("ffg0ffg0"), kStart);
  for (std::int64_t t = c->tick; t <= end->tick; t += 100) {
    while (b.now() < t) b.advance(t);
    const Pose q = b.pose(0, t);
    ASSERT_GE(clearance(s, P2{q.x_ft, q.y_ft}, r), -1e-6L) << "tick " << t;
  }
}

// thesis-1997's gun: 105 ft/s along the heading, horizontal, from 1.5 ft,
// the muzzle on the body's edge (0.53125 ft ahead of the centre), no
// stroke time. A robot at (-5, -1) heading east fires at kStart; the
// ball flies x = -5 + 0.53125 + 105 s, z = 1.5 - 32.174 s^2 / 2.
struct Shot {
  std::int64_t tick;
  Event event;
};
Shot fireEast(const std::vector<Obstacle>& obstacles) {
  const Profile p = thesis();
  ArenaConfig cfg = config(p, {Pose{-5, -1, 90}});
  cfg.field.obstacles = obstacles;
  Arena a(cfg);
  a.advance(kStart);
  a.setPortB(0, 1u << 4, kStart);  // gun 1's solenoid (default hardware)
  const auto miss = runUntil(a, EventKind::BallMiss, kStart + 10'000'000);
  EXPECT_TRUE(miss.has_value());
  return miss ? Shot{miss->tick, miss->event} : Shot{-1, Event{}};
}

// A 2-ft circle of radius 0.5 at (0, -0.8): the path y = -1 crosses it
// where (x)^2 + 0.2^2 = 0.25, x = -sqrt(0.21); the ball, 1.49 ft high
// there, is below 2 ft: it stops at x = -sqrt(0.21), after
// (5 - 0.53125 - sqrt(0.21)) / 105 s.
TEST(Obstacles, ABallStopsAtATallCircle) {
  const Shot m = fireEast({circle(0, -0.8L, 0.5L, 2).obstacle});
  const LD s = (5 - 0.53125L - std::sqrt(0.21L)) / 105;
  EXPECT_EQ(m.tick, tickAfter(kStart, s));
  EXPECT_EQ(m.event.miss, MissReason::Obstacle);
  EXPECT_EQ(m.event.obstacle, 0);
  EXPECT_NEAR(m.event.x, static_cast<double>(-std::sqrt(0.21L)), 2e-5);
}

// A box 1.45 ft high from x = -1 to x = 2 (width 3 about x = 0.5, depth 2
// about y = -1): the ball enters its footprint at x = -1, 3.46875 ft and
// 0.033036 s out, 1.5 - 16.087 s^2 = 1.4824 ft high: over it. It comes
// down through 1.45 ft at s = sqrt(0.05 * 2 / 32.174) = 0.055750 s,
// x = -4.46875 + 105 s = 1.3851, still over the box: it stops on its top.
TEST(Obstacles, ABallThatClearsABoxsEdgeStopsOnItsTop) {
  Obstacle o = makeBox(0.5, -1, 3, 2, 0, 1.45);
  const Shot m = fireEast({o});
  const LD s = std::sqrt(2 * 0.05L / 32.174L);
  EXPECT_EQ(m.tick, tickAfter(kStart, s));
  EXPECT_EQ(m.event.miss, MissReason::Obstacle);
  EXPECT_NEAR(m.event.z, 1.45, 1e-5);
}

// A box 1.0 ft high in the same place is below the ball (at most 1.5 ft,
// and 1.4 ft at x = 2): it flies over it to the east wall, x = 8 after
// (13 - 0.53125) / 105 s.
TEST(Obstacles, ABallFliesOverALowBox) {
  const Shot m = fireEast({makeBox(0.5, -1, 3, 2, 0, 1.0)});
  EXPECT_EQ(m.tick, tickAfter(kStart, (13 - 0.53125L) / 105));
  EXPECT_EQ(m.event.miss, MissReason::LeftField);
}

// Robot A at (-4, 2) facing east, B 6 ft east at (2, 2): no divider
// between them (it ends at y = -4), gamma = 0, so both eyes read
// 16 floor(S / 16) with S = kappa / 36 + 16, kappa = (4080 - 16) 3^2:
// 1016 + 16 = 1032, read 1024. A 2-ft pillar halfway (above the 9-in
// beacon) leaves both at the background, 16; a 6-in one (below it)
// changes nothing.
TEST(Obstacles, ATallObstacleHidesTheBeaconALowOneDoesNot) {
  const Profile p = thesis();
  ASSERT_EQ(p.field.beacon_height_ft, 0.75);
  for (const double height : {0.0, 2.0, 0.5}) {
    ArenaConfig cfg = config(p, {Pose{-4, 2, 90}, Pose{2, 2, 270}});
    if (height > 0) cfg.field.obstacles = {circle(-1, 2.3L, 0.4L, height).obstacle};
    Arena a(cfg);
    a.advance(1000);
    const EyeReadings e = a.eyeReadings(0, 1000);
    const int want = height == 2.0 ? 16 : 1024;
    EXPECT_EQ(e.left, want) << height;
    EXPECT_EQ(e.right, want) << height;
  }
}

}  // namespace

namespace {

// Obstacles are configuration, not state: an arena copied (its checkpoint
// restored and its calls made again) while a robot is held against a box
// goes on bit for bit as the original, through the contact's end and the
// reflex after it.
TEST(Obstacles, AnArenaCopiedDuringAContactGoesOnAsTheOriginal) {
  using namespace plant_test;
  Profile p = defaults();
  ArenaConfig cfg = config(p, {Pose{-1, 0, 40}});
  cfg.field.obstacles = {makeBox(0.5, 1.6, 2.2, 1.2, 25, 2)};
  Arena a(cfg);
  a.keepJournal();
  a.advance(777'777);
  a.setWheels(0, frame("ffg0ffg0"), 777'777);
  const auto c = runUntil(a, EventKind::Contact, 80'000'000);
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->event.with, ContactWith::Obstacle);
  Arena b(a);
  for (std::int64_t t = c->tick + 9'216; t < c->tick + 20'000'000; t += 9'216) {
    AdvanceResult ra = a.advance(t), rb = b.advance(t);
    ASSERT_EQ(ra.tick, rb.tick);
    ASSERT_EQ(ra.events.size(), rb.events.size());
    const Pose pa = a.pose(0, ra.tick), pb = b.pose(0, rb.tick);
    ASSERT_EQ(pa.x_ft, pb.x_ft) << t;
    ASSERT_EQ(pa.y_ft, pb.y_ft) << t;
  }
}

}  // namespace
