#!/usr/bin/python3
"""`mufric train` (GP fit + fast evaluator) against scikit-learn's fit of the same data, as a new user
would run them: noise-free and noisy data of 900, 2 000 and 10 000 points (issue 30).

For each data set: mufric's whole `train` wall time, its fit time and the fast evaluator's build time and
outcome (stored or not, grid size), `train --no-fast-evaluator`, and scikit-learn's fit (same kernel,
bounds and starts), each pinned to one core (`taskset -c CORE`, OMP/BLAS threads 1) so that the ratio
is a like-for-like comparison. A run longer than --timeout is stopped and reported as such.

The data: a smooth synthetic field mu(p, v, T) with several bumps over seed 000's box (no physics),
noise-free (the learned noise ends at its lower bound, where sigma is a cancelling difference) and with
2e-3 absolute noise.

    /usr/bin/python3 bench/benchmarks/train_budget.py --mufric build/app/mufric --sizes 900,2000,10000
"""
import argparse
import json
import os
import re
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

BOX = np.array([[300.0, 1300.0], [22.5, 200.0], [25.0, 900.0]])  # MPa, m/min, °C


def field(raw):
    u = (raw[:, 0] - 300) / 1000
    w = (raw[:, 1] - 22.5) / 177.5
    t = (raw[:, 2] - 25) / 875
    return (0.18 + 0.03 * np.sin(5 * u + 1) * np.cos(4 * w) - 0.04 * np.sin(3 * t) * t +
            0.02 * np.exp(-((u - 0.5) ** 2 + (w - 0.4) ** 2) / 0.1))


def write_csv(path, raw, mu):
    with open(path, "w") as out:
        out.write("contact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu\n")
        for row, m in zip(raw, mu):
            out.write(f"{row[0]!r},{row[1]!r},{row[2]!r},{m!r}\n")


def one_core_env():
    env = dict(os.environ)
    env.update(OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    return env


def timed(cmd, timeout):
    t0 = time.perf_counter()
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=one_core_env())
    except subprocess.TimeoutExpired:
        return None, time.perf_counter() - t0
    return r, time.perf_counter() - t0


def mufric_train(args, csv, model, extra):
    cmd = ["taskset", "-c", str(args.core), args.mufric, "train", "--data", str(csv), "--out", str(model),
           "--restarts", str(args.restarts)] + extra
    r, wall = timed(cmd, args.timeout)
    row = {"wall_s": wall, "finished": r is not None and r.returncode == 0}
    if r is None:
        return row
    out = r.stdout
    m = re.search(r"training points\) in (\S+) s", out)
    row["fit_s"] = float(m.group(1)) if m else None
    m = re.search(r"^fast evaluator \(model\): (\S+) MB, built in (\S+) s", out, re.M)
    if m:
        row.update(grid="stored", grid_mb=float(m.group(1)), grid_s=float(m.group(2)))
    m = re.search(r"^fast evaluator \(model\): not stored, built in (\S+) s: (.*?) before", out, re.M)
    if m:
        row.update(grid="not stored", grid_s=float(m.group(1)), why=m.group(2))
    if row["finished"]:
        d = subprocess.run([args.mufric, "describe", str(model)], capture_output=True, text=True)
        row["describe_ok"] = d.returncode == 0
    else:
        row["stderr"] = r.stderr[-300:]
    return row


SKLEARN = """
import sys, time, numpy as np, warnings
from sklearn.exceptions import ConvergenceWarning
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel
warnings.simplefilter("ignore", ConvergenceWarning)
d = np.loadtxt(sys.argv[1], delimiter=",", skiprows=1)
x, y = d[:, :3], d[:, 3]
u = (x - x.min(0)) / (x.max(0) - x.min(0))
k = ConstantKernel(1.0, (1e-3, 1e5)) * RBF([0.5] * 3, (1e-2, 1e3)) + WhiteKernel(1e-5, (1e-6, 1e-1))
gp = GaussianProcessRegressor(k, n_restarts_optimizer=int(sys.argv[2]), normalize_y=True, alpha=0.0, random_state=0)
t0 = time.perf_counter(); gp.fit(u, y); print(time.perf_counter() - t0)
"""


