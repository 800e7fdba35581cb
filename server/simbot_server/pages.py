"""The web pages (Jinja2 templates in templates/, autoescaped: every name,
file name, program text and message a team sent is shown as text).

    /                   the standings, the tournaments, the latest matches
    /teams/ID           a team: its versions with their warnings and the
                        course's checks, its matches
    /matches/ID         a match: its result, its replay page (made when first
                        asked for, replay.py) and its explain report
    /matches/ID/replay  the replay page itself
    /submit             the submission form (team token and program); a
                        program that does not compile is shown with each
                        error at its line
    /tournaments/ID     a round robin: its status, its table, its games
    /teams/ID/robot     the team's robot: every value a hardware file may
                        set, with its unit, range and source; the team's
                        token saves its answers as its hardware file
                        (robot.py), checked by simbot's own loader

The forms carry the team's token in their body, not in a cookie: no
other site can post one on a visitor's behalf."""
import json
import os
import re

from fastapi import File, Form, HTTPException, Path, Request, UploadFile
from fastapi.concurrency import run_in_threadpool
from fastapi.responses import FileResponse, HTMLResponse, Response
from fastapi.templating import Jinja2Templates
from sqlalchemy import or_, select

from . import robot, submissions
from .models import MAX_ID, MAX_PROGRAM_BYTES, Match, Submission, Team, Tournament
from .standings import standings

LATEST_MATCHES = 30  # listed on the front page and a team's page
_DIAGNOSTIC_LINE = re.compile(r"^[^:]*:(\d+):(\d+): (error|warning): (.*)$")

templates = Jinja2Templates(directory=os.path.join(os.path.dirname(__file__), "templates"))


def _found(s, model, row_id, what):
    """Row `row_id` of `model`, or 404 "no such WHAT"."""
    row = s.get(model, row_id)
    if row is None:
        raise HTTPException(404, f"no such {what}")
    return row


def _side(s, m, robot):
    """(label, team id or None) of a match's robot A or B."""
    if robot == "B" and m.b_house is not None:
        return "house:" + m.b_house, None
    sub = s.get(Submission, m.a_submission_id if robot == "A" else m.b_submission_id)
    return f"{sub.team.name} v{sub.version}", sub.team_id


def _match_row(s, m):
    result = json.loads(m.result) if m.result else None
    a, a_team = _side(s, m, "A")
    b, b_team = _side(s, m, "B")
    robots = (result or {}).get("robots", [])
    return {"id": m.id, "kind": m.kind, "status": m.status, "seed": m.seed, "a": a,
            "a_team": a_team, "b": b, "b_team": b_team, "tournament_id": m.tournament_id,
            "winner": (result or {}).get("winner"),
            "score": " / ".join(f"{r.get('hits', 0)} hits" for r in robots),
            "faulted": any(r.get("fault") for r in robots)}


def _marked_source(source, diagnostics):
    """The program's lines, each with the diagnostics at it (line, column, kind, text)."""
    at = {}
    for d in diagnostics:
        m = _DIAGNOSTIC_LINE.match(d)
        if m:
            at.setdefault(int(m.group(1)), []).append(
                {"col": int(m.group(2)), "kind": m.group(3), "text": d})
    return [{"number": n, "text": text, "notes": at.get(n, [])}
            for n, text in enumerate(source.splitlines(), start=1)]


