// Timing on compiled programs: ICEMAN's calibration target (500 slow-spin
// passes in 10 s +/- 2 s), delay-loop linearity, and interrupts landing in
// the middle of a delay loop or of a long library call.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "support/test_host.h"

using namespace simbot;
using simbot::testkit::TestHost;
using vm::Irq;
using vm::Stop;
using vm::Tick;

namespace {

const vm::CostTable& costs() { return testkit::calibratedCosts(); }

std::string readFile(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// First code address the line table gives for a source line.
uint32_t firstAddressOfLine(const vm::Image& img, int line) {
  for (uint32_t i = 0; i < img.lines.size(); ++i)
    if (img.lines[i] == line) return i;
  throw std::runtime_error("no code for line " + std::to_string(line));
}

int lineContaining(const vm::Image& img, const std::string& text, int from = 1) {
  for (int i = from; i <= static_cast<int>(img.sourceLines.size()); ++i)
    if (img.sourceLines[i - 1].find(text) != std::string::npos) return i;
  throw std::runtime_error("no line containing " + text);
}

// Address just after the first CALL to `target` inside `caller`.
uint32_t returnAddressOfFirstCall(const vm::Image& img, const vm::Symbol& caller, uint32_t target) {
  uint32_t at = caller.address;
  while (at < caller.address + caller.size) {
    const auto op = static_cast<vm::Op>(img.code[at]);
    const int size = vm::instructionSize(op);
    if (op == vm::Op::CALL &&
        static_cast<uint32_t>(img.code[at + 1] | (img.code[at + 2] << 8)) == target)
      return at + static_cast<uint32_t>(size);
    at += static_cast<uint32_t>(size);
  }
  throw std::runtime_error("no call found");
}

double seconds(Tick t) { return static_cast<double>(t) / vm::kTicksPerSecond; }

TEST(IcemanTiming, FiveHundredSlowSpinPassesTakeAboutTenSeconds) {
  const auto img =
      testkit::compileOrDie(readFile(SIMBOT_SHARED_DIR "/programs/iceman.dc"), "iceman.dc");
  const auto& search = testkit::symbol(img, "search");
  const auto& mainFn = testkit::symbol(img, "main");
  const uint32_t afterFirstSearch = returnAddressOfFirstCall(img, mainFn, search.address);
  const uint32_t slowSpinPass = firstAddressOfLine(img, lineContaining(img, "cnt++;"));

  TestHost host;  // both eyes read the background value 16
  vm::Vm v(img, host, costs());
  v.setBreakpoint(search.address);
  v.setBreakpoint(afterFirstSearch);
  v.setBreakpoint(slowSpinPass);
  std::vector<Tick> entries;
  Tick firstReturn = -1;
  int passes = 0;
  while (entries.size() < 2) {
    const Stop stop = host.runUntil(v, 120 * vm::kTicksPerSecond);
    ASSERT_EQ(stop, Stop::Breakpoint) << "ICEMAN did not re-enter search() within 120 s";
    if (v.pc() == search.address) entries.push_back(v.now());
    if (v.pc() == afterFirstSearch && firstReturn < 0) firstReturn = v.now();
    if (v.pc() == slowSpinPass && firstReturn >= 0) ++passes;
  }
  ASSERT_GE(firstReturn, 0);
  const double searchSeconds = seconds(firstReturn - entries[0]);
  const double lostSeconds = seconds(entries[1] - firstReturn);
  std::cout << "[ ICEMAN ] first search(): " << searchSeconds
            << " s; 500 slow-spin passes: " << lostSeconds << " s (" << (entries[1] - firstReturn)
            << " ticks); per pass " << lostSeconds / 500 * 1000
            << " ms; motor strings sent: " << host.sends.size() << "\n";
  RecordProperty("search_seconds", std::to_string(searchSeconds));
  RecordProperty("lost_seconds", std::to_string(lostSeconds));
  EXPECT_EQ(passes, 500);
  EXPECT_GE(lostSeconds, 8.0);
  EXPECT_LE(lostSeconds, 12.0);
  EXPECT_EQ(v.fault(), nullptr);
}

// Simulated time from start to the return of main.
Tick runToHalt(const std::string& source) {
  const auto img = testkit::compileOrDie(source);
  TestHost host;
  vm::Vm v(img, host, costs());
  v.setBreakpoint(img.entry + vm::instructionSize(vm::Op::CALL));  // main returned
  EXPECT_EQ(v.run(1000 * vm::kTicksPerSecond), Stop::Breakpoint);
  return v.now();
}

std::string delayProgram(const std::string& type, long n) {
  return type + " z;\nmain()\n{\n  for (z = 0; z < " + std::to_string(n) + "; z++);\n}\n";
}

TEST(DelayLoop, TwiceThePassesTakeTwiceTheTime) {
  for (const std::string type : {"int", "unsigned long"}) {
    const Tick base = runToHalt(delayProgram(type, 0));
    const Tick n = runToHalt(delayProgram(type, 5000)) - base;
    const Tick twoN = runToHalt(delayProgram(type, 10000)) - base;
    EXPECT_GT(n, 0);
    EXPECT_NEAR(static_cast<double>(twoN) / static_cast<double>(n), 2.0, 0.02) << type;
    // Delay loops are executed exactly: the per-pass cost is a whole number.
    EXPECT_EQ((twoN - n) % 5000, 0) << type;
  }
}

const char* kLoopWithHandler = R"(#INT_VEC PIOA_VEC edge
int z;
int hits;
int seen;
interrupt reti edge()
{
    seen = z;
    hits++;
}
main()
{
    for (z = 0; z < 1000; z++);
}
)";

struct Boundary {
  Tick tick;
  uint16_t z;
};

TEST(InterruptTiming, RequestMidDelayLoopLandsOnNextBoundaryAndLoopResumes) {
  const auto img = testkit::compileOrDie(kLoopWithHandler);
  const uint16_t zAddress = static_cast<uint16_t>(testkit::symbol(img, "z").address);
  const uint32_t mainReturn = img.entry + vm::instructionSize(vm::Op::CALL);
  const auto& handler = testkit::symbol(img, "edge");

  // Reference run, one instruction at a time: every boundary and z there.
  std::vector<Boundary> boundaries;
  Tick plainTime = 0;
  {
    TestHost host;
    vm::Vm v(img, host, costs());
    v.setBreakpoint(mainReturn);
    while (v.run(v.now() + 1) != Stop::Breakpoint)
      boundaries.push_back({v.now(), v.read16(zAddress)});
    plainTime = v.now();
  }
  ASSERT_GT(boundaries.size(), 100u);
  // One tick into an instruction in the middle of the loop.
  const Tick request = boundaries[boundaries.size() / 2].tick + 1;
  auto firstAfter = std::find_if(boundaries.begin(), boundaries.end(),
                                 [&](const Boundary& b) { return b.tick >= request; });
  ASSERT_NE(firstAfter, boundaries.end());
  ASSERT_GT(firstAfter->tick, request);  // strictly inside an instruction
  ASSERT_GT(firstAfter->z, 0);
  ASSERT_LT(firstAfter->z, 1000);

  TestHost host;
  vm::Vm v(img, host, costs());
  v.setBreakpoint(mainReturn);
  v.setBreakpoint(handler.address);
  host.schedule(request, Irq::Pio);
  ASSERT_EQ(host.runUntil(v, 100 * vm::kTicksPerSecond), Stop::Breakpoint);
  ASSERT_EQ(v.pc(), handler.address);
  ASSERT_EQ(host.events.size(), 1u);
  const Tick accepted = host.events[0].tick;
  EXPECT_EQ(accepted, firstAfter->tick);
  EXPECT_EQ(v.now(), accepted + costs().interruptAccept);
  EXPECT_EQ(v.read16(zAddress), firstAfter->z);  // loop variable exactly where it was
  ASSERT_EQ(host.runUntil(v, 100 * vm::kTicksPerSecond), Stop::Breakpoint);
  ASSERT_EQ(v.pc(), mainReturn);
  ASSERT_EQ(host.events.size(), 2u);
  const Tick handlerTime = host.events[1].tick - accepted;  // acceptance to end of RETI
  EXPECT_EQ(v.now(), plainTime + handlerTime);
  EXPECT_EQ(v.read16(zAddress), 1000);
  EXPECT_EQ(v.read16(static_cast<uint16_t>(testkit::symbol(img, "hits").address)), 1);
  EXPECT_EQ(v.read16(static_cast<uint16_t>(testkit::symbol(img, "seen").address)), firstAfter->z);
}

const char* kStrcpyWithHandler = R"(#INT_VEC PIOA_VEC edge
char dst[200];
int hits;
interrupt reti edge()
{
    hits++;
}
main()
{
    strcpy(dst, "this string is long enough that copying it takes well over a hundred T-states on the Z180, so it must be interruptible");
    hits = hits + 10;
}
)";

