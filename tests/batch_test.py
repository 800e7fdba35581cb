#!/usr/bin/env python3
"""Batch work loses nothing (bench and tournament).

Usage: batch_test.py SIMBOT ICEMAN FIG92 SPIRAL TURRET OUTDIR

- A bench killed with SIGKILL half-way and resumed with --resume writes the
  very runs.csv and summaries an uninterrupted bench writes (cmp).
- A bench stopped with SIGINT exits 130, keeps every finished run (each one
  identical to the uninterrupted bench's row) and summarises those.
- The same kill and resume for a tournament's games.csv and standings;
  games.csv names the programs and standings.md is a Markdown table.
- The output location is checked before the first run; a write that fails
  (a file-size limit) ends the bench with an error, not a success.
- --resume refuses a table another batch wrote.
- --resume refuses, in one line naming FILE:LINE and changing nothing, a
  row of another seed (bench and tournament: pasted from the same batch
  run with another --seed), of a program the batch does not play, or a run
  twice; and a batch.json that another simbot version wrote, naming both.
"""
import json
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

from scriptcheck import check, failures

SIMBOT, ICEMAN, FIG92, SPIRAL, TURRET, OUT = sys.argv[1:7]
OUT = Path(OUT)
shutil.rmtree(OUT, ignore_errors=True)
OUT.mkdir(parents=True)


BENCH = [SIMBOT, "bench", ICEMAN, FIG92, "--family", "stationary", "--seeds", "30",
         "--seconds", "20", "--threads", "2"]
TOURNAMENT = [SIMBOT, "tournament", ICEMAN, FIG92, SPIRAL, TURRET, "--rounds", "2",
              "--seconds", "30", "--threads", "2"]


def rows(path):
    try:
        return path.read_text().count("\n") - 1
    except FileNotFoundError:
        return 0


def start_and_wait(cmd, table, at_least):
    """Starts a batch and waits until its table has `at_least` rows."""
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 120
    while rows(table) < at_least and proc.poll() is None and time.time() < deadline:
        time.sleep(0.01)
    return proc


def same_files(a, b, names, what):
    for name in names:
        x, y = (a / name).read_bytes(), (b / name).read_bytes()
        check(x == y, f"{what}: {name} differs from the uninterrupted batch's")


# ---- bench: uninterrupted, then killed and resumed
whole = OUT / "bench-whole"
subprocess.run(BENCH + ["--out", str(whole)], check=True, capture_output=True)
total = rows(whole / "runs.csv")
check(total == 60, f"the uninterrupted bench has 60 runs, not {total}")

killed = OUT / "bench-killed"
proc = start_and_wait(BENCH + ["--out", str(killed)], killed / "runs.csv", 12)
proc.send_signal(signal.SIGKILL)
proc.wait()
kept = rows(killed / "runs.csv")
check(0 < kept < 60, f"SIGKILL half-way: {kept} runs in the table")
r = subprocess.run(BENCH + ["--out", str(killed), "--resume"], capture_output=True, text=True)
check(r.returncode == 0, f"--resume exits 0: {r.returncode} {r.stderr[-300:]}")
same_files(whole, killed, ["runs.csv", "summary.json", "summary.md"], "bench killed and resumed")

# ---- bench: SIGINT keeps and summarises what it finished
stopped = OUT / "bench-sigint"
proc = start_and_wait(BENCH + ["--out", str(stopped)], stopped / "runs.csv", 8)
proc.send_signal(signal.SIGINT)
_, err = proc.communicate(timeout=120)
check(proc.returncode == 130, f"SIGINT: exit status {proc.returncode}, expected 130")
check("--resume continues" in err, f"SIGINT says how to go on: {err[-300:]}")
lines = (stopped / "runs.csv").read_text().splitlines()
finished = len(lines) - 1
check(0 < finished < 60, f"SIGINT: {finished} runs kept")
whole_rows = set((whole / "runs.csv").read_text().splitlines()[1:])
check(all(line in whole_rows for line in lines[1:]),
      "every run kept after SIGINT is the uninterrupted bench's run")
