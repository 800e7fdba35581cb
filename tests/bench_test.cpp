// simbot bench and tournament: statistics, determinism across thread counts.
#include "batch/bench.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "batch/bench_metrics.h"
#include "batch/run_table.h"
#include "batch/tournament.h"
#include "config/config.h"
#include "runs/play.h"
#include "stats/stats.h"
#include "support/traced.h"

namespace {

using namespace simbot;

// Kaplan-Meier by hand: times 1, 2+, 3, 3, 4+ (+ censored). At 1: 5 at
// risk, 1 event, S = 4/5; at 3: 3 at risk, 2 events, S = 0.8 / 3. Greenwood:
// se(1) = 0.8 sqrt(1/20), se(3) = S(3) sqrt(1/20 + 2/3). The median is the
// first time with S < 0.5: 3. Its cloglog interval: r(1) = -1.131 and
// r(3) = 1.008 both within 1.96, so [1, inf) (3 is the last event time).
// RFC 4180, section 2: records end in CRLF; a field holding a comma, a quote
// or a line break is quoted, its quotes doubled.
TEST(RunTable, RecordsFollowRfc4180) {
  EXPECT_EQ(batch::csvRecord({"a,b", "say \"hi\"", "x"}), "\"a,b\",\"say \"\"hi\"\"\",x\r\n");
  // Two records, the second with a line break inside quotes, then a third
  // cut short by a kill (no line end): the third is not a record yet.
  const std::string text = "h1,h2\r\n\"two\r\nlines\",2\r\n3,3";
  const auto records = batch::csvRecords(text);
  ASSERT_EQ(records.size(), 2u);
  EXPECT_EQ(records[0], "h1,h2");
  EXPECT_EQ(records[1], "\"two\r\nlines\",2");
  EXPECT_EQ(batch::parseCsvLine(records[1]), (batch::CsvRow{"two\r\nlines", "2"}));
  // LF line ends (tables written before CRLF) still read.
  EXPECT_EQ(batch::csvRecords("a\nb\n"), (std::vector<std::string>{"a", "b"}));
}

TEST(Stats, KaplanMeierByHand) {
  const auto km = stats::kaplanMeier({{1, true}, {2, false}, {3, true}, {3, true}, {4, false}});
  ASSERT_EQ(km.times, (std::vector<double>{1, 3}));
  EXPECT_EQ(km.atRisk, (std::vector<int>{5, 3}));
  EXPECT_EQ(km.events, (std::vector<int>{1, 2}));
  EXPECT_NEAR(km.survival[0], 0.8, 1e-15);
  EXPECT_NEAR(km.survival[1], 0.8 / 3, 1e-15);
  EXPECT_NEAR(km.se[0], 0.8 * std::sqrt(1.0 / 20), 1e-15);
  EXPECT_NEAR(km.se[1], 0.8 / 3 * std::sqrt(1.0 / 20 + 2.0 / 3), 1e-15);
  EXPECT_EQ(stats::survivalAt(km, 0.5), 1);
  EXPECT_EQ(stats::survivalAt(km, 2), km.survival[0]);
  EXPECT_EQ(*stats::quantile(km, 0.5), 3);
  EXPECT_FALSE(stats::quantile(km, 0.9));  // S never falls below 0.1
  const auto ci = stats::quantileCi(km, 0.5);
  ASSERT_TRUE(ci);
  EXPECT_EQ(ci->low, 1);
  EXPECT_TRUE(std::isinf(ci->high));
  // Everyone censored: no event, no median.
  EXPECT_FALSE(stats::quantile(stats::kaplanMeier({{60, false}, {60, false}}), 0.5));
}

// Wilson for 5 of 10: centre (0.5 + z^2/20) / (1 + z^2/10) = 0.5, half
// width z sqrt(0.025 + z^2/400) / (1 + z^2/10) with z = 1.959964.
TEST(Stats, WilsonByHand) {
  const double z = 1.959963984540054, z2 = z * z;
  const double half = z * std::sqrt(0.025 + z2 / 400) / (1 + z2 / 10);
  const auto ci = stats::wilson(5, 10);
  EXPECT_NEAR(ci.low, 0.5 - half, 1e-12);
  EXPECT_NEAR(ci.high, 0.5 + half, 1e-12);
  EXPECT_GT(stats::wilson(0, 10).low, -1e-15);  // never below 0
}

// Garwood: chi-squared with 2 df is exponential with mean 2, so for a total
// of 0 the upper limit is -ln(0.025), and for 1 the lower is -ln(0.975).
TEST(Stats, PoissonIntervalByHand) {
  const auto zero = stats::poissonMeanCi(0, 1);
  EXPECT_EQ(zero.low, 0);
  EXPECT_NEAR(zero.high, -std::log(0.025), 1e-12);
  EXPECT_NEAR(stats::poissonMeanCi(1, 4).low, -std::log(0.975) / 4, 1e-12);
}

// Log-rank by hand: A events at 1 and 2, B at 3 and 4. At 1: 4 at risk
// (2 of B), O - E = 0 - 1/2, V = 1/4; at 2: 3 (2 of B), O - E = -2/3,
// V = 2/9; at 3: only B at risk, nothing. chi2 = (7/6)^2 / (17/36) = 49/17,
// and with 1 df its tail is erfc(sqrt(chi2 / 2)).
TEST(Stats, LogRankByHand) {
  const auto t = stats::logRank({{1, true}, {2, true}}, {{3, true}, {4, true}});
  ASSERT_TRUE(t);
  EXPECT_NEAR(t->statistic, 49.0 / 17, 1e-12);
  EXPECT_NEAR(t->p, std::erfc(std::sqrt(49.0 / 34)), 1e-12);
  EXPECT_FALSE(stats::logRank({{5, false}}, {{5, false}}));  // no events
}

// Exact tests by hand: 0 of 10 against 1/2 is as unlikely as 10 of 10:
// p = 2 / 2^10. [[3, 0], [0, 3]]: each extreme table has 1 / C(6, 3).
// Permutation of {1, 2} vs {3, 4}: the 6 splits give differences -2, -1,
// 0, 0, 1, 2; the observed -2 is the least: p = 2 * 1/6.
TEST(Stats, ExactTestsByHand) {
  EXPECT_NEAR(stats::binomialTest(0, 10, 0.5).p, 2.0 / 1024, 1e-15);
  EXPECT_NEAR(stats::binomialTest(5, 10, 0.5).p, 1, 1e-15);
  EXPECT_NEAR(stats::fisherExact(3, 0, 0, 3).p, 0.1, 1e-12);
  const auto perm = stats::permutationTest({1, 2}, {3, 4}, 1);
  EXPECT_NEAR(perm.statistic, -2, 1e-15);
  EXPECT_NEAR(perm.p, 1.0 / 3, 1e-15);
}

const std::string kShared = SIMBOT_SHARED_DIR;
const std::string kSource = SIMBOT_SOURCE_DIR;

std::string benchJson(const std::string& family, int threads) {
  batch::BenchConfig c;
  c.programs = {kShared + "/programs/iceman.dc"};
  c.family = family;
  c.seeds = 4;
  c.seconds = 10;
  c.threads = threads;
  c.progress = false;
  if (family == "head-to-head") c.opponent = kShared + "/programs/fig92.dc";
  const auto profile = runs::loadNamedProfile(kSource + "/profiles/default.toml");
  const auto r = batch::runBench(c, profile);
  return batch::summaryJson(r).dump(2) + batch::runsCsv(r);
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
  batch::BenchConfig c;
  c.programs = {kShared + "/programs/iceman.dc"};
  c.family = "head-to-head";
  c.opponent = kShared + "/programs/fig92.dc";
  c.seeds = 6;
  c.seconds = 0.5;
  c.progress = false;
  const auto profile = runs::loadNamedProfile(kSource + "/profiles/default.toml");
  const auto r = batch::runBench(c, profile);
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

// Head-to-head measures both robots and counts the games each won: the
// summary's wins are the runs' winners.
TEST(Bench, HeadToHeadReportsBothRobotsAndTheWinRate) {
  batch::BenchConfig c;
  c.programs = {kShared + "/programs/iceman.dc"};
  c.family = "head-to-head";
  c.opponent = kShared + "/programs/fig92.dc";
  c.seeds = 4;
  c.seconds = 5;
  c.progress = false;
  const auto r = batch::runBench(c, runs::loadNamedProfile(kSource + "/profiles/default.toml"));
  int winsA = 0;
  for (const auto& run : r.runs) {
    ASSERT_TRUE(run.metricsB);
    ASSERT_TRUE(run.winner == "A" || run.winner == "B");
    winsA += run.winner == "A";
  }
  const auto s = batch::summarize(r);
  ASSERT_EQ(s[0].robots.size(), 2u);
  EXPECT_EQ(s[0].robots[1].program, c.opponent);
  EXPECT_EQ(s[0].games, 4);
  EXPECT_EQ(s[0].winsA, winsA);
  EXPECT_NEAR(*s[0].winRate, winsA / 4.0, 1e-15);
  const auto json = batch::summaryJson(r);
  EXPECT_EQ(json["programs"][0]["games"]["won_by_a"], winsA);
  EXPECT_EQ(json["programs"][0]["robots"][1]["robot"], "B");
}

// The thresholds are options: no pair of eye readings sums to a million,
// so with that as the aim sum every run is censored for aim_s.
TEST(Bench, AimThresholdIsAnOption) {
  batch::BenchConfig c;
  c.programs = {kShared + "/programs/iceman.dc"};
  c.family = "stationary";
  c.seeds = 3;
  c.seconds = 10;
  c.progress = false;
  const auto profile = runs::loadNamedProfile(kSource + "/profiles/default.toml");
  c.thresholds.aimMinSum = 1'000'000;
  const auto r = batch::runBench(c, profile);
  for (const auto& run : r.runs) EXPECT_FALSE(run.metrics.values[1]) << "aim_s";
  const auto aim = batch::summarize(r)[0].robots[0].metrics[1];
  EXPECT_EQ(aim.metric, "aim_s");
  EXPECT_EQ(aim.events, 0);
  EXPECT_EQ(aim.n, 3);
}

TEST(Bench, ObserverDoesNotChangeTheMatch) {
  scheduler::MatchConfig c;
  c.arena = config::makeArenaConfig(runs::loadNamedProfile(kSource + "/profiles/default.toml"), 2);
  c.robots.push_back({"A", "iceman", runs::compileProgramFile(kShared + "/programs/iceman.dc")});
  c.robots.push_back({"B", "fig92", runs::compileProgramFile(kShared + "/programs/fig92.dc")});
  c.endTick = 10 * scheduler::kTicksPerSecond;
  const auto plain = testkit::runTraced(c);
  batch::MetricsObserver observer;
  c.observer = &observer;
  const auto watched = testkit::runTraced(c);
  EXPECT_EQ(plain.trace, watched.trace);
  EXPECT_EQ(plain.robots[0].cycles, watched.robots[0].cycles);
  EXPECT_EQ(plain.rounds, watched.rounds);
}

TEST(Tournament, SameStandingsOnRerunAndThreadCounts) {
  batch::TournamentConfig c;
  c.programs = {kSource + "/programs/spiral.dc", kSource + "/programs/turret.dc",
                kShared + "/programs/fig92.dc"};
  c.rounds = 1;
  c.seconds = 20;
  c.progress = false;
  const auto profile = runs::loadNamedProfile(kSource + "/profiles/default.toml");
  c.threads = 1;
  const std::string first = batch::tournamentJson(batch::runTournament(c, profile)).dump();
  EXPECT_EQ(first, batch::tournamentJson(batch::runTournament(c, profile)).dump());
  c.threads = 2;
  EXPECT_EQ(first, batch::tournamentJson(batch::runTournament(c, profile)).dump());
  c.threads = 3;
  const auto r = batch::runTournament(c, profile);
  EXPECT_EQ(first, batch::tournamentJson(r).dump());
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
  batch::TournamentConfig c;
  c.programs = {kSource + "/programs/spiral.dc", kSource + "/programs/turret.dc"};
  c.rounds = 2;
  c.seconds = 2;
  c.progress = false;
  const auto r =
      batch::runTournament(c, runs::loadNamedProfile(kSource + "/profiles/default.toml"));
  ASSERT_EQ(r.games.size(), 2u);
  EXPECT_EQ(r.games[0].a, 0);
  EXPECT_EQ(r.games[1].a, 1);
  EXPECT_NE(r.games[0].seed, r.games[1].seed);
}

}  // namespace
