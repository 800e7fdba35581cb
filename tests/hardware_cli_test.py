#!/usr/bin/env python3
"""simbot hardware: every value a hardware file may set, and a file checked.

Usage: hardware_cli_test.py SIMBOT SOURCE_DIR OUTDIR

The oracle is the TOML files themselves, read with Python's tomllib, and
docs/plant.md:

- The keys a hardware file may set are the per-robot sections of a
  profile (docs/plant.md: [robot], [bumper], [eyes], [gun], [battery],
  [controller]) in profiles/default.toml's order: 12 + 2 + 9 + 12 + 13 + 4
  = 52 keys; then [ports] (docs/plant.md: gun1_motor, gun1_solenoid,
  gun2_motor, gun2_solenoid, disc_shooter, built-in bits 3, 4, 7, 5, 6),
  then [secondary] in profiles/hardware/disc-launcher.toml's order (all 8
  keys): 65 in all.
- Each profile key's value, unit and source are tomllib's; its loaded
  value is the value times this file's own unit factors (1 in = 1/12 ft,
  1 Ah = 3600 C, ...), and its range in the unit written is the range in
  the internal unit divided by the same factor.
- By hand: body_diameter is 12.75 in (1.0625 ft), valid 0.1 .. 5 ft, that
  is 1.2 .. 60 in (times 12); battery capacity 36 .. 360000 C is
  0.01 .. 100 Ah (over 3600); motor_lag is 0 or 0.001 .. 10 s.
- profiles/hardware/weak-battery.toml passes (exit 0): its five [battery]
  keys come from it with its values, every other key as without it;
  capacity 0.05 Ah loads as 180 C.
- A bad file is one line FILE:LINE:COL: error: ..., exit 1, nothing on
  stdout, the line `match --hw A=FILE` gives: the issue's
  `mass = { value = 900, unit = "lb" }` has no source (column 8, the
  table's brace); with a source, 900 lb is out of 0.5 .. 500 lb (column
  18, the 900).
"""
import json
import math
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

from scriptcheck import check, failures

SIMBOT, SOURCE, OUT = sys.argv[1:4]
SOURCE, OUT = Path(SOURCE), Path(OUT)
shutil.rmtree(OUT, ignore_errors=True)
OUT.mkdir(parents=True)
DEFAULT = SOURCE / "profiles/default.toml"
WEAK = SOURCE / "profiles/hardware/weak-battery.toml"
DISC = SOURCE / "profiles/hardware/disc-launcher.toml"

# To the internal unit (docs/plant.md: ft, s, ft/s, deg, lb, C, V, A, ohm).
FACTOR = {"ft": 1, "in": 1 / 12, "m": 1 / 0.3048, "cm": 1 / 30.48, "mm": 1 / 304.8,
          "ft/s": 1, "in/s": 1 / 12, "m/s": 1 / 0.3048, "s": 1, "ms": 1e-3,
          "deg": 1, "rad": 180 / math.pi, "lb": 1, "kg": 1 / 0.45359237, "1": 1,
          "reading": 1, "count": 1, "step": 1, "bit": 1, "Ah": 3600, "mAh": 3.6, "C": 1,
          "V": 1, "mV": 1e-3, "A": 1, "mA": 1e-3, "ohm": 1, "mohm": 1e-3}
PER_ROBOT = ["robot", "bumper", "eyes", "gun", "battery", "controller"]
PORTS = {"gun1_motor": 3, "gun1_solenoid": 4, "gun2_motor": 7, "gun2_solenoid": 5,
         "disc_shooter": 6}


def run(*args):
    return subprocess.run([SIMBOT, *map(str, args)], capture_output=True, text=True, timeout=120)


def close(a, b):
    return math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-15)


def listing(*args):
    p = run("hardware", *args, "--json")
    check(p.returncode == 0 and p.stderr == "", f"hardware {args}: {p.returncode} {p.stderr!r}")
    return json.loads(p.stdout) if p.returncode == 0 else {"keys": []}


def toml(path):
    with open(path, "rb") as f:
        return tomllib.load(f)


profile = toml(DEFAULT)
disc = toml(DISC)
expected_keys = [(s, k) for s in PER_ROBOT for k in profile[s]]
expected_keys += [("ports", k) for k in PORTS] + [("secondary", k) for k in disc["secondary"]]
check(len(expected_keys) == 65, f"the oracle's own count: {len(expected_keys)}")


