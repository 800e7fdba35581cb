#!/usr/bin/env python3
"""simbot debug --batch on programs written for these checks (issue 38):
the debugger runs nothing it was not asked to, blames the right writer,
and treats watchpoints as breakpoints, in both directions.

Every expected tick and value below is worked out by hand from the
listings (`simbot compile --disasm`: each instruction's T-states) and
from the programs' text, in the comments beside each check; a stop whose
absolute tick is not worked out (an edge handler's entry) is the origin
the others are counted from.

Usage: debug_rules_test.py SIMBOT SOURCE_DIR
"""
import re
import subprocess
import sys
import tempfile

SIMBOT, SOURCE = sys.argv[1], sys.argv[2]
failures = []


def check(condition, message):
    if not condition:
        failures.append(message)


def session(programs, script, *run, status=0):
    """Each command of `script` and its answer. `status`: the exit status
    expected (1 when a command of the script is refused)."""
    with tempfile.NamedTemporaryFile("w", suffix=".gdb", delete=False) as f:
        f.write(script)
    out = subprocess.run([SIMBOT, "debug", *programs, *run, "--batch", f.name], cwd=SOURCE,
                         capture_output=True, text=True, timeout=300)
    check(out.returncode == status, f"exit status {out.returncode}: {out.stderr[-1000:]}")
    # The answer to each command: the text between its echo and the next.
    parts = re.split(r"^\(simbot\) (.*)$", out.stdout, flags=re.M)
    return [(parts[i], parts[i + 1]) for i in range(1, len(parts) - 1, 2)]


def stop(answer):
    """(robot, tick, function, line) of the location an answer ends at."""
    m = re.findall(r"^([AB]) at tick (\d+) \([\d.]+ s\): (\S+)\(.*?\) at \S+:(\d+)", answer, re.M)
    return (m[-1][0], int(m[-1][1]), m[-1][2], int(m[-1][3])) if m else None


def value(answer):
    m = re.search(r"= (-?\d+)", answer)
    return int(m.group(1)) if m else None


# ---- 1. Switching the held robot runs nothing -------------------------------
#
# tests/debug/pacer.dc (A): CALL main 18, DBG (line 7) 68, then each pass of
# the loop from tick 86 + 224 k: DBG 68, INCGW a 39 (line 8), DBG 68,
# INCGW b 39 (line 9), JMP 10 = 224. Line 9 starts 107 into a pass.
# `ignore 1 2` then `continue`: the third pass (k = 2) stops at
# 86 + 448 + 107 = 641 with a = 3, b = 2.
# tests/debug/walker.dc (B): CALL 18, DBG 68, then passes from 86 + 175 j:
# DBG 68 (line 8), LDGW 29, PUSHW 22, ADDW 18, STGW 28, JMP 10 = 175.
# At A's stop B stands at its first boundary at or after 641: pass j = 3
# starts at 611, its boundaries are 611, 679, ...: B at 679 (its LDGW, line
# 8), c = 3 * 3 = 9. Moving the hold back and forth six times leaves both
# exactly there, and breakpoint 1 hit 3 times.
# `continue` (A held) then meets B's breakpoint at the start of B's pass 4:
# 86 + 700 = 786, c = 12; the match holds B there and brings A to its first
# boundary at or after 786: A's pass 3 starts at 758, its next boundary is
# 758 + 68 = 826 (INCGW a, line 8) with a = 3, b = 3. Breakpoint 1 is not
# passed on the way (A's line 9 in pass 3 is at 865).
answers = session(["tests/debug/pacer.dc", "tests/debug/walker.dc"], """\
break 9
ignore 1 2
continue
break B:8
robot B
print c
robot A
print a
print b
robot B
robot A
robot B
robot A
robot B
robot A
print a
print b
info breakpoints
continue
print c
robot A
print a
print b
robot B
""")
got = {}
holds = []
for command, answer in answers:
    if command.startswith("robot") or command == "continue":
        holds.append(stop(answer))
    if command.startswith("print"):
        got.setdefault(command, []).append(value(answer))
    if command == "info breakpoints":
        check("pacer.dc:9 in main() (robot A), hit 3 times" in answer,
              f"breakpoint 1 should have 3 hits after the switches: {answer}")
        check("walker.dc:8 in main() (robot B)\n" in answer, f"B's breakpoint hit: {answer}")
