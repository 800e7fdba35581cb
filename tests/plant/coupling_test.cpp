// Why two running robots stop at every horizon (scheduler/match.cpp,
// "Larger rounds", rule (10)): the robots share one integration, and a
// port B input that changes anything that moves (here a gun motor bit)
// re-initialises it at the input's tick. The other robot's pose after that
// tick then comes from other steps, so its last bits move although nothing
// reaches it: the same pose to well within the integration's tolerance,
// not the same bits. Another robot's eye read after the horizon sees those
// bits, so no robot may run past a horizon before knowing the inputs made
// up to it: between two running robots the lookahead is zero.
#include <gtest/gtest.h>

#include <cstring>

#include "plant_support.h"

namespace {

using namespace plant_test;

constexpr std::int64_t kToggle = 4'321'987;  // off any 9,600 grid
constexpr std::int64_t kEnd = 3 * simbot::timebase::kTicksPerSecond;

// Robot 0's pose at `t` when robot 1 writes `portB` at kToggle (0: no
// write). Robot 0 drives an arc; the two are 6 ft apart and never meet.
Pose robot0At(std::int64_t t, std::uint8_t portB) {
  Arena a(config(defaults(), {{-3, 0, 0}, {3, 0, 180}}));
  a.setWheels(0, frame("3fg0frg0"), 0);
  while (a.now() < kToggle) a.advance(kToggle);
  if (portB != 0) a.setPortB(1, portB, kToggle);
  while (a.now() < t) a.advance(t);
  return a.state(0, t).pose;
}

bool sameBits(const Pose& x, const Pose& y) {
  return std::memcmp(&x.x_ft, &y.x_ft, sizeof(double)) == 0 &&
         std::memcmp(&x.y_ft, &y.y_ft, sizeof(double)) == 0 &&
         std::memcmp(&x.heading_deg, &y.heading_deg, sizeof(double)) == 0;
}

// The default hardware's bits (plant.h, Hardware): gun motor 2 on bit 7;
// the disc shooter on bit 6, only logged without a disc launcher.
constexpr std::uint8_t kGunMotor2 = 0x80;
constexpr std::uint8_t kDiscShooter = 0x40;

TEST(Coupling, AnotherRobotsInputLeavesThePoseUpToItsTickAsItWas) {
  EXPECT_TRUE(sameBits(robot0At(kToggle, 0), robot0At(kToggle, kGunMotor2)));
}

// The control: a write that moves nothing keeps the prediction (no
// re-initialisation) and every bit after it.
TEST(Coupling, AnInputThatMovesNothingLeavesEveryBitAfterIt) {
  EXPECT_TRUE(sameBits(robot0At(kEnd, 0), robot0At(kEnd, kDiscShooter)));
}

TEST(Coupling, AnotherRobotsInputMovesThePosesLastBitsAfterItsTick) {
  const Pose quiet = robot0At(kEnd, 0), toggled = robot0At(kEnd, kGunMotor2);
  EXPECT_FALSE(sameBits(quiet, toggled));
  // The same motion: within a nano-foot and a nano-degree (the
  // integration's relative tolerance is 3e-11; measured: 2e-12 ft).
  EXPECT_NEAR(quiet.x_ft, toggled.x_ft, 1e-9);
  EXPECT_NEAR(quiet.y_ft, toggled.y_ft, 1e-9);
  EXPECT_NEAR(quiet.heading_deg, toggled.heading_deg, 1e-9);
}

}  // namespace
