// The estimators and tests of stats.h. Each follows its reference
// implementation step by step (named at each function) so that the oracle
// test can hold them to 1e-9; Boost.Math supplies the distributions.
#include "stats/stats.h"

#include <algorithm>
#include <boost/math/distributions/binomial.hpp>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/hypergeometric.hpp>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace simbot::stats {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// The two-sided normal critical value z_{1 - alpha/2}.
double zCritical(double alpha) {
  return boost::math::quantile(boost::math::complement(boost::math::normal(), alpha / 2));
}

// SplitMix64 (Steele, Lea and Flood 2014), the generator plant::SplitMix64
// uses, so that resampling is the same on every platform (std's
// distributions are not).
struct SplitMix64 {
  uint64_t state;
  uint64_t next() {
    uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  // Uniform in [0, n) from the top 53 bits (n is far below 2^53 here).
  size_t below(size_t n) {
    const double u = static_cast<double>(next() >> 11) * 0x1.0p-53;
    return static_cast<size_t>(u * static_cast<double>(n));
  }
};

}  // namespace

// statsmodels.duration.survfunc._calc_survfunc_right (no weights, no entry).
KaplanMeier kaplanMeier(const std::vector<Observation>& sample) {
  std::vector<Observation> s = sample;
  std::sort(s.begin(), s.end(),
            [](const Observation& x, const Observation& y) { return x.time < y.time; });
  KaplanMeier km;
  double logS = 0, greenwood = 0;
  bool seNaN = false;
  size_t i = 0;
  while (i < s.size()) {
    size_t j = i;
    int d = 0;
    while (j < s.size() && s[j].time == s[i].time) d += s[j++].event;
    const int n = static_cast<int>(s.size() - i);  // at risk just before
    if (d > 0) {
      // statsmodels floors 1 - d/n at 1e-16 before the log and sets S = 0
      // where it did.
      double step = 1 - static_cast<double>(d) / n;
      const bool floored = step < 1e-16;
      if (floored) step = 1e-16;
      logS += std::log(step);
      const double sp = floored ? 0 : std::exp(logS);
      // Greenwood: sqrt(sum d / (n (n - d))) * S; undefined from the time
      // every subject at risk has the event (statsmodels' NaN).
      if (n == d) seNaN = true;
      greenwood += static_cast<double>(d) / std::max(static_cast<double>(n) * (n - d), 1e-12);
      const double se = seNaN ? kNaN : std::sqrt(greenwood) * sp;
      km.times.push_back(s[i].time);
      km.survival.push_back(floored ? 0 : sp);
      km.se.push_back(se);
      km.atRisk.push_back(n);
      km.events.push_back(d);
    }
    i = j;
  }
  return km;
}

double survivalAt(const KaplanMeier& km, double t) {
  const auto it = std::upper_bound(km.times.begin(), km.times.end(), t);
  if (it == km.times.begin()) return 1;
  return km.survival[static_cast<size_t>(it - km.times.begin()) - 1];
}

// SurvfuncRight.quantile.
std::optional<double> quantile(const KaplanMeier& km, double p, QuantileRule rule) {
  // S is a product of (1 - d/n) factors: "exactly 1 - p" within rounding.
  constexpr double kSame = 1e-12;
  for (size_t i = 0; i < km.times.size(); ++i) {
    if (rule == QuantileRule::Midpoint && std::abs(km.survival[i] - (1 - p)) <= kSame)
      return i + 1 < km.times.size() ? (km.times[i] + km.times[i + 1]) / 2 : km.times[i];
    if (km.survival[i] < 1 - p - (rule == QuantileRule::Midpoint ? kSame : 0)) return km.times[i];
  }
  return std::nullopt;
}

