#!/usr/bin/env python3
"""The debugger's expressions against an independent oracle: a host C
compiler doing 16-bit int arithmetic by emulation.

Usage: debug_oracle_test.py SIMBOT CXX WORKDIR [--seed N] [--count N]

A seeded generator makes COUNT random C expressions over globals of every
arithmetic type (char, signed char, int, unsigned int, long, unsigned long,
float) and constants of each kind Dynamic C types differently (32767 an
int, 40000 a long, 0xFFFF an unsigned int, 'A', 7u, 5L, 2.5). For each it
knows the C type C89's rules give with the robot's sizes, and writes two
programs:

  - oracle.cpp, compiled by the host compiler CXX: every operation spelled
    out with <cstdint> types as the robot's sizes make it, e.g. an int
    `a * b` as (int16_t)((int32_t)a * (int32_t)b), a long's in int64_t, an
    unsigned long's in uint64_t, a float's in float; it prints each value;
  - robot.dc, compiled by simbot: the same globals with the same values,
    and main storing each expression into a global of its type.

simbot debug stops robot.dc after main's last assignment and prints every
expression (the debugger's evaluation, inspect/) and every stored result
(the compiler's code on the VM). Each printed value must equal the oracle's
(floats bit for bit as IEEE singles), and each printed type the generator's.

The generator keeps to what C defines on the host: no division by zero (an
integer divisor is `(E | 1)`, a float one a nonzero constant), shift
counts below the promoted type's width, no float converted to an integer.
Those corners (shifts by 16 or more, 1/0, float to int) have hand-worked
expectations in tests/debug/expressions.gdb and tests/programs/fold_runtime.dc.
"""
import os
import random
import re
import struct
import subprocess
import sys

SIMBOT, CXX, WORK = sys.argv[1], sys.argv[2], sys.argv[3]
args = sys.argv[4:]
SEED = int(args[args.index("--seed") + 1]) if "--seed" in args else 16
COUNT = int(args[args.index("--count") + 1]) if "--count" in args else 300

# C type -> (size, signed, host type, the host type an operation is done in)
TYPES = {
    "char": (1, False, "uint8_t", "int32_t"),
    "signed char": (1, True, "int8_t", "int32_t"),
    "int": (2, True, "int16_t", "int32_t"),
    "unsigned int": (2, False, "uint16_t", "uint32_t"),
    "long": (4, True, "int32_t", "int64_t"),
    "unsigned long": (4, False, "uint32_t", "uint64_t"),
    "float": (4, True, "float", "float"),
}
INTEGER = [t for t in TYPES if t != "float"]


def promote(t):
    return "int" if t in ("char", "signed char") else t


def common(a, b):
    """C89's usual arithmetic conversions with a 16-bit int and a 32-bit long."""
    a, b = promote(a), promote(b)
    for t in ("float", "unsigned long", "long", "unsigned int"):
        if t in (a, b):
            return t
    return "int"


def wrap(value, t):
    size, signed = TYPES[t][0], TYPES[t][1]
    value &= (1 << (8 * size)) - 1
    if signed and value >= 1 << (8 * size - 1):
        value -= 1 << (8 * size)
    return value


class Expr:
    """A generated expression: its C text, its emulation on the host and its type."""

    def __init__(self, text, host, ctype, prec):
        self.text, self.host, self.ctype, self.prec = text, host, ctype, prec


def conv(e, to):
    """The host code of e converted to type `to` (never float to integer)."""
    if e.ctype == to:
        return e.host
    return f"(({TYPES[to][2]})({e.host}))"


# Precedence for minimal parentheses (higher binds tighter), as C's.
PREC = {"||": 1, "&&": 2, "|": 3, "^": 4, "&": 5, "==": 6, "!=": 6, "<": 7, "<=": 7, ">": 7,
        ">=": 7, "<<": 8, ">>": 8, "+": 9, "-": 9, "*": 10, "/": 10, "%": 10}
UNARY, PRIMARY, CONDITIONAL = 11, 12, 0


def paren(e, need):
    return e.text if e.prec >= need else f"({e.text})"


