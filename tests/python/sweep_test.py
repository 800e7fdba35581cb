"""simbot sweep gives one table whoever runs it: a 40-run sweep (2 programs
x 2 families x 2 values of eyes.noise_sigma x 5 seeds, 2 simulated seconds
each) on local threads, through --dask on a LocalCluster of 2 worker
processes this test starts, and in 3 shards concatenated, are identical
byte for byte; an interrupted table resumed with --resume is too. The
oracle for the rows themselves is simbot bench: a sweep row with master
seed S is the bench's run 0 with --seeds 1 --seed S under the same profile.

usage: sweep_test.py SIMBOT ICEMAN TURRET WORKDIR [--no-dask] (PYTHONPATH: build/python)

Through --dask, a program's compiler warning is printed once, with
progress lines and a last line; a refused address (tcp://127.0.0.1:9) is
one line, `simbot: --dask: ...`, in well under the 10-s connect timeout,
and leaves --out as it was. A Dask sweep keeps the local one's fingerprint:
killed with SIGKILL once it has written rows and resumed with --resume on
Dask, it gives the uninterrupted table byte for byte (and --resume of the
finished table changes nothing).

--resume refuses, in one line naming FILE:LINE and changing nothing, a row
pasted from the same sweep with another first seed, and a fingerprint that
another simbot version wrote (naming both).

--no-dask (the sanitizer builds, which have no Python module): everything
but the Dask run.
"""
import csv
import os
import shutil
import signal
import subprocess
import sys
import time

failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL:", what)


def read(path):
    with open(path, "rb") as f:
        return f.read()


def sweep(cli, sweep_file, *args):
    subprocess.run([cli, "sweep", sweep_file, *args], check=True, stderr=subprocess.DEVNULL)


