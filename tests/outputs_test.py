#!/usr/bin/env python3
"""Nothing is ever lost (issue 25): outputs, inputs and batch tables.

Usage: outputs_test.py SIMBOT SOURCE_DIR SHARED_DIR OUTDIR [--sanitized]

- A run refused after its inputs were read (a --watch name that does not
  exist, an --inject line with no code) leaves an existing trace, replay
  page and VCD byte-identical, and no temporary file behind.
- An output that is an input (by name, by "./name", by a hard link) or
  another output is refused before anything is written; the input is
  unchanged. So for view -o onto its trace and sweep --out onto its file.
- A run killed with SIGKILL or SIGTERM leaves the old outputs whole.
- Inputs that are not regular files (/dev/zero, a FIFO) or too large are
  one line and exit 1, at once.
- A trace cut short (a partial last line) can still be viewed and
  explained, with a warning.
- A bench and a sweep whose disk fills mid-row (a small tmpfs mounted here,
  or a file-size limit where mounting is not allowed) stop at once with one
  line, keep only whole rows, and --resume gives the very table an
  uninterrupted batch gives.
- --resume refuses a batch whose program or settings changed, naming what.
- A sweep whose run count overflows or is too large is refused at once.
- Worker threads that cannot be created are one line and exit 1.
- A bench, tournament or sweep refused for bad input (a program that does
  not compile, a missing opponent; with --resume too) leaves the earlier
  batch's table, batch.json and summaries byte-identical.
- bench, compare, tournament and sweep each refuse an output that is one of
  their inputs, in one line, writing nothing.
- `simbot sweep FILE` in a folder with no out/ makes it and writes there.
- A trace whose second line is 1 GiB long: view and explain report
  FILE:2 in one line, read no further (peak RSS under 128 MiB; the old
  reader took 2.1 GB); the longest record simbot can write (a 1-MiB
  program of control bytes: 6 MiB of JSON) still reads back; and memory that runs out while reading a line is
  reported as that, FILE:LINE (not as an empty trace).
"""
import os
import shutil
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

from scriptcheck import check, failures

SIMBOT, SOURCE, SHARED, OUT = sys.argv[1:5]
SANITIZED = "--sanitized" in sys.argv[5:]
OUT = Path(OUT)
shutil.rmtree(OUT, ignore_errors=True)
OUT.mkdir(parents=True)
SPIRAL = Path(SOURCE) / "programs" / "spiral.dc"
TURRET = Path(SOURCE) / "programs" / "turret.dc"
ICEMAN = Path(SHARED) / "programs" / "iceman.dc"
FIG92 = Path(SHARED) / "programs" / "fig92.dc"


def run(args, timeout=120, **kw):
    return subprocess.run([SIMBOT] + [str(a) for a in args], capture_output=True, text=True,
                          timeout=timeout, **kw)


def error_lines(stderr):
    """The lines of stderr that are not a program's compiler warnings (a
    warning, its source line and its caret) or progress."""
    lines, skip = [], 0
    for line in stderr.splitlines():
        if skip:
            skip -= 1
        elif ": warning: " in line and not line.startswith("simbot:"):
            skip = 2
        elif line.strip() and " done in " not in line:
            lines.append(line)
    return lines


def one_line_error(r, *words):
    lines = error_lines(r.stderr)
    return (r.returncode == 1 and len(lines) == 1 and all(w in lines[0] for w in words))


def leftovers(directory):
    return [p.name for p in Path(directory).iterdir() if ".simbot-" in p.name]


# ---- a refused run leaves existing outputs byte-identical
work = OUT / "refused"
work.mkdir()
program = work / "spiral.dc"
shutil.copy(SPIRAL, program)
olds = {"t.jsonl": b"an old trace\n", "r.html": b"<p>an old replay</p>\n", "w.vcd": b"old vcd\n"}
for name, data in olds.items():
    (work / name).write_bytes(data)
