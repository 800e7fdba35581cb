#!/usr/bin/env python3
"""simbot serve against a hostile client: every field of every endpoint
(the API and the form POST /submit) with markup, SQL, paths, control
characters, huge and wrong-typed values; the expected answer for each, and
nothing stored that should not be, nothing executed, no file named from
user text, the pages showing the text escaped.

Usage: server_hostile_test.py SIMBOT SOURCE_DIR SHARED_DIR OUTDIR

The oracles are written here, not taken from the server: each request's
status by hand from docs/serve.md; the database's row counts (read with
sqlite3, not through the server) unchanged by every refused request and
up by exactly the rows an accepted one makes; the shown file names by hand
from the documented rule (the base name if it is letters, digits, '.',
'_' and '-', at most 128 characters, else program.dc); HTML escaping by
hand (< &lt;, > &gt;); the replay page's escaping by the viewer's
documented rule ('<' inside its JSON as \\u003c); the rate limits'
refill by hand computation. A unique MARKER in every path-like or
shell-like text lets a walk of the data folder, OUTDIR, /tmp and the
folders above find any file made from user text (none may exist).

Server bugs this test found and shows fixed (each a 500 or a bound
bypassed before): a team's name with a lone surrogate (JSON "\\ud800") or
a C1 control character; an id past 2^63 - 1 in any path or as a
scrimmage's opponent (SQLite's OverflowError); a rule set's name or a file
name with a trailing newline (re's `$`); a program with a NUL byte (which
PostgreSQL cannot keep as text); a body with both Content-Length and
Transfer-Encoding: chunked (the server read the chunks past the 72-KiB
bound); the form's 429 without Retry-After.
"""
import contextlib
import json
import os
import re
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

from fastapi.testclient import TestClient  # noqa: E402

from simbot_server import db  # noqa: E402
from simbot_server.app import create_app  # noqa: E402
from simbot_server.limits import RateLimits  # noqa: E402

from scriptcheck import check, failures

shutil.rmtree(OUT, ignore_errors=True)
OUT.mkdir(parents=True)
DATA = OUT / "data"
DATABASE = DATA / "simbot.sqlite3"
MARKER = f"hostile{os.getpid()}x"  # in every name that could become a file
TABLES = ("settings", "teams", "submissions", "matches", "tournaments")
statuses = []  # every answer's status: no 5xx, ever


def esc(text):
    """HTML escaping of < and > by hand (the pages' autoescape does more: ' and ")."""
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def counts():
    with contextlib.closing(sqlite3.connect(DATABASE)) as c:
        return {t: c.execute(f"select count(*) from {t}").fetchone()[0] for t in TABLES}


@contextlib.contextmanager
def adds(label, **delta):
    """The rows the block must add (table=n); every other table unchanged."""
    before = counts()
    yield
    after = counts()
    want = {t: before[t] + delta.get(t, 0) for t in TABLES}
    check(after == want, f"{label}: rows {after}, expected {want}")


class Client:
    """FastAPI's test client that keeps every status (a 500 is an answer
    here, not an exception, so that it is seen and counted)."""

    def __init__(self, http):
        self.http = http

    def __getattr__(self, method):
        def call(*args, **kwargs):
            r = getattr(self.http, method)(*args, **kwargs)
            statuses.append((r.status_code, method, args[0]))
            return r
        return call


def auth(token):
    return {"Authorization": f"Bearer {token}"}


def multipart(parts):
    """A multipart body by hand (raw bytes in file names, as a client may
    send them): parts are (field, file name bytes or None, content bytes)."""
    boundary = b"hostile-boundary-7f3a"
    body = b""
    for field, file_name, content in parts:
        body += b"--" + boundary + b"\r\nContent-Disposition: form-data; name=\"" + field + b"\""
        if file_name is not None:
            body += b"; filename=\"" + file_name + b"\""
        body += b"\r\nContent-Type: application/octet-stream\r\n\r\n" + content + b"\r\n"
    body += b"--" + boundary + b"--\r\n"
    return body, {"Content-Type": "multipart/form-data; boundary=" + boundary.decode()}


def api_submit(c, token, file_name, content):
    body, headers = multipart([(b"program", file_name, content)])
    return c.post("/api/submissions", content=body, headers={**headers, **auth(token)})


def form_submit(c, token, file_name, content):
    body, headers = multipart([(b"token", None, token.encode()), (b"program", file_name, content)])
    return c.post("/submit", content=body, headers=headers)


def stored_file_names(team_id):
    with contextlib.closing(sqlite3.connect(DATABASE)) as c:
        return [r[0] for r in c.execute("select file_name from submissions where team_id = ? "
                                        "order by version", (team_id,))]


app = create_app(db.default_url(DATA), str(DATA), SIMBOT, house=str(SOURCE / "programs"),
                 workers=2, seconds=5)
