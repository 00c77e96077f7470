#!/usr/bin/python3
"""mufric's Gaussian process against scikit-learn's, side by side from one run.

Both fit the same data with the same kernel (constant * RBF(ARD) + white noise), the same bounds
(signal variance 1e-3..1e5, length scales 1e-2..1e3 box widths, noise variance 1e-6..1e-1), the
same unit-box inputs, normalised outputs and the same number of optimiser starts. Reported: fit
time, final log marginal likelihood, held-out mean relative error, predict time per point for a
10 000-point batch (mean only, mean+std), single-point latency; then error, fit and predict time
versus training size, and a plot.

The data are a smooth synthetic field mu(p, v, T) on the seed-000 box with 5e-4 absolute noise (no
physics: the micro-model does not exist yet); held-out error is against the noise-free field.

Run with Debian's Python (scikit-learn on OpenBLAS):
    /usr/bin/python3 bench/benchmarks/gp_vs_sklearn.py --mufric build/app/mufric
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
from sklearn.exceptions import ConvergenceWarning
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel

warnings.simplefilter("ignore", ConvergenceWarning)
BOX = np.array([[300.0, 1300.0], [22.5, 200.0], [25.0, 900.0]])  # MPa, m/min, °C
NOISE = 5e-4


def field(raw):
    ps = (raw[:, 0] - 300) / 1000
    vs = (raw[:, 1] - 22.5) / 177.5
    ts = (raw[:, 2] - 25) / 875
    return 0.3 - 0.08 * ps + 0.05 * np.sin(3 * vs) + 0.1 * np.exp(-2 * ts) * (1 + 0.3 * ps * vs)


def sample(n, rng):
    return BOX[:, 0] + rng.random((n, 3)) * (BOX[:, 1] - BOX[:, 0])


def write_csv(path, raw, mu):
    with open(path, "w") as out:
        out.write("contact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu\n")
        for row, m in zip(raw, mu):
            out.write(f"{row[0]!r},{row[1]!r},{row[2]!r},{m!r}\n")


def unit_box(raw, lo, hi):
    return (raw - lo) / (hi - lo)


def sklearn_kernel():
    return (ConstantKernel(1.0, (1e-3, 1e5)) * RBF([0.5] * 3, (1e-2, 1e3)) + WhiteKernel(1e-5, (1e-6, 1e-1)))


def run(cmd):
    return subprocess.run(cmd, capture_output=True, text=True, check=True).stdout


def mufric_fit(mufric, train_csv, model, restarts):
    t0 = time.perf_counter()
    out = run([mufric, "train", "--data", str(train_csv), "--out", str(model), "--restarts", str(restarts)])
    wall = time.perf_counter() - t0
    lml = float(re.search(r"best: start \d+, log marginal likelihood (\S+)", out).group(1))
    fit = float(re.search(r"training points\) in (\S+) s", out).group(1))
    return {"fit_s": fit, "wall_s": wall, "lml": lml, "log": out}


def mufric_error(mufric, model, test_csv):
    out = run([mufric, "eval", "--model", str(model), "--test", str(test_csv)])
    return float(re.search(r"mean relative error (\S+) %", out).group(1)) / 100


def mufric_bench(mufric, model, batches, with_std, seconds):
    cmd = [mufric, "bench", "--model", str(model), "--json", "--seconds", str(seconds), "--batch"] + [str(b) for b in batches]
    if with_std:
        cmd.append("--std")
    rows = [json.loads(line) for line in run(cmd).splitlines() if line.startswith("{")]
    return {r["batch"]: r for r in rows}


def sklearn_fit(unit, mu, restarts):
    gp = GaussianProcessRegressor(sklearn_kernel(), n_restarts_optimizer=restarts, normalize_y=True, alpha=0.0,
                                  random_state=0)
    t0 = time.perf_counter()
    gp.fit(unit, mu)
    return gp, time.perf_counter() - t0


def per_point(fn, points, min_seconds=1.0):
    """Median seconds per point of fn() over repeated calls lasting at least min_seconds."""
    fn()
    times, start = [], time.perf_counter()
    while time.perf_counter() - start < min_seconds or len(times) < 5:
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return float(np.median(times)) / points


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mufric", default="build/app/mufric")
    parser.add_argument("--n", type=int, default=900, help="training size of the side-by-side comparison")
    parser.add_argument("--restarts", type=int, default=4, help="starts after the first, both codes")
    parser.add_argument("--sizes", default="100,300,600,900,2000,3000", help="training sizes of the sweep")
    parser.add_argument("--sweep-restarts", type=int, default=2)
    parser.add_argument("--test", type=int, default=2000, help="held-out points")
    parser.add_argument("--out", default="bench/studies/gp_vs_sklearn", help="folder for the JSON and the plot")
    parser.add_argument("--seconds", type=float, default=1.0, help="minimum timing per prediction measurement")
    parser.add_argument("--replot", action="store_true", help="only redraw the tables and plot from the stored JSON")
    args = parser.parse_args()
    out_dir = Path(args.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    if args.replot:
        results = json.loads((out_dir / "gp_vs_sklearn.json").read_text())
        report(results)
        plot(results, out_dir / "gp_vs_sklearn.png")
        return 0
    rng = np.random.default_rng(2026)
    results = {"test": args.test, "n": args.n, "restarts": args.restarts, "sweep_restarts": args.sweep_restarts, "machine": os.uname().nodename, "date": time.strftime("%Y-%m-%d"),
               "cpu": subprocess.run("lscpu | sed -n 's/Model name: *//p'", shell=True, capture_output=True,
                                     text=True).stdout.strip(), "nproc": os.cpu_count()}

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        test_raw = sample(args.test, rng)
        test_mu = field(test_raw)
        write_csv(tmp / "test.csv", test_raw, test_mu)
        batch_raw = sample(10000, rng)

        def compare(n, restarts, timing):
            raw = sample(n, rng)
            mu = field(raw) + rng.normal(0, NOISE, n)
            write_csv(tmp / "train.csv", raw, mu)
            model = tmp / "model.h5"
            m = mufric_fit(args.mufric, tmp / "train.csv", model, restarts)
            row = {"n": n, "mufric_train_log": m["log"], "mufric_fit_s": m["fit_s"], "mufric_train_wall_s": m["wall_s"], "mufric_lml": m["lml"],
                   "mufric_error": mufric_error(args.mufric, model, tmp / "test.csv")}
            lo, hi = raw.min(0), raw.max(0)  # mufric's box for a CSV: the data's range
            gp, fit_s = sklearn_fit(unit_box(raw, lo, hi), mu, restarts)
            row.update({"sklearn_fit_s": fit_s, "sklearn_lml": float(gp.log_marginal_likelihood_value_),
                        "sklearn_error": float(np.mean(np.abs(gp.predict(unit_box(test_raw, lo, hi)) - test_mu) /
                                                       np.abs(test_mu)))})
            b_mean = mufric_bench(args.mufric, model, [1, 10000], False, args.seconds)
            b_std = mufric_bench(args.mufric, model, [1, 10000], True, args.seconds)
            row.update({"mufric_mean_us": 1e6 / b_mean[10000]["points_per_second"],
                        "mufric_std_us": 1e6 / b_std[10000]["points_per_second"],
                        "mufric_single_mean_us": b_mean[1]["p50_us"], "mufric_single_std_us": b_std[1]["p50_us"]})
            if timing:
                batch = unit_box(batch_raw, lo, hi)
                one = batch[:1]
                row.update({"sklearn_mean_us": 1e6 * per_point(lambda: gp.predict(batch), 10000, args.seconds),
                            "sklearn_std_us": 1e6 * per_point(lambda: gp.predict(batch, return_std=True), 10000,
                                                              args.seconds),
                            "sklearn_single_mean_us": 1e6 * per_point(lambda: gp.predict(one), 1, args.seconds),
                            "sklearn_single_std_us": 1e6 * per_point(lambda: gp.predict(one, return_std=True), 1,
                                                                     args.seconds)})
            print(json.dumps({k: v for k, v in row.items() if k != "mufric_train_log"}), flush=True)
            return row

        print(f"== side by side: n = {args.n}, {args.restarts + 1} starts each", flush=True)
        results["side_by_side"] = compare(args.n, args.restarts, True)
        print(f"== sweep: sizes {args.sizes}, {args.sweep_restarts + 1} starts each", flush=True)
        results["sweep"] = [compare(int(n), args.sweep_restarts, False) for n in args.sizes.split(",")]

    (out_dir / "gp_vs_sklearn.json").write_text(json.dumps(results, indent=1))
    report(results)
    plot(results, out_dir / "gp_vs_sklearn.png")


def report(r):
    s = r["side_by_side"]
    print(f"\n### Side by side ({r['date']}, {r['cpu']}, {r['nproc']} cores): n = {s['n']}, {r['restarts'] + 1} starts, "
          f"held-out {r['test']} points\n")
    print("| | mufric | scikit-learn | ratio |\n|---|---|---|---|")
    print(f"| fit time | {s['mufric_fit_s']:.2f} s | {s['sklearn_fit_s']:.2f} s | {s['sklearn_fit_s'] / s['mufric_fit_s']:.1f}x |")
    print(f"| final log marginal likelihood | {s['mufric_lml']:.4f} | {s['sklearn_lml']:.4f} | "
          f"{s['mufric_lml'] - s['sklearn_lml']:+.4f} |")
    print(f"| held-out mean relative error | {100 * s['mufric_error']:.4f} % | {100 * s['sklearn_error']:.4f} % | |")
    for key, label in [("mean", "10 000-point batch, mean only, per point"),
                       ("std", "10 000-point batch, mean+std, per point"),
                       ("single_mean", "single point, mean only"), ("single_std", "single point, mean+std")]:
        a, b = s[f"mufric_{key}_us"], s[f"sklearn_{key}_us"]
        print(f"| {label} | {a:.3g} us | {b:.3g} us | {b / a:.1f}x |")
    print("\n### Error and time versus training size\n")
    print("| n | mufric error | sklearn error | mufric fit | sklearn fit | fit ratio | mufric LML - sklearn LML |"
          " mufric mean/pt | mufric mean+std/pt | mufric single+std |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for w in r["sweep"]:
        print(f"| {w['n']} | {100 * w['mufric_error']:.4f} % | {100 * w['sklearn_error']:.4f} % | {w['mufric_fit_s']:.2f} s | "
              f"{w['sklearn_fit_s']:.2f} s | {w['sklearn_fit_s'] / w['mufric_fit_s']:.1f}x | "
              f"{w['mufric_lml'] - w['sklearn_lml']:+.4f} | {w['mufric_mean_us']:.3g} us | {w['mufric_std_us']:.3g} us | "
              f"{w['mufric_single_std_us']:.3g} us |")


def plot(r, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    sweep = r["sweep"]
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
    for code, colour in [("mufric", "tab:blue"), ("sklearn", "tab:orange")]:
        t = [w[f"{code}_fit_s"] for w in sweep]
        e = [100 * w[f"{code}_error"] for w in sweep]
        a.loglog(t, e, "o-", color=colour, label="scikit-learn" if code == "sklearn" else code)
        for w, x, y in zip(sweep, t, e):
            a.annotate(str(w["n"]), (x, y), textcoords="offset points", xytext=(4, 4), fontsize=8)
    a.set_xlabel("fit time [s]")
    a.set_ylabel("held-out mean relative error [%]")
    a.set_title(f"Run time against error ({r['sweep_restarts'] + 1} starts each; labels: training size)")
    a.grid(True, which="both", alpha=0.3)
    a.legend()
    n = [w["n"] for w in sweep]
    series = [("mufric_mean_us", "o-", "tab:blue", "mufric mean, 10k batch"),
              ("mufric_std_us", "s-", "tab:green", "mufric mean+std, 10k batch"),
              ("mufric_single_std_us", "^-", "tab:red", "mufric single point +std")]
    for key, style, colour, label in series:
        b.loglog(n, [w[key] for w in sweep], style, color=colour, label=label)
    s = r["side_by_side"]
    peer = "black"
    b.loglog([s["n"]], [s["sklearn_mean_us"]], "o", color=peer, mfc="none", label="scikit-learn mean, 10k batch")
    b.loglog([s["n"]], [s["sklearn_std_us"]], "s", color=peer, mfc="none", label="scikit-learn mean+std, 10k batch")
    b.loglog([s["n"]], [s["sklearn_single_std_us"]], "^", color=peer, mfc="none", label="scikit-learn single +std")
    b.axhline(20.0, color="tab:red", linestyle=":", linewidth=1, label="goal: single point +std 20 us")
    b.set_xlabel("training points")
    b.set_ylabel("time per point [us]")
    b.set_title("Prediction cost per point")
    b.grid(True, which="both", alpha=0.3)
    b.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print(f"\nplot: {path}")


if __name__ == "__main__":
    sys.exit(main())