def sklearn_fit(args, csv):
    r, wall = timed(["taskset", "-c", str(args.core), "/usr/bin/python3", "-c", SKLEARN, str(csv), str(args.restarts)],
                    args.timeout)
    if r is None or r.returncode != 0:
        return {"finished": False, "wall_s": wall}
    return {"finished": True, "fit_s": float(r.stdout.split()[-1]), "wall_s": wall}


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--mufric", default="build/app/mufric")
    p.add_argument("--sizes", default="900,2000,10000")
    p.add_argument("--restarts", type=int, default=2, help="starts after the first, both codes")
    p.add_argument("--core", type=int, default=1, help="the one core every run is pinned to")
    p.add_argument("--timeout", type=float, default=900.0, help="seconds before a run is stopped")
    p.add_argument("--noise", type=float, default=2e-3)
    p.add_argument("--skip-sklearn-above", type=int, default=1000000, help="no scikit-learn fit above this n")
    p.add_argument("--out", default="bench/studies/day_one/train_budget.json")
    args = p.parse_args()
    cpu = subprocess.run("lscpu | sed -n 's/Model name: *//p'", shell=True, capture_output=True, text=True).stdout.strip()
    flags = subprocess.run("grep -o -w -m1 'avx512f\\|avx2' /proc/cpuinfo | sort -u | tr '\\n' ' '", shell=True,
                           capture_output=True, text=True).stdout.strip()
    results = {"date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "cpu": cpu, "vector": flags, "rows": []}
    rng = np.random.default_rng(30)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for n in [int(s) for s in args.sizes.split(",")]:
            for noise in (0.0, args.noise):
                raw = BOX[:, 0] + rng.random((n, 3)) * (BOX[:, 1] - BOX[:, 0])
                mu = field(raw) + (rng.normal(0, noise, n) if noise > 0 else 0)
                csv = tmp / f"d{n}.csv"
                write_csv(csv, raw, mu)
                row = {"n": n, "noise": noise, "train": mufric_train(args, csv, tmp / "m.h5", []),
                       "train_no_grid": mufric_train(args, csv, tmp / "m0.h5", ["--no-fast-evaluator"])}
                if n <= args.skip_sklearn_above:
                    row["sklearn"] = sklearn_fit(args, csv)
                print(json.dumps(row), flush=True)
                results["rows"].append(row)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(results, indent=1))
    print(f"\n{results['date']}, {cpu} ({flags}), one core each (taskset -c {args.core}), {args.restarts + 1} starts\n")
    print("| n | noise | mufric train | of which fit | fast evaluator | train --no-fast-evaluator | scikit-learn fit | "
          "train / fit | sklearn / train |")
    print("|---|---|---|---|---|---|---|---|---|")

    def s(x, key="wall_s"):
        return f"{x[key]:.2f} s" if x.get("finished") else f"> {args.timeout:.0f} s (stopped)"
    for r in results["rows"]:
        t, t0, sk = r["train"], r["train_no_grid"], r.get("sklearn", {})
        grid = (f"{t.get('grid')} ({t.get('grid_mb', 0):.1f} MB, {t.get('grid_s', 0):.1f} s)" if t.get("grid") == "stored"
                else f"{t.get('grid', '-')} ({t.get('why', '')})")
        ratio = f"{t['wall_s'] / t['fit_s']:.2f}" if t.get("finished") and t.get("fit_s") else "-"
        sk_ratio = f"{sk['fit_s'] / t['wall_s']:.1f}x" if sk.get("finished") and t.get("finished") else "-"
        print(f"| {r['n']} | {r['noise']:g} | {s(t)} | {t.get('fit_s', float('nan')):.2f} s | {grid} | {s(t0)} | "
              f"{s(sk, 'fit_s') if sk else 'not run'} | {ratio} | {sk_ratio} |")


if __name__ == "__main__":
    main()