c = Client(TestClient(app, raise_server_exceptions=False))  # the queue does not run yet: scrimmages stay queued
instructor = (DATA / "instructor-token").read_text().strip()
TINY = b"main()\n{\n}\n"
FIG92 = (SHARED / "programs/fig92.dc").read_bytes()
# The hostile program: fig92 (it has a warning, so the form lists it) with
# markup, SQL and bytes past ASCII in a comment and markup printed on the
# robot's console.
RAW = f"</script><script>alert({MARKER})</script>"
HOSTILE = (f"/* {RAW} '); DROP TABLE submissions; -- ".encode() + b"\xff\xfe caf\xe9 */\n"
           + FIG92.replace(b"main()\n{\n", f"main()\n{{\n    printf(\"{RAW}\\n\");\n".encode(), 1))
check(HOSTILE.count(RAW.encode()) == 2, "the hostile program carries the markup twice")

# ---- tokens: every endpoint that needs one, with no token, a malformed
# one, a wrong one, SQL as a token, and the other kind's token.
with adds("the instructor makes the players", teams=8):
    players = [c.post("/api/teams", json={"name": f"player-{i}"}, headers=auth(instructor)).json()
               for i in range(4)]
    submitters = [c.post("/api/teams", json={"name": f"submitter-{i}"},
                         headers=auth(instructor)).json() for i in range(4)]
check(counts()["teams"] == 8, "eight teams made")
team_token = players[0]["token"]
calls = [("post", "/api/teams", {"json": {"name": "intruder"}}, "instructor"),
         ("post", "/api/tournaments", {"json": {"rounds": 1, "seconds": 5}}, "instructor"),
         ("post", "/api/submissions", {"files": {"program": ("a.dc", TINY)}}, "team"),
         ("post", "/api/scrimmages", {"json": {"opponent": "house:turret"}}, "team")]
bad_headers = [({}, 401), ({"Authorization": "Basic eDp5"}, 401), ({"Authorization": "Bearer"}, 401),
               ({"Authorization": "bearer " + instructor}, 401),
               (auth(""), 403), (auth("wrong"), 403), (auth("' OR '1'='1' --"), 403),
               (auth(instructor + "x"), 403), (auth(team_token[:-1]), 403)]
with adds("no request with a wrong token stores anything"):
    for method, path, kwargs, needs in calls:
        other = auth(team_token) if needs == "instructor" else auth(instructor)
        for headers, status in bad_headers + [(other, 403)]:
            r = getattr(c, method)(path, headers=headers, **kwargs)
            check(r.status_code == status, f"{path} with {headers}: {r.status_code}, expected {status}")
    for token in ["", "wrong", "' OR '1'='1' --", instructor, "\u00ff" * 40]:
        r = form_submit(c, token, b"a.dc", TINY)
        check(r.status_code == 403 and "That is not a team&#39;s token." in r.text,
              f"the form with token {token[:12]!r}: {r.status_code}")

# ---- teams: hostile names are text, stored once and given back as sent
NAME = f"<script>alert({MARKER})</script>"
JINJA = "{{ 'pwn' ~ 'jinja' }}"
kept_names = [NAME, "x'); DROP TABLE teams; --", "Robert'); DROP TABLE submissions;--", JINJA,
              f"$(touch /tmp/{MARKER}-sh)", f"`touch /tmp/{MARKER}-bt`", f"../../{MARKER}-dir",
              "a" * 64, "\u00e9" * 64, "\u202eevil"]
team_ids = {}
for name in kept_names:
    with adds(f"name {name!r}", teams=1):
        r = c.post("/api/teams", json={"name": name}, headers=auth(instructor))
    check(r.status_code == 201, f"name {name!r}: {r.status_code} {r.text}")
    if r.status_code == 201:
        team_ids[name] = r.json()
        got = c.get(f"/api/teams/{r.json()['id']}").json()["name"]
        check(got == name, f"name {name!r} comes back as {got!r}")
with contextlib.closing(sqlite3.connect(DATABASE)) as q:
    check(q.execute("select count(*) from teams where name = ?", (NAME,)).fetchone() == (1,),
          "the markup name stored as the text sent")
refused_names = ["", " \t ", "a" * 65, "\u00e9" * 65, "\x00", "a\x00b", "tab\there", "line\nbreak",
                 "\x7f", "next\u0085line", None, 7, 1.5, True, ["x"], {"$ne": ""}]
with adds("refused names store nothing"):
    for bad in refused_names:
        r = c.post("/api/teams", json={"name": bad}, headers=auth(instructor))
        check(r.status_code == 422, f"name {bad!r}: {r.status_code} {r.text[:80]}")
    # A lone surrogate can only come as a JSON escape.
    r = c.post("/api/teams", content=b'{"name": "a\\ud800b"}',
               headers={**auth(instructor), "Content-Type": "application/json"})
    check(r.status_code == 422, f"a lone surrogate in a name: {r.status_code}")
    r = c.post("/api/teams", json={"name": NAME}, headers=auth(instructor))
    check(r.status_code == 409, f"a name taken: {r.status_code}")
    for body in [b"", b"[]", b'"x"', b"null", b"{", b"{\"name\": }", b"[" * 30000 + b"]" * 30000,
                 b'{"name": ' + b"9" * 5000 + b"}"]:
        r = c.post("/api/teams", content=body,
                   headers={**auth(instructor), "Content-Type": "application/json"})
        check(r.status_code in (400, 422), f"body {body[:20]!r}...: {r.status_code}")

