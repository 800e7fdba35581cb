// The one conversion from seconds to ticks (timebase/tick.h): the nearest
// tick to the decimal written, halves away from zero. Expectations are
// exact products worked by hand with 9,216,000 ticks per second.
#include <gtest/gtest.h>

#include <limits>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <type_traits>
#include <utility>

#include "config/config.h"
#include "plant/plant.h"
#include "scheduler/event_queue.h"
#include "scheduler/match.h"
#include "timebase/tick.h"
#include "trace/trace.h"
#include "vm/vm.h"

using namespace simbot;
using timebase::ticksFromSeconds;

namespace {

TEST(Timebase, OneClockEverywhere) {
  static_assert(timebase::kTicksPerSecond == 9'216'000);
  // The parts' names are using-declarations of the one constant.
  static_assert(vm::kTicksPerSecond == timebase::kTicksPerSecond);
  static_assert(plant::kTicksPerSecond == timebase::kTicksPerSecond);
  static_assert(scheduler::kTicksPerSecond == timebase::kTicksPerSecond);
  static_assert(std::is_same_v<vm::Tick, timebase::Tick>);
  static_assert(std::is_same_v<scheduler::Tick, timebase::Tick>);
  static_assert(std::is_same_v<trace::Tick, timebase::Tick>);
  static_assert(std::is_same_v<timebase::Tick, std::int64_t>);
}

TEST(Timebase, WholeAndDecimalSeconds) {
  EXPECT_EQ(ticksFromSeconds(0), 0);
  EXPECT_EQ(ticksFromSeconds(1), 9'216'000);
  EXPECT_EQ(ticksFromSeconds(180), 1'658'880'000);  // 180 * 9,216,000
  // 12.5 * 9,216,000 = 115,200,000 exactly.
  EXPECT_EQ(ticksFromSeconds(12.5), 115'200'000);
  // 0.043 * 9,216,000 = 396,288 exactly; the double 0.043 is a hair less
  // (0.04299999999999999656...), so truncating its product gave 396,287.
  EXPECT_EQ(ticksFromSeconds(0.043), 396'288);
  // 0.1 * 9,216,000 = 921,600; 0.8 s = 7,372,800; 1 ms = 9,216.
  EXPECT_EQ(ticksFromSeconds(0.1), 921'600);
  EXPECT_EQ(ticksFromSeconds(0.8), 7'372'800);
  EXPECT_EQ(ticksFromSeconds(0.001), 9'216);
  EXPECT_EQ(ticksFromSeconds(-12.5), -115'200'000);
}

TEST(Timebase, NearestTick) {
  // 1e-9 s = 0.009216 ticks -> 0.
  EXPECT_EQ(ticksFromSeconds(1e-9), 0);
  EXPECT_EQ(ticksFromSeconds(5e-324), 0);  // the smallest double
  // 1e-6 s = 9.216 ticks -> 9; 1e-7 s = 0.9216 -> 1.
  EXPECT_EQ(ticksFromSeconds(1e-6), 9);
  EXPECT_EQ(ticksFromSeconds(1e-7), 1);
  // 0.1234567 s = 1,137,776.9472 ticks -> 1,137,777.
  EXPECT_EQ(ticksFromSeconds(0.1234567), 1'137'777);
}

TEST(Timebase, HalfATickRoundsAwayFromZero) {
  // 2^-14 s = 9,216,000 / 16,384 = 562.5 ticks, exact in binary too.
  EXPECT_EQ(ticksFromSeconds(0.00006103515625), 563);
  EXPECT_EQ(ticksFromSeconds(-0.00006103515625), -563);
  // 4.39453125e-6 s = 9 / 2,048,000 s = 40.5 ticks. The double is a hair
  // below it (by about 2.7e-22 s), so rounding its binary product would
  // give 40; the decimal written is exactly half a tick past 40.
  EXPECT_EQ(ticksFromSeconds(4.39453125e-6), 41);
  EXPECT_EQ(ticksFromSeconds(-4.39453125e-6), -41);
  // 4.8828125e-7 s = 1 / 2,048,000 s = 4.5 ticks -> 5.
  EXPECT_EQ(ticksFromSeconds(4.8828125e-7), 5);
  // Below the half: 6.1e-5 s = 562.176 ticks -> 562.
  EXPECT_EQ(ticksFromSeconds(6.1e-5), 562);
}

TEST(Timebase, LargeValuesAndRefusals) {
  // 1e6 s (the commands' longest run) = 9,216,000,000,000 ticks.
  EXPECT_EQ(ticksFromSeconds(1e6), 9'216'000'000'000);
  // 1e11 s = 921,600,000,000,000,000 ticks: the largest accepted.
  EXPECT_EQ(ticksFromSeconds(1e11), 921'600'000'000'000'000);
  EXPECT_THROW(ticksFromSeconds(1.5e11), std::out_of_range);
  EXPECT_THROW(ticksFromSeconds(std::numeric_limits<double>::infinity()), std::out_of_range);
  EXPECT_THROW(ticksFromSeconds(std::numeric_limits<double>::quiet_NaN()), std::out_of_range);
}

TEST(Timebase, SecondsFromTicks) {
  EXPECT_EQ(timebase::secondsFromTicks(115'200'000), 12.5);
  EXPECT_EQ(timebase::secondsFromTicks(396'288), 0.043);  // the double nearest 0.043
  EXPECT_EQ(ticksFromSeconds(timebase::secondsFromTicks(123'456'789)), 123'456'789);
}

TEST(Timebase, DecimalsAsWritten) {
  using timebase::ticksFromDecimal;
  const auto ticks = [](std::string_view text, timebase::Tick unit) {
    const auto t = ticksFromDecimal(text, unit);
    return t ? std::optional(std::pair(t->ticks, t->exact)) : std::nullopt;
  };
  using P = std::pair<timebase::Tick, bool>;
  EXPECT_EQ(ticks("12.5", 9'216'000), P(115'200'000, true));  // 12.5 * 9,216,000
  EXPECT_EQ(ticks("1e-3", 9'216'000), P(9'216, true));
  EXPECT_EQ(ticks("0.001", 9'216'000), P(9'216, true));
  EXPECT_EQ(ticks("25E+2", 1), P(2'500, true));
  EXPECT_EQ(ticks(".5", 9'216), P(4'608, true));  // half a millisecond
  // Trailing zeros of a fraction are not significant digits: 23 digits.
  EXPECT_EQ(ticks("0.500000000000000000000", 9'216'000), P(4'608'000, true));
  // 1e-7 s = 0.9216 ticks -> 1; 4.5 ticks -> 5 (halves away from zero).
  EXPECT_EQ(ticks("1e-7", 9'216'000), P(1, false));
  EXPECT_EQ(ticks("4.5", 1), P(5, false));
  EXPECT_EQ(ticks("1e-400", 9'216'000), P(0, false));
  EXPECT_EQ(ticks("0e99", 1), P(0, true));
  // 1e11 s is the most; a tick more is refused.
  EXPECT_EQ(ticks("1e11", 9'216'000), P(921'600'000'000'000'000, true));
  EXPECT_EQ(ticks("921600000000000001", 1), std::nullopt);
  EXPECT_EQ(ticks("0.1234567890123456789", 9'216'000), std::nullopt);  // 19 significant
  for (const char* bad : {"", ".", "1.2.3", "-1", "+1", "1e", "1e+", "e5", "1s", "0x10", " 1"})
    EXPECT_EQ(ticks(bad, 1), std::nullopt) << bad;
}

TEST(Timebase, InjectionTimesAgreeWithTheConversion) {
  // An injection's WHEN is parsed as an exact decimal (a non-whole tick is
  // refused); a whole tick is the same tick ticksFromSeconds gives.
  EXPECT_EQ(config::parseInjection("A:edge_fore@12.5s", 1).tick, ticksFromSeconds(12.5));
  EXPECT_EQ(config::parseInjection("A:edge_fore@0.043s", 1).tick, 396'288);
  EXPECT_EQ(config::parseInjection("A:edge_fore@800ms", 1).tick, ticksFromSeconds(0.8));
  // The same decimals as --seconds: 1e-3 s = 9,216 ticks.
  EXPECT_EQ(config::parseInjection("A:edge_fore@1e-3s", 1).tick, ticksFromSeconds(1e-3));
  EXPECT_EQ(config::parseInjection("A:edge_fore@2.5E3t", 1).tick, 2'500);
  // 1e-7 s is 0.9216 ticks: an injection is at a tick, so it is refused.
  EXPECT_THROW(config::parseInjection("A:edge_fore@1e-7s", 1), std::invalid_argument);
  EXPECT_THROW(config::parseInjection("A:edge_fore@-1s", 1), std::invalid_argument);
}

}  // namespace
