// The seeded variation (plant/variation.cpp, optics.cpp's noise) against
// closed forms: each kind's draws over many seeds, with the amounts of the
// shipped default profile, checked for their bounds and against the mean
// (and a second moment or a probability) the uniform or Gaussian law of
// DESIGN.md gives. Tolerances are 4.5 standard errors of the sample mean,
// computed from the same law (a wrong amount or law moves a mean by many
// more; a correct one fails about once in 150,000 runs, and the seeds are
// fixed, so the outcome is the same every run).
#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <vector>

#include "plant_support.h"

using namespace plant_test;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kSe = 4.5;

// Counts the words drawn through it.
class Counting final : public RandomBits {
 public:
  explicit Counting(std::uint64_t seed) : inner_(seed) {}
  std::uint64_t next() override {
    ++count;
    return inner_.next();
  }
  int count = 0;

 private:
  SplitMix64 inner_;
};

double phi(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

double wrap180(double d) {
  d = std::fmod(d, 360.0);
  if (d >= 180) d -= 360;
  if (d < -180) d += 360;
  return d;
}

TEST(Variation, ThesisHasNoneAndDefaultHasEveryKind) {
  const Profile t = thesis(), d = defaults();
  EXPECT_EQ(t.field.placement_radius_ft, 0);
  EXPECT_EQ(t.field.placement_heading_deg, 0);
  EXPECT_EQ(t.robot.trim_spread, 0);
  EXPECT_EQ(t.robot.muzzle_speed_spread, 0);
  EXPECT_EQ(t.robot.noise_sigma, 0);
  EXPECT_EQ(t.robot.bad_reading_probability, 0);
  EXPECT_DOUBLE_EQ(d.field.placement_radius_ft, 3.0 / 12);
  EXPECT_DOUBLE_EQ(d.field.placement_heading_deg, 5);
  EXPECT_DOUBLE_EQ(d.robot.trim_spread, 0.015);
  EXPECT_DOUBLE_EQ(d.robot.muzzle_speed_spread, 0.1);
  EXPECT_DOUBLE_EQ(d.robot.noise_sigma, 16);
  EXPECT_DOUBLE_EQ(d.robot.bad_reading_probability, 0.001);
}

// Uniform over a disc of radius R: the offset's distance d = R sqrt(u) has
// E d = 2R/3, Var d = R^2/18, E d^2 = R^2/2, Var d^2 = R^4/12; the heading
// offset, uniform in [-H, H], has mean 0, Var H^2/3, E|dh| = H/2, Var|dh|
// = H^2/12. Default start poses are 0.72 ft from the walls: no redraws.
TEST(Variation, HandPlacementOver1000SeedsMatchesTheDiscAndTheHeadingSpread) {
  const Profile d = defaults();
  const double R = d.field.placement_radius_ft, H = d.field.placement_heading_deg;
  const ArenaConfig nominal = makeArenaConfig(d, 2);
  const int seeds = 1000;
  double sumD = 0, sumD2 = 0, sumH = 0, sumAbsH = 0, sumX = 0;
  int n = 0;
  for (int s = 1; s <= seeds; ++s) {
    ArenaConfig c = nominal;
    Counting a(2 * s), b(2 * s + 1);
    placeByHand(c, {&a, &b});
    EXPECT_EQ(a.count, 3);
    EXPECT_EQ(b.count, 3);
    for (int i = 0; i < 2; ++i) {
      const Pose& p = c.robots[static_cast<std::size_t>(i)].start;
      const Pose& o = nominal.robots[static_cast<std::size_t>(i)].start;
      const double dx = p.x_ft - o.x_ft, dy = p.y_ft - o.y_ft;
      const double dist = std::hypot(dx, dy), dh = wrap180(p.heading_deg - o.heading_deg);
      ASSERT_LE(dist, R * (1 + 1e-12));
      ASSERT_LE(std::abs(dh), H * (1 + 1e-12));
      ASSERT_GE(p.heading_deg, 0);
      ASSERT_LT(p.heading_deg, 360);
      ASSERT_TRUE(placementFits(p.x_ft, p.y_ft, d.robot.body_diameter_ft / 2, d.field));
      sumD += dist;
      sumD2 += dist * dist;
      sumH += dh;
      sumAbsH += std::abs(dh);
      sumX += dx;
      ++n;
    }
  }
  const double N = n;
  EXPECT_NEAR(sumD / N, 2 * R / 3, kSe * R / std::sqrt(18 * N));
  EXPECT_NEAR(sumD2 / N, R * R / 2, kSe * R * R / std::sqrt(12 * N));
  EXPECT_NEAR(sumX / N, 0, kSe * R / std::sqrt(4 * N));  // Var x = R^2/4
  EXPECT_NEAR(sumH / N, 0, kSe * H / std::sqrt(3 * N));
  EXPECT_NEAR(sumAbsH / N, H / 2, kSe * H / std::sqrt(12 * N));
}

// A mark h = 0.1 ft from where the body would touch the east wall: a draw
// whose centre lands in the disc's segment beyond that line is redrawn.
// The segment's share of the disc is p = (R^2 acos(h/R) - h sqrt(R^2 -
// h^2)) / (pi R^2), so the first attempt fails with probability p.
TEST(Variation, PlacementNearAWallRedrawsAsOftenAsTheDiscSegmentSays) {
  const Profile d = defaults();
  const double R = d.field.placement_radius_ft, r = d.robot.body_diameter_ft / 2;
  const double h = 0.1;
  ArenaConfig nominal = makeArenaConfig(d, 1);
  nominal.robots[0].start = Pose{d.field.size_ft / 2 - r - h, 3, 90};
  const double p = (R * R * std::acos(h / R) - h * std::sqrt(R * R - h * h)) / (kPi * R * R);
  int redrawn = 0;
  const int seeds = 1000;
  for (int s = 1; s <= seeds; ++s) {
    ArenaConfig c = nominal;
    Counting a(s);
    placeByHand(c, {&a});
    const Pose& q = c.robots[0].start;
    ASSERT_TRUE(placementFits(q.x_ft, q.y_ft, r, d.field));
    ASSERT_EQ(a.count % 3, 0);
    redrawn += a.count > 3;
  }
  EXPECT_NEAR(redrawn / double(seeds), p, kSe * std::sqrt(p * (1 - p) / seeds));
}

// B's mark on top of A's: no draw can put it clear of A, so after
// kPlacementAttempts attempts B stays exactly on its mark.
TEST(Variation, PlacementThatNeverFitsGivesUpAtTheMark) {
  const Profile d = defaults();
  ArenaConfig c = makeArenaConfig(d, 2);
  c.robots[1].start = c.robots[0].start;
  const Pose mark = c.robots[1].start;
  Counting a(7), b(8);
  placeByHand(c, {&a, &b});
  EXPECT_EQ(a.count, 3);
  EXPECT_EQ(b.count, 3 * kPlacementAttempts);
  EXPECT_EQ(c.robots[1].start.x_ft, mark.x_ft);
  EXPECT_EQ(c.robots[1].start.y_ft, mark.y_ft);
  EXPECT_EQ(c.robots[1].start.heading_deg, mark.heading_deg);
}

// Zero amounts draw nothing and change nothing (thesis-1997).
TEST(Variation, ZeroAmountsDrawNothing) {
  const Profile t = thesis();
  ArenaConfig c = makeArenaConfig(t, 2);
  const ArenaConfig before = c;
  Counting a(1), b(2);
  placeByHand(c, {&a, &b});
  RobotParams params = t.robot;
  drawWheelTrims(params, a);
  EXPECT_EQ(muzzleFactor(params, &a), 1.0);
  const Dispersion none = drawDispersion(params, &a);
  EXPECT_EQ(none.azimuth_deg, 0.0);
  EXPECT_EQ(none.elevation_deg, 0.0);
  EXPECT_EQ(a.count + b.count, 0);
  EXPECT_EQ(params.left_trim, t.robot.left_trim);
  EXPECT_EQ(params.right_trim, t.robot.right_trim);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(c.robots[static_cast<std::size_t>(i)].start.x_ft,
              before.robots[static_cast<std::size_t>(i)].start.x_ft);
    EXPECT_EQ(c.robots[static_cast<std::size_t>(i)].start.heading_deg,
              before.robots[static_cast<std::size_t>(i)].start.heading_deg);
  }
  // A default robot without a stream also launches at exactly the speed.
  EXPECT_EQ(muzzleFactor(defaults().robot, nullptr), 1.0);
  EXPECT_EQ(drawDispersion(defaults().robot, nullptr).azimuth_deg, 0.0);
  EXPECT_EQ(drawDispersion(defaults().robot, nullptr).elevation_deg, 0.0);
}

