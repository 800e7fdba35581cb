"""The bench's and compare's statistics against independent implementations.

Runs `simbot bench PROGRAM --family stationary --json` and checks every
figure of its summary against statsmodels (SurvfuncRight: Kaplan-Meier
median, its default cloglog CI, the fraction reached by the horizon;
proportion_confint: Wilson) and scipy (chi2: Garwood's Poisson interval),
recomputed from runs.csv as pandas' read_csv loads it. Then runs
`simbot compare A B` and checks its log-rank tests against statsmodels'
survdiff, its Fisher and exact Poisson-rate tests against scipy's
fisher_exact and binomtest. All to 1e-9 (absolute and relative). The
permutation test (stall_s) is Monte Carlo beyond 9999 splits: it is held to
scipy's permutation_test on the same data within its sampling error.

Also: runs.csv and the tournament's games.csv load in pandas' read_csv
unchanged, seeds exact, with a comma and quotes in a program's file name.

Debian's /usr/bin/python3 runs it (statsmodels, scipy and pandas are
python3-statsmodels' and its dependencies).

usage: stats_oracle_test.py SIMBOT PROGRAM_A PROGRAM_B OUT_DIR SEEDS
"""
import csv
import json
import math
import pathlib
import subprocess
import sys

import numpy as np
import pandas as pd
from scipy import stats as sps
from statsmodels.duration.survfunc import SurvfuncRight, survdiff
from statsmodels.stats.proportion import proportion_confint

TOL = 1e-9
TIMES = ["acquire_s", "aim_s", "first_shot_s", "first_hit_s", "edge_enter_s",
         "edge_accept_s", "edge_latch_s", "edge_leave_s"]
LEGS = ["edge_enter_s", "edge_accept_s", "edge_latch_s", "edge_leave_s"]
COUNTS = ["shots", "hits", "frames_rejected"]
failures = []


def close(what, got, want):
    if want is None or (isinstance(want, float) and math.isnan(want)):
        ok = got is None
    elif math.isinf(want):
        ok = got is None  # JSON: an unbounded upper limit is null
    else:
        ok = got is not None and abs(got - want) <= TOL * max(1.0, abs(want))
    if not ok:
        failures.append(f"{what}: simbot {got}, oracle {want}")


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed ({r.returncode}):\n{r.stderr}")
    return r.stdout


def load(path):
    """runs.csv as pandas' read_csv loads it, unchanged; the seeds exact."""
    df = pd.read_csv(path)
    with open(path, newline="") as f:
        raw = [int(row["seed"]) for row in csv.DictReader(f)]
    if not pd.api.types.is_integer_dtype(df["seed"]) or [int(s) for s in df["seed"]] != raw:
        failures.append(f"{path}: read_csv does not load the seeds exactly ({df['seed'].dtype})")
    return df[df["outcome"] != "error"]


def time_sample(df, metric, seconds):
    """(time, status): an event at the value, else censored at the time the
    run had left once the metric's clock started (edge legs start where the
    one before ended; a leg never begun is not at risk)."""
    times, status = [], []
    for _, row in df.iterrows():
        start = 0.0
        if metric in LEGS:
            before = LEGS[:LEGS.index(metric)]
            if any(pd.isna(row[b]) for b in before):
                continue
            start = sum(row[b] for b in before)
        if pd.isna(row[metric]):
            times.append(seconds - start)
            status.append(0)
        else:
            times.append(row[metric])
            status.append(1)
    return np.array(times, dtype=float), np.array(status)