check(holds[:9] == [("A", 641, "main", 9)] + [("B", 679, "main", 8), ("A", 641, "main", 9)] * 4,
      f"switching moved a robot: {holds[:9]}")
check(holds[9:] == [("B", 786, "main", 8), ("A", 826, "main", 8), ("B", 786, "main", 8)],
      f"after continue: {holds[9:]}")
check(got.get("print a") == [3, 3, 3] and got.get("print b") == [2, 2, 3],
      f"A's counters: a {got.get('print a')} b {got.get('print b')}")
check(got.get("print c") == [9, 12], f"B's counter: {got.get('print c')}")

# ---- 5. A watchpoint on the robot not held ----------------------------------
#
# `watch B:c if c == 30` with A held: B's c reaches 30 at the STGW of its
# pass j = 9 (3 a pass), which ends 165 into the pass (DBG 68, LDGW 29,
# PUSHW 22, ADDW 18, STGW 28): 86 + 9 * 175 + 165 = 1,826, where B stands
# before its JMP (line 7). The match then holds B there.
answers = dict(enumerate(session(["tests/debug/pacer.dc", "tests/debug/walker.dc"], """\
watch B:c if c == 30
continue
info breakpoints
""", "--seconds", "1")))
check("Watchpoint 1: c (now 0) if c == 30" in answers[0][1], f"watch B:c: {answers[0][1]}")
check(re.search(r"Watchpoint 1: written by line 8 in main\(\)\nOld value = 27\nNew value = 30",
                answers[1][1]) and stop(answers[1][1]) == ("B", 1826, "main", 7),
      f"B's watchpoint: {answers[1][1]}")
check("B: c (now 30) if c == 30, hit 1 time" in answers[2][1], f"info: {answers[2][1]}")

# ---- 3. Writers, waiting bytes, and going back over them ---------------------
#
# tests/debug/noei.dc, an edge injected at 1 s. E = the handler's first
# body instruction (the `break edge` stop). From there (listing T-states):
#   line 24: DBG 68, INCGW 39; line 25: DBG 68, PUSHW 22, PUSHW 22,
#   strcpy 57 + 36 * 9 = 381 ("crgrcrgr" and its NUL), POP 10; line 26:
#   DBG 68, CALL 18; platform() line 15: DBG 68, PUSHW 22, STGB 29
# so `cc = sizeof(buf)` (0 -> 9, line 15, inside the handler) is seen at
# W = E + 815. Then line 16: DBG 68, PUSHW 22, PUSHW 22, outport 67
# = 179; line 17: DBG 68, PUSHW 22, PUSHW 22 = 112, then the LIB
# ser_send_z1 at W + 291, 189 T-states: its effect (the library takes
# buf[0], cc 9 -> 8) at T0 = W + 480, where the watchpoint stops, after it.
# The byte goes to the shift register and the port requests the transmit
# interrupt, but the handler never called EI(): 8 bytes wait, and `info
# arena` says why. Nothing changes cc until the handler's RETI (line 29,
# tick Q); the request is accepted right after it, at R = Q + the RETI's
# T-states (the listing's), and the service (S T-states: the trace's
# serial_isr record) takes byte 1 (cc 8 -> 7), blamed on the service
# accepted at R while line 44 of main() ran (the instruction the edge
# interrupted: the backtrace at E). The port's data register is empty again
# at once (the shift register was idle), so the service runs again at
# R + S (cc 7 -> 6), the robot standing at R + 2S.
# Going back: the last change stops before the service that made it, at
# R + S (6 -> 7 read backwards), the one before at R (7 -> 8), then
# breakpoint 3 at Q; past it the send: before the LIB, at W + 291 (8 -> 9).
# That is the middle of line 17: reverse-step goes to its start,
# W + 179, then to the start of line 16, W.
listing = subprocess.run([SIMBOT, "compile", "tests/debug/noei.dc", "--disasm"], cwd=SOURCE,
                         capture_output=True, text=True).stdout
reti = int(re.search(r"^\s+[0-9a-f]{4}\s+(\d+)\s+RETI", listing, re.M).group(1))
with tempfile.TemporaryDirectory() as work:
    subprocess.run([SIMBOT, "solo", "tests/debug/noei.dc", "--seconds", "1.1", "--inject",
                    "A:edge_fore@1s", "--trace", work + "/t.jsonl"], cwd=SOURCE,
                   capture_output=True, check=True)
    isr = re.search(r'"end_t":(\d+),"robot":"A","t":(\d+),[^\n]*"serial_isr"',
                    open(work + "/t.jsonl").read())
    service = int(isr.group(1)) - int(isr.group(2))
