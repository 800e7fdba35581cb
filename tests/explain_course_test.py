#!/usr/bin/env python3
"""simbot explain and --vcd name what the wider competition added.

Usage: explain_course_test.py SIMBOT SOURCE_DIR ICEMAN FIG92 OUTDIR

- tests/programs/fire_blind.dc alone under se3015-1997w fires 4 times
  without looking (hand-counted in its comment; both eyes read the
  background 16 alone, DESIGN.md optics): explain counts "A scatter shots
  (Detect to Engage): 4" and names each at its ball_launch's tick, eyes
  16/16, threshold 48, its hit not scoring (scatter_scores = false).
- A weak battery on A (profiles/hardware/weak-battery.toml): explain says
  "brown-out at S s (V V)" with S the first reset record's tick / 9,216,000
  to 0.1 s and its voltage; the VCD's A_reset rises at that tick's
  picosecond, round(t * 1e12 / 9216000), and falls at its restart's.
- ICEMAN vs fig92 among scenarios/course-1996.toml's mines (on the
  robots' paths) and scenarios/mines.toml's obstacles: each obstacle
  listed, each contact with an obstacle whose record says mine = true is
  "BUMPER bumper tripped by a mine: obstacle N (mine)" at its tick, and
  each ball_miss on an obstacle "stopped by an obstacle".
- ICEMAN with a disc launcher (its fire() writes 0x40, port B bit 6; fig92 never does) under se3015-1997w: each disc_fire, disc_hit
  and disc_miss named; the VCD names A's bit 6 A_disc_launcher.
- scenarios/course-1996.toml's decoy lights: each deploy record named
  where it was set down, and each release with none left.
- fig92 with its launcher on its solenoid's line (profiles/hardware/
  disc-on-solenoid.toml, seed 10: discs from 43.9 s): one disc for each of its port B writes
  that raises bit 4 (0x18 after 0x08, from the program's own writes), no
  ball, each disc named; the VCD names B's bit 4 B_disc_launcher.
- A decoy screen between fig92 (A) and programs/dropper.dc (B,
  scenarios/decoy-screen.toml): every screen_hides record named ("B
  hidden by a decoy screen (B's screen N)"), and at the first sample
  after each hidden one the segment between the robots' centres crosses
  that screen (its deploy record's centre and heading, 18 in wide from
  profiles/hardware/decoy-light.toml).
- A run without any of these: no Course section, and explain --json
  has no course key.
"""
import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

from scriptcheck import check, failures

SIMBOT, SOURCE, ICEMAN, FIG92, OUT = sys.argv[1:6]
SOURCE, OUT = Path(SOURCE), Path(OUT)
shutil.rmtree(OUT, ignore_errors=True)
OUT.mkdir(parents=True)
TPS = 9216000


def run(*args):
    p = subprocess.run([SIMBOT, *map(str, args)], capture_output=True, text=True, timeout=600,
                       cwd=SOURCE)
    check(p.returncode == 0, f"simbot {' '.join(map(str, args))}: exit {p.returncode} {p.stderr}")
    return p.stdout


def records(path, kind):
    with open(path) as f:
        return [r for r in map(json.loads, f) if r["type"] == kind]


def explain(trace):
    return run("explain", trace)


def at(t):
    return f"{t / TPS:.3f} s"


def ps(t):
    """The VCD's time of tick t: t * 10^12 / TPS picoseconds, the nearest (halves up)."""
    return (t * 10**12 * 2 + TPS) // (2 * TPS)


def vcd_changes(path, name):
    """(ps, value) of the scalar signal NAME."""
    ident, now, out = None, 0, []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line.startswith("$var"):
                parts = line.split()
                if parts[4] == name:
                    ident = parts[3]
            elif line.startswith("#"):
                now = int(line[1:])
            elif ident and line[1:] == ident and line[0] in "01":
                out.append((now, line[0]))
    return ident, out[1:]  # after its power-on value in $dumpvars


# ---- scatter shots
blind = OUT / "blind.jsonl"
run("solo", SOURCE / "tests/programs/fire_blind.dc", "--profile", "thesis-1997", "--rules",
    "se3015-1997w", "--seconds", "5", "--trace", blind)
text = explain(blind)
check("  A scatter shots (Detect to Engage): 4\n" in text, f"4 scatter shots counted: {text[-600:]}")
for launch in records(blind, "ball_launch"):
    want = (f"  A {at(launch['t'])} scatter shot: gun 1 ball {launch['ball']} fired with eyes 16/16, "
            "neither above 48; its hit would not score\n")
    check(want in text, f"named: {want!r}")
check(len(records(blind, "ball_launch")) == 4, "fire_blind launches 4 balls")

# ---- a brown-out
weak, weak_vcd = OUT / "weak.jsonl", OUT / "weak.vcd"
run("match", ICEMAN, FIG92, "--hw", "A=profiles/hardware/weak-battery.toml", "--seconds", "30",
    "--trace", weak, "--vcd", weak_vcd)