def check_written(keys, files, label):
    """Every key set in `files` (first wins) shows that file's value, unit and source."""
    for k in keys:
        name = f"{label} {k['section']}.{k['key']}"
        entry, origin = None, "built-in"
        for doc, who in files:
            if k["key"] in doc.get(k["section"], {}):
                entry, origin = doc[k["section"]][k["key"]], who
                break
        check(k["from"] == origin, f"{name}: from {k['from']}, expected {origin}")
        if entry is None:
            check(k["value"] is None and k["unit"] is None and k["source"] is None,
                  f"{name}: built-in but {k['value']!r} {k['unit']!r} {k['source']!r}")
            continue
        check(k["value"] == entry["value"] and k["unit"] == entry.get("unit")
              and k["source"] == entry["source"],
              f"{name}: {k['value']!r} {k['unit']!r} {k['source']!r}, expected {entry}")
        if k["kind"] in ("bool", "choice"):
            check(k["loaded"] == entry["value"] and k["range"] is None and k["units"] == [],
                  f"{name}: loaded {k['loaded']!r}, range {k['range']}")
            continue
        factor = FACTOR[entry["unit"]]
        want = [v * factor for v in entry["value"]] if isinstance(entry["value"], list) \
            else entry["value"] * factor
        got = k["loaded"]
        check(close(got, want) if not isinstance(want, list)
              else len(got) == 16 and all(close(a, b) for a, b in zip(got, want)),
              f"{name}: loaded {got}, expected {want}")
        check(entry["unit"] in k["units"] and k["range_shown"]["unit"] == entry["unit"]
              and close(k["range_shown"]["lo"], k["range"]["lo"] / factor)
              and close(k["range_shown"]["hi"], k["range"]["hi"] / factor),
              f"{name}: units {k['units']}, range {k['range']} shown {k['range_shown']}")


# ---- without a file: the profile's values, ports and secondary built in
plain = listing()
keys = plain["keys"]
check([(k["section"], k["key"]) for k in keys] == expected_keys,
      f"keys: {[(k['section'], k['key']) for k in keys]}")
check(plain["hardware"] is None and plain["profile"]["name"] == "default"
      and Path(plain["profile"]["file"]).resolve() == DEFAULT.resolve(),
      f"profile {plain['profile']}, hardware {plain['hardware']}")
check_written(keys, [(profile, "profile")], "default")
by = {(k["section"], k["key"]): k for k in keys}

body = by[("robot", "body_diameter")]
check(body["value"] == 12.75 and body["unit"] == "in" and body["loaded"] == 1.0625
      and body["kind"] == "length" and body["units"] == ["ft", "in", "m", "cm", "mm"]
      and body["internal_unit"] == "ft" and body["presence"] == "required"
      and body["range"] == {"lo": 0.1, "hi": 5, "or_zero": False, "unit": "ft"}
      and body["range_shown"] == {"lo": 1.2, "hi": 60, "or_zero": False, "unit": "in"},
      f"body_diameter: {body}")
capacity = by[("battery", "capacity")]
check(capacity["range_shown"] == {"lo": 0.01, "hi": 100, "or_zero": False, "unit": "Ah"}
      and capacity["presence"] == "optional_section" and capacity["loaded"] == 7200,
      f"battery.capacity (2 Ah = 7200 C): {capacity}")
lag = by[("robot", "motor_lag")]
check(lag["range"] == {"lo": 0.001, "hi": 10, "or_zero": True, "unit": "s"},
      f"motor_lag: {lag['range']}")
check(by[("controller", "timer_service")]["choices"] == ["auto", "always", "never"]
      and by[("controller", "cpu")]["choices"] == ["z80180", "z8s180"],
      "the choices' words")
for key, bit in PORTS.items():
    k = by[("ports", key)]
    check(k["loaded"] == bit and k["presence"] == "optional"
          and k["range"] == {"lo": 0, "hi": 7, "or_zero": False, "unit": "bit"}
          and type(k["range"]["hi"]) is int,
          f"ports.{key}: loaded {k['loaded']}, range {k['range']}, expected built-in {bit}")
check(by[("secondary", "kind")]["loaded"] == "none"
      and by[("secondary", "kind")]["presence"] == "optional_section"
      and by[("secondary", "bit")]["presence"] == "optional",
      f"secondary without the table: {by[('secondary', 'kind')]}")

