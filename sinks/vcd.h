// The digital signals of a run as an IEEE 1364 value change dump (VCD), for
// GTKWave and sigrok/PulseView: a trace sink (--vcd FILE.vcd).
//
// Timescale 1 ps. One tick of the 9.216 MHz clock is 1e12 / 9,216,000 =
// 108,506.944... ps; tick t is written at round(t * 1e12 / 9,216,000) ps,
// the nearest picosecond (halves up), which keeps every tick distinct and
// in order. The file's header comment says the same.
//
// One scope per robot (A, B); every signal's name starts with the robot's
// (A_txd), because sigrok names channels without their scope.
//   X_txd            serial TXD at bit level: start bit, 8 data bits LSB
//                    first, stop bit, 960 ticks each (9600 baud 8N1); idle 1
//   X_rs485_enable   the last ENB485 write was non-zero (0 until written)
//   X_edge_fore      PIO port A bit 1 (low: the fore detector is near the wire)
//   X_edge_aft       PIO port A bit 0
//   X_gun1_motor ... PIO port B bits, named by the robot's hardware file
//                    (gun1_motor, gun1_solenoid, gun2_motor, gun2_solenoid,
//                    disc_shooter; portb<N> for the others)
//   X_iff1           the Z180's IFF1: EI/DI, low in every handler until its
//                    EI or RETI, low in the serial library's own interrupt
//   X_in_pio_a       the PIO handler is in service (acceptance to RETI)
//   X_in_serial_tx   the serial library's transmit interrupt is in service
//   X_left_cmd       latched motor command per wheel: speed step, negative
//   X_right_cmd      in reverse, 0 when stopped ('s')
//   X_eye_left       the eye readings the program's ad_rd8 calls returned
//   X_eye_right      (0 until the first call)
//   X_console_lines  lines the program has printed
// The multi-bit values are `real` variables holding integers: libsigrok
// 0.5.2 (Debian 12's sigrok) stops reading a VCD at its first vector value,
// and skips real ones.
#pragma once
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>

#include "files/files.h"
#include "trace/trace.h"

namespace simbot::sinks {

class VcdSink final : public trace::Sink {
 public:
  // Opens its temporary file now (files::Output), renamed into place by
  // close(); UserError if it cannot.
  explicit VcdSink(const std::string& path);
  ~VcdSink() override;
  VcdSink(const VcdSink&) = delete;
  VcdSink& operator=(const VcdSink&) = delete;
  void write(const trace::Entry& entry) override;
  void close() override;

  struct State;

 private:
  std::string path_;
  std::optional<files::Output> out_;
  std::FILE* file_ = nullptr;  // out_'s, until close()
  State* s_;
};

}  // namespace simbot::sinks
