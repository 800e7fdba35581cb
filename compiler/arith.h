// The arithmetic types of Dynamic C on the Z180 and C89's rules over them,
// with this target's sizes: char 8 bits unsigned, signed char 8, int (and
// short) 16, long 32, float IEEE single. The compiler's type rules
// (types.cpp: promotions, the usual conversions, constant folding;
// parse_expr.cpp: the types of constants; parse_decl.cpp: the type words)
// and the debugger's expressions (inspect/) both use them, so the debugger
// computes what the robot's code would. Header-only, so that inspect/
// needs nothing else of the compiler.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>

namespace simbot::compiler {

enum class Arith : uint8_t { Char, SChar, Int, UInt, Long, ULong, Float };

constexpr int arithSize(Arith a) {
  switch (a) {
    case Arith::Char:
    case Arith::SChar:
      return 1;
    case Arith::Int:
    case Arith::UInt:
      return 2;
    default:
      return 4;
  }
}

constexpr bool arithUnsigned(Arith a) {
  return a == Arith::Char || a == Arith::UInt || a == Arith::ULong;
}

// The integer promotions: both chars become int (an int holds every value
// of either).
constexpr Arith promoteArith(Arith a) {
  return a == Arith::Char || a == Arith::SChar ? Arith::Int : a;
}

// The usual arithmetic conversions (C89 3.2.1.5). A long holds every
// unsigned int, so long and unsigned int meet in long.
constexpr Arith commonArith(Arith a, Arith b) {
  a = promoteArith(a);
  b = promoteArith(b);
  if (a == Arith::Float || b == Arith::Float) return Arith::Float;
  if (a == Arith::ULong || b == Arith::ULong) return Arith::ULong;
  if (a == Arith::Long || b == Arith::Long) return Arith::Long;
  if (a == Arith::UInt || b == Arith::UInt) return Arith::UInt;
  return Arith::Int;
}

// An integer as an object of integer type `a` holds it: the low bits, two's
// complement for the signed types (so int 32768 is -32768).
constexpr int64_t wrapArith(int64_t v, Arith a) {
  const auto u = static_cast<uint64_t>(v);
  switch (a) {
    case Arith::Char:
      return static_cast<int64_t>(u & 0xFF);
    case Arith::SChar:
      return static_cast<int8_t>(static_cast<uint8_t>(u & 0xFF));
    case Arith::Int:
      return static_cast<int16_t>(static_cast<uint16_t>(u & 0xFFFF));
    case Arith::UInt:
      return static_cast<int64_t>(u & 0xFFFF);
    case Arith::Long:
      return static_cast<int32_t>(static_cast<uint32_t>(u & 0xFFFFFFFF));
    default:
      return static_cast<int64_t>(u & 0xFFFFFFFF);
  }
}

// The type of an integer constant (at most 0xFFFFFFFF) with its suffixes:
// unsuffixed decimal the first of int, long, unsigned long that holds it;
// hex and octal the first of int, unsigned int, long, unsigned long.
constexpr Arith constantArith(uint64_t x, bool decimal, bool suffixU, bool suffixL) {
  if (suffixU && suffixL) return Arith::ULong;
  if (suffixU) return x <= 0xFFFF ? Arith::UInt : Arith::ULong;
  if (suffixL) return x <= 0x7FFFFFFF ? Arith::Long : Arith::ULong;
  if (decimal) return x <= 0x7FFF ? Arith::Int : x <= 0x7FFFFFFF ? Arith::Long : Arith::ULong;
  return x <= 0x7FFF       ? Arith::Int
         : x <= 0xFFFF     ? Arith::UInt
         : x <= 0x7FFFFFFF ? Arith::Long
                           : Arith::ULong;
}

// A float converted to an integer type as the VM's F2W, F2L and F2UL do:
// truncated toward zero, NaN as 0, held to long's range (unsigned long's
// for unsigned long), then the low bits the type keeps.
inline int64_t floatToInteger(float f, Arith to) {
  if (std::isnan(f)) return 0;
  const double hi = to == Arith::ULong ? 4294967295.0 : 2147483647.0;
  const double t = std::clamp(std::trunc(static_cast<double>(f)), -2147483648.0, hi);
  return wrapArith(static_cast<int64_t>(t), to);
}

// The shifts as the Z180 code runs them (vm/instructions.h: SHLW, SHRW,
// SHRUW and the 32-bit ones): a loop of one-bit shifts counted by the
// count's low byte, so a count of 16 or more (32 for a long) leaves 0, or
// the sign for a signed right shift, and a negative count is a large one.
// `v` is a value of the promoted type `a`, `count` the count as an int.
constexpr int64_t shiftLeft(int64_t v, int64_t count, Arith a) {
  const auto n = static_cast<unsigned>(static_cast<uint64_t>(count) & 0xFF);
  const unsigned bits = arithSize(a) * 8u;
  if (n >= bits) return 0;
  return wrapArith(static_cast<int64_t>(static_cast<uint64_t>(v) << n), a);
}
constexpr int64_t shiftRight(int64_t v, int64_t count, Arith a) {
  const auto n = static_cast<unsigned>(static_cast<uint64_t>(count) & 0xFF);
  const unsigned bits = arithSize(a) * 8u;
  if (arithUnsigned(a)) return n >= bits ? 0 : wrapArith(v, a) >> n;
  return wrapArith(v, a) >> std::min(n, bits - 1);
}

// Division and remainder of two values of the integer type `a` (b != 0),
// truncating toward zero; INT_MIN / -1 wraps to INT_MIN, as the VM's does.
constexpr int64_t divideArith(int64_t a, int64_t b, Arith t) { return wrapArith(a / b, t); }
constexpr int64_t remainderArith(int64_t a, int64_t b, Arith t) { return wrapArith(a % b, t); }

// The type words of a declaration, counted as the compiler's declspec
// does: each of void, char, short, int, long, float, double adds its bit
// (so "long long" would carry into the next), signed and unsigned or in.
namespace typeword {
inline constexpr int kVoid = 1 << 0;
inline constexpr int kChar = 1 << 2;
inline constexpr int kShort = 1 << 4;
inline constexpr int kInt = 1 << 6;
inline constexpr int kLong = 1 << 8;
inline constexpr int kFloat = 1 << 10;
inline constexpr int kDouble = 1 << 12;
inline constexpr int kOther = 1 << 14;  // a struct, union, enum or typedef name
inline constexpr int kSigned = 1 << 16;
inline constexpr int kUnsigned = 1 << 18;
}  // namespace typeword

// The arithmetic type a count of type words names ("unsigned" is unsigned
// int, "long double" float, "short" int); none for void or a combination C
// does not have.
constexpr std::optional<Arith> typeWordsArith(int counter) {
  using namespace typeword;
  switch (counter) {
    case kChar:
    case kUnsigned + kChar:
      return Arith::Char;
    case kSigned + kChar:
      return Arith::SChar;
    case kShort:
    case kShort + kInt:
    case kSigned + kShort:
    case kSigned + kShort + kInt:
    case kInt:
    case kSigned:
    case kSigned + kInt:
      return Arith::Int;
    case kUnsigned + kShort:
    case kUnsigned + kShort + kInt:
    case kUnsigned:
    case kUnsigned + kInt:
      return Arith::UInt;
    case kLong:
    case kLong + kInt:
    case kSigned + kLong:
    case kSigned + kLong + kInt:
      return Arith::Long;
    case kUnsigned + kLong:
    case kUnsigned + kLong + kInt:
      return Arith::ULong;
    case kFloat:
    case kDouble:
    case kLong + kDouble:
      return Arith::Float;
    default:
      return std::nullopt;
  }
}

}  // namespace simbot::compiler
