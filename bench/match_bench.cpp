// Whole-match speed: wall time of the 180-s ICEMAN vs Figure 9.2 match and
// its real-time factor, under the default and thesis-1997 profiles, with
// fast-forward of delay loops on (ff) and off (noff); with the VM
// instructions each robot ran (dispatched and fast-forwarded) and the
// integrator statistics. Reported, never asserted. Run:
//   build/bin/match_bench --benchmark_counters_tabular=true
// Counters (rates are per wall second): sim_s (simulated seconds),
// realtime_x (simulated seconds per wall second), vm_instr (instructions
// run, both robots, fast-forwarded ones included), vm_dispatched (those
// dispatched one by one), vm_ff (those fast-forward applied without
// dispatch), Minstr (dispatched instructions per wall second, millions),
// steps, rhs_evals, reinits and roots (the plant's integrator), rounds (the
// scheduler's), and where the wall time of one more match, run after the
// timed ones, went (MatchConfig::timeParts, steady clock; the timed runs
// read no clock, as a user's do): vm_s (the VMs running), plant_s
// (integration, plant inputs, eye readings, including those a VM's A/D read
// makes), sched_s (the rest: round loop, queue, bookkeeping), which add up
// to that run's time, its clock reads included (not counting compiling the
// programs).
// BM_Snapshots: what a debugger's snapshot of that match costs (one every
// half second of 180 s, all kept, as simbot debug keeps them): the heap
// bytes each snapshot holds (glibc's mallinfo2, in use after less before
// each MatchRun::snapshot call), and the wall time of taking them.
#include <benchmark/benchmark.h>
#include <malloc.h>

#include <stdexcept>
#include <vector>

#include "compiler/compiler.h"
#include "config/config.h"
#include "plant/plant.h"
#include "scheduler/match.h"

namespace {

using namespace simbot;

vm::Image compileFile(const std::string& path) {
  auto r = compiler::compileFile(path);
  if (!r.image) throw std::runtime_error(r.errors[0].format());
  return std::move(*r.image);
}

void BM_IcemanVsFig92(benchmark::State& state, const char* profile, bool fastForward) {
  const std::string a = SIMBOT_SHARED_DIR "/programs/iceman.dc";
  const std::string b = SIMBOT_SHARED_DIR "/programs/fig92.dc";
  scheduler::MatchConfig config;
  config.arena = config::makeArenaConfig(
      config::loadProfile(std::string(SIMBOT_SOURCE_DIR "/profiles/") + profile + ".toml"), 2);
  config.robots = {{"A", a, compileFile(a)}, {"B", b, compileFile(b)}};
  config.endTick = 180 * scheduler::kTicksPerSecond;
  config.knobs.fastForward = fastForward;
  scheduler::MatchResult last;
  for (auto _ : state) last = scheduler::runMatch(config);
  // The parts come from one more run, not timed: their clock reads cost
  // about 5 ms of the match (46 ms against 41, docs/benchmarks.md).
  config.timeParts = true;
  const scheduler::MatchResult withParts = scheduler::runMatch(config);
  const double simSeconds = static_cast<double>(last.endTick) / scheduler::kTicksPerSecond;
  const double iterations = static_cast<double>(state.iterations());
  uint64_t instructions = 0, fastForwarded = 0;
  for (const auto& robot : last.robots) {
    instructions += robot.vmInstructions;
    fastForwarded += robot.vmFastForwarded;
  }
  const double dispatched = static_cast<double>(instructions - fastForwarded);
  state.counters["sim_s"] = simSeconds;
  state.counters["realtime_x"] =
      benchmark::Counter(simSeconds * iterations, benchmark::Counter::kIsRate);
  state.counters["vm_instr"] = static_cast<double>(instructions);
  state.counters["vm_dispatched"] = dispatched;
  state.counters["vm_ff"] = static_cast<double>(fastForwarded);
  state.counters["Minstr"] =
      benchmark::Counter(dispatched * iterations / 1e6, benchmark::Counter::kIsRate);
  state.counters["steps"] = static_cast<double>(last.integrator.steps);
  state.counters["rhs_evals"] = static_cast<double>(last.integrator.rhs_evals);
  state.counters["reinits"] = static_cast<double>(last.integrator.reinits);
  state.counters["roots"] = static_cast<double>(last.integrator.roots);
  state.counters["rounds"] = static_cast<double>(last.rounds);
  state.counters["vm_s"] = withParts.parts.vm_s;
  state.counters["plant_s"] = withParts.parts.plant_s;
  state.counters["sched_s"] = withParts.parts.scheduler_s;
}

BENCHMARK_CAPTURE(BM_IcemanVsFig92, default_ff, "default", true)
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_IcemanVsFig92, default_noff, "default", false)
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_IcemanVsFig92, thesis_ff, "thesis-1997", true)
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_IcemanVsFig92, thesis_noff, "thesis-1997", false)
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(1);

void BM_Snapshots(benchmark::State& state) {
  const std::string a = SIMBOT_SHARED_DIR "/programs/iceman.dc";
  const std::string b = SIMBOT_SHARED_DIR "/programs/fig92.dc";
  scheduler::MatchConfig config;
  config.arena = config::makeArenaConfig(
      config::loadProfile(std::string(SIMBOT_SOURCE_DIR "/profiles/default.toml")), 2);
  config.robots = {{"A", a, compileFile(a)}, {"B", b, compileFile(b)}};
  config.endTick = 180 * scheduler::kTicksPerSecond;
  config.snapshots = true;
  constexpr scheduler::Tick kInterval = scheduler::kTicksPerSecond / 2;
  double bytes = 0, count = 0;
  for (auto _ : state) {
    state.PauseTiming();
    scheduler::MatchRun run(config);
    std::vector<scheduler::MatchRun::Snapshot> kept;
    kept.reserve(512);
    bytes = 0;
    for (scheduler::Tick t = 0; run.runUntil(t); t += kInterval) {
      const size_t before = mallinfo2().uordblks;
      state.ResumeTiming();
      kept.push_back(run.snapshot());
      state.PauseTiming();
      bytes += static_cast<double>(mallinfo2().uordblks) - static_cast<double>(before);
    }
    count = static_cast<double>(kept.size());
    state.ResumeTiming();
  }
  state.counters["snapshots"] = count;
  state.counters["bytes_per_snapshot"] = bytes / count;
}

BENCHMARK(BM_Snapshots)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
