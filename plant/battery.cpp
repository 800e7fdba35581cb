// plant/battery.cpp -- the battery's closed form (battery.h).
#include "plant/battery.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace simbot::plant {

void Battery::setCurrent(std::int64_t tick, double amps) {
  if (tick < tick_) throw std::logic_error("battery: current changed before its last change");
  charge_ = charge(tick);
  tick_ = tick;
  amps_ = amps;
}

double Battery::charge(std::int64_t tick) const {
  return charge_ + amps_ * static_cast<double>(tick - tick_) / static_cast<double>(kTicksPerSecond);
}

double Battery::openCircuit(std::int64_t tick) const {
  const double soc = std::max(0.0, 1.0 - charge(tick) / p_.capacity_c);
  return p_.voltage_empty_v + (p_.voltage_full_v - p_.voltage_empty_v) * soc;
}

double Battery::voltage(std::int64_t tick) const {
  return openCircuit(tick) - amps_ * p_.resistance_ohm;
}

// V is continuous and non-increasing in t: it reaches `volts` where the
// state of charge is soc* = (volts + I R - V_empty) / (V_full - V_empty),
// i.e. after drawing Q* = C (1 - soc*), at t = t_k + (Q* - Q_k) / I. If
// soc* <= 0 the empty end (V_empty - I R) stays above `volts`. The
// seconds go to a tick by eventTickFromSeconds (the ceiling of the exact
// product); the double evaluation of V at that tick and the one before
// then settles round-off, so that the tick is exactly the first one at
// which voltage() itself reads <= volts.
std::optional<std::int64_t> Battery::firstTickAtOrBelow(double volts, std::int64_t from) const {
  if (voltage(from) <= volts) return from;
  if (amps_ <= 0) return std::nullopt;
  const double soc = (volts + amps_ * p_.resistance_ohm - p_.voltage_empty_v) /
                     (p_.voltage_full_v - p_.voltage_empty_v);
  if (soc <= 0) return std::nullopt;
  const double drawn = p_.capacity_c * (1 - soc);
  const double seconds = (drawn - charge_) / amps_;
  std::int64_t t = tick_ + eventTickFromSeconds(seconds);
  t = std::max(t, from);
  // Round-off moves the tick by one at most; the bounds only guard.
  for (int k = 0; k < 4 && t > from && voltage(t - 1) <= volts; ++k) --t;
  for (int k = 0; k < 4 && voltage(t) > volts; ++k) ++t;
  return t;
}

double drawnCurrent(const BatteryParams& p, const WheelCommand& left, const WheelCommand& right,
                    int gunMotorsOn, int solenoidsHigh) {
  const auto wheel = [&](const WheelCommand& w) {
    return w.go ? p.drive_a * static_cast<double>(w.speed & 15) / 15.0 : 0.0;
  };
  return p.board_a + wheel(left) + wheel(right) + p.gun_motor_a * gunMotorsOn +
         p.solenoid_a * solenoidsHigh;
}

}  // namespace simbot::plant
