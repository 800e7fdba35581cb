// The disc launcher (a secondary weapon; plant/arena_discs.cpp,
// docs/plant.md "The disc launcher") against closed forms worked here: a
// disc's flight s(t) = v0 tau (1 - e^{-t/tau}) with its stop at
// t = tau ln(v0 / v_stop) after tau (v0 - v_stop), its hit on a robot
// standing still, the divider below and above its height, a disc that
// touches something at its launch, the magazine, and a robot without one.
//
// An event lands on the first tick at or after its time (DESIGN.md: the
// first tick at which its root function has crossed): a disc launched at
// tick L that ends t seconds later does so at tick L + ceil(t x 9,216,000);
// every t below lies well away from a tick boundary (its fraction is
// written beside it), so round-off cannot move the tick.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "plant_support.h"

namespace {

using namespace plant_test;

constexpr std::int64_t kLaunch = 777'777;  // an odd tick, as rules_test.cpp's
constexpr std::uint8_t kDiscBit = 1u << 6;
// thesis-1997's body: 12.75 in across.
constexpr double kBodyRadius = 12.75 / 24;

SecondaryWeapon disc(double v0, double height, double tau, double vStop, double diameterIn) {
  SecondaryWeapon w;
  w.kind = SecondaryKind::Disc;
  w.magazine = 15;
  w.launch_speed_fps = v0;
  w.launch_height_ft = height;
  w.drag_time_s = tau;
  w.stop_speed_fps = vStop;
  w.diameter_ft = diameterIn / 12;
  return w;
}

// thesis-1997 (no motor lag, no noise), robot A carrying `w`; the robots
// stand where they are put (no frame ever latches).
ArenaConfig arena(std::initializer_list<Pose> starts, const SecondaryWeapon& w) {
  ArenaConfig c = config(thesis(), starts);
  c.robots[0].hardware.secondary = w;
  return c;
}

struct Fired {
  std::vector<Found> now;    // setPortB's events at the launch tick
  std::vector<Found> later;  // advance()'s up to the limit
};

// Advances to `tick` exactly (advance() stops early at an event).
void reach(Arena& a, std::int64_t tick) {
  while (a.now() < tick) a.advance(tick);
}

Fired fireAt(Arena& a, std::int64_t tick, std::int64_t limit) {
  Fired f;
  reach(a, tick);
  for (const Event& e : a.setPortB(0, kDiscBit, tick)) f.now.push_back(Found{tick, e});
  while (a.now() < limit) {
    AdvanceResult r = a.advance(limit);
    for (const Event& e : r.events) f.later.push_back(Found{r.tick, e});
  }
  return f;
}

const Found* find(const std::vector<Found>& evs, EventKind k) {
  for (const Found& f : evs)
    if (f.event.kind == k) return &f;
  return nullptr;
}

// Open field: v0 = 20 ft/s, tau = 0.3 s, v_stop = 2 ft/s. The speed falls
// to v_stop at tau ln(v0 / v_stop) = 0.3 ln 10 = 0.690775527898 s =
// 6,366,187.265 ticks, so the disc stops 6,366,188 ticks after its launch,
// having gone v0 tau (1 - v_stop / v0) = 6 x 0.9 = 5.4 ft. Robot A at
// (-3, 0) heading east: the disc leaves its rim at x = -3 + 0.53125 and
// stops at x = 2.93: clear of the walls (the east one 8 ft - its radius)
// and of the divider (which ends at y = -4).
TEST(Disc, StopsAtTheDragSolutionsRangeAndTick) {
  Arena a(arena({Pose{-3, 0, 90}}, disc(20, 1.25, 0.3, 2, 4)));
  const Fired f = fireAt(a, kLaunch, kLaunch + 2 * kTicksPerSecond);
  const Found* fire = find(f.now, EventKind::DiscFire);
  ASSERT_NE(fire, nullptr);
  EXPECT_NEAR(fire->event.x, -3 + kBodyRadius, 1e-12);
  EXPECT_NEAR(fire->event.y, 0, 1e-12);
  EXPECT_NEAR(fire->event.vx, 20, 1e-12);
  EXPECT_NEAR(fire->event.vy, 0, 1e-12);
  const Found* miss = find(f.later, EventKind::DiscMiss);
  ASSERT_NE(miss, nullptr);
  EXPECT_EQ(miss->event.miss, MissReason::Stopped);
  EXPECT_EQ(miss->tick, kLaunch + 6'366'188);
  // Where it is at that tick: s(t) at t = 6,366,188 ticks, which is past
  // the range by less than a tick's flight at the stop speed.
  const double t = 6'366'188.0 / kTicksPerSecond;
  const double gone = std::hypot(miss->event.x - fire->event.x, miss->event.y - fire->event.y);
  EXPECT_NEAR(gone, 20 * 0.3 * (1 - std::exp(-t / 0.3)), 1e-9);
  EXPECT_GE(gone, 5.4 - 1e-12);
  EXPECT_LE(gone, 5.4 + 2.0 / kTicksPerSecond);
  EXPECT_EQ(miss->event.z, 1.25);
  EXPECT_EQ(miss->event.closest_ft, -1);  // solo: no target
  EXPECT_EQ(a.discShots(0), 1);
  EXPECT_EQ(a.discsLeft(0), 14);
  EXPECT_EQ(a.shots(0), 0);  // the guns' count is apart
  EXPECT_FALSE(a.ballsInFlight());
}

// A at (-4, 2) heading east, B standing at (4, 2): centres 8 ft apart. A
// 4-in disc (radius 1/6 ft) touches B when its centre is B's radius plus
// its own from B's centre, i.e. after s = 8 - 2 x 0.53125 - 1/6 =
// 6.770833 ft. With v0 = 20 ft/s and tau = 1 s, s(t) = 20 (1 - e^{-t})
// reaches it at t = -ln(1 - 6.770833 / 20) = 0.413308285569 s =
// 3,809,049.160 ticks: the hit is 3,809,050 ticks after the launch. It
// flies at 1.25 ft, below B's 2.5 ft; its stop (19 ft) and the east wall
// (11.3 ft on) lie beyond.
TEST(Disc, HitsAStandingRobotWhereTheFlightReachesIt) {
  Arena a(arena({Pose{-4, 2, 90}, Pose{4, 2, 270}}, disc(20, 1.25, 1, 1, 4)));
  const Fired f = fireAt(a, kLaunch, kLaunch + 2 * kTicksPerSecond);
  const Found* hit = find(f.later, EventKind::DiscHit);
  ASSERT_NE(hit, nullptr);
  EXPECT_EQ(find(f.later, EventKind::DiscMiss), nullptr);
  EXPECT_EQ(hit->tick, kLaunch + 3'809'050);
  EXPECT_EQ(hit->event.robot, 0);
  EXPECT_EQ(hit->event.other, 1);
  // The disc's centre then: B's surface plus the disc's radius, to within
  // a tick's flight (at most 20 ft/s).
  EXPECT_NEAR(hit->event.x, 4 - kBodyRadius - 1.0 / 6, 20.0 / kTicksPerSecond);
  EXPECT_EQ(a.discHits(0), 1);
  EXPECT_EQ(a.hits(0), 0);  // not a ball's hit
  EXPECT_EQ(a.discShots(1), 0);
}

// The same shot at 3 ft, above B's 2.5 ft: it passes over B and stops at
// the east wall, its edge at x = 8: s = 8 - 1/6 - (-4 + 0.53125) =
// 11.302083 ft, t = -ln(1 - 11.302083 / 20) = 0.832649 s = 7,673,690.79
// ticks.
TEST(Disc, FliesOverARobotLowerThanIt) {
  Arena a(arena({Pose{-4, 2, 90}, Pose{4, 2, 270}}, disc(20, 3, 1, 1, 4)));
  const Fired f = fireAt(a, kLaunch, kLaunch + 2 * kTicksPerSecond);
  EXPECT_EQ(find(f.later, EventKind::DiscHit), nullptr);
  const Found* miss = find(f.later, EventKind::DiscMiss);
  ASSERT_NE(miss, nullptr);
  EXPECT_EQ(miss->event.miss, MissReason::LeftField);
  const double t = -std::log(1 - (8 - 1.0 / 6 + 4 - kBodyRadius) / 20);
  EXPECT_EQ(miss->tick, kLaunch + static_cast<std::int64_t>(std::ceil(t * kTicksPerSecond)));
  // It passed B 0.5 ft above its top.
  EXPECT_NEAR(miss->event.closest_ft, 0.5, 1e-12);
}

// The divider: x = 0, 0.75 in thick, from y = -8 to -4, 1 ft tall. A at
// (-3, -6) heading east. A disc at 0.75 ft meets its west face (x =
// -0.03125) with its edge after s = -0.03125 - 1/6 - (-3 + 0.53125) =
// 2.2708333 ft: t = -ln(1 - 2.2708333 / 20) = 0.120521155889 s =
// 1,110,722.973 ticks, so 1,110,723 ticks after the launch. At 1.25 ft it
// flies over and stops at 19 ft or at the east wall, past the divider.
TEST(Disc, TheDividerStopsADiscNoHigherThanIt) {
  Arena low(arena({Pose{-3, -6, 90}}, disc(20, 0.75, 1, 1, 4)));
  const Fired below = fireAt(low, kLaunch, kLaunch + 2 * kTicksPerSecond);
  const Found* miss = find(below.later, EventKind::DiscMiss);
  ASSERT_NE(miss, nullptr);
  EXPECT_EQ(miss->event.miss, MissReason::Divider);
  EXPECT_EQ(miss->tick, kLaunch + 1'110'723);
  EXPECT_NEAR(miss->event.x, -0.03125 - 1.0 / 6, 20.0 / kTicksPerSecond);

  Arena high(arena({Pose{-3, -6, 90}}, disc(20, 1.25, 1, 1, 4)));
  const Fired above = fireAt(high, kLaunch, kLaunch + 2 * kTicksPerSecond);
  const Found* over = find(above.later, EventKind::DiscMiss);
  ASSERT_NE(over, nullptr);
  EXPECT_EQ(over->event.miss, MissReason::LeftField);
  EXPECT_GT(over->event.x, 7);
}

// A robot 0.1 ft north of the divider's end (y = -4), facing it: its rim
// is at (0, -3.9), 0.1 ft from the divider, less than the disc's radius
// 1/6 ft. A disc at 0.75 ft touches the divider as it leaves and ends
// there at the launch's tick, among setPortB's own events; at 1.25 ft it
// passes over and meets the south wall with its edge after
// s = -3.9 - (-8 + 1/6) = 3.9333 ft, t = -ln(1 - 3.9333 / 20) = 0.21898 s.
TEST(Disc, ADiscTouchingSomethingAtItsLaunchEndsAtOnce) {
  const Pose start{0, -4 + kBodyRadius + 0.1, 180};
  Arena low(arena({start}, disc(20, 0.75, 1, 1, 4)));
  const Fired at = fireAt(low, kLaunch, kLaunch + kTicksPerSecond);
  ASSERT_EQ(at.now.size(), 2u);
  EXPECT_EQ(at.now[0].event.kind, EventKind::DiscFire);
  EXPECT_EQ(at.now[1].event.kind, EventKind::DiscMiss);
  EXPECT_EQ(at.now[1].event.miss, MissReason::Divider);
  EXPECT_NEAR(at.now[1].event.y, -3.9, 1e-12);
  EXPECT_TRUE(at.later.empty());
  EXPECT_FALSE(low.ballsInFlight());

  Arena high(arena({start}, disc(20, 1.25, 1, 1, 4)));
  const Fired over = fireAt(high, kLaunch, kLaunch + kTicksPerSecond);
  ASSERT_EQ(over.now.size(), 1u);
  const Found* miss = find(over.later, EventKind::DiscMiss);
  ASSERT_NE(miss, nullptr);
  EXPECT_EQ(miss->event.miss, MissReason::LeftField);
  const double t = -std::log(1 - (-3.9 + 8 - 1.0 / 6) / 20);
  EXPECT_EQ(miss->tick, kLaunch + static_cast<std::int64_t>(std::ceil(t * kTicksPerSecond)));
  EXPECT_NEAR(miss->event.y, -8 + 1.0 / 6, 20.0 / kTicksPerSecond);
}

// Magazine of 3: five rising edges send three discs, then two find it
// empty; nothing flies then. A robot without a launcher only logs the bit.
TEST(Disc, TheMagazineRunsOut) {
  SecondaryWeapon w = disc(20, 1.25, 0.3, 2, 4);
  w.magazine = 3;
  Arena a(arena({Pose{-3, 0, 90}}, w));
  int fired = 0, empty = 0;
  for (int k = 0; k < 5; ++k) {
    const std::int64_t t = kLaunch + k * kTicksPerSecond;
    reach(a, t);
    for (const Event& e : a.setPortB(0, kDiscBit, t)) {
      fired += e.kind == EventKind::DiscFire;
      empty += e.kind == EventKind::DiscEmpty;
      EXPECT_NE(e.kind, EventKind::DiscShooter);
    }
    reach(a, t + 100);
    a.setPortB(0, 0, t + 100);
  }
  EXPECT_EQ(fired, 3);
  EXPECT_EQ(empty, 2);
  EXPECT_EQ(a.discShots(0), 3);
  EXPECT_EQ(a.discsLeft(0), 0);

  Arena plain(config(thesis(), {Pose{-3, 0, 90}}));
  plain.advance(kLaunch);
  const EventList ev = plain.setPortB(0, kDiscBit, kLaunch);
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].kind, EventKind::DiscShooter);
  EXPECT_EQ(plain.discShots(0), 0);
  EXPECT_FALSE(plain.ballsInFlight());
}