// Pearson's chi-square p-value of standardised draws z against a law whose
// quantile function cuts the line into k bins of equal probability (the
// oracle: Boost.Math's quantiles and chi-square tail, not simbot's code).
template <class Quantile>
double chiSquareP(const std::vector<double>& z, int k, Quantile quantile) {
  std::vector<double> edges;
  for (int j = 1; j < k; ++j) edges.push_back(quantile(static_cast<double>(j) / k));
  std::vector<double> count(static_cast<std::size_t>(k), 0);
  for (double x : z)
    count[static_cast<std::size_t>(std::upper_bound(edges.begin(), edges.end(), x) -
                                   edges.begin())] += 1;
  const double expected = static_cast<double>(z.size()) / k;
  double x2 = 0;
  for (double c : count) x2 += (c - expected) * (c - expected) / expected;
  return boost::math::cdf(boost::math::complement(boost::math::chi_squared(k - 1), x2));
}

double normalQuantile(double p) { return boost::math::quantile(boost::math::normal(), p); }

// The stated law (profiles/default.toml [gun]): azimuth and elevation
// independent normals, mean 0, standard deviations azimuth_sigma and
// elevation_sigma. 40,000 draws (seed fixed): each axis / sigma against
// N(0, 1) in 20 equiprobable bins, the pair on a 6 x 6 grid of the
// marginals' equiprobable bins (independence: each cell 1/36), and the
// squared radius against chi-square(2). Each must not be rejected at 0.1%;
// the same draws read with a sigma 5% off must be (the test has teeth).
TEST(Variation, DispersionDrawsPassChiSquareAgainstIndependentNormals) {
  const RobotParams p = defaults().robot;
  ASSERT_GT(p.azimuth_sigma_deg, 0);
  ASSERT_GT(p.elevation_sigma_deg, 0);
  const int n = 40000;
  Counting bits(1997);
  std::vector<double> az, el, r2, wrongAz;
  for (int k = 0; k < n; ++k) {
    const Dispersion d = drawDispersion(p, &bits);
    az.push_back(d.azimuth_deg / p.azimuth_sigma_deg);
    el.push_back(d.elevation_deg / p.elevation_sigma_deg);
    r2.push_back(az.back() * az.back() + el.back() * el.back());
    wrongAz.push_back(d.azimuth_deg / (1.05 * p.azimuth_sigma_deg));
    // Bounded: 53-bit words give a Box-Muller radius of at most 8.58.
    ASSERT_LT(std::sqrt(r2.back()), 8.58);
  }
  EXPECT_EQ(bits.count, 2 * n);
  const double alpha = 1e-3;
  EXPECT_GT(chiSquareP(az, 20, normalQuantile), alpha) << "azimuth";
  EXPECT_GT(chiSquareP(el, 20, normalQuantile), alpha) << "elevation";
  EXPECT_GT(
      chiSquareP(r2, 20,
                 [](double q) { return boost::math::quantile(boost::math::chi_squared(2), q); }),
      alpha)
      << "squared radius";
  // The grid: cell index from both marginals' 6 equiprobable bins.
  std::vector<double> edges;
  for (int j = 1; j < 6; ++j) edges.push_back(normalQuantile(j / 6.0));
  const auto bin = [&](double x) {
    return static_cast<double>(std::upper_bound(edges.begin(), edges.end(), x) - edges.begin());
  };
  std::vector<double> cell;
  for (int k = 0; k < n; ++k)
    cell.push_back(6 * bin(az[static_cast<std::size_t>(k)]) + bin(el[static_cast<std::size_t>(k)]));
  EXPECT_GT(chiSquareP(cell, 36, [](double q) { return 36 * q - 0.5; }), alpha) << "joint";
  EXPECT_LT(chiSquareP(wrongAz, 20, normalQuantile), 1e-6) << "a 5% wrong sigma passed";
}

