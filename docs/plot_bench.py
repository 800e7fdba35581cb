#!/usr/bin/env python3
"""A bench through the Python module, plotted with matplotlib.

Runs `simbot bench` (the module's simbot.bench, the CLI's own code) for each
program in the circle family and draws, per program, the time to the first
shot and to the first hit of every run as a strip, with the runs where it
never happened (censored at the run's end) marked at the right edge.

usage (from the checkout, after the build):
  PYTHONPATH=build/python /usr/bin/python3 docs/plot_bench.py \
      --out bench.png PROGRAM.dc [PROGRAM.dc ...]
"""
import argparse
import os

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402
import pandas  # noqa: E402

import simbot  # noqa: E402


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("programs", nargs="+")
    p.add_argument("--family", default="circle")
    p.add_argument("--seeds", type=int, default=20)
    p.add_argument("--seconds", type=float, default=30.0)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--out", default="bench.png")
    a = p.parse_args()

    frames = []
    for program in a.programs:
        result = simbot.bench(program, a.family, a.seeds, seconds=a.seconds, seed=a.seed)
        frame = pandas.DataFrame(result["runs"])
        frame["name"] = os.path.basename(program)
        frames.append(frame)
    runs = pandas.concat(frames, ignore_index=True)

    metrics = ["first_shot_s", "first_hit_s"]
    fig, axes = plt.subplots(1, len(metrics), figsize=(5 * len(metrics), 1 + len(a.programs)),
                             sharey=True, squeeze=False)
    names = list(dict.fromkeys(runs["name"]))
    for ax, metric in zip(axes[0], metrics):
        for y, name in enumerate(names):
            values = runs.loc[runs["name"] == name, metric]
            reached = values.dropna()
            ax.scatter(reached, [y] * len(reached), marker="|", s=200)
            censored = values.isna().sum()
            if censored:
                ax.scatter([a.seconds], [y], marker=">", color="grey")
                ax.annotate(f"{censored} never", (a.seconds, y), textcoords="offset points",
                            xytext=(-8, 8), ha="right", fontsize=8, color="grey")
        ax.set_xlim(0, a.seconds * 1.02)
        ax.set_xlabel(f"{metric} (simulated seconds)")
        ax.set_yticks(range(len(names)), names)
        ax.set_ylim(-0.7, len(names) - 0.3)
    fig.suptitle(f"simbot bench, family {a.family}: {a.seeds} seeds x {a.seconds:g} s")
    fig.tight_layout()
    fig.savefig(a.out, dpi=100)
    print(f"wrote {a.out}: {len(runs)} runs")


if __name__ == "__main__":
    main()
