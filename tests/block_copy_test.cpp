// The VM's block operations, interruptible after every byte as the Z180's
// are: a struct assignment (COPY, the chip's LDIR), memcpy, memset and
// strcpy. A handler accepted inside one sees exactly the bytes done by
// then, the time of each byte worked by hand from vm/z180.def; the whole
// operation still costs what the cycle table says.
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
uint32_t cost(Op op) { return testkit::calibratedCost(op); }
using testkit::countingHandler;

// A struct assignment's LDIR repeats for every byte but the last (Zilog's
// 14 T-states repeating, 12 for the last: z180.def): COPY of 10 bytes, on
// the table with no wait states and no refresh, is POP 9 + EX DE,HL 3 +
// LD rr,nn 9 + LDIR 9 x 14 + 12 + POP 9 = 168, after the two PUSHW.
TEST(BlockCopy, CopyChargesLdirForEveryByte) {
  static const vm::CostTable plain = vm::makeCostTable(vm::uncalibratedKnobs());
  Assembler a;
  const uint16_t src = a.data(10), dst = a.data(10);
  a.op(Op::PUSHW, dst).op(Op::PUSHW, src).bind("copy").op(Op::COPY, 10).bind("end").op(Op::HALT);
  const auto img = a.finish();
  TestHost host;
  vm::Vm v(img, host, plain);
  v.setBreakpoint(a.label("copy"));
  ASSERT_EQ(v.run(1'000'000), Stop::Breakpoint);
  const vm::Tick before = v.now();
  v.setBreakpoint(a.label("copy"), false);
  v.setBreakpoint(a.label("end"));
  ASSERT_EQ(v.run(1'000'000), Stop::Breakpoint);
  EXPECT_EQ(v.now() - before, 9 + 3 + 9 + 9 * 14 + 12 + 9);
}

