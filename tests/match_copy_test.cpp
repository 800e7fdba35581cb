// The copy test (issue 39): a match, its robots and their boards copy with
// the compiler's copy (= default), so that a member added later is copied
// with the rest; a member that is not (a link left pointing at the
// original, a cache left behind) shows here. A match paused right after
// the first event of each kind (a frame latched, an edge, a contact, a
// shot, a serial and a timer interrupt, a fault, a reload, ...) is copied
// twice, as MatchRun's copy (its plant replayed) and as a snapshot (its
// state and the plant's journal mark, restored into another run); both
// copies are run to the end, and their trace records after the pause and
// their results (simbot match --json) must be the bytes of the run that
// was never paused. The runs: ICEMAN vs Figure 9.2 for 30 s, seed 3
// (frames, edges, contacts, launches from 21.6 s with their gun draws,
// eye noise);
// costate_hunter (on the BIOS timer's interrupt) vs ICEMAN for 10 s; a
// faulting program against the turret with --reload-on-fault for 22 s (a
// fault inside the first second, its reload at 20.49 s, the fault again).
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include "runs/play.h"
#include "scheduler/match.h"
#include "sinks/json_text.h"
#include "sinks/trace_jsonl.h"
#include "tests/support/seeded_match.h"

using namespace simbot;
using scheduler::Tick;

namespace {

const std::string kShared = SIMBOT_SHARED_DIR;
const std::string kSource = SIMBOT_SOURCE_DIR;

// The tick of the first event of each kind.
struct FirstEvents final : scheduler::MatchObserver {
  std::map<std::string, Tick> first;
  void note(const std::string& kind, Tick t) { first.try_emplace(kind, t); }
  void onFrame(int, Tick t, bool latched) override {
    note(latched ? "frame latched" : "frame rejected", t);
  }
  void onInterruptAccepted(int, Tick t, vm::Irq irq) override {
    note(std::string(vm::irqName(irq)) + " interrupt", t);
  }
  void onPlantEvent(Tick t, const plant::Event& e) override {
    note(plant::eventKindName(e.kind), t);
  }
  void onHalt(int, Tick t) override { note("fault or exit", t); }
  void onReload(int, Tick t) override { note("reload", t); }
  void onEyeRead(int, Tick t, int, int) override { note("eye read", t); }
};

// A run's result as `simbot match --json` writes it.
std::string json(const scheduler::MatchResult& result) {
  return sinks::dumpJson(runs::matchJson(runs::Played{result, 0, 3}));
}

// A copy run to the end: the trace records it writes (after `before`,
// where it was copied) and its result are the uninterrupted run's.
void expectSameRest(scheduler::MatchRun& copy, sinks::JsonlLines& lines, size_t before,
                    const std::vector<std::string>& whole, const std::string& wholeResult) {
  lines.lines.resize(before);
  EXPECT_EQ(json(copy.finish()), wholeResult);
  ASSERT_EQ(lines.lines.size(), whole.size());
  EXPECT_TRUE(std::equal(lines.lines.begin() + static_cast<long>(before), lines.lines.end(),
                         whole.begin() + static_cast<long>(before)));
  lines.lines.resize(before);
}

void expectCopiesGoOn(const std::vector<std::string>& programs, double seconds, bool reload,
                      const std::vector<std::string>& kinds) {
  FirstEvents events;
  sinks::JsonlLines whole;
  scheduler::MatchConfig plain = testkit::seededMatch(programs, seconds, reload);
  plain.observer = &events;
  plain.sinks = {&whole};
  const std::string wholeResult = json(scheduler::runMatch(plain));
  for (const std::string& kind : kinds) ASSERT_TRUE(events.first.count(kind)) << kind;
  std::map<Tick, std::string> byTick;
  for (const auto& [kind, tick] : events.first) byTick[tick] += kind + "; ";

  // One run, paused right after each first event in turn (every round
  // that starts at or before its tick has run), copied there twice.
  sinks::JsonlLines lines;
  scheduler::MatchConfig c = testkit::seededMatch(programs, seconds, reload);
  c.snapshots = true;
  c.sinks = {&lines};
  scheduler::MatchRun run(c);
  for (const auto& [tick, here] : byTick) {
    SCOPED_TRACE("copied right after the first " + here + " at " +
                 std::to_string(timebase::secondsFromTicks(tick)) + " s");
    ASSERT_TRUE(run.runUntil(tick + 1));
    const size_t before = lines.lines.size();
    ASSERT_LT(before + 10, whole.lines.size());
    scheduler::MatchRun copy(run);
    expectSameRest(copy, lines, before, whole.lines, wholeResult);
    scheduler::MatchRun restored(c);
    restored.restore(run.snapshot());
    expectSameRest(restored, lines, before, whole.lines, wholeResult);
  }
  // Paused and copied at every one of them, the run itself is the same too.
  EXPECT_EQ(json(run.finish()), wholeResult);
  EXPECT_TRUE(lines.lines == whole.lines);
}

TEST(MatchCopy, AfterEveryKindOfEventInIcemanVsFig92) {
  expectCopiesGoOn({kShared + "/programs/iceman.dc", kShared + "/programs/fig92.dc"}, 30, false,
                   {"frame latched", "pio_a interrupt", "serial_tx interrupt", "contact",
                    "ball_launch", "edge_enter", "solenoid_stroke", "eye read"});
}

TEST(MatchCopy, AfterTheTimersInterruptInCostateHunterVsIceman) {
  expectCopiesGoOn({kSource + "/programs/costate_hunter.dc", kShared + "/programs/iceman.dc"}, 10,
                   false, {"timer interrupt", "frame latched"});
}

TEST(MatchCopy, AfterAFaultAndAReload) {
  expectCopiesGoOn({kSource + "/tests/faulting/unbound_vector.dc", kSource + "/programs/turret.dc"},
                   22, true, {"fault or exit", "reload"});
}

}  // namespace
