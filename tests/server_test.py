#!/usr/bin/env python3
"""simbot serve's HTTP API (server/simbot_server) end to end, on SQLite or
on PostgreSQL: through FastAPI's test client, then the real server over
the loopback.

Usage: server_test.py SIMBOT SOURCE_DIR SHARED_DIR OUTDIR [--db sqlite|postgres]

With --db postgres (ctest's server.api.postgres) every check runs on the
PostgreSQL server at $SIMBOT_TEST_POSTGRES_URL (scripts/postgres.sh starts
a throwaway one), each part of the test on a database of its own, dropped
and made again (so every run starts empty), named after the URL's
database: NAME_api, NAME_queue, NAME_killed, NAME_whole. Without that
variable it exits with SKIPPED (77), which ctest reports as skipped, not
passed.

- First start: the instructor token is written to DATA/instructor-token,
  mode 0600; the database holds only its SHA-256 (the token's text appears
  in no row of any table, and on SQLite nowhere in the database file); a
  second start makes no new token.
- The schema is the Alembic head, and it has exactly the models' tables
  and columns, and Alembic finds no difference between it and the models
  (types, nullability, indexes, keys; server defaults on PostgreSQL).
- Teams: no token 401, a team's token 403, the instructor's 201 with a
  token that works; a name with markup or SQL is stored and returned as
  the very text sent, and creates one row; a duplicate name 409; a name
  empty, too long, with a control character or a lone surrogate
  ("\\ud800" in the JSON, which neither database can encode) 422.
- Submissions: fig92 is version 1 with its warning at 57:9 (the line of
  its first platform() call, counted in the file), named by the uploaded
  file's base name; a second is version 2; a program with an error on its
  line 3 is 422 with "NAME:3:" and stores nothing, and so is one with a
  NUL byte in a comment, at its line and column; a program of 64 KiB + 1
  byte is 413 and stores nothing; a path as a file name is shown by its
  base name only, and no file of that name appears anywhere. A version's
  time is UTC, between the test's clock before and after its request
  (on PostgreSQL the database's time zone is set to America/Los_Angeles,
  so a time taken in the database's zone would be 7 or 8 hours off).
  16 submissions of one team at once, compiling at the same moment, are
  versions 1 to 16.
- The queue: scrimmages and a round robin give simbot match's own
  results; the largest seed, 2^63 - 1, is stored, given back and played
  (2^63 is 422); a queue left by a killed server runs at the next start.
- Two servers' queues on one database, 4 workers each, run each of 120
  matches queued at once exactly once.
- The real server (simbot serve) killed with SIGKILL mid-tournament and
  restarted ends with the table of a run without the kill.
"""
import argparse
import datetime
import hashlib
import os
import shutil
import stat
import sys
from pathlib import Path

arguments = argparse.ArgumentParser()
for name in ("simbot", "source", "shared", "out"):
    arguments.add_argument(name)
arguments.add_argument("--db", choices=("sqlite", "postgres"), default="sqlite")
arguments = arguments.parse_args()
SIMBOT, SOURCE, SHARED, OUT = (arguments.simbot, Path(arguments.source), Path(arguments.shared),
                               Path(arguments.out))
SKIPPED = 77  # ctest's SKIP_RETURN_CODE for server.api.postgres
POSTGRES = os.environ.get("SIMBOT_TEST_POSTGRES_URL") if arguments.db == "postgres" else None
if arguments.db == "postgres" and not POSTGRES:
    print("server_test: SKIPPED: no PostgreSQL server (SIMBOT_TEST_POSTGRES_URL is not set; "
          "scripts/postgres.sh sets it)")
    sys.exit(SKIPPED)
sys.path.insert(0, str(SOURCE / "server"))

from alembic.autogenerate import compare_metadata  # noqa: E402
from alembic.migration import MigrationContext  # noqa: E402
from alembic.script import ScriptDirectory  # noqa: E402
from fastapi.testclient import TestClient  # noqa: E402
from sqlalchemy import create_engine, inspect, text  # noqa: E402
from sqlalchemy.engine import make_url  # noqa: E402
from sqlalchemy.pool import NullPool  # noqa: E402

from simbot_server import db, models  # noqa: E402
from simbot_server.app import create_app  # noqa: E402
from simbot_server.models import Submission  # noqa: E402