MAX_BODY = 72 * 1024  # a request body's bound (docs/serve.md)

# ---- submissions: file names (raw bytes as sent) and the names shown,
# by hand from the documented rule.
file_names = [
    (b"fig92.dc", "fig92.dc"),
    (f"../../{MARKER}-up.dc".encode(), f"{MARKER}-up.dc"),
    (f"/tmp/{MARKER}-abs.dc".encode(), f"{MARKER}-abs.dc"),
    (f"..\\..\\{MARKER}-win.dc".encode(), f"{MARKER}-win.dc"),
    (f"C:\\{MARKER}-drive.dc".encode(), f"{MARKER}-drive.dc"),
    (f"{MARKER}\x00.dc".encode(), "program.dc"),
    (f"{MARKER}.dc\n".encode(), "program.dc"),  # a trailing newline: stored as such before
    (b"A" * 125 + b".dc", "A" * 125 + ".dc"),  # 128 characters: the longest kept
    (b"A" * 126 + b".dc", "program.dc"),
    (b"A" * 4000 + b".dc", "program.dc"),
    (f"<script>alert({MARKER})</script>.dc".encode(), "program.dc"),
    (b"x'); DROP TABLE submissions; --.dc", "program.dc"),
    (f"$(touch /tmp/{MARKER}-fn).dc".encode(), "program.dc"),
    (f"`touch {MARKER}-bt`.dc".encode(), "program.dc"),
    (b".", "program.dc"), (b"..", "program.dc"), (b"", "program.dc"),
    (f"%2e%2e%2f{MARKER}-pct.dc".encode(), "program.dc"),
    (b"\xff\xfe.dc", "program.dc"),
]
budget = {s["token"]: 6 for s in submitters}  # the rate limit: 6 a minute each


def next_submitter():
    token = next(t for t, left in budget.items() if left > 0)
    budget[token] -= 1
    return token


shown = {}
for k, (sent, want) in enumerate(file_names):
    token = next_submitter()
    via_form = k % 4 == 3  # every fourth through the web form
    with adds(f"file name {sent[:40]!r}", submissions=1):
        r = (form_submit if via_form else api_submit)(c, token, sent, TINY)
    check(r.status_code == (200 if via_form else 201), f"file name {sent[:40]!r}: {r.status_code}")
    shown.setdefault(token, []).append(want)
for s in submitters:
    got = stored_file_names(s["id"])
    check(got == shown.get(s["token"], []), f"{s['id']}: file names {got}, expected {shown.get(s['token'])}")

# The programs: the hostile one stored byte for byte; a NUL byte, an
# #error with markup, 64 KiB + 1 refused with nothing stored.
hostile_team = team_ids[NAME]
with adds("the hostile program", submissions=1):
    r = api_submit(c, hostile_team["token"], b"hostile.dc", HOSTILE)
check(r.status_code == 201 and r.json()["version"] == 1, f"the hostile program: {r.status_code} {r.text[:200]}")
with contextlib.closing(sqlite3.connect(DATABASE)) as q:
    source = q.execute("select source from submissions where team_id = ?", (hostile_team["id"],)).fetchone()[0]
check(source.encode("latin-1") == HOSTILE, "the hostile program is stored byte for byte")
# A NUL in a comment compiles, but PostgreSQL cannot keep it: refused at
# its place, line 2, column 5 ("/* a" before it).
with adds("a NUL byte stores nothing"):
    r = api_submit(c, hostile_team["token"], b"nul.dc", b"main()\n/* a\x00b */\n{\n}\n")
check(r.status_code == 422 and r.json()["errors"] == ["nul.dc:2:5: error: a NUL byte (a program is text)"],
      f"a NUL byte: {r.status_code} {r.text}")
ERROR_PROGRAM = f"main()\n{{\n}}\n#error {RAW}\n".encode()
with adds("an #error stores nothing"):
    r = api_submit(c, hostile_team["token"], b"err.dc", ERROR_PROGRAM)
check(r.status_code == 422 and r.json()["errors"] == [f"err.dc:4:1: error: #error {RAW}"],
      f"the #error's text comes back as a JSON string: {r.status_code} {r.text}")
# The form, as the hostile team: the program's lines listed escaped, the
# team's name escaped, never the raw markup.
with adds("the hostile program through the form", submissions=1):
    r = form_submit(c, hostile_team["token"], b"hostile.dc", HOSTILE)
