#!/usr/bin/env python3
"""One grammar for a written time at every entry point (timebase/written.h).

A time is a decimal with a unit s, ms, us or t (ticks of 9.216 MHz); a
number alone means what it always meant there (--seconds and a scenario's
seconds: seconds; the debugger's goto: ticks; --inject: no time). It must
be a whole number of ticks: anything else is refused in one line naming
the two nearest ticks, exit status 1. The expected ticks are worked by
hand: 300 us = 300 * 9.216 = 2,764.8 ticks (refused: 2764t, 2765t);
0.0001 s = 921.6 ticks (921t, 922t); 125 us = 1,152 ticks; 0.5 ms = 4,608;
9216t = 1 ms.

Entry points: --seconds (solo, bench, compare, tournament), --inject, a
scenario file (FILE:LINE:COL), the debugger's break, advance and goto, and
the Debug Adapter's launch `seconds` and debug-console "goto".

Usage: written_time_cli_test.py SIMBOT ICEMAN FIG92 WORKDIR
"""
import json
import os
import re
import subprocess
import sys

SIMBOT, ICEMAN, FIG92, WORK = sys.argv[1:5]
ICEMAN, FIG92 = os.path.abspath(ICEMAN), os.path.abspath(FIG92)
os.makedirs(WORK, exist_ok=True)
failures = []


def check(condition, message):
    if not condition:
        failures.append(message)


def run(*args, stdin=None):
    return subprocess.run([SIMBOT, *map(str, args)], cwd=WORK, capture_output=True, text=True,
                          timeout=300, input=stdin)


def refused(r, *words):
    """Exit status 1, and one line on stderr holding every word."""
    lines = [line for line in r.stderr.splitlines() if line.strip()]
    return r.returncode == 1 and len(lines) == 1 and all(w in lines[0] for w in words)


BETWEEN_300US = "the nearest are 2764t and 2765t"
BETWEEN_100US = "the nearest are 921t and 922t"

# ---- --seconds, on every command that takes it (one definition)
for cmd in (["solo", ICEMAN], ["match", ICEMAN, FIG92], ["profile", ICEMAN],
            ["bench", ICEMAN, "--family", "stationary", "--seeds", "1", "--out", "b"],
            ["compare", ICEMAN, FIG92, "--family", "stationary", "--seeds", "1", "--out", "c"],
            ["tournament", ICEMAN, FIG92, "--out", "t"],
            ["debug", ICEMAN]):
    r = run(*cmd, "--seconds", "300us")
    check(refused(r, "--seconds", "'300us'", BETWEEN_300US), f"{cmd[0]} --seconds 300us: {r.stderr!r}")
    r = run(*cmd, "--seconds", "0.0001")
    check(refused(r, "--seconds", BETWEEN_100US), f"{cmd[0]} --seconds 0.0001: {r.stderr!r}")
    r = run(*cmd, "--seconds", "2e6")
    check(refused(r, "--seconds", "at most 1e6 s"), f"{cmd[0]} --seconds 2e6: {r.stderr!r}")

# Accepted in every unit: the run ends at that tick (ICEMAN is still running,
# so cycles is the clock at the end: 9216t = 9,216; 125us = 1,152; 0.5ms =
# 4,608; a number alone is seconds: 0.001 = 9,216).
for written, ticks in (("9216t", 9216), ("125us", 1152), ("0.5ms", 4608), ("0.001", 9216),
                       ("1e-3s", 9216)):
    r = run("solo", ICEMAN, "--seconds", written, "--json")
    cycles = json.loads(r.stdout)["cycles"] if r.returncode == 0 else None
    check(cycles == ticks, f"solo --seconds {written}: {cycles} T-states, expected {ticks}")

# ---- --inject: the same units; a number alone is still no time here
r = run("solo", ICEMAN, "-Wno-implicit-function-declaration", "--seconds", "1", "--inject", "A:edge_fore@300us")
check(refused(r, "--inject", "'A:edge_fore@300us'", BETWEEN_300US), f"--inject @300us: {r.stderr!r}")
r = run("solo", ICEMAN, "-Wno-implicit-function-declaration", "--seconds", "1", "--inject", "A:edge_fore@0.0001s")
check(refused(r, "--inject", BETWEEN_100US), f"--inject @0.0001s: {r.stderr!r}")
r = run("solo", ICEMAN, "-Wno-implicit-function-declaration", "--seconds", "1", "--inject", "A:edge_fore@12.5")
check(refused(r, "--inject", "WHEN must be a time"), f"--inject @12.5: {r.stderr!r}")
for written in ("125us", "1152t"):  # the same tick, so the same run
    r = run("solo", ICEMAN, "--seconds", "0.01", "--inject", f"A:edge_fore@{written}", "--json")
    check(r.returncode == 0, f"--inject @{written}: {r.stderr!r}")
    if written == "125us":
        first = r.stdout
    else:
        check(json.loads(r.stdout)["cycles"] == json.loads(first)["cycles"],
              "--inject @125us and @1152t differ")

# ---- a scenario file: FILE:LINE:COL
scenario = os.path.join(WORK, "times.toml")
with open(scenario, "w") as f:
    f.write('seed = 2\nseconds = "300us"\n')
r = run("solo", ICEMAN, "--scenario", scenario)
check(refused(r, f"{scenario}:2:11: error: 'seconds': '300us'", BETWEEN_300US),
      f"scenario seconds = \"300us\": {r.stderr!r}")
