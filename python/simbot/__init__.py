"""simbot from Python: the CLI's compile, solo, match and bench, and sweeps.

Every call runs the CLI's own C++ code (the _simbot extension), so results
are the CLI's: match(A, B) returns what `simbot match A B --json` prints,
parsed, and the same seed gives the same result. Traces (the CLI's --trace
JSONL records) come back as pandas DataFrames.
"""
import csv
import io
import json
import warnings

from . import _simbot
from ._simbot import Error

__all__ = ["Error", "compile", "solo", "match", "bench", "read_trace", "trace_frame"]


def compile(path, disasm=False):
    """Compiles a Dynamic C program: {"ok", "diagnostics", "disasm"}."""
    return _simbot.compile(str(path), disasm)


def trace_frame(lines):
    """JSONL trace lines as a DataFrame, one row per record (keys as columns)."""
    import pandas
    return pandas.DataFrame.from_records([json.loads(line) for line in lines])


def read_trace(path):
    """A trace file written with --trace (or trace=...) as a DataFrame."""
    with open(path, encoding="utf-8") as f:
        return trace_frame([line for line in f if line.strip()])


def _play(programs, seconds, seed, profile, scenario, hw, inject, watch, trace, vcd,
          replay, trace_costate, no_fast_forward, reload_on_fault, keep_trace):
    text, lines, found = _simbot.play(
        [str(p) for p in programs], seconds, seed, profile, str(scenario or ""),
        list(hw), list(inject), list(watch), str(trace or ""), str(vcd or ""),
        str(replay or ""), trace_costate, no_fast_forward, reload_on_fault, keep_trace)
    for w in found:
        warnings.warn("simbot: " + w, RuntimeWarning, stacklevel=3)
    result = json.loads(text)
    return (result, trace_frame(lines)) if keep_trace else result


def solo(program, seconds=None, seed=None, profile=None, scenario=None, hw=(), inject=(),
         watch=(), trace=None, vcd=None, replay=None, trace_costate=False,
         no_fast_forward=False, reload_on_fault=False, keep_trace=False):
    """`simbot solo PROGRAM --json` as a dict; with keep_trace=True,
    (dict, trace DataFrame). hw is a hardware file's path (at most one)."""
    return _play([program], seconds, seed, profile, scenario, [hw] if isinstance(hw, str) else hw,
                 inject, watch, trace, vcd, replay, trace_costate, no_fast_forward,
                 reload_on_fault, keep_trace)


def match(a, b, seconds=None, seed=None, profile=None, scenario=None, hw=(), inject=(),
          watch=(), trace=None, vcd=None, replay=None, trace_costate=False,
          no_fast_forward=False, reload_on_fault=False, keep_trace=False):
    """`simbot match A B --json` as a dict; with keep_trace=True, (dict,
    trace DataFrame). hw holds "A=FILE" / "B=FILE" as on the command line."""
    return _play([a, b], seconds, seed, profile, scenario, hw, inject, watch, trace, vcd, replay,
                 trace_costate, no_fast_forward, reload_on_fault, keep_trace)


def _number(text):
    if text == "":
        return None
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def bench(programs, family, seeds, seconds=60.0, seed=1, profile="default", opponent="",
          threads=0):
    """`simbot bench`: {"summary": summary.json's dict, "runs": runs.csv's
    rows as dicts (numbers as numbers, empty fields as None)}."""
    if isinstance(programs, str):
        programs = [programs]
    summary, runs = _simbot.bench([str(p) for p in programs], family, seeds, float(seconds),
                                  seed, profile, str(opponent), threads)
    rows = [{k: _number(v) for k, v in row.items()}
            for row in csv.DictReader(io.StringIO(runs, newline=""))]
    return {"summary": json.loads(summary), "runs": rows}