check(r.status_code == 200 and 'id="accepted"' in r.text, f"the form keeps it: {r.status_code}")
check(esc(RAW) in r.text and RAW not in r.text, "the form lists the program escaped")
check(esc(NAME) in r.text and NAME not in r.text, "the form names the team escaped")
check("caf\u00e9" in r.text, "bytes past ASCII listed as Latin-1")
with adds("an #error through the form stores nothing"):
    r = form_submit(c, hostile_team["token"], b"err.dc", ERROR_PROGRAM)
check(r.status_code == 422 and esc(f"err.dc:4:1: error: #error {RAW}") in r.text and RAW not in r.text,
      f"the form shows the #error escaped: {r.status_code}")
check(not re.search(r"<script", r.text, re.I), "no <script> on the submit page at all")
# 64 KiB is kept; 64 KiB + 1 byte is not (the form says why).
top = b"/*" + b"x" * (64 * 1024 - 4 - len(TINY)) + b"*/" + TINY
check(len(top) == 65536, "a program of 64 KiB")
with adds("64 KiB", submissions=1):
    r = api_submit(c, next_submitter(), b"top.dc", top)
check(r.status_code == 201, f"a program of 64 KiB: {r.status_code} {r.text[:100]}")
with adds("64 KiB + 1 stores nothing"):
    r = form_submit(c, next_submitter(), b"over.dc", top + b"\n")
check(r.status_code == 413 and "A program has at most 65536 bytes." in r.text,
      f"64 KiB + 1 through the form: {r.status_code}")
with adds("other fields and parts store nothing"):
    r = c.post("/api/submissions", data={"program": "main(){}"}, headers=auth(next_submitter()))
    check(r.status_code == 422, f"a program as a plain field: {r.status_code}")
    # 1,001 fields in 53 KiB: more than Starlette's parser takes (1,000).
    body = b"".join(b'--b\r\nContent-Disposition: form-data; name="f"\r\n\r\nx\r\n' for _ in range(1001))
    body += b'--b\r\nContent-Disposition: form-data; name="program"; filename="a.dc"\r\n\r\n' + TINY
    body += b"\r\n--b--\r\n"
    r = c.post("/api/submissions", content=body,
               headers={"Content-Type": "multipart/form-data; boundary=b", **auth(next_submitter())})
    check(len(body) < MAX_BODY and r.status_code == 400, f"1,001 form fields: {len(body)} bytes, {r.status_code}")
    r = c.post("/api/submissions", content=b"garbage",
               headers={"Content-Type": "multipart/form-data; boundary=b", **auth(team_token)})
    check(r.status_code == 400, f"a broken multipart body: {r.status_code}")

# ---- scrimmages: every field. The players have a program each; requests
# go round the four (a refused request still counts against the burst of
# 20, RATES in limits.py).
for p in players:
    api_submit(c, p["token"], b"turret.dc", (SOURCE / "programs/turret.dc").read_bytes())
turn = iter(range(10**6))


def scrimmage(body, raw=None):
    token = players[next(turn) % len(players)]["token"]
    if raw is not None:
        return c.post("/api/scrimmages", content=raw,
                      headers={**auth(token), "Content-Type": "application/json"})
    return c.post("/api/scrimmages", json=body, headers=auth(token))


bad_scrimmages = [
    {}, {"opponent": None}, {"opponent": "1 OR 1=1"}, {"opponent": "1'; DROP TABLE matches; --"},
    {"opponent": "house:turret'; DROP TABLE matches; --"}, {"opponent": "house:../programs/turret"},
    {"opponent": "house:" + str(SOURCE / "programs/turret")}, {"opponent": "house:turret.dc"},
    {"opponent": "house:turret\n"}, {"opponent": "house:"}, {"opponent": "HOUSE:turret"},
    {"opponent": f"house:$(touch /tmp/{MARKER}-house)"}, {"opponent": 10**30},
    {"opponent": 2**63}, {"opponent": -1}, {"opponent": 0}, {"opponent": 999999},
    {"opponent": True}, {"opponent": 1.0}, {"opponent": [1]}, {"opponent": {"$gt": 0}},
    {"opponent": "house:turret", "seed": -1}, {"opponent": "house:turret", "seed": 2**63},
    {"opponent": "house:turret", "seed": 10**40}, {"opponent": "house:turret", "seed": 1.5},
    {"opponent": "house:turret", "seed": "1; DROP TABLE matches"},
    {"opponent": "house:turret", "seed": True}, {"opponent": "house:turret", "seed": None},
    {"opponent": "house:turret", "seed": {"a": 1}}, {"opponent": "house:turret", "seed": [1]},
]
with adds("refused scrimmages store nothing"):
    for body in bad_scrimmages:
        r = scrimmage(body)
        check(r.status_code == 422, f"scrimmage {body}: {r.status_code} {r.text[:100]}")
    for raw in [b'{"opponent": "house:turret", "seed": NaN}', b'{"opponent": "house:turret", "seed": 1e400}']:
        r = scrimmage(None, raw)
        check(r.status_code == 422, f"scrimmage {raw}: {r.status_code}")
