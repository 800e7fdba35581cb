"""The FastAPI application: the HTTP API over the database.

    POST /api/teams        (instructor) {"name"} -> 201 {"id", "token"}
    POST /api/submissions  (team; multipart field `program`)
                           -> 201 {"version", "warnings", "checks"}
                           or 422 {"errors": ["NAME:LINE:COL: error: ..."]}
    POST /api/scrimmages   (team) {"opponent": TEAM_ID | "house:NAME", "seed"}
                           -> 201 {"match_id"}: the two latest versions, queued
    GET  /api/matches/ID   -> {"status": queued|running|done|failed, "result", ...}
    POST /api/tournaments  (instructor) {"rules", "seconds", "rounds", "reload_on_fault", "seed",
                           "team_hardware"}
                           -> 201 {"id", "seed", "games"}: a round robin, queued
    GET  /api/tournaments/ID -> status, games done, its table
    GET  /api/standings    -> every team's games, wins, hits, rating (standings.py)
    GET  /api/teams/ID     -> {"id", "name", "versions": [...]}

Tokens come as `Authorization: Bearer TOKEN`. Every body is bounded
(MAX_BODY_BYTES, a program MAX_PROGRAM_BYTES); names are checked and kept
as text, shown only as JSON strings (and, in pages, escaped)."""
import datetime
import json
import os
import random
import re
import secrets
import unicodedata

from fastapi import Body, Depends, FastAPI, File, Header, HTTPException, Path, Request, UploadFile
from fastapi.responses import JSONResponse
from sqlalchemy import func, select
from sqlalchemy.exc import IntegrityError

from . import db, submissions, tokens
from .models import MAX_ID, MAX_PROGRAM_BYTES, MAX_TEAM_NAME, Match, Setting, Submission, Team, Tournament
from .limits import RATES, RateLimits
from .pages import add_pages
from .queue import MatchQueue, house_robots
from .replay import Replays
from .standings import standings

MAX_BODY_BYTES = MAX_PROGRAM_BYTES + 8 * 1024  # a program and its multipart framing
MAX_WAITING_PER_TEAM = 10  # a team's scrimmages queued or running at once
MAX_SCRIMMAGES_PER_DAY = 500  # a team's scrimmages asked in the last 24 hours
MAX_ROUNDS = 100  # of a round robin
_RULES_NAME = re.compile(r"^[A-Za-z0-9-]{1,64}$")
INSTRUCTOR_KEY = "instructor_token_hash"
TOKEN_FILE = "instructor-token"


def _write_secret(path, text):
    """Creates `path` readable by its owner only (0600), failing if it exists."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    with os.fdopen(fd, "w") as f:
        f.write(text + "\n")


def _instructor_token(session_factory, data_dir):
    """The instructor token's hash; on first start a new token, written to
    DATA/instructor-token and returned (else None)."""
    with session_factory() as s:
        if s.get(Setting, INSTRUCTOR_KEY) is not None:
            return None
        token = tokens.new_token()
        _write_secret(os.path.join(data_dir, TOKEN_FILE), token)
        s.add(Setting(key=INSTRUCTOR_KEY, value=tokens.token_hash(token)))
        s.commit()
        return token


def latest(s, team_id):
    """A team's latest submission, or None."""
    return s.execute(select(Submission).where(Submission.team_id == team_id)
                     .order_by(Submission.version.desc()).limit(1)).scalar()


def team_by_token(s, token):
    """The team whose token is `token`, or None (tokens are kept as hashes)."""
    if not token:
        return None
    return s.execute(select(Team).where(Team.token_hash == tokens.token_hash(token))).scalar()


def _name_problem(name):
    if not isinstance(name, str) or not name.strip():
        return "a team's name is a non-empty string"
    if len(name) > MAX_TEAM_NAME:
        return f"a team's name has at most {MAX_TEAM_NAME} characters"
    # Cc: C0, DEL and C1 (U+0085 is a line break to Python); Cs: a lone
    # surrogate (JSON's "\ud800"), which no database can store as text.
    if any(unicodedata.category(c) in ("Cc", "Cs") for c in name):
        return "a team's name has no control characters or lone surrogates"
    return None


