// MATH.LIB's accuracy (vm/float_math.h) against an independent oracle: the
// host C library's double functions, rounded once to float. glibc's double
// results are within one double ulp, so rounded to float they are the
// correctly rounded float but for arguments within about 1e-16 of a
// halfway point; float_math.h promises at most one float ulp from that.
// Each function is swept over a grid of its domain (a few hundred thousand
// floats, exponents spread evenly) and the largest distance in ulps must
// be at most 1. The program-level check, against Python's math module on
// chosen arguments, bit for bit, is tests/programs/math_lib.dc.
#include "vm/float_math.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>

namespace {

// Distance in units in the last place between two finite floats of the
// same sign (or both zero); NaN against NaN is 0, a NaN against a number
// is "infinitely" far.
int64_t ulps(float a, float b) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b) ? 0 : INT64_MAX;
  const auto key = [](float f) {
    const auto u = static_cast<int64_t>(std::bit_cast<uint32_t>(f));
    return u & 0x80000000 ? -(u & 0x7FFFFFFF) : u;  // monotonic in f
  };
  const int64_t d = key(a) - key(b);
  return d < 0 ? -d : d;
}

struct Sweep {
  int64_t worst = 0;
  float worstAt = 0;
  int64_t off = 0;  // results not the oracle's exactly
  int64_t n = 0;
};

// Floats from lo to hi (same sign or spanning 0), `count` of them spread
// evenly over the bit patterns, so that every binade gets its share.
template <class F, class Oracle>
Sweep sweep(float lo, float hi, int count, F f, Oracle oracle) {
  Sweep s;
  const auto key = [](float v) {
    const auto u = static_cast<int64_t>(std::bit_cast<uint32_t>(v));
    return u & 0x80000000 ? -(u & 0x7FFFFFFF) : u;
  };
  const auto unkey = [](int64_t k) {
    return std::bit_cast<float>(static_cast<uint32_t>(k < 0 ? (-k) | 0x80000000 : k));
  };
  const int64_t a = key(lo), b = key(hi);
  for (int i = 0; i <= count; ++i) {
    const float x = unkey(a + (b - a) * i / count);
    const float got = f(x);
    const auto want = static_cast<float>(oracle(static_cast<double>(x)));
    const int64_t d = ulps(got, want);
    ++s.n;
    if (d != 0) ++s.off;
    if (d > s.worst) {
      s.worst = d;
      s.worstAt = x;
    }
  }
  return s;
}

void expectWithinOneUlp(const std::string& name, const Sweep& s) {
  EXPECT_LE(s.worst, 1) << name << ": " << s.worst << " ulps at " << s.worstAt;
  ::testing::Test::RecordProperty(name + "_off_by_one",
                                  std::to_string(s.off) + " of " + std::to_string(s.n));
  std::printf("%-8s %6lld of %lld a ulp from the rounded oracle\n", name.c_str(),
              static_cast<long long>(s.off), static_cast<long long>(s.n));
}

constexpr int kCount = 200000;

TEST(FloatMath, OneArgumentFunctionsWithinOneUlpOfTheRoundedOracle) {
  using simbot::vm::mathAcos, simbot::vm::mathAsin, simbot::vm::mathAtan, simbot::vm::mathCeil,
      simbot::vm::mathCos, simbot::vm::mathExp, simbot::vm::mathFloor, simbot::vm::mathLog,
      simbot::vm::mathSin, simbot::vm::mathSqrt, simbot::vm::mathTan;
  const auto d = [](double (*g)(double)) { return g; };
  expectWithinOneUlp("sqrt", sweep(0.0f, 3e38f, kCount, mathSqrt, d(std::sqrt)));
  // A robot's angles: sin, cos and tan over +-10,000 radians.
  expectWithinOneUlp("sin", sweep(-1e4f, 1e4f, kCount, mathSin, d(std::sin)));
  expectWithinOneUlp("cos", sweep(-1e4f, 1e4f, kCount, mathCos, d(std::cos)));
  expectWithinOneUlp("tan", sweep(-1e4f, 1e4f, kCount, mathTan, d(std::tan)));
  expectWithinOneUlp("atan", sweep(-3e38f, 3e38f, kCount, mathAtan, d(std::atan)));
  expectWithinOneUlp("asin", sweep(-1.0f, 1.0f, kCount, mathAsin, d(std::asin)));
  expectWithinOneUlp("acos", sweep(-1.0f, 1.0f, kCount, mathAcos, d(std::acos)));
  expectWithinOneUlp("exp", sweep(-103.0f, 88.7f, kCount, mathExp, d(std::exp)));
  expectWithinOneUlp("log", sweep(1e-38f, 3e38f, kCount, mathLog, d(std::log)));
  expectWithinOneUlp("floor", sweep(-1e9f, 1e9f, kCount, mathFloor, d(std::floor)));
  expectWithinOneUlp("ceil", sweep(-1e9f, 1e9f, kCount, mathCeil, d(std::ceil)));
}

