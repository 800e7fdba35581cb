#!/usr/bin/env python3
"""A course's round robin, played through a running `simbot serve` by its
HTTP API alone, as an instructor and the teams would: one team per
program (named by the file's stem), each program submitted by its team,
then the instructor's round robin; waits for its games and prints its
table as Markdown (docs/serve.md shows one).

Usage: course_round_robin.py URL DATA_DIR [--rounds N] [--seconds S]
       [--seed N] [--rules NAME] PROGRAM.dc...
DATA_DIR is the server's --data, where its instructor token is."""
import argparse
import json
import os
import sys
import time
import urllib.error
import urllib.request
import uuid

WAIT_S = 1800  # at most, for the games


def call(url, method="GET", token=None, body=None, files=None):
    headers = {"Authorization": f"Bearer {token}"} if token else {}
    data = None
    if files is not None:  # one multipart field, `program`
        boundary = uuid.uuid4().hex
        name, content = files
        data = (f"--{boundary}\r\nContent-Disposition: form-data; name=\"program\"; "
                f"filename=\"{name}\"\r\nContent-Type: text/plain\r\n\r\n").encode() + content + \
            f"\r\n--{boundary}--\r\n".encode()
        headers["Content-Type"] = f"multipart/form-data; boundary={boundary}"
    elif body is not None:
        data = json.dumps(body).encode()
        headers["Content-Type"] = "application/json"
    request = urllib.request.Request(url, data=data, headers=headers, method=method)
    try:
        with urllib.request.urlopen(request, timeout=60) as r:
            return json.load(r)
    except urllib.error.HTTPError as e:
        sys.exit(f"course_round_robin: {method} {url}: {e.code} {e.read().decode()[:300]}")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("url")
    p.add_argument("data")
    p.add_argument("programs", nargs="+")
    p.add_argument("--rounds", type=int, default=2)
    p.add_argument("--seconds", type=int, default=180)
    p.add_argument("--seed", type=int, default=1997)
    p.add_argument("--rules")
    a = p.parse_args()
    url = a.url.rstrip("/")
    with open(os.path.join(a.data, "instructor-token")) as f:
        instructor = f.read().strip()
    for path in a.programs:
        name = os.path.splitext(os.path.basename(path))[0]
        team = call(f"{url}/api/teams", "POST", instructor, {"name": name})
        with open(path, "rb") as f:
            call(f"{url}/api/submissions", "POST", team["token"], files=(os.path.basename(path), f.read()))
    body = {"rounds": a.rounds, "seconds": a.seconds, "seed": a.seed}
    if a.rules:
        body["rules"] = a.rules
    t = call(f"{url}/api/tournaments", "POST", instructor, body)
    deadline = time.monotonic() + WAIT_S
    while True:
        got = call(f"{url}/api/tournaments/{t['id']}")
        if got["status"] == "done":
            break
        if time.monotonic() > deadline:
            sys.exit(f"course_round_robin: the games did not finish in {WAIT_S} s")
        time.sleep(0.5)
    games = got["games"]
    print(f"Round robin {t['id']}: {len(a.programs)} teams, {a.rounds} round(s) of {a.seconds}-s "
          f"games ({games['total']}: {games['done']} done, {games['failed']} failed), "
          f"rules {a.rules or 'none'}, brackets from seed {a.seed}.\n")
    print("| # | team | played | wins | losses | hits | scatter shots | rating | 95% interval |")
    print("|---|---|---|---|---|---|---|---|---|")
    for i, row in enumerate(got["table"], start=1):
        print(f"| {i} | {row['team']} | {row['played']} | {row['wins']} | {row['losses']} | "
              f"{row['hits']} | {row['scatter_shots']} | {row['rating']:+.2f} | "
              f"{row['ci_low']:+.2f} to {row['ci_high']:+.2f} |")


if __name__ == "__main__":
    main()
