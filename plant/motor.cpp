// plant/motor.cpp -- the motor controller's frame decoder and speed mapping.
//
// A frame is the last 8 characters before a NUL (DESIGN.md "Devices"): per
// wheel a speed step 0-9a-f, a direction f/r, g(o)/s(top), and a distance
// counter byte the controller ignores (any non-NUL byte). The decoder is a
// pure function so the scheduler's UART model and the tests share it. Only
// lowercase hex digits are accepted: the thesis's own decoder (Appendix C,
// getVelocity) maps characters above '`' with c - 87, i.e. 'a'..'f'; an
// uppercase 'A' would decode to a nonsense step, so we reject it.
#include "plant/plant.h"

namespace simbot::plant {
namespace {

std::optional<WheelCommand> parseWheel(std::string_view c) {
  WheelCommand w;
  const char s = c[0];
  if (s >= '0' && s <= '9') {
    w.speed = s - '0';
  } else if (s >= 'a' && s <= 'f') {
    w.speed = s - 'a' + 10;
  } else {
    return std::nullopt;
  }
  if (c[1] == 'f') {
    w.forward = true;
  } else if (c[1] == 'r') {
    w.forward = false;
  } else {
    return std::nullopt;
  }
  if (c[2] == 'g') {
    w.go = true;
  } else if (c[2] == 's') {
    w.go = false;
  } else {
    return std::nullopt;
  }
  if (c[3] == '\0') return std::nullopt;
  w.counter = c[3];
  return w;
}

}  // namespace

std::optional<MotorFrame> parseMotorFrame(std::string_view chars) {
  if (chars.size() != 8) return std::nullopt;
  auto l = parseWheel(chars.substr(0, 4));
  auto r = parseWheel(chars.substr(4, 4));
  if (!l || !r) return std::nullopt;
  return MotorFrame{*l, *r};
}

double wheelSpeedFps(const WheelCommand& cmd, const RobotParams& p, bool leftWheel) {
  if (!cmd.go) return 0.0;
  const double trim = leftWheel ? p.left_trim : p.right_trim;
  const double v = p.speed_table_fps[static_cast<std::size_t>(cmd.speed & 15)] * trim;
  return cmd.forward ? v : -v;
}

}  // namespace simbot::plant
