#!/usr/bin/env python3
"""Course rules (--rules, docs/rules.md) and Detect to Engage on the CLI.

Usage: rules_cli_test.py SIMBOT SOURCE_DIR ICEMAN FIG92 OUTDIR

- tests/programs/fire_blind.dc fires gun 1 four times (hand-counted in its
  comment). Alone in the arena (solo, no beacon: both eyes read the
  background 16, DESIGN.md optics) under se3015-1997w every one of its 4
  shots is a scatter shot: 4 scatter_shot records with eyes 16 and 16, and
  the JSON's scatter_shots 4. Without --rules: scatter_shots null, no
  scatter_shot or rules record.
- Facing a beacon 6 ft ahead (tests/rules/facing-beacon.toml: both eyes
  1024 by the optics formula, above the threshold 48): 0 scatter shots, 4
  launches.
- Behind the divider (tests/rules/behind-divider.toml): 4 scatter shots
  that hit; under se3015-1997w (scatter_scores = false) the result's hits
  are 0, under a copy with scatter_scores = true they are 4.
- A hardware file with a 16-ball magazine is refused before the match:
  one line "rules/se3015-1997w.toml:14:1: error: course.gun_magazine = 15
  forbids ..." (line 14 is gun_magazine's line in the file), exit 1.
- --rules on solo, match, bench, compare, tournament, sweep and profile:
  accepted with a shipped name, refused with one line naming a bad one.
"""
import json
import shutil
import subprocess
import sys
from pathlib import Path

from scriptcheck import check, failures

SIMBOT, SOURCE, ICEMAN, FIG92, OUT = sys.argv[1:6]
SOURCE, OUT = Path(SOURCE), Path(OUT)
shutil.rmtree(OUT, ignore_errors=True)
OUT.mkdir(parents=True)
FIRE = str(SOURCE / "tests/programs/fire_blind.dc")
RULES_DIR = SOURCE / "tests/rules"


def run(*args):
    return subprocess.run([SIMBOT, *map(str, args)], capture_output=True, text=True, timeout=600)


def records(path, kind):
    with open(path) as f:
        return [r for r in map(json.loads, f) if r["type"] == kind]


# Alone: every shot is blind.
trace = OUT / "blind.jsonl"
blind = run("solo", FIRE, "--profile", "thesis-1997", "--rules", "se3015-1997w", "--seconds", "5",
            "--trace", trace, "--json")
check(blind.returncode == 0, f"solo under rules exits 0: {blind.stderr}")
if blind.returncode == 0:
    j = json.loads(blind.stdout)
    check(j["scatter_shots"] == 4, f"4 scatter shots alone, got {j['scatter_shots']}")
    scatter = records(trace, "scatter_shot")
    check(len(scatter) == 4 and len(records(trace, "ball_launch")) == 4,
          f"4 launches and 4 scatter_shot records: {scatter}")
    check(all(r["eye_left"] == 16 and r["eye_right"] == 16 and r["threshold"] == 48 and
              r["scores"] is False for r in scatter), f"blind eyes 16, 16: {scatter}")
    launches = {r["t"] for r in records(trace, "ball_launch")}
    check({r["t"] for r in scatter} == launches, "each scatter shot at its launch's tick")
    rules = records(trace, "rules")
    check(len(rules) == 1 and rules[0]["name"] == "se3015-1997w" and rules[0]["floor_skips"],
          f"the rules record: {rules}")
plain_trace = OUT / "plain.jsonl"
plain = run("solo", FIRE, "--profile", "thesis-1997", "--seconds", "5", "--trace", plain_trace,
            "--json")
check(plain.returncode == 0 and json.loads(plain.stdout)["scatter_shots"] is None,
      f"without rules scatter_shots is null: {plain.stdout[-200:]}")
check(not records(plain_trace, "scatter_shot") and not records(plain_trace, "rules"),
      "without rules no scatter_shot or rules record")

# Facing a beacon in plain view.
trace = OUT / "facing.jsonl"
facing = run("solo", FIRE, "--scenario", RULES_DIR / "facing-beacon.toml", "--trace", trace,
             "--json")
