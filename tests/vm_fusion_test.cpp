// The superinstructions (vm/superinstructions.def) against the pieces run
// one by one as the oracle: the profiling run never fuses, so a profiled
// VM dispatches every piece alone. The programs are the Lua comparison
// programs (bench/programs/*.dc), shrunk, and tests/programs/c_forms.dc,
// which writes each C form that has an entry, each with a PIO handler that
// counts its calls; every entry of the table occurs in them (checked
// first). Around each superinstruction's first arrival, a run stopped at
// every horizon, an interrupt requested at every tick, PRT0's ticks, a
// breakpoint on every piece, a fault inside one and the expression stack's
// guard must stop, accept, fault and leave the machine exactly where, when
// and as the unfused run does.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support/assembler.h"
#include "support/test_host.h"
#include "vm/superinstructions.h"

using namespace simbot;
using simbot::testkit::TestHost;
using vm::Irq;
using vm::Op;
using vm::Stop;
using vm::detail::kSuperCount;
using vm::detail::kSuperShapes;

namespace {

const vm::CostTable& costs() { return testkit::calibratedCosts(); }

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// FOLDER/NAME.dc with its #defines replaced, and a PIO handler.
vm::Image withHandler(const std::string& folder, const std::string& name,
                      const std::vector<std::pair<std::string, std::string>>& defines) {
  std::string source = readFile(std::string(SIMBOT_SOURCE_DIR) + "/" + folder + "/" + name + ".dc");
  for (const auto& [from, to] : defines) {
    const auto at = source.find(from);
    EXPECT_NE(at, std::string::npos) << name << ": " << from;
    if (at != std::string::npos) source.replace(at, from.size(), to);
  }
  source +=
      "\n#INT_VEC PIOA_VEC counted\nint interrupts;\ninterrupt reti counted()\n{\n"
      "    interrupts++;\n}\n";
  return testkit::compileOrDie(source, name + ".dc");
}
vm::Image benchProgram(const std::string& name,
                       const std::vector<std::pair<std::string, std::string>>& defines) {
  return withHandler("bench/programs", name, defines);
}

struct Program {
  std::string name;
  vm::Image image;
};

const std::vector<Program>& programs() {
  static const std::vector<Program> all = {
      {"sieve", benchProgram("sieve", {{"SIZE 8000", "SIZE 60"}, {"REPS 100", "REPS 2"}})},
      {"nested", benchProgram("nested", {{"I 2000", "I 5"}, {"J 2000", "J 7"}})},
      {"fib", benchProgram("fib", {{"N 23", "N 7"}, {"REPS 30", "REPS 2"}})},
      {"sort", benchProgram("sort", {{"N 200", "N 9"}, {"REPS 200", "REPS 2"}})},
      {"strscan", benchProgram("strscan", {{"LEN 640", "LEN 41"}, {"REPS 1200", "REPS 2"}})},
      {"structs", benchProgram("structs", {{"N 100", "N 6"}, {"REPS 15000", "REPS 2"}})},
      {"grid", benchProgram("grid", {{"SIDE 32", "SIDE 5"}, {"REPS 600", "REPS 2"}})},
      {"filter", benchProgram("filter", {{"N 256", "N 12"}, {"REPS 5000", "REPS 2"}})},
      {"c_forms", withHandler("tests/programs", "c_forms", {})},
  };
  return all;
}

// Everything a run leaves that a piece could change.
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
  // The globals and the top of the robot's stack (autos, frames).
  const auto dataEnd = vm::kDataBase + static_cast<uint32_t>(f.image().data.size());
  for (uint32_t a = vm::kDataBase; a <= 0xFFFF; a = a + 1 == dataEnd ? 0xFE00 : a + 1)
    if (f.read8(static_cast<uint16_t>(a)) != p.read8(static_cast<uint16_t>(a)))
      FAIL() << what << ": memory differs at 0x" << std::hex << a;
}

