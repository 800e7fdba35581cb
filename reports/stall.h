// What a stall is, defined once for every report that counts one: simbot
// explain's list of stalls (explain.h) and simbot bench's stall_s
// (batch/bench_metrics.h), so that a bench's stall_s for a seed is the sum of
// the stalls explain lists for that seed's trace.
//
// A stall: the robot's program sees the opponent and latches no motor frame,
// for more than a second. "Sees" is what the program itself read, not the
// geometry: its latest ad_rd8 reading of either eye is above the seen
// threshold (ICEMAN's own test, `x>48`, the background being 16). So thesis
// chapter X's one-eye dead-lock (one eye at background, the other above 48,
// and a program that moves only when both are) is a stall, and an opponent
// beyond both eyes' limiting angles is not: the program cannot know it is
// there. The readings are the ones the program got, noise included; a trace
// has them as ad_read records (a record whenever a reading differs from
// that eye's previous one, so the latest reading is known at every tick).
//
// A stall window opens when the program sees the opponent, or at a latch
// while it does; it closes at the next latch, at the reading after which it
// no longer sees the opponent, or at the run's end. A window longer than
// `minimum` is a stall, counted whole (from its opening).
#pragma once
#include <limits>
#include <optional>

#include "timebase/tick.h"

namespace simbot::reports {

using timebase::Tick;

struct StallRule {
  int seen = 48;                             // an eye reading above this sees the opponent
  Tick minimum = timebase::kTicksPerSecond;  // a window longer than this is a stall
};

struct StallSpan {
  Tick from = 0, to = 0;
};

// One robot's stall windows, fed its eye readings and latches in tick order.
// Each call returns the stall that ended at `t`, if the window that closed
// there was one.
class StallWatch {
 public:
  explicit StallWatch(StallRule rule = {}) : rule_(rule) {}

  // An ad_rd8 reading of channel 0 (left eye) or 1 (right eye); other
  // channels are not eyes and change nothing.
  std::optional<StallSpan> eyeRead(Tick t, int channel, int value);
  // A motor frame latched by the motor controller.
  std::optional<StallSpan> frameLatched(Tick t);
  // The run ended at `end`: closes an open window there.
  std::optional<StallSpan> finish(Tick end);

  // The open window's start (a stall if it lasts), or none.
  std::optional<Tick> windowStart() const { return start_; }
  // The total length of the stalls returned so far.
  Tick total() const { return total_; }

 private:
  bool sees() const { return left_ > rule_.seen || right_ > rule_.seen; }
  std::optional<StallSpan> close(Tick t);

  StallRule rule_;
  // Before a first reading an eye has read nothing: it sees nothing.
  int left_ = std::numeric_limits<int>::min(), right_ = std::numeric_limits<int>::min();
  std::optional<Tick> start_;
  Tick total_ = 0;
};

}  // namespace simbot::reports
