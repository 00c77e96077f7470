#!/usr/bin/env python3
"""What a model serves, at a glance: μ along each input through the box centre (the others held at
the centre) with the 95 % interval of the mean and, when the model has one, the patch scatter
(μ ± 1.96 patch_std: where 95 % of single 10 µm contact patches fall), plus μ over (p, T) at the
centre's v. Asks `mufric predict --csv` (any model: a file, a shipped name, grpc://).
  /usr/bin/python3 tools/plot/plot_model.py MUFRIC MODEL OUT.png [--data db.h5]"""
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
parser.add_argument("--data", help="a dataset whose converged samples are drawn as points (their mu)")
args = parser.parse_args()

describe = subprocess.run([args.mufric, "describe", args.model], capture_output=True, text=True, check=True).stdout
box = {}
for line in describe.splitlines():  # "  contact_pressure   [300MPa, 3100MPa]  stored in Pa"
    words = line.split()
    if len(words) >= 3 and words[1].startswith("[") and "stored" in line:
        box[words[0]] = (words[1].strip("[,"), words[2].strip("]"))
names = list(box)
unit_scale = {"MPa": ("MPa", 1.0), "m/min": ("m/min", 1.0), "°C": ("C", 1.0), "C": ("C", 1.0), "deg": ("deg", 1.0)}


def split_quantity(text):
    for unit in ("MPa", "m/min", "°C", "deg"):
        if text.endswith(unit):
            return float(text[: -len(unit)]), unit_scale[unit][0]
    raise SystemExit(f"plot_model: cannot read the box value '{text}' (describe's format changed?)")


lo, hi, units = {}, {}, {}
for name in names:
    lo[name], units[name] = split_quantity(box[name][0])
    hi[name], _ = split_quantity(box[name][1])
centre = {n: 0.5 * (lo[n] + hi[n]) for n in names}


def ask(rows):
    text = ",".join(f"{n}[{units[n]}]" for n in names) + "\n"
    text += "".join(",".join(repr(float(r[n])) for n in names) + "\n" for r in rows)
    answer = subprocess.run([args.mufric, "predict", "--model", args.model, "--csv", "/dev/stdin"], input=text,
                            capture_output=True, text=True)
    if answer.returncode not in (0, 2):
        raise SystemExit(answer.stderr)
    return list(csv.DictReader(io.StringIO(answer.stdout)))


fig, axes = plt.subplots(1, len(names) + 1, figsize=(4.2 * (len(names) + 1), 3.8))
for ax, name in zip(axes, names):
    t = np.linspace(lo[name], hi[name], 120)
    answers = ask([{**centre, name: v} for v in t])
    mu = np.array([float(a["mu"]) for a in answers])
    ax.fill_between(t, [float(a["lo"]) for a in answers], [float(a["hi"]) for a in answers], alpha=0.45,
                    color="C0", label="95 % interval of the mean", zorder=2)
    if "patch_std" in answers[0]:
        patch = np.array([float(a["patch_std"]) for a in answers])
        ax.fill_between(t, mu - 1.96 * patch, mu + 1.96 * patch, alpha=0.15, color="C1",
                        label="95 % of single patches", zorder=1)
    ax.plot(t, mu, color="C0", zorder=3, label="μ")
    ax.set_xlabel(f"{name} [{units[name]}]")
    ax.set_ylabel("μ")
    ax.grid(alpha=0.3)
axes[0].legend(fontsize=8, loc="best")
if args.data:
    import h5py
    with h5py.File(args.data, "r") as f:
        ok = f["samples/status"][:] == 0
        x, mu = f["samples/inputs"][:][ok], f["samples/mu"][:][ok]
    to_human = {"contact_pressure": lambda v: v / 1e6, "sliding_velocity": lambda v: v * 60.0,
                "temperature": lambda v: v - 273.15, "fibre_angle": np.degrees}
    for k, (ax, name) in enumerate(zip(axes, names)):
        ax.scatter(to_human[name](x[:, k]), mu, s=6, color="k", alpha=0.5, zorder=4,
                   label="samples (all other inputs)" if k == 0 else None)
    axes[0].legend(fontsize=8, loc="best")

if "contact_pressure" in names and "temperature" in names:
    p = np.linspace(lo["contact_pressure"], hi["contact_pressure"], 60)
    temp = np.linspace(lo["temperature"], hi["temperature"], 50)
    grid = [{**centre, "contact_pressure": a, "temperature": b} for b in temp for a in p]
    mu = np.array([float(a["mu"]) for a in ask(grid)]).reshape(len(temp), len(p))
    image = axes[-1].contourf(p, temp, mu, levels=16, cmap="viridis")
    fig.colorbar(image, ax=axes[-1], label="μ")
    axes[-1].set_xlabel("contact_pressure [MPa]")
    axes[-1].set_ylabel("temperature [C]")
    others = [n for n in names if n not in ("contact_pressure", "temperature")]
    axes[-1].set_title(", ".join(f"{n} {centre[n]:.4g} {units[n]}" for n in others), fontsize=9)
else:
    axes[-1].axis("off")
fig.suptitle(f"{args.model}: μ through the box centre", fontsize=10)
fig.tight_layout()
fig.savefig(args.out, dpi=110)
print(f"wrote {args.out}")
