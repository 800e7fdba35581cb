// The scheduler's event queue: one queue of discrete events in integer ticks
// of the 9.216 MHz clock.
//
// Ordering rule (the only one): events are taken by
//   1. tick, earliest first;
//   2. event class, in the order of the EventClass enum below;
//   3. insertion sequence, first inserted first.
// The key is total, so the same insertions give the same order on every run,
// whatever the container does with equal elements. Causality is asserted: an
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
    const EventKey key{tick, cls, nextSeq_++};
    // Where it goes: after every later event. A scan from the earliest:
    // most new events (a byte's end, a reload) are among the earliest.
    auto at = events_.end();
    while (at != events_.begin() && (at - 1)->key < key) --at;
    events_.insert(at, Entry{key, std::move(payload)});
  }
  bool empty() const { return events_.empty(); }
  size_t size() const { return events_.size(); }
  Tick nextTick() const { return events_.back().key.tick; }
  const Entry& top() const { return events_.back(); }
  Entry pop() {
    Entry e = std::move(events_.back());
    events_.pop_back();
    now_ = e.key.tick;
    return e;
  }
  // The tick of the earliest event of any class but `cls`, or `none` if
  // there is none. A scan: the queue holds a handful of events.
  Tick nextTickExcept(EventClass cls, Tick none) const {
    Tick best = none;
    for (const Entry& e : events_)
      if (e.key.cls != cls && e.key.tick < best) best = e.key.tick;
    return best;
  }
  Tick now() const { return now_; }

 private:
  // Sorted by key, the latest first: the next event is the last. The
  // queue holds a handful of events, so an insertion's shift is short and
  // cheaper than a heap's sifting (and the order is the key's alone).
  std::vector<Entry> events_;
  uint64_t nextSeq_ = 0;
  Tick now_ = 0;
};

}  // namespace simbot::scheduler
