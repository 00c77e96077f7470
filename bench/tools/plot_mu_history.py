#!/usr/bin/env python3
"""Plots what a press-slide measurement did: for every draw (tool realisation / phase), eq. 17's mu at
every step against the sliding distance, its running mean over the averaging window, and the window
itself, so that a drift or a ploughing episode is seen at a glance.

  /usr/bin/python3 bench/tools/plot_mu_history.py RESULT_JSON OUT_PNG [TITLE]

RESULT_JSON is what `mufric micro run` wrote (OUT/result.json).
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    r = json.load(open(sys.argv[1]))
    p = r["protocol"]
    if p.get("name") != "press-slide":
        sys.exit(f"{sys.argv[1]}: not a press-slide result (protocol {p.get('name')})")
    lo, hi = p["run_in_m"] * 1e6, (p["run_in_m"] + p["window_m"]) * 1e6
    fig, ax = plt.subplots(figsize=(8, 4.5))
    ax.axvspan(lo, hi, color="0.92", label="averaging window")
    for k, d in enumerate(r["draws"]):
        h = [s for s in d["history"] if s["mu"] is not None and s["sliding_distance_m"] > 0]
        s = [x["sliding_distance_m"] * 1e6 for x in h]
        mu = [x["mu"] for x in h]
        line, = ax.plot(s, mu, lw=0.6, alpha=0.6)
        running, xs, total, weight, prev = [], [], 0.0, 0.0, None
        for x, m in zip(s, mu):  # the same rectangle rule as mufric: each step's mu over its segment
            if prev is not None and x > lo:
                a, b = max(prev, lo), min(x, hi)
                if b > a:
                    total += m * (b - a)
                    weight += b - a
                    xs.append(b)
                    running.append(total / weight)
            prev = x
        label = f"tool seed {d['tool_seed']}, shift {d['tool_shift_fraction']:.2f}: {d['mu']:.4f}"
        ax.plot(xs, running, lw=2.0, color=line.get_color(), label=label)
    se = r.get("mu_std_error")
    ax.axhline(r["mu"], color="k", ls="--", lw=1,
               label=f"mu = {r['mu']:.4f}" + (f" ± {se:.4f} (s.e.)" if se else ""))
    ax.set_xlabel("sliding distance [µm]")
    ax.set_ylabel("mu (thin: each step; thick: running mean over the window)")
    scene = r["scene"].get("load", {})
    ax.set_title(sys.argv[3] if len(sys.argv) > 3 else
                 f"press-slide: {scene.get('pressure', '')}, {scene.get('velocity', '')}, {scene.get('temperature', '')}")
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    fig.savefig(sys.argv[2], dpi=120)
    print(f"wrote {sys.argv[2]}")


if __name__ == "__main__":
    main()
