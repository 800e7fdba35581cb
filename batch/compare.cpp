// simbot compare (compare.h).
#include "batch/compare.h"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <tuple>
#include <utility>

#include "stats/stats.h"

namespace simbot::batch {

namespace {

// The seed of stall_s's permutation test: fixed, so a comparison is
// reproducible.
constexpr uint64_t kPermutationSeed = 0x5eed'9e37;

std::vector<const BenchRun*> measured(const BenchResult& r) {
  std::vector<const BenchRun*> out;
  for (const auto& run : r.runs)
    if (run.done && run.outcome != "error") out.push_back(&run);
  return out;
}

std::optional<double> finite(double v) {
  return std::isfinite(v) ? std::optional<double>(v) : std::nullopt;
}

size_t indexOf(const std::string& name) {
  const auto& names = metricNames();
  return static_cast<size_t>(std::find(names.begin(), names.end(), name) - names.begin());
}

int64_t total(const std::vector<const BenchRun*>& runs, size_t m) {
  int64_t sum = 0;
  for (const BenchRun* run : runs) sum += static_cast<int64_t>(run->metrics.values[m].value_or(0));
  return sum;
}

// CompareRow's reached and total of metric m over the runs measured.
std::pair<int64_t, int64_t> reached(const std::vector<const BenchRun*>& runs, size_t m) {
  const std::string& name = metricNames()[m];
  if (metricKind(name) == MetricKind::Ratio)
    return {total(runs, indexOf("hits")), total(runs, indexOf("shots"))};
  int64_t got = 0;
  for (const BenchRun* run : runs) {
    const auto& v = run->metrics.values[m];
    got += metricKind(name) == MetricKind::Count ? v.value_or(0) > 0 : v.has_value();
  }
  return {got, static_cast<int64_t>(runs.size())};
}

}  // namespace

std::vector<CompareRow> compareRuns(const BenchResult& a, const BenchResult& b) {
  const auto sa = summarize(a), sb = summarize(b);
  const auto ra = measured(a), rb = measured(b);
  const auto& names = metricNames();
  std::vector<CompareRow> rows;
  for (size_t m = 0; m < names.size(); ++m) {
    CompareRow row;
    row.metric = names[m];
    row.a = sa[0].robots[0].metrics[m];
    row.b = sb[0].robots[0].metrics[m];
    std::tie(row.reachedA, row.totalA) = reached(ra, m);
    std::tie(row.reachedB, row.totalB) = reached(rb, m);
    switch (metricKind(names[m])) {
      case MetricKind::Time: {
        row.test = "log-rank";
        const auto t = stats::logRank(timeObservations(ra, false, m, a.config.seconds),
                                      timeObservations(rb, false, m, b.config.seconds));
        if (t) {
          row.statistic = t->statistic;
          row.p = t->p;
        }
        break;
      }
      case MetricKind::Ratio: {
        row.test = "Fisher exact";
        const int64_t ha = total(ra, indexOf("hits")), na = total(ra, indexOf("shots"));
        const int64_t hb = total(rb, indexOf("hits")), nb = total(rb, indexOf("shots"));
        if (na > 0 && nb > 0) {
          const auto t = stats::fisherExact(ha, na - ha, hb, nb - hb);
          row.statistic = finite(t.statistic);
          row.p = t.p;
        }
        break;
      }
      case MetricKind::Count: {
        row.test = "exact Poisson rates";
        const int64_t ta = total(ra, m), tb = total(rb, m);
        if (ta + tb > 0 && !ra.empty() && !rb.empty()) {
          const auto t = stats::poissonRatesTest(ta, static_cast<double>(ra.size()), tb,
                                                 static_cast<double>(rb.size()));
          row.statistic = finite(t.statistic);
          row.p = t.p;
        }
        break;
      }
      case MetricKind::Continuous: {
        row.test = "permutation";
        std::vector<double> va, vb;
        for (const BenchRun* run : ra)
          if (run->metrics.values[m]) va.push_back(*run->metrics.values[m]);
        for (const BenchRun* run : rb)
          if (run->metrics.values[m]) vb.push_back(*run->metrics.values[m]);
        if (!va.empty() && !vb.empty()) {
          const auto t = stats::permutationTest(va, vb, kPermutationSeed);
          row.statistic = t.statistic;
          row.p = t.p;
        }
        break;
      }
    }
    rows.push_back(std::move(row));
  }
  // Head-to-head: the win rates against the one opponent.
  if (a.config.family == "head-to-head" && sa[0].games > 0 && sb[0].games > 0) {
    CompareRow row;
    row.metric = "win_rate";
    row.test = "Fisher exact";
    const auto winEstimate = [](const ProgramSummary& s) {
      MetricEstimate e;
      e.metric = "win_rate";
      e.estimator = "Wilson";
      e.n = s.games;
      e.events = s.winsA;
      e.trials = s.games;
      e.estimate = s.winRate;
      e.low = s.winLow;
      e.high = s.winHigh;
      return e;
    };
    row.a = winEstimate(sa[0]);
    row.b = winEstimate(sb[0]);
    row.reachedA = sa[0].winsA;
    row.totalA = sa[0].games;
    row.reachedB = sb[0].winsA;
    row.totalB = sb[0].games;
    const auto t = stats::fisherExact(sa[0].winsA, sa[0].games - sa[0].winsA, sb[0].winsA,
                                      sb[0].games - sb[0].winsA);
    row.statistic = finite(t.statistic);
    row.p = t.p;
    rows.push_back(std::move(row));
  }
  return rows;
}

namespace {

nlohmann::json metricJson(const MetricEstimate& e, int64_t reached, int64_t total) {
  return {{"estimator", e.estimator},
          {"reached", reached},
          {"total", total},
          {"n", e.n},
          {"events", e.events},
          {"estimate", estimateJson(e.estimate)},
          {"ci95_low", estimateJson(e.low)},
          {"ci95_high", estimateJson(e.high)}};
}

std::string side(const MetricEstimate& e) {
  if (!e.estimate) return "";
  if (!e.low) return estimateText(e.estimate);
  return fmt::format("{} [{:.4g}, {}]", estimateText(e.estimate), *e.low,
                     std::isfinite(*e.high) ? fmt::format("{:.4g}", *e.high) : "inf");
}

}  // namespace

nlohmann::json compareJson(const CompareResult& r) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& row : r.rows)
    rows.push_back({{"metric", row.metric},
                    {"test", row.test},
                    {"a", metricJson(row.a, row.reachedA, row.totalA)},
                    {"b", metricJson(row.b, row.reachedB, row.totalB)},
                    {"statistic", estimateJson(row.statistic)},
                    {"p", estimateJson(row.p)}});
  return {{"family", benchLabel(r.a.config)},
          {"seeds", r.a.config.seeds},
          {"seconds", r.a.config.seconds},
          {"master_seed", r.a.config.masterSeed},
          {"a", {{"program", r.a.config.programs[0]}, {"profile", r.profileA}}},
          {"b", {{"program", r.b.config.programs[0]}, {"profile", r.profileB}}},
          {"rows", rows}};
}