// Fixed obstacles stop a disc no higher than they are tall, where its
// circle (radius r = 1/6 ft) first touches the shape. Robot A at (-3, 0)
// heading east; its rim, where the disc starts, is at x0 = -2.46875; v0 =
// 20 ft/s, tau = 1 s, so a disc that has gone s ft has flown
// t = -ln(1 - s / 20) s. Worked by hand for each shape:
// - a circle of radius 0.5 at the origin: touched when the centre is at
//   x = -0.5 - 1/6, s = 1.8020833, t = 0.0944252 s = 870,222.23 ticks;
// - a unit square turned 45 deg about the origin (a diamond whose west
//   vertex is at x = -sqrt(1/2)), met on the disc's axis: at its vertex,
//   x = -0.7071068 - 1/6, s = 1.5949766, t = 0.0831086 s = 765,929.16;
// - the same diamond with the disc's axis at y = 0.2 (robot at (-3, 0.2)):
//   on its north-west edge -x + y = sqrt(1/2), at distance r from it:
//   x = 0.2 - sqrt(1/2) - r sqrt(2) = -0.7428090 (the foot of the
//   perpendicular, y = 0.2 - r / sqrt(2) = 0.082, lies on the edge),
//   s = 1.7259410, t = 0.0902498 s = 831,741.77 ticks.
// At 3 ft up the disc clears all of them (they are 2 ft tall) and meets
// the east wall.
TEST(Disc, AnObstacleStopsADiscNoHigherThanItWhereItsEdgeTouches) {
  struct Case {
    Obstacle obstacle;
    double y;
    std::int64_t ticks;
  };
  Obstacle circle;
  circle.kind = Obstacle::Kind::Circle;
  circle.radius_ft = 0.5;
  circle.height_ft = 2;
  const Obstacle diamond = makeBox(0, 0, 1, 1, 45, 2);
  for (const Case& c :
       {Case{circle, 0, 870'223}, Case{diamond, 0, 765'930}, Case{diamond, 0.2, 831'742}}) {
    ArenaConfig low = arena({Pose{-3, c.y, 90}}, disc(20, 0.75, 1, 1, 4));
    low.field.obstacles = {c.obstacle};
    Arena a(low);
    const Fired f = fireAt(a, kLaunch, kLaunch + 2 * kTicksPerSecond);
    const Found* miss = find(f.later, EventKind::DiscMiss);
    ASSERT_NE(miss, nullptr);
    EXPECT_EQ(miss->event.miss, MissReason::Obstacle);
    EXPECT_EQ(miss->event.obstacle, 0);
    EXPECT_EQ(miss->tick, kLaunch + c.ticks);

    ArenaConfig high = arena({Pose{-3, c.y, 90}}, disc(20, 3, 1, 1, 4));
    high.field.obstacles = {c.obstacle};
    Arena b(high);
    const Fired over = fireAt(b, kLaunch, kLaunch + 2 * kTicksPerSecond);
    const Found* wall = find(over.later, EventKind::DiscMiss);
    ASSERT_NE(wall, nullptr);
    EXPECT_EQ(wall->event.miss, MissReason::LeftField);
  }
}

}  // namespace