// SurvfuncRight.quantile_ci, method "cloglog" (its default): the event
// times where |g(S) - g(1 - p)| / (g'(S) se) <= z with g = log(-log x).
std::optional<Interval> quantileCi(const KaplanMeier& km, double p, double alpha) {
  const double z = zCritical(alpha);
  const auto g = [](double x) { return std::log(-std::log(x)); };
  const auto gPrime = [](double x) { return -1 / (x * std::log(x)); };
  std::optional<size_t> first, last;
  for (size_t i = 0; i < km.times.size(); ++i) {
    const double s = km.survival[i];
    const double r = (g(s) - g(1 - p)) / (gPrime(s) * km.se[i]);
    if (std::fabs(r) <= z) {  // false for NaN, as numpy's comparison
      if (!first) first = i;
      last = i;
    }
  }
  if (!first) return std::nullopt;
  Interval ci;
  ci.low = km.times[*first];
  ci.high = *last + 1 == km.times.size() ? kInf : km.times[*last + 1];
  return ci;
}

// statsmodels.stats.proportion.proportion_confint, method "wilson".
Interval wilson(int64_t successes, int64_t trials, double alpha) {
  if (trials <= 0) throw std::invalid_argument("wilson: no trials");
  const double n = static_cast<double>(trials);
  const double q = static_cast<double>(successes) / n;
  const double crit = zCritical(alpha), crit2 = crit * crit;
  const double denom = 1 + crit2 / n;
  const double center = (q + crit2 / (2 * n)) / denom;
  const double dist = crit * std::sqrt(q * (1 - q) / n + crit2 / (4 * n * n)) / denom;
  return {center - dist, center + dist};
}

// Garwood (1936): chi2(alpha/2; 2T)/2 .. chi2(1 - alpha/2; 2T + 2)/2 for
// the total T, divided by the runs.
Interval poissonMeanCi(int64_t total, int64_t runs, double alpha) {
  if (runs <= 0 || total < 0) throw std::invalid_argument("poissonMeanCi: bad counts");
  const double t = static_cast<double>(total), n = static_cast<double>(runs);
  const double low =
      total == 0 ? 0 : boost::math::quantile(boost::math::chi_squared(2 * t), alpha / 2) / 2;
  const double high = boost::math::quantile(
                          boost::math::complement(boost::math::chi_squared(2 * t + 2), alpha / 2)) /
                      2;
  return {low / n, high / n};
}

Interval bootstrapMeanCi(const std::vector<double>& sample, uint64_t seed, int resamples,
                         double alpha) {
  if (sample.empty() || resamples < 1) throw std::invalid_argument("bootstrap: no data");
  SplitMix64 bits{seed};
  std::vector<double> means(static_cast<size_t>(resamples));
  for (double& m : means) {
    double sum = 0;
    for (size_t k = 0; k < sample.size(); ++k) sum += sample[bits.below(sample.size())];
    m = sum / static_cast<double>(sample.size());
  }
  std::sort(means.begin(), means.end());
  // Linear interpolation between order statistics (numpy's default
  // percentile), at alpha/2 and 1 - alpha/2.
  const auto at = [&](double q) {
    const double pos = q * static_cast<double>(means.size() - 1);
    const auto i = static_cast<size_t>(std::floor(pos));
    if (i + 1 >= means.size()) return means.back();
    return means[i] + (pos - static_cast<double>(i)) * (means[i + 1] - means[i]);
  };
  return {at(alpha / 2), at(1 - alpha / 2)};
}

// statsmodels.duration.survfunc.survdiff with two groups and no weights:
// a is the reference group, the statistic is (O - E)^2 / V of group b over
// the distinct times with more than one subject at risk.
std::optional<TestResult> logRank(const std::vector<Observation>& a,
                                  const std::vector<Observation>& b) {
  struct Tagged {
    double time;
    bool event, inB;
  };
  std::vector<Tagged> all;
  for (const auto& o : a) all.push_back({o.time, o.event, false});
  for (const auto& o : b) all.push_back({o.time, o.event, true});
  std::sort(all.begin(), all.end(),
            [](const Tagged& x, const Tagged& y) { return x.time < y.time; });
  double oe = 0, var = 0;
  double riskB = static_cast<double>(b.size());
  size_t i = 0;
  while (i < all.size()) {
    const double riskAll = static_cast<double>(all.size() - i);
    double d = 0, dB = 0, leavingB = 0;
    size_t j = i;
    for (; j < all.size() && all[j].time == all[i].time; ++j) {
      d += all[j].event;
      dB += all[j].event && all[j].inB;
      leavingB += all[j].inB;
    }
    if (riskAll > 1) {
      const double r = riskB / riskAll;
      oe += dB - r * d;
      var += r * (1 - r) * d * (riskAll - d) / (riskAll - 1);
    }
    riskB -= leavingB;
    i = j;
  }
  if (!(var > 0)) return std::nullopt;
  TestResult t;
  t.statistic = oe * oe / var;
  t.p = boost::math::cdf(boost::math::complement(boost::math::chi_squared(1), t.statistic));
  return t;
}

