#!/usr/bin/env bash
# Sets everything up and runs simbot's main job on the programs it ships: a
# full 3-minute match between programs/spiral.dc and programs/turret.dc,
# writing the trace, the replay page, the waveforms and the JSON summary to
# out/.
set -euo pipefail
cd "$(dirname "$0")/.."
# Only what a match needs: the packages of the simbot executable and that
# executable alone (the test command installs and builds the rest).
./scripts/setup.sh --quickstart
# The normal build's flags (scripts/test.sh), so that after the test
# command nothing is compiled again.
./scripts/build.sh build -DSIMBOT_CLI_ONLY=ON "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG"
mkdir -p out
build/bin/simbot match programs/spiral.dc programs/turret.dc --seconds 180 --seed 1 \
  --trace out/match.jsonl --replay out/match.html --vcd out/match.vcd --json > out/match.json
build/bin/simbot match programs/spiral.dc programs/turret.dc --seconds 180 --seed 1
echo "trace: out/match.jsonl ($(wc -l < out/match.jsonl) records); summary: out/match.json"
echo "replay: open out/match.html in a browser; waveforms: gtkwave out/match.vcd"
