#!/usr/bin/env python3
"""The meso-code comparison (issue 69): each finished run of campaigns/meso_ti6al4v_sph against
Ducobu, Pantale & Lauwers' measured orthogonal cuts (data/cirp2022_ti6al4v_tin/cutting_tests.csv,
lambda_s = 0), and the contact states the meso code asked mufric about against the model's box.

  /usr/bin/python3 campaigns/meso_ti6al4v_sph/analyse.py [--window-from 0.3mm] [--out DIR] [--no-plots]

Writes DIR/comparison.csv (one row per run), DIR/forces.png (Fc and Ff against travel, the
measured means with their 2 sigma) and DIR/contact_states.png (the mufric runs' contact states
against the model's box), and prints the table. DIR defaults to the campaign folder.

Steady state: the mean of the force rows (one per um of travel) from --window-from to the run's end;
its scatter as the standard error of five consecutive block means (the rows are correlated); a run
counts as inside the measurement when its mean lies within the measured mean +- 2 sigma (the error
bar of the source, 2 sigma of three repeats).
"""
import argparse
import csv
import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def length_mm(text):
    units = {"mm": 1.0, "um": 1e-3, "m": 1e3}
    for unit in sorted(units, key=len, reverse=True):
        if text.endswith(unit):
            return float(text[: -len(unit)]) * units[unit]
    raise SystemExit(f"analyse.py: '{text}' needs a unit (mm, um or m)")


def read_runs(path):
    runs = []
    with open(path) as f:
        for line in f:
            if not line.strip() or line.startswith("#") or line.startswith("name,"):
                continue
            name, options = line.rstrip("\n").split(",", 1)
            runs.append((name, options))
    return runs


def read_measured(path):
    rows = {}
    with open(path) as f:
        lines = [l for l in f if not l.startswith("#")]
    for r in csv.DictReader(lines):
        if float(r["inclination_angle[deg]"]) != 0.0:
            continue
        key = (float(r["cutting_speed[m/min]"]), float(r["uncut_chip_thickness[um]"]))
        rows[key] = {k: float(r[k]) for k in ("Fc_exp_mean[N]", "Fc_exp_2sd[N]", "Ff_exp_mean[N]", "Ff_exp_2sd[N]",
                                               "chip_ratio_exp_mean[1]", "chip_ratio_exp_2sd[1]", "Fc_sim[N]", "Ff_sim[N]")}
    return rows


def read_forces(path):
    with open(path) as f:
        return [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]


def window_stats(values):
    n = len(values)
    if n == 0:
        return float("nan"), float("nan")
    mean = sum(values) / n
    per = n // 5
    if per == 0:
        return mean, float("nan")
    means = [sum(values[b * per:(b + 1) * per]) / per for b in range(5)]
    m = sum(means) / 5
    return mean, math.sqrt(sum((x - m) ** 2 for x in means) / 4 / 5)