// scipy.stats.binomtest, two-sided.
TestResult binomialTest(int64_t k, int64_t n, double p) {
  if (n <= 0 || k < 0 || k > n) throw std::invalid_argument("binomialTest: bad counts");
  const boost::math::binomial_distribution<double> dist(static_cast<double>(n), p);
  const auto pmf = [&](int64_t x) { return boost::math::pdf(dist, static_cast<double>(x)); };
  const auto cdf = [&](int64_t x) {
    return x < 0 ? 0.0 : x >= n ? 1.0 : boost::math::cdf(dist, static_cast<double>(x));
  };
  const auto sf = [&](int64_t x) {  // P(X > x)
    return x < 0    ? 1.0
           : x >= n ? 0.0
                    : boost::math::cdf(boost::math::complement(dist, static_cast<double>(x)));
  };
  TestResult t;
  t.statistic = static_cast<double>(k) / static_cast<double>(n);
  const double d = pmf(k) * (1 + 1e-7);
  const double mode = p * static_cast<double>(n);
  double pv = 1;
  if (static_cast<double>(k) == mode) {
    pv = 1;
  } else if (static_cast<double>(k) < mode) {
    // The outcomes above the mode no likelier than k: from the first x
    // with pmf(x) <= d (pmf falls there).
    int64_t x = static_cast<int64_t>(std::ceil(mode));
    while (x <= n && pmf(x) > d) ++x;
    pv = cdf(k) + sf(x - 1);
  } else {
    int64_t x = static_cast<int64_t>(std::floor(mode));
    while (x >= 0 && pmf(x) > d) --x;
    pv = cdf(x) + sf(k - 1);
  }
  t.p = std::min(1.0, pv);
  return t;
}

TestResult poissonRatesTest(int64_t a, double exposureA, int64_t b, double exposureB) {
  if (a + b == 0) return {kNaN, 1};
  TestResult t = binomialTest(a, a + b, exposureA / (exposureA + exposureB));
  t.statistic = (static_cast<double>(a) / exposureA) / (static_cast<double>(b) / exposureB);
  return t;
}

// scipy.stats.fisher_exact, two-sided: the tables no likelier than this
// one (relative tolerance 1e-14), summed from the hypergeometric tails.
TestResult fisherExact(int64_t a, int64_t b, int64_t c, int64_t d) {
  if (a < 0 || b < 0 || c < 0 || d < 0) throw std::invalid_argument("fisherExact: negative");
  TestResult t;
  if (a + b == 0 || c + d == 0 || a + c == 0 || b + d == 0) return {kNaN, 1};
  t.statistic = (c > 0 && b > 0) ? static_cast<double>(a) * static_cast<double>(d) /
                                       (static_cast<double>(c) * static_cast<double>(b))
                                 : kInf;
  const int64_t n1 = a + b, n2 = c + d, n = a + c;
  const boost::math::hypergeometric_distribution<double> dist(
      static_cast<unsigned>(n1), static_cast<unsigned>(n), static_cast<unsigned>(n1 + n2));
  const int64_t lo = std::max<int64_t>(0, n - n2), hi = std::min(n, n1);
  const auto pmf = [&](int64_t x) {
    return x < lo || x > hi ? 0.0 : boost::math::pdf(dist, static_cast<unsigned>(x));
  };
  const auto cdf = [&](int64_t x) {
    return x < lo ? 0.0 : x >= hi ? 1.0 : boost::math::cdf(dist, static_cast<unsigned>(x));
  };
  const auto sf = [&](int64_t x) {  // P(X > x)
    return x < lo    ? 1.0
           : x >= hi ? 0.0
                     : boost::math::cdf(boost::math::complement(dist, static_cast<unsigned>(x)));
  };
  const int64_t mode = static_cast<int64_t>(static_cast<double>((n + 1) * (n1 + 1)) /
                                            static_cast<double>(n1 + n2 + 2));
  const double pExact = pmf(a), pMode = pmf(mode);
  const double gamma = 1 + 1e-14;
  if (std::fabs(pExact - pMode) / std::max(pExact, pMode) <= 1e-14) {
    t.p = 1;
    return t;
  }
  double pv;
  if (a < mode) {
    int64_t x = mode;  // the first x above the mode no likelier than a
    while (x <= hi && pmf(x) > pExact * gamma) ++x;
    pv = cdf(a) + sf(x - 1);
  } else {
    int64_t x = mode;
    while (x >= lo && pmf(x) > pExact * gamma) --x;
    pv = sf(a - 1) + cdf(x);
  }
  t.p = std::min(1.0, pv);
  return t;
}

