#!/usr/bin/env python3
"""Options every command shares (issue 25, item 5):

  - simbot --version names the version, the commit, the build type and
    SUNDIALS' version;
  - every command that compiles a program takes -Wno-NAME and -Werror:
    ICEMAN's implicit declarations (five warnings with Figure 9.2) are
    silenced by -Wno-implicit-function-declaration and made an error by
    -Werror; an unknown warning name is one line and exit status 1;
  - sweep --dask refuses -W options (its workers compile with the
    defaults) in one line.

Usage: cli_options_test.py SIMBOT SOURCE_DIR SHARED_DIR WORKDIR
"""
import os
import re
import subprocess
import sys

SIMBOT, SOURCE, SHARED, WORK = sys.argv[1:5]
os.makedirs(WORK, exist_ok=True)
ICEMAN = os.path.join(SHARED, "programs/iceman.dc")
FIG92 = os.path.join(SHARED, "programs/fig92.dc")
TURRET = os.path.join(SOURCE, "programs/turret.dc")
failures = []


def check(condition, message):
    if not condition:
        failures.append(message)


def run(*args):
    return subprocess.run([SIMBOT, *args], cwd=WORK, capture_output=True, text=True, timeout=300,
                          stdin=subprocess.DEVNULL)


version = run("--version")
check(version.returncode == 0 and re.fullmatch(
    r"simbot \d+\.\d+\.\d+ \(commit \S+, \S+ build, SUNDIALS \d+\.\d+\.\d+\)\n", version.stdout),
    f"--version: {version.stdout!r}")

sweep_file = os.path.join(WORK, "small.toml")
with open(sweep_file, "w") as f:
    f.write(f'programs = ["{ICEMAN}"]\nfamilies = ["stationary"]\nseconds = 1.0\n'
            '[seeds]\ncount = 1\n')
batch = os.path.join(WORK, "quit.gdb")
with open(batch, "w") as f:
    f.write("quit\n")

# Each command, as it compiles ICEMAN (and Figure 9.2 where it takes two).
commands = {
    "solo": ["solo", ICEMAN, "--seconds", "1"],
    "match": ["match", ICEMAN, FIG92, "--seconds", "1"],
    "profile": ["profile", ICEMAN, "--seconds", "1"],
    "debug": ["debug", ICEMAN, FIG92, "--batch", batch],
    "bench": ["bench", ICEMAN, "--family", "stationary", "--seeds", "1", "--seconds", "1",
              "--out", os.path.join(WORK, "bench")],
    "compare": ["compare", ICEMAN, TURRET, "--family", "stationary", "--seeds", "1",
                "--seconds", "1", "--out", os.path.join(WORK, "compare")],
    "tournament": ["tournament", ICEMAN, TURRET, "--rounds", "1", "--seconds", "1",
                   "--out", os.path.join(WORK, "tournament")],
    "sweep": ["sweep", sweep_file, "--out", os.path.join(WORK, "sweep.csv")],
    "compile": ["compile", ICEMAN],
}
for name, args in commands.items():
    plain = run(*args)
    check("implicit declaration of function" in plain.stderr,
          f"{name}: no warning without -W options: {plain.stderr[-300:]}")
    quiet = run(*args, "-Wno-implicit-function-declaration")
    check(quiet.returncode == 0, f"{name} -Wno-...: status {quiet.returncode}: {quiet.stderr[-300:]}")
    check("warning" not in quiet.stderr, f"{name} -Wno-...: a warning left: {quiet.stderr[-300:]}")
    strict = run(*args, "-Werror")
    check(strict.returncode == 1 and "error" in strict.stderr,
          f"{name} -Werror: status {strict.returncode}: {strict.stderr[-300:]}")
    bad = run(*args, "-Wno-nosuch")
    lines = bad.stderr.strip().splitlines()
    check(bad.returncode == 1 and len(lines) == 1 and "unknown option '-Wno-nosuch'" in lines[0],
          f"{name} -Wno-nosuch: status {bad.returncode}: {bad.stderr[-300:]}")

dask = run("sweep", sweep_file, "--out", os.path.join(WORK, "dask.csv"), "--dask", "local:1",
           "-Wno-implicit-function-declaration")
lines = dask.stderr.strip().splitlines()
check(dask.returncode == 1 and len(lines) == 1 and "-W options" in lines[0],
      f"sweep --dask -W: status {dask.returncode}: {dask.stderr[-300:]}")

for f in failures:
    print("FAIL:", f)
print("cli options:", "ok" if not failures else f"{len(failures)} failures")
sys.exit(1 if failures else 0)
