// Blocks set down on the field as bodies (plant/arena_blocks.cpp) against
// closed forms worked here: a robot driven into a block touches it at the
// tick its ray cast gives; a block too heavy to push stops it as a fixed
// box does; a push moves the block by the distance the motor lag's
// exponential gives, slowed by 1 - F / T; a block pushed into a wall stops
// there at the tick its travel reaches the gap; a ball meets a block at
// the tick its flight reaches it.
#include <cmath>
#include <optional>
#include <vector>

#include "plant_support.h"

namespace {

using namespace plant_test;
using LD = long double;

constexpr std::int64_t kStart = 777'777;  // an odd tick: no answer is a round number
constexpr std::int64_t kDeployTick = 1'001;
constexpr LD kN = simbot::timebase::kTicksPerSecond;

std::int64_t tickAfter(std::int64_t from, LD seconds) {
  return from + static_cast<std::int64_t>(std::ceil(seconds * kN));
}

Deployable blockKind(double width, double depth, double height, double mass, double friction) {
  Deployable d;
  d.kind = DeployKind::Block;
  d.bit = 2;
  d.count = 1;
  d.width_ft = width;
  d.depth_ft = depth;
  d.height_ft = height;
  d.mass_lb = mass;
  d.floor_friction = friction;
  return d;
}

// Robot A at `a`, robot B heading north at (bx, by) with one block on bit
// 2; no divider. B sets the block down at kDeployTick and, if `leave`,
// drives north for 2 s (out of A's way) and stops. A may start at `go`.
struct Scene {
  Arena arena;
  std::int64_t go = kStart;
  Scene(const Profile& p, Pose a, double bx, double by, const Deployable& block, bool leave)
      : arena([&] {
          ArenaConfig c = config(p, {a, Pose{bx, by, 0}});
          c.field.divider = false;
          c.robots[1].hardware.deployables = {block};
          return c;
        }()) {
    arena.advance(kDeployTick);
    const EventList ev = arena.setPortB(1, 1u << 2, kDeployTick);
    EXPECT_EQ(ev.size(), 1u);
    EXPECT_EQ(ev[0].kind, EventKind::Deploy);
    if (!leave) return;
    arena.setWheels(1, frame("ffg0ffg0"), kDeployTick);
    arena.advance(kDeployTick + ticks(2));
    arena.setWheels(1, frame("0fs00fs0"), arena.now());
    go = arena.now() + kStart;
  }
};

// thesis-1997: 1.5 ft/s at speed 15 with no motor lag, r = 0.53125 ft,
// 35 lb at wheel friction 0.7 (traction 24.5 lbf). B at (2.5, 0) sets a
// 0.5 x 0.5 ft block down 0.53125 + 0.02 + 0.25 = 0.80125 ft behind it:
// centre (2.5, -0.80125), west face x = 2.25, corners at y = -0.55125 and
// -1.05125. Its 30 lb at floor friction 1 (30 lbf > 24.5) cannot be pushed.
// A, heading east on y = -1.20125 (0.15 below the south-west corner),
// touches that corner when (x - 2.25)^2 + 0.15^2 = 0.53125^2:
// x = 2.25 - sqrt(0.2822265625 - 0.0225) = 2.25 - 0.5096...; from x0 = -3
// at 1.5 ft/s from kStart, the tick is kStart + ceil((x - x0) / 1.5 N).
TEST(Blocks, ARobotTouchesAnUnpushableBlockAtTheClosedFormTickAndIsHeld) {
  const Profile p = thesis();
  ASSERT_EQ(p.robot.speed_table_fps[15], 1.5);
  ASSERT_EQ(p.robot.motor_lag_s, 0.0);
  const LD r = 0.53125L;
  const LD xTouch = 2.25L - std::sqrt(r * r - 0.15L * 0.15L);
  const std::int64_t want = tickAfter(kStart, (xTouch + 3) / 1.5L);
  Scene s(p, Pose{-3, -1.20125, 90}, 2.5, 0, blockKind(0.5, 0.5, 0.5, 30, 1), false);
  Arena& a = s.arena;
  const Pose placed = a.blockCentre(0, kDeployTick);
  EXPECT_DOUBLE_EQ(placed.x_ft, 2.5);
  EXPECT_DOUBLE_EQ(placed.y_ft, -0.80125);
  a.advance(kStart);
  a.setWheels(0, frame("ffg0ffg0"), kStart);
  const auto c = runUntil(a, EventKind::Contact, kStart + ticks(10), 0);
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->tick, want);
  EXPECT_EQ(c->event.with, ContactWith::Block);
  EXPECT_EQ(c->event.obstacle, 0);
  EXPECT_EQ(c->event.bumper, Bumper::Front);
  // No push; the body stays outside the block's corner while the reflex
  // (no lag: at once) backs it off, and the block does not move.
  for (std::int64_t t = c->tick; t < c->tick + ticks(0.5); t += 997) {
    AdvanceResult res = a.advance(t);
    for (const Event& e : res.events) EXPECT_NE(e.kind, EventKind::PushStart);
    const Pose q = a.pose(0, a.now());
    EXPECT_GE(std::hypot(q.x_ft - 2.25, q.y_ft + 1.05125) - 0.53125, -1e-6);
  }
  EXPECT_EQ(a.blockCentre(0, a.now()).x_ft, placed.x_ft);
  EXPECT_EQ(a.blockPushedFt(0), 0.0);
}

