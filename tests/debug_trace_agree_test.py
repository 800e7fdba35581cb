#!/usr/bin/env python3
"""The trace and the debugger agree on every variable at every tick
(issue 38, item 3).

The rule (docs/trace.md, "watch"): a record at tick t carries the watched
variables as the robot's memory holds them at its first instruction
boundary at or after t: everything that began before t has run (an
instruction, an interrupt acceptance, the serial library's atomic transmit
service), nothing that begins at t or later. The debugger's `goto t`
stops the held robot at that same boundary. So for every record of a robot
in a window, `goto t` with that robot held and `print` of each of its
globals must give the values the record's `watch` holds.

Two matches: tests/debug/noei.dc (an edge handler that forgets EI(), so
the bytes of the motor string it sends wait until its RETI and then go out
one transmit interrupt after another) against Figure 9.2 with an edge
injected into A at 1 s, in [0.5 s, 2 s]; and ICEMAN against Figure 9.2
(seed 1) in [9 s, 11.5 s], where ICEMAN fires (port B writes, the plant's
solenoid records made after the round) inside its edge handler's time.

Usage: debug_trace_agree_test.py SIMBOT SOURCE_DIR SHARED_DIR WORK_DIR
"""
import json
import os
import re
import subprocess
import sys

SIMBOT, SOURCE, SHARED, WORK = sys.argv[1:5]
os.makedirs(WORK, exist_ok=True)
FIG92 = os.path.join(SHARED, "programs/fig92.dc")
FIG92_GLOBALS = ["buf", "cc", "left", "right", "sum", "ammo", "count"]
CASES = [
    {"name": "noei",
     "programs": [os.path.join(SOURCE, "tests/debug/noei.dc"), FIG92],
     "globals": [["buf", "cc", "waited", "edges"], FIG92_GLOBALS],
     "run": ["--seconds", "2", "--seed", "2", "--inject", "A:edge_fore@1s"],
     "window": (0.5, 2.0)},
    {"name": "iceman",
     "programs": [os.path.join(SHARED, "programs/iceman.dc"), FIG92],
     "globals": [["buf", "cc", "x", "y", "i", "cnt", "s", "shcnt", "count"], FIG92_GLOBALS],
     "run": ["--seconds", "11.5", "--seed", "1"],
     "window": (9.0, 11.5)},
]

failures = []


def check(condition, message):
    if not condition:
        failures.append(message)


def value(text):
    """A printed value as --watch records it: a number, or the text."""
    first = text.split(" ")[0]
    if not text.startswith('"') and re.fullmatch(r"-?\d+(\.\d*)?(e[-+]?\d+)?", first):
        return float(first) if any(c in first for c in ".e") else int(first)
    return text


total_ticks = 0
compared = 0
kinds = set()
for case in CASES:
    name, programs, globals_ = case["name"], case["programs"], case["globals"]
    window = tuple(int(w * 9216000) for w in case["window"])
    trace = os.path.join(WORK, name + ".jsonl")
    watches = sorted(set(globals_[0]) | set(globals_[1]))
    run = subprocess.run([SIMBOT, "match", *programs, *case["run"], "--trace", trace] +
                         [a for w in watches for a in ("--watch", w)],
                         capture_output=True, text=True, timeout=300)
    check(run.returncode == 0, f"{name}: match: exit {run.returncode}: {run.stderr}")
    # Each robot's records in the window: tick -> the watch values (every
    # record of a robot at one tick must carry the same values).
    records = [{}, {}]
    with open(trace) as f:
        for line in f:
            r = json.loads(line)
            if "watch" not in r or r.get("robot") not in ("A", "B"):
                continue
            if not window[0] <= r["t"] < window[1]:
                continue
            i = "AB".index(r["robot"])
            values = {k: v for k, v in r["watch"].items() if k in globals_[i]}
            seen = records[i].setdefault(r["t"], values)
            check(seen == values, f"{name}: robot {r['robot']}: two records at tick {r['t']} "
                                  f"disagree: {seen} and {values} ({r['type']})")
            kinds.add(r["type"])
    for robot in (0, 1):
        ticks = sorted(records[robot])
        total_ticks += len(ticks)
        script = os.path.join(WORK, f"{name}-{'AB'[robot]}.gdb")
        with open(script, "w") as f:
            for t in ticks:
                f.write(f"goto {t}\n")
                for g in globals_[robot]:
                    f.write(f"output {g}\n")
        out = subprocess.run([SIMBOT, "debug", *programs, *case["run"], "--robot", "AB"[robot],
                              "--batch", script], capture_output=True, text=True, timeout=600)
        check(out.returncode == 0, f"{name}: debug: exit {out.returncode}: {out.stderr[-2000:]}")
        # Each goto's stop, then one "NAME (TYPE) = VALUE" line per global.
        blocks = re.split(r"^\(simbot\) goto \d+\n", out.stdout, flags=re.M)[1:]
        check(len(blocks) == len(ticks),
              f"{name}: robot {'AB'[robot]}: {len(blocks)} stops for {len(ticks)} gotos")
        for t, block in zip(ticks, blocks):
            printed = dict(re.findall(r"^(\w+) \([^)]*\) = (.*)$", block, re.M))
            for g in globals_[robot]:
                want, got = records[robot][t].get(g), printed.get(g)
                got = value(got) if got is not None else None
                if isinstance(want, float) and isinstance(got, (int, float)):
                    same = abs(want - got) <= 1e-6 * max(1.0, abs(want))
                else:
                    same = want == got
                check(same, f"{name}: robot {'AB'[robot]} tick {t}: {g} is {got!r} in the "
                            f"debugger, {want!r} in the trace")
                compared += 1

for needed in ("serial_isr", "serial_byte", "serial_send", "interrupt_accepted", "iff1",
               "sample", "port_b", "solenoid_stroke"):
    check(needed in kinds, f"no {needed} record in the windows")
check(total_ticks >= 2000, f"only {total_ticks} record ticks in the windows")
print(f"{total_ticks} record ticks, {compared} values compared")
for f in failures[:40]:
    print("FAIL:", f)
if failures:
    print(f"{len(failures)} failures")
    sys.exit(1)
