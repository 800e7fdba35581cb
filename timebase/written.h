// timebase/written.h -- the one grammar of a time a user writes, and the
// one limit on a run's length.
//
// Every time written in text comes through parseTime: --seconds and
// --inject, a scenario file's times, the debugger's break, advance, goto
// and until, and the Debug Adapter's goto. A time is a decimal (as
// ticksFromDecimal reads it: digits, an optional point and fraction, an
// optional exponent, no sign) and a unit:
//   s   seconds        12.5s, 1e-3s
//   ms  milliseconds   800ms, 0.5ms
//   us  microseconds   300us is 2,764.8 ticks, so refused
//   t   ticks          115200000t, 2.5E3t
// A number with no unit means what it always meant where it is written
// (BareNumber). Nothing is rounded: everything happens at a tick, so a
// time between two ticks is refused with the two nearest named.
#pragma once
#include <array>
#include <charconv>
#include <stdexcept>
#include <string>
#include <string_view>

#include "timebase/tick.h"

namespace simbot::timebase {

// A written time that is not one: what() is one line quoting the text
// (callers put the option, or FILE:LINE:COL, in front).
class TimeError : public std::invalid_argument {
 public:
  // NotATime: not in the grammar at all (a caller with other forms, such
  // as --inject's line:N#K, says so instead).
  enum class Kind { NotATime, BetweenTicks, RunLength };
  TimeError(Kind kind, const std::string& message) : std::invalid_argument(message), kind_(kind) {}
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

// What a number written without a unit is, where it is written.
enum class BareNumber {
  Seconds,  // --seconds 60, a scenario's seconds = 45 (a TOML number)
  Ticks,    // the debugger's goto 115200000, advance 9216
  Refused,  // --inject's WHEN, where 12.5 alone was never a time
};

namespace written {
// The units, longest suffix first ("ms" before "s"), and each one's
// ticks as kTicksPerSecond * 10^scale or 1 * 10^0.
struct Unit {
  std::string_view suffix;
  Tick ticksPerUnit;
  int scale;
};
inline constexpr std::array<Unit, 4> kUnits = {{{"ms", kTicksPerSecond, -3},
                                                {"us", kTicksPerSecond, -6},
                                                {"s", kTicksPerSecond, 0},
                                                {"t", 1, 0}}};

inline std::string quoted(std::string_view text) { return "'" + std::string(text) + "'"; }

// The shortest decimal that reads back as `seconds`, as %g writes it
// (0.0001, 1e-05, 2e+06): what the user most likely wrote.
struct Shortest {
  char text[40];
  std::size_t size;
  std::string_view view() const { return {text, size}; }
};
inline Shortest shortest(double seconds) {
  Shortest s{};
  const auto end =
      std::to_chars(s.text, s.text + sizeof s.text, seconds, std::chars_format::general);
  s.size = static_cast<std::size_t>(end.ptr - s.text);
  return s;
}
}  // namespace written

// The tick `text` names (see above). TimeError if it is no time, more
// than 1e11 s, or not a whole number of ticks ("'300us' is 2764.8 ticks:
// ... write 2764t or 2765t").
inline Tick parseTime(std::string_view text, BareNumber bare) {
  std::string_view digits = text;
  Tick ticksPerUnit = bare == BareNumber::Ticks ? 1 : kTicksPerSecond;
  int scale = 0;
  bool unit = false;
  for (const auto& u : written::kUnits)
    if (text.size() > u.suffix.size() && text.substr(text.size() - u.suffix.size()) == u.suffix) {
      digits = text.substr(0, text.size() - u.suffix.size());
      ticksPerUnit = u.ticksPerUnit;
      scale = u.scale;
      unit = true;
      break;
    }
  const char* bareMeans = bare == BareNumber::Seconds ? "; a number alone is seconds"
                          : bare == BareNumber::Ticks ? "; a number alone is ticks"
                                                      : "";
  const auto ticks = timebase::ticksFromDecimal(digits, ticksPerUnit, scale);
  if (!ticks || (!unit && bare == BareNumber::Refused))
    throw TimeError(TimeError::Kind::NotATime,
                    written::quoted(text) +
                        " is not a time (write 12.5s, 800ms, 300us or 115200000t, at most 1e11 s" +
                        bareMeans + ")");
  if (!ticks->exact) {
    const Tick below = ticks->roundedUp ? ticks->ticks - 1 : ticks->ticks;
    throw TimeError(TimeError::Kind::BetweenTicks,
                    written::quoted(text) +
                        " is not a whole number of ticks of the 9.216 MHz clock: the nearest are " +
                        std::to_string(below) + "t and " + std::to_string(below + 1) + "t");
  }
  return ticks->ticks;
}

// A time given as a number of seconds (a TOML or JSON number, a Python
// float): the shortest decimal that reads back as the double (0.043, not
// 0.04299999999999999656...), read by parseTime. TimeError for a negative,
// NaN or infinite number too.
inline Tick parseSeconds(double seconds) {
  return parseTime(written::shortest(seconds).view(), BareNumber::Seconds);
}

// The longest run any command plays: 1e6 s (11.6 days) of simulated time,
// far past any match (180 s) and any soak test, and far inside what a
// Tick holds. Every run length (--seconds, a scenario's or sweep's
// seconds, a profile's round_length) is checked against this one limit.
inline constexpr double kMaxRunSeconds = 1e6;
inline constexpr Tick kMaxRunTicks = static_cast<Tick>(kMaxRunSeconds) * kTicksPerSecond;

// `ticks` as a run's length, written as `text`: TimeError unless it is
// more than 0 and at most kMaxRunTicks.
inline Tick checkRunLength(Tick ticks, std::string_view text) {
  if (ticks <= 0 || ticks > kMaxRunTicks)
    throw TimeError(TimeError::Kind::RunLength,
                    written::quoted(text) +
                        " is not a run's length: more than 0 s and at most 1e6 s (" +
                        std::to_string(kMaxRunTicks) + "t)");
  return ticks;
}

// A run's length written as text (--seconds): parseTime, bare numbers
// seconds, then checkRunLength.
inline Tick parseRunLength(std::string_view text) {
  return checkRunLength(parseTime(text, BareNumber::Seconds), text);
}

// A run's length given as a number of seconds (a batch's configuration):
// parseSeconds, then checkRunLength.
inline Tick runLengthFromSeconds(double seconds) {
  const auto decimal = written::shortest(seconds);
  return checkRunLength(parseTime(decimal.view(), BareNumber::Seconds), decimal.view());
}

}  // namespace simbot::timebase