# Dask starts its worker processes by spawning: they import this file, which
# must not run the test again.
if __name__ == "__main__":
    cli, iceman, turret, work = sys.argv[1:5]
    os.makedirs(work, exist_ok=True)
    sweep_file = os.path.join(work, "grid.toml")
    with open(sweep_file, "w", encoding="utf-8") as f:
        f.write(f'''programs = ["{iceman}", "{turret}"]
    families = ["stationary", "circle"]
    seconds = 2.0
    [seeds]
    first = 1
    count = 5
    [grid]
    "eyes.noise_sigma" = [0.0, 20.0]
    ''')

    local = os.path.join(work, "local.csv")
    sweep(cli, sweep_file, "--out", local, "--threads", "2")
    table = read(local)
    with open(local, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    check(len(rows) == 40, f"local: {len(rows)} rows, not 40")
    check([int(r["run"]) for r in rows] == list(range(40)), "local: runs not in index order")
    # Seeds vary fastest, then families, then programs, then the grid.
    check([r["master_seed"] for r in rows[:5]] == ["1", "2", "3", "4", "5"], "order: seeds")
    check(rows[5]["family"] == "circle" and rows[10]["program"] == turret, "order: family, program")
    check({r["eyes.noise_sigma"] for r in rows[:20]} == {"0.0"}
          and {r["eyes.noise_sigma"] for r in rows[20:]} == {"20.0"}, "order: grid last")

    # The oracle: simbot bench, one seed (run 7: iceman, circle, master seed 3).
    bench_out = os.path.join(work, "bench")
    subprocess.run([cli, "bench", iceman, "--family", "circle", "--seeds", "1", "--seed", "3",
                    "--seconds", "2", "--out", bench_out], check=True, capture_output=True)
    with open(os.path.join(bench_out, "runs.csv"), newline="", encoding="utf-8") as f:
        bench_row = next(csv.DictReader(f))
    row = rows[7]
    check(row["family"] == "circle" and row["master_seed"] == "3", "run 7 is not circle, seed 3")
    for key, value in bench_row.items():
        if key in ("program", "run"):
            continue
        mine = row["stream_seed" if key == "seed" else key]
        check(mine == value, f"run 7 vs bench: {key} {mine!r} != {value!r}")

    # Dask: a LocalCluster of 2 worker processes, its address given to --dask.
    if "--no-dask" not in sys.argv[5:]:
        from dask.distributed import LocalCluster
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        try:
            dask = os.path.join(work, "dask.csv")
            sweep(cli, sweep_file, "--out", dask, "--dask", cluster.scheduler_address)
            check(read(dask) == table, "dask: table differs from the local one")
            # A program with a compiler warning: printed once (not once per
            # worker), with progress lines and a last line.
            warned = os.path.join(work, "warned.dc")
            with open(iceman, encoding="utf-8") as f:
                source = f.read()
            with open(warned, "w", encoding="utf-8") as f:
                f.write(source + "\nunused() { return 1; return 2; }\n")
            small = os.path.join(work, "small.toml")
            with open(small, "w", encoding="utf-8") as f:
                f.write(f'programs = ["{warned}"]\nfamilies = ["stationary"]\nseconds = 1.0\n'
                        '[seeds]\ncount = 4\n')
            r = subprocess.run([cli, "sweep", small, "--out", os.path.join(work, "small.csv"),
                                "--dask", cluster.scheduler_address],
                               capture_output=True, text=True, timeout=120)
            lines = r.stderr.splitlines()
            check(r.returncode == 0, f"dask, warned program: status {r.returncode}: {r.stderr}")
            check(sum("warning: " in line and "unreachable" in line for line in lines) == 1,
                  f"dask: the warning is printed once: {lines}")
            check(any(line.startswith("sweep: 4/4 done in ") for line in lines)
                  and lines[-1].startswith("simbot: 4 runs (runs 0 to 4 of 4) on Dask"),
                  f"dask: progress and a last line: {lines}")
            # Dask sweeps resume as local ones do: a 30-s grid (80 runs of
            # some 20 ms each) killed with SIGKILL once its table has rows,
            # then --resume on Dask, gives the uninterrupted table; so does
            # --resume of a finished one, which runs nothing.
            long_file = os.path.join(work, "long.toml")
            with open(long_file, "w", encoding="utf-8") as f:
                f.write(f'programs = ["{iceman}", "{turret}"]\n'
                        'families = ["stationary", "circle"]\nseconds = 30.0\n'
                        '[seeds]\nfirst = 1\ncount = 10\n[grid]\n'
                        '"eyes.noise_sigma" = [0.0, 20.0]\n')
            long_whole = os.path.join(work, "long-local.csv")
            sweep(cli, long_file, "--out", long_whole, "--threads", "2")
            killed = os.path.join(work, "long-killed.csv")
            for stale in (killed, killed + ".batch.json"):
                if os.path.exists(stale):
                    os.remove(stale)
            proc = subprocess.Popen([cli, "sweep", long_file, "--out", killed, "--dask",
                                     cluster.scheduler_address], stderr=subprocess.DEVNULL)
            deadline = time.monotonic() + 60
            while time.monotonic() < deadline and proc.poll() is None:
                if os.path.exists(killed) and read(killed).count(b"\n") >= 4:
                    break
                time.sleep(0.002)
            proc.send_signal(signal.SIGKILL)
            proc.wait()
            kept = read(killed).count(b"\n") - 1
            print(f"dask: SIGKILL with {kept} of 80 rows in the table")
            check(proc.returncode == -signal.SIGKILL and 3 <= kept < 80,
                  f"dask, SIGKILL: status {proc.returncode}, {kept} of 80 rows kept")
            check(os.path.exists(killed + ".batch.json"), "dask: the fingerprint is kept")
            r = subprocess.run([cli, "sweep", long_file, "--out", killed, "--resume", "--dask",
                                cluster.scheduler_address], capture_output=True, text=True,
                               timeout=120)
            check(r.returncode == 0 and r.stderr.splitlines()[-1].startswith(
                f"simbot: 80 runs (runs 0 to 80 of 80) on Dask"),
                f"dask --resume after SIGKILL: status {r.returncode}, {r.stderr[-300:]}")
            check(read(killed) == read(long_whole),
                  "dask killed and resumed: the table differs from the uninterrupted one")
            check(read(killed + ".batch.json") == read(long_whole + ".batch.json"),
                  "dask and local sweeps keep the same fingerprint")
            r = subprocess.run([cli, "sweep", long_file, "--out", killed, "--resume", "--dask",
                                cluster.scheduler_address], capture_output=True, text=True,
                               timeout=120)
            check(r.returncode == 0 and read(killed) == read(long_whole),
                  f"dask --resume of a finished sweep: {r.returncode} {r.stderr[-300:]}")
        finally:
            cluster.close()
        # A refused address: one line, at once (Dask alone retries for 30 s).
        refused = os.path.join(work, "refused.csv")
        with open(refused, "w", encoding="utf-8") as f:
            f.write("an earlier table\n")
        started = time.monotonic()
        r = subprocess.run([cli, "sweep", sweep_file, "--out", refused,
                            "--dask", "tcp://127.0.0.1:9"], capture_output=True, text=True,
                           timeout=60)
        took = time.monotonic() - started
        lines = r.stderr.splitlines()
        check(r.returncode == 1 and len(lines) == 1 and lines[0].startswith("simbot: --dask: ")
              and "127.0.0.1:9" in lines[0],
              f"dask, refused address: status {r.returncode}, {r.stderr.strip()[-500:]}")
        check(took < 10, f"dask, refused address: {took:.1f} s")
        check(read(refused) == b"an earlier table\n", "dask, refused address: --out was touched")
        r = subprocess.run([cli, "sweep", sweep_file, "--out", os.path.join(work, "bad-addr.csv"),
                            "--dask", "local:x"], capture_output=True, text=True, timeout=60)
        check(r.returncode == 1 and r.stderr.count("\n") == 1
              and r.stderr.startswith("simbot: --dask: "),
              f"dask, local:x: status {r.returncode}, {r.stderr.strip()[-500:]}")

    # Three shards, the later two without the header, concatenated.
    parts = b""
    for k in (1, 2, 3):
        part = os.path.join(work, f"shard{k}.csv")
        sweep(cli, sweep_file, "--out", part, "--shard", f"{k}/3", *(["--no-header"] if k > 1 else []))
        parts += read(part)
    check(parts == table, "shards: concatenation differs from the whole table")

    # Resume: the table cut in the middle of row 17 is completed by --resume.
    cut = os.path.join(work, "cut.csv")
    shutil.copy(local + ".batch.json", cut + ".batch.json")  # the batch's fingerprint
    lines = table.split(b"\n")
    with open(cut, "wb") as f:
        f.write(b"\n".join(lines[:18]) + b"\n" + lines[18][:25])
    sweep(cli, sweep_file, "--out", cut, "--resume", "--threads", "2")
    check(read(cut) == table, "resume: table differs")

    # --resume keeps only this sweep's rows: row 4 (run 3) replaced by run 3
    # of the same sweep with first seed 100 (master seed 103, not 4) is
    # refused in one line naming the row, and nothing changes.
    other_file = os.path.join(work, "other.toml")
    with open(sweep_file, encoding="utf-8") as f:
        other_text = f.read().replace("first = 1", "first = 100")
    with open(other_file, "w", encoding="utf-8") as f:
        f.write(other_text)
    other = os.path.join(work, "other.csv")
    sweep(cli, other_file, "--out", other, "--threads", "2")
    pasted = os.path.join(work, "pasted.csv")
    shutil.copy(local + ".batch.json", pasted + ".batch.json")
    mine, theirs = table.split(b"\r\n"), read(other).split(b"\r\n")
    with open(pasted, "wb") as f:
        f.write(b"\r\n".join(mine[:4] + theirs[4:5] + mine[5:8]) + b"\r\n")
    before = read(pasted)

    def refused_resume(what, *words):
        r = subprocess.run([cli, "sweep", sweep_file, "--out", pasted, "--resume"],
                           capture_output=True, text=True)
        # Not the compiler's warnings (each with its source line and caret).
        lines = [line for line in r.stderr.splitlines()
                 if line.startswith("simbot:") or ": error: " in line]
        check(r.returncode == 1 and len(lines) == 1 and all(w in lines[0] for w in words),
              f"{what}: status {r.returncode}, {r.stderr.strip()[-500:]}")
        check(read(pasted) == before, f"{what}: the table changed")

    refused_resume("a pasted row of another master seed", f"{pasted}:5: error: --resume:",
                   "run 3's master_seed is '103'", "has '4'")
    # Another simbot version began it: both named.
    import json
    with open(pasted + ".batch.json", encoding="utf-8") as f:
        fingerprint = json.load(f)
    version = subprocess.run([cli, "--version"], capture_output=True, text=True).stdout.strip()
    check(fingerprint.get("simbot") == version, f"the fingerprint records {fingerprint.get('simbot')}")
    fingerprint["simbot"] = "simbot 0.1.0 (commit 0123456789ab, Debug build, SUNDIALS 6.4.1)"
    with open(pasted + ".batch.json", "w", encoding="utf-8") as f:
        json.dump(fingerprint, f)
    refused_resume("another simbot's sweep",
                   f"was run by {fingerprint['simbot']}, not {version}")

    # A sweep naming a key the profile does not have is an error, exit 1.
    bad = os.path.join(work, "bad.toml")
    with open(bad, "w", encoding="utf-8") as f:
        f.write(f'programs = ["{iceman}"]\nfamilies = ["edge"]\n[seeds]\ncount = 1\n'
                '[grid]\n"eyes.no_such_key" = [1.0]\n')
    r = subprocess.run([cli, "sweep", bad, "--out", os.path.join(work, "bad.csv")],
                       capture_output=True, text=True)
    check(r.returncode == 1 and "no profile key 'eyes.no_such_key'" in r.stderr,
          f"bad key: status {r.returncode}, {r.stderr.strip()}")


    print("sweep_test:", "FAILED" if failures else "ok")
    sys.exit(1 if failures else 0)