// A fixed box of the same footprint gives the same contact tick and the
// same motion (the same contact rule: contact.h's Obstacle).
TEST(Blocks, AnUnpushableBlockIsAFixedBox) {
  const Profile p = thesis();
  Scene s(p, Pose{-3, -1.20125, 90}, 2.5, 0, blockKind(0.5, 0.5, 0.5, 30, 1), false);
  ArenaConfig c = config(p, {Pose{-3, -1.20125, 90}, Pose{2.5, 0, 0}});
  c.field.divider = false;
  c.field.obstacles = {makeBox(2.5, -0.80125, 0.5, 0.5, 0, 0.5)};
  Arena box(c);
  for (Arena* a : {&s.arena, &box}) {
    a->advance(kStart);
    a->setWheels(0, frame("ffg0ffg0"), kStart);
  }
  const auto cb = runUntil(s.arena, EventKind::Contact, kStart + ticks(10), 0);
  const auto cf = runUntil(box, EventKind::Contact, kStart + ticks(10), 0);
  ASSERT_TRUE(cb && cf);
  EXPECT_EQ(cb->tick, cf->tick);
  EXPECT_EQ(cb->event.bumper, cf->event.bumper);
  const std::int64_t later = cb->tick + ticks(0.7);
  while (s.arena.now() < later) s.arena.advance(later);
  while (box.now() < later) box.advance(later);
  EXPECT_NEAR(s.arena.pose(0, later).x_ft, box.pose(0, later).x_ft, 1e-9);
  EXPECT_NEAR(s.arena.pose(0, later).y_ft, box.pose(0, later).y_ft, 1e-9);
}

// The default profile: speed 15 is v = 1.45 ft/s, motor lag tau = 0.15 s,
// 35 lb at wheel friction 0.7: T = 24.5 lbf (g cancels). blocks.toml's
// block: 2 lb at floor friction 0.9, F = 1.8 lbf, so 1 - F/T = 0.926531.
// B at (1, -2) sets a 0.5 x 0.5 block down at (1, -2.80125) and leaves;
// A, heading east on y = -2.80125 from x = -4, meets its west face head
// on. From the contact's tick Tc (A's speed then v0 = v (1 - e^{-(Tc -
// go) / N tau}), within 1e-8 of v, A starting at `go`) the bumper's reflex drives the
// wheels towards -v: speed -v + (v0 + v) e^{-t/tau}, into the block until
// t* = tau ln((v0 + v) / v) (tau ln 2 = 0.10397 s). Meanwhile the pair
// moves at (1 - F/T) of it: d = (1 - F/T)(v0 tau - v t*), with v0 = v
// 1.45 x 0.15 x (1 - ln 2) x 0.926531 = 0.061837 ft (a straight push at
// constant v for tau would be v tau (1 - F/T) = 0.2015 ft: the next test).
struct Push {
  std::int64_t contact = -1, start = -1, end = -1;
  Event endEvent{};
};
Push pushOnce(Arena& a, std::int64_t go) {
  Push out;
  a.advance(go);
  a.setWheels(0, frame("ffg0ffg0"), go);
  while (a.now() < go + ticks(12) && out.end < 0) {
    AdvanceResult res = a.advance(go + ticks(12));
    for (const Event& e : res.events) {
      if (e.robot != 0) continue;
      if (e.kind == EventKind::Contact && out.contact < 0) out.contact = res.tick;
      if (e.kind == EventKind::PushStart) out.start = res.tick;
      if (e.kind == EventKind::PushEnd) {
        out.end = res.tick;
        out.endEvent = e;
      }
    }
  }
  return out;
}

