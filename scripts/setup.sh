#!/usr/bin/env bash
# Installs simbot's build and test dependencies: Debian 12's packages, then
# the browser test driver (playwright-core, pinned by tests/browser's
# package-lock.json) with npm. Idempotent: packages already present are
# skipped, and npm ci runs only when the lock file changed. Run as root.
# With --quickstart: only what the simbot executable needs to build and
# play a match (scripts/quickstart.sh); the tests' browsers, waveform
# tools, fuzzers, benchmarks and Python packages are left to the test
# command.
set -euo pipefail
cd "$(dirname "$0")/.."
quickstart=(
  build-essential cmake ninja-build git
  libsundials-dev libeigen3-dev
  libcli11-dev libtomlplusplus-dev nlohmann-json3-dev libfmt-dev
  libboost-math-dev            # distributions and quantiles for the statistics
  libjs-three                  # three.js r111, inlined in replay pages
  libreadline-dev              # simbot debug's line editing and history
)
packages=(
  "${quickstart[@]}"
  pkg-config clang-format
  help2man man-db              # simbot.1, the manual page, from the command line's help
  libgtest-dev libgmock-dev libbenchmark-dev
  lua5.4 python3 linux-perf     # Lua and perf for the benchmarks (bench/vs_lua.py, docs/benchmarks.md)
  sigrok-cli gtkwave xvfb      # tests read --vcd output with sigrok's decoder and GTKWave
  chromium                     # the browser test (headless, software WebGL)
  clang libclang-rt-14-dev     # libFuzzer (scripts/fuzz.sh)
  pybind11-dev python3-dev     # the Python module
  python3-pandas python3-matplotlib  # traces as DataFrames; docs/ plots a bench
  python3-statsmodels          # test oracle for the survival and interval statistics
  python3-distributed          # sweeps on a Dask cluster
)
if [ "${1:-}" = --quickstart ]; then
  packages=("${quickstart[@]}")
else
  # Node.js and npm drive the browser test; a machine that has them (from
  # Debian or elsewhere) keeps its own.
  command -v npm > /dev/null || packages+=(nodejs npm)
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
if ((${#missing[@]})); then
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
[ "${1:-}" = --quickstart ] && exit 0
# playwright-core only: it drives Debian's Chromium and downloads no browser.
lock=tests/browser/package-lock.json
stamp=tests/browser/node_modules/.simbot-lock
if ! cmp -s "$lock" "$stamp" 2>/dev/null; then
  (cd tests/browser && npm ci --no-audit --no-fund --loglevel=error)
  cp "$lock" "$stamp"
fi
