// One robot's stall windows (stall.h).
#include "reports/stall.h"

namespace simbot::reports {

std::optional<StallSpan> StallWatch::close(Tick t) {
  if (!start_) return std::nullopt;
  const StallSpan span{*start_, t};
  start_.reset();
  if (span.to - span.from <= rule_.minimum) return std::nullopt;
  total_ += span.to - span.from;
  return span;
}

std::optional<StallSpan> StallWatch::eyeRead(Tick t, int channel, int value) {
  if (channel != 0 && channel != 1) return std::nullopt;
  (channel == 0 ? left_ : right_) = value;
  if (!sees()) return close(t);
  if (!start_) start_ = t;
  return std::nullopt;
}

std::optional<StallSpan> StallWatch::frameLatched(Tick t) {
  auto ended = close(t);
  if (sees()) start_ = t;
  return ended;
}

std::optional<StallSpan> StallWatch::finish(Tick end) { return close(end); }

}  // namespace simbot::reports
