// simbot bench (bench.h): scenario sampling, the parallel runs, the outputs.
#include "batch/bench.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "batch/parallel.h"
#include "config/config.h"
#include "runs/play.h"
#include "scheduler/match.h"
#include "sinks/json_text.h"
#include "sinks/user_error.h"
#include "timebase/written.h"

namespace simbot::batch {

namespace {

double radians(double deg) { return deg * std::numbers::pi / 180; }
double normalizeHeading(double deg) {
  double h = std::fmod(deg, 360.0);
  if (h < 0) h += 360;
  return h;
}

struct Geometry {
  double wire;    // wire ring half-size
  double inside;  // centres at least 1.5 ft inside the wire
  double radius;  // body radius
  const plant::FieldParams* field;
  // A body centred here would touch the divider.
  bool nearDivider(double x, double y) const {
    return plant::dividerClearance(x, y, radius, *field) <= 0;
  }
  bool inBounds(double x, double y) const {
    return std::fabs(x) <= inside && std::fabs(y) <= inside;
  }
};

Geometry geometryOf(const config::Profile& profile) {
  Geometry g{};
  g.field = &profile.field;
  g.wire = profile.field.size_ft / 2 - profile.field.wire_inset_ft;
  g.inside = g.wire - 1.5;
  g.radius = profile.robot.body_diameter_ft / 2;
  return g;
}

// A random pose in the southern half, inside the wire, clear of the divider.
plant::Pose southernPose(plant::RandomBits& bits, const Geometry& g) {
  while (true) {
    plant::Pose p{uniform(bits, -g.inside, g.inside), uniform(bits, -g.inside, 0),
                  uniform(bits, 0, 360)};
    if (!g.nearDivider(p.x_ft, p.y_ft)) return p;
  }
}

struct Placement {
  plant::Pose a;
  std::optional<plant::Pose> b;
};

Placement samplePlacement(const std::string& family, plant::RandomBits& bits,
                          const config::Profile& profile) {
  const Geometry g = geometryOf(profile);
  Placement s;
  if (family == "stationary") {
    while (true) {
      s.a = southernPose(bits, g);
      const double bearing = uniform(bits, -180, 180), range = uniform(bits, 3, 10);
      const double dir = radians(s.a.heading_deg + bearing);
      const plant::Pose b{s.a.x_ft + range * std::sin(dir), s.a.y_ft + range * std::cos(dir), 0};
      if (g.inBounds(b.x_ft, b.y_ft) && !g.nearDivider(b.x_ft, b.y_ft)) {
        s.b = b;
        return s;
      }
    }
  }
  if (family == "circle") {
    const double r = kCircleRadiusFt;
    const double phase = uniform(bits, 0, 360);
    // Clockwise: heading is the phase plus 90 degrees.
    s.b = plant::Pose{r * std::sin(radians(phase)), r * std::cos(radians(phase)),
                      normalizeHeading(phase + 90)};
    while (true) {
      s.a = southernPose(bits, g);
      if (std::hypot(s.a.x_ft, s.a.y_ft) >= r + 1.5) return s;
    }
  }
  if (family == "head-to-head") {
    // The profile's start poses as a hand puts the robots down: within
    // 0.5 ft of the mark and 15 degrees of the heading. Without it every
    // seed of a noise-free profile would play the very same match.
    auto placed = [&](plant::Pose p) {
      p.x_ft += uniform(bits, -0.5, 0.5);
      p.y_ft += uniform(bits, -0.5, 0.5);
      p.heading_deg = normalizeHeading(p.heading_deg + uniform(bits, -15, 15));
      return p;
    };
    s.a = placed(profile.field.start[0]);
    s.b = placed(profile.field.start[1]);
    return s;
  }
  // edge: 3 ft inside the wire on a random side, heading for that side's
  // wire at an angle of incidence of 20..90 degrees, either way.
  const double ring = g.wire - 3;
  while (true) {
    const int side = static_cast<int>(bits.next() >> 62);  // 0 N, 1 E, 2 S, 3 W
    const double along = uniform(bits, -ring, ring);
    const double incidence = uniform(bits, 20, 90);
    const bool leftward = (bits.next() >> 63) != 0;
    const double normal = 90.0 * side;  // heading straight at the wire
    const double x = side == 1 ? ring : side == 3 ? -ring : along;
    const double y = side == 0 ? ring : side == 2 ? -ring : along;
    if (g.nearDivider(x, y)) continue;
    const double off = 90 - incidence;
    s.a = plant::Pose{x, y, normalizeHeading(normal + (leftward ? -off : off))};
    return s;
  }
}

std::string fileName(const std::string& path) {
  return std::filesystem::path(path).filename().string();
}

}  // namespace

const std::vector<std::string>& benchFamilies() {
  static const std::vector<std::string> f = {"stationary", "circle", "head-to-head", "edge"};
  return f;
}

std::string benchLabel(const BenchConfig& config) {
  if (!config.family.empty()) return config.family;
  return "scenario " + std::filesystem::path(config.scenario->file).stem().string();
}

namespace {

// The set-up every run of one program shares: its robots, arena and
// injections; the runs differ in poses (a family's) and seeds.
scheduler::MatchConfig baseConfig(const BenchConfig& config, const config::Profile& profile,
                                  const std::string& program, const vm::Image& image,
                                  const std::optional<scheduler::RobotSpec>& opponent) {
  scheduler::MatchConfig mc;
  mc.arena = config::makeArenaConfig(profile, opponent ? 2 : 1);
  mc.robots.push_back({"A", program, image});
  if (opponent) mc.robots.push_back(*opponent);
  for (scheduler::RobotSpec& robot : mc.robots) robot.controller = profile.controller;
  if (config.scenario)
    runs::applyScenario(
        *config.scenario,
        config.family.empty() ? runs::ScenarioUse::BenchOwn : runs::ScenarioUse::Bench, profile,
        mc);
  runs::checkRunAgainstRules(
      profile, mc,
      config.scenario
          ? std::array<std::string, 2>{config.scenario->a.hardware, config.scenario->b.hardware}
          : std::array<std::string, 2>{});
  return mc;
}

}  // namespace

uint64_t benchRunSeed(const BenchConfig& config, const std::string& program, int index) {
  return scheduler::streamSeed(
      config.masterSeed,
      fmt::format("{}/{}/{}", benchLabel(config),
                  config.seedKey.empty() ? fileName(program) : config.seedKey, index));
}

CsvRow benchHeader() {
  CsvRow header = {"program",           "run",          "seed",
                   "start_x_ft",        "start_y_ft",   "start_heading_deg",
                   "b_start_x_ft",      "b_start_y_ft", "b_start_heading_deg",
                   "outcome",           "fault",        "winner",
                   "tie_broken_by_coin"};
  for (const auto& name : metricNames()) header.push_back(name);
  // Robot B's, in head-to-head (empty otherwise).
  for (const auto& name : metricNames()) header.push_back("b_" + name);
  return header;
}

nlohmann::json benchSettings(const BenchConfig& c, const config::Profile& profile) {
  return {{"command", "bench"},
          {"programs", c.programs},
          {"family", c.family},
          {"scenario", c.scenario ? nlohmann::json(c.scenario->file) : nlohmann::json(nullptr)},
          {"opponent", c.opponent},
          {"seeds", c.seeds},
          {"seed_key", c.seedKey},
          {"seen_threshold", c.thresholds.seen},
          {"aim_max_diff", c.thresholds.aimMaxDiff},
          {"aim_min_sum", c.thresholds.aimMinSum},
          {"seconds", c.seconds},
          {"master_seed", c.masterSeed},
          {"profile", profile.name},
          {"profile_file", profile.file},
          {"contents", inputContents(benchInputs(c, profile))}};
}

std::vector<std::string> benchInputs(const BenchConfig& c, const config::Profile& profile) {
  std::vector<std::string> paths = c.programs;
  if (!c.opponent.empty()) paths.push_back(c.opponent);
  paths.push_back(profile.file);
  if (profile.course.present) paths.push_back(profile.course.file);
  if (c.scenario) {
    paths.push_back(c.scenario->file);
    for (const auto* r : {&c.scenario->a, &c.scenario->b})
      if (!r->hardware.empty()) paths.push_back(r->hardware);
    if (!c.scenario->program.empty()) paths.push_back(c.scenario->program);
  }
  return paths;
}

namespace {

std::string poseField(double v) { return fmt::format("{}", v); }

CsvRow benchRow(const BenchRun& run) {
  CsvRow row = {run.program,
                std::to_string(run.index),
                std::to_string(run.seed),
                poseField(run.startA.x_ft),
                poseField(run.startA.y_ft),
                poseField(run.startA.heading_deg),
                run.startB ? poseField(run.startB->x_ft) : "",
                run.startB ? poseField(run.startB->y_ft) : "",
                run.startB ? poseField(run.startB->heading_deg) : "",
                run.outcome,
                run.fault,
                run.winner,
                run.winner.empty() ? ""
                : run.coin         ? "1"
                                   : "0"};
  const auto add = [&row](const std::optional<double>& v) {
    row.push_back(v ? fmt::format("{}", *v) : "");
  };
  for (const auto& v : run.metrics.values) add(v);
  for (size_t m = 0; m < metricNames().size(); ++m)
    add(run.metricsB ? run.metricsB->values[m] : std::nullopt);
  return row;
}

// A row of an earlier batch back into its run (resume). Numbers were
// written in their shortest exact form, so they read back exactly.
BenchRun benchRunFromRow(const CsvRow& row) {
  const auto real = [](const std::string& s) { return std::strtod(s.c_str(), nullptr); };
  BenchRun run;
  run.program = row[0];
  run.index = std::stoi(row[1]);
  run.seed = std::stoull(row[2]);
  run.startA = {real(row[3]), real(row[4]), real(row[5])};
  if (!row[6].empty()) run.startB = plant::Pose{real(row[6]), real(row[7]), real(row[8])};
  run.outcome = row[9];
  run.fault = row[10];
  run.winner = row[11];
  run.coin = row[12] == "1";
  const size_t metrics = metricNames().size();
  run.metrics.values.resize(metrics);
  for (size_t m = 0; m < metrics; ++m)
    if (!row[13 + m].empty()) run.metrics.values[m] = real(row[13 + m]);
  // B's metrics exist exactly when the run has a winner (head-to-head).
  if (!run.winner.empty()) {
    run.metricsB.emplace().values.resize(metrics);
    for (size_t m = 0; m < metrics; ++m)
      if (!row.at(13 + metrics + m).empty()) run.metricsB->values[m] = real(row[13 + metrics + m]);
  }
  run.done = true;
  return run;
}

// Both robots' observers on the one hook a match has.
class ObserverPair final : public scheduler::MatchObserver {
 public:
  ObserverPair(scheduler::MatchObserver& a, scheduler::MatchObserver& b) : a_(a), b_(b) {}
  void onEyeRead(int robot, scheduler::Tick t, int channel, int value) override {
    a_.onEyeRead(robot, t, channel, value);
    b_.onEyeRead(robot, t, channel, value);
  }
  void onInterruptAccepted(int robot, scheduler::Tick t, vm::Irq irq) override {
    a_.onInterruptAccepted(robot, t, irq);
    b_.onInterruptAccepted(robot, t, irq);
  }
  void onFrame(int robot, scheduler::Tick t, bool latched) override {
    a_.onFrame(robot, t, latched);
    b_.onFrame(robot, t, latched);
  }
  void onPlantEvent(scheduler::Tick t, const plant::Event& e) override {
    a_.onPlantEvent(t, e);
    b_.onPlantEvent(t, e);
  }

