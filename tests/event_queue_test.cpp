// The event queue's ordering rule and its causality check.
#include "scheduler/event_queue.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <tuple>
#include <vector>

using namespace simbot::scheduler;

TEST(EventQueue, OrdersByTickThenClassThenInsertion) {
  EventQueue<int> q;
  q.schedule(10, EventClass::Sample, 1);
  q.schedule(10, EventClass::Plant, 2);
  q.schedule(5, EventClass::EndOfRound, 3);
  q.schedule(10, EventClass::Plant, 4);
  q.schedule(10, EventClass::SerialByte, 5);
  std::vector<int> order;
  while (!q.empty()) order.push_back(q.pop().payload);
  EXPECT_EQ(order, (std::vector<int>{3, 2, 4, 5, 1}));
}

TEST(EventQueue, RejectsAnEventBeforeNow) {
  EventQueue<int> q;
  q.schedule(100, EventClass::Plant, 1);
  q.pop();
  EXPECT_EQ(q.now(), 100);
  EXPECT_THROW(q.schedule(99, EventClass::Plant, 2), CausalityError);
  EXPECT_NO_THROW(q.schedule(100, EventClass::Plant, 3));
}

// Schedules and pops interleaved, as the match does, against the rule
// taken literally: each pop is the least (tick, class, insertion number)
// of the events still held, found by a scan of a plain list.
TEST(EventQueue, InterleavedAgreesWithTheRuleByScan) {
  EventQueue<int> q;
  struct Held {
    Tick tick;
    EventClass cls;
    int number;
  };
  std::vector<Held> held;
  uint64_t x = 12345;
  const auto next = [&x] {
    x = x * 6364136223846793005ull + 1442695040888963407ull;
    return x >> 33;
  };
  int number = 0;
  Tick now = 0;
  for (int step = 0; step < 5000; ++step) {
    if (held.empty() || next() % 3 != 0) {
      const Tick tick = now + static_cast<Tick>(next() % 20);
      const auto cls = static_cast<EventClass>(next() % 9);
      q.schedule(tick, cls, number);
      held.push_back({tick, cls, number++});
      continue;
    }
    const auto least = std::min_element(held.begin(), held.end(), [](const Held& a, const Held& b) {
      return std::tie(a.tick, a.cls, a.number) < std::tie(b.tick, b.cls, b.number);
    });
    ASSERT_EQ(q.nextTick(), least->tick);
    const auto e = q.pop();
    ASSERT_EQ(e.payload, least->number) << "at step " << step;
    now = least->tick;
    held.erase(least);
  }
}
