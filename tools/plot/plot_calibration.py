#!/usr/bin/python3
"""A model against measurements, as a picture: any model `mufric predict` answers (a calibrated one
above all) and any measurements CSV `mufric calibrate` reads (conditions with units, optional
NAME_sd / NAME_min / NAME_max columns, mu, mu_sd).

Left: the measured mu (error bars: +-1.96 mu_sd) and what each model serves at each row's stated
conditions (mu and its 95 % interval), against one condition (--x); between neighbouring rows a
model is also drawn along the straight line joining their conditions, so a trend along a cutting
speed (where pressure, velocity and temperature all move) shows as a band. Right, with --posterior
(repeatable, one per model, or one): each calibrated coefficient's posterior histogram (calibrate
--out's CSV; only the law's coefficients), and with --truth NAME=VALUE the value that made the data,
when it is known (a recovery study).

  /usr/bin/python3 tools/plot/plot_calibration.py --mufric build/app/mufric --model ti6al4v_tin \\
      --data data/cirp2022_ti6al4v_tin/rake_face_mu_0deg.csv --x sliding_velocity --out mu.png
Several --data files are drawn each in its marker; --label names them (default: the file's stem);
--model is repeatable, --model-label names each; --compare FILE:LABEL adds a CSV of (x, mu) rows to
draw as a line (e.g. a tabulated law). bench/studies/calibration/recovery_calibration.sh draws its study with it."""
import argparse
import csv
import io
import os
import re
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

LAW_COEFFICIENTS = ("adhesive_coefficient", "shear_factor", "childs_exponent")
# How a column's unit is shown; the CSV's own units are kept as written.
HEADER = re.compile(r"^([a-z_]+)(?:\[(.*)\])?$")


def rows_of(text):
    """A CSV's rows as dicts, its '#' comment lines skipped."""
    lines = [line for line in text.splitlines() if not line.startswith("#")]
    return list(csv.DictReader(io.StringIO("\n".join(lines))))


def read_rows(path):
    with open(path) as f:
        return rows_of(f.read())


def condition_columns(row):
    """The conditions as name[unit] columns (a condition given only as a range takes its _min's unit)."""
    columns = []
    for column in row:
        match = HEADER.match(column)
        if not match or match.group(1) in ("mu", "mu_sd") or match.group(1).endswith(("_sd", "_max")):
            continue
        name, unit = match.groups()
        name = name[:-len("_min")] if name.endswith("_min") else name
        as_column = f"{name}[{unit}]" if unit is not None else name
        if as_column not in columns:
            columns.append(as_column)
    return columns


def stated(row, column):
    """A row's stated value of a condition: its value, or its range's middle."""
    name, unit = HEADER.match(column).groups()
    if row.get(column, "") != "":
        return float(row[column])
    lo, hi = f"{name}_min[{unit}]", f"{name}_max[{unit}]"
    return 0.5 * (float(row[lo]) + float(row[hi]))


