// board/serial_port.cpp -- the ASCI and the serial library (serial_port.h).
#include "board/serial_port.h"

#include <algorithm>

namespace simbot::board {

std::optional<OverwrittenSend> SerialPort::send(Tick t0, uint16_t buf, uint16_t ccAddress,
                                                Memory& memory) {
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

void SerialPort::service(Tick t, Memory& memory) {
  fetch(t, memory);
  unfetched_ = memory.read8(ccAddress_);
}

void SerialPort::fetch(Tick t, Memory& memory) {
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

void SerialPort::loadTdr(Tick t, uint8_t byte) {
  tdr_ = byte;
  tdrFull_ = true;
  tdrLoadedAt_ = t;
  if (!tsrBusy_) moveTdrToTsr(t);
}

void SerialPort::moveTdrToTsr(Tick t) {
  tsr_ = tdr_;
  tdrFull_ = false;
  tsrBusy_ = true;
  tsrDoneAt_ = t + kTicksPerChar;
}

std::optional<uint8_t> SerialPort::byteDone(Tick t) {
  if (!tsrBusy_ || t != tsrDoneAt_) return std::nullopt;
  tsrBusy_ = false;
  ++bytesSent_;
  const uint8_t byte = tsr_;
  // The host may learn of a load a little after the tick it happened at
  // (an ISR that ended past the horizon); the TSR takes it when it is there.
  if (tdrFull_) moveTdrToTsr(std::max(t, tdrLoadedAt_));
  return byte;
}

}  // namespace simbot::board
