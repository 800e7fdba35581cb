// The scheduler's event queue: one queue of discrete events in integer ticks
// of the 9.216 MHz clock.
//
// Ordering rule (the only one): events are taken by
//   1. tick, earliest first;
//   2. event class, in the order of the EventClass enum below;
//   3. insertion sequence, first inserted first.
// The key is total, so the same insertions give the same order on every run,
// whatever the heap does with equal elements. Causality is asserted: an
// event may not be scheduled before the tick of the last event taken.
#pragma once
#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "timebase/tick.h"

namespace simbot::scheduler {

using timebase::Tick;

// Classes in the order they run at one tick. Plant events first (a detector
// crossing at tick t is seen by anything else at t), then the bytes the
// serial ports finish, then motor latches that those bytes caused, then
// weapon and referee actions, injections, reloads of faulted robots (which
// start from a settled state), and last the observers (trace samples, the
// end of the round), so that they see the settled state.
enum class EventClass : uint8_t {
  Plant = 0,
  SerialByte = 1,
  MotorLatch = 2,
  Weapon = 3,
  Referee = 4,
  Injection = 5,
  Reload = 6,
  Sample = 7,
  EndOfRound = 8,
};

struct EventKey {
  Tick tick;
  EventClass cls;
  uint64_t seq;
  friend bool operator<(const EventKey& a, const EventKey& b) {
    if (a.tick != b.tick) return a.tick < b.tick;
    if (a.cls != b.cls) return a.cls < b.cls;
    return a.seq < b.seq;
  }
};

class CausalityError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

template <typename Payload>
class EventQueue {
 public:
  struct Entry {
    EventKey key;
    Payload payload;
  };

  void schedule(Tick tick, EventClass cls, Payload payload) {
    if (tick < now_)
      throw CausalityError("event scheduled at tick " + std::to_string(tick) + " before now (" +
                           std::to_string(now_) + ")");
    heap_.push_back(Entry{EventKey{tick, cls, nextSeq_++}, std::move(payload)});
    std::push_heap(heap_.begin(), heap_.end(), Later{});
  }
  bool empty() const { return heap_.empty(); }
  size_t size() const { return heap_.size(); }
  Tick nextTick() const { return heap_.front().key.tick; }
  const Entry& top() const { return heap_.front(); }
  Entry pop() {
    std::pop_heap(heap_.begin(), heap_.end(), Later{});
    Entry e = std::move(heap_.back());
    heap_.pop_back();
    now_ = e.key.tick;
    return e;
  }
  // The tick of the earliest event of any class but `cls`, or `none` if
  // there is none. A scan: the queue holds a handful of events.
  Tick nextTickExcept(EventClass cls, Tick none) const {
    Tick best = none;
    for (const Entry& e : heap_)
      if (e.key.cls != cls && e.key.tick < best) best = e.key.tick;
    return best;
  }
  Tick now() const { return now_; }

 private:
  struct Later {
    bool operator()(const Entry& a, const Entry& b) const { return b.key < a.key; }
  };
  std::vector<Entry> heap_;  // a binary heap under Later: top at front()
  uint64_t nextSeq_ = 0;
  Tick now_ = 0;
};

}  // namespace simbot::scheduler
