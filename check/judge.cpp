// check/judge.cpp -- the runs of simbot check and each check judged on them.
//
// A step (after / within_s / expect) is judged on the trace's records in
// simulated time: every record matching `after` at tick t must be
// followed by one matching `expect` at a tick in [t, t + within]. A
// trigger whose window reaches past the run's end without its expect
// cannot be judged and is left out (the message counts it); a step with no
// trigger it can judge is skipped, never passed.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "check/check.h"
#include "runs/play.h"
#include "sinks/trace_jsonl.h"
#include "sinks/user_error.h"
#include "timebase/tick.h"

namespace simbot::check {

namespace {

using config::CheckKind;
using config::RecordPattern;
using timebase::Tick;

std::string seconds(Tick t) { return fmt::format("{:.3f} s", timebase::secondsFromTicks(t)); }

bool fieldMatches(const nlohmann::json& record, const RecordPattern::Field& f) {
  const auto it = record.find(f.name);
  if (it == record.end()) return false;
  const nlohmann::json& v = *it;
  return std::visit(
      [&](const auto& want) {
        using T = std::decay_t<decltype(want)>;
        if constexpr (std::is_same_v<T, std::string>) {
          return v.is_string() && v.get<std::string>() == want;
        } else if constexpr (std::is_same_v<T, bool>) {
          return v.is_boolean() && v.get<bool>() == want;
        } else if constexpr (std::is_same_v<T, std::int64_t>) {
          return v.is_number_integer() && v.get<std::int64_t>() == want;
        } else {
          return v.is_number() && v.get<double>() == want;
        }
      },
      f.value);
}

bool matches(const nlohmann::json& record, const RecordPattern& p) {
  for (const RecordPattern::Field& f : p.fields)
    if (!fieldMatches(record, f)) return false;
  return true;
}

// The ticks of the records each step's `after` and `expect` match, taken
// as the run emits them (in tick order). Only records of the kinds the
// steps name are turned into JSON.
class StepSink final : public trace::Sink {
 public:
  explicit StepSink(const std::vector<config::Check>& checks) : checks_(checks) {
    wanted_.assign(trace::kinds().size(), false);
    triggers_.resize(checks.size());
    expects_.resize(checks.size());
    for (const config::Check& c : checks) {
      if (c.kind != CheckKind::Step) continue;
      wanted_[static_cast<std::size_t>(trace::kindIndex(c.after.kind))] = true;
      wanted_[static_cast<std::size_t>(trace::kindIndex(c.expect.kind))] = true;
    }
  }
  void write(const trace::Entry& entry) override {
    const auto kind = entry.record.index();
    if (kind >= wanted_.size() || !wanted_[kind]) return;
    const nlohmann::json record = sinks::traceJson(entry);
    const std::string type = record.at("type").get<std::string>();
    for (std::size_t i = 0; i < checks_.size(); ++i) {
      const config::Check& c = checks_[i];
      if (c.kind != CheckKind::Step) continue;
      if (type == c.after.kind && matches(record, c.after)) triggers_[i].push_back(entry.t);
      if (type == c.expect.kind && matches(record, c.expect)) expects_[i].push_back(entry.t);
    }
  }
  const std::vector<Tick>& triggers(std::size_t i) const { return triggers_[i]; }
  const std::vector<Tick>& expects(std::size_t i) const { return expects_[i]; }

