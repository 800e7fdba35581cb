#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/) with clang, ASan and UBSan into
# build-fuzz/, and runs each for SECONDS (default 60): the compiler, the VM
# (through a solo run), the TOML loaders, the debugger's expressions, its
# command line and simbot dap's server, each starting from the shipped programs,
# configurations or debugger scripts and the saved regressions (for dap: DAP
# sessions, well and badly formed). A crash, a leak, a timeout or undefined
# behaviour fails the script; the input is left in build-fuzz/fuzzing/ (copy
# it to fuzz/regressions/TARGET/ once fixed).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
# Debug (-O0), and only the targets: with UBSan, clang's optimiser spends
# 420-475 s on vm/vm.cpp alone at -O1 or -O2 (41 s at -O0); the campaigns
# are short, so build time outweighs executions per second.
#
# This build is also the suite's build against SUNDIALS 7 (Debian 13's,
# which scripts/setup.sh unpacks into build-sundials7/prefix; the other
# builds use Debian 12's 6.4): plant/arkode.cpp's 7.x branches compiled
# with warnings as errors (so no deprecated call), the plant's tests run
# on it under ASan and UBSan, and the targets fuzz a plant built on it.
# Without that prefix (setup.sh not run) it builds against the system's.
sundials=()
if [ -e build-sundials7/prefix/.unpacked ]; then
  sundials=("-DCMAKE_PREFIX_PATH=$PWD/build-sundials7/prefix/usr")
fi
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=Debug -DSIMBOT_FUZZ=ON \
  -DSIMBOT_BENCHMARKS=OFF -DSIMBOT_WERROR=ON "${sundials[@]}" > build-fuzz.configure.log 2>&1 ||
  { cat build-fuzz.configure.log; exit 1; }
cmake --build build-fuzz --parallel "$(nproc)" --target fuzz_compiler fuzz_vm fuzz_config fuzz_inspect \
  fuzz_console fuzz_dap plant_test
if [ ${#sundials[@]} -gt 0 ]; then
  grep -q '^-- SUNDIALS 7\.' build-fuzz.configure.log ||
    { grep SUNDIALS build-fuzz.configure.log; echo "fuzz: build-fuzz did not find SUNDIALS 7"; exit 1; }
fi
# The plant's tests in two shards at once (one test binary would leave a
# core idle for its 43 s).
shards=()
for shard in 0 1; do
  GTEST_TOTAL_SHARDS=2 GTEST_SHARD_INDEX=$shard ASAN_OPTIONS=detect_leaks=1 \
    build-fuzz/bin/plant_test > "build-fuzz/plant_test.$shard.log" 2>&1 & shards+=($!)
done
for shard in 0 1; do
  wait "${shards[$shard]}" ||
    { cat "build-fuzz/plant_test.$shard.log"; echo "fuzz: plant_test failed (shard $shard)"; exit 1; }
done
work=build-fuzz/fuzzing
mkdir -p "$work"
shared=../shared/programs
run() {  # TARGET SEEDS...
  local target=$1
  shift
  mkdir -p "$work/corpus-$target"
  local dict=()
  case $target in
    config) ;;
    inspect | console) dict=(-dict=fuzz/inspect.dict) ;;
    dap) dict=(-dict=fuzz/dap.dict) ;;
    *) dict=(-dict=fuzz/dynamic_c.dict) ;;
  esac
  build-fuzz/bin/fuzz_"$target" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -max_len=8192 -print_final_stats=1 "${dict[@]}" -artifact_prefix="$work/$target-" \
    "$work/corpus-$target" fuzz/regressions/"$target" "$@" > "$work/$target.log" 2>&1
}
status=0
run compiler programs tests/programs tests/errors "$shared" & compiler=$!
run vm programs tests/programs "$shared" & vm=$!
wait "$compiler" || { status=1; echo "fuzz: the compiler target failed (log: $work/compiler.log)"; }
wait "$vm" || { status=1; echo "fuzz: the vm target failed (log: $work/vm.log)"; }
run config profiles profiles/hardware scenarios & config=$!
run inspect tests/debug & inspect=$!
wait "$config" || { status=1; echo "fuzz: the config target failed (log: $work/config.log)"; }
wait "$inspect" || { status=1; echo "fuzz: the inspect target failed (log: $work/inspect.log)"; }
run console tests/debug & console=$!
run dap & dap=$!
wait "$console" || { status=1; echo "fuzz: the console target failed (log: $work/console.log)"; }
wait "$dap" || { status=1; echo "fuzz: the dap target failed (log: $work/dap.log)"; }
for target in compiler vm config inspect console dap; do
  grep -E "stat::number_of_executed_units|stat::average_exec_per_sec" "$work/$target.log" |
    tr '\n' ' ' | sed "s/^/fuzz $target: /"
  echo
done
exit $status
