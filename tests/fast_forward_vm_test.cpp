// Fast-forward of delay loops at the VM level (issue 13): the loop is run
// in one step only where nothing can happen to the robot, so an interrupt
// requested at any tick inside the loop is accepted at the same boundary,
// and sees the same counter, as when every pass is stepped.
#include <gtest/gtest.h>

#include "support/test_host.h"

using namespace simbot;
using simbot::testkit::TestHost;
using vm::Irq;
using vm::Tick;

namespace {

const char* kDelayWithHandler = R"(#INT_VEC PIOA_VEC edge
int z, seen, seenAt;
interrupt reti edge() { seen = z; seenAt = 1; }
main()
{
    for (z = 0; z < 700; z++) ;
}
)";

struct Outcome {
  int seen;
  Tick accepted;
  Tick end;
  uint64_t instructions;
  int also;  // the int global named `also`, when one is
};

Outcome runWithEdgeAt(const vm::Image& img, Tick at, bool fastForward, const char* also = nullptr) {
  vm::CostTable table = testkit::calibratedCosts();
  table.knobs.fastForward = fastForward;
  TestHost host;
  host.schedule(at, Irq::Pio);
  vm::Vm v(img, host, table);
  EXPECT_EQ(host.runUntil(v, vm::kTicksPerSecond), vm::Stop::Halted);
  Tick accepted = -1;
  for (const auto& e : host.events)
    if (e.accepted && e.irq == Irq::Pio) accepted = e.tick;
  if (fastForward) {
    EXPECT_GT(v.stats().fastForwarded, 0u) << "request at " << at;
  }
  const auto word = [&v, &img](const char* name) {
    return static_cast<int16_t>(
        v.read16(static_cast<uint16_t>(testkit::symbol(img, name).address)));
  };
  return {word("seen"), accepted, v.now(), v.stats().instructions, also ? word(also) : 0};
}

// One pass costs 252 T-states (docs/cycle-model.md, "The cycle model"); a window of 20
// consecutive request ticks 100 passes into the loop covers boundaries
// inside a pass and between passes.
TEST(FastForward, EdgeAtEveryTickOfAWindowSeesTheSteppedCounter) {
  const auto img = testkit::compileOrDie(kDelayWithHandler);
  ASSERT_EQ(img.delayLoops.size(), 1u);
  const Tick start = 100 * 252 + 1000;
  for (Tick at = start; at < start + 20; ++at) {
    const Outcome fast = runWithEdgeAt(img, at, true);
    const Outcome stepped = runWithEdgeAt(img, at, false);
    EXPECT_EQ(fast.seen, stepped.seen) << "request at " << at;
    EXPECT_EQ(fast.accepted, stepped.accepted) << "request at " << at;
    EXPECT_EQ(fast.end, stepped.end) << "request at " << at;
    EXPECT_EQ(fast.instructions, stepped.instructions) << "request at " << at;
    // Accepted at the first boundary at or after the request: a pass has
    // seven, none more than 68 T-states apart (DBG with its hook).
    EXPECT_GE(fast.accepted, at);
    EXPECT_LT(fast.accepted, at + 68);
    EXPECT_GT(fast.seen, 90);
    EXPECT_LT(fast.seen, 110);
  }
}

// Without a request, the whole loop: 700 passes of 252 T-states and the
// final test (LDGW 29, PUSHW 22, LTW false, JZ taken) run as when stepped.
TEST(FastForward, WholeLoopEndsWhereSteppingEnds) {
  const auto img = testkit::compileOrDie("int z; main() { for (z = 0; z < 700; z++) ; }");
  vm::CostTable off = testkit::calibratedCosts();
  off.knobs.fastForward = false;
  TestHost h1, h2;
  vm::Vm fast(img, h1, testkit::calibratedCosts());
  vm::Vm stepped(img, h2, off);
  h1.runUntil(fast, vm::kTicksPerSecond);
  h2.runUntil(stepped, vm::kTicksPerSecond);
  const auto& z = testkit::symbol(img, "z");
  EXPECT_EQ(fast.read16(static_cast<uint16_t>(z.address)), 700);
  EXPECT_EQ(fast.stats().instructions, stepped.stats().instructions);
  EXPECT_EQ(fast.now(), stepped.now());
  // 700 passes x 7 instructions, the start-up stub (3), main's prologue and
  // the for's statement (DBG, PUSHW, STGW), the last test (4), RET's
  // constant and RET: the instruction count stepping gives.
  EXPECT_GT(fast.stats().instructions, 700u * 7u);
  // All passes but the measured one, and the one before the horizon, skipped.
  EXPECT_GE(fast.stats().fastForwarded, 690u * 7u);
  EXPECT_EQ(stepped.stats().fastForwarded, 0u);
}