TEST(Blocks, APushLastsWhileTheLagDrivesIntoTheBlockAndMovesItByTheClosedForm) {
  Profile p = defaults();
  ASSERT_EQ(p.robot.speed_table_fps[15], 1.45);
  ASSERT_EQ(p.robot.motor_lag_s, 0.15);
  Scene s(p, Pose{-4, -2.80125, 90}, 1, -2, blockKind(0.5, 0.5, 0.5, 2, 0.9), true);
  const Push got = pushOnce(s.arena, s.go);
  ASSERT_GE(got.contact, 0);
  EXPECT_EQ(got.start, got.contact);
  const LD v = 1.45L, tau = 0.15L, k = 1 - 1.8L / 24.5L;
  const LD v0 = v * (1 - std::exp(-(got.contact - s.go) / kN / tau));
  const LD tStar = tau * std::log((v0 + v) / v);
  EXPECT_EQ(got.end, tickAfter(got.contact, tStar));
  const LD d = k * (v0 * tau - v * tStar);
  EXPECT_NEAR(got.endEvent.z, static_cast<double>(d), 1e-7);
  EXPECT_NEAR(static_cast<double>(d), 0.061837, 1e-6);
  EXPECT_EQ(got.endEvent.with, ContactWith::None);
  EXPECT_NEAR(got.endEvent.x, 1 + static_cast<double>(d), 1e-7);
  EXPECT_NEAR(s.arena.blockCentre(0, s.arena.now()).x_ft, 1 + static_cast<double>(d), 1e-7);
  EXPECT_DOUBLE_EQ(s.arena.blockPushedFt(0), got.endEvent.z);
}

// A reflex that stops the wheels (speed step 0) leaves the lag's coast:
// speed v0 e^{-t/tau} into the block, never reversing, so the push has
// covered (1 - F/T) v0 tau (1 - e^{-t/tau}) by t, and ends only when the
// speed's double is exactly 0 (e^{-t/tau} below half an ulp of 1, t > 37
// tau): by then d = v tau (1 - m mu_b / (M mu_w)) = 1.45 x 0.15 x 0.926531
// = 0.201520 ft, the straight push at v for tau. A block too heavy (30 lb
// at 1: F = 30 lbf > T) is not pushed at all, and the body stays outside
// it.
TEST(Blocks, ACoastingPushCoversVTauTimesOneLessFOverT) {
  Profile p = defaults();
  p.robot.reflex_speed_step = 0;
  for (const double mass : {2.0, 30.0}) {
    const double friction = mass == 2.0 ? 0.9 : 1.0;
    Scene s(p, Pose{-4, -2.80125, 90}, 1, -2, blockKind(0.5, 0.5, 0.5, mass, friction), true);
    Arena& a = s.arena;
    const Push got = pushOnce(a, s.go);
    ASSERT_GE(got.contact, 0);
    const LD v = 1.45L, tau = 0.15L;
    const LD v0 = v * (1 - std::exp(-(got.contact - s.go) / kN / tau));
    const double moved = a.blockCentre(0, a.now()).x_ft - 1;
    if (mass == 2.0) {
      EXPECT_EQ(got.start, got.contact);
      EXPECT_GT(got.end, got.contact + ticks(37 * 0.15));
      const LD d = (1 - 1.8L / 24.5L) * v0 * tau;
      EXPECT_NEAR(got.endEvent.z, static_cast<double>(d), 1e-7);
      EXPECT_NEAR(moved, static_cast<double>(d), 1e-7);
      EXPECT_NEAR(moved, 0.201520, 1e-6);
      // The pusher stays flush against the block's west face.
      EXPECT_NEAR(a.pose(0, a.now()).x_ft, 1 + moved - 0.25 - 0.53125, 1e-6);
    } else {
      EXPECT_EQ(got.start, -1);
      EXPECT_EQ(got.end, -1);
      EXPECT_EQ(moved, 0.0);
      EXPECT_GE(0.75 - 0.53125 - a.pose(0, a.now()).x_ft, -1e-6);
    }
  }
}

