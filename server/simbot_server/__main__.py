"""python3 -m simbot_server: what `simbot serve` runs.

    --db URL        the database (default: SQLite file DATA/simbot.sqlite3)
    --host, --port  where to listen (default 127.0.0.1:8000)
    --data DIR      the server's folder (default ./simbot-data)
    --simbot PATH   the simbot executable (simbot serve passes its own)
    --checks FILE   the course's expectations file, run on every submission
    --house DIR     house robots: DIR/NAME.dc is "house:NAME"
    --workers N     matches run at once, each a process here (default 2)
    --dask ADDRESS  the matches on a Dask cluster instead (tcp://HOST:PORT
                    or local:N): as many at once as it has worker threads
    --seconds S     a match's length (default 180)
"""
import argparse
import sys

import uvicorn

from . import db
from .app import TOKEN_FILE, create_app
from .queue import ClusterError

KEEP_ALIVE_SECONDS = 75  # an idle connection's life (uvicorn's default: 5)


def main(argv=None):
    p = argparse.ArgumentParser(prog="simbot serve", description=__doc__.splitlines()[0])
    p.add_argument("--db")
    p.add_argument("--host", default="127.0.0.1")
    p.add_argument("--port", type=int, default=8000)
    p.add_argument("--data", default="simbot-data")
    p.add_argument("--simbot", required=True)
    p.add_argument("--checks")
    p.add_argument("--house")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, default=2)
    where.add_argument("--dask")
    p.add_argument("--seconds", type=int, default=180)
    a = p.parse_args(argv)
    try:
        app = create_app(a.db or db.default_url(a.data), a.data, a.simbot, a.checks, a.house,
                         a.workers, a.seconds, a.dask)
    except ClusterError as e:  # one line, as simbot sweep --dask says it
        print(f"simbot: --dask: {e}", file=sys.stderr)
        return 1
    if app.state.new_instructor_token:
        print(f"simbot serve: the instructor's token (also in {a.data}/{TOKEN_FILE}): "
              f"{app.state.new_instructor_token}", flush=True)
    print(f"simbot serve: listening on http://{a.host}:{a.port}/ (data: {a.data})", flush=True)
    # uvicorn 0.17 (Debian's) arms its keep-alive timer after a response
    # even when the connection's next request is already being handled, and
    # the timer then closes it mid-request, unanswered (encode/uvicorn#1637,
    # fixed upstream by #2243): its 5-s default dropped round-robin pages
    # under load.
    # The timer is therefore longer than any request takes.
    uvicorn.run(app, host=a.host, port=a.port, log_level="warning",
                timeout_keep_alive=KEEP_ALIVE_SECONDS)


if __name__ == "__main__":
    sys.exit(main())