def run_conditions(summary):
    return summary["cutting_speed_m_per_min"], summary["uncut_thickness_um"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--window-from", default="0.3mm", help="start of the steady-state window, e.g. 0.3mm")
    ap.add_argument("--out", default=None, help="where comparison.csv and the plots go (default: the campaign folder)")
    ap.add_argument("--campaign", default=HERE, help="the folder with runs.csv and runs/ (default: this one)")
    ap.add_argument("--no-plots", action="store_true", help="the table only")
    args = ap.parse_args()
    campaign = args.campaign
    args.out = args.out or campaign
    window = length_mm(args.window_from) * 1e-3
    measured = read_measured(os.path.join(ROOT, "data", "cirp2022_ti6al4v_tin", "cutting_tests.csv"))
    table = []
    traces = []
    for name, options in read_runs(os.path.join(campaign, "runs.csv")):
        folder = os.path.join(campaign, "runs", name)
        summary_file = os.path.join(folder, "summary.json")
        if not os.path.exists(summary_file) or name.startswith("verify_"):
            continue
        with open(summary_file) as f:
            summary = json.load(f)
        forces = read_forces(os.path.join(folder, "forces.csv"))
        inside = [r for r in forces if r["travel[m]"] >= window]
        fc, fc_se = window_stats([r["Fc[N/mm]"] for r in inside])
        ff, ff_se = window_stats([r["Ff[N/mm]"] for r in inside])
        h_um = summary["uncut_thickness_um"]
        chips = [r["chip_thickness[m]"] * 1e6 / h_um for r in inside if r["chip_thickness[m]"] > 0]
        ratio, ratio_se = window_stats(chips)
        mu, _ = window_stats([r["mu_weighted[1]"] for r in inside])
        v, h = run_conditions(summary)
        m = measured.get((v, h))
        row = {"run": name, "friction": summary.get("friction", ""), "cutting_speed[m/min]": v, "uncut_thickness[um]": h,
               "window_from[mm]": window * 1e3, "Fc[N]": fc, "Fc_block_se[N]": fc_se, "Ff[N]": ff, "Ff_block_se[N]": ff_se,
               "chip_ratio": ratio, "mu_weighted": mu,
               "mufric_share_of_wall": summary["mufric"]["share_of_wall"],
               "points_outside_box_share": (summary["mufric"]["extrapolated"] / summary["mufric"]["points"]
                                            if summary["mufric"]["points"] else float("nan"))}
        if m:
            row.update({"Fc_measured[N]": m["Fc_exp_mean[N]"], "Fc_measured_2sd[N]": m["Fc_exp_2sd[N]"],
                        "Fc_error[%]": 100 * (fc - m["Fc_exp_mean[N]"]) / m["Fc_exp_mean[N]"],
                        "Fc_inside_2sd": abs(fc - m["Fc_exp_mean[N]"]) <= m["Fc_exp_2sd[N]"],
                        "Ff_measured[N]": m["Ff_exp_mean[N]"], "Ff_measured_2sd[N]": m["Ff_exp_2sd[N]"],
                        "Ff_error[%]": 100 * (ff - m["Ff_exp_mean[N]"]) / m["Ff_exp_mean[N]"],
                        "Ff_inside_2sd": abs(ff - m["Ff_exp_mean[N]"]) <= m["Ff_exp_2sd[N]"],
                        "chip_ratio_measured": m["chip_ratio_exp_mean[1]"]})
        table.append(row)
        traces.append((name, v, h, forces, m))
    if not table:
        print("analyse.py: no finished run yet (runs/*/summary.json)")
        return 0
    columns = list(dict.fromkeys(k for r in table for k in r))
    with open(os.path.join(args.out, "comparison.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=columns)
        w.writeheader()
        w.writerows(table)
    print(f"{'run':34s} {'Fc':>7s} {'meas':>13s} {'err%':>6s} {'Ff':>6s} {'meas':>12s} {'err%':>6s} {'ratio':>5s} {'mu':>5s}")
    for r in table:
        print(f"{r['run']:34s} {r['Fc[N]']:7.1f} {r.get('Fc_measured[N]', float('nan')):6.1f}±{r.get('Fc_measured_2sd[N]', float('nan')):5.1f} "
              f"{r.get('Fc_error[%]', float('nan')):6.1f} {r['Ff[N]']:6.1f} {r.get('Ff_measured[N]', float('nan')):5.1f}±{r.get('Ff_measured_2sd[N]', float('nan')):5.1f} "
              f"{r.get('Ff_error[%]', float('nan')):6.1f} {r['chip_ratio']:5.2f} {r['mu_weighted']:5.3f}")
    if not args.no_plots:
        plot(traces, table, args.out)
        plot_contact_states([os.path.join(campaign, "runs", r["run"]) for r in table if "mufric" in r["friction"]], args.out)
    return 0


def read_states(folder):
    path = os.path.join(folder, "states.csv")
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]


def read_box(folder, model="ti6al4v_tin"):
    """The model's box as the run's query log wrote it ({input: (lo, hi)}, SI)."""
    path = os.path.join(folder, "uncertain", model + ".outside.json")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        log = json.load(f)
    return {i["name"]: (i["box_lo"], i["box_hi"]) for i in log["inputs"]}


def plot_contact_states(mufric_folders, out):
    """What the meso code asked: each logged step's contact states (p, v, T) against the model's box,
    answered inside (OK) or outside by the clamp policy (EXTRAPOLATED), with the share per input."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    runs = [(os.path.basename(folder), read_states(folder), read_box(folder)) for folder in mufric_folders]
    runs = [r for r in runs if r[1] and r[2]]
    if not runs:
        return
    fig, axes = plt.subplots(len(runs), 2, figsize=(12, 4.2 * len(runs)), squeeze=False)
    for row, (name, states, box) in enumerate(runs):
        p = [s["contact_pressure[Pa]"] / 1e6 for s in states]
        v = [max(s["sliding_velocity[m/s]"] * 60, 1e-4) for s in states]
        t = [s["temperature[K]"] - 273.15 for s in states]
        inside = [s["status"] == 0 for s in states]
        (plo, phi), (vlo, vhi), (tlo, thi) = (box["contact_pressure"], box["sliding_velocity"], box["temperature"])
        share = 100.0 * (1 - sum(inside) / len(inside))
        for ax, y, (ylo, yhi), label, logy in ((axes[row][0], v, (vlo * 60, vhi * 60), "sliding velocity (m/min)", True),
                                              (axes[row][1], t, (tlo - 273.15, thi - 273.15), "temperature (°C)", False)):
            for flag, colour, what in ((True, "tab:blue", "inside the box (OK)"), (False, "tab:orange", "outside: clamped")):
                ax.scatter([a for a, i in zip(p, inside) if i == flag], [b for b, i in zip(y, inside) if i == flag],
                           s=2, alpha=0.4, color=colour, label=what)
            ax.add_patch(plt.Rectangle((plo / 1e6, ylo), (phi - plo) / 1e6, yhi - ylo, fill=False, color="k", lw=1.2))
            ax.set_xscale("log")
            if logy:
                ax.set_yscale("log")
            ax.set_xlabel("contact pressure (MPa)")
            ax.set_ylabel(label)
            ax.grid(alpha=0.3)
        axes[row][0].set_title(f"{name}: {len(states)} contact states, {share:.0f} % outside the box (black)", fontsize=9)
        axes[row][0].legend(fontsize=7, markerscale=4)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "contact_states.png"), dpi=110)
    plt.close(fig)


def plot(traces, table, out):
    """Fc and Ff against travel, one row of panels per cutting condition, every friction input of
    that condition in it, the measured mean (dashed) and its 2 sigma (grey band)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    conditions = sorted({(v, h) for _, v, h, _, _ in traces})
    fig, axes = plt.subplots(len(conditions), 2, figsize=(12, 3.8 * len(conditions)), squeeze=False)
    for row, (v, h) in enumerate(conditions):
        for name, rv, rh, forces, m in traces:
            if (rv, rh) != (v, h):
                continue
            x = [r["travel[m]"] * 1e3 for r in forces]
            for ax, key in ((axes[row][0], "Fc[N/mm]"), (axes[row][1], "Ff[N/mm]")):
                ax.plot(x, [r[key] for r in forces], lw=0.8, label=name)
        m = next((m for _, rv, rh, _, m in traces if (rv, rh) == (v, h) and m), None)
        for ax, mkey, label in ((axes[row][0], "Fc", "cutting force Fc"), (axes[row][1], "Ff", "feed force Ff")):
            if m:
                mean, sd2 = m[f"{mkey}_exp_mean[N]"], m[f"{mkey}_exp_2sd[N]"]
                ax.axhspan(mean - sd2, mean + sd2, color="grey", alpha=0.15)
                ax.axhline(mean, color="k", ls="--", lw=0.8)
            ax.set_ylabel(f"{label} (N, 1 mm width)")
            ax.set_xlabel("tool travel (mm)")
            ax.set_title(f"{v:g} m/min, h = {h:g} um", fontsize=9)
            ax.grid(alpha=0.3)
        axes[row][0].legend(fontsize=7)
    fig.suptitle("mfree_iwf-ul-cut-refine (2D SPH) against the measured cuts (dashed: mean, band: 2 sigma)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "forces.png"), dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())
