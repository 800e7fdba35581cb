// The VM's runs and their horizons on hand-assembled bytecode: where a run
// stops, the continuation that carries it through the horizons a host
// gives (a robot that runs alone), and the horizons it takes without
// asking.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "support/assembler.h"
#include "support/test_host.h"

using namespace simbot;
using simbot::testkit::Assembler;
using simbot::testkit::TestHost;
using vm::Op;
using vm::Stop;

namespace {

const vm::CostTable& costs() { return testkit::calibratedCosts(); }
uint32_t cost(Op op) { return testkit::calibratedCost(op); }

TEST(Vm, RunStopsAtFirstBoundaryAtOrAfterHorizon) {
  Assembler a;
  a.bind("loop").op(Op::DBG).jump(Op::JMP, "loop");
  const auto img = a.finish();
  TestHost host;
  vm::Vm v(img, host, costs());
  const vm::Tick until = 1000;
  EXPECT_EQ(v.run(until), Stop::Horizon);
  const vm::Tick pair = cost(Op::DBG) + cost(Op::JMP);
  // Every instruction starting before `until` ran, and no more.
  EXPECT_GE(v.now(), until);
  EXPECT_LT(v.now() - std::max<vm::Tick>(cost(Op::DBG), cost(Op::JMP)), until);
  EXPECT_EQ(v.now() % pair == 0 || v.now() % pair == cost(Op::DBG), true);
}

TEST(Vm, ContinuationCarriesTheRunThroughTheHorizonsItGives) {
  // DBG; JMP loop: boundaries at k x (DBG + JMP) and k x (DBG + JMP) + DBG.
  // A Continuation asked at horizons 1000 and 2500 gives 2500 and 4000,
  // then ends the run: it is asked at the first boundary at or after each,
  // and the run stops at the first at or after 4000, as three runs would.
  Assembler a;
  a.bind("loop").op(Op::DBG).jump(Op::JMP, "loop");
  const auto img = a.finish();
  const vm::Tick pair = cost(Op::DBG) + cost(Op::JMP);
  const auto firstBoundaryFrom = [&](vm::Tick h) {
    const vm::Tick k = h / pair;
    if (k * pair >= h) return k * pair;
    return k * pair + cost(Op::DBG) >= h ? k * pair + cost(Op::DBG) : (k + 1) * pair;
  };
  vm::Tick horizon = 1000;
  struct Horizons final : vm::Continuation {
    using Continuation::Continuation;
    vm::Vm* v = nullptr;
    std::vector<vm::Tick> reached, at;
    vm::Tick nextHorizon(vm::Tick h) override {
      reached.push_back(h);
      at.push_back(v->now());
      return h == 1000 ? 2500 : h == 2500 ? 4000 : h;
    }
  } horizons{horizon};
  TestHost host;
  vm::Vm v(img, host, costs());
  horizons.v = &v;
  EXPECT_EQ(v.run(1000, &horizons), Stop::Horizon);
  EXPECT_EQ(horizons.reached, (std::vector<vm::Tick>{1000, 2500, 4000}));
  EXPECT_EQ(horizons.at, (std::vector<vm::Tick>{firstBoundaryFrom(1000), firstBoundaryFrom(2500),
                                                firstBoundaryFrom(4000)}));
  EXPECT_EQ(v.now(), firstBoundaryFrom(4000));
  TestHost other;
  vm::Vm w(img, other, costs());
  for (const vm::Tick h : {1000, 2500, 4000}) EXPECT_EQ(w.run(h), Stop::Horizon);
  EXPECT_TRUE(v.sameMachine(w));

  // A halted robot's run ends at its horizon: it is not asked.
  Assembler b;
  b.op(Op::HALT);
  const auto halts = b.finish();
  vm::Vm u(halts, host, costs());
  horizons.reached.clear();
  horizons.v = &u;
  EXPECT_EQ(u.run(1000, &horizons), Stop::Halted);
  EXPECT_TRUE(horizons.reached.empty());
}

// A continuation that asks at every horizon (cap never set) and one that
// gives the rule once (cap, step) lead a run through the same horizons.
// For JMP to itself (boundaries at k x JMP) they are, by hand,
// h0 = 1000, h(k+1) = min(40000, ceil(hk / JMP) x JMP + 1500); the second
// is asked at the first and at the cap only. With divisions in the loop
// and an outport after every twelve, the horizons it is asked at (the
// first after each bus call) are the asking run's. With outport in the
// loop (a bus call in every sub-round) it is asked at every one.
TEST(Vm, HorizonsTakenWithoutAskingAreTheOnesTheContinuationGives) {
  static constexpr vm::Tick kCap = 40000, kStep = 1500;
  struct Horizons final : vm::Continuation {
    using Continuation::Continuation;
    vm::Vm* v = nullptr;
    bool givesRule = false;
    vm::Tick upTo = INT64_MAX;
    std::vector<vm::Tick> asked;
    vm::Tick nextHorizon(vm::Tick h) override {
      asked.push_back(h);
      if (h >= kCap) return h;
      if (givesRule) {
        cap = kCap;
        step = kStep;
        unaskedUpTo = upTo;
      }
      horizon = std::min(kCap, v->now() + kStep);
      return horizon;
    }
  };
  struct Runs {
    std::vector<vm::Tick> asking, ruled;  // the horizons each was asked at
    uint64_t taken = 0;
  };
  const auto runBoth = [](const vm::Image& img, vm::Tick upTo = INT64_MAX) {
    TestHost host, otherHost;
    vm::Vm asks(img, host, costs()), rule(img, otherHost, costs());
    vm::Tick h1 = 1000, h2 = 1000;
    Horizons a{h1}, r{h2};
    a.v = &asks;
    r.v = &rule;
    r.givesRule = true;
    r.upTo = upTo;
    EXPECT_EQ(asks.run(1000, &a), Stop::Horizon);
    EXPECT_EQ(rule.run(1000, &r), Stop::Horizon);
    EXPECT_EQ(h1, kCap);
    EXPECT_EQ(h2, kCap);
    EXPECT_TRUE(rule.sameMachine(asks));
    return Runs{a.asked, r.asked, r.taken};
  };
  Assembler quiet;
  quiet.bind("loop").jump(Op::JMP, "loop");
  const Runs q = runBoth(quiet.finish());
  const vm::Tick jmp = cost(Op::JMP);
  std::vector<vm::Tick> expected{1000};
  while (expected.back() < kCap)
    expected.push_back(std::min(kCap, (expected.back() + jmp - 1) / jmp * jmp + kStep));
  EXPECT_EQ(q.asking, expected);
  EXPECT_EQ(q.ruled, (std::vector<vm::Tick>{1000, kCap}));
  EXPECT_EQ(q.taken, expected.size() - 2);
  // With unaskedUpTo = 20,000 (another robot stops sitting out after it)
  // it is asked at the first horizon and at every one whose next lies
  // past 20,000: by hand, the ones of `expected` followed by one past it.
  const Runs late = runBoth(quiet.finish(), 20000);
  EXPECT_EQ(late.asking, expected);
  std::vector<vm::Tick> fromAsk{1000};
  for (size_t k = 1; k < expected.size(); ++k)
    if (k + 1 == expected.size() || expected[k + 1] > 20000) fromAsk.push_back(expected[k]);
  EXPECT_EQ(late.ruled, fromAsk);
  EXPECT_GT(fromAsk.size(), 3u);

  // Divisions (a long instruction, its steps at most kMaxRunOvershoot
  // apart) and an outport every twelve: horizons fall between a
  // division's steps too, and the first after each bus call is asked, so
  // that where the unasked ones led shows: every horizon asked is the
  // asking run's, and the two together are all of its horizons.
  Assembler divides;
  divides.bind("loop");
  for (int k = 0; k < 12; ++k)
    divides.op(Op::PUSHW, 1000).op(Op::PUSHW, 7).op(Op::DIVW).op(Op::POP);
  divides.op(Op::PUSHW, vm::kPortPIODB).op(Op::PUSHW, 0x88).lib(vm::Lib::OUTPORT, 2);
  divides.jump(Op::JMP, "loop");
  ASSERT_GT(cost(Op::DIVW), 2 * vm::kMaxRunOvershoot);
  const Runs d = runBoth(divides.finish());
  EXPECT_GT(d.taken, 0u);
  EXPECT_GT(d.ruled.size(), 2u);
  EXPECT_EQ(d.taken + d.ruled.size(), d.asking.size());
  EXPECT_TRUE(std::includes(d.asking.begin(), d.asking.end(), d.ruled.begin(), d.ruled.end()));

  // A breakpoint in the loop: the host may act at every stop (a line
  // injection, main's return), so each run's first horizon is asked.
  Assembler stops;
  stops.bind("loop").op(Op::DBG).jump(Op::JMP, "loop");
  const vm::Image stopping = stops.finish();
  TestHost host;
  vm::Vm v(stopping, host, costs());
  v.setBreakpoint(0);
  vm::Tick h = 1000;
  Horizons ruled{h};
  ruled.v = &v;
  ruled.givesRule = true;
  int runs = 0;
  while (v.run(h, &ruled) == Stop::Breakpoint) ++runs;
  EXPECT_GT(runs, 100);
  EXPECT_EQ(ruled.taken, 0u);
  EXPECT_EQ(h, kCap);

  Assembler busy;
  busy.bind("loop").op(Op::PUSHW, vm::kPortPIODB).op(Op::PUSHW, 0x88);
  busy.lib(vm::Lib::OUTPORT, 2).jump(Op::JMP, "loop");
  const Runs b = runBoth(busy.finish());
  EXPECT_EQ(b.ruled, b.asking);
  EXPECT_GT(b.asking.size(), 4u);
  EXPECT_EQ(b.taken, 0u);
}

TEST(Vm, BusAccessNeverHappensAtOrAfterTheHorizon) {
  Assembler a;
  a.op(Op::PUSHW, vm::kPortPIODB).op(Op::PUSHW, 0x88).lib(vm::Lib::OUTPORT, 2).op(Op::HALT);
  const auto img = a.finish();
  TestHost host;
  vm::Vm v(img, host, costs());
  const vm::Tick callEnd =
      2 * cost(Op::PUSHW) + cost(Op::LIB) + costs().libCall[static_cast<int>(vm::Lib::OUTPORT)];
  // The horizon falls inside the call sequence: the write waits for the
  // next run, and happens at the end of the sequence.
  EXPECT_EQ(v.run(callEnd - 1), Stop::Horizon);
  EXPECT_TRUE(host.outs.empty());
  EXPECT_EQ(v.run(callEnd + 1), Stop::Halted);
  ASSERT_EQ(host.outs.size(), 1u);
  EXPECT_EQ(host.outs[0].tick, callEnd);
  EXPECT_EQ(host.outs[0].value, 0x88);
}

}  // namespace
