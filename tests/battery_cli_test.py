#!/usr/bin/env python3
"""Batteries, brown-out resets and injected resets against closed forms.

Usage: battery_cli_test.py SIMBOT TESTDIR OUTDIR

TESTDIR is tests/battery: spin_then_stop.dc prints "start" from main,
latches the frame "ffgxfrgx" (left wheel forward, right wheel reverse, both
at step 15: the robot spins on its spot, so nothing but the two frames
changes its current), waits about 90 s, latches "0fs00fs0" (both stopped)
and idles. Runs use the thesis-1997 profile (speed table step 15 =
1.5 ft/s, trims 1, no motor lag, no placement spread) with a hardware file
that turns the battery on.

Oracle (docs/plant.md, "Batteries"; worked here with exact fractions, from
the profile's decimals and the latch ticks L1, L2 the trace gives):
  I0 = board = 0.15 A before L1 and after L2, I1 = 0.15 + 2 x 1.5 = 3.15 A
  Q(T) = sum of I_k dt_k (coulombs, dt in ticks / 9,216,000)
  V(T) = V_empty + (V_full - V_empty)(1 - Q/C) - I(T) R
battery-test.toml: C = 0.5 Ah = 1800 C, V_full 12.8, V_empty 10.5,
R = 0.25 ohm, nominal 12 V. Checked to 1e-9 V at 60, 120 and 180 s
(battery_v_final of runs that long), and the wheels' speed while spinning
equals 1.5 ft/s x V(L1) / 12 (the supply scale is held from the latch).
brownout-test.toml: C = 0.02 Ah = 72 C, V_full 11, V_empty 8.5, R = 0.6,
brown-out 8 V, hysteresis 0.5 V, hold 0.2 s. The voltage under 3.15 A
reaches 8 V at state of charge s* = (8 + 3.15 x 0.6 - 8.5) / 2.5, i.e.
after Q* = 72 (1 - s*) = 31.968 C, at t* = L1 / N + (Q* - 0.15 L1 / N) /
3.15 s: the reset is at tick ceil(t* N) (plant::eventTickFromSeconds), the
restart 0.2 s = 1,843,200 ticks later (the voltage there, with 0.15 A, is
above 8.5 V), and the restarted program's spin frame browns it out again at
the very tick it latches (its voltage is V(t*) less the charge drawn since).
--inject A:reset@5s: a reset at tick 46,080,000 exactly, the program
restarted from main (two "start" lines), JSON resets.injected = 1,
battery_v_final null (the default profile has its battery off).
Bad values (out of range, a curve upside down): FILE:LINE:COL, exit 1.
"""
import json
import math
import shutil
import subprocess
import sys
from fractions import Fraction as F
from pathlib import Path

from scriptcheck import check, failures

SIMBOT, TESTDIR, OUT = sys.argv[1:4]
TESTDIR = Path(TESTDIR)
OUT = Path(OUT)
shutil.rmtree(OUT, ignore_errors=True)
OUT.mkdir(parents=True)
PROGRAM = str(TESTDIR / "spin_then_stop.dc")
N = 9_216_000


def run(*args):
    return subprocess.run([SIMBOT, *args], capture_output=True, text=True, timeout=600)


def solo(hw, seconds, trace=None, extra=()):
    args = ["solo", PROGRAM, "--profile", "thesis-1997", "--seconds", str(seconds), "--json",
            *extra]
    if hw:
        args += ["--hw", str(TESTDIR / hw)]
    if trace:
        args += ["--trace", str(trace)]
    r = run(*args)
    check(r.returncode == 0, f"solo {args} exits 0, got {r.returncode}: {r.stderr}")
    return json.loads(r.stdout)


def records(path):
    with open(path) as f:
        return [json.loads(line) for line in f]


# ---- discharge: V at 60, 120 and 180 s
trace = OUT / "discharge.jsonl"
j180 = solo("battery-test.toml", 180, trace)
recs = records(trace)
latched = [r["t"] for r in recs if r["type"] == "frame_latched"]
check(len(latched) == 2, f"two frames latched: {latched}")
L1, L2 = latched[0], latched[1]
check(60 * N < L2 < 120 * N, f"the stop frame latches between 60 and 120 s: {L2 / N} s")
check(not any(r["type"] == "reset" for r in recs), "no reset with a healthy battery")
C, VF, VE, R, BOARD, SPIN = F(1800), F("12.8"), F("10.5"), F("0.25"), F("0.15"), F("3.15")


def voltage(T):
    q = BOARD * min(T, L1) + SPIN * max(0, min(T, L2) - L1) + BOARD * max(0, T - L2)
    q /= N
    current = SPIN if L1 <= T < L2 else BOARD
    return VE + (VF - VE) * (1 - q / C) - current * R


