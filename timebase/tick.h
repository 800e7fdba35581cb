// timebase/tick.h -- the whole interface of simbot's time base.
//
// One definition of time (DESIGN.md "Time and determinism"): ticks of the
// 9.216 MHz clock (one Z180 T-state) in a signed 64-bit integer, and the one
// conversion from a number of seconds the user wrote to ticks. Every part
// refers to these; nothing else defines the rate or converts seconds.
// (plant::eventTickFromSeconds is not a user's decimal: it places a root the
// integrator found, with a ceiling, on the clock defined here.)
#pragma once
#include <charconv>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace simbot::timebase {

using Tick = std::int64_t;
inline constexpr Tick kTicksPerSecond = 9'216'000;

// Beyond this ticksFromSeconds refuses: the tick count must fit a Tick with
// room to add to it (1e11 s is about 9.2e17 ticks; INT64_MAX is 9.2e18).
inline constexpr double kMaxSeconds = 1e11;

// The tick nearest to `seconds`, read as the decimal the user wrote: the
// shortest decimal that reads back as this double (what "0.043" is, not the
// binary fraction 0.04299999999999999656... it is stored as), multiplied by
// 9,216,000 exactly and rounded half away from zero. So 0.043 s is 396,288
// ticks (a truncating conversion gave 396,287), 4.8828125e-7 s (exactly 4.5
// ticks) is 5, and -4.8828125e-7 s is -5. Throws std::out_of_range for NaN,
// infinities and |seconds| > kMaxSeconds.
inline Tick ticksFromSeconds(double seconds) {
  if (!(std::fabs(seconds) <= kMaxSeconds))
    throw std::out_of_range("a time of " + std::to_string(seconds) +
                            " s is not a finite number of at most 1e11 s");
  // Shortest round-trip digits: "-d.ddddde-XX", at most 17 significant.
  char text[40];
  const auto written =
      std::to_chars(text, text + sizeof text, seconds, std::chars_format::scientific);
  const char* p = text;
  const bool negative = *p == '-';
  if (negative) ++p;
  std::int64_t mantissa = 0;  // < 1e17
  int digits = 0;
  for (; *p != 'e'; ++p) {
    if (*p == '.') continue;
    mantissa = mantissa * 10 + (*p - '0');
    ++digits;
  }
  int exponent = 0;
  std::from_chars(p + 1 + (p[1] == '+'), written.ptr, exponent);
  exponent -= digits - 1;  // seconds == mantissa * 10^exponent exactly
  // mantissa * 9,216,000 < 2^81: exact in 128 bits (a GCC/Clang extension).
  __extension__ typedef unsigned __int128 Wide;
  Wide ticks = static_cast<Wide>(mantissa) * static_cast<Wide>(kTicksPerSecond);
  if (exponent >= 0) {
    for (int i = 0; i < exponent; ++i) ticks *= 10;  // <= 1e11 s: fits
  } else if (exponent < -25) {
    ticks = 0;  // mantissa * 9,216,000 < 1e24: under a tenth of a tick
  } else {
    Wide divisor = 1;
    for (int i = 0; i < -exponent; ++i) divisor *= 10;
    const Wide remainder = ticks % divisor;
    ticks /= divisor;
    if (2 * remainder >= divisor) ++ticks;  // half away from zero (on |seconds|)
  }
  const auto magnitude = static_cast<Tick>(ticks);
  return negative ? -magnitude : magnitude;
}

// The double nearest to tick / 9,216,000.
inline double secondsFromTicks(Tick tick) {
  return static_cast<double>(tick) / static_cast<double>(kTicksPerSecond);
}

}  // namespace simbot::timebase
