// The event queue's ordering rule and its causality check.
#include "scheduler/event_queue.h"

#include <gtest/gtest.h>

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
