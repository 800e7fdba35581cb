"""One match from what it is: a plain `spec` of its two programs' sources,
the names they are shown by, the robots' hardware files and simbot
match's options. A queue worker runs it, in a thread of the server
(--workers) or as a task on a Dask worker (--dask); the replay page is
made from the same spec (replay.py).

    spec = {"sources": [A bytes, B bytes], "names": ["submission", ...],
            "hardware": [A's TOML text or None, B's], "options": ["--seed", ...]}

The files are written to a fresh temporary folder as A.dc, B.dc, A.toml
and B.toml, so no text a team sends becomes a path and a Dask worker
needs no file of the server's. This module imports nothing but the
standard library: on Dask it is pickled by value (queue.py registers it),
so a worker needs Dask and the simbot executable at the server's path,
not the server's package."""
import json
import os
import subprocess
import tempfile

MATCH_SECONDS_LIMIT = 600  # wall time of one match's process


def write_match(spec, folder):
    """Writes the spec's programs and hardware files into `folder`; simbot
    match's arguments for them, its options last."""
    args, hw = [], []
    for robot, source, hardware in zip("AB", spec["sources"], spec["hardware"]):
        path = os.path.join(folder, robot + ".dc")
        with open(path, "wb") as f:
            f.write(source)
        args.append(path)
        if hardware:
            path = os.path.join(folder, robot + ".toml")
            with open(path, "w", encoding="utf-8") as f:
                f.write(hardware)
            hw += ["--hw", f"{robot}={path}"]
    return args + hw + list(spec["options"])


def failed(name, p):
    return RuntimeError(f"simbot {name} exited {p.returncode}: "
                        f"{p.stderr.decode('utf-8', 'replace').strip()[-500:]}")


def run_match(simbot, spec):
    """`simbot match A.dc B.dc ... --json` on `spec`: its JSON, with the
    robots' programs named as the spec names them and without the host's
    wall time, so that the same match gives the same text, byte for byte.
    Raises RuntimeError with simbot's message if it fails."""
    with tempfile.TemporaryDirectory(prefix="simbot-match-") as folder:
        p = subprocess.run([simbot, "match", *write_match(spec, folder), "--json"],
                           capture_output=True, timeout=MATCH_SECONDS_LIMIT, cwd=folder)
    # 3: a robot faulted, which is a result (its fault is in the JSON).
    if p.returncode not in (0, 3):
        raise failed("match", p)
    result = json.loads(p.stdout)
    for robot, name in zip(result.get("robots", []), spec["names"]):
        robot["program"] = name
    result.pop("wall_seconds", None)  # the host's time, not the match's
    return json.dumps(result, sort_keys=True)
