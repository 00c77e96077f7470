#!/usr/bin/env python3
"""The analysis of bench/studies/served_interval/shipped_model_heldout.sh: a model asked at held-out points whose own mean
comes from many independent draws. Per point z = (held-out mean - served mu) / sqrt(served std^2 +
held-out standard error^2); a calibrated 95 % interval covers |z| <= 1.96 at about 95 %. The mean
error is given net of the held-out means' own standard error (sqrt(max(0, RMS error^2 - mean SE^2))).
  /usr/bin/python3 bench/studies/served_interval/shipped_model_heldout.py MUFRIC HELDOUT.h5 MODEL"""
import csv
import io
import math
import subprocess
import sys

import h5py
import numpy as np

mufric, heldout, model = sys.argv[1], sys.argv[2], sys.argv[3]
with h5py.File(heldout, "r") as f:
    ok = f["samples/status"][:] == 0
    x, mean, se = f["samples/inputs"][:][ok], f["samples/mu"][:][ok], f["samples/mu_std"][:][ok]
    draw_mu = f["samples/draw_mu"][:][ok]
draws = np.isfinite(draw_mu).sum(axis=1)
spread = np.array([np.std(row[np.isfinite(row)], ddof=1) for row in draw_mu])
text = "contact_pressure[Pa],sliding_velocity[m/s],temperature[K]\n"
text += "".join(",".join(repr(float(v)) for v in row) + "\n" for row in x)
answer = subprocess.run([mufric, "predict", "--model", model, "--csv", "/dev/stdin"], input=text, capture_output=True,
                        text=True, check=True).stdout
rows = list(csv.DictReader(io.StringIO(answer)))
mu = np.array([float(r["mu"]) for r in rows])
sd = np.array([float(r["std"]) for r in rows])
patch = np.array([float(r["patch_std"]) for r in rows]) if "patch_std" in rows[0] else None
z = (mean - mu) / np.sqrt(sd ** 2 + se ** 2)
covered = int(np.sum(np.abs(z) <= 1.96))
rms_error = math.sqrt(np.mean((mean - mu) ** 2))
net = math.sqrt(max(0.0, rms_error ** 2 - np.mean(se ** 2)))
print(f"{model} against {len(mean)} held-out points of {heldout} ({draws.min()}-{draws.max()} draws each; their own "
      f"standard error median {100 * np.median(se / mean):.1f} % of mu)")
print(f"coverage of the 95 % interval of the mean: {covered}/{len(z)} ({100 * covered / len(z):.0f} %), RMS z {math.sqrt(np.mean(z ** 2)):.2f}")
print(f"mean error: RMS {100 * rms_error / np.mean(mean):.2f} % of mu, net of the held-out standard error "
      f"{100 * net / np.mean(mean):.2f} %")
if patch is not None:
    # A sample standard deviation from r draws has a relative standard error of about 1/sqrt(2(r-1)).
    ratio = patch / spread
    print(f"patch_std / held-out per-draw std: median {np.median(ratio):.2f} (range {ratio.min():.2f}-{ratio.max():.2f}; "
          f"sampling error of one std from {int(np.median(draws))} draws about {100 / math.sqrt(2 * (np.median(draws) - 1)):.0f} %)")
print("| p [MPa] | v [m/min] | T [C] | held-out mean +- SE | served mu +- std | z | per-draw std | patch_std |")
print("|---|---|---|---|---|---|---|---|")
for k in range(len(mean)):
    print(f"| {x[k, 0] / 1e6:.0f} | {x[k, 1] * 60:.1f} | {x[k, 2] - 273.15:.0f} | {mean[k]:.4f} +- {se[k]:.4f} | "
          f"{mu[k]:.4f} +- {sd[k]:.4f} | {z[k]:+.2f} | {spread[k]:.4f} | {'—' if patch is None else f'{patch[k]:.4f}'} |")