 private:
  scheduler::MatchObserver &a_, &b_;
};

// One line on what faulted in a finished run (every robot that did, then
// the plant), or "".
std::string faultLine(const scheduler::MatchResult& r) {
  std::string line;
  const auto add = [&line](const std::string& what) { line += (line.empty() ? "" : "; ") + what; };
  for (const auto& robot : r.robots)
    if (robot.fault)
      add(fmt::format("robot {} faulted at {:.6f} s, line {}: {}", robot.name, robot.fault->timeS,
                      robot.fault->line, robot.fault->message));
  if (r.plantFault)
    add(fmt::format("the plant's integrator failed at {:.6f} s: {}", r.plantFault->timeS,
                    r.plantFault->message));
  return line;
}

}  // namespace

BenchConfig benchConfig(const runs::RunOptions& o,
                        const std::optional<config::Scenario>& scenario) {
  BenchConfig c;
  c.scenario = scenario;
  c.family = o.family;
  c.seeds = o.seeds.value_or(0);
  std::optional<timebase::Tick> length = o.length;
  if (!length && scenario) length = scenario->length;
  if (length) c.seconds = timebase::secondsFromTicks(*length);  // a whole number of ticks: exact
  c.masterSeed = runs::preferCommandLine(
      o.seed.has_value(), scenario ? scenario->seed : std::nullopt, o.seed.value_or(c.masterSeed));
  c.threads = o.threads.value_or(0);
  c.opponent = o.opponent;
  if (o.seenThreshold) c.thresholds.seen = *o.seenThreshold;
  if (o.aimMaxDiff) c.thresholds.aimMaxDiff = *o.aimMaxDiff;
  if (o.aimMinSum) c.thresholds.aimMinSum = *o.aimMinSum;
  c.median =
      o.median == "midpoint" ? stats::QuantileRule::Midpoint : stats::QuantileRule::FirstBelow;
  return c;
}

void checkBenchConfig(const BenchConfig& config) {
  const auto& families = benchFamilies();
  if (config.family.empty() && !config.scenario)
    throw sinks::UserError("simbot: bench needs --family or --scenario\n");
  if (!config.family.empty() &&
      std::find(families.begin(), families.end(), config.family) == families.end())
    throw sinks::UserError(fmt::format(
        "simbot: unknown family '{}' (stationary, circle, head-to-head, edge)\n", config.family));
  if (config.seeds <= 0) throw sinks::UserError("simbot: --seeds must be positive\n");
  try {  // read by the one grammar already, except from a caller that set it
    timebase::runLengthFromSeconds(config.seconds);
  } catch (const timebase::TimeError& e) {
    throw sinks::UserError(fmt::format("simbot: --seconds: {}\n", e.what()));
  }
  if (config.family == "head-to-head" && config.opponent.empty())
    throw sinks::UserError("simbot: the head-to-head family needs --opponent FILE\n");
  if (config.programs.empty()) throw sinks::UserError("simbot: bench needs at least one program\n");
}

BenchResult runBench(const BenchConfig& config, const config::Profile& profile, const BenchIo& io) {
  checkBenchConfig(config);
  std::optional<scheduler::RobotSpec> opponent;
  if (config.family == "stationary") {
    opponent = runs::beaconSpec({}, false);
  } else if (config.family == "circle") {
    config::PathLeg lap;
    lap.kind = config::PathLeg::Kind::Arc;
    lap.radiusFt = kCircleRadiusFt;
    lap.turnDeg = 360;
    lap.speedFps = kCircleSpeedFps;
    opponent = runs::beaconSpec(runs::driveLegs("(circle family)", {lap}, profile.robot), true);
  } else if (config.family == "head-to-head") {
    opponent =
        scheduler::RobotSpec{"B", config.opponent, runs::compileProgramFile(config.opponent)};
  }
  std::vector<scheduler::MatchConfig> bases;
  for (const auto& p : config.programs)
    bases.push_back(baseConfig(config, profile, p, runs::compileProgramFile(p), opponent));

  BenchResult result;
  result.config = config;
  const size_t seeds = static_cast<size_t>(config.seeds);
  result.runs.resize(config.programs.size() * seeds);
  // Runs an earlier, interrupted batch finished (--resume): each must be
  // one of this bench's runs (its program, index and seed), once.
  if (io.table) {
    for (const PreviousRow& row : io.table->previous()) {
      const std::string where = io.table->where(row.line);
      BenchRun run;
      try {
        run = benchRunFromRow(row.fields);
      } catch (const std::exception&) {
        throw sinks::UserError(fmt::format("simbot: --resume: {}: a malformed row\n", where));
      }
      const auto p = std::find(config.programs.begin(), config.programs.end(), run.program);
      if (p == config.programs.end() || run.index < 0 || run.index >= config.seeds)
        throw sinks::UserError(
            fmt::format("simbot: --resume: {}: run {} of '{}' is not one of this bench's runs\n",
                        where, run.index, run.program));
      if (const uint64_t seed = benchRunSeed(config, run.program, run.index); run.seed != seed)
        throw sinks::UserError(fmt::format(
            "simbot: --resume: {}: run {} of '{}' has seed {}, but this bench's run {} has seed "
            "{} (a row from another batch)\n",
            where, run.index, run.program, run.seed, run.index, seed));
      BenchRun& slot = result.runs[static_cast<size_t>(p - config.programs.begin()) * seeds +
                                   static_cast<size_t>(run.index)];
      if (slot.done)
        throw sinks::UserError(fmt::format("simbot: --resume: {}: run {} of '{}' is there twice\n",
                                           where, run.index, run.program));
      slot = std::move(run);
    }
    // Inputs compiled, rows checked: only now does the folder change.
    io.table->begin();
  }
  std::vector<size_t> todo;
  for (size_t j = 0; j < result.runs.size(); ++j)
    if (!result.runs[j].done) todo.push_back(j);
  const scheduler::Tick endTick = timebase::ticksFromSeconds(config.seconds);
  auto job = [&](size_t k) {
    const size_t j = todo[k];
    const size_t p = j / seeds;
    BenchRun& run = result.runs[j];
    run.program = config.programs[p];
    run.index = static_cast<int>(j % seeds);
    run.seed = benchRunSeed(config, run.program, run.index);
    scheduler::MatchConfig mc = bases[p];
    if (!config.family.empty()) {
      plant::SplitMix64 bits(scheduler::streamSeed(run.seed, "scenario"));
      const Placement placement = samplePlacement(config.family, bits, profile);
      mc.arena.robots[0].start = placement.a;
      if (placement.b) mc.arena.robots[1].start = *placement.b;
    }
    run.startA = mc.arena.robots[0].start;
    if (mc.arena.robots.size() > 1) run.startB = mc.arena.robots[1].start;
    mc.endTick = endTick;
    mc.seed = run.seed;
    mc.stop = io.stop;
    // Robot B is measured when it is a program (head-to-head), on the
    // same thresholds.
    const bool measureB = config.family == "head-to-head";
    MetricsObserver observer(0, config.thresholds), observerB(1, config.thresholds);
    ObserverPair both(observer, observerB);
    mc.observer = measureB ? static_cast<scheduler::MatchObserver*>(&both) : &observer;
    try {
      const scheduler::MatchResult r = scheduler::runMatch(mc);
      observer.finish(r.endTick);
      run.metrics = collectMetrics(observer, r.robots[0]);
      if (measureB) {
        observerB.finish(r.endTick);
        run.metricsB = collectMetrics(observerB, r.robots[1]);
        run.winner = r.winner;
        run.coin = r.tieBrokenByCoin;
      }
      run.fault = faultLine(r);
      run.outcome = run.fault.empty() ? "ok" : "fault";
      run.warnings = r.warnings;
    } catch (const scheduler::Stopped&) {
      return;  // abandoned: not done, run again by --resume
    } catch (const std::exception& e) {
      // A bug in simbot: recorded for this run (the starts replay it with
      // a scenario), and the others go on.
      std::string poses;
      for (const auto& robot : mc.arena.robots)
        poses += fmt::format(" ({}, {}, {} deg)", robot.start.x_ft, robot.start.y_ft,
                             robot.start.heading_deg);
      run.outcome = "error";
      run.fault = fmt::format("internal error (starts{}): {}", poses, e.what());
      run.metrics.values.assign(metricNames().size(), std::nullopt);
    }
    run.done = true;
    if (io.table) io.table->append(benchRow(run));
  };
  parallelFor(todo.size(), config.threads, job, "bench " + benchLabel(config), config.progress,
              io.stop);
  result.stopped = std::any_of(result.runs.begin(), result.runs.end(),
                               [](const BenchRun& r) { return !r.done; });
  return result;
}

namespace {

std::vector<CsvRow> doneRows(const BenchResult& result) {
  std::vector<CsvRow> rows;
  for (const auto& run : result.runs)
    if (run.done) rows.push_back(benchRow(run));
  return rows;
}

}  // namespace

std::string runsCsv(const BenchResult& result) {
  std::string out = csvRecord(benchHeader());
  for (const auto& row : doneRows(result)) out += csvRecord(row);
  return out;
}

std::string benchFaults(const BenchResult& result, size_t most) {
  std::string out;
  size_t shown = 0, all = 0;
  for (const auto& run : result.runs) {
    if (!run.done || run.outcome == "ok") continue;
    if (shown++ < most)
      out += fmt::format("simbot: bench: run {} of {} (seed {}): {}{}\n", run.index, run.program,
                         run.seed, run.outcome == "error" ? "error: " : "", run.fault);
    ++all;
  }
  if (all > most)
    out += fmt::format("simbot: bench: ... {} more (runs.csv lists them)\n", all - most);
  return out;
}

std::string benchWarnings(const BenchResult& result, size_t most) {
  std::string out;
  size_t shown = 0, all = 0;
  for (const auto& run : result.runs) {
    for (const auto& w : run.warnings) {
      if (shown++ < most)
        out += fmt::format("simbot: warning: bench: run {} of {} (seed {}): {}\n", run.index,
                           run.program, run.seed, w);
      ++all;
    }
  }
  if (all > most) out += fmt::format("simbot: warning: bench: ... {} more\n", all - most);
  return out;
}

void writeBenchOutputs(const BenchResult& result, RunTable& table) {
  table.rewrite(doneRows(result));
  const std::filesystem::path dir = table.dir();
  writeFileAtomically((dir / "summary.json").string(),
                      sinks::dumpJson(summaryJson(result), 2) + "\n");
  writeFileAtomically((dir / "summary.md").string(), summaryMarkdown(result));
}

}  // namespace simbot::batch