// The same coasting push of a 1.2-ft-wide block whose east face stands
// 0.05 ft from the east wall (x = 8): B at (7.35, -2) sets it down with its
// centre at x = 7.35, east face 7.95. The block's travel (1 - F/T) v0 tau
// (1 - e^{-t/tau}) reaches 0.05 at t = -tau ln(1 - 0.05 / ((1 - F/T) v0
// tau)); there the push ends ("wall"), the block stands flush with the
// wall, and the robot is held by it as by a fixed box.
TEST(Blocks, ABlockPushedIntoAWallStopsThereAndHoldsTheRobot) {
  Profile p = defaults();
  p.robot.reflex_speed_step = 0;
  Scene s(p, Pose{2, -2.80125, 90}, 7.35, -2, blockKind(1.2, 0.5, 0.5, 2, 0.9), true);
  Arena& a = s.arena;
  const Push got = pushOnce(a, s.go);
  ASSERT_GE(got.contact, 0);
  ASSERT_GE(got.end, 0);
  const LD v = 1.45L, tau = 0.15L, k = 1 - 1.8L / 24.5L;
  const LD v0 = v * (1 - std::exp(-(got.contact - s.go) / kN / tau));
  EXPECT_EQ(got.end, tickAfter(got.contact, -tau * std::log(1 - 0.05L / (k * v0 * tau))));
  EXPECT_EQ(got.endEvent.with, ContactWith::Wall);
  EXPECT_NEAR(got.endEvent.z, 0.05, 1e-9);
  EXPECT_NEAR(got.endEvent.x + 0.6, 8.0, 1e-9);
  for (std::int64_t t = got.end; t < got.end + ticks(1); t += 9'973) {
    while (a.now() < t) a.advance(t);
    EXPECT_NEAR(a.blockCentre(0, t).x_ft, got.endEvent.x, 1e-12);
    EXPECT_LE(a.pose(0, t).x_ft, got.endEvent.x - 0.6 - 0.53125 + 1e-6);
  }
}

// thesis-1997's gun: 105 ft/s horizontal from 1.5 ft, the muzzle 0.53125
// ft ahead of the centre. A at (-5, -1) heading east fires at kStart; B at
// (2, -0.2) has set a 0.5 x 0.5 x 2 ft block down at (2, -1.00125) (west
// face x = 1.75, y from -1.25125 to -0.75125). The ball reaches x = 1.75
// after s = (1.75 + 5 - 0.53125) / 105 = 0.0592262 s, at z = 1.5 - 32.174
// s^2 / 2 = 1.4436 ft, below the block's 2 ft: a miss on "block 1".
TEST(Blocks, ABallStopsAtABlock) {
  const Profile p = thesis();
  Scene s(p, Pose{-5, -1, 90}, 2, -0.2, blockKind(0.5, 0.5, 2, 2, 0.9), false);
  Arena& a = s.arena;
  a.advance(kStart);
  a.setPortB(0, 1u << 4, kStart);
  const auto miss = runUntil(a, EventKind::BallMiss, kStart + ticks(1));
  ASSERT_TRUE(miss.has_value());
  EXPECT_EQ(miss->tick, tickAfter(kStart, (1.75L + 5 - 0.53125L) / 105));
  EXPECT_EQ(miss->event.miss, MissReason::Block);
  EXPECT_EQ(miss->event.obstacle, 0);
  EXPECT_NEAR(miss->event.x, 1.75, 105.0 / 9'216'000);
}