# The text table: the same rows, each column where the header puts it (the
# speed table's long value runs past its column).
p = run("hardware")
lines = p.stdout.splitlines()
header = next((i for i, l in enumerate(lines) if l.startswith("KEY")), None)
check(p.returncode == 0 and header is not None, f"text: {p.returncode} {p.stdout[:200]!r}")
if header is not None:
    rows = lines[header + 1:]
    check([r.split()[0] for r in rows] == [f"{s}.{k}" for s, k in expected_keys],
          "text: the keys' rows")
    columns = [lines[header].index(c) for c in ("VALUE", "UNIT", "VALID", "FROM", "SOURCE")]
    for row, (s, k) in zip(rows, expected_keys):
        if k == "speed_table":
            continue
        want = {"body_diameter": "12.75", "gun1_motor": "3"}.get(k)
        check(row[columns[0] - 2:columns[0]] == "  "
              and row[columns[3]:].split()[0] == by[(s, k)]["from"]
              and (want is None or row[columns[0]:].split()[0] == want),
              f"text row not aligned: {row!r}")
    body_row = rows[expected_keys.index(("robot", "body_diameter"))]
    check(body_row[columns[2]:].startswith("1.2 .. 60 "), f"text: {body_row!r}")

# --profile by file gives the same listing as by name.
by_file = listing("--profile", SOURCE / "profiles/thesis-1997.toml")
by_name = listing("--profile", "thesis-1997")
check(by_file["keys"] == by_name["keys"] and by_name["profile"]["name"] == "thesis-1997",
      "--profile FILE and NAME")
check_written(by_name["keys"], [(toml(SOURCE / "profiles/thesis-1997.toml"), "profile")],
              "thesis-1997")

# ---- a good file: its values where it sets them, the profile's elsewhere
weak = listing(WEAK)
check(weak["hardware"] == {"file": str(WEAK)}, f"hardware {weak['hardware']}")
check([(k["section"], k["key"]) for k in weak["keys"]] == expected_keys, "weak-battery: keys")
check_written(weak["keys"], [(toml(WEAK), "hardware"), (profile, "profile")], "weak-battery")
weak_by = {(k["section"], k["key"]): k for k in weak["keys"]}
check(sum(k["from"] == "hardware" for k in weak["keys"]) == 5
      and weak_by[("battery", "capacity")]["loaded"] == 180
      and weak_by[("battery", "enabled")]["loaded"] is True,
      f"weak-battery: {weak_by[('battery', 'capacity')]}")
for key, k in weak_by.items():
    if k["from"] != "hardware":
        check(k == by[key], f"weak-battery: {key} differs from the profile's: {k}")

disc_listing = listing(DISC, "--profile", "thesis-1997")
check_written(disc_listing["keys"], [(disc, "hardware"),
                                     (toml(SOURCE / "profiles/thesis-1997.toml"), "profile")],
              "disc-launcher")

# ---- bad files: the loader's one line, exit 1, as match --hw gives it
# Each error is at `token` on `line` (its column counted here, from 1).
for name, body, line, token, words in [
    ("no-source.toml", '[robot]\nmass = { value = 900, unit = "lb" }\n', 2, "{", "has no 'source'"),
    ("heavy.toml", '[robot]\nmass = { value = 900, unit = "lb", source = "x" }\n', 2, "900",
     "'robot.mass' must be between 0.5 and 500 lb, got 900 lb"),
    ("arena.toml", '# a comment\n[field]\nsize = { value = 1, unit = "ft", source = "x" }\n', 2,
     "field", "[field] is arena-wide"),
    ("ports.toml", '[ports]\ngun1_motor = { value = 8, unit = "bit", source = "x" }\n', 2, "8",
     "'ports.gun1_motor' must be in 0..7"),
]:
    column = body.splitlines()[line - 1].index(token) + 1
    bad = OUT / name
    bad.write_text(body)
    p = run("hardware", bad, "--json")
    err = p.stderr.strip().splitlines()
    check(p.returncode == 1 and p.stdout == "" and len(err) == 1
          and err[0].startswith(f"{bad}:{line}:{column}: error: ") and words in err[0],
          f"{name}: exit {p.returncode}, {p.stderr!r}")
    m = run("match", SOURCE / "programs/turret.dc", SOURCE / "programs/turret.dc",
            "--seconds", "1", "--hw", f"A={bad}")
    check(m.returncode == 1 and m.stderr == p.stderr, f"{name}: match --hw says {m.stderr!r}")

missing = OUT / "no-such.toml"
p = run("hardware", missing)
check(p.returncode == 1 and p.stderr.startswith(f"{missing}:1:1: error: ")
      and len(p.stderr.splitlines()) == 1, f"missing file: {p.returncode} {p.stderr!r}")
p = run("hardware", "--profile", "no-such-profile")
check(p.returncode == 1 and len(p.stderr.splitlines()) == 1 and "no profile" in p.stderr,
      f"--profile no-such-profile: {p.returncode} {p.stderr!r}")

if failures:
    sys.exit(f"{len(failures)} check(s) failed")
print("hardware_cli_test: all checks passed")
