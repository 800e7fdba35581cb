#!/usr/bin/env python3
"""Deployables from the command line: release ticks, counts, JSON, errors.

Usage: deploy_cli_test.py SIMBOT SOURCE_DIR SHARED_DIR OUTDIR

The oracle is what the program wrote: programs/dropper.dc raises port B
bits 0, 1 and 2 together every 1.5 s, so every `port_b` record whose value
sets a bit the previous value had clear is a rising edge of that bit, and
each rising edge of a bound bit gives, at that same tick, a `deploy`
record while the table has items left (numbered 1..count) and a
`deploy_empty` after. The JSON's `deployed` counts the `deploy` records by
kind and is all zeros without [[deployables]]. Bad [[deployables]] are one
line, FILE:LINE:COL, exit 1; a rule set that forbids decoys refuses them
in one line.
"""
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

from scriptcheck import check, failures

SIMBOT, SOURCE, SHARED, OUT = sys.argv[1:5]
OUT = Path(OUT)
shutil.rmtree(OUT, ignore_errors=True)
OUT.mkdir(parents=True)
FIG92 = f"{SHARED}/programs/fig92.dc"
DROPPER = f"{SOURCE}/programs/dropper.dc"
LIGHT = f"{SOURCE}/profiles/hardware/decoy-light.toml"
BLOCKS = f"{SOURCE}/profiles/hardware/blocks.toml"


def run(*args):
    return subprocess.run([SIMBOT, *args], capture_output=True, text=True, timeout=300)


def tables(path):
    """(kind, bit, count) of each [[deployables]] in a hardware file."""
    out, cur = [], None
    for line in Path(path).read_text().splitlines():
        if line.startswith("[[deployables]]"):
            cur = {}
            out.append(cur)
        elif cur is not None and "=" in line:
            key, value = line.split("=", 1)
            key = key.strip()
            if key == "kind":
                cur["kind"] = value.strip().strip('"')
            elif key in ("bit", "count"):
                cur[key] = int(re.search(r"value\s*=\s*(\d+)", value).group(1))
    return out


for hw in (LIGHT, BLOCKS):
    trace = OUT / (Path(hw).stem + ".jsonl")
    p = run("match", DROPPER, FIG92, "--seconds", "12", "--seed", "1", "--hw", f"A={hw}",
            "--trace", str(trace), "--json")
    check(p.returncode == 0, f"{hw}: exit {p.returncode}: {p.stderr[-300:]}")
    result = json.loads(p.stdout)
    recs = [json.loads(l) for l in trace.read_text().splitlines()]
    edges = {}  # bit -> ticks of its rising edges
    last = 0
    for r in recs:
        if r["type"] == "port_b" and r["robot"] == "A":
            for b in range(8):
                if (r["value"] >> b) & 1 and not (last >> b) & 1:
                    edges.setdefault(b, []).append(r["t"])
            last = r["value"]
    counted = {"block": 0, "decoy_light": 0, "decoy_screen": 0}
    for d in tables(hw):
        ticks = edges.get(d["bit"], [])
        check(len(ticks) > d["count"], f"{hw}: the run must exhaust bit {d['bit']}")
        got = [(r["t"], r.get("number")) for r in recs
               if r["type"] == "deploy" and r["bit"] == d["bit"]]
        empty = [r["t"] for r in recs if r["type"] == "deploy_empty" and r["bit"] == d["bit"]]
        want = [(t, i + 1) for i, t in enumerate(ticks[:d["count"]])]
        check(got == want, f"{hw} bit {d['bit']}: deploy {got} != edges {want}")
        check(empty == ticks[d["count"]:], f"{hw} bit {d['bit']}: deploy_empty {empty}")
        counted[d["kind"]] += len(got)
    check(result["robots"][0]["deployed"] == counted,
          f"{hw}: JSON deployed {result['robots'][0]['deployed']} != {counted}")
    check(result["robots"][1]["deployed"] == {"block": 0, "decoy_light": 0, "decoy_screen": 0},
          f"{hw}: B deployed {result['robots'][1]['deployed']}")

# Bad [[deployables]]: one line, FILE:LINE:COL (the line given), exit 1.
light = Path(LIGHT).read_text()
for name, old, new, says in [
        ("clash_gun", "value = 1,   unit = \"bit\"", "value = 3,   unit = \"bit\"",
         "port B bit 3 is bound twice: a [[deployables]] and gun 1's motor"),
        ("two_on_one_bit", "value = 0,  unit = \"bit\"", "value = 1,  unit = \"bit\"",
         "port B bit 1 is bound twice: two [[deployables]]"),
        ("intensity", "value = 2.0, unit = \"1\"", "value = 200, unit = \"1\"",
         "'deployables.intensity' must be between 0.01 and 100"),
        ("kind", "kind   = \"decoy_screen\"", "kind   = \"smoke\"",
         "'deployables.kind' must be"),
        ("missing", "height = { value = 12", "depth = { value = 12",
         "unknown key 'depth' in a decoy_screen [[deployables]]")]:
    assert old in light, old
    text = light.replace(old, new, 1)
    line = next(i for i, l in enumerate(text.splitlines()) if new in l) + 1
    bad = OUT / f"bad_{name}.toml"
    bad.write_text(text)
    p = run("solo", DROPPER, "--seconds", "1", "--hw", str(bad), "--json")
    err = p.stderr.strip().splitlines()
    check(p.returncode == 1, f"bad {name}: exit {p.returncode}")
    check(len(err) == 1 and re.match(re.escape(str(bad)) + rf":{line}:\d+: error: ", err[0])
          and says in err[0], f"bad {name}: line {line}: {p.stderr!r}")

