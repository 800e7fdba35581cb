// The battery's closed form (plant/battery.h), the supply scale on the
// wheels (Arena::setSupply), and jam and misfire frequencies against a
// binomial interval.
#include "plant/battery.h"

#include <boost/math/distributions/binomial.hpp>

#include "plant_support.h"

namespace plant_test {
namespace {

BatteryParams pack() {
  BatteryParams b;
  b.enabled = true;
  b.capacity_c = 3600;  // 1 Ah
  b.voltage_full_v = 12.8;
  b.voltage_empty_v = 10.8;
  b.nominal_v = 12;
  b.resistance_ohm = 0.2;
  b.board_a = 0.1;
  b.drive_a = 1.5;
  b.brownout_v = 9;
  return b;
}

// Hand computation: 0.1 A for 10 s, then 2 A for 30 s: Q = 1 + 60 = 61 C,
// SOC = 1 - 61/3600, Voc = 10.8 + 2 (1 - 61/3600) = 12.766111..., V = Voc
// - 2 x 0.2 = 12.366111... V.
TEST(Battery, VoltageIsTheDischargeFormula) {
  Battery b(pack());
  b.setCurrent(0, 0.1);
  b.setCurrent(ticks(10), 2.0);
  const std::int64_t t = ticks(40);
  EXPECT_NEAR(b.charge(t), 61.0, 1e-12);
  EXPECT_NEAR(b.openCircuit(t), 10.8 + 2.0 * (1 - 61.0 / 3600), 1e-12);
  EXPECT_NEAR(b.voltage(t), 10.8 + 2.0 * (1 - 61.0 / 3600) - 0.4, 1e-12);
  EXPECT_NEAR(b.supplyScale(t), (10.8 + 2.0 * (1 - 61.0 / 3600) - 0.4) / 12, 1e-12);
}

// The empty end of the curve is flat: past the capacity Voc stays at V_empty.
TEST(Battery, EmptyEndIsFlat) {
  Battery b(pack());
  b.setCurrent(0, 10.0);  // 360 s empties 3600 C
  EXPECT_DOUBLE_EQ(b.openCircuit(ticks(400)), 10.8);
  EXPECT_DOUBLE_EQ(b.voltage(ticks(400)), 10.8 - 2.0);
}

// Closed form: under 10 A the voltage 10.8 + 2 SOC - 2 reaches 9.5 at
// SOC = 0.35, i.e. after 0.65 x 3600 = 2340 C, at 234 s: tick 234 N, or
// the next one if the double evaluation of V at 234 N rounds above 9.5;
// either way the tick found is the first whose voltage() reads <= 9.5.
// Under 0.1 A the flat end (10.78 V) never gets to 9 V.
TEST(Battery, BrownOutTickIsTheClosedFormCrossing) {
  Battery b(pack());
  b.setCurrent(0, 10.0);
  const auto at = b.firstTickAtOrBelow(9.5, 0);
  ASSERT_TRUE(at.has_value());
  EXPECT_GE(*at, 234 * 9'216'000LL);
  EXPECT_LE(*at, 234 * 9'216'000LL + 1);
  EXPECT_LE(b.voltage(*at), 9.5);
  EXPECT_GT(b.voltage(*at - 1), 9.5);
  Battery idle(pack());
  idle.setCurrent(0, 0.1);
  EXPECT_FALSE(idle.firstTickAtOrBelow(9.0, 0).has_value());
}

// drawnCurrent: board + each wheel's step / 15 of drive_a + gun motors +
// solenoids: 0.1 + 1.5 x 15/15 + 1.5 x 5/15 + 0.8 + 2.
TEST(Battery, CurrentFromCommandsAndPortB) {
  BatteryParams p = pack();
  p.gun_motor_a = 0.8;
  p.solenoid_a = 2;
  const MotorFrame f = frame("ffgx5rgx");
  EXPECT_NEAR(drawnCurrent(p, f.left, f.right, 1, 1), 0.1 + 1.5 + 0.5 + 0.8 + 2, 1e-12);
  const MotorFrame stop = frame("ffsx5rsx");
  EXPECT_NEAR(drawnCurrent(p, stop.left, stop.right, 0, 0), 0.1, 1e-12);
}

// The thesis profile's wheels (no lag, step 15 = 1.5 ft/s): at a supply
// scale of 0.9 a wheel runs at exactly 0.9 x 1.5 ft/s, and a scale of 1
// gives the table's speed bit for bit.
TEST(Battery, WheelSpeedScalesWithTheSupply) {
  Arena a(config(thesis(), {Pose{0, 0, 0}}));
  a.setWheels(0, frame("ffgxfrgx"), 0);
  a.advance(ticks(1));
  EXPECT_EQ(a.state(0, a.now()).left_fps, 1.5);
  EXPECT_TRUE(a.setSupply(0, 0.9, a.now()));
  EXPECT_FALSE(a.setSupply(0, 0.9, a.now()));
  a.advance(a.now() + ticks(1));
  EXPECT_DOUBLE_EQ(a.state(0, a.now()).left_fps, 0.9 * 1.5);
  EXPECT_DOUBLE_EQ(a.state(0, a.now()).right_fps, -0.9 * 1.5);
  EXPECT_EQ(a.supply(0), 0.9);
}

// Jams and misfires per stroke: 4000 arenas, one stroke each from its own
// seeded stream, with jam 0.1 and misfire 0.2. Each count must lie in the
// central range of Binomial(4000, p) that holds it with probability
// 1 - 1e-6 (its 5e-7 and 1 - 5e-7 quantiles, from Boost.Math).
TEST(Battery, JamAndMisfireFrequenciesMatchTheProfile) {
  Profile p = thesis();
  p.robot.jam_probability = 0.1;
  p.robot.misfire_probability = 0.2;
  const ArenaConfig c = config(p, {Pose{0, 0, 0}});
  constexpr int kTrials = 4000;
  int jams = 0, misfires = 0;
  for (int k = 0; k < kTrials; ++k) {
    Arena a(c);
    SplitMix64 luck(0x5eed0000u + static_cast<std::uint64_t>(k));
    for (const Event& e : a.setPortB(0, 0x18, 0, &luck)) {
      jams += e.kind == EventKind::GunJammed;
      misfires += e.kind == EventKind::GunMisfire;
    }
  }
  using boost::math::binomial_distribution;
  const auto inside = [](int count, double probability) {
    // The count's bounds: quantiles of Binomial(kTrials, p) at 5e-7 and 1 - 5e-7.
    const binomial_distribution<> d(kTrials, probability);
    return count >= boost::math::quantile(d, 5e-7) &&
           count <= boost::math::quantile(boost::math::complement(d, 5e-7));
  };
  EXPECT_TRUE(inside(jams, 0.1)) << jams << " jams in " << kTrials;
  EXPECT_TRUE(inside(misfires, 0.2)) << misfires << " misfires in " << kTrials;
}

}  // namespace
}  // namespace plant_test
