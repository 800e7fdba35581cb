#!/usr/bin/env python3
"""simbot serve --dask (server/simbot_server/queue.py): the matches run as
tasks on a real Dask cluster (a `dask scheduler` and a `dask worker` of 2
one-thread processes on the loopback, started here; the worker's
PYTHONPATH has no server package, so the task's code travels with it).

Usage: server_dask_test.py SIMBOT SOURCE_DIR SHARED_DIR OUTDIR
(PYTHONPATH: build/python, for simbot sweep's Dask connection)

- A round robin of 3 teams (fig92, ICEMAN, turret), 2 rounds of 20-s
  matches, tournament seed 2024, gives on Dask the games (keyed by their
  seeds), the results and the table of the same tournament on --workers 2.
- The oracle: each game's result is `simbot match` run here on the
  original files with the game's seed (its programs named as the server
  names them, without wall_seconds), so both paths are checked against
  simbot itself, not against each other only.
- A match whose worker is killed mid-run (its simbot stopped with SIGSTOP
  first, so the kill is certainly mid-run) is not lost: killed once, Dask
  runs it again and it is done with simbot match's result; killed twice
  (the scheduler allows one failure here), it is failed with KilledWorker.
- The command: `simbot serve --dask ADDRESS` plays a scrimmage on the
  cluster; --dask with --workers, and a scheduler that refuses, are one
  line and exit status 1.
"""
import json
import os
import shutil
import signal
import socket
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

SIMBOT, SOURCE, SHARED, OUT = sys.argv[1:5]
SOURCE, SHARED, OUT = Path(SOURCE), Path(SHARED), Path(OUT)
sys.path.insert(0, str(SOURCE / "server"))

from dask.distributed import Client  # noqa: E402
from fastapi.testclient import TestClient  # noqa: E402

from simbot_server import db  # noqa: E402
from simbot_server.app import create_app  # noqa: E402

from scriptcheck import check, failures

START = time.monotonic()
shutil.rmtree(OUT, ignore_errors=True)
OUT.mkdir(parents=True)
PROGRAMS = {"fig": SHARED / "programs/fig92.dc", "ice": SHARED / "programs/iceman.dc",
            "turret": SOURCE / "programs/turret.dc"}
SECONDS, TOURNAMENT_SEED, LONG_SECONDS = 20, 2024, 1000


def auth(token):
    return {"Authorization": f"Bearer {token}"}


def direct(a, b, seed, seconds):
    """simbot match's own result for the files and seed, as the server
    stores it: programs named "submission", no wall_seconds."""
    p = subprocess.run([SIMBOT, "match", str(a), str(b), "--seed", str(seed), "--seconds",
                        str(seconds), "--json"], capture_output=True, timeout=120)
    result = json.loads(p.stdout)
    for robot in result["robots"]:
        robot["program"] = "submission"
    del result["wall_seconds"]
    return result


def wait(predicate, limit, step=0.05):
    deadline = time.monotonic() + limit
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(step)
    return predicate()


def finished(get, match_id, limit):
    """The match once done or failed, or as it is after `limit` s."""
    deadline = time.monotonic() + limit
    while True:
        m = get(f"/api/matches/{match_id}").json()
        if m["status"] in ("done", "failed") or time.monotonic() > deadline:
            return m
        time.sleep(0.05)


# ---- the cluster: a scheduler that allows one failure per task (a task
# whose worker dies a second time is KilledWorker), 2 worker processes
scheduler_file = OUT / "scheduler.json"
dask_env = dict(os.environ, DASK_DISTRIBUTED__SCHEDULER__ALLOWED_FAILURES="1")
dask_env.pop("PYTHONPATH", None)
logs = open(OUT / "dask.log", "w")
scheduler = subprocess.Popen(
    [sys.executable, "-m", "dask", "scheduler", "--host", "127.0.0.1", "--port", "0",
     "--no-dashboard", "--scheduler-file", str(scheduler_file)],
    env=dask_env, stdout=logs, stderr=logs, cwd=OUT)
