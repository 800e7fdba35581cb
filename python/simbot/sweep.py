"""simbot sweep on a Dask cluster: python3 -m simbot.sweep SWEEP.toml --dask ADDRESS.

`simbot sweep --dask ...` runs this. The sweep file is expanded by the C++
code (batch/sweep.h) and each run's row is computed by it on a worker, so a
row is the same as the local run's; the rows come back in any order and the
C++ SweepWriter writes them in run-index order as soon as a prefix is
complete. The checks before the first run, the fingerprint beside the
table (OUT.batch.json) and --resume's checks of it and of each kept row are
the local sweep's own (batch::SweepOutput), so a Dask sweep, killed or
finished, resumes as a local one does, on Dask or locally. Workers read the
programs and profiles at the paths the sweep names: a cluster on several
machines needs them on a shared file system, and the simbot package
installed on every worker.
"""
import argparse
import functools
import logging
import os
import socket
import sys
import time
import urllib.parse

from . import _simbot

# How long connecting to a Dask scheduler may take before --dask gives up
# (docs/tools.md states it): a refused connection is reported at once.
CONNECT_TIMEOUT_S = 10


class DaskError(Exception):
    """A failure of the cluster, reported in one line."""


@functools.lru_cache(maxsize=4)
def _sweep(path):
    return _simbot.Sweep(path)


@functools.lru_cache(maxsize=1)
def _quiet_worker():
    # The driver prints each program's compiler warnings once; a worker's
    # compilations would print them again, once per worker process.
    _simbot.silence_compile_warnings()


def _row(path, index):
    _quiet_worker()
    return index, _sweep(path).row(index)


def _probe(address):
    """A tcp:// scheduler that refuses or cannot be resolved fails now, not
    after Dask's retries."""
    parsed = urllib.parse.urlsplit(address if "://" in address else "tcp://" + address)
    if parsed.scheme != "tcp":
        return
    try:
        host, port = parsed.hostname, parsed.port
    except ValueError as e:
        raise DaskError(f"'{address}' is not an address ({e})") from None
    if not host or port is None:
        raise DaskError(f"'{address}' is not an address (tcp://HOST:PORT or local:N)")
    try:
        socket.create_connection((host, port), timeout=CONNECT_TIMEOUT_S).close()
    except OSError as e:
        reason = e.strerror or str(e) or type(e).__name__
        raise DaskError(f"cannot connect to {address}: {reason}") from None


def connect(address):
    """(client, cluster): a Client of the scheduler at tcp://HOST:PORT
    (cluster None), or of a new LocalCluster of N one-thread worker
    processes for local:N (closed after the client). simbot serve --dask
    connects by it too. Fails with DaskError."""
    from dask.distributed import Client, LocalCluster
    if address.startswith("local:"):
        try:
            workers = int(address[len("local:"):])
        except ValueError:
            workers = 0
        if workers < 1:
            raise DaskError("local:N needs a whole number N >= 1")
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        return Client(cluster, timeout=CONNECT_TIMEOUT_S), cluster
    _probe(address)
    try:
        return Client(address, timeout=CONNECT_TIMEOUT_S), None
    except (OSError, TimeoutError) as e:
        raise DaskError(f"cannot connect to {address} within {CONNECT_TIMEOUT_S} s: "
                        f"{_one_line(e)}") from None


class _CloseTimeoutNoise(logging.Filter):
    """Drops asyncio's report of a TimeoutError future nobody awaited: on
    a loaded machine the client's close gives up on a connection and leaves
    such a future, whose report came at exit, after the sweep's last line
    (seen once in CI). The table is complete by then; nothing else is
    dropped."""

    def filter(self, record):
        exc = record.exc_info[1] if record.exc_info else None
        return not (isinstance(exc, TimeoutError)
                    and record.getMessage().startswith("Future exception was never retrieved"))


def _one_line(e):
    text = " ".join(str(e).split())
    return text or type(e).__name__


def run(path, out, dask, shard="1/1", header=True, resume=False, progress=True):
    """Runs the sweep (or its shard) on the Dask cluster at `dask` into `out`.
    With progress, a line on stderr each time another tenth of the runs is
    done."""
    from dask.distributed import as_completed
    sweep = _simbot.Sweep(path)
    # Connected first: a cluster that cannot be reached leaves `out` as it
    # was, and is the one line said.
    client, cluster = connect(dask)
    try:
        # The CLI's own checks, fingerprint and table (batch::SweepOutput),
        # with the sweep file named as given, as a local sweep names it:
        # either resumes the other's table. Each program's compiler warnings
        # are printed once, here, and nothing is written before every check
        # has passed.
        output = sweep.output(out, shard, header, resume)
        begin, end = output.begin(), output.end()
        writer = output.open()
        todo = list(range(writer.next(), end))
        # The workers' path does not depend on their working directory.
        path = os.path.abspath(path)
        start, done, shown = time.monotonic(), 0, 0
        # By reference to simbot.sweep._row (run as __main__, _row would be
        # pickled by value with this module's globals).
        from simbot.sweep import _row as row_of
        futures = client.map(row_of, [path] * len(todo), todo, pure=False)
        for future in as_completed(futures):
            index, row = future.result()
            writer.put(index, row)
            future.release()
            done += 1
            if progress and (done * 10 // len(todo) > shown or done == len(todo)):
                shown = done * 10 // len(todo)
                print(f"sweep: {done}/{len(todo)} done in {time.monotonic() - start:.1f} s "
                      f"on Dask", file=sys.stderr, flush=True)
    finally:
        logging.getLogger("asyncio").addFilter(_CloseTimeoutNoise())
        client.close()
        if cluster is not None:
            cluster.close()
    writer.finish()
    return begin, end, len(sweep)


def main(argv=None):
    p = argparse.ArgumentParser(prog="simbot sweep",
                                description="run a sweep on a Dask cluster")
    p.add_argument("sweep")
    p.add_argument("--out", required=True)
    p.add_argument("--dask", required=True, help="tcp://HOST:PORT or local:N")
    p.add_argument("--shard", default="1/1")
    p.add_argument("--no-header", action="store_true")
    p.add_argument("--resume", action="store_true")
    a = p.parse_args(argv)
    # Dask's own log lines (reconnection attempts, a worker's traceback) are
    # not the user's: a failure is the one line below.
    logging.getLogger("distributed").setLevel(logging.CRITICAL)
    try:
        begin, end, total = run(a.sweep, a.out, a.dask, a.shard, not a.no_header, a.resume)
    except _simbot.Error as e:  # simbot's own message, as the CLI prints it
        print(str(e), file=sys.stderr)
        return 1
    except DaskError as e:
        print(f"simbot: --dask: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"simbot: --dask: interrupted; {a.out} holds the runs finished in order; "
              "--resume continues", file=sys.stderr)
        return 130
    except Exception as e:  # the cluster's failures, a worker's exception
        print(f"simbot: --dask: {type(e).__name__}: {_one_line(e)}", file=sys.stderr)
        return 1
    print(f"simbot: {end - begin} runs (runs {begin} to {end} of {total}) on Dask ({a.dask}); "
          f"wrote {a.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