def predict(mufric, model, columns, points):
    """mu, lo, hi of the model at the points (rows of values in the columns' units)."""
    with tempfile.NamedTemporaryFile("w", suffix=".csv", delete=False) as f:
        f.write(",".join(columns) + "\n")
        for p in points:
            f.write(",".join(repr(float(v)) for v in p) + "\n")
        path = f.name
    try:
        done = subprocess.run([mufric, "predict", "--model", model, "--csv", path], capture_output=True, text=True)
    finally:
        os.unlink(path)
    if done.returncode != 0:
        sys.exit(f"plot_calibration: mufric predict failed: {done.stderr.strip() or done.stdout.strip()}")
    rows = rows_of(done.stdout)
    return (np.array([float(r["mu"]) for r in rows]), np.array([float(r["lo"]) for r in rows]),
            np.array([float(r["hi"]) for r in rows]))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mufric", default="mufric")
    parser.add_argument("--model", action="append", required=True, help="a model URI or file mufric predict reads (repeatable)")
    parser.add_argument("--model-label", action="append", help="a label per --model")
    parser.add_argument("--data", action="append", required=True, help="a measurements CSV (repeatable)")
    parser.add_argument("--label", action="append", help="a label per --data")
    parser.add_argument("--x", help="the condition along the horizontal axis (default: the first column)")
    parser.add_argument("--posterior", action="append", default=[], help="calibrate --out's CSV (repeatable, per --model)")
    parser.add_argument("--truth", action="append", default=[], help="NAME=VALUE: a coefficient's known value")
    parser.add_argument("--compare", action="append", default=[], help="CSV:LABEL of (x, mu) rows drawn as a line")
    parser.add_argument("--title", default="")
    parser.add_argument("--out", required=True)
    args = parser.parse_args()

    sets = [read_rows(path) for path in args.data]
    labels = args.label or [os.path.splitext(os.path.basename(p))[0] for p in args.data]
    if len(labels) != len(sets):
        sys.exit("plot_calibration: give one --label per --data")
    columns = condition_columns(sets[0][0])
    for path, rows in zip(args.data, sets):
        if condition_columns(rows[0]) != columns:
            sys.exit(f"plot_calibration: {path} gives other conditions than {args.data[0]} ({columns})")
    x_column = next((c for c in columns if HEADER.match(c).group(1) == args.x), None) if args.x else columns[0]
    if x_column is None:
        sys.exit(f"plot_calibration: --x {args.x} is not among the conditions {columns}")
    x_index = columns.index(x_column)

    models = args.model
    model_labels = args.model_label or [os.path.splitext(os.path.basename(m))[0] for m in models]
    if len(model_labels) != len(models):
        sys.exit("plot_calibration: give one --model-label per --model")
    panels = 2 if args.posterior else 1
    fig, axes = plt.subplots(1, panels, figsize=(6.2 * panels, 4.4), squeeze=False)
    left = axes[0][0]
    colours = ["tab:blue", "tab:orange", "tab:green", "tab:purple"]
    markers = ["s", "^", "D", "v"]
    for k, (rows, label) in enumerate(zip(sets, labels)):
        points = np.array([[stated(r, c) for c in columns] for r in rows])
        mu = np.array([float(r["mu"]) for r in rows])
        sd = np.array([float(r["mu_sd"]) for r in rows])
        order = np.argsort(points[:, x_index])
        points, mu, sd = points[order], mu[order], sd[order]
        left.errorbar(points[:, x_index], mu, yerr=1.96 * sd, fmt=markers[k % len(markers)], color="k", capsize=3,
                      label=f"{label}: measured (±1.96 SD)")
        # Each model along the straight lines between neighbouring rows' conditions.
        path = [points[0]]
        for a, b in zip(points[:-1], points[1:]):
            for t in np.linspace(0.0, 1.0, 21)[1:]:
                path.append(a + t * (b - a))
        path = np.array(path)
        for j, (model, model_label) in enumerate(zip(models, model_labels)):
            colour = colours[j % len(colours)]
            served, lo, hi = predict(args.mufric, model, columns, path)
            left.fill_between(path[:, x_index], lo, hi, color=colour, alpha=0.18, lw=0)
            left.plot(path[:, x_index], served, color=colour, lw=1.2,
                      label=f"{model_label}, 95 % interval" if k == 0 else None)
            at_rows, _, _ = predict(args.mufric, model, columns, points)
            left.plot(points[:, x_index], at_rows, "o", color=colour, mfc="white", ms=5)
    for spec in args.compare:
        path, _, label = spec.partition(":")
        rows = read_rows(path)
        keys = list(rows[0].keys())
        left.plot([float(r[keys[0]]) for r in rows], [float(r[keys[1]]) for r in rows], "k--", lw=1, label=label or path)
    left.set_xlabel(x_column)
    left.set_ylabel("μ")
    left.legend(fontsize=7)
    left.set_title(args.title or "served against the measurements")

    if args.posterior:
        right = axes[0][1]
        for j, path in enumerate(args.posterior):
            samples = read_rows(path)
            owner = model_labels[j] if len(args.posterior) == len(models) else os.path.basename(path)
            for k, name in enumerate(c for c in samples[0] if c in LAW_COEFFICIENTS):
                values = np.array([float(r[name]) for r in samples])
                lo, hi = np.quantile(values, [0.025, 0.975])
                # The model's colour (as on the left), one line style per coefficient.
                right.hist(values, bins=60, density=True, histtype="step", lw=1.5, color=colours[j % len(colours)],
                           ls=("-", ":", "-.", (0, (5, 1)))[k % 4], label=f"{owner}: {name}, 95 % {lo:.3g}–{hi:.3g}")
        for truth in args.truth:
            name, _, value = truth.partition("=")
            right.axvline(float(value), color="k", ls="--", label=f"{name}* = {value}")
        right.set_xlabel("coefficient")
        right.set_ylabel("posterior density")
        right.legend(fontsize=7)
        right.set_title("the law's coefficients")
    fig.tight_layout()
    fig.savefig(args.out, dpi=130)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
