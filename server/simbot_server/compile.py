"""A submission compiled by the simbot executable (`simbot compile`), in a
folder of its own under a name the server chooses: no text a team sends
becomes a path. The compiler's diagnostics name the file as the team named
it (its base name, letters, digits, '.', '_', '-' only; else program.dc)."""
import contextlib
import os
import re
import subprocess
import tempfile

DISK_NAME = "program.dc"
COMPILE_SECONDS = 30  # the compiler's own limits bound its work; this bounds a stuck process
_DIAGNOSTIC = re.compile(r"^(?P<file>.*?):(?P<line>\d+):(?P<col>\d+): (?P<kind>error|warning): ")
_SAFE_NAME = re.compile(r"^[A-Za-z0-9._-]{1,128}$")


def display_name(file_name):
    base = os.path.basename((file_name or "").replace("\\", "/"))
    return base if _SAFE_NAME.fullmatch(base) and base not in (".", "..") else DISK_NAME


class Compiled:
    def __init__(self, ok, errors, warnings):
        self.ok, self.errors, self.warnings = ok, errors, warnings


@contextlib.contextmanager
def written(source):
    """The path of `source` (bytes) written as DISK_NAME in a fresh folder,
    removed with it afterwards: the compiler and the checks read it there."""
    with tempfile.TemporaryDirectory(prefix="simbot-submission-") as folder:
        path = os.path.join(folder, DISK_NAME)
        with open(path, "wb") as f:
            f.write(source)
        yield path


def _nul_byte(path, shown_name):
    """The error for a program's first NUL byte, or None. The compiler
    passes one in a comment, but PostgreSQL's text (where the source is
    kept) cannot hold it, and a program is text."""
    with open(path, "rb") as f:
        source = f.read()
    at = source.find(b"\0")
    if at < 0:
        return None
    line, column = source.count(b"\n", 0, at) + 1, at - source.rfind(b"\n", 0, at)
    return f"{shown_name}:{line}:{column}: error: a NUL byte (a program is text)"


def compile_file(simbot, path, shown_name):
    """Compiles the program at `path` (written()); its errors and warnings
    are one line each, "NAME:LINE:COL: error: ..." with NAME `shown_name`.
    A program with a NUL byte is refused before the compiler runs."""
    nul = _nul_byte(path, shown_name)
    if nul:
        return Compiled(False, [nul], [])
    try:
        p = subprocess.run([simbot, "compile", path], capture_output=True, timeout=COMPILE_SECONDS,
                           cwd=os.path.dirname(path))
    except subprocess.TimeoutExpired:
        return Compiled(False, [f"{shown_name}:1:1: error: the compiler took more than "
                                f"{COMPILE_SECONDS} s"], [])
    errors, warnings = [], []
    for line in p.stderr.decode("utf-8", "replace").splitlines():
        m = _DIAGNOSTIC.match(line)
        if not m:
            continue
        text = shown_name + line[len(m.group("file")):]
        (errors if m.group("kind") == "error" else warnings).append(text)
    if p.returncode != 0 and not errors:
        errors.append(f"{shown_name}:1:1: error: the compiler failed (exit status {p.returncode})")
    return Compiled(p.returncode == 0, errors, warnings)
