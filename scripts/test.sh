#!/usr/bin/env bash
# Sets everything up and runs the whole test suite: the normal build, then
# the same suite built with AddressSanitizer and UndefinedBehaviorSanitizer.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
jobs=$(nproc)
./scripts/build.sh build
ctest --test-dir build --output-on-failure --parallel "$jobs" --timeout 900
./scripts/build.sh build-asan -DSIMBOT_SANITIZE=ON -DSIMBOT_BENCHMARKS=OFF -DCMAKE_BUILD_TYPE=Debug
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build-asan --output-on-failure --parallel "$jobs" --timeout 1800
