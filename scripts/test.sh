#!/usr/bin/env bash
# Sets everything up and runs the whole test suite: the layout check
# (clang-format), the normal build with warnings as errors, the same suite
# built with AddressSanitizer and UndefinedBehaviorSanitizer, and a short
# campaign (60 s) of each libFuzzer target.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
jobs=$(nproc)
mapfile -t sources < <(find compiler vm plant scheduler trace tools tests bench fuzz \
  -path tests/browser/node_modules -prune -o \( -name '*.cpp' -o -name '*.h' \) -print | sort)
clang-format --dry-run --Werror "${sources[@]}"
./scripts/build.sh build -DSIMBOT_WERROR=ON
ctest --test-dir build --output-on-failure --parallel "$jobs" --timeout 900
./scripts/build.sh build-asan -DSIMBOT_SANITIZE=ON -DSIMBOT_BENCHMARKS=OFF -DCMAKE_BUILD_TYPE=Debug \
  -DSIMBOT_WERROR=ON
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build-asan --output-on-failure --parallel "$jobs" --timeout 1800
./scripts/fuzz.sh 60