worker = None
try:
    check(wait(scheduler_file.exists, 30), "the scheduler wrote its file")
    address = json.loads(scheduler_file.read_text())["address"]
    worker = subprocess.Popen(
        [sys.executable, "-m", "dask", "worker", "--scheduler-file", str(scheduler_file),
         "--nworkers", "2", "--nthreads", "1", "--no-dashboard", "--host", "127.0.0.1",
         "--local-directory", str(OUT / "workers")],
        env=dask_env, stdout=logs, stderr=logs, cwd=OUT)
    with Client(address, timeout=10) as watcher:
        watcher.wait_for_workers(2, timeout=30)
    print(f"server_dask_test: cluster up at {address} in {time.monotonic() - START:.1f} s")

    def league(c, token):
        """Three teams and a round robin, 2 rounds of 20-s matches, seed
        2024; the tournament's id once its games are done."""
        for name, path in PROGRAMS.items():
            team = c.post("/api/teams", json={"name": name}, headers=auth(token)).json()
            r = c.post("/api/submissions", files={"program": (path.name, path.read_bytes())},
                       headers=auth(team["token"]))
            check(r.status_code == 201, f"{name}'s program: {r.status_code}")
        r = c.post("/api/tournaments", json={"rounds": 2, "seconds": SECONDS,
                                             "seed": TOURNAMENT_SEED}, headers=auth(token))
        check(r.status_code == 201 and r.json()["games"] == 6, f"a tournament: {r.text}")
        tid = r.json()["id"]
        check(wait(lambda: c.get(f"/api/tournaments/{tid}").json()["status"] == "done", 60),
              "the tournament's games are played")
        return tid

    def games(data, tid):
        """{seed: (A's team, B's team, status, result, error)} of a tournament."""
        with sqlite3.connect(data / "simbot.sqlite3") as q:
            rows = q.execute(
                "select m.seed, ta.name, tb.name, m.status, m.result, m.error from matches m "
                "join submissions sa on sa.id = m.a_submission_id "
                "join teams ta on ta.id = sa.team_id "
                "join submissions sb on sb.id = m.b_submission_id "
                "join teams tb on tb.id = sb.team_id where m.tournament_id = ?", (tid,)).fetchall()
        return {seed: (a, b, status, json.loads(result) if result else None, error)
                for seed, a, b, status, result, error in rows}

    # ---- the same tournament on --workers 2 and on Dask
    local_data, dask_data = OUT / "local", OUT / "dask"
    local_app = create_app(db.default_url(local_data), str(local_data), SIMBOT, workers=2,
                           seconds=SECONDS)
    with TestClient(local_app) as c:
        tid = league(c, local_app.state.new_instructor_token)
        local_table = c.get(f"/api/tournaments/{tid}").json()["table"]
    local_games = games(local_data, tid)
    dask_app = create_app(db.default_url(dask_data), str(dask_data), SIMBOT, seconds=LONG_SECONDS,
                          dask=address)
    check(dask_app.state.queue.at_once == 2, f"2 at once, the cluster's threads: "
                                             f"{dask_app.state.queue.at_once}")
    with TestClient(dask_app) as c:
        token = dask_app.state.new_instructor_token
        tid = league(c, token)
        dask_table = c.get(f"/api/tournaments/{tid}").json()["table"]
        dask_games = games(dask_data, tid)
        print(f"server_dask_test: both tournaments in {time.monotonic() - START:.1f} s")
        check(len(local_games) == 6 and sorted(local_games) == sorted(dask_games),
              f"the same 6 seeds: {sorted(local_games)} {sorted(dask_games)}")
        check(local_games == dask_games, "the same games, results and statuses on Dask")
        check(local_table == dask_table, f"the same table: {local_table} and {dask_table}")
        for seed, (a, b, status, result, error) in sorted(dask_games.items()):
            check(status == "done", f"seed {seed}: {status} {error}")
            check(result == direct(PROGRAMS[a], PROGRAMS[b], seed, SECONDS),
                  f"seed {seed} ({a} against {b}): the result is not simbot match's")
        # The oracle's table: played, wins, losses, hits counted here.
        expect = {name: [0, 0, 0, 0] for name in PROGRAMS}
        for a, b, _, result, _ in dask_games.values():
            for name, robot in zip((a, b), result["robots"]):
                expect[name][0] += 1
                expect[name][3] += robot["hits"]
            if result["winner"] in ("A", "B"):
                won, lost = (a, b) if result["winner"] == "A" else (b, a)
                expect[won][1] += 1
                expect[lost][2] += 1
        for entry in dask_table:
            check([entry["played"], entry["wins"], entry["losses"], entry["hits"]]
                  == expect[entry["team"]], f"{entry['team']}: {entry} against {expect}")

        # ---- a worker killed mid-run: once (run again, done), twice
        # (KilledWorker, failed). One match at a time, so that no other
        # task is on a killed worker.
        team = c.post("/api/teams", json={"name": "kill"}, headers=auth(token)).json()
        c.post("/api/submissions", files={"program": ("fig92.dc", PROGRAMS["fig"].read_bytes())},
               headers=auth(team["token"]))
        ice_id = next(e["team_id"] for e in dask_table if e["team"] == "ice")

        def stat(pid):
            """/proc/PID/stat's fields after the name: state, parent, ..."""
            return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()

        def simbot_on_worker(seen):
            """(pid, its worker's pid, seed) of a simbot match run by one of
            the cluster's worker processes (children of `dask worker`), not
            in `seen`."""
            for entry in os.listdir("/proc"):
                if not entry.isdigit() or int(entry) in seen:
                    continue
                try:
                    argv = Path(f"/proc/{entry}/cmdline").read_bytes().split(b"\0")
                    parent = int(stat(entry)[1])
                    grandparent = int(stat(parent)[1])
                except (OSError, ValueError, IndexError):
                    continue
                if argv[:2] == [os.path.abspath(SIMBOT).encode(), b"match"] \
                        and grandparent == worker.pid:
                    return int(entry), parent, int(argv[argv.index(b"--seed") + 1])
            return None

        def state(pid):
            try:
                return stat(pid)[0]
            except OSError:
                return None

        seen = set()
        for seed, kills in ((11, 1), (12, 2)):
            r = c.post("/api/scrimmages", json={"opponent": ice_id, "seed": seed},
                       headers=auth(team["token"]))
            match_id = r.json()["match_id"]
            done = 0
            deadline = time.monotonic() + 40
            while done < kills and time.monotonic() < deadline:
                found = simbot_on_worker(seen)
                if found is None:
                    time.sleep(0.005)
                    continue
                pid, worker_pid, running_seed = found
                seen.add(pid)
                check(running_seed == seed, f"the match running is seed {running_seed}")
                os.kill(pid, signal.SIGSTOP)  # it cannot finish now
                check(wait(lambda: state(pid) == "T", 10, 0.001),
                      f"seed {seed}: stopped mid-run ({state(pid)})")
                os.kill(worker_pid, signal.SIGKILL)
                check(wait(lambda: state(worker_pid) in (None, "Z"), 10), "the worker died")
                os.kill(pid, signal.SIGKILL)  # the orphan
                done += 1
            check(done == kills, f"seed {seed}: its worker killed {done} of {kills} times")
            m = finished(c.get, match_id, 40)
            if kills == 1:
                check(m["status"] == "done" and m["result"] == direct(
                    PROGRAMS["fig"], PROGRAMS["ice"], seed, LONG_SECONDS),
                    f"killed once, run again: {m['status']} {m['error']}")
            else:
                check(m["status"] == "failed" and (m["error"] or "").startswith("KilledWorker"),
                      f"killed twice, failed with its error: {m['status']} {m['error']}")
        print(f"server_dask_test: the kills in {time.monotonic() - START:.1f} s")

    # ---- the command: simbot serve --dask
    def serve(*args, stderr=subprocess.PIPE):
        return subprocess.Popen([SIMBOT, "serve", *args], stdout=subprocess.PIPE,
                                stderr=stderr, text=True)

    p = serve("--data", str(OUT / "cli"), "--dask", address, "--workers", "2")
    check(p.wait(30) == 1 and p.stderr.read().strip().count("\n") == 0,
          "--dask with --workers: one line, status 1")
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        refused = sock.getsockname()[1]  # nothing listens there once closed
    p = serve("--data", str(OUT / "cli"), "--dask", f"tcp://127.0.0.1:{refused}")
    err = p.stderr.read()
    check(p.wait(30) == 1 and err.count("\n") == 1 and err.startswith(
        f"simbot: --dask: cannot connect to tcp://127.0.0.1:{refused}"),
        f"a scheduler that refuses: {err!r}")
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    live = serve("--data", str(OUT / "cli"), "--port", str(port), "--dask", address,
                 "--house", str(SOURCE / "programs"), stderr=logs)
    try:
        token = live.stdout.readline().rsplit(" ", 1)[-1].strip()
        check(live.stdout.readline().startswith("simbot serve: listening"), "it listens")
        import httpx
        base = f"http://127.0.0.1:{port}"

        def answers():
            try:
                return httpx.get(base + "/api/teams/0").status_code == 404
            except httpx.TransportError:
                return False
        check(wait(answers, 30), "it answers")
        team = httpx.post(base + "/api/teams", json={"name": "fig"}, headers=auth(token)).json()
        httpx.post(base + "/api/submissions", headers=auth(team["token"]),
                   files={"program": ("fig92.dc", PROGRAMS["fig"].read_bytes())}, timeout=60)
        r = httpx.post(base + "/api/scrimmages", json={"opponent": "house:turret", "seed": 3},
                       headers=auth(team["token"]))
        m = finished(lambda path: httpx.get(base + path), r.json()["match_id"], 60)
        want = direct(PROGRAMS["fig"], SOURCE / "programs/turret.dc", 3, 180)
        want["robots"][1]["program"] = "house:turret"
        check(m["status"] == "done" and m["result"] == want,
              f"simbot serve --dask: simbot match's result: {m['status']} {m['error']}")
    finally:
        live.send_signal(signal.SIGTERM)
        live.wait(30)
finally:
    for process in (worker, scheduler):
        if process is not None:
            process.send_signal(signal.SIGTERM)
            try:
                process.wait(20)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()
    logs.close()

print(f"server_dask_test: {time.monotonic() - START:.1f} s")
if failures:
    sys.exit(f"{len(failures)} check(s) failed")
print("server_dask_test: all checks passed")
