// board/serial_port.h -- the board's side of the link to the motor
// controller: the Z180's ASCI channel 1 (double-buffered: transmit data
// register TDR feeding the transmit shift register TSR) and Dynamic C's
// interrupt-driven ser_send_z1 library (DESIGN.md "Serial link",
// "Devices"). The motor controller's receiver, which frames the bytes this
// port puts on the wire, is the plant's (plant/motor_receiver.h).
//
// One character (8N1 at 9600 baud) is exactly timebase::kTicksPerChar
// ticks. ser_send_z1 ends at T0: it points the library at buf/cc and, when
// the TDR is empty, loads buf[0] (decrementing *cc), which goes straight
// to an idle TSR, so byte 0 is on the wire during [T0, T0 + one
// character). While TIE is set and the TDR is empty the port requests the
// transmit interrupt; its service routine loads the next byte from the
// robot's memory and decrements *cc there, or, with *cc at zero, clears
// TIE. When the TSR finishes a byte the TDR's byte, if any, moves to the
// TSR. A new send re-points the library at buf[0] with the new count;
// bytes already in the TDR and TSR still go out, and the rest of the
// previous send, if the library had any left to fetch, never does (the
// overwrite rule, which send() reports).
//
// A SerialPort is a value: copying it copies the port and the library.
#pragma once
#include <cstdint>
#include <optional>

#include "timebase/tick.h"

namespace simbot::board {

using timebase::kTicksPerChar;
using timebase::Tick;

// The robot memory the serial library reads from and writes to.
class Memory {
 public:
  virtual ~Memory() = default;
  virtual uint8_t read8(uint16_t address) const = 0;
  virtual void write8(uint16_t address, uint8_t value) = 0;
};

// A send that restarted the library while it still had bytes of the
// previous send to fetch (as *cc read after the library's last step: the
// program may rewrite *cc itself before sending again): the rest of that
// frame never goes out.
struct OverwrittenSend {
  Tick sentAt;  // ser_send_z1 of the overwritten send returned (T0)
  int count;    // its *cc then
  int fetched;  // bytes of it the port had taken
};

class SerialPort {
 public:
  // ser_send_z1 returned at `t0`; the send it overwrote, if any.
  std::optional<OverwrittenSend> send(Tick t0, uint16_t buf, uint16_t ccAddress, Memory& memory);
  // The library's transmit interrupt service routine ran at `t`.
  void service(Tick t, Memory& memory);
  // The TSR finished its byte at `t` (== nextByteDone()): the byte, now
  // received at the other end of the wire; nullopt if none finished at t.
  std::optional<uint8_t> byteDone(Tick t);

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
  // The library has a send under way (TIE): it fetches the next byte from
  // `pointer()` on each transmit interrupt while *countAddress() is not 0.
  bool libraryActive() const { return tie_; }
  uint16_t countAddress() const { return ccAddress_; }
  uint16_t pointer() const { return pointer_; }
  // The byte in the TSR (on the wire until nextByteDone()).
  uint8_t shifting() const { return tsr_; }
  uint64_t bytesSent() const { return bytesSent_; }

  bool operator==(const SerialPort&) const = default;

 private:
  void fetch(Tick t, Memory& memory);
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
};

}  // namespace simbot::board