// Uniform in [1 - s, 1 + s]: mean 1, variance s^2/3, every factor inside.
void checkUniformFactors(const std::vector<double>& f, double s) {
  double sum = 0, sum2 = 0;
  for (double x : f) {
    ASSERT_GE(x, 1 - s);
    ASSERT_LE(x, 1 + s);
    sum += x;
    sum2 += (x - 1) * (x - 1);
  }
  const double N = static_cast<double>(f.size());
  EXPECT_NEAR(sum / N, 1, kSe * s / std::sqrt(3 * N));
  // Var of (x-1)^2 for x-1 uniform in [-s, s]: s^4/5 - s^4/9 = 4 s^4 / 45.
  EXPECT_NEAR(sum2 / N, s * s / 3, kSe * s * s * std::sqrt(4.0 / 45 / N));
}

TEST(Variation, WheelTrimsOver1000SeedsAreUniformAroundTheGivenTrims) {
  const Profile d = defaults();
  std::vector<double> left, right;
  for (int s = 1; s <= 1000; ++s) {
    RobotParams p = d.robot;
    Counting bits(s);
    drawWheelTrims(p, bits);
    EXPECT_EQ(bits.count, 2);
    left.push_back(p.left_trim / d.robot.left_trim);
    right.push_back(p.right_trim / d.robot.right_trim);
  }
  checkUniformFactors(left, d.robot.trim_spread);
  checkUniformFactors(right, d.robot.trim_spread);
}

