#!/usr/bin/env python3
"""What a draw is worth: its variance against its cost, with the window length and the cell width as
the levers (issue 33). From `micro run` results (result.json) of many draws at one load:
  - a run with a long window (e.g. --set protocol.window=5um): each draw's μ re-averaged from its own
    history over windows of 1/4, 2/4, 3/4 and all of it after the same run-in (the micro-model's rule:
    each step's μ stands for its segment of sliding distance), its cost up to the window's end from the
    Newton iterations spent so far (a share of the draw's wall time);
  - runs of other scenes (e.g. a cell twice as wide) as they are, their cost the draws' wall time.
The figure of merit is variance x cost per draw: the cost of a given standard error of the mean.
  /usr/bin/python3 bench/studies/served_interval/draw_levers.py LONG_WINDOW/result.json [OTHER/result.json ...]"""
import json
import sys

import numpy as np


def window_mean(history, start, end):
    total = weight = 0.0
    before = None
    for h in history:
        s, mu = h["sliding_distance_m"], h["mu"]
        if before is not None and mu is not None:
            a, b = max(before, start), min(s, end)
            if b > a:
                total += mu * (b - a)
                weight += b - a
        before = s
    return total / weight if weight > 0 else float("nan")


def cost_until(draw, end):
    """Seconds of this draw until sliding distance `end`: its wall time x the share of its Newton iterations."""
    spent = sum(h["newton_iterations"] for h in draw["history"] if h["sliding_distance_m"] <= end + 1e-12)
    total = sum(h["newton_iterations"] for h in draw["history"])
    return draw["diagnostics"]["wall_seconds"] * spent / total


def row(label, mus, costs, reference):
    mus, costs = np.array(mus), np.array(costs)
    std, cost = np.std(mus, ddof=1), np.mean(costs)
    merit = std ** 2 * cost
    relative = "1.00 (reference)" if reference is None else f"{merit / reference:.2f}"
    print(f"| {label} | {len(mus)} | {np.mean(mus):.4f} | {std:.4f} ({100 * std / np.mean(mus):.1f} %) | "
          f"{cost:.1f} | {relative} |")
    return merit


print("| scene | draws | mean μ | per-draw std | one core per draw [s] | variance x cost vs default |")
print("|---|---|---|---|---|---|")
long_run = json.load(open(sys.argv[1]))
draws = [d for d in long_run["draws"] if d["completed"]]
run_in, window = long_run["protocol"]["run_in_m"], long_run["protocol"]["window_m"]
reference = None
for quarter in (2, 1, 3, 4):  # the default's 2.5 µm (half of a 5 µm window) first: the reference
    length = window * quarter / 4
    mus = [window_mean(d["history"], run_in, run_in + length) for d in draws]
    costs = [cost_until(d, run_in + length) for d in draws]
    merit = row(f"window {length * 1e6:.3g} µm after {run_in * 1e6:.3g} µm run-in", mus, costs, reference)
    reference = reference or merit
for path in sys.argv[2:]:
    other = json.load(open(path))
    done = [d for d in other["draws"] if d["completed"]]
    scene = other["scene"]
    label = f"cell {scene['geometry']['interval']}, {scene['discretisation']['elements_x']} elements across, " \
            f"window {other['protocol']['window_m'] * 1e6:.3g} µm"
    row(label, [d["mu"] for d in done], [d["diagnostics"]["wall_seconds"] for d in done], reference)
