#!/usr/bin/env python3
"""The VCD waveforms (--vcd) against independent readers.

Usage: vcd_test.py SIMBOT ICEMAN FIG92 OUTDIR

- sigrok's own UART decoder reads the TXD line of a 20-s ICEMAN solo run and
  must find exactly the bytes of every frame the trace records as latched,
  in order, each followed by its NUL.
- Every start bit sits at round(t * 10^12 / 9,216,000) ps for the tick t the
  trace gives (exact rational arithmetic here, not simbot's).
- An injected edge: the PIO handler's in-service signal spans acceptance to
  RETI, and IFF1 is low from acceptance until ICEMAN's EI() at the top of
  its handler.
- GTKWave's vcd2fst accepts every VCD this test writes, and fst2vcd gives
  back the same value changes; GTKWave itself, under Xvfb, opens the
  match's VCD with every signal and the run's end as its last time.
"""
import json
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

from scriptcheck import check, failures

SIMBOT, ICEMAN, FIG92, OUT = sys.argv[1], sys.argv[2], sys.argv[3], Path(sys.argv[4])
OUT.mkdir(parents=True, exist_ok=True)
TICKS_PER_SECOND = 9_216_000


def run(*args):
    result = subprocess.run([SIMBOT, *args], capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit(f"simbot {' '.join(args)} failed ({result.returncode}):\n{result.stderr}")
    return result.stdout


def picoseconds(tick):
    """round(tick * 1e12 / 9216000), halves up, exactly."""
    x = Fraction(tick * 10**12, TICKS_PER_SECOND)
    return int(x + Fraction(1, 2)) if x.denominator != 1 else int(x)


def read_trace(path):
    return [json.loads(line) for line in open(path)]


def parse_vcd(text):
    """Variables {id: name} and the value changes [(time, name, value)]."""
    names, changes, time, body = {}, [], 0, False
    tokens = iter(text.split("\n"))
    for line in tokens:
        line = line.strip()
        if not line:
            continue
        if not body:
            if line.startswith("$var"):
                parts = line.split()
                names[parts[3]] = parts[4]
            elif line.startswith("$enddefinitions"):
                body = True
            continue
        if line.startswith("$"):
            continue  # $dumpvars / $end: the values inside still count
        if line[0] == "#":
            time = int(line[1:])
        elif line[0] in "rRbB":
            value, ident = line[1:].split()
            changes.append((time, names[ident], float(value)))
        else:
            changes.append((time, names[line[1:]], line[0]))
    return names, changes


def final_values(changes):
    """The value each signal has at each time it was written (last wins)."""
    result = {}
    for time, name, value in changes:
        result[(time, name)] = value
    return result


def fst_round_trip(vcd_path):
    fst = vcd_path.with_suffix(".fst")
    r = subprocess.run(["vcd2fst", str(vcd_path), str(fst)], capture_output=True, text=True)
    check(r.returncode == 0 and fst.exists() and fst.stat().st_size > 0,
          f"vcd2fst rejected {vcd_path}: {r.stderr}")
    back = subprocess.run(["fst2vcd", str(fst)], capture_output=True, text=True, check=True).stdout
    _, original = parse_vcd(vcd_path.read_text())
    _, returned = parse_vcd(back)
    a, b = final_values(original), final_values(returned)
    # fst2vcd writes only changes: compare what each signal holds over time.
    def timeline(values):
        per = {}
        for (time, name), value in sorted(values.items()):
            if per.get(name, [(None, None)])[-1][1] != value:
                per.setdefault(name, []).append((time, value))
        return per
    check(timeline(a) == timeline(b), f"fst2vcd did not give back the changes of {vcd_path}")


# ---- 1. a 20-s ICEMAN solo run: sigrok's UART decoder on TXD. Under
# thesis-1997, whose eyes give no bad readings: with one, ICEMAN may restart
# a send midway, and those bytes are on the wire but never latch.
solo_vcd, solo_trace = OUT / "iceman-solo.vcd", OUT / "iceman-solo.jsonl"
run("solo", ICEMAN, "--seconds", "20", "--profile", "thesis-1997", "--trace", str(solo_trace),
    "--vcd", str(solo_vcd))
trace = read_trace(solo_trace)
expected = []
for r in trace:
    if r["type"] == "frame_latched":
        expected += [ord(c) for c in r["bytes"]] + [0]
# N = 108507 ps per sample: about one sample a tick (108506.9 ps).
decoded = subprocess.run(
    ["sigrok-cli", "-i", str(solo_vcd), "-I", "vcd:downsample=108507",
     "-P", "uart:rx=A_txd:baudrate=9600", "-A", "uart=rx-data"],
    capture_output=True, text=True, check=True).stdout.split("\n")
got = [int(line.split(":")[1].strip(), 16) for line in decoded if line.startswith("uart")]
check(len(expected) > 9 * 400, f"only {len(expected)} bytes latched in 20 s")
check(got == expected,
      f"sigrok decoded {len(got)} bytes, the trace latched {len(expected)} (with NULs); "
      f"first difference at {next((i for i, (x, y) in enumerate(zip(got, expected)) if x != y), None)}")

# ---- 2. start bits at the exact picosecond
names, changes = parse_vcd(solo_vcd.read_text())
txd = [(time, value) for time, name, value in changes if name == "A_txd"]
falls = {time for time, value in txd if value == "0"}
bytes_on_wire = [r for r in trace if r["type"] == "serial_byte"]
# A start bit follows the idle line or a stop bit: each one is a fall.
check(all(picoseconds(r["t"]) in falls for r in bytes_on_wire),
      "a start bit at round(t * 1e12 / 9216000) ps for every serial_byte")
# ICEMAN's first byte is 'c' = 0x63 = 0b01100011, sent LSB first after the
# start bit: 0 | 1 1 0 0 0 1 1 0 | 1, so the line changes at bit times
# 0 (0), 1 (1), 3 (0), 6 (1), 8 (0) and 9 (1, the stop bit), 960 ticks each.
first = bytes_on_wire[0]
check(first["byte"] == 0x63, f"ICEMAN's first byte is 'c', got {first['byte']}")
t0 = first["t"]
want = [(picoseconds(t0 + 960 * k), v) for k, v in
        ((0, "0"), (1, "1"), (3, "0"), (6, "1"), (8, "0"), (9, "1"))]
at = txd.index(want[0])
check(txd[at:at + 6] == want, f"the first byte's waveform: {txd[at:at + 6]} vs {want}")
check(picoseconds(1) == 108507 and picoseconds(9) == 976563 and picoseconds(9216000) == 10**12,
      "hand-computed picoseconds")

# ---- 3. an injected edge: handler in service, IFF1
inj_vcd, inj_trace = OUT / "iceman-inject.vcd", OUT / "iceman-inject.jsonl"
# Seed 2: the default profile's hand placement there leaves no second PIO
# request pending at the RETI (with one, as under thesis-1997, the handler
# is accepted again at the RETI's tick and in_pio_a never falls).
run("solo", ICEMAN, "--seconds", "3", "--seed", "2", "--inject", "A:edge_fore@2s",
    "--trace", str(inj_trace), "--vcd", str(inj_vcd))
trace = read_trace(inj_trace)
accepted = next(r["t"] for r in trace if r["type"] == "interrupt_accepted")
returned = next(r["t"] for r in trace if r["type"] == "interrupt_returned")
ei = next(r["t"] for r in trace if r["type"] == "iff1" and r["t"] > accepted and r["enabled"])
_, changes = parse_vcd(inj_vcd.read_text())
pio = [(time, value) for time, name, value in changes if name == "A_in_pio_a"]
iff = [(time, value) for time, name, value in changes if name == "A_iff1"]
check(pio[0] == (0, "0") and pio[1] == (picoseconds(accepted), "1"),
      f"in_pio_a rises at acceptance: {pio[:3]}")
check(pio[2] == (picoseconds(returned), "0"), f"in_pio_a falls at RETI: {pio[:3]}")
check((picoseconds(accepted), "0") in iff and (picoseconds(ei), "1") in iff,
      "IFF1 low from acceptance to the handler's EI()")

# ---- 4. a match: two scopes; every VCD the suite writes through vcd2fst
match_vcd = OUT / "match.vcd"
run("match", ICEMAN, FIG92, "--seconds", "30", "--vcd", str(match_vcd))
names, _ = parse_vcd(match_vcd.read_text())
check({"A_txd", "B_txd", "A_iff1", "B_left_cmd", "A_gun1_solenoid"} <= set(names.values()),
      f"signals of both robots: {sorted(names.values())[:8]}...")
for vcd in (solo_vcd, inj_vcd, match_vcd):
    fst_round_trip(vcd)

# ---- 5. GTKWave itself (under Xvfb) opens the match's VCD: every signal,
# and the run's 30 s exactly as its last time.
script = OUT / "gtkwave.tcl"
script.write_text("set n [gtkwave::getNumFacs]\nputs \"facs: $n\"\n"
                  "puts \"max: [gtkwave::getMaxTime]\"\ngtkwave::/File/Quit\n")
gw = subprocess.run(["xvfb-run", "-a", "gtkwave", "-S", str(script), str(match_vcd)],
                    capture_output=True, text=True, timeout=300)
report = gw.stdout + gw.stderr
check(f"facs: {len(names)}" in report, f"GTKWave lists {len(names)} signals: {report[-500:]}")
check(f"max: {picoseconds(30 * TICKS_PER_SECOND)}" in report,
      f"GTKWave's last time is the run's end (30 s): {report[-500:]}")

if failures:
    sys.exit(f"{len(failures)} check(s) failed")
print("vcd_test: all checks passed")
