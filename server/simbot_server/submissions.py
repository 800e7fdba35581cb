"""A team's submission, by the API or the web form alike: the program is
compiled at once; if it compiles, the course's checks run on it and it is
kept, frozen, as the team's next version with its warnings and checks."""
import json
import subprocess

from sqlalchemy import func, select

from . import compile as compiler
from .models import MAX_PROGRAM_BYTES, Submission

CHECK_SECONDS = 300  # wall time of the course's checks on one submission


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
    compiles. Synchronous: the callers run it on FastAPI's thread pool."""
    shown = compiler.display_name(file_name)
    if b"\0" in source:  # PostgreSQL keeps no NUL in text, and no program needs one
        at = source.index(b"\0")
        line, column = source.count(b"\n", 0, at) + 1, at - source.rfind(b"\n", 0, at)
        return Outcome(errors=[f"{shown}:{line}:{column}: error: a NUL byte: a program is text"])
    with compiler.written(source) as path:
        result = compiler.compile_file(simbot, path, shown)
        if not result.ok:
            return Outcome(errors=result.errors)
        cases = run_checks(simbot, checks, path)
    last = s.execute(select(func.max(Submission.version)).where(
        Submission.team_id == team_id)).scalar() or 0
    sub = Submission(team_id=team_id, version=last + 1, file_name=shown,
                     source=source.decode("latin-1"), warnings="\n".join(result.warnings),
                     checks=json.dumps(cases) if checks else None)
    s.add(sub)
    s.commit()
    return Outcome(submission=sub, warnings=result.warnings, cases=cases)