def add_pages(app, sessions, simbot, checks, replays, team_by_token, limited):
    def page(request, name, status_code=200, headers=None, **context):
        return templates.TemplateResponse(name, {"request": request, **context},
                                          status_code=status_code, headers=headers)

    @app.get("/", response_class=HTMLResponse)
    def front(request: Request):
        with sessions() as s:
            matches = s.execute(select(Match).order_by(Match.id.desc())
                                .limit(LATEST_MATCHES)).scalars()
            return page(request, "standings.html", table=standings(s),
                        matches=[_match_row(s, m) for m in matches],
                        tournaments=s.execute(select(Tournament).order_by(Tournament.id.desc()))
                        .scalars().all())

    @app.get("/teams/{team_id}", response_class=HTMLResponse)
    def team_page(request: Request, team_id: int = Path(..., ge=0, le=MAX_ID)):
        with sessions() as s:
            t = _found(s, Team, team_id, "team")
            mine = [sub.id for sub in t.submissions]
            matches = s.execute(select(Match).where(or_(
                Match.a_submission_id.in_(mine), Match.b_submission_id.in_(mine)))
                .order_by(Match.id.desc()).limit(LATEST_MATCHES)).scalars() if mine else []
            versions = [{"version": v.version, "file_name": v.file_name, "created": v.created,
                         "warnings": v.warnings.splitlines(),
                         "checks": json.loads(v.checks) if v.checks else None}
                        for v in reversed(t.submissions)]
            return page(request, "team.html", team=t, versions=versions,
                        matches=[_match_row(s, m) for m in matches])

    @app.get("/matches/{match_id}", response_class=HTMLResponse)
    def match_page(request: Request, match_id: int = Path(..., ge=0, le=MAX_ID)):
        with sessions() as s:
            m = _found(s, Match, match_id, "match")
            row, result, error = _match_row(s, m), json.loads(m.result) if m.result else None, m.error
            options = {"seconds": m.seconds, "rules": m.rules,
                       "reload_on_fault": bool(m.reload_on_fault),
                       "hardware": [r for r, hw in (("A", m.a_hardware), ("B", m.b_hardware)) if hw]}
        report, problem = None, None
        try:
            if row["status"] == "done" and replays.ensure(match_id):
                with open(replays.report(match_id), encoding="utf-8", errors="replace") as f:
                    report = f.read()
        except Exception as e:  # the match stands; only its replay is missing
            problem = f"{type(e).__name__}: {e}"[:2000]
        return page(request, "match.html", m=row, result=result, error=error, options=options,
                    report=report, replay_problem=problem)

    @app.get("/favicon.ico")
    def no_icon():  # the replay pages do not name one; browsers ask
        return Response(status_code=204)

    @app.get("/matches/{match_id}/replay")
    def replay_page(match_id: int = Path(..., ge=0, le=MAX_ID)):
        if not replays.ensure(match_id):
            raise HTTPException(404, "no replay: the match is not done")
        return FileResponse(replays.page(match_id), media_type="text/html")

    def robot_page(request, t, status_code=200, **context):
        found = robot.listing(simbot, t.hardware)
        sections = {}
        for key in found.keys:
            sections.setdefault(key["section"], []).append(key)
        return page(request, "robot.html", status_code=status_code, team=t, sections=sections,
                    listing_error=found.error, field=robot.field, shown=robot.shown, **context)

    @app.get("/teams/{team_id}/robot", response_class=HTMLResponse)
    def robot_form(request: Request, team_id: int = Path(..., ge=0, le=MAX_ID)):
        with sessions() as s:
            t = _found(s, Team, team_id, "team")
        return robot_page(request, t, sent={})

    @app.post("/teams/{team_id}/robot", response_class=HTMLResponse)
    async def robot_posted(request: Request, team_id: int = Path(..., ge=0, le=MAX_ID)):
        form = await request.form()
        sent = {k: v for k, v in form.items() if isinstance(v, str)}
        return await run_in_threadpool(save_robot, request, team_id, sent)

    def save_robot(request, team_id, sent):
        with sessions() as s:
            t = _found(s, Team, team_id, "team")
            who = team_by_token(s, sent.get("token", ""))
            if who is None or who.id != t.id:
                return robot_page(request, t, 403, sent=sent, problem="That is not this team's token.")
            try:
                limited(who, "robot edit")
            except HTTPException as e:
                return robot_page(request, t, e.status_code, sent=sent, problem=e.detail + ".")
            if sent.get("action") == "reset":
                text, problems = None, {}
            else:
                text, problems = robot.hardware_file(robot.listing(simbot, None).keys, sent)
            if problems:
                return robot_page(request, t, 422, sent=sent, problems=problems,
                                  problem="Some values are not what their keys take; nothing was kept.")
            text = text or None
            if text is not None:
                checked = robot.listing(simbot, text)
                if checked.error:
                    return robot_page(request, t, 422, sent=sent, made=text,
                                      problem="simbot's loader refuses the robot; nothing was kept: "
                                              + checked.error)
            t.hardware = text
            s.commit()
            return robot_page(request, t, sent={}, saved=True)

    @app.get("/tournaments/{tournament_id}", response_class=HTMLResponse)
    def tournament_page(request: Request, tournament_id: int = Path(..., ge=0, le=MAX_ID)):
        with sessions() as s:
            t = _found(s, Tournament, tournament_id, "tournament")
            games = s.execute(select(Match).where(Match.tournament_id == t.id)
                              .order_by(Match.id)).scalars().all()
            rows = [_match_row(s, m) for m in games]
            finished = sum(r["status"] in ("done", "failed") for r in rows)
            return page(request, "tournament.html", t=t, table=standings(s, t.id), games=rows,
                        finished=finished)

    @app.get("/submit", response_class=HTMLResponse)
    def submit_form(request: Request):
        return page(request, "submit.html", outcome=None)

    @app.post("/submit", response_class=HTMLResponse)
    def submit_posted(request: Request, token: str = Form(""),
                      program: UploadFile = File(...)):
        with sessions() as s:
            who = team_by_token(s, token)
            if who is None:
                return page(request, "submit.html", status_code=403, outcome=None,
                            problem="That is not a team's token.")
            try:
                limited(who, "submission")
            except HTTPException as e:
                return page(request, "submit.html", status_code=e.status_code, headers=e.headers,
                            outcome=None, problem=e.detail + ".")
            source = program.file.read(MAX_PROGRAM_BYTES + 1)
            if submissions.too_big(source):
                return page(request, "submit.html", status_code=413, outcome=None,
                            problem=f"A program has at most {MAX_PROGRAM_BYTES} bytes.")
            try:
                out = submissions.submit(s, simbot, checks, who.id, program.filename, source)
            except submissions.Busy as e:
                return page(request, "submit.html", status_code=503, outcome=None,
                            problem=str(e) + "; try again.")
            except submissions.Full as e:
                return page(request, "submit.html", status_code=409, outcome=None,
                            problem=str(e) + ".")
            text = source.decode("latin-1")
            return page(request, "submit.html", status_code=422 if out.errors else 200,
                        outcome=out, team=who,
                        listing=_marked_source(text, out.errors + out.warnings))