class Generator:
    def __init__(self, rng):
        self.rng = rng
        self.narrow = False  # int and char operands alone, where 16 bits wrap
        self.variables = {}  # name -> (type, value)
        counts = {"char": 2, "signed char": 1, "int": 3, "unsigned int": 2, "long": 2,
                  "unsigned long": 2, "float": 2}
        prefixes = {"char": "c", "signed char": "s", "int": "i", "unsigned int": "u", "long": "l",
                    "unsigned long": "ul", "float": "f"}
        for t, n in counts.items():
            for k in range(1, n + 1):
                self.variables[f"{prefixes[t]}{k}"] = (t, self.initial(t, k))

    def initial(self, t, k):
        r = self.rng
        if t == "float":
            return r.randint(-8000, 8000) / 8  # exact in a float
        size, signed = TYPES[t][0], TYPES[t][1]
        lo = -(1 << (8 * size - 1)) if signed else 0
        hi = (1 << (8 * size - 1)) - 1 if signed else (1 << (8 * size)) - 1
        # The first of each type at an extreme, the others anywhere or small.
        if k == 1:
            return r.choice([lo, hi, lo + 1, hi - 1, 0, -1 if signed else 1])
        return r.randint(lo, hi) if r.random() < 0.7 else r.randint(-100 if signed else 0, 100)

    def constant(self):
        r = self.rng
        kind = r.choice(["small"] * 5 + ["decimal", "hex", "char", "u", "L", "UL", "float"])
        if kind == "small":
            v = r.randint(0, 1000)
            return Expr(str(v), f"((int16_t){v})", "int", PRIMARY)
        if kind == "decimal":
            v = r.choice([r.randint(0, 32767), 32767, 32768, r.randint(32768, 2147483647),
                          2147483648, 4000000000])
            t = "int" if v <= 0x7FFF else "long" if v <= 0x7FFFFFFF else "unsigned long"
        elif kind == "hex":
            v = r.choice([0x7FFF, 0x8000, 0xFFFF, 0x10000, r.randint(0, 0xFFFF), 0xFFFFFFFF])
            t = ("int" if v <= 0x7FFF else "unsigned int" if v <= 0xFFFF else
                 "long" if v <= 0x7FFFFFFF else "unsigned long")
            return Expr(f"0x{v:X}", f"(({TYPES[t][2]}){v}u)", t, PRIMARY)
        elif kind == "char":
            c = r.choice("AZaz09 ~")
            return Expr(f"'{c}'", f"((int16_t){ord(c)})", "int", PRIMARY)
        elif kind == "u":
            v = r.choice([r.randint(0, 0xFFFF), 0x10000 + r.randint(0, 1000)])
            t = "unsigned int" if v <= 0xFFFF else "unsigned long"
            return Expr(f"{v}u", f"(({TYPES[t][2]}){v}u)", t, PRIMARY)
        elif kind == "L":
            v = r.randint(0, 2147483647)
            return Expr(f"{v}L", f"((int32_t){v})", "long", PRIMARY)
        elif kind == "UL":
            v = r.randint(0, 0xFFFFFFFF)
            return Expr(f"{v}UL", f"((uint32_t){v}u)", "unsigned long", PRIMARY)
        else:
            v = r.randint(-400, 400) / 4
            return Expr(f"{abs(v)}", f"((float){abs(v)})", "float", PRIMARY)
        return Expr(str(v), f"(({TYPES[t][2]}){v}u)", t, PRIMARY)

    def leaf(self):
        r = self.rng
        if self.narrow:
            if r.random() < 0.75:
                name = r.choice([n for n in sorted(self.variables)
                                 if self.variables[n][0] in ("int", "char", "signed char")])
                return Expr(name, name, self.variables[name][0], PRIMARY)
            v = r.randint(0, 1000)
            return Expr(str(v), f"((int16_t){v})", "int", PRIMARY)
        if r.random() < 0.6:
            # Half of them an int or a char, whose arithmetic stays in 16 bits.
            names = sorted(self.variables)
            if r.random() < 0.5:
                names = [n for n in names if self.variables[n][0] in ("int", "char", "signed char")]
            name = r.choice(names)
            return Expr(name, name, self.variables[name][0], PRIMARY)
        if r.random() < 0.08:
            name = r.choice(sorted(self.variables))
            t = self.variables[name][0]
            return Expr(f"sizeof({name})", f"((uint16_t){TYPES[t][0]})", "unsigned int", PRIMARY)
        return self.constant()

    def expr(self, depth):
        r = self.rng
        if depth == 0 or r.random() < 0.2:
            return self.leaf()
        choice = r.random()
        if choice < 0.55:
            return self.binary(depth)
        if choice < 0.75:
            return self.unary(depth)
        if choice < 0.88:
            return self.cast(depth)
        return self.conditional(depth)

    def binary(self, depth):
        r = self.rng
        # Arithmetic more often than the rest: that is where an int wraps.
        op = r.choice(["+", "-", "*", "*", "<<"] if self.narrow else
                      list(PREC) + ["+", "-", "*", "*", "*", "-"])
        a = self.expr(depth - 1)
        b = self.expr(depth - 1)
        if op in ("%", "&", "|", "^", "<<", ">>"):
            # integer operands only
            if a.ctype == "float" or b.ctype == "float":
                return self.binary(depth)
        if op in ("<<", ">>"):
            t = promote(a.ctype)
            bits = 8 * TYPES[t][0]
            n = r.randint(0, bits - 1)
            text = f"{paren(a, PREC[op])} {op} {n}"
            x = conv(a, t)
            if op == "<<":
                unsigned = {"int": "uint16_t", "unsigned int": "uint16_t", "long": "uint32_t",
                            "unsigned long": "uint32_t"}[t]
                host = f"(({TYPES[t][2]})({unsigned})((uint64_t)({unsigned})({x}) << {n}))"
            else:
                host = f"(({TYPES[t][2]})(({TYPES[t][2]})({x}) >> {n}))"
            return Expr(text, host, t, PREC[op])
        if op in ("/", "%"):
            t = common(a.ctype, b.ctype)
            if t == "float":
                d = r.choice(["2.5", "0.5", "4", "1.25"])
                b = Expr(d, f"((float){d})", "float" if "." in d else "int", PRIMARY)
            else:
                # An odd divisor is never zero.
                b = Expr(f"({paren(b, PREC['|'])} | 1)",
                         f"(({TYPES[promote(b.ctype)][2]})(({b.host}) | 1))", promote(b.ctype),
                         PRIMARY)
        if op in ("&&", "||"):
            host = f"((int16_t)(({a.host}) {op} ({b.host})))"
            return Expr(f"{paren(a, PREC[op])} {op} {paren(b, PREC[op] + 1)}", host, "int",
                        PREC[op])
        t = common(a.ctype, b.ctype)
        x, y = conv(a, t), conv(b, t)
        text = f"{paren(a, PREC[op])} {op} {paren(b, PREC[op] + 1)}"
        if op in ("==", "!=", "<", "<=", ">", ">="):
            return Expr(text, f"((int16_t)(({x}) {op} ({y})))", "int", PREC[op])
        wide = TYPES[t][3]
        if t == "float":
            return Expr(text, f"((float)(({x}) {op} ({y})))", t, PREC[op])
        return Expr(text, f"(({TYPES[t][2]})(({wide})({x}) {op} ({wide})({y})))", t, PREC[op])

    def unary(self, depth):
        r = self.rng
        op = r.choice(["-", "+", "~"] if self.narrow else ["-", "+", "~", "!"])
        a = self.expr(depth - 1)
        if op == "~" and a.ctype == "float":
            op = "-"
        text = f"{op}{paren(a, UNARY)}"
        if text.startswith(op * 2):  # not -- or ++
            text = f"{op} {paren(a, UNARY)}"
        if op == "!":
            return Expr(text, f"((int16_t)!({a.host}))", "int", UNARY)
        t = promote(a.ctype)
        x = conv(a, t)
        if t == "float":
            return Expr(text, f"((float)({op}({x})))", t, UNARY)
        return Expr(text, f"(({TYPES[t][2]})({op}(int64_t)({x})))", t, UNARY)

    def cast(self, depth):
        r = self.rng
        a = self.expr(depth - 1)
        targets = list(TYPES) if a.ctype != "float" else ["float"]
        if self.narrow:
            targets = ["int", "char", "signed char"]
        t = r.choice(targets)
        if a.ctype == "float" and t != "float":
            t = "float"
        return Expr(f"({t}) {paren(a, UNARY)}", conv(a, t), t, UNARY)

    def conditional(self, depth):
        c, a, b = self.expr(depth - 1), self.expr(depth - 1), self.expr(depth - 1)
        t = common(a.ctype, b.ctype)
        text = f"{paren(c, PREC['||'])} ? {a.text} : {paren(b, CONDITIONAL)}"
        host = f"(({c.host}) ? ({TYPES[t][2]})({conv(a, t)}) : ({TYPES[t][2]})({conv(b, t)}))"
        return Expr(text, host, t, CONDITIONAL)