TEST(FloatMath, TwoArgumentFunctionsWithinOneUlpOfTheRoundedOracle) {
  using simbot::vm::mathAtan2, simbot::vm::mathFmod, simbot::vm::mathPow;
  // atan2 around the whole circle: y from a sweep, x = 1 - y / 3 (all
  // four quadrants, and |y/x| from tiny to huge).
  expectWithinOneUlp(
      "atan2", sweep(
                   -1e4f, 1e4f, kCount, [](float y) { return mathAtan2(y, 1.0f - y / 3.0f); },
                   [](double y) {
                     return std::atan2(y, static_cast<double>(1.0f - static_cast<float>(y) / 3.0f));
                   }));
  expectWithinOneUlp("pow", sweep(
                                1e-3f, 1e3f, kCount, [](float x) { return mathPow(x, 2.5f); },
                                [](double x) { return std::pow(x, 2.5); }));
  expectWithinOneUlp("pow-int", sweep(
                                    -50.0f, 50.0f, kCount, [](float x) { return mathPow(x, 7.0f); },
                                    [](double x) { return std::pow(x, 7.0); }));
  expectWithinOneUlp("fmod", sweep(
                                 -1e6f, 1e6f, kCount, [](float x) { return mathFmod(x, 0.7f); },
                                 [](double x) { return std::fmod(x, static_cast<double>(0.7f)); }));
}

// The special values C89 and IEEE give, and one NaN for all domain errors.
TEST(FloatMath, SpecialValues) {
  using namespace simbot::vm;
  const float inf = INFINITY;
  const auto b = [](float f) { return std::bit_cast<uint32_t>(f); };
  EXPECT_EQ(b(mathSqrt(-1.0f)), 0x7FC00000u);
  EXPECT_EQ(b(mathLog(-1.0f)), 0x7FC00000u);
  EXPECT_EQ(b(mathAsin(1.5f)), 0x7FC00000u);
  EXPECT_EQ(b(mathFmod(1.0f, 0.0f)), 0x7FC00000u);
  EXPECT_EQ(b(mathPow(-8.0f, 1.0f / 3.0f)), 0x7FC00000u);
  EXPECT_EQ(b(mathSin(inf)), 0x7FC00000u);
  EXPECT_EQ(mathLog(0.0f), -inf);
  EXPECT_EQ(mathExp(89.0f), inf);
  EXPECT_EQ(mathExp(-200.0f), 0.0f);
  EXPECT_EQ(mathPow(0.0f, -1.0f), inf);
  EXPECT_EQ(mathPow(5.0f, 0.0f), 1.0f);
  EXPECT_EQ(mathAtan2(0.0f, -1.0f), static_cast<float>(M_PI));
  EXPECT_EQ(mathAtan2(-0.0f, 1.0f), -0.0f);
  EXPECT_TRUE(std::signbit(mathAtan2(-0.0f, 1.0f)));
  EXPECT_EQ(mathAtan(inf), static_cast<float>(M_PI / 2));
  EXPECT_EQ(mathSqrt(0.25f), 0.5f);
  // Past exact reduction (|x| > 1e6) the result stays a sine's: bounded.
  for (const float big : {2e6f, 1e16f, 1e20f, 3e38f, -3e38f}) {
    EXPECT_LE(std::fabs(mathSin(big)), 1.0f) << big;
    EXPECT_LE(std::fabs(mathCos(big)), 1.0f) << big;
    EXPECT_TRUE(std::isfinite(mathTan(big))) << big;
  }
  EXPECT_EQ(mathPow(2.0f, 10.0f), 1024.0f);
}

}  // namespace
