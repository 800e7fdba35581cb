// Deployables in the eyes (plant/deployables.cpp): a decoy light's reading
// against chapter VII's formula with its own kappa, worked by hand; two
// sources adding; screens hiding a beacon exactly when they cross the line
// of sight, cases drawn by hand; where an item is set down.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "plant/plant.h"

namespace simbot::plant {
namespace {

// The thesis's eye (Appendix C): max 4080, background 16, r_sat 3 ft, so
// kappa = (4080 - 16) 9 = 36576 reading ft^2. No divider, no obstacles.
RobotParams eyes() {
  RobotParams p;
  p.eye_max = 4080;
  p.eye_background = 16;
  p.eye_saturation_ft = 3;
  p.left_eye_width = p.right_eye_width = 1;
  p.eye_nose = 1;
  return p;
}
FieldParams openField() {
  FieldParams f;
  f.divider = false;
  f.beacon_height_ft = 0.75;
  return f;
}

Deployed light(int robot, double x, double y, double intensity) {
  Deployed d;
  d.kind = DeployKind::DecoyLight;
  d.robot = robot;
  d.x_ft = x;
  d.y_ft = y;
  d.height_ft = 0.5;
  d.intensity = intensity;
  return d;
}
Deployed screen(double x, double y, double headingDeg, double width, double height) {
  Deployed d;
  d.kind = DeployKind::DecoyScreen;
  d.x_ft = x;
  d.y_ft = y;
  d.heading_deg = headingDeg;
  d.width_ft = width;
  d.height_ft = height;
  return d;
}

EyeReadings read(const Pose* opponent, const std::vector<Deployed>& items, int self = 1) {
  const EyeScene scene{items.data(), static_cast<int>(items.size())};
  const FieldParams f = openField();
  return computeEyes(Pose{0, 0, 0}, opponent, eyes(), f, nullptr, EyeChannels::Both, &scene, self);
}

TEST(Deployables, DecoyLightReadsByTheOpticsFormulaWithItsKappa) {
  // Intensity 2: kappa = 73152. Straight ahead (gamma = 0: both eyes).
  // At 6 ft: 73152 / 36 = 2032, S = 2048, 16 floor(2048 / 16) = 2048.
  EyeReadings r = read(nullptr, {light(0, 0, 6, 2.0)});
  EXPECT_EQ(r.left, 2048);
  EXPECT_EQ(r.right, 2048);
  // At 8 ft: 73152 / 64 = 1143, S = 1159, 16 floor(72.44) = 1152.
  r = read(nullptr, {light(0, 0, 8, 2.0)});
  EXPECT_EQ(r.left, 1152);
  // Within r_sat sqrt(2) = 4.24 ft it saturates: 4080.
  r = read(nullptr, {light(0, 0, 4, 2.0)});
  EXPECT_EQ(r.left, 4080);
  // The deploying robot's own eyes are tuned to the other team: background.
  r = read(nullptr, {light(1, 0, 6, 2.0)});
  EXPECT_EQ(r.left, 16);
  EXPECT_EQ(r.right, 16);
}

TEST(Deployables, TwoSourcesAdd) {
  // The beacon at 10 ft: 36576 / 100 = 365.76; the decoy at 6 ft: 2032.
  // S = 16 + 365.76 + 2032 = 2413.76, 16 floor(150.86) = 2400 (the beacon
  // alone: 381.76 -> 368).
  const Pose opp{0, 10, 180};
  EXPECT_EQ(read(&opp, {light(0, 0, 6, 2.0)}).left, 2400);
  EXPECT_EQ(read(&opp, {screen(5, 5, 0, 0.1, 1)}).left, 368);
  // Far eye: the decoy 45 deg to the right, 8 ft away (8 / sqrt 2 each
  // way): phi = atan(1 / 1) = 45 deg, so f = 0: right (near) eye 1152 as
  // straight ahead, left eye 16.
  const double d = 8 / std::sqrt(2.0);
  const EyeReadings r = read(nullptr, {light(0, d, d, 2.0)});
  EXPECT_EQ(r.right, 1152);
  EXPECT_EQ(r.left, 16);
}

TEST(Deployables, ScreenHidesExactlyWhenItCrossesTheLineOfSight) {
  // Eye at the origin, beacon 10 ft ahead at 0.75 ft: the line of sight is
  // x = 0, 0 <= y <= 10. Seen: 368 (above); hidden: background 16.
  const Pose opp{0, 10, 180};
  // Across the line at y = 5, 1.5 ft wide (x from -0.75 to 0.75): hidden.
  EXPECT_EQ(read(&opp, {screen(0, 5, 0, 1.5, 1)}).left, 16);
  // Beside it: x from 1.25 to 2.75: seen.
  EXPECT_EQ(read(&opp, {screen(2, 5, 0, 1.5, 1)}).left, 368);
  // Its left end just over the line (x from -0.05 to 1.45): hidden.
  EXPECT_EQ(read(&opp, {screen(0.7, 5, 0, 1.5, 1)}).left, 16);
  // Lower than the beacon (0.5 < 0.75 ft): seen over it.
  EXPECT_EQ(read(&opp, {screen(0, 5, 0, 1.5, 0.5)}).left, 368);
  // Turned along the line (heading 90: its width along y) half a foot
  // beside it: seen.
  EXPECT_EQ(read(&opp, {screen(0.5, 5, 90, 1.5, 1)}).left, 368);
  // Turned 45 deg about (0.5, 5): its width runs along (0.707, -0.707);
  // it meets x = 0 at s = -0.5 / 0.707 = -0.707 ft from its centre, i.e.
  // at y = 5.5. 2 ft wide (|s| <= 1): hidden; 1.2 ft wide (|s| <= 0.6):
  // it stops short of the line, seen.
  EXPECT_EQ(read(&opp, {screen(0.5, 5, 45, 2.0, 1)}).left, 16);
  EXPECT_EQ(read(&opp, {screen(0.5, 5, 45, 1.2, 1)}).left, 368);
  // Behind the beacon (y = 12) or behind the eye (y = -2): seen.
  EXPECT_EQ(read(&opp, {screen(0, 12, 0, 1.5, 1)}).left, 368);
  EXPECT_EQ(read(&opp, {screen(0, -2, 0, 1.5, 1)}).left, 368);
  // A screen hides a decoy light behind it too.
  EXPECT_EQ(read(nullptr, {light(0, 0, 6, 2.0), screen(0, 3, 0, 1.5, 1)}).left, 16);
}

TEST(Deployables, TheReadingNamesTheScreenThatHidTheBeacon) {
  // As above: the beacon 10 ft ahead. The reading names the screen (its
  // index among the items) exactly when it hides the beacon
  // (screen_hides in the trace).
  const Pose opp{0, 10, 180};
  EXPECT_EQ(read(&opp, {screen(0, 5, 0, 1.5, 1)}).beaconScreen, 0);
  EXPECT_EQ(read(&opp, {screen(2, 5, 0, 1.5, 1)}).beaconScreen, -1);
  EXPECT_EQ(read(&opp, {screen(0, 5, 0, 1.5, 0.5)}).beaconScreen, -1);
  EXPECT_EQ(read(&opp, {light(0, 0, 6, 2.0), screen(2, 5, 0, 1.5, 1), screen(0, 7, 0, 1.5, 1)})
                .beaconScreen,
            2);
  // A light hidden by a screen is no beacon: -1.
  EXPECT_EQ(read(nullptr, {light(0, 0, 6, 2.0), screen(0, 3, 0, 1.5, 1)}).beaconScreen, -1);
  // The beacon behind the eyes: nothing to hide, -1.
  const Pose behind{0, -10, 0};
  EXPECT_EQ(read(&behind, {screen(0, -5, 0, 1.5, 1)}).beaconScreen, -1);
}

TEST(Deployables, SetDownBehindTheBackRimAlongTheHeading) {
  // A robot at (1, 2) heading 90 (east), body radius 0.53125 ft, drops a
  // block 0.125 ft deep: its centre 0.53125 + 0.02 + 0.0625 = 0.61375 ft
  // west of the robot's, at (0.38625, 2).
  Deployable block;
  block.kind = DeployKind::Block;
  block.width_ft = 0.5;
  block.depth_ft = 0.125;
  block.height_ft = 0.4;
  const Deployed b = placeDeployable(block, 0, 0, 77, Pose{1, 2, 90}, 0.53125);
  EXPECT_NEAR(b.x_ft, 0.38625, 1e-12);
  EXPECT_NEAR(b.y_ft, 2, 1e-12);
  EXPECT_EQ(b.tick, 77);
  EXPECT_EQ(b.heading_deg, 90);
  // A light has no depth: 0.55125 ft behind, heading 0 (north) -> south.
  Deployable lamp;
  lamp.kind = DeployKind::DecoyLight;
  const Deployed l = placeDeployable(lamp, 1, 0, 0, Pose{0, 0, 0}, 0.53125);
  EXPECT_NEAR(l.x_ft, 0, 1e-12);
  EXPECT_NEAR(l.y_ft, -0.55125, 1e-12);
}

}  // namespace
}  // namespace simbot::plant