summary = json.loads((stopped / "summary.json").read_text())
check(sum(p["runs_done"] for p in summary["programs"]) == finished,
      "the summary counts exactly the runs kept")

# ---- tournament: killed and resumed
whole_t = OUT / "tournament-whole"
subprocess.run(TOURNAMENT + ["--out", str(whole_t)], check=True, capture_output=True)
games = rows(whole_t / "games.csv")
check(games == 12, f"4 programs, 2 rounds: 12 games, not {games}")
# games.csv names the programs; standings.md is a Markdown table
import csv  # noqa: E402
with open(whole_t / "games.csv", newline="") as f:
    table = list(csv.DictReader(f))
programs = {ICEMAN, FIG92, SPIRAL, TURRET}
check(all(g["a"] in programs and g["b"] in programs and g["winner"] in (g["a"], g["b"])
          and g["winner_side"] == ("A" if g["winner"] == g["a"] else "B") for g in table),
      f"games.csv names the programs: {table[:1]}")
md = (whole_t / "standings.md").read_text().splitlines()
check(len(md) == 6 and all(line.startswith("| ") and line.endswith(" |") for line in md)
      and md[0].split("|")[1:3] == [" rank ", md[0].split("|")[2]] and "program" in md[0]
      and set(md[1]) <= set("|-: ") and all(line.count("|") == 10 for line in md),
      "standings.md is a Markdown table: " + " / ".join(md[:3]))
check(sorted(line.split("|")[2].strip() for line in md[2:]) == sorted(programs),
      "standings.md has a row per program")
killed_t = OUT / "tournament-killed"
proc = start_and_wait(TOURNAMENT + ["--out", str(killed_t)], killed_t / "games.csv", 3)
proc.send_signal(signal.SIGKILL)
proc.wait()
check(0 < rows(killed_t / "games.csv") < 12, "SIGKILL half-way through the tournament")
r = subprocess.run(TOURNAMENT + ["--out", str(killed_t), "--resume"], capture_output=True,
                   text=True)
check(r.returncode == 0, f"tournament --resume exits 0: {r.stderr[-300:]}")
same_files(whole_t, killed_t, ["games.csv", "standings.json", "standings.md"],
           "tournament killed and resumed")

# ---- the output location is checked before any run; every write is checked
r = subprocess.run(BENCH + ["--out", "/dev/null"], capture_output=True, text=True)
check(r.returncode == 1 and "/dev/null" in r.stderr and "runs" not in r.stderr.split("\n")[0][:5],
      f"--out /dev/null is refused at once: {r.returncode} {r.stderr[-200:]}")
limited = OUT / "bench-fsize"
r = subprocess.run(["bash", "-c", "trap '' XFSZ; ulimit -f 4; exec \"$@\"", "bash"] + BENCH +
                   ["--out", str(limited)], capture_output=True, text=True)
check(r.returncode == 1 and "File too large" in r.stderr,
      f"a write past a 2-KiB file-size limit is an error: {r.returncode} {r.stderr[-300:]}")

# ---- --resume refuses another batch's table
other = [arg if arg != "20" else "21" for arg in BENCH]  # 21 simulated seconds a run
r = subprocess.run(other + ["--out", str(whole), "--resume"], capture_output=True, text=True)
check(r.returncode == 1 and "was run with seconds 20" in r.stderr and "not 21" in r.stderr,
      f"--resume with other settings is refused: {r.returncode} {r.stderr[-300:]}")

# ---- --resume keeps only this batch's rows, and only under the same simbot
def refused_resume(what, cmd, folder, table, words):
    """--resume is refused in one line holding `words`, and changes nothing."""
    before = {p.name: p.read_bytes() for p in folder.iterdir()}
    r = subprocess.run(cmd + ["--out", str(folder), "--resume"], capture_output=True, text=True)
    lines = [line for line in r.stderr.splitlines() if line.startswith("simbot:")]
    check(r.returncode == 1 and len(lines) == 1 and all(w in lines[0] for w in words),
          f"{what}: --resume refused in one line naming {words}: {r.returncode} {r.stderr[-400:]}")
    check({p.name: p.read_bytes() for p in folder.iterdir()} == before,
          f"{what}: the refused --resume changed nothing")