TEST(InterruptTiming, RequestMidLibraryCallLandsOnItsNextInternalStep) {
  const auto img = testkit::compileOrDie(kStrcpyWithHandler);
  const uint32_t mainReturn = img.entry + vm::instructionSize(vm::Op::CALL);
  const int copyLine = lineContaining(img, "strcpy(dst");
  std::vector<Tick> boundaries;
  {
    TestHost host;
    vm::Vm v(img, host, costs());
    v.setBreakpoint(mainReturn);
    while (v.run(v.now() + 1) != Stop::Breakpoint)
      if (v.line() == copyLine) boundaries.push_back(v.now());
  }
  ASSERT_GT(boundaries.size(), 20u);
  // Internal steps of the copy are never more than 100 T-states apart.
  for (size_t i = 1; i < boundaries.size(); ++i)
    EXPECT_LE(boundaries[i] - boundaries[i - 1], 100) << i;
  const Tick request = boundaries[boundaries.size() / 2] + 1;
  const Tick expected = boundaries[boundaries.size() / 2 + 1];

  TestHost host;
  vm::Vm v(img, host, costs());
  v.setBreakpoint(mainReturn);
  host.schedule(request, Irq::Pio);
  ASSERT_EQ(host.runUntil(v, 100 * vm::kTicksPerSecond), Stop::Breakpoint);
  ASSERT_EQ(host.events.size(), 2u);
  EXPECT_EQ(host.events[0].tick, expected);
  EXPECT_EQ(img.lineAt(host.events[0].pc), copyLine);
  // The copy resumed after the handler and finished intact.
  const uint16_t dst = static_cast<uint16_t>(testkit::symbol(img, "dst").address);
  std::string copied;
  for (uint16_t a = dst; v.read8(a) != 0; ++a) copied.push_back(static_cast<char>(v.read8(a)));
  EXPECT_EQ(copied.substr(0, 16), "this string is l");
  EXPECT_EQ(copied.size(), 118u);
  EXPECT_EQ(v.read16(static_cast<uint16_t>(testkit::symbol(img, "hits").address)), 11);
}

}  // namespace
