// Function pointers (issue 24): what the compiler refuses, with the line and
// a reason; what an indirect call costs on the clock, worked by hand from
// vm/z180.def; and the calls the chip would have made into the weeds, which
// fault that robot. What such calls compute is in
// tests/programs/function_pointers.dc.
#include <gtest/gtest.h>

#include <string>

#include "compiler/compiler.h"
#include "support/test_host.h"
#include "vm/bytecode.h"

using namespace simbot;
using simbot::testkit::TestHost;
using vm::Tick;

namespace {

std::string firstError(const std::string& source) {
  const auto r = compiler::compile(source, "f.dc");
  return r.errors.empty() ? std::string("<none>") : r.errors[0].format();
}

bool startsWith(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

TEST(FunctionPointers, MisusesAreErrorsAtTheirColumn) {
  const std::string f = "int f(int x) { return x; }\n";
  EXPECT_PRED2(startsWith, firstError(f + "main() { int (*p)(int); p = f; p = p + 1; }\n"),
               "f.dc:2:38: error: arithmetic on a pointer to a function");
  EXPECT_PRED2(startsWith, firstError(f + "main() { int (*p)(int); p = f; p++; }\n"),
               "f.dc:2:33: error: arithmetic on a pointer to a function");
  EXPECT_PRED2(startsWith, firstError(f + "main() { int (*p)(int); p = f; p(1, 2); }\n"),
               "f.dc:2:33: error: too many arguments in a call through 'int (*)()' (expected 1, "
               "got 2)");
  EXPECT_PRED2(startsWith, firstError(f + "main() { int n; n(1); }\n"),
               "f.dc:2:18: error: called object 'n' is not a function");
  EXPECT_PRED2(startsWith, firstError(f + "main() { int (*p)(int, ...); }\n"),
               "f.dc:2:24: error: variadic functions are not supported");
  EXPECT_PRED2(startsWith,
               firstError("#INT_VEC PIOA_VEC edge\ninterrupt reti edge() { }\n"
                          "main() { int (*p)(); p = edge; }\n"),
               "f.dc:3:26: error: cannot take the address of interrupt function 'edge'");
  EXPECT_PRED2(startsWith,
               firstError("#INT_VEC PIOA_VEC edge\nvoid edge();\n"
                          "main() { void (*p)(); p = edge; }\ninterrupt reti edge() { }\n"),
               "f.dc:3:27: error: cannot take the address of interrupt function 'edge'");
  EXPECT_PRED2(startsWith, firstError("int g();\nmain() { int (*p)(); p = g; }\n"),
               "f.dc:2:26: error: undefined function 'g'");
  EXPECT_PRED2(startsWith, firstError("main() { int (*p)(); p = strlen; }\n"),
               "f.dc:1:26: error: library routine 'strlen' has no address in simbot");
  // *p designates the function, an rvalue: not an assignment to p.
  EXPECT_PRED2(startsWith, firstError(f + "main() { int (*p)(int); *p = f; }\n"),
               "f.dc:2:28: error: expression is not assignable");
}

// Redundant parentheses in a declarator are C89's: around a name, around
// a nested declarator, or both. getf is a function returning a pointer to
// a function (int, int) -> int, so its result's type is q's, and it is
// called with two arguments. 150 parentheses around a name, and a nest of 60
// "(*" (a 60-deep pointer), are parsed once each (each "(*" level used to
// be parsed twice: 2^60 passes).
TEST(FunctionPointers, DeclaratorsTakeRedundantParentheses) {
  const std::string getf =
      "int add(int a, int b) { return a + b; }\nint (*(getf(void)))(int, int) { return add; }\n";
  EXPECT_EQ(firstError(getf + "int (x), ((*fp))(void);\nint (*q)(int, int);\n"
                              "main() { q = getf(); x = q(1, 2); x = sizeof(int (*)(int)); }\n"),
            "<none>");
  // getf() is the pointer: called with one argument, not two (col 20).
  EXPECT_PRED2(startsWith, firstError(getf + "int n;\nmain() { n = getf()(1); }\n"),
               "f.dc:4:20: error: too few arguments in a call through 'int (*)()' (expected 2, "
               "got 1)");
  std::string pointers;
  for (int i = 0; i < 60; ++i) pointers += "(*";
  const std::string deep = "int " + std::string(150, '(') + "x" + std::string(150, ')') + ", " +
                           pointers + "p" + std::string(60, ')') + ";\nmain() { x = 1; p = 0; }\n";
  EXPECT_EQ(firstError(deep), "<none>");
}

// The Z180 sequence of a call through a pointer (vm/opcodes.def CALLI):
// EX DE,HL 3 + POP HL 9 + CALL nn 16 + PUSH DE 11 + RET 9 = 48 T-states
// (vm/z180.def), stretched by the calibrated DRAM refresh of 2 every 20,
// rounded per instruction: (48 x 2 + 10) / 20 = 5 in integers, 53 in all,
// from the CALLI to the first instruction of the function it reaches.
TEST(FunctionPointers, AnIndirectCallTakesItsSequencesTStates) {
  const auto img = testkit::compileOrDie(R"(int n;
int set(int v) { n = v; return 0; }
int (*p)(int) = set;
main()
{
    p(3);
}
)");
  uint32_t at = 0;
  while (at < img.code.size() && img.code[at] != static_cast<uint8_t>(vm::Op::CALLI))
    at += static_cast<uint32_t>(vm::instructionSize(static_cast<vm::Op>(img.code[at])));
  ASSERT_LT(at, img.code.size());
  ASSERT_EQ(img.entries.size(), 2u);  // main and set
  uint32_t target = 0;
  for (const auto& sym : img.symbols)
    if (sym.name == "set") target = sym.address;
  ASSERT_TRUE(img.entryAt(target) != nullptr);
  TestHost host;
  vm::Vm v(img, host, testkit::calibratedCosts());
  v.setBreakpoint(at);
  v.setBreakpoint(target);
  ASSERT_EQ(v.run(vm::kTicksPerSecond), vm::Stop::Breakpoint);
  ASSERT_EQ(v.pc(), at);
  const Tick before = v.now();
  ASSERT_EQ(v.run(vm::kTicksPerSecond), vm::Stop::Breakpoint);
  ASSERT_EQ(v.pc(), target);
  EXPECT_EQ(v.now() - before, 53);
}

// A pointer that does not hold a function's first instruction, or a call
// with another count of arguments than the function pops, faults the robot
// (the chip would jump into the middle of code, or return with its stack
// unbalanced), naming what was wrong; the host goes on.
TEST(FunctionPointers, BadCallsFaultTheRobot) {
  const auto faultOf = [](const std::string& source) {
    const auto img = testkit::compileOrDie(source);
    TestHost host;
    vm::Vm v(img, host, testkit::calibratedCosts());
    EXPECT_EQ(host.runUntil(v, vm::kTicksPerSecond), vm::Stop::Fault);
    return v.fault() ? v.fault()->message : std::string("<no fault>");
  };
  EXPECT_EQ(faultOf("int (*p)();\nmain() { p(); }\n"), "call through a null function pointer");
  EXPECT_EQ(faultOf("int two(int a, int b) { return a + b; }\nint (*p)();\n"
                    "main() { p = two; p(1); }\n"),
            "call through a pointer to 'two' with 1 argument; it takes 2");
  const std::string inside = faultOf(
      "int one(int a) { return a + 1; }\nint (*p)();\n"
      "main() { p = (int (*)())((unsigned)one + 1); p(1); }\n");
  EXPECT_PRED2(startsWith, inside, "call through a pointer to 0x");
  EXPECT_NE(inside.find("which is not the start of a function (it is inside 'one')"),
            std::string::npos)
      << inside;
}

}  // namespace