// A disc launcher on A (30 ft/s, tau 0.3 s, stop at 2 ft/s, 4 in across,
// 0.5 ft high) fires east from (-5, -1) at kStart at the same block 2 ft
// high: its centre leaves the rim at x = -4.46875 and goes s(t) = 9 (1 -
// e^{-t/0.3}); its edge touches the west face (x = 1.75) when s = 1.75 -
// 1/6 + 4.46875 = 6.0520833 ft, before its stop after 0.3 x 28 = 8.4 ft:
// t = -0.3 ln(1 - 6.0520833 / 9) = 0.334839 s, a miss on "block 1".
TEST(Blocks, ADiscStopsAtABlock) {
  Profile p = thesis();
  ArenaConfig c = config(p, {Pose{-5, -1, 90}, Pose{2, -0.2, 0}});
  c.field.divider = false;
  c.robots[1].hardware.deployables = {blockKind(0.5, 0.5, 2, 2, 0.9)};
  SecondaryWeapon& w = c.robots[0].hardware.secondary;
  w.kind = SecondaryKind::Disc;
  w.magazine = 1;
  w.launch_speed_fps = 30;
  w.launch_height_ft = 0.5;
  w.drag_time_s = 0.3;
  w.stop_speed_fps = 2;
  w.diameter_ft = 4.0 / 12;
  Arena a(c);
  a.advance(kDeployTick);
  ASSERT_EQ(a.setPortB(1, 1u << 2, kDeployTick)[0].kind, EventKind::Deploy);
  a.advance(kStart);
  a.setPortB(0, 1u << 6, kStart);
  const auto miss = runUntil(a, EventKind::DiscMiss, kStart + ticks(2));
  ASSERT_TRUE(miss.has_value());
  const LD s = 1.75L - 1.0L / 6 + 4.46875L;
  EXPECT_EQ(miss->tick, tickAfter(kStart, -0.3L * std::log(1 - s / 9)));
  EXPECT_EQ(miss->event.miss, MissReason::Block);
  EXPECT_EQ(miss->event.obstacle, 0);
}

// The other robot touching a block being pushed holds it. B, heading east
// at (2, -2.80125), sets a 0.5 x 0.5 block down behind it: centre x = 2 -
// 0.80125 = 1.19875, east face 0.02 ft from B's back rim. A coasts into its
// west face as in the test above; the block's travel (1 - F/T) v0 tau (1 -
// e^{-t/tau}) reaches 0.02 ft at t = -tau ln(1 - 0.02 / ((1 - F/T) v0
// tau)): there B's back bumper trips on "block 1" and the push ends, "by"
// the robot (B), with the block 0.02 ft on (to a tick's travel, 2e-7 ft).
TEST(Blocks, TheOtherRobotTouchingAPushedBlockHoldsIt) {
  Profile p = defaults();
  p.robot.reflex_speed_step = 0;
  ArenaConfig c = config(p, {Pose{-3, -2.80125, 90}, Pose{2, -2.80125, 90}});
  c.field.divider = false;
  c.robots[1].hardware.deployables = {blockKind(0.5, 0.5, 0.5, 2, 0.9)};
  Arena a(c);
  a.advance(kDeployTick);
  ASSERT_EQ(a.setPortB(1, 1u << 2, kDeployTick)[0].kind, EventKind::Deploy);
  a.advance(kStart);
  a.setWheels(0, frame("ffg0ffg0"), kStart);
  const auto start = runUntil(a, EventKind::PushStart, kStart + ticks(10), 0);
  ASSERT_TRUE(start.has_value());
  std::optional<Found> touch, end;
  while (a.now() < start->tick + ticks(2) && !end) {
    const AdvanceResult r = a.advance(start->tick + ticks(2));
    for (const Event& e : r.events) {
      if (e.kind == EventKind::Contact && e.robot == 1) touch = Found{r.tick, e};
      if (e.kind == EventKind::PushEnd) end = Found{r.tick, e};
    }
  }
  ASSERT_TRUE(touch && end);
  const LD v = 1.45L, tau = 0.15L, k = 1 - 1.8L / 24.5L;
  const LD v0 = v * (1 - std::exp(-(start->tick - kStart) / kN / tau));
  EXPECT_EQ(end->tick, tickAfter(start->tick, -tau * std::log(1 - 0.02L / (k * v0 * tau))));
  EXPECT_EQ(touch->tick, end->tick);
  EXPECT_EQ(touch->event.with, ContactWith::Block);
  EXPECT_EQ(touch->event.bumper, Bumper::Back);
  EXPECT_EQ(end->event.with, ContactWith::Robot);
  EXPECT_EQ(end->event.other, 1);
  EXPECT_NEAR(end->event.z, 0.02, 2e-7);
  // Held: A stalls against it and it stays.
  const std::int64_t later = end->tick + ticks(1);
  while (a.now() < later) a.advance(later);
  EXPECT_EQ(a.blockCentre(0, later).x_ft, end->event.x);
  EXPECT_GE(end->event.x - 0.25 - 0.53125 - a.pose(0, later).x_ft, -1e-6);
}

