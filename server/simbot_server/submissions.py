"""A team's submission, by the API or the web form alike: the program is
compiled at once; if it compiles, the course's checks run on it and it is
kept, frozen, as the team's next version with its warnings and checks."""
import json
import subprocess

from sqlalchemy import func, select
from sqlalchemy.exc import IntegrityError

from . import compile as compiler
from .models import MAX_PROGRAM_BYTES, Submission

CHECK_SECONDS = 300  # wall time of the course's checks on one submission
MAX_VERSION_TRIES = 100  # submissions of one team stored at the same moment
# The database's growth: a team keeps at most this many versions (each at
# most MAX_PROGRAM_BYTES: 12.8 MB a team at most).
MAX_VERSIONS_PER_TEAM = 200


class Full(Exception):
    """The team has kept MAX_VERSIONS_PER_TEAM versions (409)."""


class Busy(Exception):
    """A version could not be stored for the submissions at once (503)."""


class Outcome:
    """`errors` (the compiler's, one line each) and nothing kept, or the
    new `submission` with its `warnings` and the checks' `cases`."""

    def __init__(self, errors=(), submission=None, warnings=(), cases=()):
        self.errors, self.submission = list(errors), submission
        self.warnings, self.cases = list(warnings), list(cases)


def too_big(source):
    return len(source) > MAX_PROGRAM_BYTES


def run_checks(simbot, checks, source_path):
    """simbot check's cases for the program at `source_path` ([] without checks)."""
    if not checks:
        return []
    try:
        p = subprocess.run([simbot, "check", source_path, "--expect", checks, "--json"],
                           capture_output=True, timeout=CHECK_SECONDS)
    except subprocess.TimeoutExpired:
        return [{"check": "(the checks did not run)", "status": "failed",
                 "message": f"they took more than {CHECK_SECONDS} s"}]
    if p.returncode not in (0, 1):
        return [{"check": "(the checks did not run)", "status": "failed",
                 "message": p.stderr.decode("utf-8", "replace").strip()[-500:]}]
    return json.loads(p.stdout)["cases"]


def submit(s, simbot, checks, team_id, file_name, source):
    """Compiles `source` (bytes, at most MAX_PROGRAM_BYTES) sent as
    `file_name`, and keeps it as team `team_id`'s next version if it
    compiles. Synchronous: the callers run it on FastAPI's thread pool, so
    the compiler and the checks do not hold up the event loop; nor do they
    hold a database connection (PostgreSQL's pool lends 15): session `s`
    gives its back until the version is stored."""
    kept = s.execute(select(func.count(Submission.id)).where(
        Submission.team_id == team_id)).scalar()
    if kept >= MAX_VERSIONS_PER_TEAM:
        raise Full(f"a team keeps at most {MAX_VERSIONS_PER_TEAM} versions; ask the instructor")
    s.close()
    shown = compiler.display_name(file_name)
    with compiler.written(source) as path:
        result = compiler.compile_file(simbot, path, shown)
        if not result.ok:
            return Outcome(errors=result.errors)
        cases = run_checks(simbot, checks, path)
    # Submissions of one team at once may take the same next version: the
    # unique (team, version) refuses all but one, and the others take the
    # next one again (bounded: each refusal is another's success).
    for _ in range(MAX_VERSION_TRIES):
        last = s.execute(select(func.max(Submission.version)).where(
            Submission.team_id == team_id)).scalar() or 0
        sub = Submission(team_id=team_id, version=last + 1, file_name=shown,
                         source=source.decode("latin-1"), warnings="\n".join(result.warnings),
                         checks=json.dumps(cases) if checks else None)
        s.add(sub)
        try:
            s.commit()
            return Outcome(submission=sub, warnings=result.warnings, cases=cases)
        except IntegrityError:
            s.rollback()
    raise Busy("too many submissions of this team at once")
