// The eyes against DESIGN.md's formulas, computed independently here.
#include <cmath>

#include "plant_support.h"

using namespace plant_test;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Opponent pose at range r and bearing gamma (deg, + = right) from self.
Pose place(const Pose& self, double r, double gammaDeg) {
  const double b = (self.heading_deg + gammaDeg) * kPi / 180;
  return Pose{self.x_ft + r * std::sin(b), self.y_ft + r * std::cos(b), 0};
}

int expectedReading(double s, double max) {
  return static_cast<int>(std::clamp(16 * std::floor(s / 16), 16.0, max));
}

TEST(Optics, GridOfBearingsAndRanges) {
  const Profile p = thesis();
  const RobotParams& e = p.robot;
  const double kappa = (e.eye_max - e.eye_background) * e.eye_saturation_ft * e.eye_saturation_ft;
  const double phi = std::atan(e.right_eye_width / e.eye_nose) * 180 / kPi;  // widths equal
  const Pose self{2, 3, 30};  // north-east quadrant: the divider is far away
  int checked = 0;
  for (double r : {0.5, 1.0, 2.9, 2.999, 3.001, 3.1, 4.0, 6.0, 9.5}) {
    for (double g = -89; g <= 89; g += 4.25) {
      const Pose opp = place(self, r, g);
      const EyeReadings got = computeEyes(self, &opp, e, p.field);
      const double s = r <= 3.0 ? e.eye_max : kappa / (r * r) + e.eye_background;
      const double f = std::max(0.0, 1 - std::abs(g) / phi);
      const int nearR = expectedReading(s, e.eye_max), farR = expectedReading(s * f, e.eye_max);
      if (g < 0) {
        EXPECT_EQ(got.left, nearR) << r << " " << g;
        EXPECT_EQ(got.right, farR) << r << " " << g;
      } else {
        EXPECT_EQ(got.right, nearR) << r << " " << g;
        EXPECT_EQ(got.left, farR) << r << " " << g;
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 300);
  EXPECT_NEAR(phi, 33.69, 0.01);  // thesis III.B: "limiting angle 33 deg"
}

// Eyes of different widths, the opponent alternating sides: the far eye's
// limiting angle is atan(its width / nose) for the eye that is far each
// time (the right one for an opponent on the left): with widths 0.2 and
// 0.4 and nose 0.3, phi = 33.69 deg on the left, 53.13 deg on the right.
TEST(Optics, EachSideUsesItsFarEyesWidthWhenTheyDiffer) {
  Profile p = thesis();
  p.robot.left_eye_width = 0.4;
  p.robot.right_eye_width = 0.2;
  p.robot.eye_nose = 0.3;
  const double phiRightEye = std::atan(0.2 / 0.3) * 180 / kPi;
  const double phiLeftEye = std::atan(0.4 / 0.3) * 180 / kPi;
  EXPECT_NEAR(phiRightEye, 33.69, 0.01);
  EXPECT_NEAR(phiLeftEye, 53.13, 0.01);
  const Pose self{2, 3, 30};
  for (int k = 0; k < 6; ++k) {
    const double g = (k % 2 == 0 ? -1 : 1) * (10.0 + 3 * k);
    const EyeGeometry got = eyeGeometry(self, place(self, 4.0, g), p.robot, p.field);
    const double phi = g < 0 ? phiRightEye : phiLeftEye;
    EXPECT_NEAR(got.far_fraction, 1 - std::abs(g) / phi, 1e-12) << g;
  }
}

TEST(Optics, OpponentOnTheLeftMakesTheLeftEyeBrighter) {
  const Profile p = thesis();
  const Pose self{0, 2, 0};
  const Pose opp = place(self, 5, -20);
  ASSERT_LT(opp.x_ft, 0);  // heading north, the opponent is west: left
  const EyeReadings r = computeEyes(self, &opp, p.robot, p.field);
  EXPECT_GT(r.left, r.right);
  const EyeGeometry g = eyeGeometry(self, opp, p.robot, p.field);
  EXPECT_NEAR(g.gamma_deg, -20, 1e-9);
  // Appendix C's swap gives the brighter value to the far eye.
  RobotParams swapped = p.robot;
  swapped.thesis_swapped_eyes = true;
  const EyeReadings s = computeEyes(self, &opp, swapped, p.field);
  EXPECT_EQ(s.left, r.right);
  EXPECT_EQ(s.right, r.left);
}

TEST(Optics, DeadAheadGivesBothEyesTheFullSignal) {
  const Profile p = thesis();
  const Pose self{0, 0, 0}, opp{0, 6, 180};
  const EyeReadings r = computeEyes(self, &opp, p.robot, p.field);
  const double kappa = (4080.0 - 16) * 9;
  EXPECT_EQ(r.left, expectedReading(kappa / 36 + 16, 4080));
  EXPECT_EQ(r.right, r.left);
}

TEST(Optics, TheDividerHidesTheBeacon) {
  const Profile p = thesis();
  const Pose self{-3, -6, 90}, opp{3, -6, 270};
  EXPECT_TRUE(dividerBlocks(self.x_ft, self.y_ft, opp.x_ft, opp.y_ft, p.field));
  const EyeReadings r = computeEyes(self, &opp, p.robot, p.field);
  EXPECT_EQ(r.left, 16);
  EXPECT_EQ(r.right, 16);
  const Pose above{3, -2, 270};  // line of sight passes north of the divider's end
  const Pose selfN{-3, -2, 90};
  EXPECT_FALSE(dividerBlocks(selfN.x_ft, selfN.y_ft, above.x_ft, above.y_ft, p.field));
  EXPECT_GT(computeEyes(selfN, &above, p.robot, p.field).left, 16);
}

TEST(Optics, OutsideNinetyDegreesSeesBackground) {
  const Profile p = thesis();
  const Pose self{1, 1, 45};
  for (double g : {90.0, -90.0, 91.0, 135.0, -170.0, 180.0}) {
    const Pose opp = place(self, 2.0, g);
    const EyeReadings r = computeEyes(self, &opp, p.robot, p.field);
    EXPECT_EQ(r.left, 16) << g;
    EXPECT_EQ(r.right, 16) << g;
  }
  // No opponent at all (solo).
  const EyeReadings none = computeEyes(self, nullptr, p.robot, p.field);
  EXPECT_EQ(none.left, 16);
  EXPECT_EQ(none.right, 16);
}

// DESIGN.md's quantiser, clamp(16 floor(S / 16), 16, max), tops out at 2032
// for the 2040 circuit (2040 is not a multiple of 16).
TEST(Optics, MaxOf2040Clamps) {
  Profile p = thesis();
  p.robot.eye_max = 2040;
  const Pose self{0, 0, 0}, opp{0, 1, 0};
  const EyeReadings r = computeEyes(self, &opp, p.robot, p.field);
  EXPECT_EQ(r.left, 2032);
  EXPECT_EQ(r.right, 2032);
}

TEST(Optics, SeededNoiseIsReproducibleAndChangesReadings) {
  Profile p = thesis();
  p.robot.noise_sigma = 40;
  p.robot.bad_reading_probability = 0.1;
  const Pose self{0, 0, 0}, opp{1, 7, 0};
  SplitMix64 a(42), b(42);
  int differs = 0, bad = 0;
  const EyeReadings clean = computeEyes(self, &opp, p.robot, p.field);
  for (int i = 0; i < 500; ++i) {
    const EyeReadings x = computeEyes(self, &opp, p.robot, p.field, &a);
    const EyeReadings y = computeEyes(self, &opp, p.robot, p.field, &b);
    EXPECT_EQ(x.left, y.left);
    EXPECT_EQ(x.right, y.right);
    differs += x.left != clean.left;
    bad += std::abs(x.left - clean.left) > 400;
    EXPECT_EQ(x.left % 16, 0);
    EXPECT_GE(x.left, 16);
    EXPECT_LE(x.left, 4080);
  }
  EXPECT_GT(differs, 250);
  EXPECT_GT(bad, 10);
  EXPECT_LT(bad, 120);
}

// A read of one eye gives that eye's value of a read of both, and leaves the
// noise stream where a read of both leaves it (same words, same order), so
// a program's channel choice never shifts later reads.
TEST(Optics, OneChannelReadMatchesBothAndDrawsTheSameWords) {
  Profile p = thesis();
  p.robot.noise_sigma = 40;
  p.robot.bad_reading_probability = 0.1;
  const Pose self{0, 0, 0}, opp{1, 7, 0};
  SplitMix64 both(7), left(7), right(7);
  for (int i = 0; i < 500; ++i) {
    const EyeReadings b = computeEyes(self, &opp, p.robot, p.field, &both);
    const EyeReadings l = computeEyes(self, &opp, p.robot, p.field, &left, EyeChannels::Left);
    const EyeReadings r = computeEyes(self, &opp, p.robot, p.field, &right, EyeChannels::Right);
    EXPECT_EQ(l.left, b.left);
    EXPECT_EQ(r.right, b.right);
  }
  const std::uint64_t next = both.next();
  EXPECT_EQ(left.next(), next);
  EXPECT_EQ(right.next(), next);
}

// Every noisy reading is the documented formula's, evaluated in full
// here for every draw: Box-Muller from the two words (u1 = (w >> 11) + 1
// over 2^53, u2 = (w >> 11) over 2^53), s + sigma z quantised. The eyes
// skip that arithmetic where it cannot change the reading (a signal that
// already reads 16 and a draw whose cosine is certainly negative): signals
// on both sides of 32, the lowest that can read above 16, must agree on
// every read, and the skip must have been possible on many of them.
TEST(Optics, NoisyReadingsAreTheFullFormulasOnEveryDraw) {
  Profile p = defaults();
  p.robot.bad_reading_probability = 0;
  const Pose self{0, 0, 0};
  for (const double sigma : {16.0, 40.0}) {
    p.robot.noise_sigma = sigma;
    for (const double background : {16.0, 24.0, 31.0, 31.999999, 32.0, 33.0, 48.0}) {
      p.robot.eye_background = background;
      SplitMix64 eyes(11), words(11);
      int skippable = 0;
      for (int i = 0; i < 20000; ++i) {
        const EyeReadings r = computeEyes(self, nullptr, p.robot, p.field, &eyes);
        int expected[2];
        for (int& e : expected) {
          const double u1 = static_cast<double>((words.next() >> 11) + 1) / 9007199254740992.0;
          const double u2 = static_cast<double>(words.next() >> 11) / 9007199254740992.0;
          const double z = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
          e = expectedReading(background + sigma * z, p.robot.eye_max);
          skippable += background < 32 && u2 > 0.26 && u2 < 0.74;
        }
        ASSERT_EQ(r.left, expected[0]) << "sigma " << sigma << " background " << background;
        ASSERT_EQ(r.right, expected[1]) << "sigma " << sigma << " background " << background;
      }
      if (background < 32) {
        EXPECT_GT(skippable, 15000);
      }
    }
  }
}

TEST(Optics, ArenaEyesFollowThePoses) {
  const Profile p = thesis();
  Arena a(makeArenaConfig(p, 2));
  // A at (-6.5,-6.5) and B at (6.5,-6.5), both facing north; B is to A's
  // right at 90 deg exactly: out of view. The divider also hides it.
  EyeReadings r = a.eyeReadings(0, 0);
  EXPECT_EQ(r.left, 16);
  EXPECT_EQ(r.right, 16);
  Arena b(config(p, {Pose{-3, 2, 90}, Pose{3, 2, 0}}));
  r = b.eyeReadings(0, 0);
  EXPECT_EQ(r.left, r.right);
  EXPECT_GT(r.left, 16);
}

}  // namespace
