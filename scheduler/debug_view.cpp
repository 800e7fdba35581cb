// What a debugger's `info arena` shows of a match stopped at a tick
// (MatchView::describe): read from the boards and from the plant's dense
// output, changing nothing.
#include <fmt/format.h>

#include <algorithm>

#include "scheduler/match_impl.h"

namespace simbot::scheduler::detail {

namespace {

std::string byteText(uint8_t b) {
  if (b == 0) return "NUL";
  if (b >= 0x20 && b < 0x7F) return fmt::format("'{}'", static_cast<char>(b));
  return fmt::format("0x{:02X}", b);
}

// The bytes the serial library has still to fetch, and why they wait: the
// transmit interrupt is what fetches each one (DESIGN.md "Serial link").
std::string waitingBytes(const Robot& r) {
  const board::SerialPort& serial = r.board.serial;
  const vm::Vm& cpu = r.vm();
  if (!serial.libraryActive()) return "";
  const int count = cpu.read8(serial.countAddress());
  if (count == 0) return "";
  std::string why;
  if (!cpu.pending(vm::Irq::SerialTx)) {
    why = "the port takes the next when its data register empties";
  } else if (cpu.interruptsEnabled()) {
    why = "the transmit interrupt is pending, accepted at the next boundary";
  } else if (cpu.interruptDepth() > 0) {
    // The innermost handler in service (the instruction it interrupted is
    // in the activation after it).
    std::string handler = "?";
    for (const vm::Vm::Activation& a : cpu.activations())
      if (a.handler) {
        const vm::Symbol* fn = r.spec.image.functionAt(a.pc);
        handler = fn ? fn->name : "?";
        break;
      }
    why = fmt::format(
        "the transmit interrupt is pending and interrupts are disabled: handler {}() is in "
        "service and has not called EI()",
        handler);
  } else {
    why = "the transmit interrupt is pending and interrupts are disabled (DI, IFF1 = 0)";
  }
  return fmt::format("{} byte{} waiting at 0x{:04X} (*cc at 0x{:04X}): {}", count,
                     count == 1 ? "" : "s", serial.pointer(), serial.countAddress(), why);
}

}  // namespace

std::string Match::describe(Tick t) const {
  const Tick at = std::clamp(t, arena_.lastReinitTick(), arena_.now());
  std::string out = fmt::format("arena at tick {} ({:.6f} s)\n", t, timebase::secondsFromTicks(t));
  for (const auto& r : robots_) {
    const plant::RobotState st = arena_.state(r->index, at);
    const vm::Vm& cpu = r->vm();
    out += fmt::format("{} ({}): clock {}{}\n", r->spec.name, r->spec.program, cpu.now(),
                       cpu.fault()    ? ", faulted"
                       : cpu.halted() ? ", main returned"
                                      : "");
    out += fmt::format("  pose       x {:.3f} ft  y {:.3f} ft  heading {:.2f} deg\n", st.pose.x_ft,
                       st.pose.y_ft, st.pose.heading_deg);
    out += fmt::format("  wheels     left {:.3f} ft/s  right {:.3f} ft/s\n", st.left_fps,
                       st.right_fps);
    // What the photodetectors see at this tick (the plant's optics, before
    // the A/D's noise), and what the program last read.
    const plant::EyeReadings eyes = arena_.eyeReadings(r->index, at);
    out += fmt::format(
        "  eyes       now left {}  right {}; last ad_rd8 left {}  right {} ({} and {} reads)\n",
        eyes.left, eyes.right, r->board.lastAdValue[0], r->board.lastAdValue[1],
        r->board.adReads[0], r->board.adReads[1]);
    out += fmt::format(
        "  port A     edge lines 0x{:02X} (fore {}, aft {}), PIO interrupt {}, vector 0x{:02X}\n",
        r->board.edgeLines, (r->board.edgeLines & 0x02) ? "high" : "low",
        (r->board.edgeLines & 0x01) ? "high" : "low",
        r->board.pio.interruptEnabled() ? "enabled" : "disabled", r->board.pio.vector());
    const board::SerialPort& serial = r->board.serial;
    std::string link = serial.idle() ? "idle" : "busy";
    if (const auto done = serial.nextByteDone())
      link += fmt::format(", shifting {} until tick {}", byteText(serial.shifting()), *done);
    out += fmt::format("  serial     {}, {} bytes sent, receiver holds \"{}\"\n", link,
                       serial.bytesSent(), r->receiver.pending());
    if (const std::string waiting = waitingBytes(*r); !waiting.empty())
      out += "             " + waiting + "\n";
    out += fmt::format("  guns       {} shots, {} hits\n", arena_.shots(r->index),
                       arena_.hits(r->index));
    // Only a robot that carries one, so that other sessions read as before.
    if (arenaConfig_->robots[static_cast<size_t>(r->index)].hardware.secondary.kind ==
        plant::SecondaryKind::Disc)
      out += fmt::format("  discs      {} shots, {} hits, {} left\n", arena_.discShots(r->index),
                         arena_.discHits(r->index), arena_.discsLeft(r->index));
  }
  return out;
}

}  // namespace simbot::scheduler::detail
