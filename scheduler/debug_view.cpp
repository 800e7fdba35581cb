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
    out += fmt::format("  guns       {} shots, {} hits\n", arena_.shots(r->index),
                       arena_.hits(r->index));
  }
  return out;
}

}  // namespace simbot::scheduler::detail
