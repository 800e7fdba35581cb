"""The match queue: matches wait in the database (status "queued") and run
off the request path, each in a `simbot match` process, at most `workers`
at once. A match taken is marked "running"; at start, a queue left by a
killed server has its running matches queued again, so none is lost. A
match whose process fails is "failed" with its error, never dropped.

Each runs match_run.run_match on the two programs' sources (a house
robot is read from the house folder by a name that must be one of its
files' stems)."""
import os
import re
import threading
from concurrent.futures import ThreadPoolExecutor

from sqlalchemy import select, update

from . import match_run
from .models import Match, Submission

_HOUSE_NAME = re.compile(r"^[A-Za-z0-9_-]{1,64}$")


def house_robots(folder):
    """{name: path} of the house folder's programs (NAME.dc)."""
    if not folder or not os.path.isdir(folder):
        return {}
    out = {}
    folder = os.path.abspath(folder)
    for entry in sorted(os.listdir(folder)):
        stem, ext = os.path.splitext(entry)
        if ext == ".dc" and _HOUSE_NAME.match(stem):
            out[stem] = os.path.join(folder, entry)
    return out


class MatchQueue:
    def __init__(self, session_factory, simbot, house, workers):
        self.sessions, self.simbot, self.house = session_factory, simbot, house
        self.workers = max(1, workers)
        self.pool = ThreadPoolExecutor(self.workers)
        self.free = threading.Semaphore(self.workers)
        self.stopped = threading.Event()
        self.wake = threading.Event()
        self.thread = None

    def start(self):
        with self.sessions() as s:
            s.execute(update(Match).where(Match.status == "running").values(status="queued"))
            s.commit()
        self.thread = threading.Thread(target=self._dispatch, name="match-queue", daemon=True)
        self.thread.start()

    def stop(self):
        self.stopped.set()
        self.wake.set()
        if self.thread:
            self.thread.join()
        self.pool.shutdown(wait=True)

    def notify(self):
        self.wake.set()

    def _claim(self):
        """The oldest queued match, now marked running; None if there is none."""
        with self.sessions() as s:
            while True:
                first = s.execute(select(Match.id).where(Match.status == "queued")
                                  .order_by(Match.id).limit(1)).scalar()
                if first is None:
                    return None
                taken = s.execute(update(Match).where(Match.id == first, Match.status == "queued")
                                  .values(status="running"))
                s.commit()
                if taken.rowcount == 1:
                    return first

    def _dispatch(self):
        while not self.stopped.is_set():
            self.free.acquire()
            match_id = None if self.stopped.is_set() else self._claim()
            if match_id is None:
                self.free.release()
                self.wake.wait(0.2)
                self.wake.clear()
                continue
            self.pool.submit(self._run_and_release, match_id)

    def _run_and_release(self, match_id):
        try:
            self._run(match_id)
        finally:
            self.free.release()

    def _finish(self, match_id, status, result=None, error=None):
        with self.sessions() as s:
            s.execute(update(Match).where(Match.id == match_id)
                      .values(status=status, result=result, error=error))
            s.commit()

    def _run(self, match_id):
        try:
            with self.sessions() as s:
                m = s.get(Match, match_id)
                sources = [s.get(Submission, m.a_submission_id).source.encode("latin-1")]
                if m.b_submission_id:
                    sources.append(s.get(Submission, m.b_submission_id).source.encode("latin-1"))
                house, seed, seconds = m.b_house, m.seed, m.seconds
                options = (["--rules", m.rules] if m.rules else []) + \
                    (["--reload-on-fault"] if m.reload_on_fault else [])
            if house is not None:
                robots = house_robots(self.house)
                if house not in robots:
                    raise RuntimeError(f"no house robot '{house}'")
                with open(robots[house], "rb") as f:
                    sources.append(f.read())
            # The programs by what they are, not by the temporary folder's
            # paths: the same match gives the same result, byte for byte.
            names = ["submission", "house:" + house if house is not None else "submission"]
            result = match_run.run_match(self.simbot, sources, names, seed, seconds, options)
            self._finish(match_id, "done", result=result)
        except Exception as e:  # a match that fails is recorded, never lost
            self._finish(match_id, "failed", error=f"{type(e).__name__}: {e}"[:2000])
