#!/usr/bin/env python3
"""Faults are loud in every command, and run-time findings are reported.

Usage: fault_cli_test.py SIMBOT FAULTING TURRET ICEMAN OUTDIR

FAULTING (tests/faulting/unbound_vector.dc) binds no vector ("#define
INT_VEC ...") but arms the PIO, and backs onto the south wire: it faults at
its first crossing, well inside a second.

- solo: exit status 3 (a robot faulted), not 1 (bad input, also checked);
  the fault line on stderr; the JSON's fault. profile: the same status and
  its JSON's fault.
- match: a fault line in the text output (robot, time, source line,
  message); --reload-on-fault restarts it 20 s (the profile's
  [match] reload_delay) after the fault and the match runs to its end.
- tournament --json: the fault in its game; --reload-on-fault counts reloads.
- bench: the runs.csv fault column, faults per program in summary.json.
- --watch without --trace: an error, exit 1.
- an injection that never fired: a warning on stderr naming it (solo; each
  run of a bench).
- frames overwritten: shown in match text output and counted in the JSON.
"""
import csv
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

from scriptcheck import check, failures

SIMBOT, FAULTING, TURRET, ICEMAN, OUT = sys.argv[1:6]
OUT = Path(OUT)
shutil.rmtree(OUT, ignore_errors=True)
OUT.mkdir(parents=True)
# PROGRAM:LINE: fault: robot R at T s: MESSAGE
FAULT_LINE = re.compile(
    r"unbound_vector\.dc:\d+: fault: robot [AB] at \d+\.\d{6} s: pio_a interrupt through "
    r"vector 0x10, which no #INT_VEC binds")


def run(*args):
    return subprocess.run([SIMBOT, *args], capture_output=True, text=True, timeout=600)


# solo: exit 3, distinct from bad input (1).
solo = run("solo", FAULTING, "--seconds", "5")
check(solo.returncode == 3, f"solo of a faulting program exits 3, got {solo.returncode}")
check(FAULT_LINE.search(solo.stderr), f"solo's stderr has the fault line:\n{solo.stderr}")
bad = run("solo", str(OUT / "no-such.dc"))
check(bad.returncode == 1, f"solo of a missing file exits 1, got {bad.returncode}")
solo_json = run("solo", FAULTING, "--seconds", "5", "--json")
check(solo_json.returncode == 3, "solo --json exits 3 too")
j = json.loads(solo_json.stdout)
check(j["fault"] is not None and "no #INT_VEC binds" in j["fault"]["message"],
      f"solo JSON has the fault: {j['fault']}")
check(j["reloads"] == 0 and j["motor_frames_overwritten"] == 0, "solo JSON counts")

# profile: the fault in its JSON, exit 3.
prof = run("profile", FAULTING, "--seconds", "5", "--json")
check(prof.returncode == 3, f"profile of a faulting program exits 3, got {prof.returncode}")
check("no #INT_VEC binds" in json.loads(prof.stdout)["fault"]["message"], "profile JSON fault")

# match: a fault line in the text output (stdout), exit 3.
match = run("match", FAULTING, TURRET, "--seconds", "10")
check(match.returncode == 3, f"match exits 3, got {match.returncode}")
check(FAULT_LINE.search(match.stdout), f"match's text output has the fault line:\n{match.stdout}")
check("frames overwritten" in match.stdout, "match's text output shows frames overwritten")

# match --reload-on-fault: the first fault is before 1 s, the reload 20 s
# later, and the match runs its full 30 s.
reload = run("match", FAULTING, TURRET, "--seconds", "30", "--reload-on-fault", "--json",
             "--trace", str(OUT / "reload.jsonl"))
check(reload.returncode == 3, f"a match with a fault exits 3 even after reloads, got "
      f"{reload.returncode}")