// Whether the unfused run of a program reaches `address` at least
// `times` times (a breakpoint there), and the tick it first does.
struct Arrivals {
  bool enough;
  vm::Tick first;
};
Arrivals arrivals(const vm::Image& image, uint32_t address, int times) {
  TestHost host;
  vm::Vm v(image, host, costs());
  v.enableProfile();
  v.setBreakpoint(address);
  vm::Tick first = -1;
  for (int k = 0; k < times; ++k) {
    if (v.run(10'000'000) != Stop::Breakpoint) return {false, first};
    if (k == 0) first = v.now();
  }
  return {true, first};
}

// Where each superinstruction starts in a program, as the decoder finds
// it: (program, address) of the first place, in the programs' order, that
// the run reaches at least three times (a loop's body: the tests below
// stop there on three passes), or of the first place at all when none is.
struct Site {
  const Program* program;
  uint32_t address;
};
const std::vector<Site>& sites() {
  static const std::vector<Site> found = [] {
    std::vector<Site> first(kSuperCount, Site{nullptr, 0}), looped = first;
    for (const Program& p : programs()) {
      TestHost host;
      const vm::Vm v(p.image, host, costs());
      for (uint32_t a = 0; a < p.image.code.size(); ++a) {
        const int s = v.superinstructionAt(a);
        if (s < 0 || looped[s].program) continue;
        if (!first[s].program) first[s] = Site{&p, a};
        if (arrivals(p.image, a, 3).enough) looped[s] = Site{&p, a};
      }
    }
    for (int s = 0; s < kSuperCount; ++s)
      if (!looped[s].program) looped[s] = first[s];
    return looped;
  }();
  return found;
}

// The fused and the unfused VM, both run to `start`.
struct Pair {
  TestHost fusedHost, plainHost;
  vm::Vm fused, plain;
  Pair(const vm::Image& image, vm::Tick start, const vm::CostTable& table = costs())
      : fused(image, fusedHost, table), plain(image, plainHost, table) {
    plain.enableProfile();
    fused.run(start);
    plain.run(start);
  }
};

// The end of the ticks a test tries from a superinstruction's first
// arrival: past its first run at its slowest (its pieces' costs and their
// costliest branches, as in cost.h), so every tick inside it and the
// boundary after it; each try then runs 700 T-states on, into the runs
// after it.
vm::Tick windowEnd(int s, vm::Tick start) {
  vm::Tick span = 0;
  for (int k = 0; k < kSuperShapes[s].n; ++k) {
    const auto o = static_cast<int>(kSuperShapes[s].pieces[k]);
    span += costs().op[o] +
            *std::max_element(costs().branchDelta[o].begin(), costs().branchDelta[o].end());
  }
  return start + span + 1;
}

std::string nameOf(int s) { return std::string(kSuperShapes[s].name) + ": "; }

TEST(VmSuperinstruction, EveryEntryOccursInTheProgramsAndIsReached) {
  const std::vector<Site>& at = sites();
  for (int s = 0; s < kSuperCount; ++s) {
    EXPECT_NE(at[s].program, nullptr) << nameOf(s) << "in none of the programs";
    if (!at[s].program) continue;
    EXPECT_TRUE(arrivals(at[s].program->image, at[s].address, 3).enough)
        << nameOf(s) << "not reached on three passes";
  }
}

TEST(VmSuperinstruction, TheProgramsPrintWhatTheirUnfusedRunsPrint) {
  // sieve: 17 primes below 60; nested: sum of i*j + 7 over 5 x 7 = 210 +
  // 245 = 455; fib(7) = 13. The next five: their Lua twins
  // (bench/programs/*.lua) run by Lua 5.4 with the same shrunk constants
  // (sort N, REPS = 9, 2; strscan LEN, REPS = 41, 2; structs N, REPS = 6,
  // 2; grid SIDE, REPS = 5, 2; filter N, WINDOW, REPS = 12, 8, 2). c_forms:
  // the hand computation in its source.
  const std::vector<std::vector<std::string>> expected = {
      {"17 2"},
      {"455"},
      {"13 2"},
      {"51 477 835 2"},
      {"6 8 2 2"},
      {"4 5 839 2"},
      {"1 2"},
      {"0 454 2"},
      {"0 40 11 36 40", "-24", "120 22 38 56", "681 3840 -341", "15 18", "2490", "444 44"}};
  ASSERT_EQ(expected.size(), programs().size());
  for (size_t k = 0; k < programs().size(); ++k) {
    Pair run(programs()[k].image, 0);
    run.fusedHost.runUntil(run.fused, 100'000'000);
    run.plainHost.runUntil(run.plain, 100'000'000);
    ASSERT_EQ(run.fusedHost.consoleLines, expected[k]) << programs()[k].name;
    EXPECT_EQ(run.plainHost.consoleLines, run.fusedHost.consoleLines);
    expectSame(run.fused, run.plain, programs()[k].name);
  }
}

