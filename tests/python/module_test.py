"""The Python module gives the CLI's results: a match's dict is
`simbot match A B --json` parsed (but for wall_seconds, which is the host's
time), a solo run's trace DataFrame is the CLI's --trace file record by
record, and a bench's summary and runs are the CLI's summary.json and
runs.csv.

usage: module_test.py SIMBOT ICEMAN FIG92 WORKDIR (PYTHONPATH: build/python)
"""
import csv
import json
import os
import subprocess
import sys

import simbot

cli, iceman, fig92, work = sys.argv[1:5]
os.makedirs(work, exist_ok=True)
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL:", what)


def run_cli(*args):
    return subprocess.run([cli, *args], check=True, capture_output=True, text=True).stdout


def without_wall(j):
    return {k: v for k, v in j.items() if k != "wall_seconds"}


# The keywords of solo and match are the command line's run options, from
# one definition (runs/run_options.def): each is a --flag of `simbot match`
# (reload_on_fault is --reload-on-fault, inject is --inject), and an
# unknown one is refused.
import inspect
helped = run_cli("match", "--help")
for name in list(inspect.signature(simbot.match).parameters)[2:-1]:
    check(" --" + name.replace("_", "-") + " " in helped, f"match: keyword {name} is no CLI option")
try:
    simbot.solo(iceman, reload_on_faults=True)
    check(False, "solo: an unknown keyword was accepted")
except TypeError:
    pass

# A match, 20 simulated seconds, seed 7.
expected = json.loads(run_cli("match", iceman, fig92, "--seconds", "20", "--seed", "7", "--json"))
got = simbot.match(iceman, fig92, seconds=20, seed=7)
check(without_wall(got) == without_wall(expected), "match: module JSON != CLI JSON")
check(got["sim_seconds"] == 20.0 and got["seed"] == 7, "match: seconds or seed not as asked")
again = simbot.match(iceman, fig92, seconds=20, seed=7)
check(without_wall(again) == without_wall(got), "match: not deterministic")
other = simbot.match(iceman, fig92, seconds=20, seed=8)
check(other["seed"] == 8, "match: seed 8 not used")

# A solo run's trace: the CLI's JSONL file, as a DataFrame.
trace_file = os.path.join(work, "solo.jsonl")
expected = json.loads(run_cli("solo", iceman, "--seconds", "5", "--json", "--trace", trace_file))
got, frame = simbot.solo(iceman, seconds=5, keep_trace=True)
check(without_wall(got) == without_wall(expected), "solo: module JSON != CLI JSON")
from_file = simbot.read_trace(trace_file)
check(frame.equals(from_file), "solo: trace DataFrame != the CLI's --trace file")
with open(trace_file, encoding="utf-8") as f:
    records = [json.loads(line) for line in f]
check(len(frame) == len(records) and len(records) > 0, "solo: trace length")
check(list(frame["t"]) == [r["t"] for r in records], "solo: trace ticks differ")
check(frame["t"].is_monotonic_increasing, "solo: trace not in tick order")

# Compile: diagnostics, and a missing file is not ok.
c = simbot.compile(iceman, disasm=True)
check(c["ok"] and c["disasm"] == run_cli("compile", iceman, "--disasm"), "compile: disasm != CLI")
check(not simbot.compile(os.path.join(work, "no-such.dc"))["ok"], "compile: missing file ok")

# Bench: 4 seeds of 3 s, summary.json and runs.csv.
out = os.path.join(work, "bench")
subprocess.run([cli, "bench", iceman, "--family", "stationary", "--seeds", "4", "--seconds",
                "3", "--seed", "5", "--out", out], check=True, capture_output=True)
b = simbot.bench(iceman, "stationary", 4, seconds=3, seed=5)
with open(os.path.join(out, "summary.json"), encoding="utf-8") as f:
    check(b["summary"] == json.load(f), "bench: summary != the CLI's summary.json")
with open(os.path.join(out, "runs.csv"), newline="", encoding="utf-8") as f:
    rows = list(csv.DictReader(f))
check(len(b["runs"]) == len(rows) == 4, "bench: run count")
for mine, theirs in zip(b["runs"], rows):
    for key, text in theirs.items():
        value = mine[key]
        same = (value is None and text == "") or str(value) == text or (
            isinstance(value, float) and value == float(text))
        check(same, f"bench: run {theirs['run']} {key}: {value!r} != {text!r}")

# Bad input raises simbot.Error with the CLI's message.
try:
    simbot.match(iceman, fig92, seconds=-1)
    check(False, "match: --seconds -1 accepted")
except simbot.Error as e:
    check("--seconds must be in" in str(e), f"match: error message {e}")

print("module_test:", "FAILED" if failures else "ok")
sys.exit(1 if failures else 0)