// Blocks are state: an arena copied (its checkpoint restored, its calls
// made again) during a push, or while its robot is held against the block
// that the wall stopped, goes on bit for bit as the original. The wall
// test's scene.
TEST(Blocks, AnArenaCopiedDuringAPushGoesOnAsTheOriginal) {
  Profile p = defaults();
  p.robot.reflex_speed_step = 0;
  for (const bool afterEnd : {false, true}) {
    ArenaConfig c = config(p, {Pose{2, -2.80125, 90}, Pose{7.35, -2, 0}});
    c.field.divider = false;
    c.robots[1].hardware.deployables = {blockKind(1.2, 0.5, 0.5, 2, 0.9)};
    Arena a(c);
    a.keepJournal();
    a.advance(kDeployTick);
    a.setPortB(1, 1u << 2, kDeployTick);
    a.setWheels(1, frame("ffg0ffg0"), kDeployTick);
    a.advance(kDeployTick + ticks(2));
    a.setWheels(1, frame("0fs00fs0"), a.now());
    const std::int64_t go = a.now() + kStart;
    a.advance(go);
    a.setWheels(0, frame("ffg0ffg0"), go);
    const auto mark =
        runUntil(a, afterEnd ? EventKind::PushEnd : EventKind::PushStart, go + ticks(10), 0);
    ASSERT_TRUE(mark.has_value());
    a.advance(mark->tick + ticks(0.05));
    Arena b(a);
    for (std::int64_t t = a.now() + 9'216; t < mark->tick + ticks(3); t += 9'216) {
      AdvanceResult ra = a.advance(t), rb = b.advance(t);
      ASSERT_EQ(ra.tick, rb.tick);
      ASSERT_EQ(ra.events.size(), rb.events.size());
      ASSERT_EQ(a.pose(0, ra.tick).x_ft, b.pose(0, rb.tick).x_ft) << t;
      ASSERT_EQ(a.blockCentre(0, ra.tick).x_ft, b.blockCentre(0, rb.tick).x_ft) << t;
    }
    EXPECT_EQ(a.blockPushedFt(0), b.blockPushedFt(0));
  }
}

// A block that would overlap something is not set down: B against the
// south wall (its centre 0.6 ft from it) would put the block's far face
// beyond the field's edge.
TEST(Blocks, ABlockThatWouldNotFitStaysOnTheRobot) {
  const Profile p = thesis();
  ArenaConfig c = config(p, {Pose{-4, 0, 90}, Pose{2, -7.4, 0}});
  c.field.divider = false;
  c.robots[1].hardware.deployables = {blockKind(0.5, 0.5, 0.5, 2, 0.9)};
  Arena a(c);
  a.advance(kDeployTick);
  const EventList ev = a.setPortB(1, 1u << 2, kDeployTick);
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].kind, EventKind::DeployBlocked);
  EXPECT_TRUE(a.deployed().empty());
}

}  // namespace