# The edges that are accepted: seeds 0 and 2^63 - 1, the hostile team as
# opponent and as robot A.
with adds("four scrimmages", matches=4):
    for body in [{"opponent": "house:turret", "seed": 0}, {"opponent": "house:turret", "seed": 2**63 - 1},
                 {"opponent": hostile_team["id"], "seed": 3}]:
        r = scrimmage(body)
        check(r.status_code == 201, f"scrimmage {body}: {r.status_code} {r.text}")
    r = c.post("/api/scrimmages", json={"opponent": "house:turret", "seed": 4},
               headers=auth(hostile_team["token"]))
    check(r.status_code == 201, f"the hostile team's scrimmage: {r.status_code}")
    hostile_match = r.json()["match_id"]
# The waiting cap: 10 of a team's matches queued (the queue is not running
# yet), the 11th refused.
waiting = c.post("/api/teams", json={"name": "waiter"}, headers=auth(instructor)).json()
api_submit(c, waiting["token"], b"tiny.dc", TINY)
with adds("ten waiting", matches=10):
    for k in range(10):
        r = c.post("/api/scrimmages", json={"opponent": "house:turret", "seed": k},
                   headers=auth(waiting["token"]))
        check(r.status_code == 201, f"waiting {k}: {r.status_code} {r.text}")
with adds("the eleventh waiting stores nothing"):
    r = c.post("/api/scrimmages", json={"opponent": "house:turret"}, headers=auth(waiting["token"]))
check(r.status_code == 429 and "at most 10 matches waiting" in r.text, f"the 11th: {r.status_code} {r.text}")

# ---- tournaments: every field
bad_tournaments = [
    {"rules": "x'; DROP TABLE matches; --"}, {"rules": "abc\n"}, {"rules": "../rules/se3015-1996"},
    {"rules": "/etc/passwd"}, {"rules": "se3015.toml"}, {"rules": "a" * 65}, {"rules": ""},
    {"rules": f"$(touch /tmp/{MARKER}-rules)"}, {"rules": 5}, {"rules": True}, {"rules": ["a"]},
    {"rules": {"$ne": 1}},
    {"rounds": 0}, {"rounds": -1}, {"rounds": 101}, {"rounds": 10**30}, {"rounds": "1"},
    {"rounds": 1.0}, {"rounds": True}, {"rounds": None}, {"rounds": {}},
    {"seconds": 0}, {"seconds": -5}, {"seconds": 1001}, {"seconds": 10**30}, {"seconds": "60; DROP"},
    {"seconds": 2.5}, {"seconds": False}, {"seconds": [60]},
    {"seed": -1}, {"seed": 2**63}, {"seed": 10**40}, {"seed": "7"}, {"seed": 7.5}, {"seed": True},
    {"seed": [1]}, {"seed": None},
    {"reload_on_fault": "true"}, {"reload_on_fault": 1}, {"reload_on_fault": 0},
    {"reload_on_fault": None}, {"reload_on_fault": {"a": 1}},
]
with adds("refused tournaments store nothing"):
    for body in bad_tournaments:
        r = c.post("/api/tournaments", json={"seconds": 5, **body}, headers=auth(instructor))
        check(r.status_code == 422, f"tournament {body}: {r.status_code} {r.text[:100]}")
with contextlib.closing(sqlite3.connect(DATABASE)) as q:
    entrants = q.execute("select count(distinct team_id) from submissions").fetchone()[0]
games = entrants * (entrants - 1) // 2
with adds("a round robin", tournaments=1, matches=games):
    r = c.post("/api/tournaments", json={"rules": "se3015-1997w", "rounds": 1, "seconds": 5,
                                         "seed": 2**63 - 1, "reload_on_fault": True},
               headers=auth(instructor))
check(r.status_code == 201 and r.json()["games"] == games, f"a round robin of {entrants}: {r.status_code} {r.text}")
tournament = r.json()["id"]

# ---- path parameters: a row's id is 0 to 2^63 - 1; else 422 (a 500 before)
ids = [("1%27%20OR%201=1", 422), ("1;DROP%20TABLE%20teams", 422), ("-1", 422),
       ("99999999999999999999999", 422), (str(2**63), 422), (str(2**63 - 1), 404), ("0", 404),
       ("1.5", 422), ("abc", 422), ("%00", 422), ("..%2F..%2Fetc%2Fpasswd", 404)]
paths = ["/api/matches/{}", "/api/teams/{}", "/api/tournaments/{}", "/teams/{}", "/matches/{}",
         "/matches/{}/replay", "/tournaments/{}"]
