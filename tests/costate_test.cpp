// The Z180 timer and costatements at the VM level: interrupt priority with
// the timer among the sources, the BIOS timer service's cost and counters
// against Dynamic C's rule, and a waitfor on a variable an interrupt handler
// sets, and the profile knob that decides whether the service runs. The
// costatement constructs' console behaviour is in
// tests/programs/costate_*.dc and timer_counters.dc.
#include <gtest/gtest.h>

#include "config/config.h"
#include "plant/plant.h"
#include "scheduler/match.h"
#include "support/test_host.h"
#include "trace/trace.h"

using namespace simbot;
using simbot::testkit::TestHost;
using vm::Irq;
using vm::Tick;

namespace {

const vm::CostTable& costs() { return testkit::calibratedCosts(); }

// Z180 priority (DESIGN.md, "Interrupts"): INT0 (the PIO) above PRT0 (the
// timer) above the ASCI (serial transmit). All three are made pending while
// interrupts are disabled; EI lets them in one at a time, highest first.
TEST(Timer, PioThenTimerThenSerialWhenPendingTogether) {
  const auto img = testkit::compileOrDie(R"(#INT_VEC PIOA_VEC edge
int edges;
unsigned long seen;
interrupt reti edge() { edges++; }
main()
{
    int i;
    DI();
    for (i = 0; i < 100; i++) ;   /* about 25,000 T-states: past PRT0's first tick at 9,000 */
    EI();
    for (i = 0; i < 10; i++) ;
    seen = MS_TIMER;
}
)");
  TestHost host;
  host.schedule(100, Irq::SerialTx);
  host.schedule(200, Irq::Pio);
  vm::Vm v(img, host, costs());
  ASSERT_EQ(host.runUntil(v, vm::kTicksPerSecond / 10), vm::Stop::Halted);
  std::vector<Irq> order;
  for (const auto& e : host.events)
    if (e.accepted) order.push_back(e.irq);
  ASSERT_GE(order.size(), 3u);
  EXPECT_EQ(order[0], Irq::Pio);
  EXPECT_EQ(order[1], Irq::Timer);
  EXPECT_EQ(order[2], Irq::SerialTx);
  // All three were waiting for the same EI: each is accepted when the one
  // before it has returned (the PIO handler's RETI, the timer service's).
  EXPECT_GT(host.events[0].tick, Tick{9000});
}

// The timer service runs at PRT0's ticks, 9,000 T-states apart from reset
// (9.216 MHz / 20 / 450 = 1,024 Hz), costs kTimerIsrSeq along its path, and
// keeps MS_TIMER = floor(TICK_TIMER * 125 / 128) and SEC_TIMER =
// TICK_TIMER / 1024 (a halted program: nothing delays the acceptances).
TEST(Timer, CountersFollowDynamicCsRuleAndServiceCostsItsSequence) {
  const auto img = testkit::compileOrDie("unsigned long t; main() { t = TICK_TIMER; }");
  TestHost host;
  vm::Vm v(img, host, costs());
  const auto& tick = testkit::symbol(img, "TICK_TIMER");
  const auto& ms = testkit::symbol(img, "MS_TIMER");
  const auto& sec = testkit::symbol(img, "SEC_TIMER");
  for (uint32_t n : {1u, 2u, 3u, 127u, 128u, 1023u, 1024u, 1025u, 3000u}) {
    host.runUntil(v, Tick{n} * 9000 + 1000);
    EXPECT_EQ(v.read32(static_cast<uint16_t>(tick.address)), n);
    EXPECT_EQ(v.read32(static_cast<uint16_t>(ms.address)), n * 125 / 128) << "tick " << n;
    EXPECT_EQ(v.read32(static_cast<uint16_t>(sec.address)), n / 1024) << "tick " << n;
  }
  // Acceptance at exactly 9,000 k (the VM idles in HALT until then); the
  // service's time to its return.
  uint64_t serviceTime = 0;
  Tick lastAccept = 0;
  for (size_t i = 0; i + 1 < host.events.size(); ++i) {
    if (host.events[i].irq != Irq::Timer || !host.events[i].accepted) continue;
    EXPECT_EQ(host.events[i].tick % 9000, 0) << i;
    lastAccept = host.events[i].tick;
    serviceTime = static_cast<uint64_t>(host.events[i + 1].tick - host.events[i].tick);
  }
  EXPECT_EQ(lastAccept, Tick{3000} * 9000);
  // By hand, the service at tick 3000 (the fraction before it is
  // 2999 * 125 mod 128 = 91; 91 + 125 = 216 >= 128: a millisecond is due;
  // 3000 mod 1024 != 0: no second), from z180.def: INTACK 18, 3 x PUSH 33,
  // 2 x IN0 24, TICK_TIMER += 1 (LD HL,(nn) 15, LD rr,nn 9, ADD HL,rr 7,
  // LD (nn),HL 16, LD HL,(nn) 15, DEC rr 4, ADC HL,rr 10, LD (nn),HL 16 = 92),
  // the fraction (LD A,(nn) 12, ADD A,n 6, LD r,r 4, AND n 6, LD (nn),A 13,
  // BIT b,r 6, JR cc not taken 6 = 53), MS_TIMER += 1 (92), the second's
  // test (LD HL,(nn) 15, LD r,r 4, AND n 6, OR r 4, JR cc taken 8 = 37),
  // 3 x POP 27, EI 3, RETI 22 (the Z80180, the default revision): 401
  // T-states. Calibrated knobs: no memory wait states; 4 I/O wait states on
  // the two IN0: 409; refresh 2 every 20 adds (409 * 2 + 10) / 20 = 41
  // (rounded): 450.
  EXPECT_EQ(serviceTime, 450u);
}

// Without the timer library (and the knob at auto) no timer interrupt runs:
// ICEMAN's timing is what it was.
TEST(Timer, RunsOnlyWhenTheProgramUsesIt) {
  const auto img = testkit::compileOrDie("int x; main() { x = 1; }");
  EXPECT_FALSE(img.timer.used());
  TestHost host;
  vm::Vm v(img, host, costs());
  host.runUntil(v, vm::kTicksPerSecond);
  EXPECT_TRUE(host.events.empty());
  vm::CostKnobs always = vm::calibratedKnobs();
  always.timerService = vm::TimerService::Always;
  const auto table = vm::makeCostTable(always);
  TestHost host2;
  vm::Vm v2(img, host2, table);
  host2.runUntil(v2, vm::kTicksPerSecond);
  // Ticks 9,000 k for k = 1..1023 fall before 1 s (the 1,024th is at it):
  // each accepted and returned.
  EXPECT_EQ(host2.events.size(), 2u * 1023u);
}

// waitfor on a variable an interrupt handler sets resumes at the first
// evaluation of the waitfor after the handler ran: in the same pass if the
// handler ran before the costatement's test in that pass, else in the next.
// The program records which: the test's own function notes the pass it ran
// in (with interrupts off while it reads the flag), and the handler
// compares. Swept over a window of request ticks that
// covers a whole pass, so both cases occur.
TEST(Costate, WaitforOnHandlerVariableResumesOnTheFirstPassAfter) {
  const auto img = testkit::compileOrDie(R"(#INT_VEC PIOA_VEC edge
int flag, passes, tested, irqPass, afterTest, resumedPass;
interrupt reti edge()
{
    flag = 1;
    irqPass = passes;
    afterTest = tested == passes;
}
int check()
{
    int f;
    DI();   /* the handler lands before or after this, never between */
    tested = passes;
    f = flag;
    EI();
    return f;
}
main()
{
    while (resumedPass == 0) {
        passes++;
        costate {
            waitfor(check());
            resumedPass = passes;
        }
    }
}
)");
  int sameCase = 0, nextCase = 0;
  for (Tick at = 20000; at < 22000; at += 37) {
    TestHost host;
    host.schedule(at, Irq::Pio);
    vm::Vm v(img, host, costs());
    ASSERT_EQ(host.runUntil(v, vm::kTicksPerSecond), vm::Stop::Halted);
    auto word = [&](const char* name) {
      return static_cast<int16_t>(
          v.read16(static_cast<uint16_t>(testkit::symbol(img, name).address)));
    };
    const int expected = word("irqPass") + word("afterTest");
    EXPECT_EQ(word("resumedPass"), expected) << "request at " << at;
    (word("afterTest") ? nextCase : sameCase)++;
  }
  EXPECT_GT(sameCase, 0);
  EXPECT_GT(nextCase, 0);
}

// A costatement entered fresh (its CoData's resume address 0): COSTATE's
// Z180 sequence with JR Z taken over the JP (HL) that resumes, by Zilog's
// figures (vm/z180.def): LD rr,nn 9, BIT b,(HL) 9, JP cc,nn not taken 6,
// RES b,(HL) 13, INC rr 4, LD r,(HL) 6, INC rr 4, LD r,(HL) 6, EX DE,HL 3,
// LD r,r 4, OR r 4, JR cc,e taken 8: 76 T-states with no wait states (the
// calibrated MWI 0, and no I/O), stretched by the calibrated DRAM refresh
// of 2 T-states every 20, rounded per instruction: (76 x 2 + 10) / 20 = 8
// in integers, 84 in all, from the instruction to the first of the body,
// as the listing (compile --disasm) gives this path. The clock used to
// charge the resume path's 77 + 8 = 85 (issue 24).
TEST(Costate, AFreshEntryTakesItsSequencesTStates) {
  const auto img = testkit::compileOrDie(R"(int n;
main()
{
    costate {
        n = 1;
    }
}
)");
  uint32_t at = 0;
  while (at < img.code.size() && img.code[at] != static_cast<uint8_t>(vm::Op::COSTATE))
    at += static_cast<uint32_t>(vm::instructionSize(static_cast<vm::Op>(img.code[at])));
  ASSERT_LT(at, img.code.size());
  const uint32_t body = at + static_cast<uint32_t>(vm::instructionSize(vm::Op::COSTATE));
  TestHost host;
  vm::Vm v(img, host, costs());
  v.setBreakpoint(at);
  v.setBreakpoint(body);
  ASSERT_EQ(v.run(vm::kTicksPerSecond), vm::Stop::Breakpoint);
  ASSERT_EQ(v.pc(), at);
  const Tick before = v.now();
  ASSERT_EQ(v.run(vm::kTicksPerSecond), vm::Stop::Breakpoint);
  ASSERT_EQ(v.pc(), body);
  EXPECT_EQ(v.now() - before, 84);
}

// A paused named costatement (CoPause: STOPPED) goes no further than its
// JP Z to the end: LD HL,nn 9 + BIT 0,(HL) 9 + JP Z taken 9 = 27 T-states
// (vm/z180.def), + (27 x 2 + 10) / 20 = 3 of refresh: 30, from COSTATE to
// the instruction after the costatement. The listing gives the three paths
// as stopped / fresh / resumed, "30/84/85" (it gave "87/88/84/85", as if a
// taken JP Z ran on through the sequence; issue 24).
TEST(Costate, APausedEntryTakesItsStoppedSequence) {
  const auto img = testkit::compileOrDie(R"(int n;
main()
{
    costate walk {
        n = 1;
    }
    CoPause(&walk);
    costate walk {
        n = 2;
    }
}
)");
  std::vector<uint32_t> entries;
  for (uint32_t at = 0; at < img.code.size();
       at += static_cast<uint32_t>(vm::instructionSize(static_cast<vm::Op>(img.code[at]))))
    if (img.code[at] == static_cast<uint8_t>(vm::Op::COSTATE)) entries.push_back(at);
  ASSERT_EQ(entries.size(), 2u);
  const uint32_t second = entries[1];
  const int16_t rel = static_cast<int16_t>(img.code[second + 3] | (img.code[second + 4] << 8));
  const uint32_t end = second + static_cast<uint32_t>(vm::instructionSize(vm::Op::COSTATE)) +
                       static_cast<uint32_t>(rel);
  TestHost host;
  vm::Vm v(img, host, costs());
  v.setBreakpoint(second);
  v.setBreakpoint(end);
  ASSERT_EQ(v.run(vm::kTicksPerSecond), vm::Stop::Breakpoint);
  ASSERT_EQ(v.pc(), second);
  const Tick before = v.now();
  ASSERT_EQ(v.run(vm::kTicksPerSecond), vm::Stop::Breakpoint);
  ASSERT_EQ(v.pc(), end);
  EXPECT_EQ(v.now() - before, 30);
  const std::string text = vm::disassemble(img);
  EXPECT_NE(text.find("     30/84/85  COSTATE"), std::string::npos) << text;
}

// A CoData whose resume address is overwritten faults that robot, never the
// host: the checksum no longer matches.
TEST(Costate, CorruptedResumeAddressFaults) {
  const auto img = testkit::compileOrDie(R"(int i;
CoData *p;
main()
{
    for (i = 0; i < 3; i++) {
        costate blink always_on {
            yield;
        }
        p = &blink;
        p->lastlocADDR = 0x1234;
    }
}
)");
  TestHost host;
  vm::Vm v(img, host, costs());
  EXPECT_EQ(host.runUntil(v, vm::kTicksPerSecond), vm::Stop::Fault);
  ASSERT_NE(v.fault(), nullptr);
  EXPECT_NE(v.fault()->message.find("checksum"), std::string::npos) << v.fault()->message;
}

}  // namespace

