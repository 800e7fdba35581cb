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

// A push is no contact: the pusher's bumper does not trip while it moves
// the block. Push collects robot 0's first Contact, its push's start and
// end ticks.
struct Push {
  std::int64_t contact = -1, start = -1, end = -1;
  Event endEvent{}, contactEvent{};
};
Push pushOnce(Arena& a, std::int64_t go, std::int64_t until) {
  Push out;
  a.advance(go);
  a.setWheels(0, frame("ffg0ffg0"), go);
  while (a.now() < until && out.end < 0) {
    AdvanceResult res = a.advance(until);
    for (const Event& e : res.events) {
      if (e.robot != 0) continue;
      if (e.kind == EventKind::Contact && out.contact < 0) {
        out.contact = res.tick;
        out.contactEvent = e;
      }
      if (e.kind == EventKind::PushStart) out.start = res.tick;
      if (e.kind == EventKind::PushEnd) {
        out.end = res.tick;
        out.endEvent = e;
      }
    }
  }
  return out;
}

// DESIGN.md's straight push: a robot driving at constant v into a block it
// can push (traction T = M g mu_w above F = m g mu_b) moves it at v (1 -
// F / T), so in tau seconds d = v tau (1 - m mu_b / (M mu_w)). The default
// profile without motor lag, speed 15 set to 2 ft/s; 35 lb at 0.7,
// blocks.toml's 2 lb at 0.9: 1 - 1.8 / 24.5 = 0.9265306, and 1 s of push
// moves the block 2 x 0.9265306 = 1.853061 ft. B at (5.25, -2) sets a 0.5
// x 0.5 block down at (5.25, -2.80125) (east face 5.5, 2.5 ft from the
// east wall) and leaves; A, heading east on y = -2.80125 from x = -4.0001,
// touches the west face (5.0) when x + 0.53125 = 5: after 8.46885 / 2 s
// (PushStart there, no Contact). The push reaches the wall after 2.5 /
// (2 x 0.9265306) = 1.349119 s: there it ends ("wall"), and A meets the
// block as a fixed box: its front bumper trips at that tick.
TEST(Blocks, AStraightPushMovesTheBlockByVTauTimesOneLessFOverTUntilTheWall) {
  Profile p = defaults();
  p.robot.motor_lag_s = 0;
  p.robot.speed_table_fps[15] = 2;
  Scene s(p, Pose{-4.0001, -2.80125, 90}, 5.25, -2, blockKind(0.5, 0.5, 0.5, 2, 0.9), true);
  Arena& a = s.arena;
  const LD v = 2, k = 1 - 1.8L / 24.5L;
  const std::int64_t touch = tickAfter(s.go, (5 - 0.53125L + 4.0001L) / v);
  // One second into the push: 1.853061 ft.
  a.advance(s.go);
  a.setWheels(0, frame("ffg0ffg0"), s.go);
  std::int64_t start = -1;
  const std::int64_t oneSecond = touch + ticks(1);
  while (a.now() < oneSecond) {
    const AdvanceResult r = a.advance(oneSecond);
    for (const Event& e : r.events) {
      if (e.robot != 0) continue;
      EXPECT_NE(e.kind, EventKind::Contact);
      if (e.kind == EventKind::PushStart) start = r.tick;
    }
  }
  EXPECT_EQ(start, touch);
  const double moved = a.blockCentre(0, a.now()).x_ft - 5.25;
  EXPECT_NEAR(moved, static_cast<double>(v * k * ((a.now() - start) / kN)), 1e-9);
  EXPECT_NEAR(moved, 1.853061, 1e-6);
  const Push got = pushOnce(a, a.now(), touch + ticks(3));
  EXPECT_EQ(got.start, -1);
  ASSERT_GE(got.end, 0);
  EXPECT_EQ(got.end, tickAfter(start, 2.5L / (v * k)));
  EXPECT_EQ(got.endEvent.with, ContactWith::Wall);
  EXPECT_NEAR(got.endEvent.z, 2.5, 1e-12);
  EXPECT_NEAR(got.endEvent.x + 0.25, 8.0, 1e-12);
  EXPECT_DOUBLE_EQ(a.blockPushedFt(0), got.endEvent.z);
  EXPECT_EQ(got.contact, got.end);
  EXPECT_EQ(got.contactEvent.with, ContactWith::Block);
  EXPECT_EQ(got.contactEvent.bumper, Bumper::Front);
  // Held by it as by a fixed box.
  for (std::int64_t t = got.end; t < got.end + ticks(1); t += 9'973) {
    while (a.now() < t) a.advance(t);
    EXPECT_NEAR(a.blockCentre(0, t).x_ft, 7.75, 1e-12);
    EXPECT_LE(a.pose(0, t).x_ft, 7.5 - 0.53125 + 1e-6);
  }
}

