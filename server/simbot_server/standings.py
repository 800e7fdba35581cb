"""Standings: each team's games, wins, losses, hits and scatter shots over
the matches done (scrimmages and tournament games alike), and a
Bradley-Terry rating with its 95% interval.

The rating: P(i beats j) = 1 / (1 + exp(-(b_i - b_j))), fitted by maximum
likelihood with statsmodels' Logit: one row per decided game, +1 in the
winner's column and -1 in the loser's, y = 1. So that a team that
has won or lost every game still gets a finite rating, each participant
also plays two virtual games against a virtual opponent of rating 0, one
won and one lost (assumption: the usual pseudo-count; it pulls ratings a
little toward 0 and fixes the scale's origin at the virtual opponent).
House robots are participants of the fit but not listed. A game whose
result has no winner is counted as played, in neither wins nor losses,
and left out of the fit."""
import json

import numpy as np
import statsmodels.api as sm
from sqlalchemy import select

from .models import Match, Submission, Team


def _participants_and_games(s, tournament_id):
    teams = {t.id: t.name for t in s.execute(select(Team)).scalars()}
    team_of = {sub.id: sub.team_id for sub in s.execute(select(Submission)).scalars()}
    games = []
    # Columns, not Match objects: a match the session loaded earlier (a
    # page lists the games first) would come back as it was then, say
    # running without its result, though its row is done now.
    done = select(Match.a_submission_id, Match.b_submission_id, Match.b_house, Match.result).where(
        Match.status == "done").order_by(Match.id)
    if tournament_id is not None:
        done = done.where(Match.tournament_id == tournament_id)
    for a_submission, b_submission, b_house, result in s.execute(done):
        a = ("team", team_of[a_submission])
        b = ("team", team_of[b_submission]) if b_submission else ("house", b_house)
        games.append((a, b, json.loads(result)))
    return teams, games


def standings(s, tournament_id=None):
    """The table over every match done, or one tournament's games."""
    teams, games = _participants_and_games(s, tournament_id)
    row = {tid: {"team": name, "team_id": tid, "played": 0, "wins": 0, "losses": 0, "hits": 0,
                 "scatter_shots": 0} for tid, name in teams.items()}
    players = sorted({p for a, b, _ in games for p in (a, b)} | {("team", t) for t in teams})
    column = {p: k for k, p in enumerate(players)}
    xs, ys = [], []
    for a, b, r in games:
        robots = r.get("robots", [])
        for side, robot in zip((a, b), robots):
            if side[0] == "team":
                entry = row[side[1]]
                entry["played"] += 1
                entry["hits"] += robot.get("hits", 0)
                entry["scatter_shots"] += robot.get("scatter_shots") or 0
        winner = r.get("winner")
        if winner not in ("A", "B") or a == b:
            continue
        won, lost = (a, b) if winner == "A" else (b, a)
        for side, key in ((won, "wins"), (lost, "losses")):
            if side[0] == "team":
                row[side[1]][key] += 1
        x = np.zeros(len(players))
        x[column[won]], x[column[lost]] = 1, -1
        xs.append(x)
        ys.append(1)
    for p in players:  # the virtual games
        x = np.zeros(len(players))
        x[column[p]] = 1
        xs += [x, x.copy()]
        ys += [1, 0]
    if not players:
        return []
    fit = sm.Logit(np.array(ys, dtype=float), np.array(xs)).fit(disp=0, maxiter=200)
    interval = fit.conf_int(0.05)
    for tid, entry in row.items():
        k = column[("team", tid)]
        entry["rating"] = float(fit.params[k])
        entry["ci_low"], entry["ci_high"] = float(interval[k][0]), float(interval[k][1])
    return sorted(row.values(), key=lambda e: (-e["rating"], -e["wins"], e["team"]))
