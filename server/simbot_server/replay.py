"""A done match's replay page and explain report, made when first asked
for: the match is played again from what the database keeps of it (its
programs, hardware, seed and options: a match is those, so the replay is
the match that was scored) with `--trace` and `--replay`, and the trace
explained. They are kept under DATA/replays/ by the match's number (no
user text in the path); at most MAX_KEPT matches' files, the least
recently made removed first, bound the folder's growth (about 7 MB a
180-s match)."""
import os
import subprocess
import tempfile
import threading

from .models import Match
from .match_run import MATCH_SECONDS_LIMIT, failed, write_match
from .queue import match_spec

MAX_KEPT = 50  # matches whose replay page and report are kept
AT_ONCE = 2  # replays made at the same time


class Replays:
    def __init__(self, session_factory, simbot, house, data_dir):
        self.sessions, self.simbot, self.house = session_factory, simbot, house
        self.folder = os.path.join(data_dir, "replays")
        os.makedirs(self.folder, exist_ok=True)
        self.lock = threading.Lock()
        self.making = {}  # match id -> its lock while it is being made
        self.slots = threading.Semaphore(AT_ONCE)

    def page(self, match_id):
        return os.path.join(self.folder, f"{int(match_id)}.html")

    def report(self, match_id):
        return os.path.join(self.folder, f"{int(match_id)}.explain.txt")

    def ensure(self, match_id):
        """Makes match `match_id`'s page and report unless they exist; True
        when they do. A match not done has none (False)."""
        if os.path.exists(self.report(match_id)):
            return True
        with self.lock:
            one = self.making.setdefault(match_id, threading.Lock())
        try:
            with one, self.slots:
                if os.path.exists(self.report(match_id)):
                    return True
                with self.sessions() as s:
                    m = s.get(Match, match_id)
                    if m is None or m.status != "done":
                        return False
                    spec = match_spec(s, m, self.house)
                self._make(match_id, spec)
        finally:
            with self.lock:
                self.making.pop(match_id, None)
        self._trim()
        return True

    def _make(self, match_id, spec):
        with tempfile.TemporaryDirectory(prefix="simbot-replay-") as folder:
            trace, page = os.path.join(folder, "trace.jsonl"), os.path.join(folder, "replay.html")
            args = write_match(spec, folder)
            p = subprocess.run([self.simbot, "match", *args, "--trace", trace, "--replay", page],
                               capture_output=True, timeout=MATCH_SECONDS_LIMIT, cwd=folder)
            if p.returncode not in (0, 3):
                raise failed("match", p)
            e = subprocess.run([self.simbot, "explain", trace], capture_output=True,
                               timeout=MATCH_SECONDS_LIMIT, cwd=folder)
            if e.returncode != 0:
                raise failed("explain", e)
            # The programs by their names in the match (A.dc, B.dc), not by
            # the temporary folder's paths.
            with open(page, "rb") as f:
                texts = {page: f.read(), trace + ".report": e.stdout}
            for path, text in texts.items():
                with open(path, "wb") as f:
                    f.write(text.replace(folder.encode() + b"/", b""))
            # The page first, the report last: the report's presence says both are whole.
            os.replace(page, self.page(match_id))
            os.replace(trace + ".report", self.report(match_id))

    def _trim(self):
        reports = sorted((os.path.getmtime(os.path.join(self.folder, n)), n)
                         for n in os.listdir(self.folder) if n.endswith(".explain.txt"))
        for _, name in reports[:max(0, len(reports) - MAX_KEPT)]:
            stem = name[:-len(".explain.txt")]
            for path in (self.report(stem), self.page(stem)):
                try:
                    os.remove(path)
                except FileNotFoundError:
                    pass
