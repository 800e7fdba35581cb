// Statistics for batches of seeded runs (simbot bench and compare) that
// respect what the runs measure: times to an event are right-censored (a
// run that never gets there says only "later than its end"), ratios are
// binomial, counts are non-negative. Each function names its estimator and
// matches a reference implementation (tests/stats_oracle_test.py runs
// statsmodels and scipy on the same data):
//   kaplanMeier, quantile, quantileCi  statsmodels SurvfuncRight (its
//                                      default cloglog quantile CI, SAS's
//                                      method)
//   wilson                             statsmodels proportion_confint
//   poissonMeanCi                      Garwood's exact interval (chi-squared)
//   logRank                            statsmodels survdiff
//   binomialTest, fisherExact,         scipy.stats binomtest, fisher_exact,
//   permutationTest                    permutation_test
// Boost.Math supplies every distribution; this file adds only the
// estimators no C++ library ships.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

namespace simbot::stats {

struct Interval {
  double low = 0, high = 0;  // high may be +infinity (a KM quantile's)
};

// One subject: the time of its event, or of its censoring (event false).
struct Observation {
  double time = 0;
  bool event = false;
};

// The Kaplan-Meier estimate at each distinct event time.
struct KaplanMeier {
  std::vector<double> times;     // event times, ascending
  std::vector<double> survival;  // S(t) = P(T > t) just after each time
  std::vector<double> se;        // Greenwood's standard error (NaN once S reaches 0)
  std::vector<int> atRisk, events;
};
KaplanMeier kaplanMeier(const std::vector<Observation>& sample);
// S(t) of the step function (1 before the first event).
double survivalAt(const KaplanMeier& km, double t);
// Where S equals 1 - p exactly over an interval (with 200 runs, S is often
// exactly 0.5 between two event times), conventions differ:
//   FirstBelow  the first event time with S < 1 - p, i.e. the interval's
//               upper end (statsmodels' SurvfuncRight.quantile);
//   Midpoint    the midpoint of that interval (SAS's PROC LIFETEST and R's
//               survival), the plateau's start if no event ends it.
// Elsewhere both give the first event time with S < 1 - p.
enum class QuantileRule : std::uint8_t { FirstBelow, Midpoint };
// The p-quantile of the event time by `rule`; none if S never falls to
// 1 - p (or, FirstBelow, below it).
std::optional<double> quantile(const KaplanMeier& km, double p,
                               QuantileRule rule = QuantileRule::FirstBelow);
// Its 1 - alpha confidence interval by inverting z-tests on the cloglog
// scale (the limits are event times; high is +infinity when the upper
// limit lies past the last event); none if no event time qualifies.
std::optional<Interval> quantileCi(const KaplanMeier& km, double p, double alpha = 0.05);

// Wilson's score interval for a binomial proportion (trials > 0).
Interval wilson(int64_t successes, int64_t trials, double alpha = 0.05);

// Garwood's exact (central) interval for the mean count per run when
// `total` events were counted over `runs` runs (Poisson counts).
Interval poissonMeanCi(int64_t total, int64_t runs, double alpha = 0.05);

// Percentile bootstrap interval for the mean: `resamples` resamples drawn
// with a SplitMix64 stream from `seed` (so the same data give the same
// interval everywhere). It stays inside the data's range.
Interval bootstrapMeanCi(const std::vector<double>& sample, uint64_t seed, int resamples = 2000,
                         double alpha = 0.05);

struct TestResult {
  double statistic = 0;  // the test's own statistic (chi-squared, odds ratio, ...)
  double p = 1;          // two-sided p-value
};

// The log-rank test of two right-censored samples (chi-squared, 1 df);
// none when no time has an event and two at risk (the variance is 0).
std::optional<TestResult> logRank(const std::vector<Observation>& a,
                                  const std::vector<Observation>& b);

// Exact two-sided binomial test of k successes in n trials against p (as
// scipy: the outcomes no likelier than k, with a 1e-7 relative tolerance).
TestResult binomialTest(int64_t k, int64_t n, double p);

// Two counts of Poisson events over exposures (runs): the conditional exact
// test (a ~ Binomial(a + b, ea / (ea + eb)) under equal rates).
TestResult poissonRatesTest(int64_t a, double exposureA, int64_t b, double exposureB);

// Fisher's exact test of the 2x2 table [[a, b], [c, d]]; statistic: the
// sample odds ratio (scipy's).
TestResult fisherExact(int64_t a, int64_t b, int64_t c, int64_t d);

// Two-sample permutation test of the difference in means (scipy's
// permutation_test, independent samples, two-sided): every split when
// there are at most `resamples` of them, otherwise `resamples` random ones
// from `seed` (p = (hits + 1) / (resamples + 1)).
TestResult permutationTest(const std::vector<double>& a, const std::vector<double>& b,
                           uint64_t seed, int64_t resamples = 9999);

}  // namespace simbot::stats
