#!/usr/bin/env bash
# Configures and builds the fuzzing build, build-fuzz/: clang, ASan and
# UBSan, unoptimised, the libFuzzer targets (fuzz/) linked with libFuzzer.
# It is also the suite's sanitizer build (scripts/test.sh runs the tests
# there) and its build against SUNDIALS 7. With no arguments it builds
# everything; otherwise the targets named.
#
# Debug (-O0) with line tables only (-g1): with UBSan, clang's optimiser
# spends 420-475 s on vm/vm.cpp alone at -O1 or -O2 (41 s at -O0), and a
# sanitizer's report still gives FILE:LINE.
#
# SUNDIALS 7 is Debian 13's, which scripts/setup.sh unpacks into
# build-sundials7/prefix (the normal build uses Debian 12's 6.4):
# plant/arkode.cpp's 7.x branches compiled with warnings as errors (so no
# deprecated call), the tests run on it under ASan and UBSan, and the
# targets fuzz a plant built on it. Without that prefix (setup.sh not run)
# it builds against the system's.
set -euo pipefail
cd "$(dirname "$0")/.."
sundials=()
if [ -e build-sundials7/prefix/.unpacked ]; then
  sundials=("-DCMAKE_PREFIX_PATH=$PWD/build-sundials7/prefix/usr")
fi
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG=-g1 \
  -DSIMBOT_FUZZ=ON -DSIMBOT_BENCHMARKS=OFF -DSIMBOT_WERROR=ON "${sundials[@]}" \
  > build-fuzz.configure.log 2>&1 || { cat build-fuzz.configure.log; exit 1; }
if [ ${#sundials[@]} -gt 0 ]; then
  grep -q '^-- SUNDIALS 7\.' build-fuzz.configure.log ||
    { grep SUNDIALS build-fuzz.configure.log; echo "build_fuzz: build-fuzz did not find SUNDIALS 7"; exit 1; }
fi
targets=()
for target in "$@"; do targets+=(--target "$target"); done
cmake --build build-fuzz --parallel "$(nproc)" "${targets[@]}"