answers = dict(enumerate(session(["tests/debug/noei.dc"], """\
break edge
continue
backtrace
watch cc
continue
continue
info arena
break 29
continue
continue
info arena
continue
info breakpoints
reverse-continue
reverse-continue
reverse-continue
delete 3
reverse-continue
reverse-step
reverse-step
""", "--seconds", "2", "--inject", "A:edge_fore@1s")))
E = stop(answers[1][1])[1]
W, T0 = E + 815, E + 1295
interrupted = re.search(r"#1\s+main\(\) at noei.dc:(\d+) \[interrupted here\]", answers[2][1])
check(interrupted is not None, f"the edge did not interrupt main(): {answers[2][1]}")
line = interrupted.group(1) if interrupted else "?"
wp = re.compile(r"Watchpoint 2: written by (.*)\nOld value = (\d+)[^\n]*\nNew value = (\d+)")


def watch_stop(k, writer, old, new, where):
    answer = answers[k][1]
    m = wp.search(answer)
    check(m is not None and (m.group(1), int(m.group(2)), int(m.group(3))) == (writer, old, new),
          f"{answers[k][0]} (#{k}): expected {writer!r} {old} -> {new}: {answer}")
    check(stop(answer) == where, f"{answers[k][0]} (#{k}): at {stop(answer)}, expected {where}")


watch_stop(4, "line 15 in platform() [in interrupt handler edge()]", 0, 9, ("A", W, "platform", 16))
watch_stop(5, "line 17 in platform() [in interrupt handler edge()]", 9, 8, ("A", T0, "platform", 18))
check("8 bytes waiting" in answers[6][1] and "handler edge() is in service and has not called "
      "EI()" in answers[6][1], f"info arena in the handler: {answers[6][1]}")
Q = stop(answers[8][1])[1]
check(stop(answers[8][1])[2:] == ("edge", 29), f"breakpoint 3: {answers[8][1]}")
R = Q + reti
service_text = "the serial library's transmit interrupt (serial_tx), accepted at tick {} during " \
               "line {} in main()"
watch_stop(9, service_text.format(R, line), 8, 7, ("A", R + service, "main", int(line)))
check("7 bytes waiting" in answers[10][1] and "pending, accepted at the next boundary"
      in answers[10][1], f"info arena after RETI: {answers[10][1]}")
watch_stop(11, service_text.format(R + service, line), 7, 6, ("A", R + 2 * service, "main",
                                                                int(line)))
check("last written by " + service_text.format(R + service, line) in answers[12][1],
      f"info breakpoints: {answers[12][1]}")
backwards = " (going backwards: stopped before that write)"
watch_stop(13, service_text.format(R + service, line) + backwards, 6, 7,
           ("A", R + service, "main", int(line)))
watch_stop(14, service_text.format(R, line) + backwards, 7, 8, ("A", R, "main", int(line)))
check("Breakpoint 3." in answers[15][1] and stop(answers[15][1]) == ("A", Q, "edge", 29),
      f"reverse-continue to breakpoint 3: {answers[15][1]}")
watch_stop(17, "line 17 in platform() [in interrupt handler edge()]" + backwards, 8, 9,
           ("A", W + 291, "platform", 17))
check(stop(answers[18][1]) == ("A", W + 179, "platform", 17),
      f"reverse-step from the middle of line 17: {answers[18][1]}")
check(stop(answers[19][1]) == ("A", W, "platform", 16), f"reverse-step again: {answers[19][1]}")

