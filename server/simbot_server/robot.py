"""A team's robot: the hardware file its /teams/ID/robot form makes.

The form lists what `simbot hardware --json` lists (every value a
hardware file may set, with its unit, valid range and source, from the
course's profile or the team's file), and a team's answer becomes a
hardware file of the values that differ from the profile's, which the
same command checks with the loader `simbot match --hw` uses: what it
refuses is shown as its one-line FILE:LINE:COL error, what it takes is
kept (Team.hardware) and used for that team's scrimmages, and for a round
robin when the instructor asks for the teams' robots.

No text of the form goes into the file as it was sent: a number must
parse as one, a unit must be one of the key's units, a choice one of its
words; the file is written by this module, so it is always well formed."""
import json
import math
import os
import subprocess
import tempfile

HARDWARE_SECONDS = 30  # wall time of one `simbot hardware`
FILE_NAME = "robot.toml"  # how a team's file is named in messages
SOURCE = "the team's robot form"
UNITLESS = ("bool", "choice")


class Listing:
    """simbot hardware's keys (a list of dicts, docs/plant.md) or its error."""

    def __init__(self, keys=None, error=None):
        self.keys, self.error = keys or [], error


_course = {}  # simbot executable -> its listing of the course's profile alone


def listing(simbot, hardware=None):
    """The keys over the course's profile, with `hardware` (a file's text,
    or None) loaded over it. The course's alone is the same for every team
    and form: it is made once (the profile is read when the server first
    shows a form)."""
    if hardware is None:
        if simbot not in _course:
            found = _listing(simbot, None)
            if found.error:
                return found
            _course[simbot] = found
        return _course[simbot]
    return _listing(simbot, hardware)


def _listing(simbot, hardware):
    with tempfile.TemporaryDirectory(prefix="simbot-robot-") as folder:
        args = [simbot, "hardware", "--json"]
        if hardware is not None:
            path = os.path.join(folder, FILE_NAME)
            with open(path, "w", encoding="utf-8") as f:
                f.write(hardware)
            args.insert(2, path)
        try:
            p = subprocess.run(args, capture_output=True, timeout=HARDWARE_SECONDS, cwd=folder)
        except subprocess.TimeoutExpired:
            return Listing(error=f"{FILE_NAME}: error: the check took more than {HARDWARE_SECONDS} s")
    if p.returncode != 0:
        message = p.stderr.decode("utf-8", "replace").strip().splitlines()
        line = message[0] if message else f"simbot hardware exited {p.returncode}"
        return Listing(error=line.replace(folder + "/", ""))
    return Listing(keys=json.loads(p.stdout)["keys"])


def field(key):
    return f"{key['section']}.{key['key']}"


def shown(key, value=None):
    """A key's value as the form shows it (its profile's when `value` is None)."""
    value = key["value"] if value is None else value
    if value is None:
        return ""
    if key["kind"] == "bool":
        return "true" if value else "false"
    if key["kind"] == "speed_table":
        return ", ".join(f"{v:g}" for v in value)
    if isinstance(value, float):
        return f"{value:g}"
    return str(value)


def _number(text, integer):
    v = int(text) if integer else float(text)
    if not math.isfinite(v):
        raise ValueError
    return repr(v) if not integer else str(v)


def _toml_value(key, text):
    """The TOML of a value the form sent for `key`; ValueError if it is not one."""
    kind = key["kind"]
    if kind == "bool":
        if text not in ("true", "false"):
            raise ValueError
        return text
    if kind == "choice":
        if text not in key["choices"]:
            raise ValueError
        return json.dumps(text)
    if kind == "speed_table":
        return "[" + ", ".join(_number(v.strip(), False) for v in text.split(",")) + "]"
    return _number(text, kind in ("count", "step", "bit"))


def hardware_file(keys, form):
    """The hardware file (TOML text) of the form's answers that differ
    from the profile's, and the problems with what it sent ({field: why})."""
    sections, problems = {}, {}
    for key in keys:
        name = field(key)
        text = (form.get("v." + name) or "").strip()
        unit = form.get("u." + name) or key["unit"] or (key["units"][0] if key["units"] else None)
        if not text:
            continue
        if key["kind"] not in UNITLESS and unit not in key["units"]:
            problems[name] = f"the unit is one of {', '.join(key['units'])}"
            continue
        same_unit = key["kind"] in UNITLESS or unit == key["unit"]
        if key["from"] == "profile" and same_unit and text == shown(key):
            continue  # as the course has it
        try:
            value = _toml_value(key, text)
        except ValueError:
            problems[name] = {"bool": "true or false", "choice": "one of " + ", ".join(key["choices"]),
                              "speed_table": "16 numbers, separated by commas"}.get(
                key["kind"], "a number" if key["kind"] not in ("count", "step", "bit")
                else "a whole number")
            continue
        entry = f"value = {value}" + ("" if key["kind"] in UNITLESS else f", unit = {json.dumps(unit)}")
        sections.setdefault(key["section"], []).append(
            f"{key['key']} = {{ {entry}, source = {json.dumps(SOURCE)} }}")
    text = "".join(f"[{section}]\n" + "\n".join(lines) + "\n\n" for section, lines in sections.items())
    return text, problems
