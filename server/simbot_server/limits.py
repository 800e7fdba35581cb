"""Per-team rate limits: a token bucket per team and kind of request, in
the server's memory (one server process; a restart forgets them, which
only ever lets a team do more for a minute). A bucket holds `burst`
requests and refills at `per_minute`; an empty one answers 429 with the
seconds until the next request is allowed."""
import threading
import time

# Limits beside what they limit. A submission is compiled and checked at
# once (about a second of CPU with the course's checks); a scrimmage only
# queues a match, which MAX_WAITING_PER_TEAM (app.py) bounds as well.
# kind: (requests a minute, burst)
RATES = {"submission": (6, 6), "scrimmage": (60, 20), "robot edit": (10, 10)}


class RateLimits:
    def __init__(self, clock=time.monotonic):
        self.clock = clock
        self.lock = threading.Lock()
        self.buckets = {}  # (team id, kind) -> [tokens, last refill]

    def take(self, team_id, kind):
        """None if team `team_id` may make a `kind` request now (and counts
        it), else the seconds it must wait."""
        per_minute, burst = RATES[kind]
        now = self.clock()
        with self.lock:
            tokens, last = self.buckets.get((team_id, kind), (burst, now))
            tokens = min(burst, tokens + (now - last) * per_minute / 60)
            if tokens < 1:
                self.buckets[(team_id, kind)] = [tokens, now]
                return (1 - tokens) * 60 / per_minute
            self.buckets[(team_id, kind)] = [tokens - 1, now]
            return None