std::string compareMarkdown(const CompareResult& r) {
  const auto& c = r.a.config;
  std::string out = fmt::format(
      "### compare: A {} (profile {}) vs B {} (profile {}): family {}{}, the same {} seeds x "
      "{} s\n\n",
      r.a.config.programs[0], r.profileA, r.b.config.programs[0], r.profileB, benchLabel(c),
      c.opponent.empty() ? "" : " vs " + c.opponent, c.seeds, c.seconds);
  out +=
      "| metric | estimator | A reached / total | A (95% CI) | B reached / total | B (95% CI) | "
      "test | statistic | p |\n"
      "|---|---|---:|---|---:|---|---|---:|---:|\n";
  for (const auto& row : r.rows)
    out += fmt::format("| {} | {} | {}/{} | {} | {}/{} | {} | {} | {} | {} |\n", row.metric,
                       row.a.estimator, row.reachedA, row.totalA, side(row.a), row.reachedB,
                       row.totalB, side(row.b), row.test, estimateText(row.statistic),
                       estimateText(row.p));
  out +=
      "\nreached / total: times, the runs that got there of the runs measured (a median is blank "
      "while fewer than half got there); hit_ratio, hits of shots; counts, the runs with at least "
      "one; stall_s, the runs with a value; win_rate, games won of games.\n";
  return out + '\n';
}

}  // namespace simbot::batch
