// Motor frames: parsing the 8 characters the controller latched, and the
// wheel speeds a frame asks for (the profile loaders' tests are in
// tests/config/).
#include "plant_support.h"

using namespace plant_test;

namespace {

TEST(MotorFrame, ValidFrames) {
  auto f = parseMotorFrame("ffgrffgr");
  ASSERT_TRUE(f);
  EXPECT_EQ(f->left.speed, 15);
  EXPECT_TRUE(f->left.forward);
  EXPECT_TRUE(f->left.go);
  EXPECT_EQ(f->left.counter, 'r');
  f = parseMotorFrame("0rs 9fgx");
  ASSERT_TRUE(f);
  EXPECT_EQ(f->left.speed, 0);
  EXPECT_FALSE(f->left.forward);
  EXPECT_FALSE(f->left.go);
  EXPECT_EQ(f->right.speed, 9);
  f = parseMotorFrame(
      "arg\xff"
      "cfs1");
  ASSERT_TRUE(f);
  EXPECT_EQ(f->left.speed, 10);
  EXPECT_EQ(f->right.speed, 12);
}

TEST(MotorFrame, InvalidFramesAreRejected) {
  EXPECT_FALSE(parseMotorFrame("gfgrffgr"));                        // speed out of 0-f
  EXPECT_FALSE(parseMotorFrame("Ffgrffgr"));                        // uppercase hex
  EXPECT_FALSE(parseMotorFrame("fxgrffgr"));                        // direction
  EXPECT_FALSE(parseMotorFrame("ffqrffgr"));                        // go/stop
  EXPECT_FALSE(parseMotorFrame("ffgrffg"));                         // too short
  EXPECT_FALSE(parseMotorFrame("ffgrffgrr"));                       // too long
  EXPECT_FALSE(parseMotorFrame(std::string_view("ffg\0ffgr", 8)));  // NUL counter
  EXPECT_FALSE(parseMotorFrame("ffgrff r"));
}

TEST(MotorFrame, SpeedTableTrimDirectionAndStop) {
  const Profile d = defaults();
  auto f = *parseMotorFrame("7fg0crg0");
  EXPECT_DOUBLE_EQ(wheelSpeedFps(f.left, d.robot, true),
                   d.robot.speed_table_fps[7] * d.robot.left_trim);
  EXPECT_DOUBLE_EQ(wheelSpeedFps(f.right, d.robot, false),
                   -d.robot.speed_table_fps[12] * d.robot.right_trim);
  f = *parseMotorFrame("ffs0ffs0");
  EXPECT_EQ(wheelSpeedFps(f.left, d.robot, true), 0.0);
  const Profile t = thesis();
  for (int k = 0; k < 16; ++k)
    EXPECT_NEAR(t.robot.speed_table_fps[static_cast<std::size_t>(k)], 1.5 * k / 15, 1e-12);
}

}  // namespace