j = json.loads(reload.stdout)
a = j["robots"][0]
check(j["sim_seconds"] == 30, f"the match went on to its end: {j['sim_seconds']}")
check(a["fault"]["time_s"] < 1.0, f"first fault under a second: {a['fault']}")
check(a["reloads"] == 1, f"one reload in 30 s: {a['reloads']}")
records = [json.loads(line) for line in open(OUT / "reload.jsonl")]
faults = [r for r in records if r["type"] == "fault"]
reloads = [r for r in records if r["type"] == "reload"]
check(len(reloads) == 1 and reloads[0]["t"] == faults[0]["t"] + 20 * 9_216_000,
      "the reload record is the profile's 20 s after the fault")
check("(reloaded)" in reload.stderr, "stderr marks the fault that was reloaded")

# tournament: the fault in the JSON, per game; reloads counted.
tour = run("tournament", FAULTING, TURRET, "--rounds", "2", "--seconds", "25", "--threads", "2",
           "--out", str(OUT / "tournament"), "--json", "--reload-on-fault")
check(tour.returncode == 0, f"tournament exits 0, got {tour.returncode}: {tour.stderr}")
j = json.loads(tour.stdout)
for game in j["games"]:
    side = "a" if game["a"] == FAULTING else "b"
    check(game[f"fault_{side}"] and "no #INT_VEC binds" in game[f"fault_{side}"],
          f"tournament game has the fault: {game}")
    check(game[f"reloads_{side}"] == 1, f"tournament game counts the reload: {game}")
check("simbot: tournament:" in tour.stderr and "no #INT_VEC binds" in tour.stderr,
      "tournament's stderr has the fault lines")
with open(OUT / "tournament" / "games.csv", newline="") as f:
    rows = list(csv.DictReader(f))
check(all(r["fault_a"] or r["fault_b"] for r in rows), "games.csv has the faults")

# bench: runs.csv's fault column, faults per program in the summary.
bench = run("bench", FAULTING, "--family", "stationary", "--seeds", "2", "--seconds", "20",
            "--threads", "2", "--out", str(OUT / "bench"))
check(bench.returncode == 0, f"bench exits 0, got {bench.returncode}: {bench.stderr}")
with open(OUT / "bench" / "runs.csv", newline="") as f:
    rows = list(csv.DictReader(f))
check(len(rows) == 2 and all(r["outcome"] == "fault" and "no #INT_VEC binds" in r["fault"]
                             for r in rows), f"runs.csv fault column: {rows}")
summary = json.load(open(OUT / "bench" / "summary.json"))
check(summary["programs"][0]["runs_faulted"] == 2, "summary.json counts faulted runs")
check("2 with a fault" in bench.stdout, f"bench's text output counts faults:\n{bench.stdout}")
check("simbot: bench: run 0" in bench.stderr and "no #INT_VEC binds" in bench.stderr,
      "bench's stderr has the fault lines")

# --watch without --trace: an error, exit 1, nothing run.
watch = run("solo", ICEMAN, "--seconds", "1", "--watch", "cnt")
check(watch.returncode == 1, f"--watch without --trace exits 1, got {watch.returncode}")
check("--watch needs --trace" in watch.stderr, f"and says why: {watch.stderr}")

# An injection that never fired: a warning naming it.
never = run("solo", ICEMAN, "--seconds", "1", "--inject", "A:edge_fore@2s")
check(never.returncode == 0, f"exit 0, got {never.returncode}")
check("warning: --inject A:edge_fore@2s never fired" in never.stderr,
      f"the unfired injection is named: {never.stderr}")

# bench: a scenario's injection that never fired, in each run, is named.
(OUT / "late.toml").write_text('[A]\ninject = ["edge_fore@50s"]\n')
late = run("bench", ICEMAN, "--family", "stationary", "--scenario", str(OUT / "late.toml"),
           "--seeds", "2", "--seconds", "2", "--threads", "2", "--out", str(OUT / "late"))
check(late.returncode == 0, f"bench exits 0, got {late.returncode}: {late.stderr}")
check(late.stderr.count("--inject A:edge_fore@50s never fired") == 2,
      f"each run's unfired injection is named: {late.stderr}")

if failures:
    print(f"{len(failures)} failure(s)")
    sys.exit(1)
print("all fault and finding checks passed")
