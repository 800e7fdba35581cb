// plant/motor_receiver.h -- the motor controller's serial receiver and its
// framing rule (DESIGN.md "Serial link", "Devices"): the other end of the
// wire from the board's serial port (board/serial_port.h).
//
// A NUL ends a frame; the controller latches the last 8 characters
// received before it when there are at least 8 since the previous NUL and
// all are valid, and otherwise rejects the frame (the wheels keep the
// previous command). The latch happens at the end of the NUL's stop bit,
// the tick the byte is received.
#pragma once
#include <cstdint>
#include <optional>
#include <string>

#include "plant/plant.h"

namespace simbot::plant {

// A frame the receiver finished at a NUL: the last 8 characters before it
// (or all of them, when fewer), and the command when they form a valid one.
struct ReceivedFrame {
  std::string bytes;
  std::optional<MotorFrame> command;  // nullopt: rejected
};

class MotorReceiver {
 public:
  // A byte's stop bit ended: the frame it finished, if it was a NUL.
  std::optional<ReceivedFrame> receive(uint8_t byte);
  // Drops a partial frame (the controller's board was reset: a fragment
  // from before never joins the reloaded program's frames).
  void clear() { received_.clear(); }
  // Bytes received since the previous NUL.
  const std::string& pending() const { return received_; }

  bool operator==(const MotorReceiver&) const = default;

 private:
  std::string received_;
};

}  // namespace simbot::plant