def check_bench(simbot, program, out, seeds):
    summary = json.loads(run([simbot, "bench", program, "--family", "stationary",
                              "--seeds", str(seeds), "--threads", "2", "--out", out,
                              "--json"]))
    seconds = summary["seconds"]
    df = load(pathlib.Path(out) / "runs.csv")
    rows = {m["metric"]: m for m in summary["programs"][0]["metrics"]}
    for metric in TIMES:
        got = rows[metric]
        if got["estimator"] != "Kaplan-Meier median":
            failures.append(f"{metric}: estimator {got['estimator']}")
        t, s = time_sample(df, metric, seconds)
        if got["n"] != len(t) or got["events"] != int(s.sum()):
            failures.append(f"{metric}: n/events {got['n']}/{got['events']} vs {len(t)}/{s.sum()}")
        if len(t) == 0 or s.sum() == 0:
            close(f"{metric} median", got["estimate"], None)
            continue
        sf = SurvfuncRight(t, s)
        close(f"{metric} median", got["estimate"], float(sf.quantile(0.5)))
        lb, ub = sf.quantile_ci(0.5)
        close(f"{metric} CI low", got["ci95_low"], float(lb))
        close(f"{metric} CI high", got["ci95_high"], float(ub))
        if got["ci95_high_unbounded"] != bool(np.isinf(ub)):
            failures.append(f"{metric}: unbounded flag {got['ci95_high_unbounded']}, oracle {ub}")
        horizon = got["reached_by_s"]
        before = np.flatnonzero(sf.surv_times <= horizon)
        surv = 1.0 if len(before) == 0 else float(sf.surv_prob[before[-1]])
        close(f"{metric} reached by {horizon} s", got["reached_by"], 1 - surv)
    hits, shots = int(df["hits"].sum()), int(df["shots"].sum())
    got = rows["hit_ratio"]
    if got["estimator"] != "Wilson" or got["events"] != hits or got["trials"] != shots:
        failures.append(f"hit_ratio: {got}")
    if shots:
        low, high = proportion_confint(hits, shots, alpha=0.05, method="wilson")
        close("hit_ratio", got["estimate"], hits / shots)
        close("hit_ratio CI low", got["ci95_low"], float(low))
        close("hit_ratio CI high", got["ci95_high"], float(high))
    for metric in COUNTS:
        got = rows[metric]
        total, n = int(df[metric].sum()), len(df)
        if got["estimator"] != "exact Poisson" or got["events"] != total:
            failures.append(f"{metric}: {got}")
        low = 0.0 if total == 0 else sps.chi2.ppf(0.025, 2 * total) / 2
        high = sps.chi2.isf(0.025, 2 * total + 2) / 2
        close(f"{metric} mean", got["estimate"], total / n)
        close(f"{metric} CI low", got["ci95_low"], low / n)
        close(f"{metric} CI high", got["ci95_high"], high / n)
    got = rows["stall_s"]
    close("stall_s mean", got["estimate"], float(df["stall_s"].mean()))
    if not (df["stall_s"].min() <= got["ci95_low"] <= got["estimate"] <= got["ci95_high"]
            <= df["stall_s"].max()):
        failures.append(f"stall_s bootstrap interval out of order or range: {got}")
    return summary


def check_compare(simbot, a, b, out, seeds):
    result = json.loads(run([simbot, "compare", a, b, "--family", "stationary", "--seeds",
                             str(seeds), "--seconds", "20", "--threads", "2", "--out", out,
                             "--json"]))
    da, db = load(pathlib.Path(out) / "runs-a.csv"), load(pathlib.Path(out) / "runs-b.csv")
    if list(da["seed"]) != list(db["seed"]):
        failures.append("compare: A and B did not play the same seeds")
    rows = {r["metric"]: r for r in result["rows"]}
    for metric in TIMES:
        ta, sa = time_sample(da, metric, 20.0)
        tb, sb = time_sample(db, metric, 20.0)
        got = rows[metric]
        for side, df in (("a", da), ("b", db)):
            want = (int(df[metric].notna().sum()), len(df))
            if (got[side]["reached"], got[side]["total"]) != want:
                failures.append(f"compare {metric} {side} reached/total "
                                f"{got[side]['reached']}/{got[side]['total']}, runs.csv {want}")
        if got["test"] != "log-rank":
            failures.append(f"compare {metric}: test {got['test']}")
        if sa.sum() + sb.sum() == 0 or len(ta) == 0 or len(tb) == 0:
            close(f"compare {metric} p", got["p"], None)
            continue
        chisq, p = survdiff(np.concatenate([ta, tb]), np.concatenate([sa, sb]),
                            np.array([0] * len(ta) + [1] * len(tb)))
        close(f"compare {metric} log-rank chi2", got["statistic"], float(chisq))
        close(f"compare {metric} log-rank p", got["p"], float(p))
    ha, na = int(da["hits"].sum()), int(da["shots"].sum())
    hb, nb = int(db["hits"].sum()), int(db["shots"].sum())
    if na and nb:
        odds, p = sps.fisher_exact([[ha, na - ha], [hb, nb - hb]])
        close("compare hit_ratio Fisher p", rows["hit_ratio"]["p"], float(p))
        close("compare hit_ratio odds ratio", rows["hit_ratio"]["statistic"], float(odds))
    for metric in COUNTS:
        ca, cb = int(da[metric].sum()), int(db[metric].sum())
        if ca + cb == 0:
            continue
        p = sps.binomtest(ca, ca + cb, len(da) / (len(da) + len(db))).pvalue
        close(f"compare {metric} exact Poisson p", rows[metric]["p"], float(p))
    perm = sps.permutation_test((da["stall_s"].to_numpy(), db["stall_s"].to_numpy()),
                                lambda x, y, axis: np.mean(x, axis=axis) - np.mean(y, axis=axis),
                                permutation_type="independent", vectorized=True,
                                n_resamples=9999, random_state=1)
    # Two Monte Carlo p-values of 9999 resamples: within 5 standard errors.
    se = math.sqrt(max(perm.pvalue * (1 - perm.pvalue), 1e-4) / 9999) * 2
    if abs(rows["stall_s"]["p"] - perm.pvalue) > 5 * se + 2e-4:
        failures.append(f"compare stall_s permutation p {rows['stall_s']['p']}, scipy {perm.pvalue}")
    return result