namespace {

scheduler::MatchConfig soloConfig(const std::string& file, vm::TimerService timerService,
                                  double seconds, vm::CpuRevision cpu = vm::CpuRevision::Z80180) {
  auto profile = config::loadProfile(SIMBOT_SOURCE_DIR "/profiles/default.toml");
  EXPECT_EQ(profile.controller.cpu, vm::CpuRevision::Z80180);
  profile.controller.timerService = timerService;
  profile.controller.cpu = cpu;
  scheduler::MatchConfig c;
  c.arena = config::makeArenaConfig(profile, 1);
  c.robots.push_back({"A", file, testkit::compileFileOrDie(file)});
  c.robots.back().controller = profile.controller;
  c.endTick = timebase::ticksFromSeconds(seconds);
  return c;
}

// The profile's [controller] timer_service: "auto" runs the service only in
// a program that uses the timer library, "always" in every program (ICEMAN
// then takes 1,024 timer interrupts a second: 2,048 in 2 s less the one at
// exactly 2 s), "never" in none (a DelayMs never ends).
TEST(Timer, ProfileKnobDecidesWhetherTheServiceRuns) {
  const std::string iceman = SIMBOT_SHARED_DIR "/programs/iceman.dc";
  const std::string toggler = SIMBOT_SOURCE_DIR "/tests/programs/costate_delayms.dc";
  const auto autoIceman = scheduler::runMatch(soloConfig(iceman, vm::TimerService::Auto, 2));
  EXPECT_EQ(autoIceman.robots[0].interrupts.at("timer"), 0u);
  auto always = soloConfig(iceman, vm::TimerService::Always, 2);
  always.profile = true;  // the service's cycles are a profile figure
  const auto alwaysIceman = scheduler::runMatch(always);
  EXPECT_EQ(alwaysIceman.robots[0].interrupts.at("timer"), 2047u);
  EXPECT_GT(alwaysIceman.robots[0].timerIsrCycles, 0u);
  const auto autoToggler = scheduler::runMatch(soloConfig(toggler, vm::TimerService::Auto, 2));
  EXPECT_TRUE(autoToggler.robots[0].exited);
  const auto neverToggler = scheduler::runMatch(soloConfig(toggler, vm::TimerService::Never, 2));
  EXPECT_FALSE(neverToggler.robots[0].exited);
  EXPECT_EQ(neverToggler.robots[0].interrupts.at("timer"), 0u);
}

// The profile's [controller] cpu reaches the robot's VM: the BIOS timer
// service ends in RETI, 22 T-states on the Z80180 and 12 on the Z8S180
// (vm/z180.def), so with the calibrated refresh (+ (2t + 10) / 20 on the
// service's t T-states) each service is 10 + 1 = 11 T-states longer on the
// Z80180, whatever its path. ICEMAN with the service always on takes 2,047
// services in 2 s on either chip (PRT0 ticks, not the program, decide
// that): 2,047 x 11 = 22,517 T-states of service apart.
TEST(Timer, ServiceEndsWithTheChosenRevisionsReti) {
  const std::string iceman = SIMBOT_SHARED_DIR "/programs/iceman.dc";
  uint64_t cycles[2] = {};
  for (const vm::CpuRevision cpu : {vm::CpuRevision::Z80180, vm::CpuRevision::Z8S180}) {
    auto c = soloConfig(iceman, vm::TimerService::Always, 2, cpu);
    c.profile = true;
    const auto r = scheduler::runMatch(c);
    EXPECT_EQ(r.robots[0].interrupts.at("timer"), 2047u);
    cycles[static_cast<int>(cpu)] = r.robots[0].timerIsrCycles;
  }
  EXPECT_EQ(cycles[0] - cycles[1], 2047u * 11u);
}

// --trace-costate records only changes of state (Robot::costate). By hand,
// pass by pass of the loop below (k counts the passes that reach counter):
//   pass 1: waiter's first entry (enter, line 7), its waitfor false with
//           k = 0: it begins waiting at line 7 (yield 7); counter's first
//           entry (enter, line 11) and its end (end 12);
//   passes 2-4: waiter resumed at line 7, k = 1..3, gives way at line 7
//           again: still waiting, nothing; counter runs from its top to its
//           end again: nothing;
//   pass 5: k = 4: waiter's wait is over, n = 1, it ends (end 9);
//   passes 6-7: waiter runs from its top to its end without a wait (n = 2,
//           3): nothing. The loop ends and main returns.
// Five records, where the VM reports 2 + 7 x 2 (counter) + 4 + 4 x 2 + 2 x 2
// (waiter) = 32 entries, give-ways and ends.
// --trace-costate records changes of state only (trace/records.def). By
// hand, with the program's lines (waiter 6-9, its waitfor on 7; counter
// 10-12): pass 1 enters waiter (enter 7), whose waitfor is false (yield 7),
// and enters counter (enter 11), which runs to its end (end 12). Passes 2-4
// re-check the waitfor at the same line (nothing) and run counter top to
// end again (nothing: its first pass said so). Pass 5 (k = 4) lets waiter
// through to its end (end 9); from then on waiter too runs top to end
// without giving way, and n reaches 3 on pass 7: five records in all.
TEST(Costate, TraceRecordsOnlyChangesOfState) {
  const std::string file = testing::TempDir() + "costate_changes.dc";
  std::FILE* f = std::fopen(file.c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fputs(R"(int n, k;
main()
{
    n = 0; k = 0;
    while (n < 3) {
        costate waiter always_on {
            waitfor(k >= 4);
            n++;
        }
        costate counter always_on {
            k++;
        }
    }
}
)",
             f);
  std::fclose(f);
  auto config = soloConfig(file, vm::TimerService::Auto, 1);
  trace::Collector collector;
  config.sinks.push_back(&collector);
  config.traceCostate = true;
  const auto result = scheduler::runMatch(config);
  EXPECT_TRUE(result.robots[0].exited);
  std::vector<std::string> got;
  for (const auto& e : collector.entries)
    if (const auto* c = std::get_if<trace::rec::Costate>(&e.record))
      got.push_back(c->name + ' ' + c->event + ' ' + std::to_string(c->line));
  const std::vector<std::string> want = {"waiter enter 7", "waiter yield 7", "counter enter 11",
                                         "counter end 12", "waiter end 9"};
  EXPECT_EQ(got, want);
}

}  // namespace