// Vm::quietUntil, which lets the scheduler run longer rounds: stopped
// anywhere inside a measured delay loop, the VM names the arrival at the
// loop's top where the compare fails, and no bus access comes before it.
// The oracle: the first arrival at the top, T0, found by stepping tick by
// tick with fast-forward off, plus 700 passes of 252 T-states.
TEST(FastForward, QuietUntilIsTheLoopsExitAndNoAccessComesSooner) {
  const auto img =
      testkit::compileOrDie("int z; main() { for (z = 0; z < 700; z++) ; outport(PIODB, 1); }");
  ASSERT_EQ(img.delayLoops.size(), 1u);
  const uint32_t top = img.delayLoops[0].top;
  vm::CostTable off = testkit::calibratedCosts();
  off.knobs.fastForward = false;
  TestHost stepHost;
  vm::Vm stepped(img, stepHost, off);
  Tick t0 = 0;
  while (stepped.pc() != top) stepped.run(++t0);
  t0 = stepped.now();
  const Tick exitArrival = t0 + 700 * 252;

  TestHost host;
  vm::Vm v(img, host, testkit::calibratedCosts());
  int inside = 0;
  for (Tick h = 997; host.outs.empty(); h += 997) {
    v.run(h);
    const Tick q = v.quietUntil();
    EXPECT_GE(q, v.now());
    const bool inLoop = v.pc() >= top && v.pc() < img.delayLoops[0].exit;
    // From the second pass on (the first one measures the pass).
    if (inLoop && v.now() >= t0 + 2 * 252) {
      ++inside;
      EXPECT_EQ(q, exitArrival) << "stopped at " << v.now();
    } else {
      EXPECT_EQ(q, v.now()) << "stopped at " << v.now();
    }
  }
  EXPECT_GT(inside, 100);
  ASSERT_EQ(host.outs.size(), 1u);
  // The access comes where stepping puts it, after the exit arrival (the
  // final test, LDGW PUSHW LTW JZ, and the outport's instructions).
  stepHost.runUntil(stepped, vm::kTicksPerSecond);
  ASSERT_EQ(stepHost.outs.size(), 1u);
  EXPECT_EQ(host.outs[0].tick, stepHost.outs[0].tick);
  EXPECT_GT(host.outs[0].tick, exitArrival);
}

