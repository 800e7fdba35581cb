// VM dispatch speed: bytecode instructions per second of wall time on
// loop-heavy programs (reported, never asserted). Run:
//   build/bin/vm_bench --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <stdexcept>

#include "compiler/compiler.h"
#include "vm/vm.h"

namespace {

using namespace simbot;

class NullBus : public vm::Bus {
 public:
  void out(vm::Tick, uint16_t, uint8_t) override {}
  uint8_t in(vm::Tick, uint16_t) override { return 0xFF; }
  int adSample(vm::Tick, int) override { return 16; }
};

// Nested loops with 16-bit arithmetic, array indexing and a call.
const char* kLoops = R"(
int i, j, s;
int a[64];
int f(x) int x; { return x + 1; }
main()
{
    for (i = 0; i < 200; i++)
        for (j = 0; j < 64; j++) {
            a[j] = a[j] + i * j;
            s = s ^ a[j];
            if (j == 63) s = f(s);
        }
}
)";

// ICEMAN-style delay loops: static int and unsigned long counters.
const char* kDelays = R"(
int z;
unsigned long int count;
main()
{
    int k;
    for (k = 0; k < 20; k++) {
        for (z = 0; z < 700; z++);
        for (count = 0; count < 1000; count++);
    }
}
)";

void runProgram(benchmark::State& state, const char* source, bool debug) {
  compiler::Options options;
  options.debug = debug;
  auto result = compiler::compile(source, "bench.dc", options);
  if (!result.image) throw std::runtime_error(result.errors[0].format());
  const auto costs = vm::makeCostTable(vm::calibratedKnobs());
  NullBus bus;
  uint64_t instructions = 0;
  vm::Tick ticks = 0;
  for (auto _ : state) {
    vm::Vm v(*result.image, bus, costs);
    // Stop where main returns to the start-up stub (CALL main; POP; HALT).
    v.setBreakpoint(result.image->entry + vm::instructionSize(vm::Op::CALL));
    if (v.run(INT64_MAX / 2) != vm::Stop::Breakpoint) state.SkipWithError("main did not return");
    instructions += v.stats().instructions;
    ticks = v.now();
  }
  state.counters["insns/s"] =
      benchmark::Counter(static_cast<double>(instructions), benchmark::Counter::kIsRate);
  state.counters["sim_s/run"] = static_cast<double>(ticks) / vm::kTicksPerSecond;
}

void BM_Loops(benchmark::State& s) { runProgram(s, kLoops, true); }
void BM_LoopsNodebug(benchmark::State& s) { runProgram(s, kLoops, false); }
void BM_DelayLoops(benchmark::State& s) { runProgram(s, kDelays, true); }
BENCHMARK(BM_Loops)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LoopsNodebug)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DelayLoops)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