def create_app(db_url, data_dir, simbot, checks=None, house=None, workers=2, seconds=180,
               dask=None):
    """The application over the database at `db_url` (migrated to the newest
    revision), with `data_dir` for the instructor token, the simbot
    executable `simbot`, the course's expectations file `checks` (run on
    every submission; None: no checks), the folder of house robots
    `house`, `workers` matches at once, each `seconds` long, or with
    `dask` (an address) the matches on that Dask cluster. The match
    queue runs while the application does (its startup and shutdown)."""
    os.makedirs(data_dir, exist_ok=True)
    if os.sep in simbot:  # the compiler and matches run in folders of their own
        simbot = os.path.abspath(simbot)
    engine = db.make_engine(db_url)
    db.migrate(engine)
    session_factory = db.sessions(engine)
    app = FastAPI(title="simbot serve", docs_url=None, redoc_url=None, openapi_url=None)
    # The cluster first: a server that cannot reach it makes no token.
    app.state.queue = queue = MatchQueue(session_factory, simbot, house, workers, dask)
    app.state.new_instructor_token = _instructor_token(session_factory, data_dir)
    app.state.engine = engine
    app.add_event_handler("startup", queue.start)
    app.add_event_handler("shutdown", queue.stop)
    rates = RateLimits()

    def limited(who, kind):
        """429 when team `who` has made too many `kind` requests of late."""
        wait = rates.take(who.id, kind)
        if wait is not None:
            raise HTTPException(429, f"at most {RATES[kind][0]} {kind}s a minute; try again in "
                                     f"{wait:.0f} s", {"Retry-After": str(max(1, round(wait)))})

    add_pages(app, session_factory, simbot, checks, Replays(session_factory, simbot, house, data_dir),
              team_by_token, limited)

    @app.middleware("http")
    async def bounded_bodies(request: Request, call_next):
        length = request.headers.get("content-length")
        # A body sent in chunks could be of any length: only a declared one
        # is read. With both headers the server reads the chunks (RFC 9112
        # 6.3), so a small Content-Length would not bound them.
        chunked = "transfer-encoding" in request.headers
        if (length is None or chunked) and request.method not in ("GET", "HEAD", "OPTIONS"):
            return JSONResponse({"detail": "a request body needs its Content-Length"},
                                status_code=411)
        if length is not None and (not length.isdigit() or int(length) > MAX_BODY_BYTES):
            return JSONResponse({"detail": f"a request body has at most {MAX_BODY_BYTES} bytes"},
                                status_code=413)
        return await call_next(request)

    def session():
        with session_factory() as s:
            yield s

    def bearer(authorization):
        if not authorization or not authorization.startswith("Bearer "):
            raise HTTPException(401, "a bearer token is needed", {"WWW-Authenticate": "Bearer"})
        return tokens.token_hash(authorization[len("Bearer "):].strip())

    def instructor(authorization: str = Header(None), s=Depends(session)):
        given = bearer(authorization)
        stored = s.get(Setting, INSTRUCTOR_KEY)
        if stored is None or not tokens.same_hash(given, stored.value):
            raise HTTPException(403, "the instructor's token is needed")

    def team(authorization: str = Header(None), s=Depends(session)):
        bearer(authorization)  # 401 without one
        found = team_by_token(s, authorization[len("Bearer "):].strip())
        if found is None:
            raise HTTPException(403, "a team's token is needed")
        return found

    @app.post("/api/teams", status_code=201, dependencies=[Depends(instructor)])
    def create_team(body: dict = Body(...), s=Depends(session)):
        name = body.get("name")
        problem = _name_problem(name)
        if problem:
            raise HTTPException(422, problem)
        token = tokens.new_token()
        t = Team(name=name, token_hash=tokens.token_hash(token))
        s.add(t)
        try:
            s.commit()
        except IntegrityError:
            s.rollback()
            raise HTTPException(409, "a team of that name exists")
        return {"id": t.id, "token": token}

    @app.post("/api/submissions", status_code=201)
    def submit(program: UploadFile = File(...), who: Team = Depends(team), s=Depends(session)):
        limited(who, "submission")
        source = program.file.read(MAX_PROGRAM_BYTES + 1)
        if submissions.too_big(source):
            raise HTTPException(413, f"a program has at most {MAX_PROGRAM_BYTES} bytes")
        try:
            out = submissions.submit(s, simbot, checks, who.id, program.filename, source)
        except submissions.Busy as e:
            raise HTTPException(503, str(e))
        except submissions.Full as e:
            raise HTTPException(409, str(e))
        if out.errors:
            return JSONResponse({"errors": out.errors}, status_code=422)
        return {"version": out.submission.version, "warnings": out.warnings, "checks": out.cases}

    @app.post("/api/scrimmages", status_code=201)
    def scrimmage(body: dict = Body(...), who: Team = Depends(team), s=Depends(session)):
        limited(who, "scrimmage")
        opponent, seed = body.get("opponent"), body.get("seed", 1)
        if not isinstance(seed, int) or isinstance(seed, bool) or not 0 <= seed < 2**63:
            raise HTTPException(422, "'seed' is an integer from 0 to 2^63 - 1")
        a = latest(s, who.id)
        if a is None:
            raise HTTPException(409, "submit a program first")
        # Each team's robot as it is now (its /teams/ID/robot form), kept
        # with the match: the match is played, and replayed, with it.
        m = Match(kind="scrimmage", a_submission_id=a.id, seed=seed, seconds=seconds,
                  status="queued", a_hardware=who.hardware)
        if isinstance(opponent, str) and opponent.startswith("house:"):
            if opponent[len("house:"):] not in house_robots(house):
                raise HTTPException(422, f"no such house robot (there are: "
                                         f"{', '.join(sorted(house_robots(house))) or 'none'})")
            m.b_house = opponent[len("house:"):]
        elif isinstance(opponent, int) and not isinstance(opponent, bool):
            b = latest(s, opponent) if 0 <= opponent <= MAX_ID else None
            if b is None:
                raise HTTPException(422, "that team has no program")
            m.b_submission_id = b.id
            m.b_hardware = s.get(Team, opponent).hardware
        else:
            raise HTTPException(422, "'opponent' is a team's id or \"house:NAME\"")
        waiting = s.execute(select(func.count(Match.id)).join(
            Submission, Match.a_submission_id == Submission.id).where(
            Submission.team_id == who.id, Match.status.in_(("queued", "running")))).scalar()
        if waiting >= MAX_WAITING_PER_TEAM:
            raise HTTPException(429, f"a team has at most {MAX_WAITING_PER_TEAM} matches waiting")
        # The database's growth: a day's scrimmages of a team are bounded
        # (a match's row holds its result, a few KB).
        today = s.execute(select(func.count(Match.id)).join(
            Submission, Match.a_submission_id == Submission.id).where(
            Submission.team_id == who.id, Match.kind == "scrimmage",
            Match.created >= datetime.datetime.utcnow() - datetime.timedelta(days=1))).scalar()
        if today >= MAX_SCRIMMAGES_PER_DAY:
            raise HTTPException(429, f"a team plays at most {MAX_SCRIMMAGES_PER_DAY} scrimmages "
                                     f"a day", {"Retry-After": "3600"})
        s.add(m)
        s.commit()
        queue.notify()
        return {"match_id": m.id}

    @app.post("/api/tournaments", status_code=201, dependencies=[Depends(instructor)])
    def create_tournament(body: dict = Body(...), s=Depends(session)):
        rules, rounds = body.get("rules"), body.get("rounds", 1)
        length, reload = body.get("seconds", seconds), body.get("reload_on_fault", False)
        team_hardware = body.get("team_hardware", False)
        seed = body.get("seed", secrets.randbits(63))
        if rules is not None and (not isinstance(rules, str) or not _RULES_NAME.fullmatch(rules)):
            raise HTTPException(422, "'rules' is a rule set's name (letters, digits, '-')")
        for name, value, top in (("rounds", rounds, MAX_ROUNDS), ("seconds", length, 1000),
                                 ("seed", seed, 2**63 - 1)):
            if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value <= top:
                raise HTTPException(422, f"'{name}' is an integer from 0 to {top}")
        for name, value in (("reload_on_fault", reload), ("team_hardware", team_hardware)):
            if not isinstance(value, bool):
                raise HTTPException(422, f"'{name}' is true or false")
        # Each team's latest version and robot, read once for all its games.
        teams = s.execute(select(Team).order_by(Team.id)).scalars().all()
        version = {t.id: latest(s, t.id) for t in teams}
        entrants = [t.id for t in teams if version[t.id] is not None]
        if len(entrants) < 2 or rounds < 1 or length < 1:
            raise HTTPException(422, "a round robin needs two teams with programs, a round and a length")
        t = Tournament(rules=rules, seconds=length, rounds=rounds, reload_on_fault=int(reload),
                       seed=seed, team_hardware=int(team_hardware))
        # The teams' robots (their forms' hardware files) if the instructor
        # asks for them, else every robot the course's.
        robot_of = {t.id: t.hardware if team_hardware else None for t in teams}
        s.add(t)
        s.flush()
        # The brackets: every pair `rounds` times, sides swapped each round,
        # shuffled, each game's seed drawn, all from the recorded seed.
        draw = random.Random(seed)
        games = [(a, b) if r % 2 == 0 else (b, a) for r in range(rounds)
                 for i, a in enumerate(entrants) for b in entrants[i + 1:]]
        draw.shuffle(games)
        for a, b in games:
            s.add(Match(kind="tournament", tournament_id=t.id, a_submission_id=version[a].id,
                        b_submission_id=version[b].id, seed=draw.getrandbits(63),
                        seconds=length, rules=rules, reload_on_fault=int(reload),
                        a_hardware=robot_of[a], b_hardware=robot_of[b], status="queued"))
        s.commit()
        queue.notify()
        return {"id": t.id, "seed": seed, "games": len(games)}

    @app.get("/api/tournaments/{tournament_id}")
    def get_tournament(tournament_id: int = Path(..., ge=0, le=MAX_ID), s=Depends(session)):
        t = s.get(Tournament, tournament_id)
        if t is None:
            raise HTTPException(404, "no such tournament")
        counts = dict(s.execute(select(Match.status, func.count(Match.id)).where(
            Match.tournament_id == t.id).group_by(Match.status)).all())
        total = sum(counts.values())
        finished = counts.get("done", 0) + counts.get("failed", 0)
        return {"id": t.id, "seed": t.seed, "rules": t.rules, "rounds": t.rounds,
                "seconds": t.seconds, "reload_on_fault": bool(t.reload_on_fault),
                "team_hardware": bool(t.team_hardware),
                "status": "done" if finished == total else "running",
                "games": {"total": total, "done": counts.get("done", 0),
                          "failed": counts.get("failed", 0)},
                "table": standings(s, t.id)}

    @app.get("/api/standings")
    def get_standings(s=Depends(session)):
        return standings(s)

    @app.get("/api/matches/{match_id}")
    def get_match(match_id: int = Path(..., ge=0, le=MAX_ID), s=Depends(session)):
        m = s.get(Match, match_id)
        if m is None:
            raise HTTPException(404, "no such match")
        return {"id": m.id, "kind": m.kind, "status": m.status, "seed": m.seed,
                "seconds": m.seconds, "result": json.loads(m.result) if m.result else None,
                "error": m.error}

    @app.get("/api/teams/{team_id}")
    def get_team(team_id: int = Path(..., ge=0, le=MAX_ID), s=Depends(session)):
        t = s.get(Team, team_id)
        if t is None:
            raise HTTPException(404, "no such team")
        return {"id": t.id, "name": t.name,
                "versions": [{"version": v.version, "file_name": v.file_name,
                              "created": v.created.isoformat(),
                              "warnings": v.warnings.splitlines()} for v in t.submissions]}

    return app
