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

// The ticks from the start to the breakpoint at `stopAt`, on a table with
// no wait states and no refresh, so that the figures are the Z180 table's.
vm::Tick ticksTo(Assembler& a, uint32_t stopAt) {
  static const vm::CostTable plain = vm::makeCostTable(vm::uncalibratedKnobs());
  const auto img = a.finish();
  TestHost host;
  vm::Vm v(img, host, plain);
  v.setBreakpoint(stopAt);
  EXPECT_EQ(v.run(1'000'000), Stop::Breakpoint);
  return v.now();
}

TEST(Vm, ChargesEachInstructionTheZ180SumOfItsSequence) {
  // PUSHW: PUSH HL 11; LD HL,nn 9 = 20. POP: POP HL 9. INCGW: LD HL,(nn) 15;
  // INC HL 4; LD (nn),HL 16 = 35. DBG: RST 28h 11 + hook 51 = 62.
  Assembler a;
  const uint16_t n = a.data(2);
  a.op(Op::PUSHW, 7).op(Op::POP).op(Op::INCGW, n).op(Op::DBG).bind("end").op(Op::HALT);
  EXPECT_EQ(ticksTo(a, a.label("end")), 20 + 9 + 35 + 62);
}

TEST(Vm, ConditionalJumpsChargeTakenOrNotTaken) {
  // PUSHW 20, then JZ: LD A,L 4; OR H 4; POP HL 9; JP Z 9 taken / 6 not.
  for (int value : {0, 1}) {
    Assembler a;
    a.op(Op::PUSHW, static_cast<uint32_t>(value)).jump(Op::JZ, "end").bind("end").op(Op::HALT);
    EXPECT_EQ(ticksTo(a, a.label("end")), 20 + 4 + 4 + 9 + (value == 0 ? 9 : 6)) << value;
  }
  for (int value : {0, 1}) {
    Assembler a;
    a.op(Op::PUSHW, static_cast<uint32_t>(value)).jump(Op::JNZ, "end").bind("end").op(Op::HALT);
    EXPECT_EQ(ticksTo(a, a.label("end")), 20 + 4 + 4 + 9 + (value != 0 ? 9 : 6)) << value;
  }
}

TEST(Vm, ComparisonsChargeTheWayTheirBranchesGo) {
  struct Case {
    Op op;
    uint32_t a, b;
    int tstates;  // of the comparison alone
  };
  const Case cases[] = {
      // EQW: POP 9; OR 4; SBC 10; LD HL,0 9 = 32; + JR NZ 6 + INC 4 when
      // equal (42), + JR NZ taken 8 when not (40).
      {Op::EQW, 5, 5, 42},
      {Op::EQW, 5, 6, 40},
      // LTW: POP 9; EX 3; OR 4; SBC 10; LD 9 = 35; then JP PO (9 taken when
      // a - b does not overflow, 6 + XOR 4 when it does), JP (6 + INC 4
      // when true, 9 when false).
      {Op::LTW, 3, 5, 35 + 9 + 6 + 4},            // no overflow, true: 54
      {Op::LTW, 5, 3, 35 + 9 + 9},                // no overflow, false: 53
      {Op::LTW, 0x8000, 1, 35 + 6 + 4 + 6 + 4},   // -32768 - 1 overflows, true: 55
      {Op::LTW, 0x7FFF, 0xFFFF, 35 + 6 + 4 + 9},  // 32767 - (-1) overflows, false: 54
      // LTUW: POP 9; EX 3; OR 4; SBC 10; LD 9 = 35; JR NC 6 + INC 4 when
      // true, 8 when false.
      {Op::LTUW, 3, 5, 35 + 6 + 4},
      {Op::LTUW, 5, 3, 35 + 8},
  };
  for (const auto& c : cases) {
    Assembler a;
    a.op(Op::PUSHW, c.a).op(Op::PUSHW, c.b).op(c.op).bind("end").op(Op::HALT);
    EXPECT_EQ(ticksTo(a, a.label("end")), 20 + 20 + c.tstates)
        << vm::info(c.op).name << " " << c.a << " " << c.b;
  }
}

TEST(Vm, RetPopsIxOnlyAfterEnter) {
  // CALL 16; RET 9 for a static-class function.
  {
    Assembler a;
    a.op(Op::CALL, 4).bind("end").op(Op::HALT).bind("f").op(Op::RET);
    ASSERT_EQ(a.label("f"), 4u);
    EXPECT_EQ(ticksTo(a, a.label("end")), 16 + 9);
  }
  // #class auto: ENTER is PUSH IX 14; LD DE,nn 9; ADD IX,DE 10; LD HL,nn 9;
  // ADD HL,SP 7; LD SP,HL 4 = 53, and RET is POP IX 12 + RET 9.
  {
    Assembler a;
    a.op(Op::CALL, 4).bind("end").op(Op::HALT).bind("f").op(Op::ENTER, 2).op(Op::RET);
    ASSERT_EQ(a.label("f"), 4u);
    EXPECT_EQ(ticksTo(a, a.label("end")), 16 + 53 + 12 + 9);
  }
}

TEST(Vm, LibraryCallIsChargedOneCall) {
  // PUSHW 20 x 2, then outport's sequence alone: POP 9; POP 9; CALL 16;
  // LD C,L 4; OUT (C),A 10 + 1 I/O wait; RET 9 = 58. The write happens at
  // the end of the sequence.
  Assembler a;
  a.op(Op::PUSHW, vm::kPortPIODB).op(Op::PUSHW, 0x88).lib(vm::Lib::OUTPORT, 2).op(Op::HALT);
  const auto img = a.finish();
  TestHost host;
  vm::Vm v(img, host, vm::makeCostTable(vm::uncalibratedKnobs()));
  host.runUntil(v, 1000);
  ASSERT_EQ(host.outs.size(), 1u);
  EXPECT_EQ(host.outs[0].tick, 20 + 20 + 58);
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