def c_literal(t, v):
    if t == "float":
        return repr(float(v))
    return str(v) + ("u" if v >= 0 else "")


def main():
    rng = random.Random(SEED)
    g = Generator(rng)
    exprs = []
    while len(exprs) < COUNT:
        # The first third over int and char alone: their 16-bit wrap shows there.
        g.narrow = len(exprs) < COUNT // 3
        e = g.expr(rng.randint(1, 4))
        if e.prec == PRIMARY and e.text in g.variables:
            continue  # a bare variable shows nothing
        exprs.append(e)
    os.makedirs(WORK, exist_ok=True)

    # The oracle.
    lines = ["#include <cstdint>", "#include <cstdio>"]
    for name, (t, v) in g.variables.items():
        lines.append(f"{TYPES[t][2]} {name} = ({TYPES[t][2]}){c_literal(t, v)};")
    lines.append("int main() {")
    for e in exprs:
        if e.ctype == "float":
            lines.append(f'  std::printf("%.9g\\n", (double)({e.host}));')
        else:
            lines.append(f'  std::printf("%lld\\n", (long long)({e.host}));')
    lines.append("  return 0;\n}")
    oracle_src = os.path.join(WORK, "oracle.cpp")
    with open(oracle_src, "w") as f:
        f.write("\n".join(lines) + "\n")
    oracle_bin = os.path.join(WORK, "oracle")
    build = subprocess.run([CXX, "-std=c++17", "-O1", "-ffp-contract=off", "-w", "-o", oracle_bin,
                            oracle_src], capture_output=True, text=True)
    if build.returncode != 0:
        print(f"the oracle does not compile:\n{build.stderr}")
        return 1
    expected = subprocess.run([oracle_bin], capture_output=True, text=True, check=True).stdout.split()

    # The robot's program: the same globals, each expression stored into a global of its type.
    robot = ["/* generated by tests/debug_oracle_test.py */"]
    for name, (t, v) in g.variables.items():
        robot.append(f"{t} {name} = {v};")
    for k, e in enumerate(exprs):
        robot.append(f"{e.ctype} r{k};")
    robot.append("int done;")
    robot.append("main()")
    robot.append("{")
    for k, e in enumerate(exprs):
        robot.append(f"    r{k} = {e.text};")
    robot.append("    done = 1;")
    last = len(robot)
    robot.append("}")
    program = os.path.join(WORK, "robot.dc")
    with open(program, "w") as f:
        f.write("\n".join(robot) + "\n")
    script = [f"break {last}", "continue"]
    script += [f"print {e.text}" for e in exprs]
    script += [f"print r{k}" for k in range(len(exprs))]
    script.append("quit")
    script_path = os.path.join(WORK, "oracle.gdb")
    with open(script_path, "w") as f:
        f.write("\n".join(script) + "\n")
    run = subprocess.run([SIMBOT, "debug", program, "--batch", script_path], capture_output=True,
                         text=True, timeout=120)
    if run.returncode != 0:
        print(f"simbot debug exited {run.returncode}: {run.stderr}")
        return 1

    # Each print's answer is the line after its echo.
    out = run.stdout.splitlines()
    answers = {}
    for i, line in enumerate(out):
        if line.startswith("(simbot) print ") and i + 1 < len(out):
            answers.setdefault(line[len("(simbot) print "):], []).append(out[i + 1])

    def answer(text):
        line = answers[text].pop(0)
        m = re.match(re.escape(text) + r" \((.*?)\) = (\S+)", line)
        return (m.group(1), m.group(2)) if m else (None, line)

    def same(value, want, ctype):
        if ctype == "float":
            try:
                a, b = float(value), float(want.replace("-nan", "nan"))
            except ValueError:
                return False
            if a != a or b != b:
                return a != a and b != b
            return struct.pack("<f", a) == struct.pack("<f", b)
        try:
            return int(value) == int(want)
        except ValueError:
            return False

    failures = []
    for k, e in enumerate(exprs):
        want = expected[k]
        ctype, value = answer(e.text)
        if ctype != e.ctype or not same(value, want, e.ctype):
            failures.append(f"debugger: {e.text}: ({ctype}) {value}, oracle ({e.ctype}) {want}")
    for k, e in enumerate(exprs):
        want = expected[k]
        ctype, value = answer(f"r{k}")
        if not same(value, want, e.ctype):
            failures.append(f"robot: r{k} = {e.text}: {value}, oracle {want}")
    for f in failures[:40]:
        print(f)
    print(f"{len(exprs)} expressions (seed {SEED}): {len(failures)} differ from the oracle")
    return 1 if failures else 0


sys.exit(main())
