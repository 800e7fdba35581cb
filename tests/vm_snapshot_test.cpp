// A VM is a value apart from its bus: a copy taken at any tick goes on as
// the original does, a restore from it replays the same run, and a reset
// (a reload) is the machine of a VM powered on at that tick, with the
// run's counters carried on. The programs are the thesis' ICEMAN (serial
// frames, eye reads, fast-forwarded delay loops) and a costatement program
// on the BIOS timer (PRT0's interrupt, TICK_TIMER).
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "support/test_host.h"
#include "vm/bytecode.h"

using namespace simbot;
using testkit::TestHost;
using vm::Tick;

namespace {

const vm::CostTable& costs() { return testkit::calibratedCosts(); }

constexpr vm::Tick kSecond = vm::kTicksPerSecond;

struct Program {
  const char* name;
  std::string path;
};

const Program kPrograms[] = {
    {"iceman", SIMBOT_SHARED_DIR "/programs/iceman.dc"},
    {"costate_hunter", SIMBOT_SOURCE_DIR "/programs/costate_hunter.dc"},
};

// What a host saw of a run: every port write, send and interrupt.
void expectSameRun(const TestHost& a, const TestHost& b) {
  ASSERT_EQ(a.outs.size(), b.outs.size());
  for (size_t i = 0; i < a.outs.size(); ++i) {
    EXPECT_EQ(a.outs[i].tick, b.outs[i].tick) << i;
    EXPECT_EQ(a.outs[i].port, b.outs[i].port) << i;
    EXPECT_EQ(a.outs[i].value, b.outs[i].value) << i;
  }
  EXPECT_EQ(a.sends, b.sends);
  EXPECT_EQ(a.sentBytes, b.sentBytes);
  ASSERT_EQ(a.events.size(), b.events.size());
  for (size_t i = 0; i < a.events.size(); ++i) {
    EXPECT_EQ(a.events[i].tick, b.events[i].tick) << i;
    EXPECT_EQ(a.events[i].irq, b.events[i].irq) << i;
  }
}

TEST(VmSnapshot, ACopyGoesOnAsTheOriginalAndARestoreReplaysIt) {
  for (const Program& p : kPrograms) {
    SCOPED_TRACE(p.name);
    const vm::Image image = testkit::compileFileOrDie(p.path);
    TestHost host;
    vm::Vm v(image, host, costs());
    host.runUntil(v, 3 * kSecond / 2);
    ASSERT_EQ(v.fault(), nullptr);

    // The snapshot: the VM and the host's own state (its pending requests).
    TestHost savedHost = host;
    const vm::Vm saved(v, savedHost);
    EXPECT_TRUE(saved == v);

    TestHost copyHost = host;
    vm::Vm copy(v, copyHost);
    host.runUntil(v, 4 * kSecond);
    copyHost.runUntil(copy, 4 * kSecond);
    EXPECT_TRUE(copy == v);
    expectSameRun(host, copyHost);
    // The run went on past the snapshot: it is a different state now.
    EXPECT_FALSE(saved == v);
    EXPECT_GT(host.events.size(), savedHost.events.size());

    // Restore: back to the snapshot, and the same 2.5 s again.
    const TestHost firstRun = host;
    host = savedHost;
    v.restore(saved);
    EXPECT_TRUE(saved == v);
    host.runUntil(v, 4 * kSecond);
    EXPECT_TRUE(copy == v);
    expectSameRun(host, firstRun);
  }
}

// The program (image, cost table, decode tables) is the VM's constant
// half: every copy shares it, and a copy holds only the machine's state. A
// breakpoint a copy sets is its own (its dispatch is copied then, not
// before); a copy runs only once attached to a bus.
TEST(VmSnapshot, ACopySharesTheProgramAndKeepsItsBreakpointsToItself) {
  const vm::Image image = testkit::compileFileOrDie(SIMBOT_SHARED_DIR "/programs/iceman.dc");
  TestHost host;
  vm::Vm v(image, host, costs());
  host.runUntil(v, kSecond / 2);
  const vm::Vm unattached(v);
  EXPECT_TRUE(unattached.sharesProgram(v));
  EXPECT_TRUE(unattached == v);
  vm::Vm idle(unattached);
  EXPECT_THROW(idle.run(v.now() + 1), std::logic_error);
  // Another VM of the same image decodes it again: the same machine, not
  // the same program.
  TestHost otherHost;
  const vm::Vm other(image, otherHost, costs());
  EXPECT_FALSE(other.sharesProgram(v));

  // ICEMAN's main calls read() before its search: a breakpoint there.
  uint32_t read = 0;
  for (const vm::Symbol& s : image.symbols)
    if (s.kind == vm::Symbol::Kind::Function && s.name == "read") read = s.address;
  ASSERT_GT(read, 0u);
  TestHost copyHost = host;
  vm::Vm copy(v, copyHost);
  copy.setBreakpoint(read);
  EXPECT_TRUE(copy.sharesProgram(v));
  ASSERT_EQ(copyHost.runUntil(copy, 30 * kSecond), vm::Stop::Breakpoint);
  EXPECT_EQ(copy.pc(), read);
  EXPECT_NE(host.runUntil(v, copy.now()), vm::Stop::Breakpoint);
  // The original ran the same instructions up to there, and on past it.
  host.runUntil(v, copy.now() + kSecond);
  EXPECT_GT(v.now(), copy.now());
  EXPECT_EQ(v.fault(), nullptr);
}

TEST(VmReset, IsTheMachineOfAVmPoweredOnThenWithTheCountersCarriedOn) {
  for (const Program& p : kPrograms) {
    SCOPED_TRACE(p.name);
    const vm::Image image = testkit::compileFileOrDie(p.path);
    TestHost host;
    vm::Vm v(image, host, costs());
    v.enableProfile();
    // Main's return, as the scheduler sets it (neither program returns).
    const uint32_t mainReturn =
        image.entry + static_cast<uint32_t>(vm::instructionSize(vm::Op::CALL));
    v.setBreakpoint(mainReturn);
    host.runUntil(v, kSecond);
    const vm::Tick t = v.now();
    const uint64_t instructions = v.stats().instructions;
    ASSERT_GT(instructions, 0u);

    v.reset(t);
    TestHost freshHost;
    vm::Vm fresh(image, freshHost, costs(), t);
    fresh.enableProfile();
    fresh.setBreakpoint(mainReturn);
    EXPECT_EQ(v.now(), t);
    EXPECT_TRUE(v.sameMachine(fresh));
    // A run that runs nothing builds the fast path's tables, a cache: still
    // the same machine.
    fresh.run(t);
    EXPECT_TRUE(v.sameMachine(fresh));
    // The counters are the whole run's.
    EXPECT_FALSE(v == fresh);
    EXPECT_EQ(v.stats().instructions, instructions);
    // Powered on at another tick is another machine (the clock, PRT0).
    TestHost otherHost;
    vm::Vm atZero(image, otherHost, costs());
    atZero.enableProfile();
    atZero.setBreakpoint(mainReturn);
    EXPECT_FALSE(v.sameMachine(atZero));

    // From there both run alike; the reset one's counters are the sums.
    TestHost resetHost;
    vm::Vm reloaded(v, resetHost);
    resetHost.runUntil(reloaded, t + 2 * kSecond);
    freshHost.runUntil(fresh, t + 2 * kSecond);
    EXPECT_TRUE(reloaded.sameMachine(fresh));
    expectSameRun(resetHost, freshHost);
    EXPECT_EQ(reloaded.stats().instructions, instructions + fresh.stats().instructions);
  }
}

// The first timer acceptance at or after `from`.
Tick firstTimerAcceptance(const TestHost& host, Tick from) {
  for (const auto& e : host.events)
    if (e.accepted && e.irq == vm::Irq::Timer && e.tick >= from) return e.tick;
  return -1;
}

// PRT0 ticks every kPrtTicks = 9,216,000 / 1,024 = 9,000 ticks from the
// power-on: the first timer request of a VM powered on at 0 is at 9,000,
// of one reset at t at t + 9,000, and each is accepted at the first
// instruction boundary at or after it (here within 200 ticks: two steps of
// at most 100 T-states, or one instruction).
TEST(VmReset, PrtTicksFromTheReset) {
  const vm::Image image =
      testkit::compileFileOrDie(SIMBOT_SOURCE_DIR "/programs/costate_hunter.dc");
  ASSERT_TRUE(image.timer.used());
  TestHost host;
  vm::Vm v(image, host, costs());
  host.runUntil(v, 20'000);
  const Tick first = firstTimerAcceptance(host, 0);
  EXPECT_GE(first, 9'000);
  EXPECT_LT(first, 9'200);

  host.runUntil(v, kSecond / 3);
  const Tick t = v.now();
  v.reset(t);
  TestHost afterReset;
  vm::Vm reloaded(v, afterReset);
  afterReset.runUntil(reloaded, t + 20'000);
  const Tick again = firstTimerAcceptance(afterReset, t);
  EXPECT_GE(again, t + 9'000);
  EXPECT_LT(again, t + 9'200);
}

}  // namespace