resets = [r for r in records(weak, "reset") if r["robot"] == "A"]
check(len(resets) > 0 and resets[0]["cause"] == "brown_out", f"A browns out: {resets[:1]}")
if resets:
    first = resets[0]
    text = explain(weak)
    want = (f"  A {at(first['t'])} brown-out at {first['t'] / TPS:.1f} s ({first['voltage_v']:.2f} V): "
            "the board reset (brown-out 1)\n")
    check(want in text, f"named: {want!r}")
    ident, changes = vcd_changes(weak_vcd, "A_reset")
    check(ident is not None, "the VCD has A_reset")
    restarts = [r for r in records(weak, "restart") if r["robot"] == "A"]
    check(changes[:1] == [(ps(first["t"]), "1")], f"A_reset rises at the reset: {changes[:2]}")
    if restarts:
        check(changes[1:2] == [(ps(restarts[0]["t"]), "0")],
              f"A_reset falls at the restart: {changes[:2]}, restart t {restarts[0]['t']}")

# ---- mines (on the robots' paths) and a mountain that stops balls; the
# course-1996 match also sets down decoy lights (below)
mines, mountain = OUT / "course-1996.jsonl", OUT / "mountain.jsonl"
course_vcd = OUT / "course-1996.vcd"
run("match", ICEMAN, FIG92, "--scenario", "scenarios/course-1996.toml", "--seconds", "50",
    "--trace", mines, "--vcd", course_vcd)
run("match", ICEMAN, FIG92, "--scenario", "scenarios/mines.toml", "--rules", "se3015-1996",
    "--seconds", "60", "--trace", mountain)
text = explain(mines) + explain(mountain)
obstacles = records(mines, "obstacle") + records(mountain, "obstacle")
labels = {f"obstacle {o['index']}" + (f" ({o['name']})" if o["name"] else ""): o for o in obstacles}
for label, o in labels.items():
    check(f"  run 0.000 s {label}: " in text, f"{label} listed")
tripped = [c for c in records(mines, "contact") + records(mountain, "contact")
           if labels.get(c["with"], {}).get("mine")]
check(len(tripped) > 0, "the course-1996 mines trip bumpers")
for c in tripped:
    want = f"  {c['robot']} {at(c['t'])} {c['bumper']} bumper tripped by a mine: {c['with']}\n"
    check(want in text, f"named: {want!r}")
check(text.count("tripped by a mine") == len(tripped),
      f"{len(tripped)} mine contacts, {text.count('tripped by a mine')} named")
stopped = [m for m in records(mountain, "ball_miss") if m["hit"].startswith("obstacle")]
check(len(stopped) > 0, "the mountain stops balls")
for m in stopped:
    check(f"  {m['robot']} {at(m['t'])} ball {m['ball']} (gun " in text and
          f"stopped by an obstacle: {m['hit']}\n" in text, f"ball {m['ball']} stopped at {at(m['t'])}")
print(f"mines: {len(tripped)} mine contacts, {len(stopped)} balls stopped by an obstacle")

# ---- deployables: course-1996's decoy lights, set down from 42 s on
decoys = mines
text = explain(decoys)
deploys = records(decoys, "deploy")
check(len(deploys) == 2, f"two decoy lights set down: {deploys}")
for d in deploys:
    want = (f"  {d['robot']} {at(d['t'])} set down decoy light {d['number']} (bit {d['bit']}) at "
            f"({d['x_ft']:.2f}, {d['y_ft']:.2f}) ft\n")
    check(want in text, f"named: {want!r}")
empties = records(decoys, "deploy_empty")
check(text.count("no decoy light left to set down") == len(empties), "each empty release named")
# The VCD names the release bit by its table's kind, and the bit rises at
# each release's tick, whether an item was left or not (a deploy or a
# deploy_empty record), and at no other tick.
for robot in sorted({d["robot"] for d in deploys + empties}):
    ident, changes = vcd_changes(course_vcd, f"{robot}_deploy_decoy_light")
    check(ident is not None, f"the VCD has {robot}_deploy_decoy_light")
    rises = [t for t, v in changes if v == "1"]
    releases = sorted(ps(d["t"]) for d in deploys + empties if d["robot"] == robot)
    check(rises == releases, f"{robot}'s release bit rises at its releases: {rises} vs {releases}")

# ---- discs
discs, discs_vcd = OUT / "discs.jsonl", OUT / "discs.vcd"
run("match", ICEMAN, FIG92, "--rules", "se3015-1997w", "--hw",
    "A=profiles/hardware/disc-launcher.toml", "--seconds", "60", "--trace", discs, "--vcd", discs_vcd)
