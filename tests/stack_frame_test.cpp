// Return addresses on the robot's stack (issue 24): what the host keeps of
// the calls stays bounded when a program keeps diverting its returns. What
// a smashed frame does is in tests/programs/return_address_*.dc and
// saved_fp_overwritten.dc; the layout in tests/vm_test.cpp.
#include <gtest/gtest.h>

#include <string>

#include "compiler/compiler.h"
#include "support/test_host.h"

using namespace simbot;
using simbot::testkit::TestHost;

namespace {

// deep() recurses 7,000 calls, then points its IX's saved copy and its
// return address back into again(): each pass of main's loop returns once
// over 7,000 frames that will never return. The host drops the calls that
// SP has passed, so its record never holds more than one pass's calls
// (7,000 deep, again and main), however long the robot runs.
TEST(StackFrames, DivertedReturnsKeepTheCallRecordBounded) {
  const std::string source = R"(void again(int m);
void deep(int n);
main()
{
    for (;;)
        again(1);
}
#class auto
void again(int m)
{
    int k;
    deep(7000);
}
void deep(int n)
{
    int *p;
    if (n > 0) {
        deep(n - 1);
        return;
    }
    p = &n;
    p[2] = 0xFFEE;
    p = (int *)0xFFF4;
    *p = (int)again + 13;
}
)";
  const auto r = compiler::compile(source, "deep.dc");
  ASSERT_TRUE(r.image) << r.errors[0].format();
  TestHost host;
  vm::Vm v(*r.image, host, testkit::calibratedCosts());
  int deepest = 0;
  for (int second = 1; second <= 60; ++second) {
    host.runUntil(v, second * vm::kTicksPerSecond);
    ASSERT_EQ(v.fault(), nullptr) << v.fault()->message;
    deepest = std::max(deepest, v.callDepth());
  }
  EXPECT_GT(v.stats().instructions, 10'000'000u);  // many passes ran
  EXPECT_LE(deepest, 7'000 + 1 + 2);
}

}  // namespace
