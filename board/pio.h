// board/pio.h -- the Z80 PIO's port A in mode 3 (bit control), as the course programs set it
// up through its control port, and port B's output latch.
//
// Control words (Z80 PIO technical manual), written to the control port:
//   mode word        xx1111 b: D7-D6 = mode (11 = mode 3); in mode 3 the next
//                    word is the I/O direction register (1 = input)
//   vector           D0 = 0: the IM2 vector byte
//   interrupt control  D3-D0 = 0111: D7 enable, D6 AND(1)/OR(0), D5 active
//                    high(1)/low(0), D4 mask word follows
//   mask             after a control word with D4 set: 1 = bit ignored
//   enable/disable   D3-D0 = 0011: D7 sets the interrupt enable flip-flop
// In mode 3 the port requests an interrupt when the logic condition on the
// monitored input bits changes from false to true. While the port's
// interrupt is under service (acceptance to RETI) it raises no new request;
// a condition that becomes true then is held and raised after the RETI.
#pragma once
#include <cstdint>

namespace simbot::board {

class Pio {
 public:
  // A byte written to the control port.
  void control(uint8_t word);
  // The input lines changed (bit = 1 high). Returns true if the port now
  // requests an interrupt.
  bool setInputs(uint8_t lines);
  // What a read of the data port returns: inputs from the lines, outputs
  // from the output latch.
  uint8_t read() const;
  void writeData(uint8_t value) { output_ = value; }

  // The CPU accepted / returned from this port's interrupt. Returns true if
  // a request is raised at RETI (condition became true while in service).
  void accepted() { inService_ = true; }
  bool returned();

  uint8_t vector() const { return vector_; }
  bool interruptEnabled() const { return enabled_; }
  int mode() const { return mode_; }
  bool condition() const;

  bool operator==(const Pio&) const = default;

 private:
  enum class Expect : uint8_t { Any, Direction, Mask };
  int mode_ = 1;  // after reset: mode 1 (input), interrupts disabled
  Expect expect_ = Expect::Any;
  uint8_t direction_ = 0xFF;
  uint8_t mask_ = 0xFF;  // all ignored until a mask word arrives
  bool andMode_ = false;
  bool activeHigh_ = false;
  bool enabled_ = false;
  uint8_t vector_ = 0;
  uint8_t lines_ = 0xFF;
  uint8_t output_ = 0;
  bool lastCondition_ = false;
  bool inService_ = false;
  bool heldRequest_ = false;
};

}  // namespace simbot::board
