#include "plant/serial_link.h"

#include <algorithm>

namespace simbot::plant {

std::optional<OverwrittenSend> SerialLink::send(Tick t0, uint16_t buf, uint16_t ccAddress,
                                                RobotMemory& memory) {
  std::optional<OverwrittenSend> overwritten;
  if (unfetched_ > 0) overwritten = OverwrittenSend{sentAt_, sentCount_, fetched_};
  pointer_ = buf;
  ccAddress_ = ccAddress;
  tie_ = true;
  sentAt_ = t0;
  sentCount_ = memory.read8(ccAddress);
  fetched_ = 0;
  fetch(t0, memory);  // the library loads buf[0] itself when the TDR is empty
  unfetched_ = memory.read8(ccAddress_);
  return overwritten;
}

void SerialLink::service(Tick t, RobotMemory& memory) {
  fetch(t, memory);
  unfetched_ = memory.read8(ccAddress_);
}

void SerialLink::fetch(Tick t, RobotMemory& memory) {
  if (tdrFull_) return;
  const uint8_t count = memory.read8(ccAddress_);
  if (count == 0) {
    tie_ = false;
    return;
  }
  const uint8_t byte = memory.read8(pointer_);
  pointer_ = static_cast<uint16_t>(pointer_ + 1);
  memory.write8(ccAddress_, static_cast<uint8_t>(count - 1));
  ++fetched_;
  loadTdr(t, byte);
}

void SerialLink::loadTdr(Tick t, uint8_t byte) {
  tdr_ = byte;
  tdrFull_ = true;
  tdrLoadedAt_ = t;
  if (!tsrBusy_) moveTdrToTsr(t);
}

void SerialLink::moveTdrToTsr(Tick t) {
  tsr_ = tdr_;
  tdrFull_ = false;
  tsrBusy_ = true;
  tsrDoneAt_ = t + kTicksPerChar;
}

std::optional<ReceivedFrame> SerialLink::byteDone(Tick t) {
  if (!tsrBusy_ || t != tsrDoneAt_) return std::nullopt;
  tsrBusy_ = false;
  ++bytesSent_;
  const uint8_t byte = tsr_;
  // The host may learn of a load a little after the tick it happened at
  // (an ISR that ended past the horizon); the TSR takes it when it is there.
  if (tdrFull_) moveTdrToTsr(std::max(t, tdrLoadedAt_));
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