# ---- 4. Watchpoints take the breakpoints' commands ---------------------------
#
# The handler's loop (lines 27-28) adds one to `waited` per pass of
# LDGW 29, PUSHW 22, LTW 59 (true), JZ 25 (not taken), DBG 68, INCGW 39,
# INCGW 39, JMP 10 = 291 T-states; main() keeps `waited` at 0 until then.
# `watch waited if waited == 1000` stops at 999 -> 1000 (tick X). With the
# condition `waited % 500 == 0` and one hit ignored, `continue` passes 1500
# and stops at 2000, 1000 passes later: X + 291,000. Disabled, nothing stops
# the match (2 s); reverse-continue goes back to breakpoint 1 (its second
# hit). Enabled again, it stops at 500: X - 145,500. Its hits: 1000, 1500
# (ignored), 2000, 500 = 4.
answers = dict(enumerate(session(["tests/debug/noei.dc"], """\
break edge
continue
watch waited if waited == 1000
continue
condition 2 waited % 500 == 0
ignore 2 1
continue
disable 2
continue
reverse-continue
enable 2
continue
info breakpoints
delete 2
info breakpoints
rwatch waited
""", "--seconds", "2", "--inject", "A:edge_fore@1s", status=1)))
check("Watchpoint 2: waited (now 0) if waited == 1000" in answers[2][1], f"watch: {answers[2][1]}")
X = stop(answers[3][1])[1]
loop = "line 28 in edge() [interrupt handler]"
watch_stop(3, loop, 999, 1000, ("A", X, "edge", 27))
watch_stop(6, loop, 1999, 2000, ("A", X + 291000, "edge", 27))
check("The match is over at tick 18432000" in answers[8][1], f"disabled: {answers[8][1]}")
check("Breakpoint 1." in answers[9][1] and stop(answers[9][1]) == stop(answers[1][1]),
      f"reverse-continue past a disabled watchpoint: {answers[9][1]}")
watch_stop(11, loop, 499, 500, ("A", X - 145500, "edge", 27))
check("waited (now 500) if waited % 500 == 0, hit 4 times" in answers[12][1]
      and "edge() (robot A), hit 2 times" in answers[12][1], f"info: {answers[12][1]}")
check("watchpoint" not in answers[14][1], f"delete 2: {answers[14][1]}")
check(answers[15][1].strip().startswith("error: rwatch: not supported"),
      f"rwatch: {answers[15][1]}")

# ---- A time inside a library call --------------------------------------------
#
# `goto` T0 (the send's last tick, 9,217,428 in the session above:
# E = 9,216,133 + 1,295) stands where the call's effect is still due (the
# events of that tick come first): cc is 9 there and the location says so;
# one stepi makes the effect happen and stands at the boundary after the
# call, cc 8, the same tick.
answers = dict(enumerate(session(["tests/debug/noei.dc"], f"""\
goto {T0}
print cc
stepi
print cc
""", "--seconds", "2", "--inject", "A:edge_fore@1s")))
check(stop(answers[0][1]) == ("A", T0, "platform", 17) and "effect is due" in answers[0][1],
      f"goto T0: {answers[0][1]}")
check(value(answers[1][1]) == 9 and value(answers[3][1]) == 8, "cc before and after the effect")
check(stop(answers[2][1]) == ("A", T0, "platform", 18), f"stepi over the effect: {answers[2][1]}")

# ---- 6. A struct assignment an interrupt tears --------------------------------
#
# tests/debug/torn.dc: main() runs straight to `latest = fresh;` (line 27):
# CALL main 18, six outport lines of DBG 68, PUSHW 22, PUSHW 22, LIB 67 =
# 179, three stores of DBG 68, PUSHW 22, STGW 28 = 118: line 27 starts at
# 18 + 6 * 179 + 3 * 118 = 1,446; its DBG and two PUSHWs bring the COPY to
# 1,558. The COPY (121 T-states for 6 bytes) is LDIR's: POP, EX DE,HL,
# LD BC,6 (9 + 3 + 9 = 21, 23 with the refresh), then a boundary after each
# byte, 14 T-states a repeat (15 with the refresh): 1,581 (no byte yet),
# 1,596, 1,611, 1,626, 1,641 (four bytes: x and y copied, heading not).
# An edge requested at tick 1,612 is accepted at the next boundary, 1,626,
# with three bytes copied: x = 0x1111, y's low byte 0x22 only. The handler
# (acceptance 99, DBG 68, PUSHW 22, PUSHW 22, COPY 121) reaches its RETI at
# 1,626 + 332 = 1,958 with seen = {0x1111, 0x0022, 0}: half a fix, and the
# backtrace names line 27 as the one interrupted.
answers = dict(enumerate(session(["tests/debug/torn.dc"], """\
break 27
continue
stepi
stepi
stepi
stepi
stepi
stepi
stepi
stepi
print/x latest
""", "--seconds", "0.01")))
ticks = [stop(answers[k][1])[1] for k in range(1, 10)]
check(ticks == [1446, 1514, 1536, 1558, 1581, 1596, 1611, 1626, 1641],
      f"the copy's boundaries: {ticks}")
