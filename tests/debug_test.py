#!/usr/bin/env python3
"""simbot debug --batch: the scripted session of issue 26 gives the
transcript in tests/debug/iceman.transcript, and the debugger's manual
(docs/debugging.md) shows that same transcript (so it stays true).

Usage: debug_test.py SIMBOT SOURCE_DIR [--update]

Run from SOURCE_DIR (the programs are named ../shared/programs/..., as the
manual's command names them). Besides the exact transcript, the session's
claims are checked on their own:
  - the first stop is the edge handler INT1 at its first entry; stepping
    back lands in the delay loop it interrupted (platform(), line 220) and
    stepping on enters the handler again at the same tick;
  - the loop counter and both poses printed at the entry, after stepping
    back and after stepping on are the same;
  - each watchpoint stop on buf was written by a line that copies a motor
    string into buf, and its new value is one of the strings that program
    copies there.
--update rewrites the transcript and the manual's block from this run.
"""
import os
import re
import subprocess
import sys

SIMBOT, SOURCE = sys.argv[1], sys.argv[2]
UPDATE = "--update" in sys.argv[3:]
SCRIPT = "tests/debug/iceman.gdb"
EXPECTED = os.path.join(SOURCE, "tests/debug/iceman.transcript")
MANUAL = os.path.join(SOURCE, "docs/debugging.md")
COMMAND = ["debug", "../shared/programs/iceman.dc", "../shared/programs/fig92.dc",
           "--seed", "3", "--batch", SCRIPT]
BEGIN, END = "<!-- debug transcript: tests/debug_test.py -->", "<!-- end of debug transcript -->"

failures = []


def check(condition, message):
    if not condition:
        failures.append(message)


run = subprocess.run([SIMBOT] + COMMAND, cwd=SOURCE, capture_output=True, text=True,
                     timeout=300)
check(run.returncode == 0, f"exit status {run.returncode}: {run.stderr}")
out = run.stdout

# The session's own claims.
stops = re.findall(r"^A at tick (\d+) \([\d.]+ s\): (\w+)\(\) at iceman\.dc:(\d+)", out, re.M)
check(len(stops) >= 3, f"too few stops: {stops}")
if len(stops) >= 3:
    entry, back, again = stops[0], stops[1], stops[2]
    check(entry[1] == "INT1", f"first stop not in INT1: {entry}")
    check(back[1:] == ("platform", "220"), f"reverse-step did not land in the loop: {back}")
    check(int(back[0]) < int(entry[0]), "reverse-step did not go back in time")
    check(again == entry, f"step did not enter the handler again at the same tick: {again}")
values = re.findall(r"^(?:platform::)?z \(int\) = (-?\d+)$", out, re.M)
check(len(values) == 3 and len(set(values)) == 1, f"the loop counter differs: {values}")
poses = re.findall(r"^A: x (.*)$", out, re.M)
check(len(poses) == 3 and len(set(poses)) == 1, f"ICEMAN's pose differs: {poses}")
source = open(os.path.join(SOURCE, "../shared/programs/iceman.dc")).read().splitlines()
copied = set(re.findall(r'strcpy\(buf, *"(\w+)"\)', "\n".join(source)))
writes = re.findall(r"^Watchpoint \d+: written by line (\d+)[^\n]*\nOld value = (.*)\nNew value = "
                    r"\"(\w*)\"", out, re.M)
check(len(writes) == 3, f"expected 3 watchpoint stops, got {len(writes)}")
for line, old, new in writes:
    check("strcpy(buf" in source[int(line) - 1], f"line {line} does not copy into buf")
    check(new in copied, f"new value {new!r} is not a string ICEMAN copies into buf")
    check(not old.startswith(f'"{new}"'), f"watchpoint stopped without a change: {new}")

# The transcript, and the manual's copy of it.
if UPDATE:
    with open(EXPECTED, "w") as f:
        f.write(out)
expected = open(EXPECTED).read()
check(out == expected, "the transcript differs from tests/debug/iceman.transcript:\n" + out)
manual = open(MANUAL).read()
block = "```text\n$ simbot " + " ".join(COMMAND) + "\n" + expected + "```\n"
pattern = re.compile(re.escape(BEGIN) + r"\n.*?" + re.escape(END), re.S)
if UPDATE:
    manual = pattern.sub(lambda m: BEGIN + "\n" + block + END, manual)
    with open(MANUAL, "w") as f:
        f.write(manual)
match = pattern.search(manual)
check(match is not None, "docs/debugging.md has no debug transcript block")
if match:
    check(match.group(0) == BEGIN + "\n" + block + END,
          "docs/debugging.md's debug transcript is not this run's (run with --update)")

for f in failures:
    print("FAIL:", f)
print("debug transcript:", "ok" if not failures else f"{len(failures)} failures")
sys.exit(1 if failures else 0)
