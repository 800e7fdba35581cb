// simbot bench and tournament: statistics, determinism across thread counts.
#include "tools/bench.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "scheduler/metrics.h"
#include "support/traced.h"
#include "tools/runner.h"
#include "tools/tournament.h"

namespace {

using namespace simbot;

TEST(Stats, StudentTQuantile) {
  EXPECT_NEAR(scheduler::studentTQuantile(0.975, 1), 12.706, 1e-3);
  EXPECT_NEAR(scheduler::studentTQuantile(0.975, 10), 2.228, 1e-3);
  EXPECT_NEAR(scheduler::studentTQuantile(0.975, 30), 2.042, 1e-3);
  EXPECT_NEAR(scheduler::studentTQuantile(0.975, 1e6), 1.960, 1e-3);
  EXPECT_NEAR(scheduler::studentTQuantile(0.95, 5), 2.015, 1e-3);
  EXPECT_NEAR(scheduler::studentTQuantile(0.025, 10), -2.228, 1e-3);
  EXPECT_NEAR(scheduler::studentTCdf(0, 7), 0.5, 1e-12);
}

TEST(Stats, MeanMedianP90) {
  const std::vector<double> v = {5, 1, 4, 2, 3};
  EXPECT_DOUBLE_EQ(scheduler::mean(v), 3);
  EXPECT_DOUBLE_EQ(scheduler::quantile(v, 0.5), 3);
  EXPECT_DOUBLE_EQ(scheduler::quantile(v, 0.9), 4.6);  // 4 + 0.6 * (5 - 4)
  EXPECT_DOUBLE_EQ(scheduler::quantile({1, 2, 3, 4}, 0.5), 2.5);
}

TEST(Stats, SummaryCountsCensoredRuns) {
  const auto s = scheduler::summarize("x", {1.0, std::nullopt, 3.0, std::nullopt, 2.0});
  EXPECT_EQ(s.reached, 3);
  EXPECT_EQ(s.censored, 2);
  EXPECT_DOUBLE_EQ(*s.mean, 2);
  EXPECT_DOUBLE_EQ(*s.median, 2);
  // sd = 1, t(0.975, 2) = 4.303
  EXPECT_NEAR(*s.ciLow, 2 - 4.303 / std::sqrt(3.0), 1e-3);
  EXPECT_NEAR(*s.ciHigh, 2 + 4.303 / std::sqrt(3.0), 1e-3);
  const auto none = scheduler::summarize("y", {std::nullopt});
  EXPECT_EQ(none.reached, 0);
  EXPECT_FALSE(none.mean);
}

const std::string kShared = SIMBOT_SHARED_DIR;
const std::string kSource = SIMBOT_SOURCE_DIR;

std::string benchJson(const std::string& family, int threads) {
  tools::BenchConfig c;
  c.programs = {kShared + "/programs/iceman.dc"};
  c.family = family;
  c.seeds = 4;
  c.seconds = 10;
  c.threads = threads;
  c.progress = false;
  if (family == "head-to-head") c.opponent = kShared + "/programs/fig92.dc";
  const auto profile = tools::loadNamedProfile(kSource + "/profiles/default.toml");
  const auto r = tools::runBench(c, profile);
  return tools::summaryJson(r).dump(2) + tools::runsCsv(r);
}

TEST(Bench, SameSummaryWhateverTheThreadCount) {
  const std::string one = benchJson("stationary", 1);
  EXPECT_EQ(one, benchJson("stationary", 2));
  EXPECT_NE(one.find("\"acquire_s\""), std::string::npos);
}

TEST(Bench, EdgeFamilyIsDeterministic) { EXPECT_EQ(benchJson("edge", 1), benchJson("edge", 2)); }

TEST(Bench, CircleAndHeadToHeadFamiliesRun) {
  EXPECT_EQ(benchJson("circle", 1), benchJson("circle", 2));
  EXPECT_EQ(benchJson("head-to-head", 1), benchJson("head-to-head", 2));
}

TEST(Bench, HeadToHeadPutsTheRobotsDownByHand) {
  tools::BenchConfig c;
  c.programs = {kShared + "/programs/iceman.dc"};
  c.family = "head-to-head";
  c.opponent = kShared + "/programs/fig92.dc";
  c.seeds = 6;
  c.seconds = 0.5;
  c.progress = false;
  const auto profile = tools::loadNamedProfile(kSource + "/profiles/default.toml");
  const auto r = tools::runBench(c, profile);
  const plant::Pose mark = profile.field.start[0];
  for (size_t i = 0; i < r.runs.size(); ++i) {
    const plant::Pose& p = r.runs[i].startA;
    EXPECT_LE(std::fabs(p.x_ft - mark.x_ft), 0.5);
    EXPECT_LE(std::fabs(p.y_ft - mark.y_ft), 0.5);
    const double turn = std::fabs(std::remainder(p.heading_deg - mark.heading_deg, 360.0));
    EXPECT_LE(turn, 15.0);
    if (i > 0) {
      EXPECT_NE(p.x_ft, r.runs[i - 1].startA.x_ft);
    }
  }
}

TEST(Bench, ObserverDoesNotChangeTheMatch) {
  scheduler::MatchConfig c;
  c.arena = plant::makeArenaConfig(tools::loadNamedProfile(kSource + "/profiles/default.toml"), 2);
  c.robots.push_back({"A", "iceman", tools::compileProgramFile(kShared + "/programs/iceman.dc")});
  c.robots.push_back({"B", "fig92", tools::compileProgramFile(kShared + "/programs/fig92.dc")});
  c.endTick = 10 * scheduler::kTicksPerSecond;
  const auto plain = testkit::runTraced(c);
  scheduler::MetricsObserver observer;
  c.observer = &observer;
  const auto watched = testkit::runTraced(c);
  EXPECT_EQ(plain.trace, watched.trace);
  EXPECT_EQ(plain.robots[0].cycles, watched.robots[0].cycles);
  EXPECT_EQ(plain.rounds, watched.rounds);
}

TEST(Tournament, SameStandingsOnRerunAndThreadCounts) {
  tools::TournamentConfig c;
  c.programs = {kSource + "/programs/spiral.dc", kSource + "/programs/turret.dc",
                kShared + "/programs/fig92.dc"};
  c.rounds = 1;
  c.seconds = 20;
  c.progress = false;
  const auto profile = tools::loadNamedProfile(kSource + "/profiles/default.toml");
  c.threads = 1;
  const std::string first = tools::tournamentJson(tools::runTournament(c, profile)).dump();
  EXPECT_EQ(first, tools::tournamentJson(tools::runTournament(c, profile)).dump());
  c.threads = 2;
  EXPECT_EQ(first, tools::tournamentJson(tools::runTournament(c, profile)).dump());
  c.threads = 3;
  const auto r = tools::runTournament(c, profile);
  EXPECT_EQ(first, tools::tournamentJson(r).dump());
  ASSERT_EQ(r.games.size(), 3u);
  int wins = 0;
  for (const auto& s : r.standings) {
    wins += s.wins;
    EXPECT_EQ(s.points, s.wins);
    EXPECT_EQ(s.wins + s.losses, 2);
  }
  EXPECT_EQ(wins, 3);
}

TEST(Tournament, SidesSwapEachRound) {
  tools::TournamentConfig c;
  c.programs = {kSource + "/programs/spiral.dc", kSource + "/programs/turret.dc"};
  c.rounds = 2;
  c.seconds = 2;
  c.progress = false;
  const auto r =
      tools::runTournament(c, tools::loadNamedProfile(kSource + "/profiles/default.toml"));
  ASSERT_EQ(r.games.size(), 2u);
  EXPECT_EQ(r.games[0].a, 0);
  EXPECT_EQ(r.games[1].a, 1);
  EXPECT_NE(r.games[0].seed, r.games[1].seed);
}

}  // namespace
