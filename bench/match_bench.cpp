// Whole-match speed: wall time of the 180-s ICEMAN vs Figure 9.2 match and
// its real-time factor, with the integrator statistics. Reported, never
// asserted. Run: build/bin/match_bench --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <stdexcept>

#include "compiler/compiler.h"
#include "plant/plant.h"
#include "scheduler/match.h"

namespace {

using namespace simbot;

vm::Image compileFile(const std::string& path) {
  auto r = compiler::compileFile(path);
  if (!r.image) throw std::runtime_error(r.errors[0].format());
  return std::move(*r.image);
}

void BM_IcemanVsFig92(benchmark::State& state, const char* profile) {
  const std::string a = SIMBOT_SHARED_DIR "/programs/iceman.dc";
  const std::string b = SIMBOT_SHARED_DIR "/programs/fig92.dc";
  scheduler::MatchConfig config;
  config.arena = plant::makeArenaConfig(
      plant::loadProfile(std::string(SIMBOT_SOURCE_DIR "/profiles/") + profile + ".toml"), 2);
  config.robots = {{"A", a, compileFile(a)}, {"B", b, compileFile(b)}};
  config.endTick = 180 * scheduler::kTicksPerSecond;
  scheduler::MatchResult last;
  for (auto _ : state) last = scheduler::runMatch(config);
  const double simSeconds = static_cast<double>(last.endTick) / scheduler::kTicksPerSecond;
  state.counters["sim_s"] = simSeconds;
  state.counters["realtime_x"] = benchmark::Counter(
      simSeconds * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["steps"] = static_cast<double>(last.integrator.steps);
  state.counters["rhs_evals"] = static_cast<double>(last.integrator.rhs_evals);
  state.counters["reinits"] = static_cast<double>(last.integrator.reinits);
  state.counters["roots"] = static_cast<double>(last.integrator.roots);
  state.counters["rounds"] = static_cast<double>(last.rounds);
}

BENCHMARK_CAPTURE(BM_IcemanVsFig92, default, "default")->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK_CAPTURE(BM_IcemanVsFig92, thesis, "thesis-1997")->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