text = explain(discs)
fires = records(discs, "disc_fire")
check(len(fires) > 0, "ICEMAN fires discs")
for f in fires:
    check(f"  {f['robot']} {at(f['t'])} disc {f['disc']} fired, heading {f['heading_deg']:.1f} deg" in text,
          f"disc fired at {at(f['t'])}")
for h in records(discs, "disc_hit"):
    check(f"  {h['robot']} {at(h['t'])} disc {h['disc']} hit {h['target']}\n" in text, f"disc hit {h}")
for m in records(discs, "disc_miss"):
    check(f"  {m['robot']} {at(m['t'])} disc {m['disc']} missed: " in text, f"disc miss {m}")
check(vcd_changes(discs_vcd, "A_disc_launcher")[0] is not None, "the VCD names A_disc_launcher")

# ---- discs from fig92's solenoid line
fig_discs, fig_vcd = OUT / "fig92_discs.jsonl", OUT / "fig92_discs.vcd"
run("match", ICEMAN, FIG92, "--rules", "se3015-1997w", "--hw",
    "B=profiles/hardware/disc-on-solenoid.toml", "--seed", "10", "--seconds", "60", "--trace",
    fig_discs, "--vcd", fig_vcd)
text = explain(fig_discs)
writes = [r for r in records(fig_discs, "port_b") if r["robot"] == "B"]
rises = sum(1 for a, b in zip([0] + [w["value"] for w in writes], [w["value"] for w in writes])
            if b & 0x10 and not a & 0x10)
b_fires = [f for f in records(fig_discs, "disc_fire") if f["robot"] == "B"]
b_empty = [f for f in records(fig_discs, "disc_empty") if f["robot"] == "B"]
check(rises > 0 and len(b_fires) + len(b_empty) == rises,
      f"fig92: one disc per rise of bit 4: {rises} rises, {len(b_fires)} + {len(b_empty)} discs")
check(not [b for b in records(fig_discs, "ball_launch") if b["robot"] == "B"],
      "fig92's gun 1 (solenoid on bit 6) launches no ball")
for f in b_fires:
    check(f"  B {at(f['t'])} disc {f['disc']} fired, heading {f['heading_deg']:.1f} deg" in text,
          f"fig92's disc fired at {at(f['t'])}")
for h in (h for h in records(fig_discs, "disc_hit") if h["robot"] == "B"):
    check(f"  B {at(h['t'])} disc {h['disc']} hit A\n" in text, f"fig92's disc hit {h}")
check(vcd_changes(fig_vcd, "B_disc_launcher")[0] is not None, "the VCD names B_disc_launcher")

# ---- a decoy screen between the robots
screens = OUT / "screen.jsonl"
run("match", FIG92, SOURCE / "programs/dropper.dc", "--scenario", "scenarios/decoy-screen.toml",
    "--seconds", "10", "--trace", screens)
text = explain(screens)
hides = records(screens, "screen_hides")
check(any(h["hidden"] for h in hides), f"the screen hides B from A: {hides}")
placed = [d for d in records(screens, "deploy") if d["kind"] == "decoy_screen"]
samples = records(screens, "sample")


def crosses(a, b, c, d):
    """Whether segments ab and cd cross (their points as (x, y))."""
    def side(p, q, r):
        return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
    return side(a, b, c) * side(a, b, d) < 0 and side(c, d, a) * side(c, d, b) < 0


for h in hides:
    verb = "hidden by" if h["hidden"] else "no longer hidden by"
    want = f"  {h['robot']} {at(h['t'])} B {verb} a decoy screen ({h['owner']}'s screen {h['number']})\n"
    check(want in text, f"named: {want!r}")
    if not h["hidden"]:
        continue
    scr = [d for d in placed if d["robot"] == h["owner"] and d["number"] == h["number"]]
    after = [r for r in samples if r["t"] >= h["t"]][:2]
    check(len(scr) == 1 and len(after) == 2, f"screen {h['number']} and the samples after {h['t']}")
    if len(scr) == 1 and len(after) == 2:
        d = scr[0]
        hd = math.radians(d["heading_deg"])
        w = (0.75 * math.cos(hd), -0.75 * math.sin(hd))  # half of 18 in, across the heading
        ends = ((d["x_ft"] - w[0], d["y_ft"] - w[1]), (d["x_ft"] + w[0], d["y_ft"] + w[1]))
        pos = {r["robot"]: (r["x_ft"], r["y_ft"]) for r in after}
        check(crosses(pos["A"], pos["B"], *ends),
              f"at {at(after[0]['t'])} the line A-B crosses B's screen {h['number']}: {pos} {ends}")

# ---- none of it
plain = OUT / "plain.jsonl"
run("match", ICEMAN, FIG92, "--seconds", "10", "--trace", plain)
check("Course:" not in explain(plain), "no Course section without the new elements")
check("course" not in json.loads(run("explain", plain, "--json")), "no course key without them")

if failures:
    sys.exit(f"{len(failures)} check(s) failed")
print("explain_course_test: all checks passed")
