// One robot's stall windows (stall.h).
#include "reports/stall.h"

#include <cmath>

namespace simbot::reports {

std::optional<StallSpan> StallWatch::close(Tick t) {
  if (!start_) return std::nullopt;
  const StallSpan span{*start_, t};
  start_.reset();
  if (span.to - span.from <= rule_.minimum) return std::nullopt;
  total_ += span.to - span.from;
  return span;
}

std::optional<StallSpan> StallWatch::update(Tick t) {
  if (!stalling()) return close(t);
  if (!start_) start_ = t;
  return std::nullopt;
}

std::optional<StallSpan> StallWatch::eyeRead(Tick t, int channel, int value) {
  if (channel != 0 && channel != 1) return std::nullopt;
  (channel == 0 ? left_ : right_) = value;
  return update(t);
}

std::optional<StallSpan> StallWatch::frameLatched(Tick t) {
  auto ended = close(t);
  if (stalling()) start_ = t;
  return ended;
}

std::optional<StallSpan> StallWatch::pose(Tick t, double x_ft, double y_ft) {
  if (lastPoseT_ && t > *lastPoseT_) {
    const double seconds =
        static_cast<double>(t - *lastPoseT_) / static_cast<double>(timebase::kTicksPerSecond);
    still_ = std::hypot(x_ft - lastX_, y_ft - lastY_) <= rule_.still_fps * seconds;
  }
  lastPoseT_ = t;
  lastX_ = x_ft;
  lastY_ = y_ft;
  return update(t);
}

std::optional<StallSpan> StallWatch::halted(Tick t) {
  halted_ = true;
  return update(t);
}

std::optional<StallSpan> StallWatch::reloaded(Tick t) {
  halted_ = false;
  left_ = right_ = std::numeric_limits<int>::min();
  return update(t);
}

std::optional<StallSpan> StallWatch::finish(Tick end) { return close(end); }

}  // namespace simbot::reports
