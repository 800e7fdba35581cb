// simbot bench (bench.h): scenario sampling, the parallel runs, the outputs.
#include "tools/bench.h"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "scheduler/match.h"
#include "tools/json_text.h"
#include "tools/runner.h"

namespace simbot::tools {

namespace {

using scheduler::kTicksPerSecond;

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

Geometry geometryOf(const plant::Profile& profile) {
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
                          const plant::Profile& profile) {
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

std::string number(const std::optional<double>& v, const char* format = "{:.4g}") {
  return v ? fmt::format(fmt::runtime(format), *v) : "";
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
scheduler::MatchConfig baseConfig(const BenchConfig& config, const plant::Profile& profile,
                                  const std::string& program, const vm::Image& image,
                                  const std::optional<scheduler::RobotSpec>& opponent) {
  scheduler::MatchConfig mc;
  mc.arena = plant::makeArenaConfig(profile, opponent ? 2 : 1);
  mc.robots.push_back({"A", program, image});
  if (opponent) mc.robots.push_back(*opponent);
  if (config.scenario)
    applyScenario(*config.scenario,
                  config.family.empty() ? ScenarioUse::BenchOwn : ScenarioUse::Bench, profile, mc);
  return mc;
}

}  // namespace

BenchResult runBench(const BenchConfig& config, const plant::Profile& profile) {
  const auto& families = benchFamilies();
  if (config.family.empty() && !config.scenario)
    throw ToolError("simbot: bench needs --family or --scenario\n");
  if (!config.family.empty() &&
      std::find(families.begin(), families.end(), config.family) == families.end())
    throw ToolError(fmt::format(
        "simbot: unknown family '{}' (stationary, circle, head-to-head, edge)\n", config.family));
  if (config.seeds <= 0) throw ToolError("simbot: --seeds must be positive\n");
  if (!(config.seconds > 0) || config.seconds > 1e6)
    throw ToolError(fmt::format("simbot: --seconds must be in (0, 1e6], got {}\n", config.seconds));
  if (config.family == "head-to-head" && config.opponent.empty())
    throw ToolError("simbot: the head-to-head family needs --opponent FILE\n");
  if (config.programs.empty()) throw ToolError("simbot: bench needs at least one program\n");

  std::optional<scheduler::RobotSpec> opponent;
  if (config.family == "stationary") {
    opponent = beaconSpec({}, false);
  } else if (config.family == "circle") {
    PathLeg lap;
    lap.kind = PathLeg::Kind::Arc;
    lap.radiusFt = kCircleRadiusFt;
    lap.turnDeg = 360;
    lap.speedFps = kCircleSpeedFps;
    opponent = beaconSpec(driveLegs("(circle family)", {lap}, profile.robot), true);
  } else if (config.family == "head-to-head") {
    opponent = scheduler::RobotSpec{"B", config.opponent, compileProgramFile(config.opponent)};
  }
  std::vector<scheduler::MatchConfig> bases;
  for (const auto& p : config.programs)
    bases.push_back(baseConfig(config, profile, p, compileProgramFile(p), opponent));

  BenchResult result;
  result.config = config;
  const size_t seeds = static_cast<size_t>(config.seeds);
  result.runs.resize(config.programs.size() * seeds);
  const scheduler::Tick endTick =
      static_cast<scheduler::Tick>(std::llround(config.seconds * kTicksPerSecond));
  const std::string label = benchLabel(config);
  auto job = [&](size_t j) {
    const size_t p = j / seeds;
    BenchRun& run = result.runs[j];
    run.program = config.programs[p];
    run.index = static_cast<int>(j % seeds);
    run.seed = scheduler::streamSeed(
        config.masterSeed, fmt::format("{}/{}/{}", label, fileName(run.program), run.index));
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
    scheduler::MetricsObserver observer(0);
    mc.observer = &observer;
    try {
      const scheduler::MatchResult r = scheduler::runMatch(mc);
      observer.finish(r.endTick);
      run.metrics = scheduler::collectMetrics(observer, r.robots[0]);
    } catch (const std::exception& e) {
      // Name the run, so that it can be replayed as a match with a scenario.
      std::string poses;
      for (const auto& robot : mc.arena.robots)
        poses += fmt::format(" ({}, {}, {} deg)", robot.start.x_ft, robot.start.y_ft,
                             robot.start.heading_deg);
      throw ToolError(
          fmt::format("simbot: internal error in run {} of {} (seed {}, starts{}): {}\n", run.index,
                      run.program, run.seed, poses, e.what()));
    }
  };
  parallelFor(result.runs.size(), config.threads, job, "bench " + benchLabel(config),
              config.progress);
  return result;
}

std::string runsCsv(const BenchResult& result) {
  std::string out =
      "program,run,seed,start_x_ft,start_y_ft,start_heading_deg,b_start_x_ft,b_start_y_ft,"
      "b_start_heading_deg";
  for (const auto& name : scheduler::metricNames()) out += "," + name;
  out += '\n';
  for (const auto& run : result.runs) {
    out += fmt::format("{},{},{},{},{},{}", run.program, run.index, run.seed, run.startA.x_ft,
                       run.startA.y_ft, run.startA.heading_deg);
    if (run.startB)
      out += fmt::format(",{},{},{}", run.startB->x_ft, run.startB->y_ft, run.startB->heading_deg);
    else
      out += ",,,";
    for (const auto& v : run.metrics.values) out += "," + (v ? fmt::format("{}", *v) : "");
    out += '\n';
  }
  return out;
}

namespace {

std::vector<std::vector<scheduler::MetricSummary>> summaries(const BenchResult& result) {
  std::vector<std::vector<scheduler::MetricSummary>> all;
  const size_t seeds = static_cast<size_t>(result.config.seeds);
  const auto& names = scheduler::metricNames();
  for (size_t p = 0; p < result.config.programs.size(); ++p) {
    std::vector<scheduler::MetricSummary> per;
    for (size_t m = 0; m < names.size(); ++m) {
      std::vector<std::optional<double>> values;
      for (size_t i = 0; i < seeds; ++i)
        values.push_back(result.runs[p * seeds + i].metrics.values[m]);
      per.push_back(scheduler::summarize(names[m], values));
    }
    all.push_back(std::move(per));
  }
  return all;
}

nlohmann::json optionalJson(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
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
      {"programs", nlohmann::json::array()}};
  const auto all = summaries(result);
  for (size_t p = 0; p < c.programs.size(); ++p) {
    nlohmann::json metrics = nlohmann::json::array();
    for (const auto& s : all[p])
      metrics.push_back({{"metric", s.name},
                         {"reached", s.reached},
                         {"censored", s.censored},
                         {"mean", optionalJson(s.mean)},
                         {"median", optionalJson(s.median)},
                         {"p90", optionalJson(s.p90)},
                         {"ci95_low", optionalJson(s.ciLow)},
                         {"ci95_high", optionalJson(s.ciHigh)}});
    j["programs"].push_back({{"program", c.programs[p]}, {"metrics", metrics}});
  }
  return j;
}

std::string summaryMarkdown(const BenchResult& result) {
  const auto& c = result.config;
  std::string out;
  const auto all = summaries(result);
  for (size_t p = 0; p < c.programs.size(); ++p) {
    out += fmt::format("### {}: {}, {} seeds x {} s\n\n", c.programs[p],
                       c.family.empty() ? benchLabel(c) : "family " + c.family, c.seeds, c.seconds);
    out += "| metric | n reached | mean | median | p90 | 95% CI of mean | censored |\n";
    out += "|---|---:|---:|---:|---:|---|---:|\n";
    for (const auto& s : all[p]) {
      const std::string ci =
          s.ciLow ? fmt::format("[{:.4g}, {:.4g}]", *s.ciLow, *s.ciHigh) : std::string("");
      out += fmt::format("| {} | {} | {} | {} | {} | {} | {} |\n", s.name, s.reached,
                         number(s.mean), number(s.median), number(s.p90), ci, s.censored);
    }
    out += '\n';
  }
  return out;
}

void writeBenchOutputs(const BenchResult& result, const std::string& dir) {
  std::filesystem::create_directories(dir);
  auto write = [&](const std::string& name, const std::string& text) {
    const auto path = std::filesystem::path(dir) / name;
    std::ofstream out(path, std::ios::binary);
    if (!out) throw ToolError(fmt::format("simbot: cannot write '{}'\n", path.string()));
    out << text;
  };
  write("runs.csv", runsCsv(result));
  write("summary.json", dumpJson(summaryJson(result), 2) + "\n");
  write("summary.md", summaryMarkdown(result));
}

}  // namespace simbot::tools
