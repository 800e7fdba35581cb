"""One match from its two programs' sources: what a queue worker runs, in
a thread of the server (--workers) or as a task on a Dask worker (--dask).

The sources travel with the call and are written to a fresh temporary
folder as A.dc and B.dc, so no text a team sends becomes a path and a Dask
worker needs no file of the server's. This module imports nothing but the
standard library: on Dask it is pickled by value (queue.py registers it),
so a worker needs Dask and the simbot executable at the server's path,
not the server's package."""
import json
import os
import subprocess
import tempfile

MATCH_SECONDS_LIMIT = 600  # wall time of one match's process


def run_match(simbot, sources, names, seed, seconds, options):
    """`simbot match A.dc B.dc --seed SEED --seconds SECONDS --json OPTIONS`
    on `sources` (two bytes objects): its JSON, with the robots' programs
    named `names` and without the host's wall time, so that the same match
    gives the same text, byte for byte. Raises RuntimeError with simbot's
    message if it fails."""
    with tempfile.TemporaryDirectory(prefix="simbot-match-") as folder:
        paths = [os.path.join(folder, name) for name in ("A.dc", "B.dc")]
        for path, source in zip(paths, sources):
            with open(path, "wb") as f:
                f.write(source)
        p = subprocess.run([simbot, "match", *paths, "--seed", str(seed), "--seconds",
                            str(seconds), "--json", *options],
                           capture_output=True, timeout=MATCH_SECONDS_LIMIT, cwd=folder)
    # 3: a robot faulted, which is a result (its fault is in the JSON).
    if p.returncode not in (0, 3):
        raise RuntimeError(f"simbot match exited {p.returncode}: "
                           f"{p.stderr.decode('utf-8', 'replace').strip()[-500:]}")
    result = json.loads(p.stdout)
    for robot, name in zip(result.get("robots", []), names):
        robot["program"] = name
    result.pop("wall_seconds", None)  # the host's time, not the match's
    return json.dumps(result, sort_keys=True)
