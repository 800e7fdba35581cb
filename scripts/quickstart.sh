#!/usr/bin/env bash
# Sets everything up and runs simbot's main job on the programs it ships:
# until matches exist, compiling each one and printing its disassembly.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
./scripts/build.sh build
for program in programs/*.dc; do
  echo "=== $program"
  build/bin/simbot compile "$program" --disasm
done