with open(scenario, "w") as f:
    f.write('seconds = "9216t"\n[A]\ninject = ["edge_fore@0.0001s"]\n')
r = run("solo", ICEMAN, "--scenario", scenario)
check(refused(r, f"{scenario}:3:11: error: 'edge_fore@0.0001s'", BETWEEN_100US),
      f"scenario inject @0.0001s: {r.stderr!r}")
with open(scenario, "w") as f:
    f.write('seconds = "125us"\n')
r = run("solo", ICEMAN, "--scenario", scenario, "--json")
check(r.returncode == 0 and json.loads(r.stdout)["cycles"] == 1152,
      f"scenario seconds = \"125us\": {r.stdout[:200]!r} {r.stderr!r}")


# ---- the debugger: break, advance, goto
def debug(commands):
    batch = os.path.join(WORK, "times.gdb")
    with open(batch, "w") as f:
        f.write(commands)
    return run("debug", ICEMAN, "--seconds", "1", "--batch", batch)


# break 0.0001s was rounded to tick 922; it is refused, as --inject refuses it.
r = debug("break 0.0001s\n")
check(r.returncode == 1 and BETWEEN_100US in r.stdout + r.stderr, f"break 0.0001s: {r.stdout!r}")
r = debug("goto 300us\n")
check(r.returncode == 1 and BETWEEN_300US in r.stdout + r.stderr, f"goto 300us: {r.stdout!r}")
# advance 9216t was refused as no line; goto 9216 (a number alone: ticks).
r = debug("advance 9216t\ngoto 1152\nbreak 125us\n")
check(r.returncode == 0, f"advance 9216t, goto 1152, break 125us: {r.stdout!r} {r.stderr!r}")


def stop_after(out, command):
    """The tick of the first stop printed after `command`'s prompt line."""
    rest = out.split(f"(simbot) {command}\n", 1)[-1]
    found = re.search(r"^A at tick (\d+) ", rest, re.M)
    return int(found.group(1)) if found else None


# Each stops at the first instruction boundary at or after the tick (an
# instruction takes well under 200 T-states).
for command, tick in (("advance 9216t", 9216), ("goto 1152", 1152)):
    at = stop_after(r.stdout, command)
    check(at is not None and tick <= at < tick + 200, f"{command}: stopped at {at}: {r.stdout!r}")
check("Breakpoint 1 at tick 1152 (0.000125 s)" in r.stdout, f"break 125us: {r.stdout!r}")


# ---- the Debug Adapter: launch's seconds and the console's goto
class Dap:
    def __init__(self):
        self.p = subprocess.Popen([SIMBOT, "dap"], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                  stderr=subprocess.DEVNULL)
        self.seq = 0

    def read(self):
        length = 0
        while True:
            line = self.p.stdout.readline().decode()
            if line in ("\r\n", ""):
                break
            if line.lower().startswith("content-length:"):
                length = int(line.split(":")[1])
        return json.loads(self.p.stdout.read(length))

    def request(self, command, arguments=None):
        self.seq += 1
        body = json.dumps({"seq": self.seq, "type": "request", "command": command,
                           "arguments": arguments or {}}).encode()
        self.p.stdin.write(b"Content-Length: %d\r\n\r\n" % len(body) + body)
        self.p.stdin.flush()
        while True:
            m = self.read()
            if m.get("type") == "response" and m.get("request_seq") == self.seq:
                return m

    def event(self, name):
        while True:
            m = self.read()
            if m.get("type") == "event" and m.get("event") == name:
                return m

    def close(self):
        self.request("disconnect")
        self.p.stdin.close()
        self.p.wait(timeout=60)


dap = Dap()
dap.request("initialize", {"adapterID": "simbot"})
r = dap.request("launch", {"program": ICEMAN, "seconds": "300us"})
check(not r["success"] and BETWEEN_300US in r.get("message", ""), f"launch seconds 300us: {r}")
r = dap.request("launch", {"program": ICEMAN, "seconds": 0.0001})
check(not r["success"] and BETWEEN_100US in r.get("message", ""), f"launch seconds 0.0001: {r}")
r = dap.request("launch", {"program": ICEMAN, "seconds": "500ms", "stopOnEntry": True})
check(r["success"], f"launch seconds 500ms: {r}")
dap.event("initialized")
dap.request("configurationDone")
dap.event("stopped")
r = dap.request("evaluate", {"expression": "goto 300us", "context": "repl"})
check(not r["success"] and BETWEEN_300US in r.get("message", "") + json.dumps(r.get("body", {})),
      f"evaluate goto 300us: {r}")
r = dap.request("evaluate", {"expression": "goto 125us", "context": "repl"})
check(r["success"] and "going to tick 1152 " in r["body"]["result"], f"evaluate goto 125us: {r}")
dap.event("stopped")
# Past the run's 500 ms (4,608,000 ticks): the match ends there.
r = dap.request("evaluate", {"expression": "goto 9216000t", "context": "repl"})
check(r["success"] and "going to tick 9216000 " in r["body"]["result"], f"goto 9216000t: {r}")
dap.close()

for f in failures:
    print("FAIL:", f)
print(f"written_time_cli_test: {len(failures)} failures")
sys.exit(1 if failures else 0)