def check_csv_files(simbot, a, b, out):
    """runs.csv and games.csv load in pandas' read_csv unchanged (RFC 4180
    quoting), a file name with a comma and quotes included."""
    out.mkdir(parents=True, exist_ok=True)
    odd = out / 'ice,man "q".dc'
    odd.write_text(pathlib.Path(a).read_text())
    run([simbot, "bench", str(odd), "--family", "head-to-head", "--opponent", b, "--seeds", "2",
         "--seconds", "2", "--seed", "18446744073709551615", "--out", str(out / "bench")])
    df = load(out / "bench" / "runs.csv")
    if list(df["program"]) != [str(odd)] * 2 or df.shape[1] != len(open(
            out / "bench" / "runs.csv").readline().split(",")):
        failures.append(f"runs.csv with an odd file name: {df['program'].tolist()}")
    if not set(df["winner"]) <= {"A", "B"}:
        failures.append(f"runs.csv winners: {df['winner'].tolist()}")
    run([simbot, "tournament", str(odd), b, "--rounds", "2", "--seconds", "2",
         "--out", str(out / "tournament")])
    games = load_games(out / "tournament" / "games.csv")
    if (len(games) != 2 or not set(games["winner"]) <= {str(odd), b}
            or not set(games["winner_side"]) <= {"A", "B"}
            or set(games["a"]) != {str(odd), b}):
        failures.append(f"games.csv: {games}")


def load_games(path):
    df = pd.read_csv(path)
    with open(path, newline="") as f:
        raw = [int(row["seed"]) for row in csv.DictReader(f)]
    if not pd.api.types.is_integer_dtype(df["seed"]) or [int(s) for s in df["seed"]] != raw:
        failures.append(f"{path}: read_csv does not load the seeds exactly")
    return df


def check_midpoint(simbot, program, out, seeds):
    """bench --median midpoint: on an exact 0.5 plateau of statsmodels' own
    Kaplan-Meier curve, the midpoint of the plateau (SAS's and R's rule);
    elsewhere statsmodels' median. Returns how many medians sat on a plateau."""
    summary = json.loads(run([simbot, "bench", program, "--family", "stationary",
                              "--seeds", str(seeds), "--threads", "2", "--out", out,
                              "--json", "--median", "midpoint"]))
    df = load(pathlib.Path(out) / "runs.csv")
    rows = {m["metric"]: m for m in summary["programs"][0]["metrics"]}
    plateaus = 0
    for metric in TIMES:
        t, s = time_sample(df, metric, summary["seconds"])
        if len(t) == 0 or s.sum() == 0:
            continue
        sf = SurvfuncRight(t, s)
        times, surv = list(sf.surv_times), list(sf.surv_prob)
        want = None
        for i, p in enumerate(surv):
            if abs(p - 0.5) <= 1e-12:
                plateaus += 1
                want = (times[i] + times[i + 1]) / 2 if i + 1 < len(times) else times[i]
                break
            if p < 0.5:
                want = times[i]
                break
        close(f"{metric} midpoint median", rows[metric]["estimate"], want)
    return plateaus


def main():
    simbot, a, b, out, seeds = sys.argv[1:6]
    out = pathlib.Path(out)
    check_csv_files(simbot, a, b, out / "csv")
    summary = check_bench(simbot, a, str(out / "bench"), int(seeds))
    plateaus = check_midpoint(simbot, a, str(out / "bench-midpoint"), int(seeds))
    if plateaus == 0:
        failures.append("no median sat on an exact 0.5 plateau: the midpoint rule went untested")
    check_compare(simbot, a, b, str(out / "compare"), max(8, int(seeds) // 2))
    if failures:
        print("\n".join(failures))
        sys.exit(1)
    rows = summary["programs"][0]["metrics"]
    print(f"{len(rows)} summary figures of {seeds} seeds and the compare tests match "
          "statsmodels and scipy to 1e-9")


if __name__ == "__main__":
    main()
