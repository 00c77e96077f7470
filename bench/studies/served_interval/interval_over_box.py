#!/usr/bin/env python3
"""How wide the served interval of the mean is over a model's whole box: the 95 % half-width relative
to mu at the box centre and its percentiles over a dense tensor grid (n points per input, the inputs
as the model stores them, uniform in each), the patch scatter beside it, and a PNG of the half-width
over (p, T) at three sliding velocities. Asks `mufric predict --csv` (any model: a file, a shipped
name, grpc://), so it measures what a meso code is served.
  /usr/bin/python3 bench/studies/served_interval/interval_over_box.py MUFRIC MODEL OUT.png [--n 21] [--level 0.95]"""
import argparse
import csv
import io
import subprocess

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("mufric")
parser.add_argument("model")
parser.add_argument("out")
parser.add_argument("--n", type=int, default=21, help="grid points per input (default 21)")
parser.add_argument("--level", type=float, default=0.95, help="confidence level (default 0.95)")
args = parser.parse_args()

describe = subprocess.run([args.mufric, "describe", args.model], capture_output=True, text=True, check=True).stdout
units = {"MPa": "MPa", "m/min": "m/min", "°C": "C", "deg": "deg"}
box = {}
for line in describe.splitlines():  # "  contact_pressure   [300MPa, 3100MPa]  stored in Pa"
    words = line.split()
    if len(words) >= 3 and words[1].startswith("[") and "stored" in line:
        ends = []
        for text in (words[1].strip("[,"), words[2].strip("]")):
            unit = next((u for u in units if text.endswith(u)), None)
            if unit is None:
                raise SystemExit(f"interval_over_box: cannot read the box value '{text}' (describe's format changed?)")
            ends.append((float(text[: -len(unit)]), units[unit]))
        box[words[0]] = (ends[0][0], ends[1][0], ends[0][1])
names = list(box)
if len(names) != 3:
    raise SystemExit(f"interval_over_box: draws (p, v, T) models; this one has inputs {names}")


def ask(points):
    text = ",".join(f"{n}[{box[n][2]}]" for n in names) + "\n"
    text += "".join(",".join(repr(float(v)) for v in row) + "\n" for row in points)
    answer = subprocess.run([args.mufric, "predict", "--model", args.model, "--csv", "/dev/stdin",
                             "--level", str(args.level)], input=text, capture_output=True, text=True)
    if answer.returncode != 0:
        raise SystemExit(f"interval_over_box: predict failed: {answer.stderr}")
    rows = list(csv.DictReader(io.StringIO(answer.stdout)))
    mu = np.array([float(r["mu"]) for r in rows])
    half = 0.5 * (np.array([float(r["hi"]) for r in rows]) - np.array([float(r["lo"]) for r in rows]))
    patch = np.array([float(r["patch_std"]) for r in rows]) if rows and "patch_std" in rows[0] else None
    return mu, half, patch


axes_values = [np.linspace(box[n][0], box[n][1], args.n) for n in names]
grid = np.stack(np.meshgrid(*axes_values, indexing="ij"), axis=-1).reshape(-1, 3)
mu, half, patch = ask(grid)
relative = half / mu
centre = [0.5 * (box[n][0] + box[n][1]) for n in names]
mu_c, half_c, patch_c = ask([centre])

level = f"{round(100 * args.level)} %"
print(f"model {args.model}: {len(grid)} grid points ({args.n} per input, uniform in the stored units)")
print(f"box centre {', '.join(f'{c:g} {box[n][2]}' for n, c in zip(names, centre))}: mu {mu_c[0]:.4f}, "
      f"{level} half-width {half_c[0]:.5f} = {100 * half_c[0] / mu_c[0]:.2f} % of mu"
      + (f", patch_std {patch_c[0]:.4f} = {100 * patch_c[0] / mu_c[0]:.1f} % of mu" if patch_c is not None else ""))
print(f"{level} half-width / mu over the grid: median {100 * np.median(relative):.2f} %, "
      f"90th percentile {100 * np.percentile(relative, 90):.2f} %, max {100 * relative.max():.2f} %; "
      f"half-width median {np.median(half):.5f}, max {half.max():.5f}; mu {mu.min():.3f}-{mu.max():.3f}")
worst = np.argmax(relative)
print(f"widest relative: {', '.join(f'{v:g} {box[n][2]}' for n, v in zip(names, grid[worst]))} "
      f"(mu {mu[worst]:.4f} +- {half[worst]:.4f})")
if patch is not None:
    print(f"patch_std / mu: median {100 * np.median(patch / mu):.1f} %, 90th percentile "
          f"{100 * np.percentile(patch / mu, 90):.1f} %")

cube = relative.reshape(args.n, args.n, args.n)
slices = [0, args.n // 2, args.n - 1]
fig, axes = plt.subplots(1, len(slices), figsize=(4.6 * len(slices), 3.9), constrained_layout=True)
top = np.percentile(relative, 99) * 100
for ax, j in zip(axes, slices):
    image = ax.pcolormesh(axes_values[0], axes_values[2], 100 * cube[:, j, :].T, shading="nearest",
                          vmin=0, vmax=top, cmap="viridis")
    ax.set_xlabel(f"{names[0]} [{box[names[0]][2]}]")
    ax.set_ylabel(f"{names[2]} [{box[names[2]][2]}]")
    ax.set_title(f"{names[1]} = {axes_values[1][j]:g} {box[names[1]][2]}", fontsize=10)
fig.colorbar(image, ax=axes, label=f"{level} half-width of the mean / mu [%]")
fig.suptitle(f"{args.model}: served interval of the mean over its box (median {100 * np.median(relative):.1f} %, "
             f"90th pct {100 * np.percentile(relative, 90):.1f} %)", fontsize=11)
fig.savefig(args.out, dpi=110)
print(f"wrote {args.out}")
