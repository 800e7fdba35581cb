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
  python3-junitparser          # reads simbot check's JUnit XML in its test
  python3-fastapi python3-uvicorn python3-multipart python3-httpx  # simbot serve, and its tests' client
  python3-jinja2                # simbot serve's pages
  python3-sqlalchemy python3-alembic python3-psycopg2             # its database and migrations
  postgresql                   # a throwaway server for its tests on PostgreSQL (scripts/postgres.sh)
  curl                         # docs/serve.md's example
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
# SUNDIALS 7 beside Debian 12's 6.4, for the test suite's build of the plant
# against it (scripts/test.sh): Debian 13's libsundials-dev and the
# libsundials-* packages it depends on, fetched from the mirror this
# machine's apt already uses through a throwaway apt configuration and
# unpacked into build-sundials7/prefix, never installed (the system, its
# apt sources and its package state are left as they are). They need only
# Debian 12's glibc and Open MPI's libmpi.so.40 (mpi-default-dev, which
# Debian 12's libsundials-dev brings).
sundials7=build-sundials7/prefix
if [ ! -e "$sundials7/.unpacked" ]; then
  . /etc/os-release
  mirror=$(apt-get indextargets --no-release-info --format '$(REPO_URI)' \
    "Release: $VERSION_CODENAME" "Identifier: Packages" | awk 'NR == 1')
  [ -n "$mirror" ] || { echo "setup.sh: no apt source for $VERSION_CODENAME to take SUNDIALS 7 from" >&2; exit 1; }
  apt_dir=$(mktemp -d)
  trap 'rm -rf "$apt_dir"' EXIT
  mkdir -p "$apt_dir/lists/partial" "$apt_dir/cache/archives/partial" "$apt_dir/debs"
  echo "deb [signed-by=/usr/share/keyrings/debian-archive-keyring.gpg] $mirror trixie main" \
    > "$apt_dir/sources.list"
  touch "$apt_dir/status"
  apt_opts=(-qq -o "Dir::Etc::sourcelist=$apt_dir/sources.list" -o Dir::Etc::sourceparts=-
    -o "Dir::State::Lists=$apt_dir/lists" -o "Dir::State::status=$apt_dir/status"
    -o "Dir::Cache=$apt_dir/cache" -o APT::Sandbox::User=root)
  apt-get "${apt_opts[@]}" update
  mapfile -t libs < <(apt-cache "${apt_opts[@]}" depends libsundials-dev |
    awk '$1 == "Depends:" && $2 ~ /^libsundials-/ { print $2 }')
  (cd "$apt_dir/debs" && apt-get "${apt_opts[@]}" download libsundials-dev "${libs[@]}")
  rm -rf "$sundials7"
  mkdir -p "$sundials7"
  for deb in "$apt_dir"/debs/*.deb; do dpkg-deb -x "$deb" "$sundials7"; done
  touch "$sundials7/.unpacked"
fi
# playwright-core only: it drives Debian's Chromium and downloads no browser.
lock=tests/browser/package-lock.json
stamp=tests/browser/node_modules/.simbot-lock
if ! cmp -s "$lock" "$stamp" 2>/dev/null; then
  (cd tests/browser && npm ci --no-audit --no-fund --loglevel=error)
  cp "$lock" "$stamp"
fi
