"""The Python module gives the CLI's results: a match's dict is
`simbot match A B --json` parsed (but for wall_seconds, which is the host's
time), a solo run's trace DataFrame is the CLI's --trace file record by
record, and a bench's summary and runs are the CLI's summary.json and
runs.csv.

It cannot be crashed through its private API (_simbot): a bad shard, the
sweep writer finished twice or written after it finished, a trace that is
no regular file, threads that cannot be created are exceptions.

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
    check("--seconds: '-1' is not a time" in str(e), f"match: error message {e}")

# seconds is written as --seconds is (timebase/written.h): a number of
# seconds or a time with its unit, a whole number of ticks. 300 us is
# 2,764.8 ticks; 0.0001 s is 921.6; 500 ms is 4,608,000 ticks.
for bad, ticks in (("300us", "2764t and 2765t"), (0.0001, "921t and 922t")):
    try:
        simbot.solo(iceman, seconds=bad)
        check(False, f"solo: seconds={bad!r} accepted")
    except simbot.Error as e:
        check(f"the nearest are {ticks}" in str(e), f"solo: seconds={bad!r}: {e}")
got = simbot.solo(iceman, seconds="500ms")
check(got["cycles"] == 4_608_000 and not got["exited"], f"solo: seconds='500ms' ran {got['cycles']} T-states")
check(without_wall(got) == without_wall(json.loads(run_cli("solo", iceman, "--seconds", "500ms",
                                                           "--json"))),
      "solo: seconds='500ms' differs from --seconds 500ms")
# bench's keywords are the command line's bench options, from the same table.
helped = run_cli("bench", "--help")
for name in list(inspect.signature(simbot.bench).parameters)[1:]:
    check(" --" + name.replace("_", "-") + " " in helped, f"bench: keyword {name} is no CLI option")
try:
    simbot.bench(iceman, "stationary", 0)
    check(False, "bench: seeds=0 accepted")
except simbot.Error as e:
    check("--seeds: '0' is not an integer from 1 to 1000000" in str(e), f"bench: seeds=0: {e}")

# The module checks its arguments and cannot be crashed (issue 25): each
# case below answers with an exception, never a signal.
from simbot import _simbot  # noqa: E402


def raises(kind, what, call):
    try:
        call()
        check(False, f"{what}: no exception")
    except kind as e:
        return str(e)
    except Exception as e:  # noqa: BLE001
        check(False, f"{what}: {type(e).__name__} {e}, not {kind.__name__}")
    return ""


# shard_range: K/N checked (a division by N = 0 was SIGFPE).
raises(ValueError, "shard_range(10, 1, 0)", lambda: _simbot.shard_range(10, 1, 0))
raises(ValueError, "shard_range(10, 0, 3)", lambda: _simbot.shard_range(10, 0, 3))
raises(ValueError, "shard_range(10, 4, 3)", lambda: _simbot.shard_range(10, 4, 3))
check(_simbot.shard_range(10, 2, 3) == (3, 6), "shard_range(10, 2, 3)")
# The sweep writer: finish twice, put after finish, a run not awaited, a
# begin after its end.
table = os.path.join(work, "writer.csv")
w = _simbot.SweepWriter(table, ["run", "x"], True, 0, 1, False)
w.put(0, ["0", "a"])
w.finish()
w.finish()  # twice: nothing more (it used to segfault)
raises(RuntimeError, "put of a run already written", lambda: w.put(0, ["0", "b"]))
with open(table, encoding="utf-8") as f:
    check(f.read() == "run,x\n0,a\n", "writer: the table after finish")
w = _simbot.SweepWriter(os.path.join(work, "writer2.csv"), ["run"], True, 0, 2, False)
raises(RuntimeError, "put of a run not awaited", lambda: w.put(5, ["5"]))
w.put(1, ["1"])
raises(simbot.Error, "finish with a row missing", w.finish)
message = raises(simbot.Error, "put after finish", lambda: w.put(0, ["0"]))
check("is finished" in message, f"put after finish: {message}")
raises(simbot.Error, "finish again", w.finish)
raises(ValueError, "a writer whose begin is after its end",
       lambda: _simbot.SweepWriter(os.path.join(work, "w3.csv"), ["run"], True, 3, 1, False))
# read_trace: a regular file of at most 16 GiB, checked before reading.
message = raises(simbot.Error, "read_trace('/dev/zero')", lambda: simbot.read_trace("/dev/zero"))
check("not a regular file" in message, f"read_trace('/dev/zero'): {message}")
fifo = os.path.join(work, "fifo")
if not os.path.exists(fifo):
    os.mkfifo(fifo)
message = raises(simbot.Error, "read_trace(FIFO)", lambda: simbot.read_trace(fifo))
check("not a regular file" in message, f"read_trace(FIFO): {message}")
raises(simbot.Error, "read_trace(directory)", lambda: simbot.read_trace(work))
raises(simbot.Error, "read_trace(missing)", lambda: simbot.read_trace(os.path.join(work, "no")))
check(simbot.MAX_TRACE_BYTES == 16 << 30, "read_trace's stated limit is 16 GiB")
# A line past MAX_TRACE_LINE_BYTES (8 MiB, as view and explain) is an error
# naming FILE:LINE: here a 64-MiB second line (sparse), after a real record.
check(simbot.MAX_TRACE_LINE_BYTES == 8 << 20, "read_trace's line limit is 8 MiB")
long_trace = os.path.join(work, "long-line.jsonl")
with open(trace_file, "rb") as f, open(long_trace, "wb") as out:
    out.write(f.readline())
    out.truncate(out.tell() + (64 << 20))
message = raises(simbot.Error, "read_trace(a 64-MiB line)", lambda: simbot.read_trace(long_trace))
check(message.startswith(f"{long_trace}:2: error: a line of more than 8388608 bytes"),
      f"read_trace(a 64-MiB line): {message}")
# A bench whose threads cannot all be created is simbot.Error, not an
# abort of Python: a child process with its address space limited so that
# 400 thread stacks cannot fit.
child = subprocess.run([sys.executable, "-c", f"""
import resource, sys
import simbot
with open("/proc/self/status") as f:
    size = next(int(l.split()[1]) for l in f if l.startswith("VmSize:")) * 1024
limit = size + (256 << 20)
resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
try:
    simbot.bench({iceman!r}, "stationary", 400, seconds=0.05, threads=400)
except simbot.Error as e:
    print("Error:", e)
    sys.exit(0)
print("no error")
"""], capture_output=True, text=True, env={**os.environ, "MALLOC_ARENA_MAX": "1"}, timeout=120)
check(child.returncode == 0 and "cannot start" in child.stdout and "worker threads" in child.stdout,
      f"bench with threads it cannot create: status {child.returncode}, "
      f"{child.stdout.strip()[-200:]} {child.stderr.strip()[-300:]}")

print("module_test:", "FAILED" if failures else "ok")
sys.exit(1 if failures else 0)
