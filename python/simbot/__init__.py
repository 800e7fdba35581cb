"""simbot from Python: the CLI's compile, solo, match and bench, and sweeps.

Every call runs the CLI's own C++ code (the _simbot extension), so results
are the CLI's: match(A, B) returns what `simbot match A B --json` prints,
parsed, and the same seed gives the same result. Traces (the CLI's --trace
JSONL records) come back as pandas DataFrames.
"""
import csv
import inspect
import io
import json
import os
import stat
import warnings

from . import _simbot
from ._simbot import Error

__all__ = ["Error", "compile", "solo", "match", "bench", "read_trace", "trace_frame",
           "MAX_TRACE_BYTES", "MAX_TRACE_LINE_BYTES"]


def compile(path, disasm=False):
    """Compiles a Dynamic C program: {"ok", "diagnostics", "disasm"}."""
    return _simbot.compile(str(path), disasm)


def trace_frame(lines):
    """JSONL trace lines as a DataFrame, one row per record (keys as columns)."""
    import pandas
    return pandas.DataFrame.from_records([json.loads(line) for line in lines])


# The largest trace read_trace reads, and its longest line, as the CLI's
# view and explain (files/files.h, kMaxTraceBytes and kMaxTraceLineBytes):
# 16 GiB and 8 MiB.
MAX_TRACE_BYTES = _simbot.MAX_TRACE_BYTES
MAX_TRACE_LINE_BYTES = _simbot.MAX_TRACE_LINE_BYTES


def read_trace(path):
    """A trace file written with --trace (or trace=...) as a DataFrame.

    The file must be a regular file of at most MAX_TRACE_BYTES (16 GiB);
    anything else (a directory, /dev/zero, a FIFO, which is not waited on)
    raises simbot.Error at once, as the CLI refuses it. A line longer than
    MAX_TRACE_LINE_BYTES (8 MiB) raises simbot.Error naming FILE:LINE once
    that much of it is read, as the CLI's view and explain do."""
    name = os.fspath(path)

    def refuse(problem):
        return Error(f"simbot: read_trace: '{name}': {problem}")

    try:
        # Opened without waiting (a FIFO with no writer), then checked.
        fd = os.open(name, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as e:
        raise refuse(e.strerror or str(e)) from None
    try:
        st = os.fstat(fd)
        if stat.S_ISDIR(st.st_mode):
            raise refuse("it is a directory")
        if not stat.S_ISREG(st.st_mode):
            raise refuse("not a regular file")
        if st.st_size > MAX_TRACE_BYTES:
            raise refuse(f"{st.st_size} bytes is more than the limit of {MAX_TRACE_BYTES}")
        os.set_blocking(fd, True)
        f = os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise
    lines, size, number = [], 0, 0
    with f:
        while True:
            # At most the limit and a byte: a longer line is never held whole.
            line = f.readline(MAX_TRACE_LINE_BYTES + 2)
            if not line:
                break
            number += 1
            if len(line.rstrip(b"\n")) > MAX_TRACE_LINE_BYTES:
                raise Error(f"{name}:{number}: error: a line of more than "
                            f"{MAX_TRACE_LINE_BYTES} bytes: no record of a simbot trace is "
                            "that long")
            size += len(line)  # a file that grows while it is read
            if size > MAX_TRACE_BYTES:
                raise refuse(f"more than the limit of {MAX_TRACE_BYTES} bytes")
            if line.strip():
                lines.append(line.decode("utf-8"))
    return trace_frame(lines)


# The run options, as runs/run_options.def defines them for the command
# line too: [(keyword, kind)], kind "value" (None: not given), "list" or
# "flag". solo's, match's and bench's signatures are made from them.
_RUN_OPTIONS = _simbot.run_options()
_BENCH_OPTIONS = _simbot.bench_options()
_DEFAULTS = {"value": None, "list": (), "flag": False}


def _option(kind, value):
    if kind == "list":
        return [os.fspath(v) for v in value]
    if kind == "flag":
        return bool(value)
    return os.fspath(value) if isinstance(value, os.PathLike) else value


def _signature(options, leading, required=(), trailing=()):
    P = inspect.Parameter
    return inspect.Signature(
        [P(name, P.POSITIONAL_OR_KEYWORD) for name in leading]
        + [P(k, P.POSITIONAL_OR_KEYWORD) for k, _ in options if k in required]
        + [P(k, P.POSITIONAL_OR_KEYWORD, default=_DEFAULTS[kind])
           for k, kind in options if k not in required]
        + [P(name, P.POSITIONAL_OR_KEYWORD, default=False) for name in trailing])


def _play(function, programs, args, kwargs):
    given = function.__signature__.bind(*args, **kwargs).arguments
    keep_trace = bool(given.pop("keep_trace", False))
    kinds = dict(_RUN_OPTIONS)
    options = {k: _option(kinds[k], v) for k, v in given.items() if k in kinds}
    text, lines, found = _simbot.play([os.fspath(p) for p in programs], keep_trace, **options)
    for w in found:
        warnings.warn("simbot: " + w, RuntimeWarning, stacklevel=3)
    result = json.loads(text)
    return (result, trace_frame(lines)) if keep_trace else result


def solo(*args, **kwargs):
    """`simbot solo PROGRAM --json` as a dict; with keep_trace=True,
    (dict, trace DataFrame). The keywords are the command line's options
    (--reload-on-fault is reload_on_fault=True); hw is a hardware file's
    path (at most one)."""
    if isinstance(kwargs.get("hw"), (str, os.PathLike)):
        kwargs["hw"] = [kwargs["hw"]]
    program = solo.__signature__.bind(*args, **kwargs).arguments["program"]
    return _play(solo, [program], args, kwargs)


def match(*args, **kwargs):
    """`simbot match A B --json` as a dict; with keep_trace=True, (dict,
    trace DataFrame). The keywords are the command line's options; hw holds
    "A=FILE" / "B=FILE" as on the command line."""
    given = match.__signature__.bind(*args, **kwargs).arguments
    return _play(match, [given["a"], given["b"]], args, kwargs)


solo.__signature__ = _signature(_RUN_OPTIONS, ["program"], trailing=["keep_trace"])
match.__signature__ = _signature(_RUN_OPTIONS, ["a", "b"], trailing=["keep_trace"])


def _number(text):
    if text == "":
        return None
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def bench(*args, **kwargs):
    """`simbot bench`: {"summary": summary.json's dict, "runs": runs.csv's
    rows as dicts (numbers as numbers, empty fields as None)}. The keywords
    are the command line's options (seconds is a number of seconds or a
    time such as "800ms"; None: the command's default)."""
    given = bench.__signature__.bind(*args, **kwargs).arguments
    programs = given.pop("programs")
    if isinstance(programs, (str, os.PathLike)):
        programs = [programs]
    kinds = dict(_BENCH_OPTIONS)
    options = {k: _option(kinds[k], v) for k, v in given.items()}
    summary, runs = _simbot.bench([os.fspath(p) for p in programs], **options)
    rows = [{k: _number(v) for k, v in row.items()}
            for row in csv.DictReader(io.StringIO(runs, newline=""))]
    return {"summary": json.loads(summary), "runs": rows}


bench.__signature__ = _signature(_BENCH_OPTIONS, ["programs"], required=["family", "seeds"])
