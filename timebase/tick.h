// timebase/tick.h -- simbot's time base (with timebase/written.h, the
// grammar of a time a user writes and the limit on a run's length).
//
// One definition of time (DESIGN.md "Time and determinism"): ticks of the
// 9.216 MHz clock (one Z180 T-state) in a signed 64-bit integer, the one
// parser of the decimals a user writes for a time and the one conversion of
// seconds to ticks, and the times other layers share (the serial link's bit
// and character, the waveforms' picoseconds). Every part refers to these;
// nothing else defines the rate or converts seconds.
// (plant::eventTickFromSeconds is not a user's decimal: it places a root the
// integrator found, with a ceiling, on the clock defined here.)
#pragma once
#include <charconv>
#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace simbot::timebase {

using Tick = std::int64_t;
inline constexpr Tick kTicksPerSecond = 9'216'000;

// Beyond this ticksFromSeconds refuses: the tick count must fit a Tick with
// room to add to it (1e11 s is about 9.2e17 ticks; INT64_MAX is 9.2e18).
inline constexpr double kMaxSeconds = 1e11;

// A number of units of `ticksPerUnit` * 10^`scale` ticks written as a
// decimal ("12.5", "0.043", "1e-3", "25E+2"; digits, an optional point and
// fraction, an optional exponent; no sign), as ticks: the decimal is taken
// as written, multiplied exactly and rounded to the nearest tick, halves
// away from zero (`scale` -6 with a second's ticks is a microsecond,
// 9.216 ticks). `exact` says whether it was a whole number of ticks, and
// `roundedUp` whether `ticks` is above the value (so the two ticks nearest
// a value that is not whole are ticks - 1 and ticks, or ticks and ticks +
// 1). The one parser of durations: ticksFromSeconds and the grammar of a
// written time (timebase/written.h) come through it. nullopt if the text
// is not such a number, is more than kMaxSeconds' worth of ticks or has
// more than 18 significant digits, or if a unit is not between one tick
// and one second.
struct DecimalTicks {
  Tick ticks;
  bool exact;
  bool roundedUp = false;
};
inline std::optional<DecimalTicks> ticksFromDecimal(std::string_view text, Tick ticksPerUnit,
                                                    int scale = 0) {
  // text == mantissa * 10^exponent exactly, mantissa < 10^18. A fraction's
  // trailing zeros are not significant ("0.5000" is 5e-1).
  std::int64_t mantissa = 0;
  int significant = 0, exponent = 0;
  bool digits = false, point = false;
  std::size_t end = text.find_first_of("eE");
  if (end == std::string_view::npos) end = text.size();
  std::size_t last = end;
  if (text.substr(0, end).find('.') != std::string_view::npos)
    while (last > 0 && text[last - 1] == '0') --last, digits = true;
  std::size_t i = 0;
  for (; i < last; ++i) {
    const char c = text[i];
    if (c == '.' && !point) {
      point = true;
      continue;
    }
    if (c < '0' || c > '9') break;
    digits = true;
    if (mantissa == 0 && c == '0') {  // a leading zero: no significant digit
      if (point) --exponent;
      continue;
    }
    if (++significant > 18) return std::nullopt;
    mantissa = mantissa * 10 + (c - '0');
    if (point) --exponent;
  }
  if (!digits || i < last) return std::nullopt;
  i = end;
  if (i < text.size()) {  // the exponent: e or E, an optional sign, digits
    ++i;
    const bool negative = i < text.size() && text[i] == '-';
    if (i < text.size() && (text[i] == '-' || text[i] == '+')) ++i;
    int written = 0;
    const auto [stop, error] = std::from_chars(text.data() + i, text.data() + text.size(), written);
    if (error != std::errc() || stop != text.data() + text.size() || stop == text.data() + i ||
        written > 100'000)
      return std::nullopt;
    exponent += negative ? -written : written;
  }
  exponent += scale;
  if (mantissa == 0) return DecimalTicks{0, true};
  // mantissa * ticksPerUnit < 10^18 * 2^24 < 2^84: exact in 128 bits (a
  // GCC/Clang extension); a run never needs more than kMaxTicks.
  __extension__ typedef unsigned __int128 Wide;
  constexpr auto kMaxTicks = static_cast<Wide>(kMaxSeconds) * kTicksPerSecond;
  if (ticksPerUnit <= 0 || ticksPerUnit > kTicksPerSecond) return std::nullopt;
  Wide ticks = static_cast<Wide>(mantissa) * static_cast<Wide>(ticksPerUnit);
  bool exact = true, roundedUp = false;
  if (exponent >= 0) {
    for (int k = 0; k < exponent; ++k)
      if ((ticks *= 10) > kMaxTicks) return std::nullopt;
  } else if (exponent < -26) {
    return DecimalTicks{0, false, false};  // ticks < 10^25 / 10^27: under a hundredth of a tick
  } else {
    Wide divisor = 1;
    for (int k = 0; k < -exponent; ++k) divisor *= 10;
    const Wide remainder = ticks % divisor;
    ticks /= divisor;
    exact = remainder == 0;
    roundedUp = 2 * remainder >= divisor;  // halves away from zero
    if (roundedUp) ++ticks;
  }
  if (ticks > kMaxTicks) return std::nullopt;
  return DecimalTicks{static_cast<Tick>(ticks), exact, roundedUp};
}

// The tick nearest to `seconds`, read as the decimal the user wrote: the
// shortest decimal that reads back as this double (what "0.043" is, not the
// binary fraction 0.04299999999999999656... it is stored as), through
// ticksFromDecimal. So 0.043 s is 396,288 ticks (a truncating conversion
// gave 396,287), 4.8828125e-7 s (exactly 4.5 ticks) is 5, and
// -4.8828125e-7 s is -5. Throws std::out_of_range for NaN, infinities and
// |seconds| > kMaxSeconds.
inline Tick ticksFromSeconds(double seconds) {
  if (!(std::fabs(seconds) <= kMaxSeconds))
    throw std::out_of_range("a time of " + std::to_string(seconds) +
                            " s is not a finite number of at most 1e11 s");
  // Shortest round-trip digits: "-d.ddddde-XX", at most 17 significant.
  char text[40];
  const auto written =
      std::to_chars(text, text + sizeof text, seconds, std::chars_format::scientific);
  const bool negative = text[0] == '-';
  const std::string_view digits(text + negative,
                                static_cast<std::size_t>(written.ptr - text) - negative);
  const Tick magnitude = ticksFromDecimal(digits, kTicksPerSecond)->ticks;  // in range: checked
  return negative ? -magnitude : magnitude;
}

// The double nearest to tick / 9,216,000.
inline double secondsFromTicks(Tick tick) {
  return static_cast<double>(tick) / static_cast<double>(kTicksPerSecond);
}

// The robots' serial link (DESIGN.md "Serial link"): 9600 baud, 8N1 (a
// start bit, eight data bits, a stop bit), on this clock exactly 960 ticks
// a bit and 9,600 a character.
inline constexpr Tick kSerialBaud = 9'600;
inline constexpr Tick kTicksPerBit = kTicksPerSecond / kSerialBaud;
static_assert(kTicksPerBit * kSerialBaud == kTicksPerSecond, "a bit is a whole number of ticks");
inline constexpr Tick kBitsPerChar = 10;
inline constexpr Tick kTicksPerChar = kBitsPerChar * kTicksPerBit;

// Tick t in picoseconds (the waveforms' time scale), to the nearest one,
// halves up: 1e12 / 9,216,000 = 1,953,125 / 18 exactly, split so that
// nothing overflows for any tick of a run.
inline constexpr std::int64_t kPicosecondsPerSecond = 1'000'000'000'000;
inline constexpr std::int64_t picosecondsFromTicks(Tick tick) {
  constexpr std::int64_t kNumerator = 1'953'125, kDenominator = 18;
  static_assert(kNumerator * kTicksPerSecond == kPicosecondsPerSecond * kDenominator);
  const std::int64_t q = tick / kDenominator, r = tick % kDenominator;
  return q * kNumerator + (r * kNumerator + kDenominator / 2) / kDenominator;
}

}  // namespace simbot::timebase
