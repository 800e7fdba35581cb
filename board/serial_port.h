// The serial link from a robot's controller to its motor controller: the
// Z180's ASCI channel 1 (double-buffered: transmit data register TDR feeding
// the transmit shift register TSR), Dynamic C's interrupt-driven
// ser_send_z1 library, and the motor controller's receiver with its framing
// rule (DESIGN.md "Serial link", "Devices").
//
// One character (8N1 at 9600 baud) is exactly 9600 ticks. ser_send_z1 ends
// at T0: it points the library at buf/cc and, when the TDR is empty, loads
// buf[0] (decrementing *cc), which goes straight to an idle TSR, so byte 0 is
// on the wire during [T0, T0 + 9600). While TIE is set and the TDR is empty
// the port requests the transmit interrupt; its service routine loads the
// next byte from the robot's memory and decrements *cc there, or, with *cc
// at zero, clears TIE. When the TSR finishes a byte the receiver gets it and
// the TDR's byte, if any, moves to the TSR. A new send re-points the library
// at buf[0] with the new count; bytes already in the TDR and TSR still go out.
//
// Receiver: a NUL ends a frame; the controller latches the last 8 characters
// received before it when there are at least 8 since the previous NUL and all
// are valid, and otherwise rejects the frame (the wheels keep the previous
// command). The latch happens at the end of the NUL's stop bit.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "plant/plant.h"

namespace simbot::plant {

using timebase::kTicksPerChar;
using timebase::Tick;

// The robot memory the serial library reads from and writes to.
class RobotMemory {
 public:
  virtual ~RobotMemory() = default;
  virtual uint8_t read8(uint16_t address) const = 0;
  virtual void write8(uint16_t address, uint8_t value) = 0;
};

// A send that restarted the library while it still had bytes of the
// previous send to fetch (as *cc read after the library's last step: the
// program may rewrite *cc itself before sending again): the rest of that
// frame never goes out.
struct OverwrittenSend {
  Tick sentAt;      // ser_send_z1 of the overwritten send returned (T0)
  int count;        // its *cc then
  int fetched;      // bytes of it the port had taken
};

// A frame the receiver finished at a NUL: the last 8 characters before it
// (or all of them, when fewer), and the command when they form a valid one.
struct ReceivedFrame {
  std::string bytes;
  std::optional<MotorFrame> command;  // nullopt: rejected
};

class SerialLink {
 public:
  // ser_send_z1 returned at `t0`; the send it overwrote, if any.
  std::optional<OverwrittenSend> send(Tick t0, uint16_t buf, uint16_t ccAddress,
                                      RobotMemory& memory);
  // The library's transmit interrupt service routine ran at `t`.
  void service(Tick t, RobotMemory& memory);
  // The TSR finished its byte at `t` (== nextByteDone()). Returns the frame
  // the receiver latched or rejected, if this byte was a NUL ending one.
  std::optional<ReceivedFrame> byteDone(Tick t);

  // Whether the port is requesting the transmit interrupt (TIE and TDRE).
  bool requestingInterrupt() const { return tie_ && !tdrFull_; }
  // When the byte now in the TSR finishes, if one is shifting.
  std::optional<Tick> nextByteDone() const {
    return tsrBusy_ ? std::optional<Tick>(tsrDoneAt_) : std::nullopt;
  }
  bool idle() const { return !tsrBusy_ && !tdrFull_; }
  // When a NUL already in the port finishes (the only byte that can latch a
  // frame): the TSR's, or else the TDR's, which follows it. Nullopt when
  // neither holds a NUL: any later one finishes after the next byte done.
  std::optional<Tick> nulDone() const {
    if (tsrBusy_ && tsr_ == 0) return tsrDoneAt_;
    if (tsrBusy_ && tdrFull_ && tdr_ == 0) return tsrDoneAt_ + kTicksPerChar;
    return std::nullopt;
  }
  // The byte in the TSR (on the wire until nextByteDone()).
  uint8_t shifting() const { return tsr_; }
  uint64_t bytesSent() const { return bytesSent_; }
  // Bytes received since the previous NUL (for traces).
  const std::string& pending() const { return received_; }

 private:
  void fetch(Tick t, RobotMemory& memory);
  void loadTdr(Tick t, uint8_t byte);
  void moveTdrToTsr(Tick t);

  // library state
  bool tie_ = false;
  uint16_t pointer_ = 0;
  uint16_t ccAddress_ = 0;
  // The current send: when, its count, bytes fetched, and *cc after the
  // library's last step (above zero: a new send overwrites it).
  Tick sentAt_ = 0;
  int sentCount_ = 0;
  int fetched_ = 0;
  uint8_t unfetched_ = 0;
  // port state
  bool tdrFull_ = false;
  uint8_t tdr_ = 0;
  Tick tdrLoadedAt_ = 0;  // a byte never leaves the TDR before it arrived
  bool tsrBusy_ = false;
  uint8_t tsr_ = 0;
  Tick tsrDoneAt_ = 0;
  uint64_t bytesSent_ = 0;
  // receiver state
  std::string received_;
};

}  // namespace simbot::plant
