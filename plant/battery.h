// plant/battery.h -- a robot's battery in closed form (DESIGN.md "The
// wider competition": batteries that run down, brown-out resets).
//
// The current is piecewise constant: it changes only at the ticks the
// scheduler tells (a latched motor frame, a port B write, a bumper
// reflex's start or end, a reset), so between two changes the charge drawn
// is linear in time and so is the terminal voltage:
//   Q(t)   = Q_k + I_k (t - t_k)                       (coulombs)
//   SOC(t) = max(0, 1 - Q(t) / C)
//   Voc(t) = V_empty + (V_full - V_empty) SOC(t)        (linear curve)
//   V(t)   = Voc(t) - I_k R                             (terminal voltage)
// The first tick at which V falls to a threshold is then a closed form
// (firstTickAtOrBelow), placed on the clock by eventTickFromSeconds, as a
// root the integrator finds is. docs/plant.md, "Batteries", has the model.
#pragma once

#include <cstdint>
#include <optional>

#include "plant/plant.h"

namespace simbot::plant {

class Battery {
 public:
  // Full at tick 0, drawing nothing.
  explicit Battery(const BatteryParams& params) : p_(params) {}

  // From `tick` on the battery delivers `amps` (>= 0; tick not before the
  // last change).
  void setCurrent(std::int64_t tick, double amps);
  double current() const { return amps_; }
  std::int64_t lastChange() const { return tick_; }

  // At any tick not before the last change: charge drawn (C), open-circuit
  // and terminal voltage (V).
  double charge(std::int64_t tick) const;
  double openCircuit(std::int64_t tick) const;
  double voltage(std::int64_t tick) const;
  // The wheels' and gun wheels' speed factor at `tick`: terminal voltage
  // over the nominal voltage the speed table was measured at.
  double supplyScale(std::int64_t tick) const { return voltage(tick) / p_.nominal_v; }

  // The first tick T >= from with voltage(T) <= volts under the present
  // current, or nullopt if the voltage never gets there (no current, or
  // the flat empty end of the curve stays above it).
  std::optional<std::int64_t> firstTickAtOrBelow(double volts, std::int64_t from) const;

  const BatteryParams& params() const { return p_; }
  bool operator==(const Battery&) const = default;

 private:
  BatteryParams p_;
  std::int64_t tick_ = 0;  // last change of current
  double charge_ = 0;      // drawn up to tick_
  double amps_ = 0;        // since tick_
};

// The current a robot draws (A): the board always; each drive wheel in
// proportion to its commanded speed step (full_speed current at step 15,
// none when stopped); each gun motor that is on; each solenoid whose bit
// is high. `gunOn` and `solenoidHigh` come from port B and the hardware
// file's bindings.
double drawnCurrent(const BatteryParams& p, const WheelCommand& left, const WheelCommand& right,
                    int gunMotorsOn, int solenoidsHigh);

}  // namespace simbot::plant
