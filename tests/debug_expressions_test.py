#!/usr/bin/env python3
"""simbot debug's expressions by the robot's rules (16-bit int that wraps,
casts, sizeof, shifts, ?:, format letters, x/NFU), and the inputs that
must be refused with one line, on tests/debug/expressions.dc.

Usage: debug_expressions_test.py SIMBOT SOURCE_DIR WORKDIR

tests/debug/expressions.gdb holds the commands, each followed by the lines
it must print ("# expect: ..."), worked out by hand in its comments; this
script runs it and compares each command's output with them. Then --watch
on a solo run: an expression is recorded as the robot computes it (x * 20
is -31616), one that can never be evaluated (1/0, x % 0) is refused
before the run with one line and exit status 1, and one that fails only on
the values it reads (count / (x - x)) is accepted and recorded as null.
"""
import json
import os
import subprocess
import sys

SIMBOT, SOURCE, WORK = sys.argv[1], sys.argv[2], sys.argv[3]
PROGRAM = os.path.join(SOURCE, "tests/debug/expressions.dc")
SCRIPT = os.path.join(SOURCE, "tests/debug/expressions.gdb")
PROMPT = "(simbot) "

failures = []


def check(condition, message):
    if not condition:
        failures.append(message)


# The commands and what each must print.
commands = []  # (command, [expected lines])
for line in open(SCRIPT).read().splitlines():
    if line.startswith("# expect:"):
        commands[-1][1].append(line[len("# expect: "):] if len(line) > 9 else "")
    elif line.strip() and not line.startswith("#"):
        commands.append((line, []))
checked = sum(1 for _, want in commands if want)
check(checked >= 90, f"only {checked} commands have expectations")

run = subprocess.run([SIMBOT, "debug", PROGRAM, "--batch", SCRIPT], capture_output=True, text=True,
                     timeout=120)
# A batch whose commands were refused exits 1 (cli/debug_command.cpp); this one's last are.
check(run.returncode == 1, f"simbot debug exited {run.returncode}: {run.stderr}")
blocks = []  # (command, [lines])
for line in run.stdout.splitlines():
    if line.startswith(PROMPT):
        blocks.append((line[len(PROMPT):], []))
    elif blocks:
        blocks[-1][1].append(line)
check(len(blocks) == len(commands),
      f"{len(commands)} commands in the script, {len(blocks)} echoed:\n{run.stdout}")
for (command, want), (echoed, got) in zip(commands, blocks):
    check(command == echoed, f"echoed {echoed!r} where the script has {command!r}")
    if want:
        check(got == want, f"{command}\n  printed:  {got}\n  expected: {want}")

# --watch on a solo run: the trace's samples carry each expression's value.
os.makedirs(WORK, exist_ok=True)


def solo(*watches):
    trace = os.path.join(WORK, "watch.jsonl")
    if os.path.exists(trace):
        os.remove(trace)
    command = [SIMBOT, "solo", PROGRAM, "--seconds", "0.01", "--trace", trace]
    for w in watches:
        command += ["--watch", w]
    r = subprocess.run(command, capture_output=True, text=True, timeout=120)
    last = None
    if r.returncode == 0:
        for line in open(trace):
            record = json.loads(line)
            if record.get("type") == "sample" and "watch" in record:
                last = record["watch"]
    return r, last


r, watch = solo("x * 20", "(long) x * 20", "count / (x - x)", "sizeof(buf)")
check(r.returncode == 0, f"--watch run exited {r.returncode}: {r.stderr}")
if watch is not None:
    # 1696 * 20 wraps to -31616 as an int; as a long it is 33920.
    check(watch.get("x * 20") == -31616, f"x * 20 recorded as {watch.get('x * 20')}")
    check(watch.get("(long) x * 20") == 33920, f"(long) x * 20: {watch.get('(long) x * 20')}")
    # x - x is 0 only by the values read: a fault at each record, null.
    check(watch.get("count / (x - x)", "absent") is None,
          f"count / (x - x): {watch.get('count / (x - x)', 'absent')}")
    check(watch.get("sizeof(buf)") == 6, f"sizeof(buf): {watch.get('sizeof(buf)')}")
else:
    check(False, "no sample with watch values in the trace")
for refused, why in [("1/0", "division by zero"), ("x % 0", "division by zero"),
                     ("buf[0]@0", "the count after '@' must be at least 1"),
                     ("where * 2", "invalid operands to '*' (struct and int)"),
                     ("buf[9223372036854775807]", "integer constant '9223372036854775807' is too large"),
                     ("*(&count + 4611686018427387904)", "is too large")]:
    r, _ = solo(refused)
    lines = r.stderr.strip().splitlines()
    check(r.returncode == 1, f"--watch {refused}: exit {r.returncode}, expected 1")
    check(len(lines) == 1 and f"--watch {refused}: " in lines[0] and why in lines[0],
          f"--watch {refused}: stderr {r.stderr!r}, expected one line with {why!r}")

for f in failures:
    print(f)
print(f"{checked} debugger commands checked; {len(failures)} failures")
sys.exit(1 if failures else 0)
