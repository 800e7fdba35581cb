#!/usr/bin/env python3
"""Chained sub-rounds while the other robot sits them out are exact.

Usage: chain_test.py SIMBOT SOURCE_DIR OUTDIR

scheduler/match.cpp, "Larger rounds", rules (6), (7) and (9): without a
trace, a robot quiet in a delay loop sits sub-rounds out, and the robot
left running takes the next sub-round's horizons inside its own VM run,
asking the scheduler only where a horizon could change its answer: past
the last horizon the other sits out (Continuation::unaskedUpTo). With a trace
no robot sits out and no run is chained: every sub-round is the round
loop's own, so the traced run is the oracle, and the untraced run's JSON
must be its JSON (but for the wall-clock field).

tests/chain/decoyer.dc (B) waits in delay loops and sets down a decoy
light three times; tests/chain/reader.dc (A), facing it
(tests/chain/facing.toml), computes for PASSES passes with no bus call,
reads its eye, and computes on for a count that depends on the reading,
so its JSON depends on every reading. B's port B write is an input that A
sees at once (the decoy adds to B's beacon), applied where the sub-round
it falls in ends: a chain that ran A past that sub-round without B would
let A read the field without the decoy. PASSES runs over 20..45 and the
seed over 1..3, so that A's reads fall at every phase of B's sub-rounds
(a build that ignored unaskedUpTo, or that chained A while B did not sit out,
gave a different JSON for several of them). A robot's own serial bytes
taken inside its chain (rule (9)) are checked by tests/fast_forward_test.py
(fig92's 77,000 bytes against every program).

The premise, from the programs: B's three rising edges of bit 1 give three
`deploy` records of a decoy light (the table holds three), and A's first
reading after the first decoy is at least twice its last before it (the
decoy's intensity is twice a beacon's, profiles/hardware/decoy-light.toml).
"""
import json
import shutil
import subprocess
import sys
from pathlib import Path

from scriptcheck import check, failures

SIMBOT, SOURCE, OUT = sys.argv[1:4]
OUT = Path(OUT)
shutil.rmtree(OUT, ignore_errors=True)
OUT.mkdir(parents=True)
CHAIN = Path(SOURCE) / "tests" / "chain"
SCENARIO = CHAIN / "facing.toml"
DECOYER = CHAIN / "decoyer.dc"


def summary(reader, seed, trace=None):
    args = [SIMBOT, "match", str(reader), str(DECOYER), "--scenario", str(SCENARIO),
            "--seed", str(seed), "--json"]
    if trace:
        args += ["--trace", str(trace)]
    out = subprocess.run(args, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"FAIL: {' '.join(args)} exited {out.returncode}: {out.stderr}")
    result = json.loads(out.stdout)
    result.pop("wall_seconds", None)
    return result


source = (CHAIN / "reader.dc").read_text()
for passes in range(20, 46):
    reader = OUT / f"reader{passes}.dc"
    reader.write_text(f"#define PASSES {passes}\n" + source)
    for seed in (1, 2, 3):
        trace = OUT / f"reader{passes}-{seed}.trace"
        traced = summary(reader, seed, trace)
        untraced = summary(reader, seed)
        check(untraced == traced, f"PASSES {passes} seed {seed}: JSON differs without a trace")
        if passes == 28 and seed == 3:
            records = [json.loads(line) for line in trace.read_text().splitlines()]
            decoys = [r["t"] for r in records
                      if r["type"] == "deploy" and r["kind"] == "decoy_light"]
            check(len(decoys) == 3, f"three decoy lights, not {len(decoys)}")
            check(traced["robots"][1]["deployed"]["decoy_light"] == 3, "JSON: three decoys")
            reads = [(r["t"], r["value"]) for r in records
                     if r["type"] == "ad_read" and r["robot"] == "A"]
            before = [v for t, v in reads if decoys and t < decoys[0]]
            after = [v for t, v in reads if decoys and t >= decoys[0]]
            check(before and after and after[0] >= 2 * before[-1],
                  f"A sees the first decoy: {before[-1:]} then {after[:1]}")
        trace.unlink()

if failures:
    sys.exit(f"{len(failures)} failure(s)")
print("ok: 78 untraced runs are their traced runs")