TEST(Variation, MuzzleFactorsOver1000ShotsAreUniform) {
  const Profile d = defaults();
  Counting bits(99);
  std::vector<double> f;
  for (int k = 0; k < 1000; ++k) f.push_back(muzzleFactor(d.robot, &bits));
  EXPECT_EQ(bits.count, 1000);
  checkUniformFactors(f, d.robot.muzzle_speed_spread);
}

// Eye readings with the default noise. At background (16, no beacon) a
// clean reading is 16 + sigma z quantised down to a multiple of 16: 16 for
// z < 16/sigma, 32 up to 32/sigma, at least 64 from 48/sigma on. A bad
// reading (probability q) is 16 k, k uniform in 0..255, clamped to 16..max:
// 16 for k <= 1, 32 for k = 2, at least 64 for k >= 4.
TEST(Variation, EyeNoiseAtBackgroundMatchesTheProfilesSigmaAndBadReadings) {
  const Profile d = defaults();
  const double sigma = d.robot.noise_sigma, q = d.robot.bad_reading_probability;
  const Pose self{-6.5, -6.5, 0};
  SplitMix64 bits(2024);
  const int calls = 20000;
  int at16 = 0, at32 = 0, above48 = 0, n = 0;
  for (int k = 0; k < calls; ++k) {
    const EyeReadings e = computeEyes(self, nullptr, d.robot, d.field, &bits);
    for (int v : {e.left, e.right}) {
      ASSERT_EQ(v % 16, 0);
      ASSERT_GE(v, 16);
      ASSERT_LE(v, d.robot.eye_max);
      at16 += v == 16;
      at32 += v == 32;
      above48 += v > 48;
      ++n;
    }
  }
  const auto check = [n](int count, double p, const char* what) {
    EXPECT_NEAR(count / double(n), p, kSe * std::sqrt(p * (1 - p) / n)) << what;
  };
  check(at16, (1 - q) * phi(16 / sigma) + q * 2 / 256, "16");
  check(at32, (1 - q) * (phi(32 / sigma) - phi(16 / sigma)) + q / 256, "32");
  check(above48, (1 - q) * (1 - phi(48 / sigma)) + q * 252 / 256, "> 48");
}

// With the beacon saturating both eyes (4080 at 2 ft dead ahead) noise
// cannot take a clean reading below 4000 (that is 5 sigma), so the readings
// below 4000 are the bad ones whose k is at most 249: probability q 250/256.
TEST(Variation, BadReadingsAtSaturationComeAtTheProfilesRate) {
  const Profile d = defaults();
  const double q = d.robot.bad_reading_probability;
  const Pose self{3, 3, 0}, opp{3, 5, 0};
  SplitMix64 bits(77);
  int low = 0, n = 0;
  for (int k = 0; k < 50000; ++k) {
    const EyeReadings e = computeEyes(self, &opp, d.robot, d.field, &bits);
    for (int v : {e.left, e.right}) {
      low += v < 4000;
      ++n;
    }
  }
  const double p = q * 250 / 256 + (1 - q) * phi(-80 / d.robot.noise_sigma);
  EXPECT_NEAR(low / double(n), p, kSe * std::sqrt(p * (1 - p) / n));
}

}  // namespace

