#!/usr/bin/env python3
"""Every command the README and the manual show runs as written.

Usage: readme_test.py SIMBOT WORKDIR README [PAGE...]

Each ```sh block of the README, then of each manual page (docs/*.md) in
the order given, runs with bash -e, in a sandbox
laid out like the project's checkout (WORKDIR/main holding build/bin/simbot,
programs/, scenarios/, profiles/, checks/, tests/, bench/, docs/, scripts/, the bench binaries
and build/python,
beside WORKDIR/shared), so that
the files a command writes land in WORKDIR and a later block can read them.
The Quickstart block is the exception: `.ci/run` runs `scripts/test.sh` and
`scripts/quickstart.sh` themselves on a clean clone; its third line, a
server (`simbot serve`), runs here like any other. A server, a command
that does not end by itself, passes when it answers its front page
(HTTP 200) within SERVER_SECONDS; it is then stopped. A desktop program
(GTKWave) runs under Xvfb and passes when it is still showing the file
after a few seconds; anything else must exit with status 0. A block
that already ran (the README shows some of the manual's) runs once.
The README's layout table must list every top-level folder of the
checkout, and only those.
"""
import os
import re
import shutil
import subprocess
import sys
import time
import urllib.request

CI_RUNS_THESE = {"./scripts/quickstart.sh", "./scripts/test.sh"}
DESKTOP_PROGRAMS = {"gtkwave"}
DESKTOP_SECONDS = 8
SERVER_SECONDS = 60


def blocks(readme_text):
    """The ```sh blocks, each a list of logical lines (continuations joined)."""
    out = []
    for body in re.findall(r"^```sh\n(.*?)^```", readme_text, re.S | re.M):
        lines, pending = [], ""
        for raw in body.splitlines():
            if raw.endswith("\\"):
                pending += raw[:-1] + " "
                continue
            lines.append(pending + raw)
            pending = ""
        out.append([line for line in lines if line.strip()])
    return out


def layout_mismatch(readme_text, source):
    """Folders the README's layout table leaves out, and rows for folders that are not there."""
    table = readme_text.split("\n## Layout\n", 1)[-1]
    listed = set(re.findall(r"^\| `([^`/]+)/` \|", table, re.M))
    # What .gitignore keeps out of the checkout: build folders and out/.
    folders = {d for d in os.listdir(source) if os.path.isdir(os.path.join(source, d))
               and not d.startswith((".", "build")) and d != "out"}
    return sorted(folders - listed), sorted(listed - folders)


def sandbox(source, simbot, work):
    main = os.path.join(work, "main")
    if os.path.exists(work):
        shutil.rmtree(work)
    os.makedirs(os.path.join(main, "build", "bin"))
    os.symlink(os.path.abspath(simbot), os.path.join(main, "build", "bin", "simbot"))
    # The benchmark binaries beside it, for docs/benchmarks.md.
    for name in ("match_bench", "vm_bench"):
        built = os.path.join(os.path.dirname(os.path.abspath(simbot)), name)
        if os.path.exists(built):
            os.symlink(built, os.path.join(main, "build", "bin", name))
    # The manual page the build generates.
    page = os.path.join(os.path.dirname(os.path.abspath(simbot)), "..", "simbot.1")
    if os.path.exists(page):
        os.symlink(os.path.abspath(page), os.path.join(main, "build", "simbot.1"))
    # The Python module beside it (docs/tools.md, "Python and sweeps").
    module = os.path.join(os.path.dirname(os.path.abspath(simbot)), "..", "python")
    if os.path.isdir(module):
        os.symlink(os.path.abspath(module), os.path.join(main, "build", "python"))
    for part in ("programs", "scenarios", "profiles", "checks", "tests", "bench", "docs", "scripts"):
        os.symlink(os.path.join(source, part), os.path.join(main, part))
    os.symlink(os.path.abspath(os.path.join(source, "..", "shared")), os.path.join(work, "shared"))
    return main


def run_desktop(line, cwd):
    """Starts a desktop program under Xvfb; it passes if it is still up."""
    proc = subprocess.Popen(["xvfb-run", "-a", "bash", "-c", line], cwd=cwd,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True)
    try:
        status = proc.wait(timeout=DESKTOP_SECONDS)
        return f"exited with status {status} within {DESKTOP_SECONDS} s: {proc.stderr.read().decode()[-400:]}"
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, 9)
        proc.wait()
        return None


def is_server(line):
    """A `simbot serve` line left to run (one put in the background with `&`
    runs in its block, which stops it)."""
    command = line.split("#")[0]
    words = command.split()
    return len(words) > 1 and words[0].endswith("bin/simbot") and words[1] == "serve" \
        and "&" not in command


def run_server(line, cwd):
    """Starts `simbot serve ...`; it passes if its front page answers 200."""
    words = line.split("#")[0].split()
    port = words[words.index("--port") + 1] if "--port" in words else "8000"
    proc = subprocess.Popen(["bash", "-c", "exec " + line.split("#")[0]], cwd=cwd,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True)
    problem = f"its front page did not answer within {SERVER_SECONDS} s"
    deadline = time.monotonic() + SERVER_SECONDS
    try:
        while time.monotonic() < deadline and proc.poll() is None:
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=5) as r:
                    problem = None if r.status == 200 else f"its front page answered {r.status}"
                    break
            except OSError:
                time.sleep(0.3)
        if proc.poll() is not None:
            problem = f"exited with status {proc.returncode}: {proc.stderr.read().decode()[-400:]}"
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, 15)
            proc.wait()
    return problem


def main():
    simbot, work, readme = sys.argv[1:4]
    pages = [readme] + sys.argv[4:]
    source = os.path.dirname(os.path.abspath(readme))
    cwd = sandbox(source, simbot, os.path.abspath(work))
    failures, ran = [], 0
    missing, extra = layout_mismatch(open(readme, encoding="utf-8").read(), source)
    if missing or extra:
        failures.append(f"README's layout table: folders not listed {missing}, rows for no folder {extra}")
    seen = set()
    every = [b for page in pages for b in blocks(open(page, encoding="utf-8").read())]
    for block in every:
        block = [line for line in block if line.split("#")[0].strip() not in CI_RUNS_THESE]
        if not block:
            continue
        if tuple(block) in seen:
            continue
        seen.add(tuple(block))
        script = []
        for line in block:
            if line.split()[0] in DESKTOP_PROGRAMS or is_server(line):
                problem = None
                if script:  # what comes before it runs first
                    done = subprocess.run(["bash", "-e", "-c", "\n".join(script)], cwd=cwd,
                                          capture_output=True, text=True)
                    ran += len(script)
                    script = []
                    if done.returncode != 0:
                        problem = f"status {done.returncode}: {done.stderr[-600:]}"
                problem = problem or (run_server if is_server(line) else run_desktop)(line, cwd)
                ran += 1
                if problem:
                    failures.append(f"{line}\n  {problem}")
                continue
            script.append(line)
        if script:
            started = time.monotonic()
            done = subprocess.run(["bash", "-e", "-c", "\n".join(script)], cwd=cwd,
                                  capture_output=True, text=True)
            ran += len(script)
            print(f"ran {len(script)} command(s) in {time.monotonic() - started:.1f} s: {script[0][:70]}")
            if done.returncode != 0:
                failures.append("\n".join(script) + f"\n  status {done.returncode}: {done.stderr[-600:]}")
    for failure in failures:
        print("FAIL: " + failure)
    print(f"{ran} commands of {len(pages)} pages run, {len(failures)} failed")
    sys.exit(1 if failures or ran == 0 else 0)


if __name__ == "__main__":
    main()
