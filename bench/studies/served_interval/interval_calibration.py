#!/usr/bin/env python3
"""The analysis of bench/studies/served_interval/interval_calibration.sh: both designs' models against the held-out means, at
growing budgets (the first k samples of each database, k = 8, 16, ... N: a prefix of a Sobol' plan
is itself spread over the box). Per held-out point z = (held-out mean - served mu) /
sqrt(served std^2 + held-out standard error^2); a calibrated interval covers |z| <= 1.96 at ~95 %.
  /usr/bin/python3 bench/studies/served_interval/interval_calibration.py MUFRIC OUT"""
import csv
import io
import math
import shutil
import subprocess
import sys

import h5py
import numpy as np

mufric, out = sys.argv[1], sys.argv[2]
with h5py.File(f"{out}/heldout.h5", "r") as f:
    ok = f["samples/status"][:] == 0
    x, mean, se = f["samples/inputs"][:][ok], f["samples/mu"][:][ok], f["samples/mu_std"][:][ok]
    draws = np.isfinite(f["samples/draw_mu"][:][ok]).sum(axis=1)
points = f"{out}/heldout-points.csv"
with open(points, "w") as c:
    c.write("contact_pressure[Pa],sliding_velocity[m/s],temperature[K]\n")
    for row in x:
        c.write(",".join(repr(float(v)) for v in row) + "\n")
print(f"held-out: {len(mean)} points, {draws.min()}-{draws.max()} draws each; their own standard error "
      f"median {np.median(se):.4f} ({100 * np.median(se / mean):.1f} % of mu); mu {mean.min():.3f}-{mean.max():.3f}")


def prefix(database, k, target):
    """The first k samples of a database (every /samples dataset sliced; the plan kept)."""
    shutil.copyfile(database, target)
    def cut(group, name):
        data = group[name]
        values, dtype = data[:k], data.dtype
        del group[name]
        group.create_dataset(name, data=values, dtype=dtype)

    with h5py.File(target, "r+") as f:
        for name, item in list(f["samples"].items()):
            if isinstance(item, h5py.Group):
                for sub in list(item):
                    cut(item, sub)
            else:
                cut(f["samples"], name)


def served(model):
    answers = subprocess.run([mufric, "predict", "--model", model, "--csv", points], capture_output=True, text=True,
                             check=True).stdout
    rows = list(csv.DictReader(io.StringIO(answers)))
    column = lambda key: np.array([float(a[key]) for a in rows])
    patch = column("patch_std") if "patch_std" in rows[0] else None
    return column("mu"), column("std"), column("hi") - column("lo"), patch


with h5py.File(f"{out}/independent.h5", "r") as f:
    total = len(f["samples/mu"])
budgets = sorted({k for k in (8, 16, 32, 64, 128) if k < total} | {total})
print("| samples (x 4 draws) | design | coverage of held-out means, 95 % | RMS z | RMS error / mean mu | 95 % width, median | patch_std / held-out per-draw std, median |")
print("|---|---|---|---|---|---|---|")
for k in budgets:
    for name in ("independent", "common"):
        data, model = f"{out}/{name}-{k}.h5", f"{out}/{name}-{k}-gp.h5"
        prefix(f"{out}/{name}.h5", k, data)
        subprocess.run([mufric, "train", "--data", data, "--out", model, "--restarts", "4"], check=True,
                       capture_output=True)
        mu, sd, width, patch = served(model)
        z = (mean - mu) / np.sqrt(sd ** 2 + se ** 2)
        covered = int(np.sum(np.abs(z) <= 1.96))
        ratio = "—" if patch is None else f"{np.median(patch / (se * np.sqrt(draws))):.2f}"
        print(f"| {k} | {name} | {100 * covered / len(z):.0f} % ({covered}/{len(z)}) | {math.sqrt(np.mean(z ** 2)):.2f} | "
              f"{100 * math.sqrt(np.mean((mean - mu) ** 2)) / np.mean(mean):.1f} % | {np.median(width):.4f} | {ratio} |")