with adds("no GET stores anything"):
    for path in paths:
        for value, status in ids:
            r = c.get(path.format(value))
            check(r.status_code == status, f"GET {path.format(value)}: {r.status_code}, expected {status}")
    r = c.get(f"/matches/{hostile_match}/replay")
    check(r.status_code == 404, f"no replay of a queued match: {r.status_code}")

# ---- bodies: at most 72 KiB (73,728 bytes) declared; none in chunks
with adds("bodies past the bound store nothing"):
    for size, status in [(MAX_BODY, 422), (MAX_BODY + 1, 413)]:
        body = json.dumps({"name": "n" * (size - len('{"name": ""}'))}).encode()
        check(len(body) == size, "the body's size")
        r = c.post("/api/teams", content=body, headers={**auth(instructor), "Content-Type": "application/json"})
        check(r.status_code == status, f"a body of {size} bytes: {r.status_code}, expected {status}")
    body, headers = multipart([(b"program", b"big.dc", b"/*" + b"x" * MAX_BODY + b"*/")])
    r = c.post("/api/submissions", content=body, headers={**headers, **auth(team_token)})
    check(r.status_code == 413, f"an upload past 72 KiB: {r.status_code}")
    body, headers = multipart([(b"token", None, team_token.encode()), (b"program", b"big.dc", b"x" * MAX_BODY)])
    r = c.post("/submit", content=body, headers=headers)
    check(r.status_code == 413, f"a form past 72 KiB: {r.status_code}")

    def chunks():
        yield b'{"name": '
        yield b'"chunked"}'
    r = c.post("/api/teams", content=chunks(), headers={**auth(instructor), "Content-Type": "application/json"})
    check(r.status_code == 411, f"a chunked body: {r.status_code}")
    r = c.post("/api/teams", content=b'{"name": "both"}', headers={
        **auth(instructor), "Content-Type": "application/json", "Transfer-Encoding": "chunked"})
    check(r.status_code == 411, f"Content-Length and chunked: {r.status_code}")

# ---- rate limits: the 7th submission within a minute is 429 with
# Retry-After, through the API and the form alike; another team is not
# limited. (The seven take well under the 10 s one token takes to come back.)
r1, r2 = [c.post("/api/teams", json={"name": f"rate-{k}"}, headers=auth(instructor)).json() for k in (1, 2)]
with adds("six submissions", submissions=6):
    for k in range(6):
        r = (form_submit if k % 2 else api_submit)(c, r1["token"], b"tiny.dc", TINY)
        check(r.status_code == (200 if k % 2 else 201), f"submission {k + 1}: {r.status_code}")
with adds("the 7th and 8th store nothing"):
    r = api_submit(c, r1["token"], b"tiny.dc", TINY)
    retry = r.headers.get("retry-after", "")
    check(r.status_code == 429 and retry.isdigit() and 1 <= int(retry) <= 10,
          f"the 7th: {r.status_code}, Retry-After {retry!r}")
    r = form_submit(c, r1["token"], b"tiny.dc", TINY)
    retry = r.headers.get("retry-after", "")
    check(r.status_code == 429 and "at most 6 submissions a minute; try again in" in r.text
          and retry.isdigit() and 1 <= int(retry) <= 10,
          f"the form says so: {r.status_code}, Retry-After {retry!r}")
with adds("another team", submissions=1):
    r = api_submit(c, r2["token"], b"tiny.dc", TINY)
check(r.status_code == 201, f"another team is not limited: {r.status_code}")
# Scrimmages: a burst of 20, refused ones counted (they were taken before
# their check); then one a second comes back, so requests faster than that
# meet a 429 (Retry-After: 1) soon after the 20th.
with adds("scrimmage burst stores nothing"):
    answers = []
    for k in range(40):
        r = c.post("/api/scrimmages", json={"seed": -1}, headers=auth(r2["token"]))
        answers.append((r.status_code, r.headers.get("retry-after")))
        if r.status_code == 429:
            break
    check(answers[:20] == [(422, None)] * 20 and answers[-1] == (429, "1"),
          f"scrimmages: 20 of a burst, then 429: {answers}")

# RateLimits with an injected clock, by hand: submissions 6 a minute, a
# burst of 6, so one token per 10 s. At t = 0 six are taken and the 7th
# waits (1 - 0) * 10 = 10 s; at t = 5 the bucket holds 5 * 6 / 60 = 0.5,
# so 5 s more; at t = 10 it holds 0.5 + 5 * 0.1 = 1: taken (0 left); at
# t = 70 it holds min(6, 60 * 0.1) = 6 again: six taken, the 7th waits
# 10 s. Scrimmages 60 a minute, a burst of 20: the 21st at t = 0 waits
# 1 s; at t = 0.25 (0.25 of a token) 0.75 s. Teams and kinds apart.
now = [0.0]
limits = RateLimits(clock=lambda: now[0])
got = [limits.take(1, "submission") for _ in range(7)]
check(got == [None] * 6 + [10.0], f"six then 10 s: {got}")
check(limits.take(2, "submission") is None, "another team has its own bucket")
now[0] = 5.0
check(limits.take(1, "submission") == 5.0, "at 5 s: 5 s more")
now[0] = 10.0
check(limits.take(1, "submission") is None and limits.take(1, "submission") == 10.0, "at 10 s: one")
now[0] = 70.0
got = [limits.take(1, "submission") for _ in range(7)]
check(got == [None] * 6 + [10.0], f"a minute later, six again: {got}")
got = [limits.take(1, "scrimmage") for _ in range(21)]
check(got == [None] * 20 + [1.0], f"scrimmages: 20 then 1 s: {got[-2:]}")
now[0] = 70.25
check(limits.take(1, "scrimmage") == 0.75, "a quarter token later: 0.75 s")

