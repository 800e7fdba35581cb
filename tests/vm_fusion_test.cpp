// The idioms (vm/idioms.h) against the unfused run as the oracle: the
// profiling run never fuses, so a profiled VM steps every piece one by one.
// For every idiom a loop built around it must stop at every horizon, accept
// an interrupt requested at every tick, take PRT0's ticks, fault, overflow
// the expression stack and stop at breakpoints exactly where, when and
// with what state the unfused run does. The same for every join (a loop's
// closer run with the compare-and-branch at its JMP's target).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "support/assembler.h"
#include "support/test_host.h"
#include "vm/idioms.h"

using namespace simbot;
using simbot::testkit::Assembler;
using simbot::testkit::TestHost;
using vm::Irq;
using vm::Op;
using vm::Stop;
using vm::detail::IdiomShape;
using vm::detail::kIdiomShapes;

namespace {

const vm::CostTable& costs() { return testkit::calibratedCosts(); }

enum class Variant {
  Plain,   // operands in range
  Fault,   // the byte address in the null page, the auto past memory's end
  Growing  // each pass leaves a value on the expression stack
};

std::string nameOf(const IdiomShape& s) {
  std::string n;
  for (int k = 0; k < s.n; ++k) n += std::string(vm::info(s.pieces[k]).name) + " ";
  return n;
}

bool leavesValue(const IdiomShape& s) {
  const Op last = s.pieces[s.n - 1];
  return last != Op::STIB && last != Op::STGW && last != Op::JZ && last != Op::JNZ &&
         last != Op::JMP;
}

constexpr uint16_t kDataBytes = 80;  // x, y, r, hits, i, ints, then the byte array

// A loop around the idiom: its variable x (a global, or the auto at
// offset 0) starts at 0x7FFC and counts up past 0x8000 against the
// constant 0x7FFF, so that the comparisons go both ways, signed ones with
// and without overflow; the byte array holds zeros and non-zeros; the
// idiom's value, if it leaves one, goes to r; a branch taken skips
// INCGW hits. The PIO handler counts into ints.
// First, `dbgs` DBG and `pairs` PUSHW POP (PrtTicksLandingInside...).
// An idiom that ends in RET is a function's end: the loop calls it.
// `start` receives the idiom's first piece's address.
vm::Image idiomProgram(const IdiomShape& s, Variant v, bool dbg, int dbgs = 0, int pairs = 0,
                       uint32_t* start = nullptr) {
  Assembler a;
  const uint16_t x = a.data(2), y = a.data(2), r = a.data(2), hits = a.data(2), i = a.data(2),
                 ints = a.data(2), arg = a.data(2), arr = a.data(kDataBytes - 14);
  auto set16 = [&](uint16_t at, uint16_t value) {
    a.image.data[at - vm::kDataBase] = static_cast<uint8_t>(value);
    a.image.data[at - vm::kDataBase + 1] = static_cast<uint8_t>(value >> 8);
  };
  set16(x, 0x7FFC);
  set16(y, 0x0123);
  for (uint16_t j = 0; j < kDataBytes - 14; ++j)
    a.image.data[arr - vm::kDataBase + j] = static_cast<uint8_t>(j % 3 == 0 ? 0 : j);
  for (int k = 0; k < dbgs; ++k) a.op(Op::DBG);
  for (int k = 0; k < pairs; ++k) a.op(Op::PUSHW, 0).op(Op::POP);
  a.op(Op::ENTER, 4).op(Op::PUSHW, 0x7FFC).op(Op::STLW, 0);
  a.bind("top");
  // An idiom that takes values from below its own (ADDW after MULW,
  // KS's ADDW) finds y there.
  int depth = 0, lowest = 0;
  for (int k = 0; k < s.n; ++k) {
    depth -= vm::info(s.pieces[k]).pop;
    lowest = std::min(lowest, depth);
    depth += vm::info(s.pieces[k]).push;
  }
  for (int k = 0; k < -lowest; ++k) a.op(Op::LDGW, y);
  uint32_t callAt = 0;
  const bool isFunction = s.pieces[s.n - 1] == Op::RET;
  uint32_t callIdiomAt = 0;
  if (isFunction) {
    callIdiomAt = a.here() + 1;
    a.op(Op::CALL, 0);
  }
  auto emitIdiom = [&] {
    a.line = 10;
    if (dbg) a.op(Op::DBG);
    if (start) *start = a.here();
    for (int k = 0; k < s.n; ++k) {
      const Op o = s.pieces[k];
      switch (o) {
        case Op::LDGW:
          a.op(o, k == 0 ? x : s.pieces[0] == Op::PUSHW ? i : y);
          break;
        case Op::LDLW:
          a.op(o, v == Variant::Fault ? 3u : 0u);  // FP + 3: 0xFFFF, past the end
          break;
        case Op::PUSHW:
          if (k == 0)
            a.op(o, v == Variant::Fault ? 0x10u : arr);  // a byte array's base
          else
            a.op(o, k == 1 ? 0x7FFFu : 0xA5C3u);  // a constant; a byte to store
          break;
        case Op::STGW:
          a.op(o, r);
          break;
        case Op::JZ:
        case Op::JNZ:
        case Op::JMP:
          a.jump(o, "next");
          break;
        case Op::CALL:
          callAt = a.here() + 1;
          a.op(o, 0);
          break;
        default:
          a.op(o);
      }
    }
  };
  if (!isFunction) emitIdiom();
  a.line = 11;
  if (leavesValue(s)) a.op(Op::STGW, r);
  a.op(Op::INCGW, hits);
  a.bind("next");
  a.line = 12;
  a.op(Op::INCGW, x).op(Op::INCGW, i);
  a.op(Op::LDLW, 0).op(Op::PUSHW, 1).op(Op::ADDW).op(Op::STLW, 0);
  if (v == Variant::Growing) a.op(Op::PUSHW, 7);
  a.jump(Op::JMP, "top");
  // The function a CALL piece calls: it keeps its argument and returns 0x55.
  a.line = 30;
  const uint32_t fn = a.here();
  a.op(Op::STGW, arg).op(Op::PUSHW, 0x55).op(Op::RET);
  if (callAt) {
    a.image.code[callAt] = static_cast<uint8_t>(fn);
    a.image.code[callAt + 1] = static_cast<uint8_t>(fn >> 8);
  }
  if (isFunction) {
    const uint32_t f = a.here();
    emitIdiom();
    a.image.code[callIdiomAt] = static_cast<uint8_t>(f);
    a.image.code[callIdiomAt + 1] = static_cast<uint8_t>(f >> 8);
  }
  a.line = 20;
  a.bind("handler").op(Op::INCGW, ints).op(Op::RETI);
  a.image.vectors.push_back({vm::kVecPIOA, static_cast<uint16_t>(a.label("handler")), "handler"});
  return a.finish();
}

// Where each of the idiom's pieces starts.
std::vector<uint32_t> pieceAddresses(const IdiomShape& s, uint32_t start) {
  std::vector<uint32_t> at;
  for (int k = 0; k < s.n; ++k) {
    at.push_back(start);
    start += static_cast<uint32_t>(vm::instructionSize(s.pieces[k]));
  }
  return at;
}

// Everything a run leaves that the idiom could change.
void expectSame(const vm::Vm& f, const vm::Vm& p, const std::string& what) {
  ASSERT_EQ(f.now(), p.now()) << what;
  ASSERT_EQ(f.stats().instructions, p.stats().instructions) << what;
  ASSERT_EQ(f.pc(), p.pc()) << what;
  ASSERT_EQ(f.halted(), p.halted()) << what;
  ASSERT_EQ(f.interruptDepth(), p.interruptDepth()) << what;
  ASSERT_EQ(f.stats().interrupts, p.stats().interrupts) << what;
  ASSERT_EQ(f.fault() != nullptr, p.fault() != nullptr) << what;
  if (f.fault()) {
    EXPECT_EQ(f.fault()->message, p.fault()->message) << what;
    EXPECT_EQ(f.fault()->tick, p.fault()->tick) << what;
    EXPECT_EQ(f.fault()->line, p.fault()->line) << what;
  }
  for (uint32_t a = vm::kDataBase; a < vm::kDataBase + kDataBytes + 96u; ++a)
    ASSERT_EQ(f.read8(static_cast<uint16_t>(a)), p.read8(static_cast<uint16_t>(a)))
        << what << " at 0x" << std::hex << a;
  for (uint32_t a = 0xFFF0; a <= 0xFFFF; ++a)
    ASSERT_EQ(f.read8(static_cast<uint16_t>(a)), p.read8(static_cast<uint16_t>(a)))
        << what << " at 0x" << std::hex << a;
}

// The fused run and the unfused (profiling) run of img stop at horizon h
// alike, and run on alike to h + resume.
void expectSameAtHorizon(const vm::Image& img, vm::Tick h, vm::Tick resume,
                         const std::string& name) {
  TestHost h1, h2;
  vm::Vm fused(img, h1, costs());
  vm::Vm plain(img, h2, costs());
  plain.enableProfile();
  ASSERT_EQ(fused.run(h), plain.run(h)) << name << h;
  expectSame(fused, plain, name + "horizon " + std::to_string(h));
  if (::testing::Test::HasFatalFailure()) return;
  ASSERT_EQ(fused.run(h + resume), plain.run(h + resume)) << name << h;
  expectSame(fused, plain, name + "resumed from " + std::to_string(h));
}

// A PIO interrupt requested at tick `at` is accepted by both runs at the
// same ticks and pcs, up to at + tail.
void expectSameInterrupt(const vm::Image& img, vm::Tick at, vm::Tick tail,
                         const std::string& name) {
  TestHost h1, h2;
  vm::Vm fused(img, h1, costs());
  vm::Vm plain(img, h2, costs());
  plain.enableProfile();
  h1.schedule(at, Irq::Pio);
  h2.schedule(at, Irq::Pio);
  h1.runUntil(fused, at + tail);
  h2.runUntil(plain, at + tail);
  const std::string what = name + "request at " + std::to_string(at);
  ASSERT_EQ(h1.events.size(), h2.events.size()) << what;
  ASSERT_FALSE(h1.events.empty()) << what;
  for (size_t k = 0; k < h1.events.size(); ++k) {
    EXPECT_EQ(h1.events[k].tick, h2.events[k].tick) << what;
    EXPECT_EQ(h1.events[k].pc, h2.events[k].pc) << what;
  }
  expectSame(fused, plain, what);
}

// With the BIOS timer service on, three PRT0 ticks land where they do
// unfused.
void expectSamePrtTicks(const vm::Image& img, const std::string& what) {
  vm::CostKnobs knobs = vm::calibratedKnobs();
  knobs.timerService = vm::TimerService::Always;
  const vm::CostTable timed = vm::makeCostTable(knobs);
  TestHost h1, h2;
  vm::Vm fused(img, h1, timed);
  vm::Vm plain(img, h2, timed);
  plain.enableProfile();
  const vm::Tick end = 3 * vm::kPrtTicks + 500;
  ASSERT_EQ(fused.run(end), plain.run(end)) << what;
  ASSERT_EQ(fused.timerIsrCycles(), plain.timerIsrCycles()) << what;
  ASSERT_EQ(fused.stats().interrupts[static_cast<int>(Irq::Timer)], 3u) << what;
  expectSame(fused, plain, what);
}

// One pass of any of these loops is under 700 T-states: the sweeps cover
// at least three passes.
constexpr vm::Tick kSweep = 2100;

TEST(VmIdiom, EveryHorizonStopsWhereTheUnfusedRunStops) {
  for (const IdiomShape& s : kIdiomShapes)
    for (const bool dbg : {false, true}) {
      const auto img = idiomProgram(s, Variant::Plain, dbg);
      for (vm::Tick h = 1; h <= kSweep; ++h) {
        expectSameAtHorizon(img, h, 1000, nameOf(s));
        if (HasFatalFailure()) return;
      }
    }
}

TEST(VmIdiom, AnInterruptRequestedAtAnyTickIsAcceptedWhereItIsUnfused) {
  for (const IdiomShape& s : kIdiomShapes)
    for (const bool dbg : {false, true}) {
      const auto img = idiomProgram(s, Variant::Plain, dbg);
      for (vm::Tick at = 1; at <= kSweep; ++at) {
        expectSameInterrupt(img, at, 1500, nameOf(s));
        if (HasFatalFailure()) return;
      }
    }
}

TEST(VmIdiom, PrtTicksLandingInsideAreTakenWhereTheyAreUnfused) {
  // A prefix of p DBG (62 T-states) and q PUSHW POP (29) moves the loop
  // against PRT0's ticks, so that they land at every offset into the
  // idiom's pieces.
  for (const IdiomShape& s : kIdiomShapes)
    for (const bool dbg : {false, true})
      for (int p = 0; p < 12; ++p)
        for (int q = 0; q < 3; ++q) {
          expectSamePrtTicks(idiomProgram(s, Variant::Plain, dbg, p, q),
                             nameOf(s) + "prefix " + std::to_string(p) + "," + std::to_string(q));
          if (HasFatalFailure()) return;
        }
}

TEST(VmIdiom, APieceThatFaultsFaultsAsItDoesAlone) {
  // The byte idioms address the null page (0x10 + i), the auto ones read
  // FP + 3 = 0xFFFF: the unfused run faults in STIB, LDIB or LDLW.
  int faulting = 0;
  for (const IdiomShape& s : kIdiomShapes)
    for (const bool dbg : {false, true}) {
      const auto img = idiomProgram(s, Variant::Fault, dbg);
      TestHost h1, h2;
      vm::Vm fused(img, h1, costs());
      vm::Vm plain(img, h2, costs());
      plain.enableProfile();
      const Stop stop = plain.run(1'000'000);
      ASSERT_EQ(fused.run(1'000'000), stop) << nameOf(s);
      expectSame(fused, plain, nameOf(s) + "fault");
      if (HasFatalFailure()) return;
      if (stop == Stop::Fault) {
        ++faulting;
        EXPECT_EQ(plain.fault()->line, 10) << nameOf(s);  // inside the idiom
      }
    }
  // Every idiom with a byte access or an auto, with and without DBG.
  int expected = 0;
  for (const IdiomShape& s : kIdiomShapes) {
    bool faults = s.pieces[0] == Op::LDLW;
    for (int k = 0; k < s.n; ++k) faults |= s.pieces[k] == Op::LDIB || s.pieces[k] == Op::STIB;
    expected += faults ? 2 : 0;
  }
  EXPECT_EQ(faulting, expected);
}

TEST(VmIdiom, TheExpressionStackGuardStopsWhereItDoesUnfused) {
  // Each pass leaves one value more; some pass's pushes inside the idiom
  // reach the guard, and the boundary after that push faults.
  for (const IdiomShape& s : kIdiomShapes)
    for (const bool dbg : {false, true}) {
      const auto img = idiomProgram(s, Variant::Growing, dbg);
      TestHost h1, h2;
      vm::Vm fused(img, h1, costs());
      vm::Vm plain(img, h2, costs());
      plain.enableProfile();
      ASSERT_EQ(plain.run(100'000'000), Stop::Fault) << nameOf(s);
      ASSERT_EQ(fused.run(100'000'000), Stop::Fault) << nameOf(s);
      expectSame(fused, plain, nameOf(s) + "guard");
      if (HasFatalFailure()) return;
    }
}

TEST(VmIdiom, ABreakpointOnAnyPieceStopsThereEveryPass) {
  // Set before the first run, and set after some passes have run fused.
  for (const IdiomShape& s : kIdiomShapes)
    for (const bool dbg : {false, true}) {
      uint32_t start = 0;
      const auto img = idiomProgram(s, Variant::Plain, dbg, 0, 0, &start);
      const auto at = pieceAddresses(s, start);
      for (int k = 1; k < s.n; ++k)
        for (const vm::Tick before : {vm::Tick{0}, vm::Tick{1000}}) {
          TestHost h1, h2;
          vm::Vm fused(img, h1, costs());
          vm::Vm plain(img, h2, costs());
          plain.enableProfile();
          if (before) {
            ASSERT_EQ(fused.run(before), plain.run(before));
          }
          fused.setBreakpoint(at[k]);
          plain.setBreakpoint(at[k]);
          for (int pass = 0; pass < 4; ++pass) {
            const Stop stop = plain.run(1'000'000);
            ASSERT_EQ(fused.run(1'000'000), stop) << nameOf(s) << k;
            const std::string what = nameOf(s) + "piece " + std::to_string(k);
            expectSame(fused, plain, what);
            if (HasFatalFailure()) return;
            if (stop != Stop::Breakpoint) break;  // a branch went round it
            EXPECT_EQ(plain.pc(), at[k]) << what;
          }
        }
    }
}

// ---- joins (idioms.h SIMBOT_JOINS) ----

struct JoinCase {
  std::string closer;  // IJ (INCGW a; JMP t) or a BSJ idiom's name
  Op load, compare;    // the target: load x; PUSHW k; compare; JZ out
};

const std::vector<JoinCase>& joinCases() {
  static const std::vector<JoinCase> cases = {
#define SIMBOT_JOIN_CASE(C, l, c) {#C, Op::l, Op::c},
      SIMBOT_JOINS(SIMBOT_JOIN_CASE)
#undef SIMBOT_JOIN_CASE
  };
  return cases;
}

std::string nameOf(const JoinCase& j) {
  return j.closer + " to " + std::string(vm::info(j.load).name) + " PUSHW " +
         std::string(vm::info(j.compare).name) + " JZ ";
}

// A loop entered at its closer, so that its target first runs joined:
//   top:  load v; PUSHW 0x7FFE; compare; JZ out     (v: x, or the auto)
//         INCGW hits (the auto: v += 1)
//   closer: x += 1 (INCGW x, or x = x ADDW 1 / SUBW 0xFFFF); JMP top
//   out:  v += 1; INCGW i; JMP top (an IJ closer too)
// v counts up from 0x7FFC across 0x8000, so that every comparison goes
// both ways within a few passes, signed ones with and without overflow.
// Growing: each pass leaves a value on the expression stack; Fault:
// the auto is read at FP + 3 (0xFFFF, past the end). `pieces` receives
// the target's and the closer's pieces' addresses.
vm::Image joinProgram(const JoinCase& j, Variant v, int dbgs = 0, int pairs = 0,
                      std::vector<uint32_t>* pieces = nullptr) {
  Assembler a;
  const uint16_t x = a.data(2), hits = a.data(2), i = a.data(2), ints = a.data(2), one = a.data(2),
                 minusOne = a.data(2);
  auto set16 = [&](uint16_t at, uint16_t value) {
    a.image.data[at - vm::kDataBase] = static_cast<uint8_t>(value);
    a.image.data[at - vm::kDataBase + 1] = static_cast<uint8_t>(value >> 8);
  };
  set16(x, 0x7FFC);
  set16(one, 1);
  set16(minusOne, 0xFFFF);
  const bool isAuto = j.load == Op::LDLW;
  auto step = [&] {  // v += 1
    if (isAuto)
      a.op(Op::LDLW, 0).op(Op::PUSHW, 1).op(Op::ADDW).op(Op::STLW, 0);
    else
      a.op(Op::INCGW, x);
  };
  for (int k = 0; k < dbgs; ++k) a.op(Op::DBG);
  for (int k = 0; k < pairs; ++k) a.op(Op::PUSHW, 0).op(Op::POP);
  a.op(Op::ENTER, 4).op(Op::PUSHW, 0x7FFC).op(Op::STLW, 0);
  a.jump(Op::JMP, "closer");
  a.line = 10;
  a.bind("top");
  if (pieces) pieces->clear();
  auto piece = [&] {
    if (pieces) pieces->push_back(a.here());
  };
  piece();
  a.op(j.load, isAuto ? (v == Variant::Fault ? 3u : 0u) : x);
  piece();
  a.op(Op::PUSHW, 0x7FFE);
  piece();
  a.op(j.compare);
  piece();
  a.jump(Op::JZ, "out");
  a.line = 11;
  a.op(Op::INCGW, hits);
  if (isAuto) step();
  if (v == Variant::Growing) a.op(Op::PUSHW, 7);
  a.line = 12;
  a.bind("closer");
  if (j.closer == "IJ") {
    piece();
    a.op(Op::INCGW, x);
  } else {
    const bool sub = j.closer.find("SUBW") != std::string::npos;
    const bool global = j.closer.find("LDGW_") != std::string::npos;
    piece();
    a.op(Op::LDGW, x);
    piece();
    if (global)
      a.op(Op::LDGW, sub ? minusOne : one);
    else
      a.op(Op::PUSHW, sub ? 0xFFFFu : 1u);
    piece();
    a.op(sub ? Op::SUBW : Op::ADDW);
    piece();
    a.op(Op::STGW, x);
  }
  piece();
  a.jump(Op::JMP, "top");
  a.line = 13;
  a.bind("out");
  step();
  if (v == Variant::Growing) a.op(Op::PUSHW, 7);
  a.op(Op::INCGW, i);
  a.jump(Op::JMP, "top");
  a.line = 20;
  a.bind("handler").op(Op::INCGW, ints).op(Op::RETI);
  a.image.vectors.push_back({vm::kVecPIOA, static_cast<uint16_t>(a.label("handler")), "handler"});
  return a.finish();
}

// One pass of these loops is under 400 T-states: three passes.
constexpr vm::Tick kJoinSweep = 1200;

TEST(VmJoin, EveryHorizonStopsWhereTheUnfusedRunStops) {
  for (const JoinCase& j : joinCases()) {
    const auto img = joinProgram(j, Variant::Plain);
    for (vm::Tick h = 1; h <= kJoinSweep; ++h) {
      expectSameAtHorizon(img, h, 3000, nameOf(j));
      if (HasFatalFailure()) return;
    }
  }
}

TEST(VmJoin, AnInterruptRequestedAtAnyTickIsAcceptedWhereItIsUnfused) {
  for (const JoinCase& j : joinCases()) {
    const auto img = joinProgram(j, Variant::Plain);
    for (vm::Tick at = 1; at <= kJoinSweep; ++at) {
      expectSameInterrupt(img, at, 1000, nameOf(j));
      if (HasFatalFailure()) return;
    }
  }
}

TEST(VmJoin, PrtTicksLandingInsideAreTakenWhereTheyAreUnfused) {
  // As for the idioms: prefixes of DBG and PUSHW POP move the loop against
  // PRT0's ticks.
  for (const JoinCase& j : joinCases())
    for (int p = 0; p < 12; ++p)
      for (int q = 0; q < 3; ++q) {
        expectSamePrtTicks(joinProgram(j, Variant::Plain, p, q),
                           nameOf(j) + "prefix " + std::to_string(p) + "," + std::to_string(q));
        if (HasFatalFailure()) return;
      }
}

TEST(VmJoin, ATargetThatFaultsFaultsAsItDoesAlone) {
  // The auto targets read FP + 3: the unfused run faults in the target's
  // LDLW, first reached through the closer's JMP.
  int faulting = 0;
  for (const JoinCase& j : joinCases()) {
    const auto img = joinProgram(j, Variant::Fault);
    TestHost h1, h2;
    vm::Vm fused(img, h1, costs());
    vm::Vm plain(img, h2, costs());
    plain.enableProfile();
    const Stop stop = plain.run(1'000'000);
    ASSERT_EQ(fused.run(1'000'000), stop) << nameOf(j);
    expectSame(fused, plain, nameOf(j) + "fault");
    if (HasFatalFailure()) return;
    if (stop == Stop::Fault) {
      ++faulting;
      EXPECT_EQ(plain.fault()->line, 10) << nameOf(j);
    }
  }
  EXPECT_EQ(faulting,
            static_cast<int>(std::count_if(joinCases().begin(), joinCases().end(),
                                           [](const JoinCase& j) { return j.load == Op::LDLW; })));
}

TEST(VmJoin, TheExpressionStackGuardStopsWhereItDoesUnfused) {
  for (const JoinCase& j : joinCases()) {
    const auto img = joinProgram(j, Variant::Growing);
    TestHost h1, h2;
    vm::Vm fused(img, h1, costs());
    vm::Vm plain(img, h2, costs());
    plain.enableProfile();
    ASSERT_EQ(plain.run(100'000'000), Stop::Fault) << nameOf(j);
    ASSERT_EQ(fused.run(100'000'000), Stop::Fault) << nameOf(j);
    expectSame(fused, plain, nameOf(j) + "guard");
    if (HasFatalFailure()) return;
  }
}

TEST(VmJoin, ABreakpointOnAnyPieceOfTheCloserOrTheTargetStopsThereEveryPass) {
  // Set before the first run, and after some passes have run joined (the
  // closer's entry must then stop joining: the target is far from it).
  for (const JoinCase& j : joinCases()) {
    std::vector<uint32_t> at;
    const auto img = joinProgram(j, Variant::Plain, 0, 0, &at);
    for (size_t k = 0; k < at.size(); ++k)
      for (const vm::Tick before : {vm::Tick{0}, vm::Tick{1000}}) {
        TestHost h1, h2;
        vm::Vm fused(img, h1, costs());
        vm::Vm plain(img, h2, costs());
        plain.enableProfile();
        if (before) {
          ASSERT_EQ(fused.run(before), plain.run(before));
        }
        fused.setBreakpoint(at[k]);
        plain.setBreakpoint(at[k]);
        int stops = 0;
        for (int pass = 0; pass < 6; ++pass) {
          const Stop stop = plain.run(20'000);
          ASSERT_EQ(fused.run(20'000), stop) << nameOf(j) << k;
          const std::string what = nameOf(j) + "piece " + std::to_string(k);
          expectSame(fused, plain, what);
          if (HasFatalFailure()) return;
          if (stop != Stop::Breakpoint) break;
          EXPECT_EQ(plain.pc(), at[k]) << what;
          ++stops;
        }
        // The target's pieces run every pass (the closer's, only while the
        // comparison holds).
        if (k < 4) {
          EXPECT_EQ(stops, 6) << nameOf(j) << k;
        }
      }
  }
}

TEST(VmIdiom, AWordAt0xFFFFWrapsAsItDoesUnfused) {
  // The handlers access a global's word at once: the decoder must leave a
  // global at 0xFFFF (high byte at 0x0000) to the unfused pieces.
  Assembler a;
  const uint16_t r = a.data(2);
  a.bind("top");
  a.op(Op::LDGW, 0xFFFF).op(Op::PUSHW, 0x0101).op(Op::ADDW).op(Op::STGW, 0xFFFF);  // BS
  a.op(Op::LDGW, 0xFFFF).op(Op::LDGW, 0xFFFF).op(Op::MULW).op(Op::STGW, r);        // Mul
  a.op(Op::INCGW, 0xFFFF).jump(Op::JMP, "cb");                                     // IJ
  a.bind("cb");
  a.op(Op::LDGW, 0xFFFF).op(Op::PUSHW, 0x7FFE).op(Op::LTW).jump(Op::JZ, "top");  // CB
  a.op(Op::LDGW, 0xFFFF).op(Op::PUSHW, 3).op(Op::ADDW).op(Op::STGW, 0xFFFF);
  a.jump(Op::JMP, "cb");  // BSJ, joined
  const vm::Image img = a.finish();
  for (vm::Tick h = 1; h <= 1500; h += 7) {
    TestHost h1, h2;
    vm::Vm fused(img, h1, costs());
    vm::Vm plain(img, h2, costs());
    plain.enableProfile();
    ASSERT_EQ(fused.run(h), plain.run(h)) << h;
    expectSame(fused, plain, "horizon " + std::to_string(h));
    if (HasFatalFailure()) return;
    ASSERT_EQ(fused.read16(0xFFFF), plain.read16(0xFFFF)) << h;
    ASSERT_EQ(fused.read8(0x0000), plain.read8(0x0000)) << h;
  }
  TestHost h1;
  vm::Vm fused(img, h1, costs());
  fused.run(1500);
  EXPECT_NE(fused.read8(0x0000), 0) << "the high byte went to 0x0000";
}

}  // namespace
