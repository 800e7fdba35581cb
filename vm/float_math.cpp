// MATH.LIB in double from exact or correctly rounded steps only (see
// float_math.h). Series are summed by Horner's rule from the smallest
// term, after a reduction that keeps the argument small enough for the
// truncation error to be far below double's 1.1e-16:
//   sin, cos: x - k pi/2 by Cody and Waite's three-part pi/2, |r| <= pi/4,
//     Taylor to r^21 (truncation (pi/4)^23 / 23! < 1e-23);
//   atan: two half-angle steps atan(x) = 2 atan(x / (1 + sqrt(1 + x^2)))
//     after atan(x) = pi/2 - atan(1/x) for |x| > 1, |t| <= tan(pi/16) < 0.2,
//     series to t^39 (0.2^41 / 41 < 1e-30);
//   exp: x - k ln 2 by a two-part ln 2, |r| <= 0.35, Taylor to r^17,
//     scaled by 2^k exactly;
//   log: x = m 2^e with m in [sqrt(1/2), sqrt(2)), log m = 2 atanh(s),
//     s = (m - 1) / (m + 1), |s| < 0.172, series to s^33.
// Cody-Waite reduction is exact while k times pi/2's 33-bit leading part is
// exact: k below 2^20, |x| below about 1.6e6 (kExactReduction: 1e6). A
// larger argument is first reduced exactly (fmod) modulo the double nearest
// 2 pi: the result is bounded, the same bits everywhere, but no longer the
// true sine of so large an argument (that would need Payne and Hanek's
// reduction); a robot's angles are far smaller.
#include "vm/float_math.h"

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

