// The copy test (issue 39): a match, its robots and their boards copy with
// the compiler's copy (= default), so that a member added later is copied
// with the rest; a member that is not (a link left pointing at the
// original, a cache left behind) shows here. A match paused right after
// the first event of each kind (a frame latched, an edge, a contact, a
// shot, a serial and a timer interrupt, a fault, a reload, ...) is copied
// twice, as MatchRun's copy (its plant replayed) and as a snapshot (its
// state and the plant's journal mark, restored into another run); the
// original and both copies are run to the end, and their trace records
// after the pause and their results (simbot match --json) must be the same
// bytes. The runs: ICEMAN vs Figure 9.2 for 40 s, seed 3 (frames, edges,
// contacts, launches from 21.6 s with their gun draws, eye noise);
// costate_hunter (on the BIOS timer's interrupt) vs ICEMAN for 10 s; a
// faulting program against the turret with --reload-on-fault (a fault
// inside the first second, its reload at 20.49 s, the fault again).
#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "runs/play.h"
#include "scheduler/match.h"
#include "sinks/json_text.h"
#include "sinks/trace_jsonl.h"

using namespace simbot;
using scheduler::Tick;

namespace {

const std::string kShared = SIMBOT_SHARED_DIR;
const std::string kSource = SIMBOT_SOURCE_DIR;

scheduler::MatchConfig configFor(const std::vector<std::string>& programs, double seconds,
                                 bool reload) {
  runs::RunOptions o;
  o.seconds = seconds;
  o.profile = "default";
  o.seed = 3;
  o.reloadOnFault = reload;
  return runs::buildConfig(programs, o, runs::ScenarioUse::Match);
}

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

// What a run writes after the pause: its trace records and its result.
struct Rest {
  std::vector<std::string> records;
  std::string result;
};

Rest finish(scheduler::MatchRun& run, sinks::JsonlLines& lines, size_t before) {
  lines.lines.resize(before);
  Rest rest;
  rest.result = json(run.finish());
  rest.records.assign(lines.lines.begin() + static_cast<long>(before), lines.lines.end());
  return rest;
}

void expectCopiesGoOn(const std::vector<std::string>& programs, double seconds, bool reload,
                      const std::vector<std::string>& kinds) {
  FirstEvents events;
  scheduler::MatchConfig plain = configFor(programs, seconds, reload);
  plain.observer = &events;
  scheduler::runMatch(plain);
  for (const std::string& kind : kinds) ASSERT_TRUE(events.first.count(kind)) << kind;
  std::string seen;
  for (const auto& [kind, tick] : events.first) seen += kind + "; ";
  std::printf("first events: %s\n", seen.c_str());

  for (const auto& [kind, tick] : events.first) {
    SCOPED_TRACE("copied right after the first " + kind + " (tick " + std::to_string(tick) + ")");
    sinks::JsonlLines lines;
    scheduler::MatchConfig c = configFor(programs, seconds, reload);
    c.snapshots = true;
    c.sinks = {&lines};
    scheduler::MatchRun run(c);
    // The first pause after the event: every round that starts at or
    // before its tick has run.
    ASSERT_TRUE(run.runUntil(tick + 1));
    const size_t before = lines.lines.size();
    scheduler::MatchRun copy(run);
    const scheduler::MatchRun::Snapshot snapshot = run.snapshot();

    const Rest original = finish(run, lines, before);
    ASSERT_GT(original.records.size(), 10u);
    const Rest copied = finish(copy, lines, before);
    EXPECT_EQ(copied.result, original.result);
    EXPECT_TRUE(copied.records == original.records);
    EXPECT_EQ(copied.records.size(), original.records.size());

    scheduler::MatchRun restored(c);
    restored.restore(snapshot);
    const Rest fromSnapshot = finish(restored, lines, before);
    EXPECT_EQ(fromSnapshot.result, original.result);
    EXPECT_TRUE(fromSnapshot.records == original.records);
    EXPECT_EQ(fromSnapshot.records.size(), original.records.size());
  }
}

TEST(MatchCopy, AfterEveryKindOfEventInIcemanVsFig92) {
  expectCopiesGoOn({kShared + "/programs/iceman.dc", kShared + "/programs/fig92.dc"}, 40, false,
                   {"frame latched", "pio_a interrupt", "serial_tx interrupt", "contact",
                    "ball_launch", "edge_enter", "solenoid_stroke", "eye read"});
}

TEST(MatchCopy, AfterTheTimersInterruptInCostateHunterVsIceman) {
  expectCopiesGoOn({kSource + "/programs/costate_hunter.dc", kShared + "/programs/iceman.dc"}, 10,
                   false, {"timer interrupt", "frame latched"});
}

TEST(MatchCopy, AfterAFaultAndAReload) {
  expectCopiesGoOn({kSource + "/tests/faulting/unbound_vector.dc", kSource + "/programs/turret.dc"},
                   30, true, {"fault or exit", "reload"});
}

}  // namespace