for seconds in (60, 120, 180):
    j = j180 if seconds == 180 else solo("battery-test.toml", seconds)
    got = j["battery_v_final"]
    want = float(voltage(seconds * N))
    check(abs(got - want) <= 1e-9, f"V at {seconds} s: {got!r}, closed form {want!r}")

# ---- the wheels at the held supply scale
samples = [r for r in recs if r["type"] == "sample" and r["t"] == 60 * N]
check(len(samples) == 1, "a sample at 60 s")
if samples:
    want = float(F("1.5") * voltage(L1) / 12)
    check(abs(samples[0]["left_fps"] - want) <= 1e-12,
          f"left wheel at 60 s: {samples[0]['left_fps']!r}, 1.5 x V(L1) / 12 = {want!r}")
    check(abs(samples[0]["right_fps"] + want) <= 1e-12,
          f"right wheel at 60 s: {samples[0]['right_fps']!r}, -{want!r}")

# ---- brown-out
trace = OUT / "brownout.jsonl"
jb = solo("brownout-test.toml", 20, trace)
recs = records(trace)
resets = [r for r in recs if r["type"] == "reset"]
restarts = [r for r in recs if r["type"] == "restart"]
latched = [r["t"] for r in recs if r["type"] == "frame_latched"]
check(len(resets) >= 2 and len(restarts) >= 1, f"resets {len(resets)}, restarts {len(restarts)}")
if resets and restarts and latched:
    L1 = latched[0]
    C, VF, VE, R, VBO = F(72), F(11), F("8.5"), F("0.6"), F(8)
    s_star = (VBO + SPIN * R - VE) / (VF - VE)
    q_star = C * (1 - s_star)
    t_star = F(L1, N) + (q_star - BOARD * F(L1, N)) / SPIN
    tick = math.ceil(t_star * N)
    check(resets[0]["t"] == tick, f"brown-out at tick {resets[0]['t']}, closed form {tick}")
    check(resets[0]["cause"] == "brown_out", "cause brown_out")
    check(abs(resets[0]["voltage_v"] - 8.0) < 1e-6, f"V at the brown-out {resets[0]['voltage_v']}")
    hold = 1_843_200
    check(restarts[0]["t"] == resets[0]["t"] + hold,
          f"restart {restarts[0]['t']} = reset + 0.2 s = {resets[0]['t'] + hold}")
    q_restart = BOARD * F(L1, N) + SPIN * F(resets[0]["t"] - L1, N) + BOARD * F(hold, N)
    v_restart = VE + (VF - VE) * (1 - q_restart / C) - BOARD * R
    check(abs(restarts[0]["voltage_v"] - float(v_restart)) <= 1e-9,
          f"V at the restart {restarts[0]['voltage_v']}, closed form {float(v_restart)}")
    after = [t for t in latched if t > restarts[0]["t"]]
    check(after and resets[1]["t"] == after[0],
          f"the restarted program's spin frame browns it out as it latches: {resets[1]['t']}")
    check(jb["resets"]["brown_out"] == len(resets), f"JSON resets {jb['resets']}")
    check(jb["console"].count("start") == len(restarts) + 1,
          f"main ran once per restart: {jb['console'][:5]}")

# ---- injected reset
trace = OUT / "inject.jsonl"
r = run("solo", PROGRAM, "--seconds", "10", "--json", "--trace", str(trace),
        "--inject", "A:reset@5s")
check(r.returncode == 0, f"injected reset: exit {r.returncode} {r.stderr}")
ji = json.loads(r.stdout)
recs = records(trace)
resets = [x for x in recs if x["type"] == "reset"]
check(len(resets) == 1 and resets[0]["t"] == 46_080_000 and resets[0]["cause"] == "injected"
      and resets[0]["voltage_v"] is None, f"one injected reset at tick 46,080,000: {resets}")
check(ji["resets"] == {"brown_out": 0, "injected": 1}, f"JSON resets {ji['resets']}")
check(ji["battery_v_final"] is None, "no battery: battery_v_final null")
check(ji["console"] == ["start", "start"], f"main ran again: {ji['console']}")
bad = run("solo", PROGRAM, "--inject", "A:reset@line:20#1")
check(bad.returncode == 1 and "a reset is injected at a time" in bad.stderr,
      f"reset at a program point refused: {bad.returncode} {bad.stderr}")

# ---- bad values
for hw, message in (("bad-capacity.toml", "'battery.capacity' must be between"),
                    ("bad-curve.toml", "voltage_empty must be below battery.voltage_full")):
    r = run("solo", PROGRAM, "--hw", str(TESTDIR / hw))
    first = r.stderr.splitlines()[0] if r.stderr else ""
    check(r.returncode == 1 and f"{hw}:" in first and message in first and
          first.split(f"{hw}:")[1].split(":")[0].isdigit(),
          f"{hw}: FILE:LINE:COL error, exit 1: {r.returncode} {r.stderr!r}")

if failures:
    sys.exit(1)
print("battery: all checks passed")
