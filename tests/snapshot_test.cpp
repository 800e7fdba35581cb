// A snapshot of a whole match is a copy (scheduler::MatchRun): both
// boards, the scheduler's queue, the plant, every random stream and the
// trace records not yet written. Taken between rounds at tick T, the match
// run on to its end and the snapshot run on from T write the same records
// after T and end with the same result; and a run paused at T writes what
// the run without a pause writes. ICEMAN vs Figure 9.2 for 30 s on the
// default profile, seed 3 (seeded variation, eye noise; ICEMAN's 14
// launches come from 21.6 s on, after both snapshots, with their gun
// draws), and a faulting program against the turret with
// --reload-on-fault (a fault inside the first second and again after its
// reload at 20.49 s: the reload after one snapshot, before the other).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "runs/play.h"
#include "scheduler/match.h"
#include "sinks/trace_jsonl.h"
#include "tests/support/seeded_match.h"

using namespace simbot;

namespace {

const std::string kShared = SIMBOT_SHARED_DIR;
const std::string kSource = SIMBOT_SOURCE_DIR;

// What a result says, without the host's wall times.
std::string summary(const scheduler::MatchResult& r) {
  std::string s = r.winner + " " + std::to_string(r.endTick) + " " +
                  std::to_string(r.integrator.steps) + " " + std::to_string(r.integrator.rhs_evals);
  for (const auto& rr : r.robots)
    s += " | " + std::to_string(rr.hits) + " " + std::to_string(rr.shots) + " " +
         std::to_string(rr.framesLatched) + " " + std::to_string(rr.cycles) + " " +
         std::to_string(rr.vmInstructions) + " " + std::to_string(rr.reloads);
  return s;
}

void expectSnapshotsContinue(const std::vector<std::string>& programs, double seconds, bool reload,
                             const std::vector<double>& at) {
  sinks::JsonlLines whole;
  scheduler::MatchConfig plain = testkit::seededMatch(programs, seconds, reload);
  plain.sinks = {&whole};
  const scheduler::MatchResult uninterrupted = scheduler::runMatch(plain);

  for (const double t : at) {
    SCOPED_TRACE("snapshot at " + std::to_string(t) + " s");
    sinks::JsonlLines lines;
    scheduler::MatchConfig c = testkit::seededMatch(programs, seconds, reload);
    c.snapshots = true;
    c.sinks = {&lines};
    scheduler::MatchRun run(c);
    ASSERT_TRUE(run.runUntil(timebase::ticksFromSeconds(t)));
    EXPECT_GE(run.now(), timebase::ticksFromSeconds(t));
    const size_t before = lines.lines.size();
    const scheduler::MatchRun snapshot(run);

    const scheduler::MatchResult first = run.finish();
    const std::vector<std::string> firstRest(lines.lines.begin() + static_cast<long>(before),
                                             lines.lines.end());
    // Paused or not, the same run.
    EXPECT_EQ(lines.lines, whole.lines);
    EXPECT_EQ(summary(first), summary(uninterrupted));

    lines.lines.resize(before);
    scheduler::MatchRun restored(snapshot);
    const scheduler::MatchResult second = restored.finish();
    const std::vector<std::string> secondRest(lines.lines.begin() + static_cast<long>(before),
                                              lines.lines.end());
    ASSERT_GT(firstRest.size(), 100u);
    EXPECT_EQ(firstRest.size(), secondRest.size());
    EXPECT_TRUE(firstRest == secondRest);
    EXPECT_EQ(summary(second), summary(first));
  }
}

TEST(MatchSnapshot, IcemanVsFig92GoesOnByteForByte) {
  expectSnapshotsContinue({kShared + "/programs/iceman.dc", kShared + "/programs/fig92.dc"}, 30,
                          false, {0.5, 17.3});
}

TEST(MatchSnapshot, AReloadBeforeOrAfterTheSnapshot) {
  // The faulting program faults well inside a second; the profile's reload
  // delay is 20 s.
  expectSnapshotsContinue(
      {kSource + "/tests/faulting/unbound_vector.dc", kSource + "/programs/turret.dc"}, 30, true,
      {10.0, 21.0});
}

}  // namespace
