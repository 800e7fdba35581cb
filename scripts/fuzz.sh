#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/) with clang, ASan and UBSan into
# build-fuzz/ (scripts/build_fuzz.sh), and runs each for SECONDS (default 60): the compiler, the VM
# (through a solo run), the TOML loaders, the debugger's expressions, its
# command line and simbot dap's server, each starting from the shipped programs,
# configurations or debugger scripts and the saved regressions (for dap: DAP
# sessions, well and badly formed). A crash, a leak, a timeout or undefined
# behaviour fails the script; the input is left in build-fuzz/fuzzing/ (copy
# it to fuzz/regressions/TARGET/ once fixed).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
./scripts/build_fuzz.sh fuzz_compiler fuzz_vm fuzz_config fuzz_inspect fuzz_console fuzz_dap
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