check(all(stop(answers[k][1])[3] == 27 for k in range(5, 10)), "inside the COPY: line 27")
check("{x = 0x1111, y = 0x2222, heading = 0x0}" in answers[10][1], f"4 bytes: {answers[10][1]}")
answers = dict(enumerate(session(["tests/debug/torn.dc"], """\
break 14
continue
print/x seen
backtrace
""", "--seconds", "0.01", "--inject", "A:edge_fore@1612t")))
check(stop(answers[1][1]) == ("A", 1958, "edge", 14), f"the handler's RETI: {answers[1][1]}")
check("seen (struct fix) = {x = 0x1111, y = 0x22, heading = 0x0}" in answers[2][1],
      f"the handler saw 3 bytes: {answers[2][1]}")
check("#1  main() at torn.dc:27 [interrupted here]" in answers[3][1], f"backtrace: {answers[3][1]}")

# ---- 8. The controller's CPU revision in a step ---------------------------------
#
# The handler's RETI, stepped: the epilogue's sequence with the default
# profile's Z80180 (RETI 22 T-states) is 94 calibrated; a profile that
# says "z8s180" (RETI 12) charges 10 fewer plus the one refresh cycle
# those 10 would have stretched (2 T-states every 20; docs/cycle-model.md):
# 83, from tick 1,958 to 2,052 and to 2,041.
with tempfile.TemporaryDirectory() as work:
    default = open(SOURCE + "/profiles/default.toml").read()
    check('cpu           = { value = "z80180"' in default, "the default profile's cpu line")
    with open(work + "/z8s180.toml", "w") as f:
        f.write(default.replace('cpu           = { value = "z80180"',
                                'cpu           = { value = "z8s180"'))
    for profile, reti in (("default", 94), (work + "/z8s180.toml", 83)):
        answers = dict(enumerate(session(["tests/debug/torn.dc"], "break 14\ncontinue\nstepi\n",
                                         "--seconds", "0.01", "--inject", "A:edge_fore@1612t",
                                         "--profile", profile)))
        check(f"000f  RETI       [{reti} T-states]" in answers[2][1] and
              f"clock   {1958 + reti} " in answers[2][1], f"RETI on {profile}: {answers[2][1]}")

# ---- 7. Counts and numbers the user writes ----------------------------------
#
# The audit's reproducers (each was signed overflow, UB, or a wrong value):
# every count is 1 to 2^31 - 1, every number a breakpoint, display, frame
# or line that exists; each refusal is one line and the session goes on.
# noei.dc has 46 lines and one frame at the start; an ignore count of
# 2^31 - 1 is taken. A script or a pipe with a refused command exits 1.
expected = {
    "stepi 2147483648": "error: a count is 1 to 2147483647: '2147483648' is out of range",
    "up 2147483647": "error: no frame 2147483647 (frames 0 to 0)",
    "list 2147483647": "error: a line number is 1 to 46: '2147483647' is out of range",
    "ignore 1 99999999999":
        "error: an ignore count is 0 to 2147483647: '99999999999' is out of range",
    "frame 4294967296": "error: a frame number is 0 to 2147483647: '4294967296' is out of range",
    "ignore 1 2147483647": "Will ignore the next 2147483647 crossings of breakpoint 1.",
    "delete 99999999999999999999999": "error: a breakpoint number is 1 to 2147483647: "
                                      "'99999999999999999999999' is out of range",
    "undisplay -1": "error: a display number is 1 to 2147483647: '-1' is out of range",
    "continue 0": "error: a count is 1 to 2147483647: '0' is out of range",
    "print buf[9223372036854775807]": "error: ",
}
answers = session(["tests/debug/noei.dc"], "break 17\n" + "\n".join(expected) + "\n", status=1)
for command, answer in answers[1:]:
    check(answer.strip().startswith(expected[command]) and len(answer.strip().splitlines()) == 1,
          f"{command}: {answer.strip()!r}")
piped = subprocess.run([SIMBOT, "debug", "tests/debug/pacer.dc"], input="stepi 2147483648\n",
                       cwd=SOURCE, capture_output=True, text=True, timeout=60)
check(piped.returncode == 1, f"piped commands with an error: exit {piped.returncode}")

for f in failures:
    print("FAIL:", f)
if failures:
    print(f"debug rules: {len(failures)} failures")
    sys.exit(1)
print("debug rules: all checks hold")
