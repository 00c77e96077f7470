#!/usr/bin/env python3
"""Why a lubricated run stopped: the last accepted steps before the stop and the failed attempts at
the stopping step, from a run's result.json and (optionally) its MUFRIC_TRACE_COUPLING=1 stderr.

Per accepted step: sliding distance, contact fraction, the film's share of the normal load, the
pockets (count and the smallest), the liquid and the cavitated fraction. At the stop: every failed
attempt's reason and, from the trace, the largest change of the film's traction between two
exchanges. Then the slot-flow estimate of the pressure that pushes a shrinking pocket's liquid through
the minimum film over a contact spot, Δp = 12 η L q / h³ (plane Poiseuille flow in a slot of height h
and length L carrying q per unit depth; e.g. Hamrock, Fundamentals of Fluid Film Lubrication, ch. 7),
with q the smallest pocket's measured rate of loss and L the mean spot length.

  /usr/bin/python3 bench/tools/sealed_stop_report.py RUN/result.json [RUN/trace.log]
"""
import json
import re
import sys


def parse_quantity(text, unit_scale):
    m = re.match(r"\s*([-+\d.eE]+)\s*([a-zA-Z]*)", str(text))
    value, unit = float(m.group(1)), m.group(2)
    return value * unit_scale.get(unit, 1.0)


def trace_jumps(path):
    """The largest |dlambda| per traced coupled step (by its end time), and the step's outcome line."""
    steps, current = [], None
    with open(path) as f:
        for line in f:
            head = re.match(r"coupling t ([\d.eE+-]+) dt ([\d.eE+-]+): (.*)", line)
            if head:
                current = {"t": float(head.group(1)), "dt": float(head.group(2)), "outcome": head.group(3).strip(), "jump": 0.0}
                steps.append(current)
                continue
            jump = re.match(r"\s*\|dlambda\| ([\d.eE+-]+) Pa", line)
            if jump and current is not None:
                current["jump"] = max(current["jump"], float(jump.group(1)))
    return steps


def main():
    result = json.load(open(sys.argv[1]))
    scene = result["scene"]
    lub = scene.get("lubricant", {})
    viscosity = float(lub.get("viscosity", 0.032))
    min_film = parse_quantity(lub.get("min_film", "20nm"), {"nm": 1e-9, "um": 1e-6, "m": 1.0})
    interval = None
    for draw in result["draws"]:
        history = draw["history"]
        print(f"## draw: tool seed {draw.get('tool_seed')}, completed {draw['completed']}")
        if draw["completed"]:
            print(f"mu {draw['mu']:.4f}")
        cutbacks = draw.get("cutbacks", [])
        last = history[-1]
        print(f"last accepted step: t {last['time_s']:.4e} s, slid {last['sliding_distance_m'] * 1e6:.3f} um; cut-backs {len(cutbacks)}")
        print("| slid [um] | contact | film's share of F_y | pockets | smallest pocket [m2/m] | liquid [m2/m] | cavitated |")
        print("|---|---|---|---|---|---|---|")
        for h in history[-8:]:
            pockets = h.get("pocket_areas_m2_per_m") or []
            share = h["fluid_force_y_n_per_m"] / h["force_y_n_per_m"] if h["force_y_n_per_m"] else 0.0
            smallest = min(pockets) if pockets else float("nan")
            print(f"| {h['sliding_distance_m'] * 1e6:.4f} | {h['contact_area_fraction']:.3f} | {share:.3f} | {len(pockets)} | "
                  f"{smallest:.3e} | {h['liquid_area_m2_per_m']:.3e} | {h['cavitated_fraction']:.3f} |")
        if draw["completed"]:
            continue
        stop_time = last["time_s"]
        at_stop = [c for c in cutbacks if c["time_s"] >= stop_time * (1 - 1e-12)]
        print(f"failed attempts at the stopping step: {len(at_stop)}, dt down to {min((c['dt_failed_s'] for c in at_stop), default=float('nan')):.3e} s")
        reasons = {}
        for c in at_stop:
            key = re.sub(r"[\d.eE+-]{4,}", "#", c["reason"])[:120]
            reasons[key] = reasons.get(key, 0) + 1
        for reason, n in sorted(reasons.items(), key=lambda kv: -kv[1]):
            print(f"  {n} x {reason}")
        # The smallest pocket's rate of loss over the last accepted steps, and the slot-flow pressure it needs.
        tail = [h for h in history[-6:] if h.get("pocket_areas_m2_per_m")]
        if len(tail) >= 2:
            a0, a1 = min(tail[0]["pocket_areas_m2_per_m"]), min(tail[-1]["pocket_areas_m2_per_m"])
            dt = tail[-1]["time_s"] - tail[0]["time_s"]
            q = max(0.0, (a0 - a1) / dt)
            if interval is None:
                interval = parse_quantity(scene["geometry"].get("interval", "10um"), {"um": 1e-6, "nm": 1e-9, "m": 1.0})
            spots = max(1, len(tail[-1]["pocket_areas_m2_per_m"]))
            spot_length = tail[-1]["contact_area_fraction"] * interval / spots
            dp = 12 * viscosity * spot_length * q / min_film ** 3
            print(f"smallest pocket: {a0:.3e} -> {a1:.3e} m2/m in {dt:.3e} s (q = {q:.3e} m2/s); mean spot {spot_length * 1e6:.3f} um; "
                  f"slot flow through h = {min_film * 1e9:.0f} nm needs dp = 12 eta L q / h^3 = {dp:.3e} Pa")
    if len(sys.argv) > 2:
        steps = trace_jumps(sys.argv[2])
        failed = [s for s in steps if "converged" not in s["outcome"]]
        print(f"trace: {len(steps)} traced coupled attempts, {len(failed)} not converged")
        for s in failed[-6:]:
            print(f"  t {s['t']:.6e} dt {s['dt']:.2e}: largest traction change between exchanges {s['jump']:.3e} Pa; {s['outcome'][:90]}")


if __name__ == "__main__":
    main()
