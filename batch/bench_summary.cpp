// The bench's summary (bench.h): each metric with the estimator its kind of
// data calls for, from stats/ (whose functions match statsmodels and scipy,
// tests/stats_oracle_test.py). Times to an event are right-censored at the
// end of the run (a run that never got there is "later than T", not
// dropped), so they get Kaplan-Meier: its median with statsmodels' default
// (cloglog) interval, and the fraction reached by 60 s. The hit ratio is
// pooled hits over pooled shots with Wilson's interval; counts get
// Garwood's exact Poisson interval for their mean per run; stall_s, a
// bounded duration every run has, a seeded percentile bootstrap.
#include <fmt/format.h>

#include <cmath>
#include <filesystem>

#include "batch/bench.h"

namespace simbot::batch {

namespace {

// The first time metrics of the edge sequence; each later leg starts
// where the one before it ended.
constexpr const char* kEdgeLegs[] = {"edge_enter_s", "edge_accept_s", "edge_latch_s",
                                     "edge_leave_s"};

size_t metricIndex(const std::string& name) {
  const auto& names = metricNames();
  return static_cast<size_t>(std::find(names.begin(), names.end(), name) - names.begin());
}

const RunMetrics& metricsOf(const BenchRun& run, bool robotB) {
  return robotB ? *run.metricsB : run.metrics;
}

// The seed of stall_s's bootstrap: fixed, so a summary is reproducible.
constexpr uint64_t kBootstrapSeed = 0x5eed'b007;

}  // namespace

MetricKind metricKind(const std::string& name) {
  if (name == "hit_ratio") return MetricKind::Ratio;
  if (name == "shots" || name == "hits" || name == "frames_rejected") return MetricKind::Count;
  if (name == "stall_s") return MetricKind::Continuous;
  return MetricKind::Time;
}

double reachedByHorizon(const BenchConfig& config) { return std::min(60.0, config.seconds); }

std::vector<stats::Observation> timeObservations(const std::vector<const BenchRun*>& runs,
                                                 bool robotB, size_t metric, double seconds) {
  const std::string& name = metricNames()[metric];
  // An edge leg: the legs before it give its start (and whether it began).
  size_t leg = 0;
  while (leg < std::size(kEdgeLegs) && name != kEdgeLegs[leg]) ++leg;
  std::vector<stats::Observation> out;
  for (const BenchRun* run : runs) {
    const auto& values = metricsOf(*run, robotB).values;
    double start = 0;
    bool began = true;
    for (size_t k = 0; leg < std::size(kEdgeLegs) && k < leg; ++k) {
      const auto& v = values[metricIndex(kEdgeLegs[k])];
      if (!v) {
        began = false;
        break;
      }
      start += *v;
    }
    if (!began) continue;
    const auto& v = values[metric];
    out.push_back(v ? stats::Observation{*v, true} : stats::Observation{seconds - start, false});
  }
  return out;
}

namespace {

MetricEstimate estimate(const BenchConfig& config, const std::vector<const BenchRun*>& runs,
                        bool robotB, size_t m) {
  const std::string& name = metricNames()[m];
  MetricEstimate e;
  e.metric = name;
  switch (metricKind(name)) {
    case MetricKind::Time: {
      e.estimator = "Kaplan-Meier median";
      const auto obs = timeObservations(runs, robotB, m, config.seconds);
      e.n = static_cast<int>(obs.size());
      for (const auto& o : obs) e.events += o.event;
      e.reachedByS = reachedByHorizon(config);
      if (obs.empty()) break;
      const stats::KaplanMeier km = stats::kaplanMeier(obs);
      e.estimate = stats::quantile(km, 0.5, config.median);
      if (const auto ci = stats::quantileCi(km, 0.5)) {
        e.low = ci->low;
        e.high = ci->high;
      }
      e.reachedBy = 1 - stats::survivalAt(km, e.reachedByS);
      break;
    }
    case MetricKind::Ratio: {
      e.estimator = "Wilson";
      const size_t hits = metricIndex("hits"), shots = metricIndex("shots");
      int64_t h = 0, s = 0;
      for (const BenchRun* run : runs) {
        const auto& v = metricsOf(*run, robotB).values;
        h += static_cast<int64_t>(v[hits].value_or(0));
        s += static_cast<int64_t>(v[shots].value_or(0));
      }
      e.n = static_cast<int>(runs.size());
      e.events = static_cast<int>(h);
      e.trials = s;
      if (s == 0) break;
      e.estimate = static_cast<double>(h) / static_cast<double>(s);
      const stats::Interval ci = stats::wilson(h, s);
      e.low = ci.low;
      e.high = ci.high;
      break;
    }
    case MetricKind::Count: {
      e.estimator = "exact Poisson";
      int64_t total = 0;
      for (const BenchRun* run : runs)
        total += static_cast<int64_t>(metricsOf(*run, robotB).values[m].value_or(0));
      e.n = static_cast<int>(runs.size());
      e.events = static_cast<int>(total);
      if (runs.empty()) break;
      e.estimate = static_cast<double>(total) / static_cast<double>(runs.size());
      const stats::Interval ci = stats::poissonMeanCi(total, e.n);
      e.low = ci.low;
      e.high = ci.high;
      break;
    }
    case MetricKind::Continuous: {
      e.estimator = "bootstrap mean";
      std::vector<double> v;
      for (const BenchRun* run : runs)
        if (const auto& x = metricsOf(*run, robotB).values[m]) v.push_back(*x);
      e.n = static_cast<int>(v.size());
      if (v.empty()) break;
      double sum = 0;
      for (double x : v) sum += x;
      e.estimate = sum / static_cast<double>(v.size());
      const stats::Interval ci = stats::bootstrapMeanCi(v, kBootstrapSeed);
      e.low = ci.low;
      e.high = ci.high;
      break;
    }
  }
  return e;
}

}  // namespace

std::vector<ProgramSummary> summarize(const BenchResult& result) {
  const auto& c = result.config;
  const size_t seeds = static_cast<size_t>(c.seeds);
  std::vector<ProgramSummary> all;
  for (size_t p = 0; p < c.programs.size(); ++p) {
    ProgramSummary s;
    s.program = c.programs[p];
    std::vector<const BenchRun*> runs;  // done and measured
    for (size_t i = 0; i < seeds; ++i) {
      const BenchRun& run = result.runs[p * seeds + i];
      if (!run.done) continue;
      ++s.done;
      s.faults += run.outcome == "fault";
      s.errors += run.outcome == "error";
      if (run.outcome != "error") runs.push_back(&run);
    }
    const bool headToHead = c.family == "head-to-head";
    for (int robot = 0; robot < (headToHead ? 2 : 1); ++robot) {
      RobotSummary r;
      r.robot = robot == 0 ? "A" : "B";
      r.program = robot == 0 ? c.programs[p] : c.opponent;
      // B's measured runs: those that have B's metrics (all but a
      // malformed resumed row would).
      std::vector<const BenchRun*> measured;
      for (const BenchRun* run : runs)
        if (robot == 0 || run->metricsB) measured.push_back(run);
      for (size_t m = 0; m < metricNames().size(); ++m)
        r.metrics.push_back(estimate(c, measured, robot == 1, m));
      s.robots.push_back(std::move(r));
    }
    if (headToHead) {
      for (const BenchRun* run : runs) {
        if (run->winner.empty()) continue;
        ++s.games;
        s.winsA += run->winner == "A";
        s.coinWins += run->winner == "A" && run->coin;
      }
      if (s.games > 0) {
        s.winRate = static_cast<double>(s.winsA) / s.games;
        const stats::Interval ci = stats::wilson(s.winsA, s.games);
        s.winLow = ci.low;
        s.winHigh = ci.high;
      }
    }
    all.push_back(std::move(s));
  }
  return all;
}

nlohmann::json estimateJson(const std::optional<double>& v) {
  return v && std::isfinite(*v) ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

std::string estimateText(const std::optional<double>& v) {
  return v ? fmt::format("{:.4g}", *v) : "";
}

namespace {

std::string interval(const std::optional<double>& low, const std::optional<double>& high) {
  if (!low) return "";
  return fmt::format("[{:.4g}, {}]", *low,
                     std::isfinite(*high) ? fmt::format("{:.4g}", *high) : "inf");
}

}  // namespace

nlohmann::json summaryJson(const BenchResult& result) {
  const auto& c = result.config;
  nlohmann::json j = {
      {"family", benchLabel(c)},
      {"scenario", c.scenario ? nlohmann::json(c.scenario->file) : nlohmann::json(nullptr)},
      {"seeds", c.seeds},
      {"seconds", c.seconds},
      {"master_seed", c.masterSeed},
      {"opponent", c.opponent.empty() ? nlohmann::json(nullptr) : nlohmann::json(c.opponent)},
      {"thresholds",
       {{"seen", c.thresholds.seen},
        {"aim_max_diff", c.thresholds.aimMaxDiff},
        {"aim_min_sum", c.thresholds.aimMinSum}}},
      {"confidence", 0.95},
      {"programs", nlohmann::json::array()}};
  for (const ProgramSummary& s : summarize(result)) {
    nlohmann::json robots = nlohmann::json::array();
    for (const RobotSummary& r : s.robots) {
      nlohmann::json metrics = nlohmann::json::array();
      for (const MetricEstimate& e : r.metrics) {
        nlohmann::json m = {{"metric", e.metric},
                            {"estimator", e.estimator},
                            {"n", e.n},
                            {"events", e.events},
                            {"estimate", estimateJson(e.estimate)},
                            {"ci95_low", estimateJson(e.low)},
                            {"ci95_high", estimateJson(e.high)},
                            {"ci95_high_unbounded", e.high && !std::isfinite(*e.high)}};
        if (metricKind(e.metric) == MetricKind::Time) {
          m["censored"] = e.n - e.events;
          m["reached_by_s"] = e.reachedByS;
          m["reached_by"] = estimateJson(e.reachedBy);
        }
        if (metricKind(e.metric) == MetricKind::Ratio) m["trials"] = e.trials;
        metrics.push_back(std::move(m));
      }
      robots.push_back({{"robot", r.robot}, {"program", r.program}, {"metrics", metrics}});
    }
    nlohmann::json p = {{"program", s.program},
                        {"runs_done", s.done},
                        {"runs_faulted", s.faults},
                        {"runs_failed", s.errors},
                        {"robots", robots},
                        // robot A's, as before head-to-head had two
                        {"metrics", robots[0]["metrics"]}};
    if (c.family == "head-to-head")
      p["games"] = {{"played", s.games},
                    {"won_by_a", s.winsA},
                    {"won_by_b", s.games - s.winsA},
                    {"a_won_by_coin", s.coinWins},
                    {"estimator", "Wilson"},
                    {"win_rate_a", estimateJson(s.winRate)},
                    {"ci95_low", estimateJson(s.winLow)},
                    {"ci95_high", estimateJson(s.winHigh)}};
    j["programs"].push_back(std::move(p));
  }
  return j;
}

std::string summaryMarkdown(const BenchResult& result) {
  const auto& c = result.config;
  std::string out;
  const double horizon = reachedByHorizon(c);
  const auto fileName = [](const std::string& path) {
    return std::filesystem::path(path).filename().string();
  };
  for (const ProgramSummary& s : summarize(result)) {
    out += fmt::format("### {}: {}{}, {} seeds x {} s\n\n", s.program,
                       c.family.empty() ? benchLabel(c) : "family " + c.family,
                       c.opponent.empty() ? "" : " vs " + c.opponent, c.seeds, c.seconds);
    if (s.done < c.seeds || s.faults || s.errors)
      out += fmt::format("{} of {} runs done; {} with a fault, {} failed (runs.csv lists them)\n\n",
                         s.done, c.seeds, s.faults, s.errors);
    if (s.winRate)
      out += fmt::format(
          "A ({}) won {} of {} games ({} by the coin), B ({}) {}: win rate of A {:.4g}, 95% CI "
          "[{:.4g}, {:.4g}] (Wilson)\n\n",
          fileName(s.program), s.winsA, s.games, s.coinWins, fileName(c.opponent),
          s.games - s.winsA, *s.winRate, *s.winLow, *s.winHigh);
    for (const RobotSummary& r : s.robots) {
      if (s.robots.size() > 1)
        out += fmt::format("Robot {} ({}):\n\n", r.robot, fileName(r.program));
      out += fmt::format(
          "| metric | estimator | n | reached / total | estimate | 95% CI | reached by {:g} s |\n",
          horizon);
      out += "|---|---|---:|---:|---:|---|---:|\n";
      for (const MetricEstimate& e : r.metrics) {
        const MetricKind kind = metricKind(e.metric);
        const std::string count = kind == MetricKind::Ratio
                                      ? fmt::format("{}/{}", e.events, e.trials)
                                  : kind == MetricKind::Continuous ? std::string("")
                                                                   : fmt::format("{}", e.events);
        out += fmt::format("| {} | {} | {} | {} | {} | {} | {} |\n", e.metric, e.estimator, e.n,
                           count, estimateText(e.estimate), interval(e.low, e.high),
                           estimateText(e.reachedBy));
      }
      out += '\n';
    }
  }
  return out;
}

}  // namespace simbot::batch
