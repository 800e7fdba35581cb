#!/usr/bin/env python3
"""Fast-forward of delay loops is exact (issue 13).

Usage: fast_forward_test.py SIMBOT SOURCE_DIR SHARED_DIR WORKDIR [--sanitized]

Runs every program in programs/, tests/programs/ and the two reference
programs solo and in a match against fig92, each with and without
fast-forward (--no-fast-forward), and requires the same JSON summary (but
for its wall-clock field and the integrator's step and right-hand-side
counts) and a byte-identical trace. Each also runs without a trace, where
a robot quiet past a sub-round's horizon sits it out (scheduler/match.cpp,
"Larger rounds", (6)): its JSON must be the traced run's but for the
wall-clock field. programs/ and the reference programs run again with
PRT0 ticking in each (a profile with timer_service = "always"). Under the
sanitizers (slow) only programs/ and the reference programs run.
"""
import copy
import json
import pathlib
import re
import subprocess
import sys


def summary_of(simbot, args):
    out = subprocess.run([simbot, *args, "--json"], capture_output=True, text=True)
    if out.returncode not in (0, 3):
        sys.exit(f"FAIL: {' '.join(args)} exited {out.returncode}: {out.stderr}")
    summary = json.loads(out.stdout)
    summary.pop("wall_seconds", None)
    return summary


def run(simbot, args, trace):
    """The traced run's summary without the integrator's work counts, and whole."""
    summary = summary_of(simbot, [*args, "--trace", str(trace)])
    traced = copy.deepcopy(summary)
    # The integrator's steps, right-hand sides and roots count work, not
    # results: steps past an input's tick (and the roots found in them) are
    # thrown away at its re-initialisation, and fast-forward lets the
    # scheduler end rounds elsewhere (Vm::quietUntil; scheduler/match.h,
    # step 1). Resets must match, and so must every event in the trace.
    integrator = summary.get("integrator")
    if integrator:
        for work in ("steps", "rhs_evals", "roots"):
            integrator.pop(work, None)
    return summary, traced


def main():
    simbot, source, shared, work = sys.argv[1:5]
    sanitized = "--sanitized" in sys.argv[5:]
    source, shared, work = pathlib.Path(source), pathlib.Path(shared), pathlib.Path(work)
    work.mkdir(parents=True, exist_ok=True)
    fig92 = shared / "programs" / "fig92.dc"
    programs = sorted((source / "programs").glob("*.dc"))
    programs += [shared / "programs" / "iceman.dc", fig92]
    if not sanitized:
        programs += sorted((source / "tests" / "programs").glob("*.dc"))
    seconds = "10" if sanitized else "20"
    runs = []
    for p in programs:
        runs.append((f"solo-{p.stem}", ["solo", str(p), "--seconds", seconds]))
        runs.append((f"match-{p.stem}", ["match", str(p), str(fig92), "--seconds", seconds]))
    if not sanitized:
        runs.append(("match-iceman-fig92-180s",
                     ["match", str(shared / "programs" / "iceman.dc"), str(fig92)]))
    # PRT0 ticking in every program (the profile's timer_service = "always"):
    # its ticks bound quietUntil and land inside delay loops' passes.
    always = work / "timer-always.toml"
    always.write_text(re.sub(r'timer_service *= *\{ *value *= *"auto"', 'timer_service = { value = "always"',
                             (source / "profiles" / "default.toml").read_text()))
    for p in [shared / "programs" / "iceman.dc", fig92, *sorted((source / "programs").glob("*.dc"))]:
        timed = ["--profile", str(always), "--seconds", seconds]
        runs.append((f"timer-solo-{p.stem}", ["solo", str(p), *timed]))
        runs.append((f"timer-match-{p.stem}", ["match", str(p), str(fig92), *timed]))
    failures = 0
    for name, args in runs:
        fast_trace, slow_trace = work / f"{name}.ff.jsonl", work / f"{name}.step.jsonl"
        fast, traced = run(simbot, args, fast_trace)
        slow, _ = run(simbot, args + ["--no-fast-forward"], slow_trace)
        untraced = summary_of(simbot, args)
        if untraced != traced:
            failures += 1
            print(f"FAIL {name}: JSON differs without a trace\n  traced: {traced}\n"
                  f"  untraced: {untraced}")
        elif fast != slow:
            failures += 1
            print(f"FAIL {name}: JSON differs\n  fast: {fast}\n  step: {slow}")
        elif fast_trace.read_bytes() != slow_trace.read_bytes():
            failures += 1
            print(f"FAIL {name}: traces differ ({fast_trace} vs {slow_trace})")
        else:
            print(f"ok   {name}")
    if failures:
        sys.exit(f"{failures} of {len(runs)} runs differ with fast-forward")
    print(f"all {len(runs)} runs identical with and without fast-forward")


if __name__ == "__main__":
    main()