namespace simbot::vm {

namespace {

constexpr double kPi = 3.14159265358979311600e+00;
constexpr double kPiOver2 = 1.57079632679489655800e+00;
// pi/2 in three parts, the first two with trailing zero bits (fdlibm's).
constexpr double kPiOver2Hi = 1.57079632673412561417e+00;
constexpr double kPiOver2Mid = 6.07710050630396597660e-11;
constexpr double kPiOver2Lo = 2.02226624879595063154e-21;
// ln 2 in two parts, the first with trailing zero bits (fdlibm's).
constexpr double kLn2Hi = 6.93147180369123816490e-01;
constexpr double kLn2Lo = 1.90821492927058770002e-10;
constexpr double kLn2 = 6.93147180559945286227e-01;
constexpr double kSqrtHalf = 7.07106781186547572737e-01;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// sin r and cos r for |r| <= pi/4: Taylor series by Horner's rule.
double sinSeries(double r) {
  const double z = r * r;
  double s = 0.0;
  for (int n = 21; n >= 3; n -= 2) s = (s + 1.0) * z / (-(n - 1.0) * n);
  return r + r * s;
}
double cosSeries(double r) {
  const double z = r * r;
  double s = 0.0;
  for (int n = 22; n >= 2; n -= 2) s = (s + 1.0) * z / (-(n - 1.0) * n);
  return 1.0 + s;
}

constexpr double kExactReduction = 1.0e6;

// x = k pi/2 + r: the quadrant k mod 4 and r.
int reduce(double x, double& r) {
  if (std::fabs(x) > kExactReduction) x = std::fmod(x, 2.0 * kPi);
  const double k = std::nearbyint(x / kPiOver2);
  r = ((x - k * kPiOver2Hi) - k * kPiOver2Mid) - k * kPiOver2Lo;
  return static_cast<int>(std::fmod(k, 4.0) + 4.0) % 4;
}

// sin(k pi/2 + r) by the quadrant k mod 4; cos x is sin of the next one.
double sinQuadrant(int q, double r) {
  switch (q % 4) {
    case 0:
      return sinSeries(r);
    case 1:
      return cosSeries(r);
    case 2:
      return -sinSeries(r);
    default:
      return -cosSeries(r);
  }
}

double sinD(double x) {
  double r;
  const int q = reduce(x, r);
  return sinQuadrant(q, r);
}

double cosD(double x) {
  double r;
  const int q = reduce(x, r);
  return sinQuadrant(q + 1, r);
}

// atan t for |t| <= 0.2: t - t^3/3 + t^5/5 - ...
double atanSeries(double t) {
  const double z = t * t;
  double s = 0.0;
  for (int n = 39; n >= 3; n -= 2) s = z * (1.0 / n - s);
  return t - t * s;
}

double atanD(double x) {
  if (std::isnan(x)) return x;
  if (std::isinf(x)) return x > 0 ? kPiOver2 : -kPiOver2;
  const bool invert = std::fabs(x) > 1.0;
  double t = invert ? 1.0 / x : x;
  for (int i = 0; i < 2; ++i) t = t / (1.0 + std::sqrt(1.0 + t * t));
  const double a = 4.0 * atanSeries(t);
  if (!invert) return a;
  return (x > 0 ? kPiOver2 : -kPiOver2) - a;
}

// C89 4.5.2.4: the principal value in [-pi, pi], by the signs of both.
double atan2D(double y, double x) {
  if (std::isnan(x) || std::isnan(y)) return kNaN;
  if (x == 0.0) {
    if (y == 0.0) return std::signbit(x) ? std::copysign(kPi, y) : std::copysign(0.0, y);
    return y > 0 ? kPiOver2 : -kPiOver2;
  }
  if (std::isinf(x) && std::isinf(y)) return std::copysign(x > 0 ? kPi / 4 : 3 * kPi / 4, y);
  const double a = atanD(std::fabs(y / x));
  const double q = x > 0 ? a : kPi - a;
  return std::copysign(q, y);
}

double expD(double x) {
  if (std::isnan(x)) return x;
  if (x > 710.0) return std::numeric_limits<double>::infinity();
  if (x < -750.0) return 0.0;
  const double k = std::nearbyint(x / kLn2);
  const double r = (x - k * kLn2Hi) - k * kLn2Lo;
  double s = 1.0;
  for (int n = 17; n >= 1; --n) s = 1.0 + s * r / n;
  return std::ldexp(s, static_cast<int>(k));
}

double logD(double x) {
  if (std::isnan(x) || x < 0.0) return kNaN;
  if (x == 0.0) return -std::numeric_limits<double>::infinity();
  if (std::isinf(x)) return x;
  int e;
  double m = std::frexp(x, &e);  // [0.5, 1)
  if (m < kSqrtHalf) {
    m *= 2.0;
    --e;
  }
  const double s = (m - 1.0) / (m + 1.0);
  const double z = s * s;
  double sum = 0.0;
  for (int n = 33; n >= 3; n -= 2) sum = z * (1.0 / n + sum);
  return e * kLn2 + 2.0 * (s + s * sum);
}

// C89 4.5.5.1 with the usual special cases: a negative base only to an
// integral power, 0 to a negative power is infinite.
double powD(double x, double y) {
  if (y == 0.0) return 1.0;
  if (std::isnan(x) || std::isnan(y)) return kNaN;
  if (x == 0.0) {
    const bool odd = std::fmod(std::fabs(y), 2.0) == 1.0;
    if (y < 0) return odd ? std::copysign(HUGE_VAL, x) : HUGE_VAL;
    return odd ? x : 0.0;
  }
  if (x < 0.0) {
    if (std::floor(y) != y) return kNaN;
    const double p = expD(y * logD(-x));
    return std::fmod(std::fabs(y), 2.0) == 1.0 ? -p : p;
  }
  return expD(y * logD(x));
}

// Rounded once to float. Past the largest float (or at its halfway point
// to the next power of two, a tie that rounds to even) the result is
// infinite, as IEEE rounding gives, without the undefined conversion; every
// NaN is the one quiet NaN 0x7FC00000, whose sign and payload would
// otherwise be the host processor's (negative on x86, positive on ARM).
float toFloat(double v) {
  if (std::isnan(v)) return std::bit_cast<float>(0x7FC00000u);
  if (std::fabs(v) >= 0x1.ffffffp127)
    return std::copysign(std::numeric_limits<float>::infinity(),
                         static_cast<float>(v > 0 ? 1 : -1));
  return static_cast<float>(v);
}

}  // namespace

float mathSqrt(float x) { return toFloat(std::sqrt(x)); }
float mathSin(float x) { return std::isfinite(x) ? toFloat(sinD(x)) : toFloat(kNaN); }
float mathCos(float x) { return std::isfinite(x) ? toFloat(cosD(x)) : toFloat(kNaN); }
float mathTan(float x) {
  if (!std::isfinite(x)) return toFloat(kNaN);
  double r;
  const int q = reduce(x, r);
  const double t = sinSeries(r) / cosSeries(r);
  return toFloat(q % 2 == 0 ? t : -1.0 / t);
}
float mathAtan(float x) { return toFloat(atanD(x)); }
float mathAtan2(float y, float x) { return toFloat(atan2D(y, x)); }
float mathAsin(float x) {
  if (!(std::fabs(x) <= 1.0f)) return toFloat(kNaN);
  const double d = x;
  return toFloat(atan2D(d, std::sqrt((1.0 - d) * (1.0 + d))));
}
float mathAcos(float x) {
  if (!(std::fabs(x) <= 1.0f)) return toFloat(kNaN);
  const double d = x;
  return toFloat(atan2D(std::sqrt((1.0 - d) * (1.0 + d)), d));
}
float mathExp(float x) { return toFloat(expD(x)); }
float mathLog(float x) { return toFloat(logD(x)); }
float mathPow(float x, float y) { return toFloat(powD(x, y)); }
float mathFloor(float x) { return toFloat(std::floor(x)); }
float mathCeil(float x) { return toFloat(std::ceil(x)); }
float mathFmod(float x, float y) { return toFloat(std::fmod(x, y)); }

}  // namespace simbot::vm
