#!/usr/bin/env bash
# Sets everything up and runs the whole test suite: the layout check
# (clang-format, no source file over 1,000 lines), the normal build with warnings as errors, the plant
# built against SUNDIALS 7 and its tests, the same suite
# built with AddressSanitizer and UndefinedBehaviorSanitizer, the threaded
# bench and tournament built with ThreadSanitizer, and a short campaign
# (20 s) of each libFuzzer target.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
jobs=$(nproc)
# Each stage's wall time and CPU time (user + system of every process it
# waited for: what a loaded machine does not inflate), printed as it ends
# and again at the end, so that the suite's 30-minute budget can be kept.
stages=()
cpu() { awk -v hz="$(getconf CLK_TCK)" '{ printf "%d", ($16 + $17) / hz }' /proc/$$/stat; }
phase() {
  local now
  now=$(cpu)
  stages+=("$(printf '%5d s wall %5d s CPU  %s' $((SECONDS - mark)) $((now - cpu_mark)) "$1")")
  echo "test.sh: ${stages[-1]}"
  mark=$SECONDS
  cpu_mark=$now
}
mark=$SECONDS
cpu_mark=$(cpu)
mapfile -t sources < <(find compiler vm board plant scheduler config trace sinks reports runs batch cli tests bench fuzz \
  debug inspect files stats timebase python \
  -path tests/browser/node_modules -prune -o \( -name '*.cpp' -o -name '*.h' \) -print | sort)
clang-format --dry-run --Werror "${sources[@]}"
# No source file over 1,000 lines (each one over is named with its count).
./scripts/line_limit.sh
# SUNDIALS is the plant's adapter's alone (docs/plant.md): no other file
# includes its headers.
sundials_users=$(grep -lE '#include <(arkode|cvode|cvodes|ida|idas|kinsol|nvector|sundials|sunmatrix|sunlinsol|sunnonlinsol)/' \
  "${sources[@]}" || true)
[ "$sundials_users" = plant/arkode.cpp ] ||
  { echo "test.sh: SUNDIALS' headers included by:" $sundials_users "(only plant/arkode.cpp may)"; exit 1; }
phase "set-up and layout check"
# Line tables only (-g1) here too: a test's failure still gives FILE:LINE,
# and the build takes about a fifth less (scheduler/match.cpp 17.9 s at
# -O2 -g, 13.9 s at -O2 -g1; tests/match_test.cpp 31.5 s, 21.1 s). The
# optimisation is the one users run (-O2).
./scripts/build.sh build -DSIMBOT_WERROR=ON -DSIMBOT_CLI_ONLY=OFF "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG"
phase "normal build"
ctest --test-dir build --output-on-failure --parallel "$jobs" --timeout 900
phase "normal tests"
# The sanitizer builds keep line tables only (-g1): their reports still give
# FILE:LINE, and compiling takes less time (ThreadSanitizer at -O1 -g1: 14 s
# for reports/explain.cpp where -O2 -g takes 22).
./scripts/build.sh build-asan -DSIMBOT_SANITIZE=ON -DSIMBOT_BENCHMARKS=OFF -DCMAKE_BUILD_TYPE=Debug \
  -DCMAKE_CXX_FLAGS_DEBUG=-g1 -DSIMBOT_WERROR=ON
phase "sanitizer build"
# Left out under the sanitizers, to keep the suite under 30 minutes: checks
# that repeat whole CLI matches for determinism or variation (cli.match.*,
# cli.variation: 39 s under ASan), run every program with and without
# fast-forward (fast_forward.identical: 31 s), explain the 180-s match again
# from its JSONL file (Explain.FromTheJsonlFile: 76 s), kill and resume
# batch runs from Python, drive the replay page in Chromium, compare
# numbers with statsmodels, or run every superinstruction of the VM against
# its unfused run at each of 3,000 horizons and interrupt ticks (each a copy
# of two VMs: 2 s each in the normal build), or calibrate ICEMAN's delay
# loops against the thesis's ten seconds (IcemanTiming.CalibratedKnobs...:
# 95 s under ASan) and play costate_hunter against ICEMAN for 180 s
# (Match.CostateHunter...: 92 s; costate_test covers costatements under the
# sanitizers), or copy two matches after every kind of event and run each
# copy to the end (MatchCopy.AfterEveryKindOfEvent... and
# MatchCopy.AfterTheTimersInterrupt...: about 200 s under ASan; the copy
# code runs there in MatchCopy.AfterAFaultAndAReload and MatchSnapshot.*). The code
# they run is exercised under the sanitizers by the gtest suites (Match.*,
# Stats.*, FastForward.*, Trace.* reading JSONL back, the other Explain.*,
# the other VmSuperinstruction.* checks: faulting pieces, the stack guard, PRT0
# ticks, breakpoints) and hostile.inputs (which also writes replay pages),
# and the checks themselves ran in the normal build above.
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build-asan --output-on-failure --parallel "$jobs" --timeout 1800 \
  -E '^(cli\.match\.deterministic|cli\.variation|fast_forward\.identical|Explain\.FromTheJsonlFile|batch\.kill_and_resume|browser\.viewer|stats\.oracle|VmSuperinstruction\.EveryHorizonStopsWhereTheUnfusedRunStops|VmSuperinstruction\.AnInterruptRequestedAtAnyTickIsAcceptedWhereItIsUnfused|IcemanTiming\.CalibratedKnobsAreTheHardwareSettingNearestTenSeconds|Match\.CostateHunterPlaysIcemanAndLatchesFrames|MatchCopy\.AfterEveryKindOfEventInIcemanVsFig92|MatchCopy\.AfterTheTimersInterruptInCostateHunterVsIceman)$'
phase "sanitizer tests"
# ThreadSanitizer: only the suite that runs work on several threads.
cmake -S . -B build-tsan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" -DSIMBOT_TSAN=ON \
  -DSIMBOT_BENCHMARKS=OFF -DSIMBOT_WERROR=ON > build-tsan.configure.log 2>&1 ||
  { cat build-tsan.configure.log; exit 1; }
cmake --build build-tsan --parallel "$jobs" --target bench_test
TSAN_OPTIONS=halt_on_error=1 \
  ctest --test-dir build-tsan -R '^(Bench|Tournament)\.' --output-on-failure --parallel "$jobs"
phase "ThreadSanitizer build and tests"
./scripts/fuzz.sh 20
phase "fuzzing build (against SUNDIALS 7), the plant's tests on it, campaigns"
echo "test.sh: time per stage"
printf '  %s\n' "${stages[@]}"
echo "  $SECONDS s wall, $(cpu) s CPU in all"
