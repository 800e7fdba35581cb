// scheduler/power.cpp -- each robot's battery, brown-out resets and injected
// resets (docs/plant.md, "Batteries"; DESIGN.md "The wider competition").
//
// The battery (plant/battery.h) is a closed form under a piecewise-constant
// current, and the current changes only where the scheduler already acts:
// a latched motor frame, a port B write, a bumper reflex's start or end, a
// reset. At each change the battery takes the new current, the plant takes
// the terminal voltage over the nominal one as the wheels' and gun wheels'
// supply scale (held until the next change: sample and hold, so the plant
// stays a closed form between its inputs), and the first tick at which the
// voltage falls to the brown-out voltage under this current is computed in
// closed form and queued (a power event). A robot keeps at most one such
// check queued per crossing that moved earlier (one that moved later is
// found when the earlier check comes due, and queued again then), so an
// unchanged current queues nothing.
//
// At the brown-out the board resets (Robot::powerOff: its VM runs no
// instruction), the motor controller on the same battery drops its command
// (wheels stop), port B's outputs go low, the serial port empties (a byte
// on the wire is lost). The board then draws only its own current, and the
// voltage jumps back up by the motors' I R: it leaves reset at the reset
// hold's end if the voltage then is at least the brown-out voltage plus the
// hysteresis (under a constant current the voltage only falls, so if not
// then, never: a dead battery). An injected reset does the same and starts
// the program again at once. Without a battery nothing here runs.
#include <fmt/format.h>

#include "scheduler/match_impl.h"

namespace simbot::scheduler::detail {

namespace {
constexpr int kBrownOutCheck = 0;
constexpr int kRestart = 1;

// The current robot r draws now.
double currentOf(const Robot& r, const plant::RobotSetup& setup) {
  const plant::BatteryParams& b = setup.params.battery;
  if (r.powerOff) {
    // Held in reset: the board, and a bumper reflex under way (hard-wired in
    // the motor controller, it runs to its end).
    if (!r.reflexOn) return b.board_a;
    const plant::WheelCommand w{setup.params.reflex_speed_step, true, true, '0'};
    return plant::drawnCurrent(b, w, w, 0, 0);
  }
  const plant::Hardware& hw = setup.hardware;
  const auto high = [&](int bit) { return (r.portB >> bit) & 1; };
  const int guns =
      setup.params.gun_motors_always_on ? 2 : high(hw.gun_motor_bit[0]) + high(hw.gun_motor_bit[1]);
  const int solenoids = high(hw.gun_solenoid_bit[0]) + high(hw.gun_solenoid_bit[1]);
  plant::WheelCommand left = r.motorCommand.left, right = r.motorCommand.right;
  if (r.reflexOn) {
    // The reflex drives both wheels at its step, whatever was latched.
    left = right = plant::WheelCommand{setup.params.reflex_speed_step, true, true, '0'};
  }
  return plant::drawnCurrent(b, left, right, guns, solenoids);
}
}  // namespace

void Match::powerChanged(int robot, Tick t) {
  Robot& r = *robots_[static_cast<size_t>(robot)];
  if (!r.battery) return;
  const plant::RobotSetup& setup = arenaConfig_->robots[static_cast<size_t>(robot)];
  plant::Battery& battery = *r.battery;
  battery.setCurrent(t, currentOf(r, setup));
  if (r.powerOff) return;  // the motors are stopped: no scale to apply
  {
    const PartScope plant(clock_, PartClock::Plant);
    arena_.setSupply(robot, std::max(battery.supplyScale(t), 1e-6), t);
  }
  queueBrownOutCheck(robot, t);
}

// The first tick at or after t at which robot `robot`'s voltage reaches the
// brown-out voltage under its present current; a crossing that an input
// applied after the VMs ran past it causes at once is taken at the round's
// horizon, where they stand (docs/plant.md, "Batteries").
void Match::queueBrownOutCheck(int robot, Tick t) {
  Robot& r = *robots_[static_cast<size_t>(robot)];
  auto at = r.battery->firstTickAtOrBelow(r.battery->params().brownout_v, t);
  if (!at) return;
  at = std::max(*at, inputsHorizon_);
  if (*at >= config_.endTick) return;
  if (r.brownOutCheckAt >= t && r.brownOutCheckAt <= *at) return;  // an earlier one will look
  r.brownOutCheckAt = *at;
  queue_.schedule(*at, EventClass::Reload, {QueuedEvent::Kind::Power, robot, kBrownOutCheck});
}

void Match::powerEvent(int robot, int what, Tick t) {
  Robot& r = *robots_[static_cast<size_t>(robot)];
  if (what == kRestart) {
    if (r.powerOff && r.restartAt == t) brownOutEnds(robot, t);
    return;
  }
  if (r.brownOutCheckAt == t) r.brownOutCheckAt = -1;
  if (r.powerOff || !r.battery) return;
  if (r.battery->voltage(t) <= r.battery->params().brownout_v) {
    resetBoard(robot, t, false);
    return;
  }
  // The current fell since this check was queued: look again when the
  // voltage gets there under the present one.
  queueBrownOutCheck(robot, t);
}

void Match::resetBoard(int robot, Tick t, bool injected) {
  Robot& r = *robots_[static_cast<size_t>(robot)];
  sampleUpTo(t);
  const int count = injected ? ++r.result.resetsInjected : ++r.result.resetsBrownOut;
  const std::optional<double> volts =
      r.battery ? std::optional<double>(r.battery->voltage(t)) : std::nullopt;
  if (trace_.on())
    emit(t, trace::rec::Reset{robot, injected ? "injected" : "brown_out", volts, count});
  if (r.powerOff) return;  // already held in reset: its end starts the program
  // The serial port empties: a byte on the wire never arrives (its queued
  // event finds the port idle), and the motor controller, on the same
  // battery, drops a partial frame and its command.
  r.board.serial = board::SerialPort{};
  r.receiver.clear();
  r.serialEventAt = -1;
  r.motorCommand = plant::MotorFrame{};
  r.portB = 0;
  {
    const PartScope plant(clock_, PartClock::Plant);
    arena_.setWheels(robot, plant::MotorFrame{}, t);
    const plant::EventList none = arena_.setPortB(robot, 0, t);  // no rising edge: no event
    (void)none;
  }
  if (injected) {
    r.restartProgram(t);
    if (trace_.on()) emit(t, trace::rec::Restart{robot, volts});
    powerChanged(robot, t);
    return;
  }
  r.powerOff = true;
  powerChanged(robot, t);  // only the board draws now
  const plant::BatteryParams& b = r.battery->params();
  const Tick end = t + timebase::ticksFromSeconds(b.reset_hold_s);
  if (end < config_.endTick && r.battery->voltage(end) >= b.brownout_v + b.hysteresis_v) {
    r.restartAt = end;
    queue_.schedule(end, EventClass::Reload, {QueuedEvent::Kind::Power, robot, kRestart});
  }
}

void Match::brownOutEnds(int robot, Tick t) {
  Robot& r = *robots_[static_cast<size_t>(robot)];
  sampleUpTo(t);
  r.powerOff = false;
  r.restartAt = -1;
  r.reloadPending = false;  // the power-on starts the program, a fault's reload is moot
  r.restartProgram(t);
  if (trace_.on()) emit(t, trace::rec::Restart{robot, r.battery->voltage(t)});
  powerChanged(robot, t);
}

}  // namespace simbot::scheduler::detail
