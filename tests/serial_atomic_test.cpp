// The serial library's calls are atomic and leave the caller's interrupt
// state as they found it (DESIGN.md, "Interrupts"): no request is accepted
// inside ser_send_z1 or ser_init_z1; one raised during them is accepted
// right after the call; a caller with interrupts disabled stays disabled.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "config/config.h"
#include "plant/plant.h"
#include "scheduler/match.h"
#include "support/assembler.h"
#include "support/programs.h"
#include "support/test_host.h"
#include "support/traced.h"

using namespace simbot;
using simbot::testkit::Assembler;
using simbot::testkit::TestHost;
using vm::Irq;
using vm::Op;
using vm::Stop;
using vm::Tick;

namespace {

uint32_t libCallCost(const vm::CostTable& t, vm::Lib l) { return t.libCall[static_cast<int>(l)]; }

// Arms port A as ICEMAN does, then sends one frame; the edge handler counts.
const std::string kSendWithEdge = R"(#INT_VEC PIOA_VEC edge
char buf[9];
char cc;
int z, hits;
interrupt reti edge()
{
    hits++;
}
main()
{
    ser_init_z1(0, 9600/1200);
)" + std::string(testkit::kArmPortA) +
                                  R"(    strcpy(buf, "4fgr4rgr");
    cc = sizeof(buf);
    ser_send_z1(buf, &cc);
    for (z = 0; z < 2000; z++);
}
)";

// Address of the first LIB instruction calling `lib`.
uint32_t firstLibCall(const vm::Image& img, vm::Lib lib) {
  uint32_t at = 0;
  while (at < img.code.size()) {
    const auto op = static_cast<Op>(img.code[at]);
    if (op == Op::LIB && img.code[at + 1] == static_cast<uint8_t>(lib)) return at;
    at += static_cast<uint32_t>(vm::instructionSize(op));
  }
  throw std::runtime_error("no such library call");
}

TEST(SerialAtomic, EdgeDuringSerSendIsAcceptedAfterItAndTheFrameLatchesIntact) {
  const auto img = testkit::compileOrDie(kSendWithEdge, "send.dc");
  const vm::CostTable& costs = testkit::calibratedCosts();
  // Where the ser_send_z1 call starts, from a bare VM (the match runs the
  // same instructions at the same ticks until the first request).
  const uint32_t sendAt = firstLibCall(img, vm::Lib::SER_SEND_Z1);
  Tick callStart = 0;
  {
    TestHost host;
    vm::Vm v(img, host, costs);
    v.setBreakpoint(sendAt);
    ASSERT_EQ(host.runUntil(v, vm::kTicksPerSecond), Stop::Breakpoint);
    callStart = v.now();
  }
  // The call's sequence is longer than a library step (100 T-states), so
  // before it was atomic it had a boundary at callStart + 100.
  const Tick callEnd = callStart + libCallCost(costs, vm::Lib::SER_SEND_Z1);
  ASSERT_GT(callEnd - callStart, 100);
  const Tick request = callStart + 50;  // well inside the call

  scheduler::MatchConfig c;
  c.arena =
      config::makeArenaConfig(config::loadProfile(SIMBOT_SOURCE_DIR "/profiles/default.toml"), 1);
  c.robots.push_back({"A", "send.dc", img});
  c.endTick = 2 * scheduler::kTicksPerSecond;
  c.stopWhenAllExited = true;
  c.injections.push_back(config::parseInjection("A:edge_fore@" + std::to_string(request) + "t", 1));
  const testkit::TracedRun r = testkit::runTraced(c);
  Tick sendT = -1, acceptedT = -1, injectionT = -1;
  std::vector<std::string> latched;
  for (const auto& line : r.trace) {
    const auto j = nlohmann::json::parse(line);
    const std::string type = j.at("type");
    if (type == "serial_send" && sendT < 0) sendT = j.at("t").get<Tick>();
    if (type == "interrupt_accepted" && acceptedT < 0) acceptedT = j.at("t").get<Tick>();
    if (type == "injection" && injectionT < 0) injectionT = j.at("t").get<Tick>();
    if (type == "frame_latched") latched.push_back(j.at("bytes").get<std::string>());
  }
  // The request was raised inside the call...
  ASSERT_GE(injectionT, 0);
  EXPECT_GT(injectionT, callStart);
  EXPECT_LT(injectionT, callEnd);
  // ...the call ran to its end (T0 is its last tick)...
  EXPECT_EQ(sendT, callEnd);
  // ...and the handler was accepted at the first boundary after it, with no
  // instruction in between.
  EXPECT_EQ(acceptedT, callEnd);
  // The frame went out whole: the controller latched the string.
  const auto& a = r.robots[0];
  EXPECT_EQ(a.interrupts.at("pio_a"), 1u);
  EXPECT_EQ(a.framesLatched, 1);
  EXPECT_EQ(latched, std::vector<std::string>{"4fgr4rgr"});
}

// On a bare VM: DI or EI before each serial call, a request in the middle of
// it. The call's sequence is one piece (no boundary inside); the caller's
// IFF1 is what it was before the call.
void runSerialCall(vm::Lib lib, bool enabled) {
  const vm::CostTable& costs = testkit::calibratedCosts();
  Assembler a;
  const uint16_t counter = a.data(2);
  const uint16_t buf = a.string("4fgr4rgr");
  const uint16_t cc = a.data(2);
  a.op(enabled ? Op::EI : Op::DI).op(Op::PUSHW, lib == vm::Lib::SER_SEND_Z1 ? buf : 0);
  a.op(Op::PUSHW, lib == vm::Lib::SER_SEND_Z1 ? cc : 8).lib(lib, 2).op(Op::HALT);
  a.bind("handler").op(Op::INCGW, counter).op(Op::RETI);
  a.image.vectors.push_back({vm::kVecPIOA, static_cast<uint16_t>(a.label("handler")), "handler"});
  const auto img = a.finish();
  TestHost host;
  vm::Vm v(img, host, costs);
  const Tick callStart = costs.op[static_cast<int>(enabled ? Op::EI : Op::DI)] +
                         2 * costs.op[static_cast<int>(Op::PUSHW)];
  const Tick callEnd = callStart + libCallCost(costs, lib);
  ASSERT_GT(callEnd - callStart, 100) << "the call would fit in one step anyway";
  host.schedule(callStart + 1, Irq::Pio);
  host.runUntil(v, callEnd - 1);
  EXPECT_TRUE(host.events.empty()) << "accepted inside the call";
  host.runUntil(v, 100'000);
  if (enabled) {
    ASSERT_FALSE(host.events.empty());
    EXPECT_EQ(host.events[0].tick, callEnd);  // right after the call
    EXPECT_EQ(v.read16(counter), 1);
  } else {
    EXPECT_TRUE(host.events.empty());  // still disabled after the call
    EXPECT_FALSE(v.interruptsEnabled());
    EXPECT_TRUE(v.pending(Irq::Pio));
  }
}

TEST(SerialAtomic, SerSendLeavesTheCallersInterruptStateAsItFoundIt) {
  runSerialCall(vm::Lib::SER_SEND_Z1, true);
  runSerialCall(vm::Lib::SER_SEND_Z1, false);
}

TEST(SerialAtomic, SerInitLeavesTheCallersInterruptStateAsItFoundIt) {
  runSerialCall(vm::Lib::SER_INIT_Z1, true);
  runSerialCall(vm::Lib::SER_INIT_Z1, false);
}

}  // namespace