SMALL = [SIMBOT, "bench", ICEMAN, FIG92, "--family", "stationary", "--seeds", "3", "--seconds",
         "2", "--threads", "2"]
mine, other = OUT / "paste-mine", OUT / "paste-other"
subprocess.run(SMALL + ["--out", str(mine)], check=True, capture_output=True)
subprocess.run(SMALL + ["--seed", "2", "--out", str(other)], check=True, capture_output=True)
mine_rows = (mine / "runs.csv").read_bytes().split(b"\r\n")[:-1]  # header and 6 rows
other_rows = (other / "runs.csv").read_bytes().split(b"\r\n")[:-1]
# Row 4 of the table (ICEMAN's run 2) replaced by the bench with --seed 2's run 2, and the
# last rows dropped as by a kill: the same program and run index, another seed.
(mine / "runs.csv").write_bytes(b"\r\n".join(mine_rows[:3] + other_rows[3:4]) + b"\r\n")
pasted_seed = other_rows[3].split(b",")[2].decode()
refused_resume("bench, a row of another seed", SMALL, mine, "runs.csv",
               [f"{mine}/runs.csv:4:", f"seed {pasted_seed}", "run 2 of"])
# A row of a program this bench does not play.
(mine / "runs.csv").write_bytes(b"\r\n".join(mine_rows[:3] + [
    mine_rows[3].replace(ICEMAN.encode(), SPIRAL.encode())]) + b"\r\n")
refused_resume("bench, a row of another program", SMALL, mine, "runs.csv",
               [f"{mine}/runs.csv:4:", SPIRAL, "not one of this bench's runs"])
# The same row twice.
(mine / "runs.csv").write_bytes(b"\r\n".join(mine_rows[:4] + mine_rows[3:4]) + b"\r\n")
refused_resume("bench, a row twice", SMALL, mine, "runs.csv",
               [f"{mine}/runs.csv:5:", "twice"])

TWO = [SIMBOT, "tournament", ICEMAN, FIG92, SPIRAL, "--rounds", "1", "--seconds", "2"]
mine_t, other_t = OUT / "paste-mine-t", OUT / "paste-other-t"
subprocess.run(TWO + ["--out", str(mine_t)], check=True, capture_output=True)
subprocess.run(TWO + ["--seed", "2", "--out", str(other_t)], check=True, capture_output=True)
games_mine = (mine_t / "games.csv").read_bytes().split(b"\r\n")[:-1]
games_other = (other_t / "games.csv").read_bytes().split(b"\r\n")[:-1]
(mine_t / "games.csv").write_bytes(b"\r\n".join(games_mine[:2] + games_other[2:3]) + b"\r\n")
refused_resume("tournament, a game of another seed", TWO, mine_t, "games.csv",
               [f"{mine_t}/games.csv:3:", f"seed {games_other[2].split(b',')[5].decode()}",
                "pair 0-2 round 0"])

# Another simbot: batch.json records `simbot --version`, and --resume names both.
version = subprocess.run([SIMBOT, "--version"], capture_output=True, text=True).stdout.strip()
settings = json.loads((whole / "batch.json").read_text())
check(settings.get("simbot") == version, f"batch.json records {settings.get('simbot')!r}, "
      f"simbot --version says {version!r}")
older = "simbot 0.24.0 (commit 0123456789ab, RelWithDebInfo build, SUNDIALS 6.4.1)"
settings["simbot"] = older
(whole / "batch.json").write_text(json.dumps(settings, indent=2) + "\n")
refused_resume("bench, another simbot", BENCH, whole, "runs.csv",
               [f"was run by {older}, not {version}"])

if failures:
    sys.exit(f"{len(failures)} check(s) failed")
print("batch_test: all checks passed")