 private:
  const std::vector<config::Check>& checks_;
  std::vector<bool> wanted_;
  std::vector<std::vector<Tick>> triggers_, expects_;
};

Case judgeStep(const config::Check& c, const std::vector<Tick>& triggers,
               const std::vector<Tick>& expects, Tick end) {
  Case k;
  k.check = c.name;
  int judged = 0, late = 0, failed = 0;
  Tick firstFailure = -1, slowest = 0;
  for (const Tick t : triggers) {
    const auto next = std::lower_bound(expects.begin(), expects.end(), t);
    if (next != expects.end() && *next - t <= c.within) {
      ++judged;
      slowest = std::max(slowest, *next - t);
      continue;
    }
    if (t + c.within > end) {  // its window outlasts the run
      ++late;
      continue;
    }
    ++judged;
    ++failed;
    if (firstFailure < 0) firstFailure = t;
  }
  const std::string lateNote =
      late > 0 ? fmt::format("; {} too near the end to judge", late) : std::string();
  if (judged == 0) {
    k.status = Status::Skipped;
    k.message = triggers.empty() ? fmt::format("no {} record matched 'after'", c.after.kind)
                                 : fmt::format(
                                       "every {} matched too near the end to judge "
                                       "({} of them)",
                                       c.after.kind, late);
  } else if (failed > 0) {
    k.status = Status::Failed;
    k.message = fmt::format("{} at {} not followed by {} within {} ({} of {} triggers failed{})",
                            c.after.kind, seconds(firstFailure), c.expect.kind, seconds(c.within),
                            failed, judged, lateNote);
  } else {
    k.message = fmt::format("{} triggers, each followed by {} (the slowest after {}{})", judged,
                            c.expect.kind, seconds(slowest), lateNote);
  }
  return k;
}

Case judgeResult(const config::Check& c, const scheduler::MatchResult& result) {
  const scheduler::RobotResult& a = result.robots.front();
  Case k;
  k.check = c.name;
  bool ok = true;
  switch (c.kind) {
    case CheckKind::NoFault:
      if (a.fault) {
        ok = false;
        k.message = runs::faultText(a, *a.fault);
      } else if (result.plantFault) {
        ok = false;
        k.message = "the plant failed: " + result.plantFault->message;
      } else {
        k.message = "no fault";
      }
      break;
    case CheckKind::HitsAtLeast:
      ok = a.hits >= c.count;
      k.message = fmt::format("{} hits, at least {} wanted", a.hits, c.count);
      break;
    case CheckKind::ShotsAtMost:
      ok = a.shots <= c.count;
      k.message = fmt::format("{} shots, at most {} wanted", a.shots, c.count);
      break;
    case CheckKind::NoScatterShot:
      ok = a.scatterShots.value_or(0) == 0;
      k.message = fmt::format("{} scatter shots", a.scatterShots.value_or(0));
      break;
    case CheckKind::NoOverwrittenSend:
      ok = a.framesOverwritten == 0;
      k.message = fmt::format("{} sends overwritten", a.framesOverwritten);
      break;
    case CheckKind::FramesAtLeast:
      ok = a.framesLatched >= c.count;
      k.message = fmt::format("{} frames latched, at least {} wanted", a.framesLatched, c.count);
      break;
    case CheckKind::Step:
      break;
  }
  k.status = ok ? Status::Passed : Status::Failed;
  return k;
}

// A beacon standing `range` ft straight ahead of A's start, facing A.
void addStationaryBeacon(scheduler::MatchConfig& config, const config::Expectations& e) {
  const config::Profile profile =
      runs::loadRunProfile(e.profile.value_or("default"), e.rules.value_or(""));
  const plant::ArenaConfig two = config::makeArenaConfig(profile, 2);
  const plant::Pose a = config.arena.robots.front().start;
  const double h = a.heading_deg * M_PI / 180;
  plant::RobotSetup b = two.robots[1];
  b.start = {a.x_ft + e.stationaryFt * std::sin(h), a.y_ft + e.stationaryFt * std::cos(h),
             std::fmod(a.heading_deg + 180, 360)};
  const double half = profile.field.size_ft / 2, radius = b.params.body_diameter_ft / 2;
  if (std::fabs(b.start.x_ft) + radius > half || std::fabs(b.start.y_ft) + radius > half ||
      plant::dividerClearance(b.start.x_ft, b.start.y_ft, radius, profile.field) <= 0)
    throw sinks::UserError(fmt::format(
        "simbot: {}: a beacon {} ft ahead of A's start ({:.2f}, {:.2f}) ft is off the field or "
        "on the divider\n",
        e.file, e.stationaryFt, b.start.x_ft, b.start.y_ft));
  config.arena.robots.push_back(b);
  config.robots.push_back(runs::beaconSpec({}, false));
  config.robots.back().controller = config.robots.front().controller;
}

}  // namespace

int Report::count(Status s) const {
  return static_cast<int>(
      std::count_if(cases.begin(), cases.end(), [s](const Case& c) { return c.status == s; }));
}

Report runChecks(const std::string& program, const config::Expectations& e) {
  Report report;
  report.program = program;
  report.expectations = e.file;
  using Opponent = config::Expectations::Opponent;
  std::vector<std::string> programs = {program};
  if (e.opponent == Opponent::Program) programs.push_back(e.opponentProgram);
  const bool steps = std::any_of(e.checks.begin(), e.checks.end(),
                                 [](const config::Check& c) { return c.kind == CheckKind::Step; });
  for (const std::uint64_t seed : e.seeds) {
    runs::RunOptions o;
    o.length = e.length;
    o.seed = seed;
    o.profile = e.profile;
    o.rules = e.rules;
    scheduler::MatchConfig config = runs::buildConfig(
        programs, o,
        e.opponent == Opponent::Program ? runs::ScenarioUse::Match : runs::ScenarioUse::Solo);
    if (e.opponent == Opponent::Stationary) addStationaryBeacon(config, e);
    config.stopWhenAllExited = e.opponent == Opponent::None;
    StepSink sink(e.checks);
    if (steps) config.sinks.push_back(&sink);
    scheduler::MatchResult result;
    try {
      result = scheduler::runMatch(config);
    } catch (const std::invalid_argument& err) {
      throw sinks::UserError(fmt::format("simbot: {}\n", err.what()));
    }
    for (std::size_t i = 0; i < e.checks.size(); ++i) {
      const config::Check& c = e.checks[i];
      Case k = c.kind == CheckKind::Step
                   ? judgeStep(c, sink.triggers(i), sink.expects(i), result.endTick)
                   : judgeResult(c, result);
      k.seed = seed;
      report.cases.push_back(std::move(k));
    }
  }
  return report;
}

}  // namespace simbot::check
