"""simbot sweep on a Dask cluster: python3 -m simbot.sweep SWEEP.toml --dask ADDRESS.

`simbot sweep --dask ...` runs this. The sweep file is expanded by the C++
code (batch/sweep.h) and each run's row is computed by it on a worker, so a
row is the same as the local run's; the rows come back in any order and the
C++ SweepWriter writes them in run-index order as soon as a prefix is
complete. Workers read the programs and profiles at the paths the sweep
names: a cluster on several machines needs them on a shared file system,
and the simbot package installed on every worker.
"""
import argparse
import functools
import os
import sys

from . import _simbot


@functools.lru_cache(maxsize=4)
def _sweep(path):
    return _simbot.Sweep(path)


def _row(path, index):
    return index, _sweep(path).row(index)


def _client(address):
    from dask.distributed import Client, LocalCluster
    if address.startswith("local:"):
        workers = int(address[len("local:"):])
        if workers < 1:
            raise ValueError("--dask local:N needs N >= 1")
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        return Client(cluster), cluster
    return Client(address), None


def run(path, out, dask, shard="1/1", header=True, resume=False):
    """Runs the sweep (or its shard) on the Dask cluster at `dask` into `out`."""
    from dask.distributed import as_completed
    path = os.path.abspath(path)
    sweep = _sweep(path)
    k, n = _simbot.parse_shard(shard)
    begin, end = _simbot.shard_range(len(sweep), k, n)
    writer = _simbot.SweepWriter(out, sweep.header(), header, begin, end, resume)
    todo = list(range(writer.next(), end))
    client, cluster = _client(dask)
    try:
        # By reference to simbot.sweep._row (run as __main__, _row would be
        # pickled by value with this module's globals).
        from simbot.sweep import _row as row_of
        futures = client.map(row_of, [path] * len(todo), todo, pure=False)
        for future in as_completed(futures):
            index, row = future.result()
            writer.put(index, row)
            future.release()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    writer.finish()
    return end - begin


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
    try:
        runs = run(a.sweep, a.out, a.dask, a.shard, not a.no_header, a.resume)
    except _simbot.Error as e:
        print(e, file=sys.stderr)
        return 1
    print(f"simbot: {runs} runs on Dask ({a.dask}); wrote {a.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
