"""The match queue: matches wait in the database (status "queued") and run
off the request path, each in a `simbot match` process, at most `workers`
at once. A match taken is marked "running"; at start, a queue left by a
killed server has its running matches queued again, so none is lost. A
match whose process fails is "failed" with its error, never dropped.

The programs are written to a fresh temporary folder as A.dc and B.dc (a
house robot is read from the house folder by a name that must be one of
its files' stems): no text a team sends becomes a path."""
import json
import os
import re
import subprocess
import tempfile
import threading
from concurrent.futures import ThreadPoolExecutor

from sqlalchemy import select, update

from .models import Match, Submission

MATCH_SECONDS_LIMIT = 600  # wall time of one match's process
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


def match_inputs(s, m):
    """What a match is, read from the database: its programs' sources, the
    house robot's name, the robots' hardware files and the options."""
    return {
        "a": s.get(Submission, m.a_submission_id).source,
        "b": s.get(Submission, m.b_submission_id).source if m.b_submission_id else None,
        "house": m.b_house, "a_hardware": m.a_hardware, "b_hardware": m.b_hardware,
        "options": ["--seed", str(m.seed), "--seconds", str(m.seconds)]
        + (["--rules", m.rules] if m.rules else [])
        + (["--reload-on-fault"] if m.reload_on_fault else []),
    }


def write_inputs(inputs, house_folder, folder):
    """Writes a match's programs (A.dc, B.dc) and hardware files (A.toml,
    B.toml) into `folder` and returns simbot match's arguments for them."""
    def written(name, text):
        path = os.path.join(folder, name)
        with open(path, "wb") as f:
            f.write(text.encode("latin-1") if name.endswith(".dc") else text.encode("utf-8"))
        return path

    args = [written("A.dc", inputs["a"])]
    if inputs["b"] is not None:
        args.append(written("B.dc", inputs["b"]))
    if inputs["house"] is not None:
        robots = house_robots(house_folder)
        if inputs["house"] not in robots:
            raise RuntimeError(f"no house robot '{inputs['house']}'")
        args.append(robots[inputs["house"]])
    for robot in ("a", "b"):
        if inputs[robot + "_hardware"]:
            args += ["--hw", f"{robot.upper()}=" + written(robot.upper() + ".toml",
                                                            inputs[robot + "_hardware"])]
    return args + inputs["options"]


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
                house = m.b_house
                inputs = match_inputs(s, m)
            with tempfile.TemporaryDirectory(prefix="simbot-match-") as folder:
                p = subprocess.run([self.simbot, "match", *write_inputs(inputs, self.house, folder),
                                    "--json"], capture_output=True,
                                   timeout=MATCH_SECONDS_LIMIT, cwd=folder)
            # 3: a robot faulted, which is a result (its fault is in the JSON).
            if p.returncode not in (0, 3):
                raise RuntimeError(f"simbot match exited {p.returncode}: "
                                   f"{p.stderr.decode('utf-8', 'replace').strip()[-500:]}")
            result = json.loads(p.stdout)
            # The programs by what they are, not by the temporary folder's
            # paths: the same match gives the same result, byte for byte.
            names = ["submission", "house:" + house if house is not None else "submission"]
            for robot, name in zip(result.get("robots", []), names):
                robot["program"] = name
            result.pop("wall_seconds", None)  # the host's time, not the match's
            self._finish(match_id, "done", result=json.dumps(result, sort_keys=True))
        except Exception as e:  # a match that fails is recorded, never lost
            self._finish(match_id, "failed", error=f"{type(e).__name__}: {e}"[:2000])