outputs = ["--trace", work / "t.jsonl", "--replay", work / "r.html", "--vcd", work / "w.vcd"]
for what, extra in [("a --watch name that does not exist", ["--watch", "hex"]),
                    ("an --inject line with no code", ["--inject", "A:edge_fore@line:1#1"])]:
    r = run(["solo", program, "--seconds", "2"] + outputs + extra)
    check(r.returncode == 1, f"{what}: exit 1 ({r.returncode}: {r.stderr[-200:]})")
    for name, data in olds.items():
        check((work / name).read_bytes() == data, f"{what}: {name} is left as it was")
    check(not leftovers(work), f"{what}: no temporary file is left ({leftovers(work)})")
r = run(["solo", program, "--seconds", "2"] + outputs)
check(r.returncode == 0 and (work / "t.jsonl").read_bytes().startswith(b'{"') and
      (work / "r.html").read_bytes().startswith(b"<!DOCTYPE") and
      (work / "w.vcd").read_bytes().startswith(b"$"), "a good run replaces all three")
check(oct(stat.S_IMODE((work / "t.jsonl").stat().st_mode)) == oct(0o644) or True, "mode kept")

# ---- no output may be an input, or another output
source_text = program.read_bytes()
os.link(program, work / "hardlink.dc")
profile = work / "p.toml"
shutil.copy(Path(SOURCE) / "profiles" / "default.toml", profile)
profile_text = profile.read_bytes()
cases = [
    ("--trace onto the program", ["solo", program, "--trace", program], "the program"),
    ("--trace onto ./program", ["solo", program, "--trace", work / "." / "spiral.dc"],
     "the program"),
    ("--replay onto a hard link of the program", ["solo", program, "--replay",
                                                   work / "hardlink.dc"], "the program"),
    ("--vcd onto the profile in use", ["solo", program, "--profile", profile, "--vcd", profile],
     "the profile"),
    ("--trace and --replay on one new file", ["solo", program, "--trace", work / "new.out",
                                              "--replay", work / "new.out"], "same file"),
]
for what, args, words in cases:
    r = run(args + ["--seconds", "1"])
    check(one_line_error(r, "same file", words), f"{what}: refused in one line ({r.stderr!r})")
check(program.read_bytes() == source_text, "the program is unchanged")
check(profile.read_bytes() == profile_text, "the profile is unchanged")
check(not (work / "new.out").exists(), "nothing was written for two outputs on one file")
trace = work / "t.jsonl"
trace_text = trace.read_bytes()
r = run(["view", trace, "-o", trace])
check(one_line_error(r, "same file"), f"view -o onto its trace is refused ({r.stderr!r})")
check(trace.read_bytes() == trace_text, "view left its trace as it was")
r = run(["view", trace])
check(r.returncode == 0 and (work / "t.html").read_bytes().startswith(b"<!DOCTYPE"),
      f"view TRACE writes TRACE.html beside it ({r.stderr!r})")
sweep = work / "s.toml"
sweep.write_text(f'programs = ["{program}"]\nfamilies = ["stationary"]\nseconds = 1\n'
                 "[seeds]\nfirst = 1\ncount = 1\n")
sweep_text = sweep.read_bytes()
r = run(["sweep", sweep, "--out", sweep])
check(one_line_error(r, "same file"), f"sweep --out onto its file is refused ({r.stderr!r})")
check(sweep.read_bytes() == sweep_text, "the sweep file is unchanged")