check(facing.returncode == 0, f"facing run exits 0: {facing.stderr}")
if facing.returncode == 0:
    check(json.loads(facing.stdout)["scatter_shots"] == 0, "facing the beacon: 0 scatter shots")
    samples = [r for r in records(trace, "sample") if r["robot"] == "A"]
    check(samples and samples[0]["eye_left"] == 1024 and samples[0]["eye_right"] == 1024,
          f"eyes 1024 at 6 ft (optics formula): {samples[:1]}")
    check(len(records(trace, "ball_launch")) == 4 and not records(trace, "scatter_shot"),
          "4 launches, none a scatter shot")

# Hidden by the divider: scatter shots that hit, scored as the rules say.
lenient = OUT / "lenient.toml"
lenient.write_text((SOURCE / "rules/se3015-1997w.toml").read_text().replace(
    'scatter_scores     = { value = false', 'scatter_scores     = { value = true'))
for rules, hits in (("se3015-1997w", 0), (lenient, 4)):
    trace = OUT / "hidden.jsonl"
    hidden = run("solo", FIRE, "--scenario", RULES_DIR / "behind-divider.toml", "--rules", rules,
                 "--trace", trace, "--json")
    check(hidden.returncode == 0, f"hidden run exits 0: {hidden.stderr}")
    if hidden.returncode != 0:
        continue
    check(json.loads(hidden.stdout)["scatter_shots"] == 4, f"{rules}: 4 scatter shots")
    check(len(records(trace, "ball_hit")) == 4, f"{rules}: 4 balls hit")
    result = [r for r in records(trace, "result") if r["robot"] == "A"]
    check(result and result[0]["hits"] == hits, f"{rules}: A's hits {hits}: {result}")

# A magazine larger than issued: refused before the match, one line.
# (fire_blind.dc compiles without warnings: stderr is the one line.)
big = run("match", FIRE, FIRE, "--rules", "se3015-1997w", "--hw",
          f"A={RULES_DIR / 'big-magazine.toml'}", "--seconds", "1")
line = big.stderr.strip()
check(big.returncode == 1 and "\n" not in line and line.startswith(
    str(SOURCE / "rules/se3015-1997w.toml") + ":14:1: error: course.gun_magazine = 15 forbids "
    "robot A's gun magazine of 16 balls set by ") and line.endswith(
    "big-magazine.toml (the standard gun's magazine remains as issued)"),
    f"the magazine refusal: exit {big.returncode}: {big.stderr!r}")
check(run("match", FIRE, FIRE, "--hw", f"A={RULES_DIR / 'big-magazine.toml'}", "--seconds",
          "1").returncode == 0, "the same hardware without rules plays")

# Every command takes --rules, and names a bad one in one line.
sweep = OUT / "small.toml"
sweep.write_text(f'programs = ["{ICEMAN}"]\nfamilies = ["stationary"]\nseconds = 1.0\n'
                 '[seeds]\ncount = 1\n')
commands = {
    "solo": ["solo", ICEMAN, "--seconds", "1"],
    "match": ["match", ICEMAN, FIG92, "--seconds", "1"],
    "profile": ["profile", ICEMAN, "--seconds", "1"],
    "bench": ["bench", ICEMAN, "--family", "stationary", "--seeds", "1", "--seconds", "1",
              "--out", OUT / "bench"],
    "compare": ["compare", ICEMAN, FIG92, "--family", "stationary", "--seeds", "1",
                "--seconds", "1", "--out", OUT / "compare"],
    "tournament": ["tournament", ICEMAN, FIG92, "--rounds", "1", "--seconds", "1", "--out",
                   OUT / "tournament"],
    "sweep": ["sweep", sweep, "--out", OUT / "sweep.csv"],
}
for name, args in commands.items():
    good = run(*args, "--rules", "se3015-1996")
    check(good.returncode == 0, f"{name} --rules se3015-1996 exits 0: {good.stderr[-300:]}")
    bad = run(*args, "--rules", "no-such-rules")
    check(bad.returncode == 1 and bad.stderr == "simbot: --rules: no rule set 'no-such-rules' "
          "(a file, or one of rules/*.toml)\n", f"{name} with a bad name: {bad.stderr!r}")

if failures:
    sys.exit(f"{len(failures)} failure(s)")
print("ok")
