// MATH.LIB's functions as the VM computes them: IEEE single in and out,
// the same bits on every machine.
//
// Each is worked in double from the float argument with the four
// operations, sqrt, and exact steps (frexp, ldexp, floor, nearbyint), which
// IEEE 754 defines to the bit, and never with the host's libm, whose last
// bit differs between libraries and versions. The double result, good to
// about 1e-15 relative, is rounded once to float: within one unit in the
// last place of the correctly rounded float, and equal to it but for
// values within 1e-15 of a halfway point. The build keeps every operation
// separate (-ffp-contract=off: no fused multiply-add).
#pragma once

namespace simbot::vm {

float mathSqrt(float x);
float mathSin(float x);
float mathCos(float x);
float mathTan(float x);
float mathAtan(float x);
float mathAtan2(float y, float x);
float mathAsin(float x);
float mathAcos(float x);
float mathExp(float x);
float mathLog(float x);
float mathPow(float x, float y);
float mathFloor(float x);
float mathCeil(float x);
float mathFmod(float x, float y);

}  // namespace simbot::vm
