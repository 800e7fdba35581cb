#!/usr/bin/env bash
# Sets everything up and runs the whole test suite: the layout check
# (clang-format, no source file over 1,000 lines), the normal build with warnings as errors
# (its tests beside a throwaway PostgreSQL server, scripts/postgres.sh), the plant
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
# Beside a throwaway PostgreSQL server (scripts/postgres.sh), which
# server.api.postgres runs simbot serve's tests on; the sanitizer builds
# have no server.
./scripts/postgres.sh ctest --test-dir build --output-on-failure --parallel "$jobs" --timeout 900
phase "normal tests"
# The sanitizer builds keep line tables only (-g1): their reports still give
# FILE:LINE, and compiling takes less time (ThreadSanitizer at -O1 -g1: 14 s
# for reports/explain.cpp where -O2 -g takes 22).
./scripts/build.sh build-asan -DSIMBOT_SANITIZE=ON -DSIMBOT_BENCHMARKS=OFF -DCMAKE_BUILD_TYPE=Debug \
  -DCMAKE_CXX_FLAGS_DEBUG=-g1 -DSIMBOT_WERROR=ON
phase "sanitizer build"
# Left out under the sanitizers, to keep the suite under 30 minutes: the
# checks that play long matches again and again to compare what they give
# (their code runs under the sanitizers in shorter tests: the other Match.*,
# Stats.*, FastForward.*, Trace.*, Explain.*, VmSuperinstruction.*,
# MatchCopy.* and DebugSession.* checks, debug.rules, debug.dap and
# hostile.inputs, which also writes replay pages), and the checks ran in
# the normal build above. CPU seconds under ASan, measured in a fresh clone:
asan_skip=(
  # whole CLI matches repeated for determinism or variation (39 s)
  'cli\.match\.deterministic' 'cli\.variation'
  # every program with and without fast-forward (31 s)
  'fast_forward\.identical'
  # the 180-s match explained again from its JSONL file (76 s)
  'Explain\.FromTheJsonlFile'
  # Python, Chromium and statsmodels drivers (batch runs killed and resumed,
  # the replay page, the statistics' oracle)
  'batch\.kill_and_resume' 'browser\.viewer' 'browser\.course' 'stats\.oracle'
  # every superinstruction against its unfused run at 3,000 horizons and
  # interrupt ticks (each a copy of two VMs)
  'VmSuperinstruction\.EveryHorizonStopsWhereTheUnfusedRunStops'
  'VmSuperinstruction\.AnInterruptRequestedAtAnyTickIsAcceptedWhereItIsUnfused'
  # ICEMAN's delay loops against the thesis's ten seconds (95 s)
  'IcemanTiming\.CalibratedKnobsAreTheHardwareSettingNearestTenSeconds'
  # 180-s matches played for their figures (costate_hunter vs ICEMAN 92 s,
  # the bearing program 124 s, no body entering another 72 s, seeds and
  # profiles 54 s and 51 s, determinism with and without a trace 44 s)
  'Match\.CostateHunterPlaysIcemanAndLatchesFrames' 'Match\.BearingStudentProgramPlaysFig92'
  'Match\.NoBodyEntersAWallTheDividerOrTheOtherRobot'
  'Match\.DefaultProfileGivesEachSeedItsOwnMatchAndTheSameSeedTheSameOne'
  'Match\.Thesis1997SeedChangesOnlyTheCoin' 'Match\.IcemanAgainstFig92IsDeterministicAndTraceDoesNotChangeIt'
  # two matches copied after every kind of event, each copy run to the end
  # (about 200 s); MatchCopy.AfterAFaultAndAReload stays
  'MatchCopy\.AfterEveryKindOfEventInIcemanVsFig92' 'MatchCopy\.AfterTheTimersInterruptInCostateHunterVsIceman'
  # the 180-s match's debugger against its trace at 3,987 ticks (162 s), a
  # 600-s debugging session (34 s), a 180-s match restored byte for byte (60 s)
  'debug\.trace_agrees' 'DebugSession\.SnapshotsThinOutWithDistanceFromThePresent'
  'MatchSnapshot\.IcemanVsFig92GoesOnByteForByte'
  # the plant's tests run under ASan and UBSan in the fuzzing build (on SUNDIALS 7)
  'plant_test'
  # discs and obstacles through the CLI (31 s and 26 s): their plant code
  # runs in plant_test there, and their matches, traces and reports under
  # ASan here in cli.explain_course
  'cli\.disc' 'cli\.obstacles'
  # simbot check's worked example on three seeds, each case judged again
  # from the traces (107 s), and deployables through the CLI (70 s): under
  # ASan, hostile.inputs runs simbot check on bad expectations files and a
  # short run with its JUnit and JSON, and the plant's deployables run in
  # plant_test (fuzzing build)
  'cli\.check' 'cli\.deploy'
  # two 180-s matches explained for one figure each (31 s): the explain
  # report runs under ASan in cli.explain_course and Explain.TheIcemanFig92Match
  'Explain\.SlowSteadyDriveWhileSeeingIsNoStall' 'Explain\.ReportsReloads'
)
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build-asan --output-on-failure --parallel "$jobs" --timeout 1800 \
  -E "^($(IFS='|'; echo "${asan_skip[*]}"))\$"
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
