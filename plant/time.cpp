// plant/time.cpp -- conversions between integer ticks and ARKODE's seconds.
//
// DESIGN.md: an event found by the integrator at t seconds happens at tick
// ceil(t * 9,216,000). The rounded double product t * N can sit on the wrong
// side of an integer (t = k/N rounded up gives k + 1e-9, rounded down gives
// k - 1e-9), so we take the ceiling of the exact real product. With p the
// rounded product, fma(t, N, -p) is the exact rounding error e (the product
// of two doubles minus a double near it is representable), and p + e is the
// exact product. If p is not an integer, |e| <= ulp(p)/2 cannot carry it past
// the next integer (integers up to 2^53 are doubles, so an integer is at
// least one ulp away from p); if p is an integer the sign of e decides.
#include <cmath>

#include "plant/plant.h"

namespace simbot::plant {

std::int64_t eventTickFromSeconds(double t) {
  const double n = static_cast<double>(kTicksPerSecond);
  const double p = t * n;
  const double e = std::fma(t, n, -p);  // exact: t*n == p + e
  const double c = std::ceil(p);
  if (c == p && e > 0) return static_cast<std::int64_t>(c) + 1;
  return static_cast<std::int64_t>(c);
}

double secondsFromTick(std::int64_t tick) { return timebase::secondsFromTicks(tick); }

}  // namespace simbot::plant
