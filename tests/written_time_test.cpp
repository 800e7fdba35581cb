// The one grammar of a written time (timebase/written.h). Every expected
// tick is worked by hand from 9,216,000 ticks a second (9,216 a
// millisecond, 9.216 a microsecond), and every refusal names the two ticks
// either side of the value, also worked by hand.
#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <string_view>

#include "timebase/written.h"

using namespace simbot::timebase;

namespace {

// The message parseTime refuses `text` with ("" if it is accepted).
std::string refusal(std::string_view text, BareNumber bare) {
  try {
    parseTime(text, bare);
  } catch (const TimeError& e) {
    return e.what();
  }
  return "";
}

TEST(WrittenTime, EveryUnit) {
  for (const BareNumber bare : {BareNumber::Seconds, BareNumber::Ticks, BareNumber::Refused}) {
    EXPECT_EQ(parseTime("12.5s", bare), 115'200'000);  // 12.5 * 9,216,000
    EXPECT_EQ(parseTime("1e-3s", bare), 9'216);
    EXPECT_EQ(parseTime("800ms", bare), 7'372'800);  // 800 * 9,216
    EXPECT_EQ(parseTime("0.5ms", bare), 4'608);      // 9,216 / 2
    EXPECT_EQ(parseTime("1e3ms", bare), 9'216'000);  // one second
    EXPECT_EQ(parseTime("125us", bare), 1'152);      // 125 * 9.216 = 1,152 exactly
    EXPECT_EQ(parseTime("1.5e3us", bare), 13'824);   // 1.5 ms = 1.5 * 9,216
    EXPECT_EQ(parseTime("9216t", bare), 9'216);
    EXPECT_EQ(parseTime("2.5E3t", bare), 2'500);
    EXPECT_EQ(parseTime("0s", bare), 0);
    EXPECT_EQ(parseTime("1e11s", bare), 921'600'000'000'000'000);  // the most: 1e11 s
  }
}

TEST(WrittenTime, BareNumbers) {
  EXPECT_EQ(parseTime("60", BareNumber::Seconds), 552'960'000);  // 60 * 9,216,000
  EXPECT_EQ(parseTime("0.043", BareNumber::Seconds), 396'288);   // 43 * 9,216
  EXPECT_EQ(parseTime("60", BareNumber::Ticks), 60);
  EXPECT_EQ(parseTime("115200000", BareNumber::Ticks), 115'200'000);
  EXPECT_EQ(refusal("60", BareNumber::Refused),
            "'60' is not a time (write 12.5s, 800ms, 300us or 115200000t, at most 1e11 s)");
  EXPECT_EQ(refusal("x", BareNumber::Seconds),
            "'x' is not a time (write 12.5s, 800ms, 300us or 115200000t, at most 1e11 s; a "
            "number alone is seconds)");
}

TEST(WrittenTime, BetweenTwoTicksIsRefusedNamingBoth) {
  // 300 us * 9.216 = 2,764.8 ticks.
  EXPECT_EQ(refusal("300us", BareNumber::Ticks),
            "'300us' is not a whole number of ticks of the 9.216 MHz clock: the nearest are "
            "2764t and 2765t");
  // 0.0001 s * 9,216,000 = 921.6 ticks (the debugger's break rounded it to 922).
  EXPECT_NE(refusal("0.0001s", BareNumber::Refused).find("921t and 922t"), std::string::npos);
  // 0.00006103515625 s = 562.5 ticks exactly: a half is not a tick either.
  EXPECT_NE(refusal("0.00006103515625", BareNumber::Seconds).find("562t and 563t"),
            std::string::npos);
  // 1e-7 s = 0.9216 ticks; 1e-12 s = 0.000009216 ticks; 1e-400 s below 0.01.
  EXPECT_NE(refusal("1e-7s", BareNumber::Seconds).find("0t and 1t"), std::string::npos);
  EXPECT_NE(refusal("1e-12", BareNumber::Seconds).find("0t and 1t"), std::string::npos);
  EXPECT_NE(refusal("1e-400s", BareNumber::Seconds).find("0t and 1t"), std::string::npos);
  // 2.5 ticks; 0.1 ms = 921.6 ticks.
  EXPECT_NE(refusal("2.5t", BareNumber::Ticks).find("2t and 3t"), std::string::npos);
  EXPECT_NE(refusal("0.1ms", BareNumber::Ticks).find("921t and 922t"), std::string::npos);
  // 1 us = 9.216 ticks: rounded down to 9 it was, and still is not a tick.
  EXPECT_NE(refusal("1us", BareNumber::Ticks).find("9t and 10t"), std::string::npos);
  // 7 us = 64.512 ticks, 8 us = 73.728 (rounded up, so the nearest is above).
  EXPECT_NE(refusal("8us", BareNumber::Ticks).find("73t and 74t"), std::string::npos);
}

TEST(WrittenTime, NotTimes) {
  for (const char* bad : {"", "s", "ms", "t", "-1s", "+1s", "1 s", "12.5S", "1e", "1es", "5m",
                          "0x10t", "1.2.3s", "1e12s", "1.5min", "inf", "nan"})
    EXPECT_NE(refusal(bad, BareNumber::Seconds).find("is not a time"), std::string::npos) << bad;
}

TEST(WrittenTime, SecondsAsNumbers) {
  // A TOML, JSON or Python number: the decimal it is written as.
  EXPECT_EQ(parseSeconds(0.043), 396'288);
  EXPECT_EQ(parseSeconds(45), 414'720'000);  // 45 * 9,216,000
  EXPECT_EQ(parseSeconds(1e6), 9'216'000'000'000);
  EXPECT_THROW(parseSeconds(0.0001), TimeError);  // 921.6 ticks
  EXPECT_THROW(parseSeconds(-1), TimeError);
  EXPECT_THROW(parseSeconds(std::numeric_limits<double>::quiet_NaN()), TimeError);
  EXPECT_THROW(parseSeconds(std::numeric_limits<double>::infinity()), TimeError);
}

TEST(WrittenTime, OneRunLengthLimit) {
  static_assert(kMaxRunTicks == 9'216'000'000'000);  // 1e6 s
  EXPECT_EQ(parseRunLength("1e6"), 9'216'000'000'000);
  EXPECT_EQ(parseRunLength("9216000000000t"), 9'216'000'000'000);
  EXPECT_EQ(parseRunLength("1t"), 1);
  EXPECT_EQ(parseRunLength("300ms"), 2'764'800);
  EXPECT_THROW(parseRunLength("9216000000001t"), TimeError);
  EXPECT_THROW(parseRunLength("2e6"), TimeError);
  std::string message;
  try {
    parseRunLength("0");
  } catch (const TimeError& e) {
    message = e.what();
  }
  EXPECT_EQ(message, "'0' is not a run's length: more than 0 s and at most 1e6 s (9216000000000t)");
}

}  // namespace