// A push ends when the robot no longer drives into the block, with no
// contact. The default profile (v = 1.45 ft/s at speed 15, motor lag tau =
// 0.15 s): A starts at `go` (speed v (1 - e^{-t/tau})), touches the block
// of the test above at Tc (a = Tc - go) and is stopped at Ts = Tc + 0.5 s
// (b = Ts - go): it has then gone v ((b - a) - tau (e^{-a/tau} - e^{-b/tau}))
// along the push and coasts v (1 - e^{-b/tau}) tau more, the speed's
// double reaching exactly 0 only after 37 tau. The block moves (1 - F/T) of
// that (0.926531 x 1.45 x (0.5 + 0.15) = 0.8733 ft) and A rests flush
// against it, no Contact written. A block too heavy (30 lb at 1: F = 30
// lbf > T) is not pushed: A's bumper trips at the touch and the body stays
// outside it.
TEST(Blocks, APushEndsWithoutAContactWhenTheRobotStopsDrivingIntoIt) {
  Profile p = defaults();
  ASSERT_EQ(p.robot.speed_table_fps[15], 1.45);
  ASSERT_EQ(p.robot.motor_lag_s, 0.15);
  p.robot.reflex_speed_step = 0;
  for (const double mass : {2.0, 30.0}) {
    const double friction = mass == 2.0 ? 0.9 : 1.0;
    Scene s(p, Pose{-4, -2.80125, 90}, 1, -2, blockKind(0.5, 0.5, 0.5, mass, friction), true);
    Arena& a = s.arena;
    const LD v = 1.45L, tau = 0.15L, k = 1 - 1.8L / 24.5L;
    if (mass == 30.0) {
      const Push got = pushOnce(a, s.go, s.go + ticks(12));
      ASSERT_GE(got.contact, 0);
      EXPECT_EQ(got.contactEvent.bumper, Bumper::Front);
      EXPECT_EQ(got.start, -1);
      EXPECT_EQ(got.end, -1);
      EXPECT_EQ(a.blockCentre(0, a.now()).x_ft - 1, 0.0);
      EXPECT_GE(0.75 - 0.53125 - a.pose(0, a.now()).x_ft, -1e-6);
      continue;
    }
    const auto start = [&] {
      a.advance(s.go);
      a.setWheels(0, frame("ffg0ffg0"), s.go);
      return runUntil(a, EventKind::PushStart, s.go + ticks(10), 0);
    }();
    ASSERT_TRUE(start.has_value());
    const std::int64_t stop = start->tick + ticks(0.5);
    a.advance(stop);
    a.setWheels(0, frame("0fs00fs0"), stop);
    Push got;
    while (a.now() < stop + ticks(12) && got.end < 0) {
      const AdvanceResult r = a.advance(stop + ticks(12));
      for (const Event& e : r.events) {
        if (e.robot != 0) continue;
        EXPECT_NE(e.kind, EventKind::Contact);
        EXPECT_NE(e.kind, EventKind::ContactEnd);
        if (e.kind == EventKind::PushEnd) {
          got.end = r.tick;
          got.endEvent = e;
        }
      }
    }
    ASSERT_GE(got.end, 0);
    EXPECT_GT(got.end, stop + ticks(37 * 0.15));
    const LD ta = (start->tick - s.go) / kN, tb = (stop - s.go) / kN;
    const LD d = k * v *
                 ((tb - ta) - tau * (std::exp(-ta / tau) - std::exp(-tb / tau)) +
                  (1 - std::exp(-tb / tau)) * tau);
    EXPECT_EQ(got.endEvent.with, ContactWith::None);
    EXPECT_NEAR(got.endEvent.z, static_cast<double>(d), 1e-7);
    const double moved = a.blockCentre(0, a.now()).x_ft - 1;
    EXPECT_NEAR(moved, static_cast<double>(d), 1e-7);
    EXPECT_NEAR(moved, 0.8733, 1e-4);
    // Flush against the block's west face, and no contact after the push.
    EXPECT_NEAR(a.pose(0, a.now()).x_ft, 1 + moved - 0.25 - 0.53125, 1e-6);
    const std::int64_t later = a.now() + ticks(1);
    while (a.now() < later)
      for (const Event& e : a.advance(later).events) EXPECT_NE(e.kind, EventKind::Contact);
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

// The other robot touching a block being pushed holds it. Without motor
// lag (speed 15: v = 1.45 ft/s at once) B, heading east at (2, -2.80125),
// sets a 0.5 x 0.5 block down behind it: centre x = 2 - 0.80125 =
// 1.19875, east face 0.02 ft from B's back rim. A drives into its west
// face and pushes it at (1 - F/T) v = 0.926531 x 1.45 ft/s: it travels
// 0.02 ft in 0.02 / (0.926531 x 1.45) s. There B's back bumper trips on
// "block 1", the push ends "by" the robot (B), with the block 0.02 ft on
// (to a tick's travel, 2e-7 ft), and A meets the held block as a fixed
// box: its front bumper trips at the same tick (and not before).
TEST(Blocks, TheOtherRobotTouchingAPushedBlockHoldsIt) {
  Profile p = defaults();
  p.robot.motor_lag_s = 0;
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
  std::optional<Found> touch, pusherTouch, end;
  while (a.now() < start->tick + ticks(2) && !end) {
    const AdvanceResult r = a.advance(start->tick + ticks(2));
    for (const Event& e : r.events) {
      if (e.kind == EventKind::Contact && e.robot == 1) touch = Found{r.tick, e};
      if (e.kind == EventKind::Contact && e.robot == 0) pusherTouch = Found{r.tick, e};
      if (e.kind == EventKind::PushEnd) end = Found{r.tick, e};
    }
  }
  ASSERT_TRUE(touch && pusherTouch && end);
  const LD v = 1.45L, k = 1 - 1.8L / 24.5L;
  EXPECT_EQ(end->tick, tickAfter(start->tick, 0.02L / (k * v)));
  EXPECT_EQ(touch->tick, end->tick);
  EXPECT_EQ(touch->event.with, ContactWith::Block);
  EXPECT_EQ(touch->event.bumper, Bumper::Back);
  EXPECT_EQ(pusherTouch->tick, end->tick);
  EXPECT_EQ(pusherTouch->event.bumper, Bumper::Front);
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

// Without motor lag a wheel command steps the robot's velocity: reversing
// A half a second into a push (the default profile without its lag:
// 1.45 ft/s at speed 15; the block of the tests above) ends the push at that very tick,
// "drive", with no contact, the block 1.45 x 0.5 x 0.926531 = 0.671735 ft
// on; it stays there while A backs away (it is not pulled back).
TEST(Blocks, AReverseCommandWithoutLagEndsThePushAtItsTick) {
  Profile p = defaults();
  p.robot.motor_lag_s = 0;
  Scene s(p, Pose{-4, -2.80125, 90}, 1, -2, blockKind(0.5, 0.5, 0.5, 2, 0.9), true);
  Arena& a = s.arena;
  a.advance(s.go);
  a.setWheels(0, frame("ffg0ffg0"), s.go);
  const auto start = runUntil(a, EventKind::PushStart, s.go + ticks(10), 0);
  ASSERT_TRUE(start.has_value());
  const std::int64_t rev = start->tick + ticks(0.5);
  a.advance(rev);
  a.setWheels(0, frame("frg0frg0"), rev);
  const auto end = runUntil(a, EventKind::PushEnd, rev + ticks(1), 0);
  ASSERT_TRUE(end.has_value());
  EXPECT_EQ(end->tick, rev);
  EXPECT_EQ(end->event.with, ContactWith::None);
  const LD d = 1.45L * (1 - 1.8L / 24.5L) * ((rev - start->tick) / kN);
  EXPECT_NEAR(end->event.z, static_cast<double>(d), 1e-9);
  EXPECT_NEAR(end->event.z, 0.671735, 1e-6);
  const std::int64_t later = rev + ticks(1);
  while (a.now() < later)
    for (const Event& e : a.advance(later).events) EXPECT_NE(e.kind, EventKind::Contact);
  EXPECT_EQ(a.blockCentre(0, later).x_ft, end->event.x);
  EXPECT_NEAR(a.pose(0, later).x_ft, end->event.x - 0.25 - 0.53125 - 1.45, 1e-6);
}
