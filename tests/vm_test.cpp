// VM semantics on hand-assembled bytecode: cycle charging, interrupt
// acceptance (boundaries, EI shadow, priority, nesting, RETI epilogue),
// interruptible long operations and faults.
#include <gtest/gtest.h>

#include "support/assembler.h"
#include "support/test_host.h"

using namespace simbot;
using simbot::testkit::Assembler;
using simbot::testkit::TestHost;
using vm::Irq;
using vm::Op;
using vm::Stop;

namespace {

const vm::CostTable& costs() { return testkit::calibratedCosts(); }
uint32_t cost(Op op) { return costs().op[static_cast<int>(op)]; }

// A handler at label "handler" that counts into `counter` and returns.
void countingHandler(Assembler& a, uint16_t counter) {
  a.bind("handler").op(Op::INCGW, counter).op(Op::RETI);
  a.image.vectors.push_back({vm::kVecPIOA, static_cast<uint16_t>(a.label("handler")), "handler"});
}

TEST(Vm, ChargesEachInstructionItsCost) {
  Assembler a;
  a.op(Op::PUSHW, 7).op(Op::POP).op(Op::HALT);
  const auto img = a.finish();
  TestHost host;
  vm::Vm v(img, host, costs());
  EXPECT_EQ(v.run(1'000'000), Stop::Halted);
  EXPECT_TRUE(v.halted());
  // HALT's cost is charged, then the halted VM idles to the horizon.
  EXPECT_EQ(v.stats().instructions, 3u);
  EXPECT_EQ(v.now(), 1'000'000);
}

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

TEST(Vm, RequestAcceptedAtFirstBoundaryAtOrAfterIt) {
  Assembler a;
  const uint16_t counter = a.data(2);
  a.bind("loop").op(Op::DBG).jump(Op::JMP, "loop");
  countingHandler(a, counter);
  const auto img = a.finish();
  TestHost host;
  vm::Vm v(img, host, costs());
  const vm::Tick request = 1001;
  host.schedule(request, Irq::Pio);
  host.runUntil(v, 5000);
  ASSERT_FALSE(host.events.empty());
  const auto& accepted = host.events.front();
  ASSERT_TRUE(accepted.accepted);
  // Boundaries of the loop are at multiples of (DBG+JMP) and after each DBG.
  const vm::Tick pair = cost(Op::DBG) + cost(Op::JMP);
  vm::Tick boundary = 0;
  while (boundary < request) {
    const vm::Tick inPair = boundary % pair;
    boundary += inPair == 0 ? cost(Op::DBG) : cost(Op::JMP);
  }
  EXPECT_EQ(accepted.tick, boundary);
  EXPECT_EQ(v.read16(counter), 1);
}

TEST(Vm, HandlerStartsAfterAcceptanceCost) {
  Assembler a;
  const uint16_t counter = a.data(2);
  a.bind("loop").op(Op::DBG).jump(Op::JMP, "loop");
  countingHandler(a, counter);
  const auto img = a.finish();
  TestHost host;
  vm::Vm v(img, host, costs());
  v.setBreakpoint(a.label("handler"));
  v.request(Irq::Pio, vm::kVecPIOA);
  EXPECT_EQ(v.run(10'000), Stop::Breakpoint);
  EXPECT_EQ(v.now(), costs().interruptAccept);
  EXPECT_FALSE(v.interruptsEnabled());
}

TEST(Vm, EiShadowDelaysAcceptanceByOneInstruction) {
  Assembler a;
  const uint16_t counter = a.data(2);
  const uint16_t marker = a.data(2);
  a.op(Op::DI).op(Op::EI).op(Op::INCGW, marker).op(Op::INCGW, marker);
  a.bind("loop").op(Op::DBG).jump(Op::JMP, "loop");
  countingHandler(a, counter);
  const auto img = a.finish();
  TestHost host;
  vm::Vm v(img, host, costs());
  EXPECT_EQ(v.run(1), Stop::Horizon);  // DI only
  v.request(Irq::Pio, vm::kVecPIOA);   // pending, masked by DI
  v.setBreakpoint(a.label("handler"));
  EXPECT_EQ(v.run(10'000), Stop::Breakpoint);
  // DI, EI and the one instruction in EI's shadow ran before acceptance.
  EXPECT_EQ(v.read16(marker), 1);
  EXPECT_EQ(host.events.front().tick, cost(Op::DI) + cost(Op::EI) + cost(Op::INCGW));
}

TEST(Vm, EpilogueReenablesInterruptsUnlessKnobDropsIt) {
  for (bool epilogueEi : {true, false}) {
    auto knobs = vm::calibratedKnobs();
    knobs.epilogueEi = epilogueEi;
    const auto table = vm::makeCostTable(knobs);
    Assembler a;
    const uint16_t counter = a.data(2);
    a.bind("loop").op(Op::DBG).jump(Op::JMP, "loop");
    countingHandler(a, counter);
    const auto img = a.finish();
    TestHost host;
    vm::Vm v(img, host, table);
    v.request(Irq::Pio, vm::kVecPIOA);
    host.runUntil(v, 2000);
    EXPECT_EQ(v.read16(counter), 1);
    EXPECT_EQ(v.interruptsEnabled(), epilogueEi);
  }
}

TEST(Vm, RequestPendingAtRetiIsAcceptedRightAfter) {
  Assembler a;
  const uint16_t counter = a.data(2);
  a.bind("loop").op(Op::DBG).jump(Op::JMP, "loop");
  countingHandler(a, counter);
  const auto img = a.finish();
  TestHost host;
  vm::Vm v(img, host, costs());
  v.request(Irq::Pio, vm::kVecPIOA);
  v.setBreakpoint(a.label("handler"));
  ASSERT_EQ(v.run(10'000), Stop::Breakpoint);
  v.request(Irq::Pio, vm::kVecPIOA);  // arrives while under service
  v.setBreakpoint(a.label("handler"), false);
  host.runUntil(v, 10'000);
  ASSERT_GE(host.events.size(), 3u);
  EXPECT_FALSE(host.events[1].accepted);  // first RETI
  EXPECT_TRUE(host.events[2].accepted);
  EXPECT_EQ(host.events[2].tick, host.events[1].tick);  // no instruction between
  EXPECT_EQ(v.read16(counter), 2);
}

TEST(Vm, PioHasPriorityOverSerial) {
  Assembler a;
  const uint16_t counter = a.data(2);
  a.bind("loop").op(Op::DBG).jump(Op::JMP, "loop");
  countingHandler(a, counter);
  const auto img = a.finish();
  TestHost host;
  vm::Vm v(img, host, costs());
  v.request(Irq::SerialTx);
  v.request(Irq::Pio, vm::kVecPIOA);
  host.runUntil(v, 5000);
  ASSERT_GE(host.events.size(), 4u);
  EXPECT_EQ(host.events[0].irq, Irq::Pio);
  EXPECT_EQ(host.events[2].irq, Irq::SerialTx);
}

TEST(Vm, HandlerThatEnablesInterruptsLetsSerialNest) {
  Assembler a;
  const uint16_t counter = a.data(2);
  a.bind("loop").op(Op::DBG).jump(Op::JMP, "loop");
  a.bind("handler").op(Op::EI);
  for (int i = 0; i < 20; ++i) a.op(Op::DBG);
  a.op(Op::INCGW, counter).op(Op::RETI);
  a.image.vectors.push_back({vm::kVecPIOA, static_cast<uint16_t>(a.label("handler")), "handler"});
  const auto img = a.finish();
  TestHost host;
  vm::Vm v(img, host, costs());
  v.request(Irq::Pio, vm::kVecPIOA);
  host.schedule(500, Irq::SerialTx);
  host.runUntil(v, 5000);
  ASSERT_GE(host.events.size(), 4u);
  EXPECT_EQ(host.events[0].irq, Irq::Pio);
  EXPECT_TRUE(host.events[1].accepted);
  EXPECT_EQ(host.events[1].irq, Irq::SerialTx);  // nested inside the PIO handler
  EXPECT_EQ(host.events[3].irq, Irq::Pio);
  EXPECT_FALSE(host.events[3].accepted);
}

TEST(Vm, LongOperationIsInterruptibleEvery100Tstates) {
  Assembler a;
  const uint16_t counter = a.data(2);
  const uint16_t result = a.data(4);
  a.op(Op::PUSHL, 1000000).op(Op::PUSHL, 7).op(Op::DIVL).op(Op::STGL, result).op(Op::HALT);
  countingHandler(a, counter);
  const auto img = a.finish();
  ASSERT_GT(cost(Op::DIVL), 100u);
  TestHost host;
  vm::Vm v(img, host, costs());
  const vm::Tick divStart = 2 * cost(Op::PUSHL);
  const vm::Tick request = divStart + 250;
  host.schedule(request, Irq::Pio);
  host.runUntil(v, 100'000);
  ASSERT_FALSE(host.events.empty());
  EXPECT_EQ(host.events[0].tick, divStart + 300);  // next internal step
  EXPECT_EQ(host.events[0].pc, 2u * vm::instructionSize(Op::PUSHL));
  EXPECT_EQ(v.read32(result), 1000000u / 7);
  EXPECT_EQ(v.read16(counter), 1);
}

TEST(Vm, StrcpyIsInterruptibleAndCompletesAfterTheHandler) {
  Assembler a;
  const uint16_t counter = a.data(2);
  const std::string text(120, 'x');
  const uint16_t src = a.string(text);
  const uint16_t dst = a.data(200);
  a.op(Op::PUSHW, dst).op(Op::PUSHW, src).lib(vm::Lib::STRCPY, 2).op(Op::POP).op(Op::HALT);
  countingHandler(a, counter);
  const auto img = a.finish();
  TestHost host;
  vm::Vm v(img, host, costs());
  const vm::Tick callEnd =
      2 * cost(Op::PUSHW) + cost(Op::LIB) + costs().libCall[static_cast<int>(vm::Lib::STRCPY)];
  host.schedule(callEnd + 150, Irq::Pio);
  host.runUntil(v, 100'000);
  ASSERT_FALSE(host.events.empty());
  const uint32_t unit = costs().libStep[static_cast<int>(vm::Lib::STRCPY)];
  const uint32_t perStep = 100 / unit;
  vm::Tick boundary = callEnd;
  while (boundary < callEnd + 150) boundary += perStep * unit;
  EXPECT_EQ(host.events[0].tick, boundary);
  EXPECT_LE(perStep * unit, 100u);
  for (size_t i = 0; i <= text.size(); ++i)
    EXPECT_EQ(v.read8(static_cast<uint16_t>(dst + i)), i < text.size() ? 'x' : 0);
}

TEST(Vm, HaltedVmStillTakesInterrupts) {
  Assembler a;
  const uint16_t counter = a.data(2);
  a.op(Op::HALT);
  countingHandler(a, counter);
  const auto img = a.finish();
  TestHost host;
  vm::Vm v(img, host, costs());
  host.schedule(50'000, Irq::Pio);
  host.runUntil(v, 100'000);
  EXPECT_TRUE(v.halted());
  EXPECT_EQ(v.read16(counter), 1);
  ASSERT_FALSE(host.events.empty());
  EXPECT_EQ(host.events[0].tick, 50'000);
}

void expectFault(Assembler& a, const std::string& message) {
  const auto img = a.finish();
  TestHost host;
  vm::Vm v(img, host, costs());
  EXPECT_EQ(v.run(1'000'000'000), Stop::Fault);
  ASSERT_NE(v.fault(), nullptr);
  EXPECT_NE(v.fault()->message.find(message), std::string::npos) << v.fault()->message;
  EXPECT_EQ(v.fault()->line, 7);
  const auto at = v.now();
  EXPECT_EQ(v.run(2'000'000'000), Stop::Fault);  // never runs again
  EXPECT_EQ(v.now(), at);
}

TEST(VmFault, DivisionByZero) {
  Assembler a;
  a.op(Op::PUSHW, 1).op(Op::PUSHW, 0);
  a.line = 7;
  a.op(Op::DIVW).op(Op::HALT);
  expectFault(a, "division by zero");
}

TEST(VmFault, NullPointer) {
  Assembler a;
  a.op(Op::PUSHW, 0x0010);
  a.line = 7;
  a.op(Op::LDIW).op(Op::HALT);
  expectFault(a, "null pointer");
}

TEST(VmFault, AccessPastTopOfMemory) {
  Assembler a;
  a.op(Op::PUSHW, 0xFFFE);
  a.line = 7;
  a.op(Op::LDIL).op(Op::HALT);
  expectFault(a, "outside memory");
}

TEST(VmFault, UnboundedRecursionOverflowsTheStack) {
  Assembler a;
  a.line = 7;
  a.bind("f").op(Op::CALL, 0);
  expectFault(a, "stack overflow");
}

TEST(VmFault, InterruptThroughUnboundVector) {
  Assembler a;
  a.line = 7;
  a.bind("loop").op(Op::DBG).jump(Op::JMP, "loop");
  const auto img = a.finish();
  TestHost host;
  vm::Vm v(img, host, costs());
  v.request(Irq::Pio, 0x20);
  EXPECT_EQ(v.run(1000), Stop::Fault);
  EXPECT_NE(v.fault()->message.find("0x20"), std::string::npos);
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
  EXPECT_EQ(v.run(callEnd + 1), Stop::Io);
  ASSERT_EQ(host.outs.size(), 1u);
  EXPECT_EQ(host.outs[0].tick, callEnd);
  EXPECT_EQ(host.outs[0].value, 0x88);
}

TEST(Vm, BreakpointStopsBeforeAndResumes) {
  Assembler a;
  const uint16_t n = a.data(2);
  a.bind("loop").op(Op::INCGW, n).jump(Op::JMP, "loop");
  const auto img = a.finish();
  TestHost host;
  vm::Vm v(img, host, costs());
  v.setBreakpoint(0);
  for (int k = 0; k < 5; ++k) {
    EXPECT_EQ(v.run(1'000'000), Stop::Breakpoint);
    EXPECT_EQ(v.read16(n), k);
    EXPECT_EQ(v.now(), k * static_cast<vm::Tick>(cost(Op::INCGW) + cost(Op::JMP)));
  }
}

}  // namespace