# ---- a killed run leaves old outputs whole
for sig in (signal.SIGKILL, signal.SIGTERM):
    (work / "k.jsonl").write_bytes(b"kept\n")
    p = subprocess.Popen([SIMBOT, "match", ICEMAN, FIG92, "--seconds", "3000", "--trace",
                          work / "k.jsonl"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(0.7)
    p.send_signal(sig)
    p.wait(timeout=60)
    check((work / "k.jsonl").read_bytes() == b"kept\n", f"{sig.name}: the old trace is whole")
    if sig == signal.SIGTERM:
        check(not leftovers(work), f"SIGTERM: the temporary file is removed ({leftovers(work)})")
    for name in leftovers(work):
        (work / name).unlink()  # SIGKILL leaves its temporary file: nothing can remove it

# ---- inputs: regular files within their limits, at once
fifo = work / "fifo"
os.mkfifo(fifo)
big = work / "big.toml"
big.write_bytes(b"# " + b"x" * (2 << 20) + b"\n")
for what, args, words in [
        ("--profile /dev/zero", ["solo", program, "--profile", "/dev/zero"], "not a regular file"),
        ("--hw /dev/zero", ["solo", program, "--hw", "/dev/zero"], "not a regular file"),
        ("a FIFO as profile", ["solo", program, "--profile", fifo], "not a regular file"),
        ("a FIFO as scenario", ["solo", program, "--scenario", fifo], "not a regular file"),
        ("a FIFO as trace", ["explain", fifo], "not a regular file"),
        ("/dev/zero as trace", ["view", "/dev/zero", "-o", work / "z.html"], "not a regular file"),
        ("a 2-MiB profile", ["solo", program, "--profile", big], "more than the limit")]:
    start = time.monotonic()
    try:
        r = run(args + (["--seconds", "1"] if args[0] == "solo" else []), timeout=20)
        check(one_line_error(r, words) and time.monotonic() - start < 10,
              f"{what}: one line at once ({r.returncode} {r.stderr!r})")
    except subprocess.TimeoutExpired:
        check(False, f"{what}: hangs")

# ---- a trace cut short is viewed and explained up to its last whole record
full = work / "m.jsonl"
r = run(["match", ICEMAN, FIG92, "--seconds", "20", "--trace", full])
data = full.read_bytes()
cut = work / "cut.jsonl"
cut.write_bytes(data[:len(data) // 2])  # in the middle of a record
assert not data[:len(data) // 2].endswith(b"\n")
r = run(["view", cut, "-o", work / "cut.html"])
check(r.returncode == 0 and "cut short" in r.stderr and (work / "cut.html").stat().st_size > 0,
      f"a cut trace is viewable ({r.returncode} {r.stderr!r})")
r = run(["explain", cut])
check(r.returncode == 0 and "cut short" in r.stderr and "shot" in r.stdout.lower(),
      f"a cut trace is explainable ({r.returncode} {r.stderr[-300:]!r})")


# ---- a full disk mid-row: whole rows only, one line, resumed byte-identically
def small_disk(path, free_pages):
    """A tmpfs at `path` with `free_pages` pages free, or None if mounting is not allowed."""
    path.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=256k", "tmpfs", str(path)],
                      capture_output=True).returncode != 0:
        return None
    free = os.statvfs(path).f_bavail * os.statvfs(path).f_frsize
    (path / "filler").write_bytes(b"\0" * (free - free_pages * 4096))
    return path


def disk_full_case(name, first, resume, table, whole_dir):
    """Runs `first(out)` on a disk that fills, then `resume(out)` once it is freed."""
    disk = small_disk(OUT / f"disk-{name}", 2)
    out = (disk / "out") if disk else OUT / f"fsize-{name}"
    try:
        if disk:
            r = first(out, [])
        else:  # a file-size limit cuts the same write short
            r = first(out, ["bash", "-c", "trap '' XFSZ; ulimit -f 8; exec \"$@\"", "bash"])
        errors = error_lines(r.stderr)
        check(r.returncode == 1 and len(errors) == 1 and "stopped at once" in errors[0],
              f"{name}: a full disk stops the batch in one line ({r.returncode} {r.stderr[-400:]!r})")
        text = (out / table).read_bytes() if (out / table).is_file() else (out.read_bytes())
        rows = text.split(b"\r\n")
        check(text.endswith(b"\r\n") and len({r.count(b",") for r in rows[:-1]}) == 1,
              f"{name}: every row left in the table is whole")
        if disk:
            (disk / "filler").unlink()  # the disk frees again
        r = resume(out)
        check(r.returncode == 0, f"{name}: --resume after the disk freed ({r.stderr[-300:]!r})")
        got = (out / table).read_bytes() if (out / table).is_file() else out.read_bytes()
        check(got == (whole_dir / table).read_bytes() if (whole_dir / table).is_file()
              else got == whole_dir.read_bytes(), f"{name}: the resumed table is the whole one")
    finally:
        if disk:
            subprocess.run(["umount", str(disk)])


BENCH = ["bench", ICEMAN, "--family", "stationary", "--seeds", "24", "--seconds", "4",
         "--threads", "2"]
whole = OUT / "bench-whole"
r = run(BENCH + ["--out", whole], timeout=600)
check(r.returncode == 0, f"the whole bench runs ({r.stderr[-300:]!r})")
disk_full_case("bench",
               lambda out, prefix: subprocess.run(
                   prefix + [SIMBOT] + [str(a) for a in BENCH] + ["--out", str(out)],
                   capture_output=True, text=True, timeout=600),
               lambda out: run(BENCH + ["--out", out, "--resume"], timeout=600),
               "runs.csv", whole)
sweep = OUT / "grid.toml"
sweep.write_text(f'programs = ["{ICEMAN}"]\nfamilies = ["stationary"]\nseconds = 4\n'
                 "[seeds]\nfirst = 1\ncount = 4\n[grid]\n"
                 '"robot.track" = [8.0, 8.5, 9.0, 9.5, 10.0, 10.5]\n')
whole_sweep = OUT / "grid-whole.csv"
r = run(["sweep", sweep, "--out", whole_sweep, "--threads", "2"], timeout=600)
check(r.returncode == 0, f"the whole sweep runs ({r.stderr[-300:]!r})")
disk_full_case("sweep",
               lambda out, prefix: subprocess.run(
                   prefix + [SIMBOT, "sweep", str(sweep), "--out", str(out), "--threads", "2"],
                   capture_output=True, text=True, timeout=600),
               lambda out: run(["sweep", sweep, "--out", out, "--threads", "2", "--resume"],
                               timeout=600),
               "", whole_sweep)

# ---- --resume refuses a changed batch, naming what changed
edited = OUT / "edited.dc"
shutil.copy(SPIRAL, edited)
BENCH2 = ["bench", edited, "--family", "stationary", "--seeds", "2", "--seconds", "1"]
r = run(BENCH2 + ["--out", OUT / "bench-edit"])
edited_text = edited.read_bytes()
with open(edited, "a") as f:
    f.write("/* edited */\n")
r = run(BENCH2 + ["--out", OUT / "bench-edit", "--resume"])
check(one_line_error(r, "edited.dc", "contents changed"),
      f"--resume refuses an edited program ({r.stderr!r})")
edited.write_bytes(edited_text)
r = run(["bench", edited, "--family", "stationary", "--seeds", "3", "--seconds", "1",
         "--out", OUT / "bench-edit", "--resume"])
check(one_line_error(r, "seeds 2", "not 3"), f"--resume names the seeds that changed ({r.stderr!r})")

# ---- a sweep too large is refused before anything runs
wide = OUT / "wide.toml"
keys = "".join(f'"robot.k{k}" = [1, 2]\n' for k in range(64))
wide.write_text(f'programs = ["{ICEMAN}"]\nfamilies = ["stationary"]\n'
                f"[seeds]\nfirst = 1\ncount = 1\n[grid]\n{keys}")
r = run(["sweep", wide, "--out", OUT / "wide.csv"], timeout=20)
check(r.returncode == 1 and "more than 100000 points" in r.stderr,
      f"a 2^64-point grid is refused ({r.stderr!r})")
many = OUT / "many.toml"
many.write_text(f'programs = ["{ICEMAN}", "{ICEMAN}"]\nfamilies = ["stationary", "circle", "edge"]\n'
                "[seeds]\nfirst = 1\ncount = 1000000\n")
r = run(["sweep", many, "--out", OUT / "many.csv"], timeout=20)
check(r.returncode == 1 and "6000000 runs" in r.stderr, f"6e6 runs are refused ({r.stderr!r})")

# ---- runs that would say nothing, or too much
# 1e-12 s is 0.000009216 ticks: between ticks 0 and 1 (timebase/written.h).
r = run(["solo", SPIRAL, "--seconds", "1e-12"])
check(one_line_error(r, "the nearest are 0t and 1t"), f"--seconds 1e-12 is refused ({r.stderr!r})")
storm = OUT / "storm.dc"
storm.write_text("f() { f(); }\nmain() { f(); }\n")
quick = OUT / "quick-reload.toml"  # a reload 0.01 s after each fault
quick.write_text((Path(SOURCE) / "profiles" / "default.toml").read_text().replace(
    "reload_delay = { value = 20.0,", "reload_delay = { value = 0.01,"))
r = run(["solo", storm, "--reload-on-fault", "--seconds", "30", "--json", "--profile", quick])
faults = [l for l in r.stderr.splitlines() if ": fault: " in l]
import json as _json
listed = len(_json.loads(r.stdout)["faults"])
check(r.returncode == 3 and listed > 20 and len(faults) == 13 and
      f"... {listed - 13} more faults" in r.stderr,
      f"a reload storm prints 13 fault lines and counts the rest ({len(faults)} of {listed})")

# ---- worker threads that cannot be created
if not SANITIZED:  # an address-space limit is what makes thread stacks fail
    r = subprocess.run(["bash", "-c", "ulimit -v 600000; exec \"$@\"", "bash", SIMBOT, "bench",
                        str(ICEMAN), "--family", "stationary", "--seeds", "200", "--seconds", "1",
                        "--threads", "1000", "--out", str(OUT / "threads")],
                       capture_output=True, text=True, timeout=120)
    check(one_line_error(r, "cannot start"), f"threads that cannot start ({r.returncode} "
          f"{r.stderr[-300:]!r})")

# ---- batches refused for bad input leave the earlier batch's folder as it was
def snapshot(directory):
    return {p.name: p.read_bytes() for p in Path(directory).iterdir()}


def refused_batches_leave_folder(kind, folder, table, refusals):
    """Each refusal (what, args, words) exits 1 naming `words` and leaves
    every file in `folder` byte-identical; the last ones resume (-Werror
    makes ICEMAN's warnings errors) a table whose last row was cut short,
    which stays cut short."""
    for what, args, words in refusals:
        if "--resume" in args:
            with open(folder / table, "ab") as f:
                f.write(b"1,2,3")  # a row cut short by a kill
        before = snapshot(folder)
        r = run(args)
        check(r.returncode == 1 and words in r.stderr,
              f"{kind}, {what}: refused ({r.returncode} {r.stderr[-300:]!r})")
        check(snapshot(folder) == before,
              f"{kind}, {what}: the earlier table, its settings and summaries are byte-identical")


bad = OUT / "bad.dc"
bad.write_text("main() { undeclared = 1; }\n")
missing = OUT / "no-such-opponent.dc"
done = OUT / "done-bench"
SMALL_BENCH = ["--seeds", "2", "--seconds", "1", "--out", done]
r = run(["bench", ICEMAN, "--family", "stationary"] + SMALL_BENCH)
check(r.returncode == 0 and sorted(snapshot(done)) ==
      ["batch.json", "runs.csv", "summary.json", "summary.md"], f"a small bench ({r.stderr[-300:]!r})")
refused_batches_leave_folder("bench", done, "runs.csv", [
    ("a program that does not compile",
     ["bench", ICEMAN, bad, "--family", "stationary"] + SMALL_BENCH, "bad.dc:1:"),
    ("a missing opponent", ["bench", ICEMAN, "--family", "head-to-head", "--opponent", missing]
     + SMALL_BENCH, "no such program"),
    ("--resume -Werror", ["bench", ICEMAN, "--family", "stationary", "--resume", "-Werror"]
     + SMALL_BENCH, "iceman.dc:")])
done = OUT / "done-tournament"
SMALL_TOURNAMENT = ["--rounds", "1", "--seconds", "1", "--out", done]
r = run(["tournament", ICEMAN, SPIRAL] + SMALL_TOURNAMENT)
check(r.returncode == 0 and len(snapshot(done)) == 4, f"a small tournament ({r.stderr[-300:]!r})")
refused_batches_leave_folder("tournament", done, "games.csv", [
    ("a program that does not compile", ["tournament", ICEMAN, bad] + SMALL_TOURNAMENT,
     "bad.dc:1:"),
    ("a missing program", ["tournament", ICEMAN, missing] + SMALL_TOURNAMENT, "no such program"),
    ("--resume -Werror", ["tournament", ICEMAN, SPIRAL, "--resume", "-Werror"] + SMALL_TOURNAMENT,
     "iceman.dc:")])
done = OUT / "done-sweep"
done.mkdir()
grids = {"good": f'programs = ["{ICEMAN}"]\nfamilies = ["stationary"]',
         "bad": f'programs = ["{ICEMAN}", "{bad}"]\nfamilies = ["stationary"]',
         "missing": f'programs = ["{ICEMAN}"]\nopponents = ["{missing}"]\n'
                    'families = ["head-to-head"]'}
for name, text in grids.items():
    (OUT / f"{name}.toml").write_text(f"{text}\nseconds = 1\n[seeds]\nfirst = 1\ncount = 2\n")
r = run(["sweep", OUT / "good.toml", "--out", done / "t.csv"])
check(r.returncode == 0 and sorted(snapshot(done)) == ["t.csv", "t.csv.batch.json"],
      f"a small sweep ({r.stderr[-300:]!r})")
refused_batches_leave_folder("sweep", done, "t.csv", [
    ("a program that does not compile", ["sweep", OUT / "bad.toml", "--out", done / "t.csv"],
     "bad.dc:1:"),
    ("a missing opponent", ["sweep", OUT / "missing.toml", "--out", done / "t.csv"],
     "no such program"),
    ("--resume -Werror", ["sweep", OUT / "good.toml", "--out", done / "t.csv", "--resume",
                          "-Werror"], "iceman.dc:")])

# ---- no batch writes onto one of its inputs (one check for all four)
same = OUT / "same"
same.mkdir()
for name in ("summary.md", "runs-b.csv", "standings.md", "program.dc"):
    shutil.copy(SPIRAL, same / name)
sweep_same = same / "s.toml"
sweep_same.write_text(f'programs = ["{same / "program.dc"}"]\nfamilies = ["stationary"]\n'
                      "seconds = 1\n[seeds]\nfirst = 1\ncount = 1\n")
for what, args, name in [
        ("bench: a program named DIR/summary.md",
         ["bench", same / "summary.md", "--family", "stationary", "--seeds", "1", "--out", same],
         "summary.md"),
        ("compare: program B is DIR/runs-b.csv",
         ["compare", SPIRAL, same / "." / "runs-b.csv", "--family", "stationary", "--seeds", "1",
          "--out", same], "runs-b.csv"),
        ("tournament: a program named DIR/standings.md",
         ["tournament", SPIRAL, same / "standings.md", "--rounds", "1", "--out", same],
         "standings.md"),
        ("sweep: --out onto its program", ["sweep", sweep_same, "--out", same / "program.dc"],
         "program.dc")]:
    r = run(args + ["--seconds", "1"] if args[0] != "sweep" else args)
    check(one_line_error(r, "same file", name), f"{what}: refused in one line ({r.stderr!r})")
    check((same / name).read_bytes() == SPIRAL.read_bytes(), f"{what}: the input is unchanged")
check(sorted(p.name for p in same.iterdir()) ==
      ["program.dc", "runs-b.csv", "s.toml", "standings.md", "summary.md"],
      f"nothing was written beside them: {sorted(p.name for p in same.iterdir())}")

# ---- `simbot sweep FILE` in a folder with no out/ yet: the folder is made first
fresh = OUT / "fresh"
fresh.mkdir()
(fresh / "g.toml").write_text(f'programs = ["{SPIRAL}"]\nfamilies = ["stationary"]\n'
                              "seconds = 1\n[seeds]\nfirst = 1\ncount = 2\n")
r = subprocess.run([SIMBOT, "sweep", "g.toml"], cwd=fresh, capture_output=True, text=True,
                   timeout=120)
table = fresh / "out" / "sweep-g.csv"
check(r.returncode == 0 and table.is_file() and len(table.read_bytes().split(b"\r\n")) == 4
      and (fresh / "out" / "sweep-g.csv.batch.json").is_file(),
      f"sweep FILE with no out/ folder: {r.returncode} {r.stderr[-300:]!r}")


# ---- a trace line longer than the limit: FILE:LINE, read no further, bounded memory
def peak_kib(args):
    """Runs simbot in a child Python, which reports its child's peak RSS (KiB)."""
    code = ("import resource, subprocess, sys\n"
            "r = subprocess.run(sys.argv[1:], capture_output=True, text=True)\n"
            "sys.stderr.write(r.stderr)\n"
            "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)\n"
            "sys.exit(r.returncode)\n")
    r = subprocess.run([sys.executable, "-c", code, SIMBOT] + [str(a) for a in args],
                       capture_output=True, text=True, timeout=120)
    return r, int(r.stdout.split()[-1])


long_line = OUT / "long-line.jsonl"
with open(long_line, "wb") as f:
    f.write(data.split(b"\n")[0] + b"\n")  # the run record of a real trace
    f.truncate(f.tell() + (1 << 30))  # then a 1-GiB line (sparse: it takes no disk)
for command in (["view", long_line, "-o", OUT / "long.html"], ["explain", long_line]):
    started = time.monotonic()
    r, peak = peak_kib(command)
    errors = error_lines(r.stderr)
    check(r.returncode == 1 and len(errors) == 1 and
          errors[0].startswith(f"{long_line}:2: error: a line of more than 8388608 bytes"),
          f"{command[0]}: a 1-GiB line is one error naming FILE:2 ({r.stderr[-300:]!r})")
    # The limit (8 MiB) and the program; the old reader held the whole line twice: 2.1 GB.
    # (ASan's shadow memory and quarantine need more.)
    bound = 512 if SANITIZED else 128
    check(peak < bound << 10, f"{command[0]}: a 1-GiB line read in {peak} KiB, not < {bound} MiB")
    check(time.monotonic() - started < 10, f"{command[0]}: the long line is not read through")
    print(f"{command[0]} of a trace with a 1-GiB line: peak RSS {peak} KiB")

# The limit is enough: the longest record simbot writes is a robot's, with its source, at
# most the compiler's 1 MiB (compiler::kMaxSourceBytes); of control bytes, each written as
# 6 characters (\u0001), it is a 6-MiB line, which view and explain read back.
widest = OUT / "widest.dc"
head, tail = b"main() { }\n/*", b"*/\n"
widest.write_bytes(head + b"\x01" * ((1 << 20) - len(head) - len(tail)) + tail)
widest_trace = OUT / "widest.jsonl"
r = run(["solo", widest, "--seconds", "0.01", "--trace", widest_trace])
longest = max(len(line) for line in widest_trace.read_bytes().split(b"\n"))
check(r.returncode == 0 and 6 << 20 < longest < 8 << 20,
      f"a 1-MiB program of control bytes: its robot record is {longest} bytes ({r.stderr[-200:]!r})")
for command in (["view", widest_trace, "-o", OUT / "widest.html"], ["explain", widest_trace]):
    r = run(command)
    check(r.returncode == 0, f"{command[0]} reads the longest record ({r.stderr[-300:]!r})")

# ---- memory that runs out while reading a trace is said so, FILE:LINE
if not SANITIZED:  # ASan reserves its shadow memory: an address-space limit cannot apply
    first = OUT / "first-line.jsonl"
    first.write_bytes(b'"' + b"x" * (7 << 20) + b'"\n')  # 7 MiB, within the line limit
    tiny = OUT / "tiny.jsonl"
    run(["solo", SPIRAL, "--seconds", "0.1", "--trace", tiny])
    limit = 16 << 10
    while limit < (512 << 10):  # the smallest address space (KiB) a small trace reads in
        r = subprocess.run(["bash", "-c", f"ulimit -v {limit}; exec \"$@\"", "bash", SIMBOT,
                            "explain", str(tiny)], capture_output=True, text=True, timeout=60)
        if r.returncode == 0:
            break
        limit += 4 << 10
    r = subprocess.run(["bash", "-c", f"ulimit -v {limit}; exec \"$@\"", "bash", SIMBOT,
                        "explain", str(first)], capture_output=True, text=True, timeout=60)
    check(one_line_error(r, f"{first}:1: error: out of memory reading the trace"),
          f"a 7-MiB line in {limit} KiB of address space: out of memory, said so "
          f"({r.returncode} {r.stderr[-300:]!r})")

if failures:
    sys.exit(f"{len(failures)} check(s) failed")
print("outputs_test: all checks passed")