# ---- the database's growth: a team keeps at most MAX_VERSIONS_PER_TEAM
# versions (409 after, through the API and the form) and asks at most
# MAX_SCRIMMAGES_PER_DAY scrimmages in 24 hours (429 after); both set low
# here: 2 versions, 2 scrimmages.
from simbot_server import app as app_module  # noqa: E402
from simbot_server import submissions as submissions_module  # noqa: E402

grower = c.post("/api/teams", json={"name": "grower"}, headers=auth(instructor)).json()
kept_versions, kept_scrimmages = submissions_module.MAX_VERSIONS_PER_TEAM, app_module.MAX_SCRIMMAGES_PER_DAY
submissions_module.MAX_VERSIONS_PER_TEAM, app_module.MAX_SCRIMMAGES_PER_DAY = 2, 2
with adds("two versions", submissions=2):
    for k in range(2):
        check(api_submit(c, grower["token"], b"tiny.dc", TINY).status_code == 201, f"version {k + 1}")
with adds("a third version stores nothing"):
    r = api_submit(c, grower["token"], b"tiny.dc", TINY)
    check(r.status_code == 409 and "at most 2 versions" in r.text, f"a third version: {r.status_code} {r.text}")
    r = form_submit(c, grower["token"], b"tiny.dc", TINY)
    check(r.status_code == 409 and "at most 2 versions" in r.text, f"the form: {r.status_code}")
with adds("two scrimmages", matches=2):
    for k in range(2):
        r = c.post("/api/scrimmages", json={"opponent": "house:turret", "seed": k}, headers=auth(grower["token"]))
        check(r.status_code == 201, f"scrimmage {k + 1}: {r.status_code} {r.text}")
with adds("a third scrimmage in a day stores nothing"):
    r = c.post("/api/scrimmages", json={"opponent": "house:turret", "seed": 2}, headers=auth(grower["token"]))
    check(r.status_code == 429 and "at most 2 scrimmages a day" in r.text
          and r.headers.get("retry-after") == "3600", f"a third scrimmage: {r.status_code} {r.text}")
submissions_module.MAX_VERSIONS_PER_TEAM, app_module.MAX_SCRIMMAGES_PER_DAY = kept_versions, kept_scrimmages

# ---- the queue runs: every match done; the pages show every name and
# program escaped; the replay page carries the program and its console
# only as JSON with '<' as \u003c.
with contextlib.closing(sqlite3.connect(DATABASE)) as q:
    queued = q.execute("select count(*) from matches").fetchone()[0]
with TestClient(app, raise_server_exceptions=False) as live:
    deadline = time.monotonic() + 240
    while time.monotonic() < deadline:
        with contextlib.closing(sqlite3.connect(DATABASE)) as q:
            left = q.execute("select count(*) from matches where status in ('queued', 'running')").fetchone()[0]
        if left == 0:
            break
        time.sleep(0.2)
    with contextlib.closing(sqlite3.connect(DATABASE)) as q:
        by_status = dict(q.execute("select status, count(*) from matches group by status").fetchall())
    check(by_status == {"done": queued}, f"every match done: {by_status}")
    live_client = Client(live)
    pages = {"/": None, f"/teams/{hostile_team['id']}": None, f"/matches/{hostile_match}": None,
             f"/tournaments/{tournament}": None, f"/teams/{team_ids[JINJA]['id']}": None}
    for path in pages:
        r = live_client.get(path)
        pages[path] = r.text
        check(r.status_code == 200, f"GET {path}: {r.status_code}")
        check(not re.search(r"<script", r.text, re.I), f"{path}: no <script> at all")
    for path in ["/", f"/teams/{hostile_team['id']}", f"/matches/{hostile_match}", f"/tournaments/{tournament}"]:
        check(esc(NAME) in pages[path], f"{path}: the team's name escaped")
    check("pwnjinja" not in "".join(pages.values())
          and "{{ &#39;pwn&#39; ~ &#39;jinja&#39; }}" in pages[f"/teams/{team_ids[JINJA]['id']}"],
          "a template in a name is text")
    check("What happened" in pages[f"/matches/{hostile_match}"], "the match page has its report")
    r = live_client.get(f"/matches/{hostile_match}/replay")
    check(r.status_code == 200, f"the replay page: {r.status_code}")
    check(RAW not in r.text and f"<script>alert({MARKER})" not in r.text,
          "the replay page never carries the program's raw markup")
    check(r.text.count(RAW.replace("<", "\\u003c")) >= 2,
          "the replay page carries the program (source and console) with '<' as \\u003c")

