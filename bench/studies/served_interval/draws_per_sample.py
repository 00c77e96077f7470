#!/usr/bin/env python3
"""Points or replications: for a fixed budget of micro-model draws (each draw a whole press-slide run
of one tool and chip surface, so a draw is the unit of cost), how many draws per sample r (1, 2, 4, 8)
give the narrowest interval of the mean over the box? Stochastic kriging's integrated mean squared
error (Ankenman, Nelson & Staum 2010, eq. 7 with Sigma_eps = diag(V(x_i)/r)) for n = budget/r scrambled
Sobol' points, with the hyper-parameters and the per-draw variance V(x) (the patch scatter) of a
model trained on the campaign -- the measured inputs of the study -- held fixed:
    IMSE = mean over reference x of  s2 - k(x)^T (s2 R + diag(V/r) + noise)^-1 k(x).
What it leaves out: with r = 1 the scatter cannot be learned from the samples themselves (train falls
back to one noise level), and hyper-parameters learned from fewer points are less certain.
  /usr/bin/python3 bench/studies/served_interval/draws_per_sample.py MUFRIC MODEL.h5 [BUDGET ...]"""
import csv
import io
import subprocess
import sys

import h5py
import numpy as np
from scipy.stats import qmc

mufric, model = sys.argv[1], sys.argv[2]
budgets = [int(b) for b in sys.argv[3:]] or [256, 512, 1024]
with h5py.File(model, "r") as f:  # a model file (its hyper-parameters are read here)
    g = f["gp"]
    s2, noise = float(g.attrs["signal_variance"]), float(g.attrs["noise_variance"])
    y_scale = float(g.attrs["y_scale"])
    length = g["length_scales"][:]
    lo, hi = f["inputs/box_lo"][:], f["inputs/box_hi"][:]
    names = [n.decode() if isinstance(n, bytes) else n for n in f["inputs/names"][:]]
    units = [u.decode() if isinstance(u, bytes) else u for u in f["inputs/units"][:]]


def per_draw_variance(unit_points):
    """V(x) in normalised units, from the model's patch scatter (predict --csv, SI columns)."""
    x = lo + unit_points * (hi - lo)
    text = ",".join(f"{n}[{u}]" for n, u in zip(names, units)) + "\n"
    text += "".join(",".join(repr(float(v)) for v in row) + "\n" for row in x)
    out = subprocess.run([mufric, "predict", "--model", model, "--csv", "/dev/stdin"], input=text,
                         capture_output=True, text=True, check=True).stdout
    patch = np.array([float(r["patch_std"]) for r in csv.DictReader(io.StringIO(out))])
    return (patch / y_scale) ** 2


def correlation(a, b):
    d = (a[:, None, :] - b[None, :, :]) / length
    return np.exp(-0.5 * np.sum(d * d, axis=2))


reference = qmc.Sobol(d=len(names), scramble=True, seed=12345).random(2048)
print(f"model {model}: signal variance {s2:.3g}, length scales {np.array2string(length, precision=3)} box widths, "
      f"y scale {y_scale:.4g}; reference: 2048 Sobol' points")
print("| budget (draws) | r draws per sample | samples n | RMS std of the mean over the box | median 95 % width | vs r = 4 |")
print("|---|---|---|---|---|---|")
for budget in budgets:
    rows = []
    for r in (1, 2, 4, 8):
        n = budget // r
        imse, widths = [], []
        for seed in range(4):  # four scrambles: the design's own luck
            x = qmc.Sobol(d=len(names), scramble=True, seed=seed).random(n)
            k = s2 * correlation(x, x) + np.diag(per_draw_variance(x) / r + noise)
            k_star = s2 * correlation(reference, x)
            chol = np.linalg.cholesky(k)
            v = np.linalg.solve(chol, k_star.T)
            var = np.maximum(s2 - np.sum(v * v, axis=0), 0.0) * y_scale ** 2
            imse.append(np.mean(var))
            widths.append(np.median(2 * 1.96 * np.sqrt(var)))
        rows.append((r, n, np.sqrt(np.mean(imse)), np.mean(widths)))
    base = [row for row in rows if row[0] == 4][0][2]
    for r, n, rms, width in rows:
        print(f"| {budget} | {r} | {n} | {rms:.5f} | {width:.5f} | {rms / base:.2f} |")
