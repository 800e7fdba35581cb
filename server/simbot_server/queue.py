"""The match queue: matches wait in the database (status "queued") and run
off the request path, at most as many at once as there are workers: with
--workers N, N threads of the server, each running a `simbot match`
process; with --dask ADDRESS, the Dask cluster's worker threads (counted
again whenever that many are running, so workers may join later), each match
a task that runs `simbot match` on a worker. A match taken is marked
"running"; at start, a queue left by a killed server has its running
matches queued again, so none is lost. A match whose process or task
fails is "failed" with its error, never dropped: on Dask, a task whose
worker dies is run again by Dask on another worker (up to the scheduler's
allowed-failures, 3 by default) and then fails with KilledWorker.

Both ways run match_run.run_match on the match's spec (match_spec: the
programs' sources, a house robot read from the house folder by a name
that must be one of its files' stems, the hardware, the options)."""
import os
import re
import threading
import time
import uuid
from concurrent.futures import ThreadPoolExecutor

from sqlalchemy import select, update

from . import match_run
from .models import Match, Submission

_HOUSE_NAME = re.compile(r"^[A-Za-z0-9_-]{1,64}$")
# On Dask: at most this many matches at once, whatever the cluster's size;
# a match not back from the cluster in DASK_WAIT_S (a run and the three
# reruns Dask allows by default, at their longest) is failed.
MAX_DASK_AT_ONCE = 64
DASK_WAIT_S = 4 * match_run.MATCH_SECONDS_LIMIT


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



def match_spec(s, m, house_folder):
    """Match `m` as match_run's spec, from what the database keeps of it:
    the frozen programs (a house robot read from `house_folder`), the
    hardware files copied at queueing, its seed, length and options."""
    sources = [s.get(Submission, m.a_submission_id).source.encode("latin-1")]
    if m.b_submission_id:
        sources.append(s.get(Submission, m.b_submission_id).source.encode("latin-1"))
    else:
        robots = house_robots(house_folder)
        if m.b_house not in robots:
            raise RuntimeError(f"no house robot '{m.b_house}'")
        with open(robots[m.b_house], "rb") as f:
            sources.append(f.read())
    # The programs by what they are, not by the temporary folder's paths:
    # the same match gives the same result, byte for byte.
    names = ["submission", "house:" + m.b_house if m.b_house is not None else "submission"]
    options = ["--seed", str(m.seed), "--seconds", str(m.seconds)] + \
        (["--rules", m.rules] if m.rules else []) + (["--reload-on-fault"] if m.reload_on_fault else [])
    return {"sources": sources, "names": names, "hardware": [m.a_hardware, m.b_hardware],
            "options": options}

class ClusterError(Exception):
    """The Dask cluster cannot be used, in one line."""


class _Dask:
    """The matches' tasks on a Dask cluster (`address` as for simbot sweep
    --dask: tcp://HOST:PORT or local:N), connected by simbot sweep's own
    code; ClusterError if it cannot be."""

    def __init__(self, address):
        try:
            import cloudpickle
            from simbot.sweep import DaskError, connect
        except ImportError as e:
            raise ClusterError(f"{e} (it needs Dask and simbot's Python module)") from None
        # The task's code travels with it: a worker needs no server package.
        cloudpickle.register_pickle_by_value(match_run)
        try:
            self.client, self.cluster = connect(address)
        except DaskError as e:
            raise ClusterError(str(e)) from None
        except Exception as e:  # a LocalCluster that cannot start
            raise ClusterError(f"{type(e).__name__}: {' '.join(str(e).split())}") from None

    def capacity(self, last):
        """The cluster's worker threads (at least 1, at most
        MAX_DASK_AT_ONCE); `last` if the scheduler does not answer."""
        try:
            threads = sum(self.client.nthreads().values())
        except Exception:  # the scheduler gone: the matches' waits say so
            return last
        return min(MAX_DASK_AT_ONCE, max(1, threads))

    def run(self, match_id, stopped, *args):
        """run_match(*args) on a worker; None if `stopped` first (the task
        is cancelled)."""
        future = self.client.submit(match_run.run_match, *args, pure=False,
                                    key=f"simbot-match-{match_id}-{uuid.uuid4().hex}")
        deadline = time.monotonic() + DASK_WAIT_S
        try:
            while not future.done():
                if stopped.is_set():
                    return None
                if time.monotonic() > deadline:
                    raise TimeoutError(f"no result from the Dask cluster in {DASK_WAIT_S} s")
                time.sleep(0.05)
            return future.result()
        finally:
            if not future.done():
                try:
                    future.cancel()
                except Exception:  # the scheduler gone: it has dropped the task
                    pass

    def close(self):
        self.client.close()
        if self.cluster is not None:
            self.cluster.close()


class MatchQueue:
    def __init__(self, session_factory, simbot, house, workers, dask=None):
        """`workers` matches at once in this process, or on the Dask cluster
        at the address `dask` (connected now)."""
        self.sessions, self.simbot, self.house = session_factory, simbot, house
        self.dask = _Dask(dask) if dask else None
        self.at_once = self.dask.capacity(1) if self.dask else max(1, workers)
        self.pool = ThreadPoolExecutor(MAX_DASK_AT_ONCE if self.dask else self.at_once)
        self.in_flight = 0
        self.lock = threading.Lock()
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
        if self.dask:
            self.dask.close()

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
            with self.lock:
                full = self.in_flight >= self.at_once
            if full and self.dask:  # the cluster may have grown (or shrunk)
                self.at_once = self.dask.capacity(self.at_once)
                with self.lock:
                    full = self.in_flight >= self.at_once
            match_id = None if full else self._claim()
            if match_id is None:
                self.wake.wait(0.2)
                self.wake.clear()
                continue
            with self.lock:
                self.in_flight += 1
            self.pool.submit(self._run_and_release, match_id)

    def _run_and_release(self, match_id):
        try:
            self._run(match_id)
        finally:
            with self.lock:
                self.in_flight -= 1
            self.wake.set()

    def _finish(self, match_id, status, result=None, error=None):
        with self.sessions() as s:
            s.execute(update(Match).where(Match.id == match_id)
                      .values(status=status, result=result, error=error))
            s.commit()

    def _run(self, match_id):
        try:
            with self.sessions() as s:
                spec = match_spec(s, s.get(Match, match_id), self.house)
            if self.dask is None:
                result = match_run.run_match(self.simbot, spec)
            else:
                result = self.dask.run(match_id, self.stopped, self.simbot, spec)
                if result is None:  # the server stopping: the next start runs it
                    self._finish(match_id, "queued")
                    return
            self._finish(match_id, "done", result=result)
        except Exception as e:  # a match that fails is recorded, never lost
            self._finish(match_id, "failed", error=f"{type(e).__name__}: {e}"[:2000])