from scriptcheck import check, failures

shutil.rmtree(OUT, ignore_errors=True)
OUT.mkdir(parents=True)


def fresh_database(label, data):
    """The URL of an empty database for one part of the test: on SQLite
    the default file in `data` (a new folder), on PostgreSQL NAME_label,
    dropped and made again."""
    if not POSTGRES:
        return db.default_url(data)
    base = make_url(POSTGRES)
    name = f"{base.database}_{label}"
    admin = create_engine(base, isolation_level="AUTOCOMMIT", poolclass=NullPool)
    with admin.connect() as c:
        c.execute(text(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)'))
        c.execute(text(f'CREATE DATABASE "{name}"'))
        # Not UTC (the throwaway server's is the machine's, often UTC): a
        # time the server stores in the database's own zone shows.
        c.execute(text(f"ALTER DATABASE \"{name}\" SET timezone TO 'America/Los_Angeles'"))
    admin.dispose()
    return base.set(database=name).render_as_string(hide_password=False)


def rows(url, query, **params):
    """The rows of `query` on the database at `url`, read outside the server."""
    engine = create_engine(url, poolclass=NullPool)
    try:
        with engine.connect() as c:
            return [tuple(r) for r in c.execute(text(query), params)]
    finally:
        engine.dispose()


def stored_text(url):
    """Every value of every row of every table, as text."""
    engine = create_engine(url, poolclass=NullPool)
    try:
        with engine.connect() as c:
            return "\n".join(str(v) for table in inspect(c).get_table_names()
                             for row in c.execute(text(f'select * from "{table}"')) for v in row)
    finally:
        engine.dispose()


DATA = OUT / "data"
URL = fresh_database("api", DATA)


def auth(token):
    return {"Authorization": f"Bearer {token}"}


# ---- first start, the instructor's token
app = create_app(URL, str(DATA), SIMBOT)
client = TestClient(app)
token_file = DATA / "instructor-token"
instructor = token_file.read_text().strip()
check(app.state.new_instructor_token == instructor, "the printed token is the file's")
check(stat.S_IMODE(token_file.stat().st_mode) == 0o600,
      f"instructor-token mode {oct(stat.S_IMODE(token_file.stat().st_mode))}")
stored = stored_text(URL)
check(instructor not in stored, "the instructor token is in no row")
check(hashlib.sha256(instructor.encode()).hexdigest() in stored, "its SHA-256 is stored")
if not POSTGRES:
    database = (DATA / "simbot.sqlite3").read_bytes()
    check(instructor.encode() not in database, "the instructor token is not in the file")
again = create_app(URL, str(DATA), SIMBOT)
check(again.state.new_instructor_token is None and token_file.read_text().strip() == instructor,
      "a second start makes no new token")

# ---- the schema: Alembic's head, the models' tables and columns
heads = ScriptDirectory(db.MIGRATIONS).get_heads()
got = rows(URL, "select version_num from alembic_version")
check(len(heads) == 1 and got == [(heads[0],)], f"alembic_version {got}, the head {heads}")
found = inspect(app.state.engine)
for table in models.Base.metadata.sorted_tables:
    columns = {col["name"] for col in found.get_columns(table.name)}
    check(columns == {col.name for col in table.columns},
          f"table {table.name}: migration {sorted(columns)}, model {sorted(c.name for c in table.columns)}")
# Alembic's own comparison of the migrated database with the models:
# tables, columns, their types (a seed migrated as INTEGER would be cut to
# 32 bits on PostgreSQL), nullability, indexes, unique and foreign keys;
# on PostgreSQL the server defaults too (SQLite gives them back as text
# that Alembic cannot match with now()).
with app.state.engine.connect() as c:
    differences = compare_metadata(MigrationContext.configure(c, opts={
        "compare_type": True, "compare_server_default": bool(POSTGRES)}), models.Base.metadata)
check(differences == [], f"the migrations against the models: {differences}")

# ---- teams
r = client.post("/api/teams", json={"name": "alpha"})
check(r.status_code == 401, f"no token: {r.status_code}")
r = client.post("/api/teams", json={"name": "alpha"}, headers=auth("wrong"))
check(r.status_code == 403, f"a wrong token: {r.status_code}")
r = client.post("/api/teams", json={"name": "alpha"}, headers=auth(instructor))
check(r.status_code == 201, f"the instructor makes a team: {r.status_code} {r.text}")
alpha = r.json()
r = client.post("/api/teams", json={"name": "beta"}, headers=auth(alpha["token"]))
check(r.status_code == 403, f"a team's token cannot make teams: {r.status_code}")
r = client.post("/api/teams", json={"name": "alpha"}, headers=auth(instructor))
check(r.status_code == 409, f"a duplicate name: {r.status_code}")
for name in ["<script>alert(1)</script>", "x'); DROP TABLE teams; --", "\u00e9quipe \u2603"]:
    r = client.post("/api/teams", json={"name": name}, headers=auth(instructor))
    check(r.status_code == 201, f"name {name!r}: {r.status_code}")
    got = client.get(f"/api/teams/{r.json()['id']}").json()
    check(got["name"] == name, f"name {name!r} comes back as {got['name']!r}")
for bad in ["", " ", "a" * 65, "tab\there", None, 7, "\ud800 lone"]:
    r = client.post("/api/teams", json={"name": bad}, headers=auth(instructor))
    check(r.status_code == 422, f"name {bad!r}: {r.status_code}")
check(rows(URL, "select count(*) from teams") == [(4,)], "four teams stored")

# ---- submissions
fig92 = (SHARED / "programs/fig92.dc").read_bytes()
before = datetime.datetime.utcnow().replace(microsecond=0)  # SQLite keeps whole seconds
r = client.post("/api/submissions", files={"program": ("fig92.dc", fig92)},
                headers=auth(alpha["token"]))
after = datetime.datetime.utcnow()
check(r.status_code == 201, f"fig92 submitted: {r.status_code} {r.text}")
body = r.json()
check(body.get("version") == 1, f"version 1: {body}")
check(any(w.startswith("fig92.dc:57:9: warning: implicit declaration of function 'platform'")
          for w in body.get("warnings", [])), f"fig92's warning at 57:9: {body.get('warnings')}")
check(body.get("checks") == [], "no course checks configured: none run")
r = client.post("/api/submissions", files={"program": ("../../etc/evil.dc", fig92)},
                headers=auth(alpha["token"]))
check(r.status_code == 201 and r.json()["version"] == 2, f"second version: {r.text}")
check(all(w.startswith("evil.dc:") for w in r.json()["warnings"]),
      f"a path as a name is shown by its base name: {r.json()['warnings'][:1]}")
check(not any(p.name == "evil.dc" for p in OUT.rglob("*")), "no file named by the team")
bad = b"main()\n{\n    int x\n    x = 1;\n}\n"
r = client.post("/api/submissions", files={"program": ("bad.dc", bad)}, headers=auth(alpha["token"]))
check(r.status_code == 422 and r.json()["errors"][0].startswith("bad.dc:3:"),
      f"an error at its line: {r.status_code} {r.text}")
# simbot compile passes a NUL byte in a comment (this program compiles),
# but PostgreSQL's text cannot hold one: refused, with its place.
r = client.post("/api/submissions", files={"program": ("nul.dc", b"main()\n{\n}\n// \0 a NUL\n")},
                headers=auth(alpha["token"]))
check(r.status_code == 422 and r.json()["errors"] == ["nul.dc:4:4: error: a NUL byte (a program is text)"],
      f"a NUL byte at 4:4: {r.status_code} {r.text}")
huge = b"/*" + b"x" * (64 * 1024 - 3) + b"*/"
r = client.post("/api/submissions", files={"program": ("huge.dc", huge)},
                headers=auth(alpha["token"]))
check(r.status_code == 413, f"64 KiB + 1 byte: {r.status_code}")
r = client.post("/api/submissions", files={"program": ("fig92.dc", fig92)},
                headers=auth(instructor))
check(r.status_code == 403, f"the instructor is not a team: {r.status_code}")
versions = client.get(f"/api/teams/{alpha['id']}").json()["versions"]
check([v["version"] for v in versions] == [1, 2], f"two versions stored: {versions}")
created = datetime.datetime.fromisoformat(versions[0]["created"])
check(before <= created <= after, f"version 1 made at {created}, UTC, between {before} and {after}")
stored = rows(URL, "select source from submissions where version = 1")[0][0]
check(stored.encode("latin-1") == fig92, "the source is stored byte for byte")

# 16 submissions of one team at once, all compiling at the same moment (a
# barrier in the compiler's call): more than SQLAlchemy's pool for
# PostgreSQL lends (5 connections and 10 more), so a request that kept its
# connection while it compiled would leave the 16th waiting at the pool
# and break the barrier; and all 16 then ask for the next version together.
import threading  # noqa: E402

from simbot_server import compile as compiler  # noqa: E402

crowd = client.post("/api/teams", json={"name": "crowd"}, headers=auth(instructor)).json()
AT_ONCE = 16
barrier = threading.Barrier(AT_ONCE, timeout=20)
compile_file = compiler.compile_file


def compile_together(*args):
    barrier.wait()
    return compile_file(*args)


def submit_one(answers):
    r = TestClient(app, raise_server_exceptions=False).post(
        "/api/submissions", files={"program": ("fig92.dc", fig92)}, headers=auth(crowd["token"]))
    answers.append((r.status_code, r.json().get("version") if r.status_code == 201 else r.text[:200]))


# The per-team rate limit (6 a minute, limits.py; server.hostile tests it)
# is lifted for this crowd: it is the database under test here.
from simbot_server import limits  # noqa: E402

submission_rate = limits.RATES["submission"]
limits.RATES["submission"] = (AT_ONCE, AT_ONCE)
compiler.compile_file = compile_together
answers = []
threads = [threading.Thread(target=submit_one, args=(answers,)) for _ in range(AT_ONCE)]
for t in threads:
    t.start()
for t in threads:
    t.join()
compiler.compile_file = compile_file
limits.RATES["submission"] = submission_rate
check(sorted(answers) == [(201, v) for v in range(1, AT_ONCE + 1)],
      f"16 submissions at once are versions 1 to 16: {sorted(answers, key=str)[:3]}...")
versions = [v["version"] for v in client.get(f"/api/teams/{crowd['id']}").json()["versions"]]
check(versions == list(range(1, AT_ONCE + 1)), f"16 versions stored: {versions}")

# ---- scrimmages: the queue runs them off the request path
import json  # noqa: E402
import subprocess  # noqa: E402
import time  # noqa: E402

from simbot_server.models import Match  # noqa: E402


def wait_done(c, match_id, limit=120):
    deadline = time.monotonic() + limit
    while time.monotonic() < deadline:
        m = c.get(f"/api/matches/{match_id}").json()
        if m["status"] in ("done", "failed"):
            return m
        time.sleep(0.05)
    return c.get(f"/api/matches/{match_id}").json()


def direct(a, b, seed):
    """simbot match's own JSON for the same programs and seed."""
    p = subprocess.run([SIMBOT, "match", a, b, "--seed", str(seed), "--seconds", "10", "--json"],
                       capture_output=True, text=True)
    return json.loads(p.stdout)


def score(result):
    return result["winner"], [(r["hits"], r["shots"], r["motor_frames_latched"]) for r in result["robots"]]


QDATA = OUT / "queue"
QURL = fresh_database("queue", QDATA)
queued = create_app(QURL, str(QDATA), SIMBOT, house=str(SOURCE / "programs"),
                    workers=2, seconds=10)
qtoken = (QDATA / "instructor-token").read_text().strip()
with TestClient(queued) as c:
    r = c.post("/api/teams", json={"name": "fig"}, headers=auth(qtoken))
    fig = r.json()
    r = c.post("/api/scrimmages", json={"opponent": "house:turret"}, headers=auth(fig["token"]))
    check(r.status_code == 409, f"no program yet: {r.status_code}")
    c.post("/api/submissions", files={"program": ("fig92.dc", fig92)}, headers=auth(fig["token"]))
    r = c.post("/api/teams", json={"name": "ice"}, headers=auth(qtoken))
    ice = r.json()
    iceman = (SHARED / "programs/iceman.dc").read_bytes()
    c.post("/api/submissions", files={"program": ("iceman.dc", iceman)}, headers=auth(ice["token"]))
    r = c.post("/api/scrimmages", json={"opponent": "house:nothere"}, headers=auth(fig["token"]))
    check(r.status_code == 422, f"an unknown house robot: {r.status_code}")
    r = c.post("/api/scrimmages", json={"opponent": "house:../../etc/passwd"}, headers=auth(fig["token"]))
    check(r.status_code == 422, f"a path as a house robot: {r.status_code}")
    r = c.post("/api/scrimmages", json={"opponent": "house:turret", "seed": 2**63},
               headers=auth(fig["token"]))
    check(r.status_code == 422, f"a seed of 2^63: {r.status_code}")
    # The largest seed (a BIGINT on PostgreSQL, SQLite's 8-byte INTEGER).
    r = c.post("/api/scrimmages", json={"opponent": "house:turret", "seed": 2**63 - 1},
               headers=auth(fig["token"]))
    check(r.status_code == 201, f"a scrimmage against a house robot: {r.status_code} {r.text}")
    m = wait_done(c, r.json()["match_id"])
    check(m["status"] == "done" and m["seed"] == 2**63 - 1,
          f"it ran: {m['status']} {m.get('error')} {m['seed']}")
    if m["status"] == "done":
        want = direct(SHARED / "programs/fig92.dc", SOURCE / "programs/turret.dc", 2**63 - 1)
        check(score(m["result"]) == score(want), f"its result is simbot match's: {score(m['result'])} {score(want)}")
    r = c.post("/api/scrimmages", json={"opponent": ice["id"], "seed": 5}, headers=auth(fig["token"]))
    m = wait_done(c, r.json()["match_id"])
    if m["status"] == "done":
        want = direct(SHARED / "programs/fig92.dc", SHARED / "programs/iceman.dc", 5)
        check(score(m["result"]) == score(want), f"team against team: {score(m['result'])} {score(want)}")
    else:
        check(False, f"team against team ran: {m}")

    # A round robin of the two teams, two rounds (sides swapped), the
    # largest seed.
    r = c.post("/api/tournaments", json={"rounds": 2, "seconds": 10, "seed": 2**63 - 1},
               headers=auth(fig["token"]))
    check(r.status_code == 403, f"a team cannot start a tournament: {r.status_code}")
    r = c.post("/api/tournaments", json={"rounds": 2, "seconds": 10, "seed": 2**63 - 1},
               headers=auth(qtoken))
    check(r.status_code == 201 and r.json()["games"] == 2, f"a tournament: {r.status_code} {r.text}")
    check(c.get(f"/api/tournaments/{r.json()['id']}").json()["seed"] == 2**63 - 1, "its seed kept")
    tid = r.json()["id"]
    deadline = time.monotonic() + 120
    while c.get(f"/api/tournaments/{tid}").json()["status"] != "done" and time.monotonic() < deadline:
        time.sleep(0.05)
    tour = c.get(f"/api/tournaments/{tid}").json()
    check(tour["games"] == {"total": 2, "done": 2, "failed": 0}, f"its games: {tour['games']}")
    # The oracle: each game played again by simbot match from the stored
    # programs and seed; wins and hits counted here.
    programs = {"fig": SHARED / "programs/fig92.dc", "ice": SHARED / "programs/iceman.dc"}
    games = rows(QURL, "select ta.name, tb.name, m.seed, m.seconds from matches m "
                 "join submissions sa on sa.id = m.a_submission_id join teams ta on ta.id = sa.team_id "
                 "join submissions sb on sb.id = m.b_submission_id join teams tb on tb.id = sb.team_id "
                 "where m.tournament_id = :tid order by m.id", tid=tid)
    check(sorted((a, b) for a, b, _, _ in games) == [("fig", "ice"), ("ice", "fig")],
          f"each side once: {games}")
    expect = {"fig": [0, 0, 0, 0], "ice": [0, 0, 0, 0]}  # played, wins, losses, hits
    for a, b, seed, _ in games:
        res = direct(programs[a], programs[b], seed)
        for name, robot in zip((a, b), res["robots"]):
            expect[name][0] += 1
            expect[name][3] += robot["hits"]
        winner = a if res["winner"] == "A" else b
        expect[winner][1] += 1
        expect[b if winner == a else a][2] += 1
    for entry in tour["table"]:
        e = expect[entry["team"]]
        check([entry["played"], entry["wins"], entry["losses"], entry["hits"]] == e,
              f"{entry['team']}: {entry} against {e}")
        check(entry["ci_low"] < entry["rating"] < entry["ci_high"], f"an interval about the rating: {entry}")
    # Bradley-Terry by direct maximisation of the same likelihood
    # (scipy), the two virtual games per participant included.
    from scipy.optimize import minimize

    def nll(b):
        bt = dict(zip(("fig", "ice"), b))
        total = 0.0
        for name in bt:
            total += np.logaddexp(0, -bt[name]) + np.logaddexp(0, bt[name])
        for name, e in expect.items():
            other = "ice" if name == "fig" else "fig"
            total += e[1] * np.logaddexp(0, -(bt[name] - bt[other]))
        return total
    import numpy as np
    best = minimize(nll, np.zeros(2), method="BFGS").x
    for entry in tour["table"]:
        want = best[0] if entry["team"] == "fig" else best[1]
        check(abs(entry["rating"] - want) < 1e-4, f"{entry['team']}'s rating {entry['rating']} against {want}")
    table = c.get("/api/standings").json()
    check({e["team"] for e in table} == {"fig", "ice"} and all(e["played"] >= 2 for e in table),
          f"the standings count every match: {table}")

# A killed server: a match left "running" and one queued; a match whose
# house robot is gone. At the next start the first two run, the third is
# "failed" with its error.
sessions = db.sessions(queued.state.engine)
with sessions() as s:
    sub = s.execute(__import__("sqlalchemy").select(Submission).limit(1)).scalar()
    left = [Match(kind="scrimmage", a_submission_id=sub.id, b_house="turret", seed=7, seconds=10,
                  status=st) for st in ("running", "queued")]
    gone = Match(kind="scrimmage", a_submission_id=sub.id, b_house="gone", seed=7, seconds=10,
                 status="queued")
    s.add_all(left + [gone])
    s.commit()
    ids = [m.id for m in left] + [gone.id]
restarted = create_app(QURL, str(QDATA), SIMBOT, house=str(SOURCE / "programs"),
                       workers=2, seconds=10)
with TestClient(restarted) as c:
    got = [wait_done(c, i) for i in ids]
check([g["status"] for g in got] == ["done", "done", "failed"],
      f"after a restart: {[(g['status'], g['error']) for g in got]}")
check(got[0]["result"] == got[1]["result"], "the same seed gives the same result")
check("no house robot 'gone'" in (got[2]["error"] or ""), f"the failure says why: {got[2]['error']}")

# Two servers' queues on one database (what PostgreSQL allows), 4
# workers each, take 120 matches queued at once: each match is run once.
# Their simbot is a script that logs the seed it is given (each match has
# its own) and answers a match without a winner.
fake = OUT / "fake-simbot"
runs = OUT / "runs.log"
fake.write_text(f"""#!/bin/sh
while [ $# -gt 0 ]; do [ "$1" = --seed ] && echo "$2" >> '{runs}'; shift; done
echo '{{"robots": [], "winner": null}}'
""")
fake.chmod(0o755)
twins = [create_app(QURL, str(QDATA), str(fake), house=str(SOURCE / "programs"), workers=4, seconds=10)
         for _ in range(2)]
with TestClient(twins[0]) as c, TestClient(twins[1]):
    with sessions() as s:
        crowd = [Match(kind="scrimmage", a_submission_id=sub.id, b_house="turret", seed=1000 + k,
                       seconds=10, status="queued") for k in range(120)]
        s.add_all(crowd)
        s.commit()
        ids = [m.id for m in crowd]
    for twin in twins:
        twin.state.queue.notify()
    got = [wait_done(c, i) for i in ids]
check(all(g["status"] == "done" for g in got), f"all 120 done: {[g['status'] for g in got][:5]}...")
seeds = sorted(int(line) for line in runs.read_text().split())
check(seeds == list(range(1000, 1120)),
      f"each match run once: {len(seeds)} runs, {len(set(seeds))} matches")

# ---- simbot serve: the real server over the loopback; a tournament
# killed with SIGKILL mid-way and restarted ends with the table of one run
# without the kill (the same teams, programs and tournament seed).
import signal  # noqa: E402
import socket  # noqa: E402
import urllib.error  # noqa: E402
import urllib.request  # noqa: E402


def free_port():
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


class Live:
    def __init__(self, data, url):
        self.data, self.port = data, free_port()
        self.base = f"http://127.0.0.1:{self.port}"
        # SQLite: the default database (no --db), DATA/simbot.sqlite3.
        self.process = subprocess.Popen(
            [SIMBOT, "serve", "--data", str(data), "--port", str(self.port), "--workers", "2",
             *(["--db", url] if POSTGRES else [])],
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        # Its first line the instructor's token (first start only), then
        # "simbot serve: listening on ...".
        self.first = ""
        line = self.process.stdout.readline()
        if not line.startswith("simbot serve: listening"):
            self.first = line
            self.process.stdout.readline()
        for _ in range(200):
            try:
                urllib.request.urlopen(self.base + "/api/standings", timeout=5)
                break
            except urllib.error.URLError:
                time.sleep(0.05)

    def call(self, path, body=None, token=None, files=None):
        headers = {"Authorization": f"Bearer {token}"} if token else {}
        data = None
        if files is not None:
            boundary = "simbot-test-boundary"
            name, content = files
            data = (f"--{boundary}\r\nContent-Disposition: form-data; name=\"program\"; "
                    f"filename=\"{name}\"\r\nContent-Type: application/octet-stream\r\n\r\n"
                    ).encode() + content + f"\r\n--{boundary}--\r\n".encode()
            headers["Content-Type"] = f"multipart/form-data; boundary={boundary}"
        elif body is not None:
            data = json.dumps(body).encode()
            headers["Content-Type"] = "application/json"
        request = urllib.request.Request(self.base + path, data=data, headers=headers)
        try:
            with urllib.request.urlopen(request, timeout=30) as answer:
                return answer.status, json.loads(answer.read())
        except urllib.error.HTTPError as e:
            return e.code, json.loads(e.read() or b"null")

    def kill(self, sig):
        self.process.send_signal(sig)
        self.process.wait(timeout=30)


def league(data, url):
    """A server on the empty database at `url` with three teams (fig92,
    ICEMAN, turret) and a 30-game round robin of 180-s matches, seed 99;
    returns the server and the tournament's id."""
    live = Live(data, url)
    token = (data / "instructor-token").read_text().strip()
    check(live.first.rstrip().endswith(token), f"simbot serve prints the token: {live.first!r}")
    for name, program in [("fig", SHARED / "programs/fig92.dc"), ("ice", SHARED / "programs/iceman.dc"),
                          ("turret", SOURCE / "programs/turret.dc")]:
        status, team = live.call("/api/teams", {"name": name}, token)
        check(status == 201, f"{name}: {status} {team}")
        status, _ = live.call("/api/submissions", token=team["token"],
                              files=(program.name, program.read_bytes()))
        check(status == 201, f"{name}'s program: {status}")
    status, tour = live.call("/api/tournaments", {"rounds": 10, "seed": 99}, token)
    check(status == 201 and tour["games"] == 30, f"a 30-game round robin: {status} {tour}")
    return live, tour["id"]


def finish(live, tid):
    deadline = time.monotonic() + 240
    while time.monotonic() < deadline:
        status, tour = live.call(f"/api/tournaments/{tid}")
        if tour["status"] == "done":
            return tour
        time.sleep(0.1)
    return tour


killed_url = fresh_database("killed", OUT / "killed")
killed, tid = league(OUT / "killed", killed_url)
done = 0
deadline = time.monotonic() + 120
while done < 2 and time.monotonic() < deadline:
    done = killed.call(f"/api/tournaments/{tid}")[1]["games"]["done"]
    time.sleep(0.01)
killed.kill(signal.SIGKILL)
check(2 <= done < 30, f"killed with {done} of 30 games done")
again = Live(OUT / "killed", killed_url)
check(again.first == "", f"no new token at a restart: {again.first!r}")
after = finish(again, tid)
again.kill(signal.SIGTERM)
whole, tid2 = league(OUT / "whole", fresh_database("whole", OUT / "whole"))
uninterrupted = finish(whole, tid2)
whole.kill(signal.SIGTERM)
check(after["games"] == {"total": 30, "done": 30, "failed": 0}, f"after the restart: {after['games']}")
strip = [{k: v for k, v in e.items() if k != "team_id"} for e in after["table"]]
check(strip == [{k: v for k, v in e.items() if k != "team_id"} for e in uninterrupted["table"]],
      f"the same table: {after['table']} and {uninterrupted['table']}")
if failures:
    sys.exit(f"{len(failures)} check(s) failed")
print(f"server_test: all checks passed on {arguments.db}")
