// plant/motor_receiver.cpp -- the motor controller's framing (motor_receiver.h).
#include "plant/motor_receiver.h"

namespace simbot::plant {

std::optional<ReceivedFrame> MotorReceiver::receive(uint8_t byte) {
  if (byte != 0) {
    received_.push_back(static_cast<char>(byte));
    return std::nullopt;
  }
  ReceivedFrame frame;
  frame.bytes = received_.size() >= 8 ? received_.substr(received_.size() - 8) : received_;
  if (received_.size() >= 8) frame.command = parseMotorFrame(frame.bytes);
  received_.clear();
  return frame;
}

}  // namespace simbot::plant
