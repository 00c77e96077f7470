#!/usr/bin/env python3
"""The recovery study at a glance (bench/recovery_calibration.sh writes what this reads): left, the
posterior of the shear factor m with and without the discrepancy delta against the m* that made the
measurements; right, the measurements (mean of their draws, ±1.96 standard errors) against what each
calibrated model serves at their conditions (μ and its 95 % interval: the data it was calibrated on,
not a held-out check). Asks `mufric predict --csv` for the served values.
  /usr/bin/python3 bench/plot_recovery.py MUFRIC OUT_DIR M_STAR OUT.png"""
import argparse
import csv
import io
import os
import subprocess

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("mufric")
parser.add_argument("out_dir", help="bench/recovery_calibration.sh's --out")
parser.add_argument("m_star", type=float)
parser.add_argument("png")
args = parser.parse_args()


def rows_of(text):
    """A CSV's rows as dicts, its '#' comment lines skipped."""
    return list(csv.DictReader(io.StringIO("".join(l + "\n" for l in text.splitlines() if not l.startswith("#")))))


def read_csv(path):
    with open(path) as f:
        return rows_of(f.read())


measured = read_csv(os.path.join(args.out_dir, "measured.csv"))
condition_columns = [c for c in measured[0] if c not in ("mu", "mu_sd")]
mu_measured = np.array([float(r["mu"]) for r in measured])
sd_measured = np.array([float(r["mu_sd"]) for r in measured])

variants = [("", "δ off", "tab:blue"), ("--discrepancy", "δ on", "tab:orange")]
fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
order = np.argsort(mu_measured)
x = np.arange(len(order))
right.errorbar(x, mu_measured[order], yerr=1.96 * sd_measured[order], fmt="ks", capsize=3,
               label="micro-model at m* (mean of 4 draws, ±1.96 SE)")
for k, (suffix, label, colour) in enumerate(variants):
    posterior = os.path.join(args.out_dir, f"posterior{suffix}.csv")
    model = os.path.join(args.out_dir, f"calibrated{suffix}.h5")
    if not os.path.exists(posterior):
        continue
    m = np.array([float(r["shear_factor"]) for r in read_csv(posterior)])
    lo, hi = np.quantile(m, [0.025, 0.975])
    left.hist(m, bins=60, density=True, histtype="step", color=colour, lw=1.5,
              label=f"{label}: 95 % {lo:.3f}–{hi:.3f}")
    if not os.path.exists(model):
        continue
    points = os.path.join(args.out_dir, "conditions.csv")
    with open(points, "w") as f:
        f.write(",".join(condition_columns) + "\n")
        for r in measured:
            f.write(",".join(r[c] for c in condition_columns) + "\n")
    served = subprocess.run([args.mufric, "predict", "--model", model, "--csv", points], capture_output=True, text=True,
                            check=True).stdout
    rows = rows_of(served)
    mu = np.array([float(r["mu"]) for r in rows])
    lo95 = np.array([float(r["lo"]) for r in rows])
    hi95 = np.array([float(r["hi"]) for r in rows])
    shift = -0.15 + 0.3 * k
    right.errorbar(x + shift, mu[order], yerr=[mu[order] - lo95[order], hi95[order] - mu[order]], fmt="o", color=colour,
                   capsize=3, label=f"calibrated, {label} (95 %)")
left.axvline(args.m_star, color="k", ls="--", label=f"m* = {args.m_star}")
left.set_xlabel("shear factor m")
left.set_ylabel("posterior density")
left.legend(fontsize=8)
left.set_title("m's posterior")
right.set_xticks(x)
right.set_xticklabels([f"{float(measured[i][condition_columns[0]]) / 1e6:.0f} MPa\n"
                       f"{float(measured[i][condition_columns[1]]) * 60:.0f} m/min\n"
                       f"{float(measured[i][condition_columns[2]]) - 273.15:.0f} °C" for i in order], fontsize=6)
right.set_ylabel("μ")
right.legend(fontsize=7)
right.set_title("served at the measured conditions")
fig.tight_layout()
fig.savefig(args.png, dpi=130)
print(f"wrote {args.png}")