namespace {

// The arena applies the muzzle factor drawn at the stroke: thesis-1997's
// instant gun (105 ft/s, stroke 0) with a 10% spread launches gun 1's ball
// at 105 (1 + 0.1 (2 u - 1)), u from the stream's first word, and gun 2's
// (the next stroke) from its second; no stream: exactly 105.
TEST(Variation, ArenaLaunchesAtTheMuzzleSpeedTimesTheDrawnFactor) {
  Profile p = thesis();
  p.robot.muzzle_speed_spread = 0.1;
  SplitMix64 oracle(31);
  const double u1 = unit53(oracle.next()), u2 = unit53(oracle.next());
  const auto launchSpeeds = [&](RandomBits* muzzle) {
    Arena a(config(p, {Pose{0, 3, 90}}));
    std::vector<double> speeds;
    const auto runTo = [&](std::int64_t stop) {
      while (a.now() < stop)
        for (const Event& e : a.advance(stop).events)
          if (e.kind == EventKind::BallLaunch) speeds.push_back(std::hypot(e.vx, e.vy));
    };
    runTo(1000);
    a.setPortB(0, 1u << 4, 1000, nullptr, muzzle);  // gun 1's solenoid
    runTo(2000);
    a.setPortB(0, (1u << 4) | (1u << 5), 2000, nullptr, muzzle);  // then gun 2's
    runTo(ticks(0.1));
    return speeds;
  };
  SplitMix64 stream(31);
  const auto drawn = launchSpeeds(&stream);
  ASSERT_EQ(drawn.size(), 2u);
  EXPECT_NEAR(drawn[0], 105 * (1 + 0.1 * (2 * u1 - 1)), 1e-9);
  EXPECT_NEAR(drawn[1], 105 * (1 + 0.1 * (2 * u2 - 1)), 1e-9);
  const auto plain = launchSpeeds(nullptr);
  ASSERT_EQ(plain.size(), 2u);
  EXPECT_NEAR(plain[0], 105, 1e-9);
  EXPECT_NEAR(plain[1], 105, 1e-9);
}

// Each launch carries its dispersion: the arena turns the ball's velocity
// from the heading by the azimuth and raises it by the elevation, at the
// full muzzle speed, and leaves the muzzle on the body's edge along the
// heading. 10 single-robot arenas (thesis-1997's instant gun with default's
// sigmas) fire all 30 balls each; the angles recovered from the launch
// events' velocities (what ball_launch records) equal the draws of a copy
// of the stream, and the 300 of them pass a chi-square test of each axis
// against its normal law (10 equiprobable bins, Boost's quantiles).
TEST(Variation, ArenaLaunchesCarryTheDrawnDispersion) {
  Profile p = thesis();
  const RobotParams d = defaults().robot;
  p.robot.azimuth_sigma_deg = d.azimuth_sigma_deg;
  p.robot.elevation_sigma_deg = d.elevation_sigma_deg;
  std::vector<double> az, el;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const double heading = 37.0 * static_cast<double>(seed);
    Arena a(config(p, {Pose{0, 3, heading}}));
    SplitMix64 stream(seed), copy(seed);
    std::vector<Event> launches;
    std::int64_t t = 0;
    for (int shot = 0; shot < 2 * p.robot.balls_per_gun; ++shot) {
      const std::uint8_t solenoid = shot % 2 == 0 ? 1u << 4 : 1u << 5;
      for (const std::uint8_t v : {solenoid, std::uint8_t{0}}) {
        a.setPortB(0, v, t, nullptr, nullptr, &stream);
        t += 1000;
        while (a.now() < t)
          for (const Event& e : a.advance(t).events)
            if (e.kind == EventKind::BallLaunch) launches.push_back(e);
      }
    }
    ASSERT_EQ(launches.size(), 30u);
    for (const Event& e : launches) {
      const Dispersion want = drawDispersion(p.robot, &copy);
      EXPECT_NEAR(e.heading_deg, std::fmod(heading, 360.0), 1e-9);
      const double h = e.heading_deg * kPi / 180;
      EXPECT_NEAR(e.x, 0.53125 * std::sin(h), 1e-9);  // the muzzle: along the heading
      EXPECT_NEAR(e.y, 3 + 0.53125 * std::cos(h), 1e-9);
      const double across = std::hypot(e.vx, e.vy);
      EXPECT_NEAR(std::hypot(across, e.vz), 105, 1e-9);
      const double gotAz = wrap180(std::atan2(e.vx, e.vy) * 180 / kPi - e.heading_deg);
      const double gotEl = std::atan2(e.vz, across) * 180 / kPi;
      EXPECT_NEAR(gotAz, want.azimuth_deg, 1e-9);
      EXPECT_NEAR(gotEl, want.elevation_deg, 1e-9);
      az.push_back(gotAz / p.robot.azimuth_sigma_deg);
      el.push_back(gotEl / p.robot.elevation_sigma_deg);
    }
  }
  EXPECT_GT(chiSquareP(az, 10, normalQuantile), 1e-3) << "azimuth";
  EXPECT_GT(chiSquareP(el, 10, normalQuantile), 1e-3) << "elevation";
}

}  // namespace