// A request the host raises ends the quiet at once.
TEST(FastForward, QuietUntilIsNowWhileARequestIsPending) {
  const auto img = testkit::compileOrDie(kDelayWithHandler);
  TestHost host;
  vm::Vm v(img, host, testkit::calibratedCosts());
  v.run(50'000);
  ASSERT_GT(v.quietUntil(), v.now() + 100'000);
  v.request(Irq::Pio);
  EXPECT_EQ(v.quietUntil(), v.now());
}

}  // namespace

namespace {

// ICEMAN's delay loops count an unsigned long (`for(count=0;count<1000;
// count++);`): the 32-bit shape fast-forwards as exactly.
TEST(FastForward, LongCountersTooAndAnEdgeSeesTheSteppedCount) {
  const auto img = testkit::compileOrDie(R"(#INT_VEC PIOA_VEC edge
unsigned long count, seen;
interrupt reti edge() { seen = count; }
main()
{
    for (count = 0; count < 50000; count++) ;
}
)");
  ASSERT_EQ(img.delayLoops.size(), 1u);
  const auto& seen = testkit::symbol(img, "seen");
  for (Tick at : {Tick{1'000'000}, Tick{1'000'001}, Tick{7'777'777}}) {
    uint32_t counts[2];
    Tick ends[2];
    for (int mode = 0; mode < 2; ++mode) {
      vm::CostTable table = testkit::calibratedCosts();
      table.knobs.fastForward = mode == 0;
      TestHost host;
      host.schedule(at, Irq::Pio);
      vm::Vm v(img, host, table);
      host.runUntil(v, 4 * vm::kTicksPerSecond);
      counts[mode] = v.read32(static_cast<uint16_t>(seen.address));
      ends[mode] = v.now();
      if (mode == 0) {
        EXPECT_GT(v.stats().fastForwarded, 0u);
      }
    }
    EXPECT_EQ(counts[0], counts[1]) << "request at " << at;
    EXPECT_EQ(ends[0], ends[1]) << "request at " << at;
    EXPECT_GT(counts[0], 0u);
  }
}

}  // namespace

namespace {

// A loop entered right after EI with a request already pending (raised
// while interrupts were disabled): the request waits only for EI's shadow
// and is accepted inside the loop's first pass (nodebug: no DBG between EI
// and the loop's top). From the second entry on,
// the loop's pass is known, and fast-forward must not apply passes before
// that acceptance. Oracle: every pass stepped (--no-fast-forward), for a
// request at each tick around the third entry's DI section.
TEST(FastForward, ARequestPendingAtEntryAfterEiIsAcceptedInTheFirstPass) {
  const auto img = testkit::compileOrDie(R"(#INT_VEC PIOA_VEC edge
int i, x, seen, seenX;
interrupt reti edge() { seen = i; seenX = x; }
nodebug main()
{
    while (x < 4) {
        i = 0;
        DI();
        x++;
        EI();
        for (; i < 500; i++) ;
    }
}
)");
  ASSERT_EQ(img.delayLoops.size(), 1u);
  const auto& x = testkit::symbol(img, "x");
  // Where the third entry's x++ has run: stepped tick by tick.
  vm::CostTable off = testkit::calibratedCosts();
  off.knobs.fastForward = false;
  TestHost probeHost;
  vm::Vm probe(img, probeHost, off);
  Tick t = 0;
  while (probe.read16(static_cast<uint16_t>(x.address)) < 3) probe.run(++t);
  const Tick third = probe.now();
  int insideWindow = 0;
  for (Tick at = third - 150; at < third + 150; ++at) {
    const Outcome fast = runWithEdgeAt(img, at, true, "seenX");
    const Outcome stepped = runWithEdgeAt(img, at, false, "seenX");
    EXPECT_EQ(fast.accepted, stepped.accepted) << "request at " << at;
    EXPECT_EQ(fast.seen, stepped.seen) << "request at " << at;
    EXPECT_EQ(fast.end, stepped.end) << "request at " << at;
    EXPECT_EQ(fast.instructions, stepped.instructions) << "request at " << at;
    if (stepped.also == 3 && stepped.seen == 0) ++insideWindow;  // accepted at the loop's top
  }
  // Some of the requests fell inside DI ... EI and waited for the shadow.
  EXPECT_GT(insideWindow, 0);
}

}  // namespace

namespace {

// An unsigned counter that leaves its loop at 0xFFFF and enters it again
// at 0: the arrival at the top is the successor of the exit's (0xFFFF + 1
// wraps to 0), but what came between is no pass, and its time must not be
// taken for one. Oracle: every pass stepped.
TEST(FastForward, AWrappedCounterAtReentryIsNoMeasuredPass) {
  const auto img = testkit::compileOrDie(R"(unsigned int u;
int n;
main()
{
    while (n < 3) {
        for (u = 0; u < 0xFFFF; u++) ;
        n++;
    }
}
)");
  ASSERT_EQ(img.delayLoops.size(), 1u);
  vm::CostTable off = testkit::calibratedCosts();
  off.knobs.fastForward = false;
  TestHost h1, h2;
  vm::Vm fast(img, h1, testkit::calibratedCosts());
  vm::Vm stepped(img, h2, off);
  h1.runUntil(fast, 10 * vm::kTicksPerSecond);
  h2.runUntil(stepped, 10 * vm::kTicksPerSecond);
  EXPECT_EQ(fast.now(), stepped.now());
  EXPECT_EQ(fast.stats().instructions, stepped.stats().instructions);
  EXPECT_GT(fast.stats().fastForwarded, 3u * 65000u * 6u);
}

}  // namespace

namespace {

// A robot stopped at a breakpoint on a delay loop's top, the breakpoint
// removed and the robot run on exactly to a pass's landing (passes applied
// at that first arrival), stands at the top again: a breakpoint set there
// now stops it at once, as stepping would, not one pass later.
TEST(FastForward, ABreakpointSetAgainAfterAppliedPassesStopsAtOnce) {
  const auto img = testkit::compileOrDie("int z; main() { for (z = 0; z < 700; z++) ; }");
  ASSERT_EQ(img.delayLoops.size(), 1u);
  const uint32_t top = img.delayLoops[0].top;
  TestHost host;
  vm::Vm v(img, host, testkit::calibratedCosts());
  v.run(100 * 252);  // the pass is measured
  v.setBreakpoint(top);
  ASSERT_EQ(v.run(vm::kTicksPerSecond), vm::Stop::Breakpoint);
  ASSERT_EQ(v.pc(), top);
  v.setBreakpoint(top, false);
  const Tick landing = v.now() + 10 * 252;  // a pass is 252 T-states
  v.run(landing);
  ASSERT_EQ(v.now(), landing);
  ASSERT_EQ(v.pc(), top);
  v.setBreakpoint(top);
  EXPECT_EQ(v.run(vm::kTicksPerSecond), vm::Stop::Breakpoint);
  EXPECT_EQ(v.now(), landing);
}

}  // namespace