# ---- the real server (uvicorn's HTTP parser): chunked bodies, with and
# without a Content-Length; a Content-Length past the bound; not a number.


def free_port():
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


LIVE = OUT / "live"
port = free_port()
server = subprocess.Popen([sys.executable, "-m", "simbot_server", "--simbot", SIMBOT, "--data", str(LIVE),
                           "--port", str(port)], env={**os.environ, "PYTHONPATH": str(SOURCE / "server")},
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


def raw(request):
    with socket.create_connection(("127.0.0.1", port), timeout=30) as sock:
        with contextlib.suppress(OSError):  # the server may answer and close before the end
            sock.sendall(request)
        answer = b""
        while b"\r\n" not in answer:
            part = sock.recv(4096)
            if not part:
                break
            answer += part
    line = answer.split(b"\r\n")[0].decode("latin-1")
    return int(line.split()[1]) if line.startswith("HTTP/1.1 ") else line


try:
    for _ in range(300):
        try:
            socket.create_connection(("127.0.0.1", port), timeout=1).close()
            break
        except OSError:
            time.sleep(0.05)
    live_token = (LIVE / "instructor-token").read_text().strip().encode()
    head = b"POST /api/teams HTTP/1.1\r\nHost: x\r\nAuthorization: Bearer " + live_token + \
        b"\r\nContent-Type: application/json\r\n"
    name = b'{"name": "' + b"n" * 200000 + b'"}'
    chunked = b"%x\r\n" % len(name) + name + b"\r\n0\r\n\r\n"
    small = b'{"name":"x"}'
    for label, request, want in [
            ("chunked, no length", head + b"Transfer-Encoding: chunked\r\n\r\n" + chunked, 411),
            # 200,000 bytes behind a Content-Length of 13: read before (a 422).
            ("chunked behind a small length", head + b"Content-Length: 13\r\nTransfer-Encoding: chunked\r\n\r\n"
             + chunked, 411),
            ("a length past 72 KiB", head + b"Content-Length: 73729\r\n\r\n" + small, 413),
            ("a length not a number", head + b"Content-Length: \xb2\r\n\r\n" + small, 400),
            ("two lengths", head + b"Content-Length: 12\r\nContent-Length: 99999\r\n\r\n" + small, 400)]:
        got = raw(request)
        check(got == want, f"the real server, {label}: {got}, expected {want}")
    with contextlib.closing(sqlite3.connect(LIVE / "simbot.sqlite3")) as q:
        check(q.execute("select count(*) from teams").fetchone() == (0,), "the real server stored no team")
finally:
    server.send_signal(signal.SIGTERM)
    try:
        server.wait(timeout=30)
    except subprocess.TimeoutExpired:
        server.kill()

# ---- the files: none named from user text anywhere; the data folder
# holds only the server's own names.
found = []
for top in [OUT, Path("/tmp")]:
    for folder, dirs, files in os.walk(top, onerror=lambda e: None):
        found += [os.path.join(folder, n) for n in dirs + files if MARKER in n]
for folder in {Path.cwd(), *DATA.parents, SOURCE, SOURCE.parent, Path.home()}:
    with contextlib.suppress(OSError):
        found += [str(folder / n) for n in os.listdir(folder) if MARKER in n]
check(found == [], f"files named from user text: {found}")
allowed = re.compile(r"^(instructor-token|simbot\.sqlite3(-journal|-wal|-shm)?|replays|replays/\d+\.(html|explain\.txt))$")
for folder in (DATA, LIVE):
    for path in folder.rglob("*"):
        name = path.relative_to(folder).as_posix()
        check(allowed.match(name) is not None, f"an unexpected file in the data folder: {name}")

# ---- the canary: every table still there, the database whole
with contextlib.closing(sqlite3.connect(DATABASE)) as q:
    tables = {r[0] for r in q.execute("select name from sqlite_master where type = 'table'")}
    check(set(TABLES) | {"alembic_version"} <= tables, f"every table there: {sorted(tables)}")
    check(q.execute("pragma integrity_check").fetchone() == ("ok",), "the database is whole")
    check(q.execute("select count(*) from teams").fetchone()[0] == 8 + len(kept_names) + 1 + 2 + 1,
          "the teams made, and only those")
bad = [s for s in statuses if s[0] >= 500]
check(bad == [], f"5xx answers: {bad[:10]}")
print(f"server_hostile_test: {len(statuses)} requests")
if failures:
    sys.exit(f"{len(failures)} check(s) failed")
print("server_hostile_test: all checks passed")