// scipy.stats.permutation_test(permutation_type="independent",
// alternative="two-sided") of mean(a) - mean(b).
TestResult permutationTest(const std::vector<double>& a, const std::vector<double>& b,
                           uint64_t seed, int64_t resamples) {
  if (a.empty() || b.empty()) throw std::invalid_argument("permutationTest: empty sample");
  std::vector<double> pooled = a;
  pooled.insert(pooled.end(), b.begin(), b.end());
  const size_t na = a.size(), n = pooled.size();
  const double total = std::accumulate(pooled.begin(), pooled.end(), 0.0);
  const auto statistic = [&](double sumA) {
    return sumA / static_cast<double>(na) - (total - sumA) / static_cast<double>(n - na);
  };
  const double observed = statistic(std::accumulate(a.begin(), a.end(), 0.0));
  const double gamma = std::max(1e-14, std::fabs(1e-14 * observed));
  // How many splits: C(n, na), capped once it passes the resamples.
  double splits = 1;
  for (size_t k = 1; k <= na && splits <= static_cast<double>(resamples); ++k)
    splits = splits * static_cast<double>(n - na + k) / static_cast<double>(k);
  int64_t less = 0, greater = 0, count = 0;
  const auto tally = [&](double s) {
    less += s <= observed + gamma;
    greater += s >= observed - gamma;
    ++count;
  };
  bool exact = std::round(splits) <= static_cast<double>(resamples);
  if (exact) {
    // Every na-subset of the pooled sample, in lexicographic order.
    std::vector<size_t> idx(na);
    std::iota(idx.begin(), idx.end(), 0);
    while (true) {
      double sumA = 0;
      for (size_t k : idx) sumA += pooled[k];
      tally(statistic(sumA));
      size_t k = na;
      while (k > 0 && idx[k - 1] == n - na + k - 1) --k;
      if (k == 0) break;
      ++idx[k - 1];
      for (size_t m = k; m < na; ++m) idx[m] = idx[m - 1] + 1;
    }
  } else {
    SplitMix64 bits{seed};
    std::vector<double> shuffled = pooled;
    for (int64_t r = 0; r < resamples; ++r) {
      // A partial Fisher-Yates shuffle picks group A.
      double sumA = 0;
      for (size_t k = 0; k < na; ++k) {
        std::swap(shuffled[k], shuffled[k + bits.below(n - k)]);
        sumA += shuffled[k];
      }
      tally(statistic(sumA));
    }
  }
  const int64_t adjust = exact ? 0 : 1;
  const double pLess = static_cast<double>(less + adjust) / static_cast<double>(count + adjust);
  const double pGreater =
      static_cast<double>(greater + adjust) / static_cast<double>(count + adjust);
  return {observed, std::clamp(2 * std::min(pLess, pGreater), 0.0, 1.0)};
}

}  // namespace simbot::stats
