#!/usr/bin/env python3
"""The disc launcher from the command line: JSON, trace and errors.

Usage: disc_cli_test.py SIMBOT SOURCE_DIR SHARED_DIR OUTDIR

The oracle is what the programs wrote: every rising edge of port B bit 6
in a robot's `port_b` records is one pull of the launcher, so a robot
with profiles/hardware/disc-launcher.toml (15 discs) sends
min(edges, 15) discs (`disc_fire`) and finds the magazine empty on the
rest (`disc_empty`); each disc ends once (`disc_hit` or `disc_miss`, same
number) unless the run ends first. The JSON's `secondary` counts them;
its `hits` stay the balls' (`ball_hit`). ICEMAN's fire() raises bit 6
before each volley (0x40, "CLOSES SOLENOID FOR DISK SHOOTER"); without a
launcher the bit is logged only (`disc_shooter`) and the JSON has no
`secondary`. A bad [secondary] value is one line, FILE:LINE:COL, exit 1.
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
ICEMAN = f"{SHARED}/programs/iceman.dc"
FIG92 = f"{SHARED}/programs/fig92.dc"
TIMER = f"{SOURCE}/programs/disc_timer.dc"
LAUNCHER = f"{SOURCE}/profiles/hardware/disc-launcher.toml"


def run(*args):
    return subprocess.run([SIMBOT, *args], capture_output=True, text=True, timeout=600)


def records(path):
    with open(path) as f:
        return [json.loads(line) for line in f]


def rising_edges(trace, robot, bit=6):
    edges, before = 0, 0
    for r in trace:
        if r["type"] == "port_b" and r["robot"] == robot:
            if (r["value"] >> bit) & 1 and not (before >> bit) & 1:
                edges += 1
            before = r["value"]
    return edges


def count(trace, kind, robot):
    return sum(1 for r in trace if r["type"] == kind and r["robot"] == robot)


def check_discs(trace, robot, magazine, label):
    edges = rising_edges(trace, robot)
    fired = count(trace, "disc_fire", robot)
    check(edges > 0, f"{label}: {robot} never raised bit 6")
    check(fired == min(edges, magazine), f"{label}: {fired} disc_fire for {edges} edges")
    check(count(trace, "disc_empty", robot) == edges - fired,
          f"{label}: disc_empty != edges - discs")
    check(count(trace, "disc_shooter", robot) == 0, f"{label}: disc_shooter with a launcher")
    flying = set()
    for r in trace:
        if r.get("robot") != robot:
            continue
        if r["type"] == "disc_fire":
            check(r["disc"] not in flying, f"{label}: disc {r['disc']} reused in flight")
            flying.add(r["disc"])
        elif r["type"] in ("disc_hit", "disc_miss"):
            check(r["disc"] in flying, f"{label}: {r['type']} of a disc not in flight")
            flying.discard(r["disc"])
            if r["type"] == "disc_miss":
                check(r["hit"] in ("wall", "divider", "stopped"), f"{label}: miss {r['hit']}")
    return fired, count(trace, "disc_hit", robot)


# ICEMAN with the launcher against fig92.
trace_path = OUT / "launcher.jsonl"
p = run("match", ICEMAN, FIG92, "--seconds", "60", "--seed", "1", "--hw", f"A={LAUNCHER}",
        "--trace", str(trace_path), "--json")
check(p.returncode == 0, f"match with the launcher: exit {p.returncode}: {p.stderr}")
result = json.loads(p.stdout)
trace = records(trace_path)
a, b = result["robots"]
shots, hits = check_discs(trace, "A", 15, "ICEMAN")
check(a.get("secondary") == {"shots": shots, "hits": hits},
      f"A's secondary {a.get('secondary')} != {{shots: {shots}, hits: {hits}}}")
check("secondary" not in b, "B carries no secondary weapon but has the key")
check(a["hits"] == count(trace, "ball_hit", "A"), "A's hits are not its ball hits")
check(a["shots"] == count(trace, "ball_launch", "A"), "A's shots are not its balls")
setup = [r for r in trace if r["type"] == "secondary"]
check(len(setup) == 1 and setup[0]["robot"] == "A" and setup[0]["magazine"] == 15
      and setup[0]["bit"] == 6 and setup[0]["kind"] == "disc", f"secondary records {setup}")
final = [r for r in trace if r["type"] == "secondary_result"]
check(len(final) == 1 and final[0]["shots"] == shots and final[0]["hits"] == hits,
      f"secondary_result {final}")

# The same match without it: bit 6 logged only, no secondary anywhere.
plain_path = OUT / "plain.jsonl"
p = run("match", ICEMAN, FIG92, "--seconds", "60", "--seed", "1", "--trace", str(plain_path),
        "--json")
check(p.returncode == 0, f"plain match: exit {p.returncode}")
plain = json.loads(p.stdout)
ptrace = records(plain_path)
check(all("secondary" not in r for r in plain["robots"]), "secondary key without a launcher")
check(count(ptrace, "disc_shooter", "A") == rising_edges(ptrace, "A"),
      "without a launcher each rising edge is one disc_shooter")
check(not any(r["type"].startswith("disc_") and r["type"] != "disc_shooter"
              or r["type"].startswith("secondary") for r in ptrace),
      "disc records without a launcher")

# Solo: the timer program empties its magazine.
solo_path = OUT / "timer.jsonl"
p = run("solo", TIMER, "--seconds", "40", "--hw", LAUNCHER, "--trace", str(solo_path), "--json")
check(p.returncode == 0, f"solo timer: exit {p.returncode}: {p.stderr}")
solo = json.loads(p.stdout)
strace = records(solo_path)
shots, hits = check_discs(strace, "A", 15, "timer")
check(rising_edges(strace, "A") > 15, "the timer program did not empty the magazine")
check(solo.get("secondary") == {"shots": 15, "hits": 0}, f"solo secondary {solo.get('secondary')}")
check(all(r["closest_ft"] is None for r in strace if r["type"] == "disc_miss"),
      "a solo miss has a closest distance")

# Bad values: one line, FILE:LINE:COL, exit 1.
text = Path(LAUNCHER).read_text()
for key, line, says in [
        ("magazine", 'magazine = { value = 16.5, unit = "count", source = "x" }',
         "'secondary.magazine' must be an integer"),
        ("launch_speed", 'launch_speed = { value = 2, unit = "ft/s", source = "x" }',
         "secondary.stop_speed must be below secondary.launch_speed"),
        ("diameter", 'diameter = { value = -1, unit = "in", source = "x" }',
         "'secondary.diameter' must be between 0.01 and 2 ft"),
        ("kind", 'kind = { value = "pencil", source = "x" }', "'secondary.kind' must be \"disc\"")]:
    lines = text.splitlines()
    number = next(i for i, l in enumerate(lines) if l.startswith(key + " "))
    lines[number] = line
    bad = OUT / f"bad_{key}.toml"
    bad.write_text("\n".join(lines) + "\n")
    p = run("solo", TIMER, "--seconds", "1", "--hw", str(bad), "--json")
    err = p.stderr.strip().splitlines()
    check(p.returncode == 1, f"bad {key}: exit {p.returncode}")
    check(len(err) == 1 and re.match(re.escape(str(bad)) + r":\d+:\d+: error: ", err[0])
          and says in err[0], f"bad {key}: {p.stderr!r}")
    where = re.match(re.escape(str(bad)) + r":(\d+):", err[0]) if err else None
    # the changed key's own line, except the cross-check, reported at stop_speed
    want = number + 1 if key != "launch_speed" else next(
        i for i, l in enumerate(lines) if l.startswith("stop_speed ")) + 1
    check(where is not None and int(where.group(1)) == want, f"bad {key}: line {err}")

if failures:
    print(f"{len(failures)} failure(s)")
    sys.exit(1)
print("disc launcher: JSON, trace and errors as documented")