# A rule set without decoys refuses them before the match, in one line.
p = run("match", DROPPER, FIG92, "--seconds", "1", "--rules", "se3015-1997w", "--hw",
        f"A={LIGHT}")
err = [l for l in p.stderr.splitlines() if ": error: " in l]  # fig92 compiles with warnings
check(p.returncode == 1 and len(err) == 1 and "course.decoy_lights = false forbids robot" in err[0],
      f"rules: {p.returncode} {p.stderr!r}")

# Blocks are bodies (docs/plant.md "Deployables"): seed 2's 180 s has fig92
# (B) pushing A's first block. Each robot's JSON `block_push_ft` is the
# sum of its push_end records' pushed_ft; every push_end follows a
# push_start of the same robot and block. A push is no contact: a robot
# starts one only while it has no contact with that block, and has none
# during it; a contact_end with a block always follows its contact; a
# push stopped by something (`by` not "drive") is followed at its tick by
# the robot's contact with that block (it meets it as a fixed box), one
# that ends by "drive" by none.
trace = OUT / "pushes.jsonl"
p = run("match", DROPPER, FIG92, "--seed", "2", "--hw", f"A={BLOCKS}", "--trace", str(trace),
        "--json")
check(p.returncode == 0, f"pushes: exit {p.returncode}: {p.stderr[-300:]}")
result = json.loads(p.stdout)
recs = [json.loads(l) for l in trace.read_text().splitlines()]
open_push, touching, pushed = {}, set(), {"A": 0.0, "B": 0.0}
stopped = {}  # (robot, block) -> (t, by) of a push_end awaiting its contact
for r in recs:
    if r["type"] == "contact" and r["with"].startswith("block "):
        key = (r["robot"], int(r["with"].split()[1]))
        check(key not in open_push, f"contact during a push at {r['t']}")
        check(key not in touching, f"second contact without contact_end at {r['t']}")
        end = stopped.pop(key, None)
        check(end is None or (end[0] == r["t"] and end[1] != "drive"),
              f"contact after a push_end {end} at {r['t']}")
        touching.add(key)
    elif r["type"] == "contact_end" and r["with"].startswith("block "):
        key = (r["robot"], int(r["with"].split()[1]))
        check(key in touching, f"contact_end without contact at {r['t']}")
        touching.discard(key)
    elif r["type"] == "push_start":
        key = (r["robot"], r["block"])
        check(key not in touching, f"push_start while in contact at {r['t']}")
        open_push[key] = r["t"]
    elif r["type"] == "push_end":
        key = (r["robot"], r["block"])
        check(open_push.pop(key, None) is not None, f"push_end without push_start at {r['t']}")
        pushed[r["robot"]] += r["pushed_ft"]
        if r["by"] != "drive":
            stopped[key] = (r["t"], r["by"])
    for key, (t, by) in list(stopped.items()):
        check(r["t"] == t, f"push_end by {by} at {t} without the robot's contact")
check(not stopped, f"push_ends without their contacts: {stopped}")
check(pushed["B"] > 0, "pushes: seed 2 must push a block")
for i, name in enumerate("AB"):
    got = result["robots"][i]["block_push_ft"]
    check(abs(got - pushed[name]) <= 1e-12 * max(1.0, pushed[name]),
          f"pushes: {name} block_push_ft {got} != {pushed[name]}")

# More blocks than the plant's table holds per robot (plant.h
# kMaxBlocksPerRobot = 16): one line at the table that passes the limit.
blocks = Path(BLOCKS).read_text()
old = "count          = { value = 4,"
assert old in blocks
second = blocks[blocks.index("[[deployables]]"):].replace("value = 2,   unit = \"bit\"",
                                                          "value = 1,   unit = \"bit\"", 1)
text = blocks.replace(old, "count          = { value = 16,", 1) + "\n" + second
line = text.splitlines().index("[[deployables]]", text.splitlines().index("[[deployables]]") + 1) + 1
bad = OUT / "bad_blocks.toml"
bad.write_text(text)
p = run("solo", DROPPER, "--seconds", "1", "--hw", str(bad), "--json")
err = p.stderr.strip().splitlines()
check(p.returncode == 1 and len(err) == 1 and
      re.match(re.escape(str(bad)) + rf":{line}:\d+: error: ", err[0]) and
      "at most 16 blocks in a robot's [[deployables]], 20 here" in err[0],
      f"too many blocks: {p.returncode} {p.stderr!r}")

if failures:
    print(f"{len(failures)} failure(s)")
    sys.exit(1)
print("deployables: release ticks, counts, JSON and errors as documented")