// A struct assignment is interruptible after every byte, as the Z180's
// LDIR is (it runs again with BC decremented): a handler accepted inside
// it sees the copy exactly as far as it has gone. Main: PUSHW dst; PUSHW
// src; COPY 7; HALT. The handler copies main's destination into `seen`
// (its own COPY runs with interrupts disabled) and returns; main's copy
// then finishes. For every request tick c, the acceptance is at the first
// boundary at or after c, and `seen` holds exactly the bytes copied there.
// By hand, COPY's sequence (opcodes.def): POP HL 9; EX DE,HL 3; LD BC,nn 9
// (the head: 21), then LDIR, 14 T-states a byte after which BC is not yet
// 0 and 12 for the last, then POP HL 9 (z180.def):
//  - plain table (no wait states, no refresh): PUSHW is PUSH HL 11; LD
//    HL,nn 9 = 20, so COPY starts at 40; the head ends at 61 (0 bytes
//    copied); byte j = 1..6 ends at 61 + 14j; the 7th and the POP end the
//    instruction at 61 + 6 x 14 + 12 + 9 = 166 (7 bytes);
//  - calibrated (refresh 2 every 20, rounded per sequence: + (2t + 10) /
//    20): PUSHW 20 + 2 = 22, COPY starts at 44; head 21 + 2 = 23, ends at
//    67; a repeating byte 14 + 1 = 15; the whole COPY's figure is 42 + 4 =
//    46, of which 46 - 23 = 23 is the last byte and the POP: byte j ends
//    at 67 + 15j, the instruction at 67 + 6 x 15 + 23 = 180.
// A request at COPY's start is accepted there, before it (0 bytes).
TEST(BlockCopy, StructCopyIsInterruptibleAfterEveryByte) {
  struct Figures {
    vm::CostTable table;
    vm::Tick start, headEnd, repeat, end;
  };
  const Figures figures[] = {
      {vm::makeCostTable(vm::uncalibratedKnobs()), 40, 61, 14, 166},
      {costs(), 44, 67, 15, 180},
  };
  const std::string text = "ABCDEFG";
  constexpr int n = 7;
  for (const Figures& f : figures) {
    // (acceptance tick, bytes copied there) for a request at c.
    auto expected = [&](vm::Tick c) -> std::pair<vm::Tick, int> {
      if (c == f.start) return {f.start, 0};
      if (c <= f.headEnd) return {f.headEnd, 0};
      for (int j = 1; j < n; ++j)
        if (c <= f.headEnd + f.repeat * j) return {f.headEnd + f.repeat * j, j};
      return {f.end, n};
    };
    for (vm::Tick c = f.start; c <= f.end; ++c) {
      Assembler a;
      const uint16_t src = a.string(text), dst = a.data(n), seen = a.data(n);
      a.op(Op::PUSHW, dst).op(Op::PUSHW, src).bind("copy").op(Op::COPY, n).op(Op::HALT);
      a.bind("handler").op(Op::PUSHW, seen).op(Op::PUSHW, dst).op(Op::COPY, n).op(Op::RETI);
      a.image.vectors.push_back(
          {vm::kVecPIOA, static_cast<uint16_t>(a.label("handler")), "handler"});
      const auto img = a.finish();
      TestHost host;
      vm::Vm v(img, host, f.table);
      host.schedule(c, Irq::Pio);
      host.runUntil(v, 10'000);
      const auto [accepted, k] = expected(c);
      ASSERT_EQ(host.events.size(), 2u) << c;
      EXPECT_EQ(host.events[0].tick, accepted) << c;
      if (accepted < f.end) {
        EXPECT_EQ(host.events[0].pc, a.label("copy")) << c;
      }
      for (int i = 0; i < n; ++i) {
        EXPECT_EQ(v.read8(static_cast<uint16_t>(seen + i)), i < k ? text[i] : 0)
            << "request at " << c << ", byte " << i;
        EXPECT_EQ(v.read8(static_cast<uint16_t>(dst + i)), text[i]) << c;
      }
    }
  }
}

// memcpy and memset likewise: a boundary after every byte (memcpy's LDIR,
// memset's JR NZ loop), each byte's effect at its step's start. Plain
// table: three PUSHW (20 each) = 60; the call POP BC 9; POP DE 9; POP HL
// 9; CALL 16; PUSH HL 11; RET 9 = 63 ends at 123, a boundary with 0 bytes
// done; byte j = 1..4 of 5 ends at 123 + j x u, the 5th at 123 + 4u + l:
// memcpy LDIR u = 14, l = 12; memset LD (HL),A 7; INC HL 4; DEC BC 4; LD
// A,B 4; OR C 4; JR NZ 8 (taken) = 31 = u, 6 not taken: l = 29.
TEST(BlockCopy, MemcpyAndMemsetAreInterruptibleAfterEveryByte) {
  static const vm::CostTable plain = vm::makeCostTable(vm::uncalibratedKnobs());
  struct Case {
    vm::Lib lib;
    vm::Tick unit, last;
  };
  const std::string text = "VWXYZ";
  constexpr int n = 5;
  for (const Case& lc : {Case{vm::Lib::MEMCPY, 14, 12}, Case{vm::Lib::MEMSET, 31, 29}}) {
    const vm::Tick callEnd = 123, end = callEnd + (n - 1) * lc.unit + lc.last;
    for (vm::Tick c = callEnd; c <= end; ++c) {
      Assembler a;
      const uint16_t src = a.string(text), dst = a.data(n), seen = a.data(n);
      a.op(Op::PUSHW, dst)
          .op(Op::PUSHW, lc.lib == vm::Lib::MEMCPY ? src : 'V')
          .op(Op::PUSHW, n)
          .lib(lc.lib, 3)
          .op(Op::POP)
          .op(Op::HALT);
      a.bind("handler").op(Op::PUSHW, seen).op(Op::PUSHW, dst).op(Op::COPY, n).op(Op::RETI);
      a.image.vectors.push_back(
          {vm::kVecPIOA, static_cast<uint16_t>(a.label("handler")), "handler"});
      const auto img = a.finish();
      TestHost host;
      vm::Vm v(img, host, plain);
      host.schedule(c, Irq::Pio);
      host.runUntil(v, 10'000);
      // After the 4th byte, the next boundary is the call's end.
      const bool last = c > callEnd + (n - 1) * lc.unit;
      const int k = last ? n : static_cast<int>((c - callEnd + lc.unit - 1) / lc.unit);
      ASSERT_EQ(host.events.size(), 2u) << c;
      EXPECT_EQ(host.events[0].tick, last ? end : callEnd + k * lc.unit) << c;
      for (int i = 0; i < n; ++i) {
        const char want = lc.lib == vm::Lib::MEMCPY ? text[i] : 'V';
        EXPECT_EQ(v.read8(static_cast<uint16_t>(seen + i)), i < k ? want : 0)
            << vm::info(lc.lib).name << ": request at " << c << ", byte " << i;
        EXPECT_EQ(v.read8(static_cast<uint16_t>(dst + i)), want) << c;
      }
    }
  }
}

TEST(BlockCopy, StrcpyIsInterruptibleAndCompletesAfterTheHandler) {
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
  // A boundary after every byte, as the chip's JR NZ loop has (between
  // any two of its instructions): a looping byte is LD A,(HL) 6; LD (DE),A
  // 7; INC HL 4; INC DE 4; OR A 4; JR NZ taken 8 = 33 T-states, + refresh
  // (33 x 2 + 10) / 20 = 3: 36. A request 150 T-states after the call
  // sequence is accepted at the 5th byte's end (5 x 36 = 180 >= 150 >
  // 4 x 36), with exactly 5 bytes copied.
  v.setBreakpoint(static_cast<uint32_t>(a.label("handler")));
  host.schedule(callEnd + 150, Irq::Pio);
  ASSERT_EQ(host.runUntil(v, 100'000), Stop::Breakpoint);
  ASSERT_EQ(host.events.size(), 1u);
  EXPECT_EQ(host.events[0].tick, callEnd + 5 * 36);
  EXPECT_EQ(costs().libStepLooping[static_cast<int>(vm::Lib::STRCPY)], 36u);
  for (size_t i = 0; i < 8; ++i)
    EXPECT_EQ(v.read8(static_cast<uint16_t>(dst + i)), i < 5 ? 'x' : 0) << i;
  v.setBreakpoint(static_cast<uint32_t>(a.label("handler")), false);
  host.runUntil(v, 100'000);
  for (size_t i = 0; i <= text.size(); ++i)
    EXPECT_EQ(v.read8(static_cast<uint16_t>(dst + i)), i < text.size() ? 'x' : 0);
}

}  // namespace
