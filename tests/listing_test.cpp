// `simbot compile --disasm` against the clock (issue 24): for every opcode
// and every library routine, the T-states the listing prints for an
// instruction are what the VM charges it, on every path the listing names,
// measured between a breakpoint on the instruction and the one it leads to
// (or, where that varies, over one instruction: run() to the next tick).
//
// A listing field is one figure per path ("44/46"), a figure per unit
// ("57+36n": the call and n bytes), or a call and its conversion ("163+276").
// Every measured charge must be one of the field's figures (for a per-unit
// figure: A + B n with n >= 1, and two runs n units apart differ by B per
// unit), and every path the field prints must be reached by some operands.
#include <gtest/gtest.h>

#include <bit>
#include <cstring>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "compiler/compiler.h"
#include "support/assembler.h"
#include "support/test_host.h"
#include "vm/bytecode.h"

using namespace simbot;
using simbot::testkit::Assembler;
using simbot::testkit::TestHost;
using vm::Op;
using vm::Stop;

namespace {

const vm::CostTable& costs() { return testkit::calibratedCosts(); }

struct Alternative {
  int64_t base = 0;
  int64_t perUnit = 0;  // 0: a fixed figure
};

// The listing's cost field for the instruction at `at`.
std::vector<Alternative> listedCost(const vm::Image& img, uint32_t at) {
  std::istringstream text(vm::disassemble(img));
  std::string line;
  while (std::getline(text, line)) {
    std::istringstream fields(line);
    std::string address, cost;
    if (!(fields >> address >> cost) || address.size() != 4) continue;
    if (std::stoul(address, nullptr, 16) != at) continue;
    std::vector<Alternative> out;
    std::istringstream paths(cost);
    std::string path;
    while (std::getline(paths, path, '/')) {
      Alternative alt;
      const auto plus = path.find('+');
      alt.base = std::stoll(path.substr(0, plus));
      if (plus != std::string::npos) {
        const std::string rest = path.substr(plus + 1);
        if (rest.ends_with("n"))
          alt.perUnit = std::stoll(rest.substr(0, rest.size() - 1));
        else
          alt.base += std::stoll(rest);  // a conversion that always follows
      }
      out.push_back(alt);
    }
    return out;
  }
  ADD_FAILURE() << "no listing line at " << at;
  return {};
}

// What one instruction took on the clock: the program's setup, then the
// instruction at "it", then HALT at "after".
struct Measured {
  std::optional<vm::Tick> ticks;  // none: it faulted (division by zero)
  std::vector<Alternative> listed;
};

Measured measure(Assembler& a) {
  const auto img = a.finish();
  TestHost host;
  vm::Vm v(img, host, costs());
  v.setBreakpoint(a.label("it"));
  EXPECT_EQ(v.run(100'000'000), Stop::Breakpoint);
  const vm::Tick before = v.now();
  v.setBreakpoint(a.label("it"), false);
  v.setBreakpoint(a.label("after"));
  const Stop stop = v.run(1'000'000'000);
  Measured m;
  m.listed = listedCost(img, a.label("it"));
  if (stop == Stop::Fault) return m;
  EXPECT_EQ(stop, Stop::Breakpoint) << v.fault()->message;
  m.ticks = v.now() - before;
  return m;
}

// The alternative `ticks` matches, or -1.
int matching(const std::vector<Alternative>& listed, vm::Tick ticks) {
  for (size_t i = 0; i < listed.size(); ++i) {
    const Alternative& alt = listed[i];
    if (alt.perUnit == 0 ? ticks == alt.base
                         : ticks > alt.base && (ticks - alt.base) % alt.perUnit == 0)
      return static_cast<int>(i);
  }
  return -1;
}

enum class Kind { Word, Long, Float };

// Operands that reach every path: signs, zero, the extremes, small shift
// counts.
std::vector<uint32_t> samples(Kind k) {
  switch (k) {
    case Kind::Word:
      return {0, 1, 2, 5, 17, 0x7FFF, 0x8000, 0xFFFF};
    case Kind::Long:
      return {0, 1, 2, 5, 40, 0x7FFFFFFF, 0x80000000, 0xFFFFFFFF};
    case Kind::Float:
      return {std::bit_cast<uint32_t>(0.0f),  std::bit_cast<uint32_t>(1.0f),
              std::bit_cast<uint32_t>(-1.0f), std::bit_cast<uint32_t>(2.5f),
              std::bit_cast<uint32_t>(1e30f), std::bit_cast<uint32_t>(-3e-5f)};
  }
  return {};
}

// The kind of value an opcode takes, from its name (opcodes.def: W 16-bit,
// L 32-bit, F float; a conversion takes what its name starts with).
Kind operandKind(std::string_view name) {
  if (name.starts_with("F2")) return Kind::Float;
  if (name.starts_with("L2") || name.starts_with("UL2")) return Kind::Long;
  if (name.starts_with("W2") || name.starts_with("UW2") || name == "SXB") return Kind::Word;
  if (name.ends_with("F")) return Kind::Float;
  if (name.ends_with("L")) return Kind::Long;
  return Kind::Word;
}

bool isControlOrCostate(Op op) {
  switch (op) {
    case Op::JMP:
    case Op::JZ:
    case Op::JNZ:
    case Op::CALL:
    case Op::CALLI:
    case Op::ENTER:
    case Op::RET:
    case Op::RETI:
    case Op::HALT:
    case Op::LIB:
    case Op::COSTATE:
    case Op::COYIELD:
    case Op::COEND:
    case Op::CODONE:
      return true;
    default:
      return false;
  }
}

void push(Assembler& a, Kind k, uint32_t v) {
  if (k == Kind::Word)
    a.op(Op::PUSHW, v & 0xFFFF);
  else
    a.op(k == Kind::Long ? Op::PUSHL : Op::PUSHF, v);
}

void checkAll(const std::string& what, const std::vector<Measured>& runs) {
  SCOPED_TRACE(what);
  ASSERT_FALSE(runs.empty());
  const std::vector<Alternative>& listed = runs.front().listed;
  ASSERT_FALSE(listed.empty());
  std::set<int> reached;
  for (const Measured& m : runs) {
    if (!m.ticks) continue;
    const int i = matching(listed, *m.ticks);
    EXPECT_GE(i, 0) << "charged " << *m.ticks << ", not among the listed figures";
    // Paths with the same figure ("58/59/59/61") are told apart by nothing
    // but their operands: reaching the figure reaches them all.
    for (size_t j = 0; j < listed.size(); ++j)
      if (i >= 0 && listed[j].base == listed[static_cast<size_t>(i)].base &&
          listed[j].perUnit == listed[static_cast<size_t>(i)].perUnit)
        reached.insert(static_cast<int>(j));
  }
  for (size_t i = 0; i < listed.size(); ++i)
    EXPECT_TRUE(reached.count(static_cast<int>(i)))
        << "listed path " << i << " (" << listed[i].base << ") never charged";
}

// Opcodes: every pair (or single) of operand samples; memory operands at a
// data address, a pointer operand's both orders a data address too.
TEST(ListingMatchesClock, EveryDataOpcodeOnEveryPath) {
  int checked = 0;
  for (int o = 0; o < vm::kOpCount; ++o) {
    const Op op = static_cast<Op>(o);
    if (isControlOrCostate(op)) continue;
    const vm::OpInfo& info = vm::info(op);
    const std::string_view name = info.name;
    const Kind kind = operandKind(name);
    const bool pointers = name.starts_with("LDI") || name.starts_with("STI") || op == Op::COPY;
    std::vector<std::vector<uint32_t>> operandSets;
    if (pointers) {
      operandSets = {{vm::kDataBase, vm::kDataBase + 8u}};
    } else if (info.pop == 0) {
      operandSets = {{}};
    } else if (info.pop == 1) {
      for (uint32_t x : samples(kind)) operandSets.push_back({x});
    } else {
      for (uint32_t x : samples(kind))
        for (uint32_t y : samples(kind)) operandSets.push_back({x, y});
    }
    std::vector<Measured> runs;
    for (const auto& operands : operandSets) {
      Assembler a;
      a.data(32);
      const bool local = name.starts_with("LDL") || name.starts_with("STL") || op == Op::LEAL;
      if (local) a.op(Op::ENTER, 8);  // a frame for the local
      for (uint32_t v : operands) push(a, pointers ? Kind::Word : kind, v);
      a.bind("it");
      if (info.shape == vm::Shape::NONE)
        a.op(op);
      else if (op == Op::COPY)
        a.op(op, 8);
      else if (local)
        a.op(op, 2);
      else
        a.op(op, vm::kDataBase);  // globals; a constant to push
      a.bind("after").op(Op::HALT);
      runs.push_back(measure(a));
    }
    checkAll(std::string(name), runs);
    ++checked;
  }
  EXPECT_EQ(checked, vm::kOpCount - 14);
}

// Control flow, each way it can go: a jump (taken or not, both to the
// next instruction), a call to the next instruction, a frame, a return
// with and without one, a call through a pointer.
TEST(ListingMatchesClock, EveryControlOpcode) {
  std::vector<Measured> jz, jnz;
  for (const uint32_t v : {0u, 1u}) {
    for (const Op op : {Op::JZ, Op::JNZ}) {
      Assembler a;
      a.op(Op::PUSHW, v).bind("it").jump(op, "after").bind("after").op(Op::HALT);
      (op == Op::JZ ? jz : jnz).push_back(measure(a));
    }
  }
  checkAll("JZ", jz);
  checkAll("JNZ", jnz);
  {
    Assembler a;
    a.bind("it").jump(Op::JMP, "after").bind("after").op(Op::HALT);
    checkAll("JMP", {measure(a)});
  }
  {
    // 0: CALL 3; 3 (after): HALT.
    Assembler a;
    a.bind("it").op(Op::CALL, 3).bind("after").op(Op::HALT);
    checkAll("CALL", {measure(a)});
  }
  {
    Assembler a;
    a.bind("it").op(Op::ENTER, 6).bind("after").op(Op::HALT);
    checkAll("ENTER", {measure(a)});
  }
  for (const bool autoFrame : {false, true}) {
    // 0: CALL 4; 3 (after): HALT; f at 4: [ENTER 2;] RET.
    Assembler a;
    a.op(Op::CALL, 4).bind("after").op(Op::HALT);
    if (autoFrame) a.op(Op::ENTER, 2);
    a.bind("it").op(Op::RET);
    checkAll(autoFrame ? "RET after ENTER" : "RET", {measure(a)});
  }
  {
    // 0: PUSHW 6 (3); 3: CALLI 0 (2); 5: HALT; f at 6 (after): HALT.
    Assembler a;
    a.op(Op::PUSHW, 6).bind("it").op(Op::CALLI, 0).op(Op::HALT).bind("after").op(Op::HALT);
    a.image.entries.push_back({6, 0});
    checkAll("CALLI", {measure(a)});
  }
}

bool isCostateRoutine(std::string_view name) {
  return name.starts_with("Delay") || name.starts_with("Co") || name.starts_with("isCo");
}

// One instruction from a breakpoint: run() to the next tick stops at the
// boundary after it. None when an interrupt came first or in between.
std::optional<vm::Tick> stepOne(vm::Vm& v) {
  const vm::Tick before = v.now();
  const auto interrupts = v.stats().interrupts;
  const uint64_t count = v.stats().instructions;
  v.run(before + 1);
  if (v.stats().interrupts != interrupts || v.stats().instructions != count + 1) return {};
  return v.now() - before;
}

TEST(ListingMatchesClock, HaltAndReti) {
  {
    Assembler a;
    a.bind("it").op(Op::HALT);
    const auto img = a.finish();
    TestHost host;
    vm::Vm v(img, host, costs());
    checkAll("HALT", {Measured{stepOne(v), listedCost(img, 0)}});
  }
  {
    // 0: loop: DBG; JMP loop (3); handler at 4: RETI.
    Assembler a;
    a.bind("loop").op(Op::DBG).jump(Op::JMP, "loop");
    a.bind("it").op(Op::RETI);
    a.image.vectors.push_back({vm::kVecPIOA, static_cast<uint16_t>(a.label("it")), "h"});
    const auto img = a.finish();
    TestHost host;
    vm::Vm v(img, host, costs());
    v.setBreakpoint(a.label("it"));
    v.request(vm::Irq::Pio, vm::kVecPIOA);
    ASSERT_EQ(v.run(100'000), Stop::Breakpoint);
    checkAll("RETI", {Measured{stepOne(v), listedCost(img, a.label("it"))}});
  }
}

// The costatement opcodes and routines, in a program that takes each of
// their paths over 6 s: every COSTATE, COYIELD, COEND and CODONE is
// stepped from a breakpoint each time the robot reaches it, and every call
// of a costatement routine measured to the instruction after its LIB.
TEST(ListingMatchesClock, EveryCostatementOpcodeAndRoutine) {
  const std::string source = R"(int n, i, r;
main() {
  for (n = 0; n < 4000; n++) {
    costate every always_on {
      waitfor(DelayMs(20L));
      waitfor(DelaySec(1L));
      waitfor(DelayTicks(3));
      yield;
      if (n > 3500) abort;
    }
    costate later {
      yield;
      i++;
    }
    costate once init_on {
      i++;
    }
    if (n == 5) CoBegin(&later);
    if (n == 9) CoPause(&every);
    if (n == 12) CoResume(&every);
    if (n == 15) CoReset(&later);
    r = isCoDone(&once) + isCoRunning(&later);
    for (i = 0; i < 50; i++) ;
  }
}
)";
  const auto compiled = compiler::compile(source, "co.dc");
  ASSERT_TRUE(compiled.image) << compiled.errors[0].format();
  const vm::Image& img = *compiled.image;
  TestHost host;
  vm::Vm v(img, host, costs());
  std::map<uint32_t, std::vector<Measured>> runs;  // by code address
  std::map<uint32_t, std::string> names;
  std::map<uint32_t, std::vector<Alternative>> listed;
  for (uint32_t at = 0; at < img.code.size();) {
    const auto op = static_cast<Op>(img.code[at]);
    const bool co = op == Op::COSTATE || op == Op::COYIELD || op == Op::COEND || op == Op::CODONE;
    const bool coLib =
        op == Op::LIB && isCostateRoutine(vm::info(static_cast<vm::Lib>(img.code[at + 1])).name);
    if (co || coLib) {
      v.setBreakpoint(at);
      names[at] = coLib ? std::string(vm::info(static_cast<vm::Lib>(img.code[at + 1])).name)
                        : std::string(vm::info(op).name);
      listed[at] = listedCost(img, at);
    }
    at += static_cast<uint32_t>(vm::instructionSize(op));
  }
  const vm::Tick end = 6 * vm::kTicksPerSecond;
  while (v.now() < end && v.run(end) == Stop::Breakpoint) {
    const uint32_t at = v.pc();
    const auto op = static_cast<Op>(img.code[at]);
    if (op != Op::LIB) {
      runs[at].push_back(Measured{stepOne(v), listed[at]});
      continue;
    }
    // A routine: to the instruction after its LIB (a breakpoint of its own
    // when it is one of ours).
    const uint32_t next = at + 3;
    const bool ours = names.count(next) > 0;
    const vm::Tick before = v.now();
    const auto interrupts = v.stats().interrupts;
    if (!ours) v.setBreakpoint(next);
    EXPECT_EQ(v.run(end + vm::kTicksPerSecond), Stop::Breakpoint);
    if (!ours) v.setBreakpoint(next, false);
    ASSERT_EQ(v.pc(), next);
    const bool quiet = v.stats().interrupts == interrupts;
    runs[at].push_back(
        Measured{quiet ? std::optional<vm::Tick>(v.now() - before) : std::nullopt, listed[at]});
  }
  ASSERT_EQ(v.fault(), nullptr) << v.fault()->message;
  // Each site's charges are among its listed figures; each figure of a
  // kind (COSTATE's stopped, fresh and resumed) is reached at some site.
  std::map<std::string, std::vector<Measured>> byKind;
  for (auto& [at, list] : runs) {
    for (const Measured& m : list) {
      if (!m.ticks) continue;
      EXPECT_GE(matching(m.listed, *m.ticks), 0)
          << names[at] << " at " << at << " charged " << *m.ticks;
      byKind[names[at]].push_back(m);
    }
  }
  for (const auto& [kind, list] : byKind) checkAll(kind, list);
  for (const char* kind :
       {"COSTATE", "COYIELD", "COEND", "CODONE", "DelayMs", "DelaySec", "DelayTicks", "CoBegin",
        "CoReset", "CoPause", "CoResume", "isCoDone", "isCoRunning"})
    EXPECT_TRUE(byKind.count(kind)) << kind << " never measured";
}

// A library routine called with `args` (pushed as words, or as floats
// where the routine's letter is 'f').
Measured measureLib(vm::Lib lib, const std::vector<uint32_t>& args, Assembler& a) {
  const std::string_view letters = vm::info(lib).args;
  for (size_t i = 0; i < args.size(); ++i)
    push(a, i < letters.size() && letters[i] == 'f' ? Kind::Float : Kind::Word, args[i]);
  a.bind("it").lib(lib, static_cast<int>(args.size())).bind("after").op(Op::HALT);
  return measure(a);
}

// Library routines: each with arguments that reach its paths; one with an
// inner loop twice, n and n + 3 units, whose charges differ by 3 units.
TEST(ListingMatchesClock, EveryLibraryRoutine) {
  int checked = 0;
  for (int id = 0; id < vm::kLibCount; ++id) {
    const auto lib = static_cast<vm::Lib>(id);
    const vm::LibInfo& info = vm::info(lib);
    if (isCostateRoutine(info.name)) continue;  // EveryCostatementOpcodeAndRoutine
    SCOPED_TRACE(std::string(info.name));
    // Two runs: for a routine with units, strings of 4 and 7 characters
    // (memory routines: counts 4 and 7); otherwise arguments of each sign.
    std::vector<Measured> runs;
    std::vector<int64_t> units;
    for (const int length : {4, 7}) {
      Assembler a;
      const std::string text(static_cast<size_t>(length), '7');
      const uint16_t s1 = a.string(text), s2 = a.string(text), buf = a.data(64);
      const uint16_t fmt = a.string(text);
      std::vector<uint32_t> args;
      const std::string_view name = info.name;
      if (name == "printf") {
        args = {fmt};
      } else if (name == "sprintf") {
        args = {buf, fmt};
      } else if (name == "strcat") {
        args = {buf, s1};  // buf holds "": the copy is the string and its NUL
      } else if (name == "strchr" || name == "strrchr") {
        args = {s1, 'x'};  // not there: the whole string and its NUL
      } else if (name == "ser_send_z1") {
        const uint16_t cc = a.data(2);
        a.image.data[cc - vm::kDataBase] = 8;
        args = {s1, cc};
      } else {
        for (const char letter : info.args) {
          if (letter == '.') break;
          if (letter == 'p')
            args.push_back(args.empty() ? (name == "strcpy" || name == "memset" ||
                                                   name == "memcpy" || name == "strncpy"
                                               ? buf
                                               : s1)
                                        : s2);
          if (letter == 'i') args.push_back(static_cast<uint32_t>(length));
          if (letter == 'u' || letter == 'l') args.push_back(static_cast<uint32_t>(length));
          if (letter == 'f') args.push_back(std::bit_cast<uint32_t>(0.5f + length));
        }
      }
      runs.push_back(measureLib(lib, args, a));
      units.push_back(length);
      if (info.unit.empty()) break;
    }
    if (lib == vm::Lib::ABS)
      for (const uint32_t v : {0xFFFBu, 5u}) {
        Assembler a;
        runs.push_back(measureLib(lib, {v}, a));
      }
    checkAll(std::string(info.name), runs);
    if (!info.unit.empty()) {
      ASSERT_EQ(runs.size(), 2u);
      ASSERT_TRUE(runs[0].ticks && runs[1].ticks);
      const int64_t perUnit = runs[0].listed.back().perUnit;
      ASSERT_GT(perUnit, 0);
      EXPECT_EQ(*runs[1].ticks - *runs[0].ticks, (units[1] - units[0]) * perUnit);
      // And exactly the units the routine processes for a length-L text or
      // count: the string and its NUL (strcat: also the NUL it starts at;
      // sprintf writes its NUL; atoi reads it), or the count (printf: the
      // characters it prints).
      const std::string_view name = info.name;
      const int64_t extra = name == "strcat" ? 2
                            : name == "memset" || name == "memcpy" || name == "strncpy" ||
                                    name == "strncmp" || name == "memcmp" || name == "printf"
                                ? 0
                                : 1;
      for (size_t k = 0; k < 2; ++k)
        EXPECT_EQ(*runs[k].ticks, runs[k].listed.back().base + (units[k] + extra) * perUnit)
            << "length " << units[k];
    }
    ++checked;
  }
  EXPECT_GT(checked, 30);
}

}  // namespace