TEST(VmSuperinstruction, EveryHorizonStopsWhereTheUnfusedRunStops) {
  const std::vector<Site>& at = sites();
  for (int s = 0; s < kSuperCount; ++s) {
    ASSERT_NE(at[s].program, nullptr) << nameOf(s) << "in none of the programs";
    const vm::Tick start = arrivals(at[s].program->image, at[s].address, 1).first;
    ASSERT_GE(start, 0) << nameOf(s) << "not reached";
    const Pair base(at[s].program->image, start - 1);
    for (vm::Tick h = start; h < windowEnd(s, start); ++h) {
      TestHost h1, h2;
      vm::Vm fused(base.fused, h1), plain(base.plain, h2);
      const std::string what = nameOf(s) + "horizon " + std::to_string(h);
      ASSERT_EQ(fused.run(h), plain.run(h)) << what;
      expectSame(fused, plain, what);
      ASSERT_EQ(fused.run(h + 700), plain.run(h + 700)) << what;
      expectSame(fused, plain, what + " and on");
      if (::testing::Test::HasFatalFailure()) return;
    }
  }
}

TEST(VmSuperinstruction, AnInterruptRequestedAtAnyTickIsAcceptedWhereItIsUnfused) {
  const std::vector<Site>& at = sites();
  for (int s = 0; s < kSuperCount; ++s) {
    ASSERT_NE(at[s].program, nullptr) << nameOf(s) << "in none of the programs";
    const vm::Tick start = arrivals(at[s].program->image, at[s].address, 1).first;
    ASSERT_GE(start, 0) << nameOf(s) << "not reached";
    const Pair base(at[s].program->image, start - 1);
    for (vm::Tick t = start; t < windowEnd(s, start); ++t) {
      TestHost h1, h2;
      vm::Vm fused(base.fused, h1), plain(base.plain, h2);
      h1.schedule(t, Irq::Pio);
      h2.schedule(t, Irq::Pio);
      h1.runUntil(fused, t + 600);
      h2.runUntil(plain, t + 600);
      const std::string what = nameOf(s) + "request at " + std::to_string(t);
      ASSERT_EQ(h1.events.size(), h2.events.size()) << what;
      ASSERT_FALSE(h1.events.empty()) << what;
      for (size_t k = 0; k < h1.events.size(); ++k) {
        ASSERT_EQ(h1.events[k].tick, h2.events[k].tick) << what;
        ASSERT_EQ(h1.events[k].pc, h2.events[k].pc) << what;
      }
      expectSame(fused, plain, what);
      if (::testing::Test::HasFatalFailure()) return;
    }
  }
}

TEST(VmSuperinstruction, PrtTicksAreTakenWhereTheyAreUnfused) {
  vm::CostKnobs knobs = vm::calibratedKnobs();
  knobs.timerService = vm::TimerService::Always;
  const vm::CostTable timed = vm::makeCostTable(knobs);
  for (const Program& p : programs()) {
    Pair run(p.image, 0, timed);
    // Stops just after each of the first 20 ticks (9,000 T-states apart).
    for (int k = 1; k <= 20; ++k) {
      const vm::Tick h = k * vm::kPrtTicks + 37;
      ASSERT_EQ(run.fused.run(h), run.plain.run(h)) << p.name;
      EXPECT_EQ(run.fused.timerIsrCycles(), run.plain.timerIsrCycles()) << p.name;
      expectSame(run.fused, run.plain, p.name + " after PRT0 tick " + std::to_string(k));
    }
  }
}

