// scheduler/part_clock.h -- internal: where a match's wall time goes.
//
// The benchmark asks for the split VM / plant / scheduler
// (MatchConfig::timeParts); normal runs read no clock at all. The match is
// always in exactly one part: a PartScope switches to its part for its
// lifetime and back to the enclosing one after, so a plant query made from
// inside the VM (an A/D read) counts as plant, and everything not inside a
// scope (queue, trace, bookkeeping of the round loop) as scheduler. Each
// switch adds the time since the last switch to the part being left: the
// three sums add up to the time between start() and stop().
#pragma once

#include <array>
#include <chrono>

#include "scheduler/match.h"

namespace simbot::scheduler {

class PartClock {
 public:
  enum Part : int { Vm = 0, Plant = 1, Scheduler = 2 };

  explicit PartClock(bool on) : on_(on) {}
  bool on() const { return on_; }
  void start() {
    if (on_) last_ = Clock::now();
  }
  // Switches to part p; returns the part that was current.
  Part enter(Part p) {
    const Part was = current_;
    if (on_ && p != current_) {
      const auto t = Clock::now();
      sums_[static_cast<std::size_t>(current_)] += t - last_;
      last_ = t;
      current_ = p;
    }
    return was;
  }
  void stop() { enter(Scheduler); }
  PartTimes times() const {
    const auto s = [this](Part p) {
      return std::chrono::duration<double>(sums_[static_cast<std::size_t>(p)]).count();
    };
    return PartTimes{s(Vm), s(Plant), s(Scheduler)};
  }

 private:
  using Clock = std::chrono::steady_clock;
  bool on_;
  Part current_ = Scheduler;
  Clock::time_point last_{};
  std::array<Clock::duration, 3> sums_{};
};

class PartScope {
 public:
  PartScope(PartClock& c, PartClock::Part p) : c_(c), was_(c.enter(p)) {}
  ~PartScope() { c_.enter(was_); }
  PartScope(const PartScope&) = delete;
  PartScope& operator=(const PartScope&) = delete;

 private:
  PartClock& c_;
  PartClock::Part was_;
};

}  // namespace simbot::scheduler
