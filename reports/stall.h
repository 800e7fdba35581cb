// What a stall is, defined once for every report that counts one: simbot
// explain's list of stalls (explain.h) and simbot bench's stall_s
// (batch/bench_metrics.h), so that a bench's stall_s for a seed is the sum of
// the stalls explain lists for that seed's trace.
//
// A stall: the robot's program runs, sees the opponent and latches no motor
// frame, and the robot stands still, for more than a second.
//
// "Sees" is what the program itself read, not the geometry: its latest
// ad_rd8 reading of either eye is above the seen threshold (ICEMAN's own
// test, `x>48`, the background being 16). So thesis chapter X's one-eye
// dead-lock (one eye at background, the other above 48, and a program that
// moves only when both are) is a stall, and an opponent beyond both eyes'
// limiting angles is not: the program cannot know it is there. The readings
// are the ones the program got, noise included; a trace has them as ad_read
// records (a record whenever a reading differs from that eye's previous one,
// so the latest reading is known at every tick). A reloaded program
// (--reload-on-fault) has read nothing yet.
//
// "Stands still" is judged at the pose samples (the trace's 20-Hz sample
// records; bench's observer gets the same plant poses at the same ticks): the
// robot is still from a sample whose centre lies within
// StallRule::still_fps * (the time since the previous sample) of the
// previous sample's, until a sample that lies further. The threshold,
// kStillFeetPerSecond below, is 0.02 ft/s: below the slowest centre speed
// any motor command gives (one wheel at speed step 1, the other stopped:
// 0.05 / 2 = 0.025 ft/s in profile default, 0.05 in thesis-1997), so a
// robot that drives, however slowly, is never stalled; and above zero, so a
// robot whose command is stop is still once its motor lag has decayed (from
// full speed, 0.6 s with default's 0.15-s lag). Turning on the spot (the
// centre still) counts as standing still.
//
// "Runs": a robot that faulted or whose main returned is not stalled (it
// cannot latch anything); after a reload it runs again.
//
// A stall window opens when all of these become true (at the eye reading,
// latch, sample or reload that makes them so); it closes at the next latch,
// at the reading after which the program no longer sees the opponent, at the
// sample that finds the robot moving, at a fault or exit, or at the run's
// end. A window longer than `minimum` is a stall, counted whole (from its
// opening). The feeding must be in tick order, and within a tick in the
// order the trace has the records.
#pragma once
#include <limits>
#include <optional>

#include "timebase/tick.h"

namespace simbot::reports {

using timebase::Tick;

// The stall's movement threshold (see above): a centre moving slower than
// this between two pose samples stands still.
inline constexpr double kStillFeetPerSecond = 0.02;

struct StallRule {
  int seen = 48;                             // an eye reading above this sees the opponent
  Tick minimum = timebase::kTicksPerSecond;  // a window longer than this is a stall
  double still_fps = kStillFeetPerSecond;    // slower than this between samples: still
};

struct StallSpan {
  Tick from = 0, to = 0;
};

// One robot's stall windows, fed its eye readings, latches, pose samples,
// halts and reloads in tick order. Each call returns the stall that ended at
// `t`, if the window that closed there was one.
class StallWatch {
 public:
  explicit StallWatch(StallRule rule = {}) : rule_(rule) {}

  // An ad_rd8 reading of channel 0 (left eye) or 1 (right eye); other
  // channels are not eyes and change nothing.
  std::optional<StallSpan> eyeRead(Tick t, int channel, int value);
  // A motor frame latched by the motor controller.
  std::optional<StallSpan> frameLatched(Tick t);
  // A pose sample: the robot's centre at t, in feet.
  std::optional<StallSpan> pose(Tick t, double x_ft, double y_ft);
  // The program faulted or main returned.
  std::optional<StallSpan> halted(Tick t);
  // The faulted program was reloaded: it runs again and has read nothing.
  std::optional<StallSpan> reloaded(Tick t);
  // The run ended at `end`: closes an open window there.
  std::optional<StallSpan> finish(Tick end);

  // The open window's start (a stall if it lasts), or none.
  std::optional<Tick> windowStart() const { return start_; }
  // The total length of the stalls returned so far.
  Tick total() const { return total_; }

 private:
  bool sees() const { return left_ > rule_.seen || right_ > rule_.seen; }
  bool stalling() const { return sees() && still_ && !halted_; }
  // Closes the window if the conditions no longer hold, opens one if they
  // newly do.
  std::optional<StallSpan> update(Tick t);
  std::optional<StallSpan> close(Tick t);

  StallRule rule_;
  // Before a first reading an eye has read nothing: it sees nothing.
  int left_ = std::numeric_limits<int>::min(), right_ = std::numeric_limits<int>::min();
  bool still_ = true;  // before a second sample: at rest, where every run starts
  bool halted_ = false;
  std::optional<Tick> lastPoseT_;
  double lastX_ = 0, lastY_ = 0;
  std::optional<Tick> start_;
  Tick total_ = 0;
};

}  // namespace simbot::reports