TEST(VmSuperinstruction, ABreakpointOnAnyPieceStopsThereEveryPass) {
  const std::vector<Site>& at = sites();
  for (int s = 0; s < kSuperCount; ++s) {
    ASSERT_NE(at[s].program, nullptr) << nameOf(s) << "in none of the programs";
    // Every piece's address, following the pieces as the decoder does.
    const vm::Image& image = at[s].program->image;
    std::vector<uint32_t> pieces;
    uint32_t a = at[s].address;
    for (int k = 0; k < kSuperShapes[s].n; ++k) {
      pieces.push_back(a);
      const Op o = kSuperShapes[s].pieces[k];
      const auto operand = static_cast<uint32_t>(image.code[a + 1] | (image.code[a + 2] << 8));
      a = o == Op::JMP    ? a + 3 + static_cast<uint32_t>(static_cast<int16_t>(operand))
          : o == Op::CALL ? operand
                          : a + static_cast<uint32_t>(vm::instructionSize(o));
    }
    for (const uint32_t piece : pieces) {
      Pair run(image, 0);
      run.fused.setBreakpoint(piece);
      run.plain.setBreakpoint(piece);
      EXPECT_NE(run.fused.superinstructionAt(at[s].address), s)
          << nameOf(s) << "a breakpoint on any piece stops it fusing";
      for (int stops = 0; stops < 3; ++stops) {
        const std::string what = nameOf(s) + "breakpoint at " + std::to_string(piece);
        ASSERT_EQ(run.fused.run(100'000'000), Stop::Breakpoint) << what;
        ASSERT_EQ(run.plain.run(100'000'000), Stop::Breakpoint) << what;
        ASSERT_EQ(run.fused.pc(), piece) << what;
        expectSame(run.fused, run.plain, what);
        if (::testing::Test::HasFatalFailure()) return;
      }
    }
  }
}

TEST(VmSuperinstruction, APieceThatFaultsFaultsAsItDoesAlone) {
  // fib(30000) recurses until the robot's stack overflows, in CALL or in
  // ENTER: pieces of CallIntoTest and StatementCallIntoTest.
  const vm::Image image = benchProgram("fib", {{"N 23", "N 30000"}, {"REPS 30", "REPS 1"}});
  Pair run(image, 0);
  ASSERT_EQ(run.fused.run(1'000'000'000), Stop::Fault);
  ASSERT_EQ(run.plain.run(1'000'000'000), Stop::Fault);
  EXPECT_EQ(run.fused.fault()->message, "stack overflow");
  expectSame(run.fused, run.plain, "deep recursion");
}

TEST(VmSuperinstruction, TheExpressionStackGuardStopsWhereItDoesUnfused) {
  // A loop that leaves a value on the expression stack every pass around
  // MultiplyAccumulate, whose three loads cross the guard in some pass.
  for (int leftPerPass = 1; leftPerPass <= 3; ++leftPerPass) {
    testkit::Assembler a;
    const uint16_t s = a.data(2), i = a.data(2), j = a.data(2);
    a.bind("top");
    for (int k = 0; k < leftPerPass; ++k) a.op(Op::PUSHW, 7);
    a.op(Op::DBG).op(Op::LDGW, s).op(Op::LDGW, i).op(Op::LDGW, j).op(Op::MULW).op(Op::ADDW);
    a.op(Op::PUSHW, 7).op(Op::ADDW).op(Op::STGW, s);
    a.jump(Op::JMP, "top");
    const vm::Image image = a.finish();
    Pair run(image, 0);
    ASSERT_EQ(run.fused.superinstructionAt(static_cast<uint32_t>(leftPerPass * 3)), [] {
      for (int k = 0; k < kSuperCount; ++k)
        if (kSuperShapes[k].name == "MultiplyAccumulate") return k;
      return -1;
    }());
    ASSERT_EQ(run.fused.run(1'000'000'000), Stop::Fault);
    ASSERT_EQ(run.plain.run(1'000'000'000), Stop::Fault);
    EXPECT_EQ(run.fused.fault()->message,
              "expression stack overflow (too many arguments or values pending)");
    expectSame(run.fused, run.plain, "left per pass " + std::to_string(leftPerPass));
  }
}

}  // namespace
