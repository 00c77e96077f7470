#!/usr/bin/env python3
"""The pressing-then-sliding comparison with an independent FE code (bench/studies/press_slide_protocol/README.md, "The pressing
phase against an independent code"): a flat chip (10 um interval, 5 um high), Johnson-Cook at T* = 0
with no rate term and no heating, displacement-pressed 0.4 um against a rigid sinusoidal tool (one
wavelength over the interval, amplitude 1 um), then slid. Prints the mean contact pressure after
pressing and mu after 0.125, 0.25 and 0.5 um of sliding for each numerical choice varied alone.

  /usr/bin/python3 bench/studies/press_slide_protocol/fe_comparison.py MUFRIC OUT_DIR
"""
import json
import math
import os
import subprocess
import sys


def tool_csv(path, amplitude_um=1.0, samples=1024):
    with open(path, "w") as f:
        f.write("x[um],height[um]\n")
        for k in range(samples):
            x = 10.0 * k / samples
            f.write(f"{x:.12g},{-amplitude_um * math.cos(2 * math.pi * x / 10.0):.12g}\n")


def run(mufric, out, name, tool, extra):
    d = os.path.join(out, name)
    base = ["physics=dry", "geometry.chip_surface={\"flat\": true, \"fit\": {\"degree\": 2, \"control_points\": 64}}",
            f"geometry.tool_surface={{\"csv\": \"{tool}\", \"fit\": {{\"degree\": 3, \"control_points\": 64}}}}",
            "load.pressure=null", "load.vertical_displacement=0.4um", "load.temperature=20C", "material.c=0",
            "material.heat_fraction=0", "thermal.model=adiabatic", "protocol.run_in=0um", "protocol.window=0.5um",
            "protocol.blocks=4", "protocol.phases=1", "protocol.realisations=1"]
    cmd = [mufric, "micro", "run", "--quiet", "--out", d]
    for o in base + extra:
        cmd += ["--set", o]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if not os.path.exists(os.path.join(d, "result.json")):
        return None, p.stdout[-300:] + p.stderr[-300:]
    return json.load(open(os.path.join(d, "result.json"))), ""


def at_distance(history, distance):
    """mu at the first step that has slid at least `distance` (linear interpolation to it)."""
    prev = None
    for s in history:
        if s["sliding_distance_m"] >= distance and s["mu"] is not None:
            if prev is None or prev["mu"] is None:
                return s["mu"]
            t = (distance - prev["sliding_distance_m"]) / (s["sliding_distance_m"] - prev["sliding_distance_m"])
            return prev["mu"] + t * (s["mu"] - prev["mu"])
        prev = s
    return float("nan")


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    mufric, out = sys.argv[1], sys.argv[2]
    os.makedirs(out, exist_ok=True)
    tool = os.path.abspath(os.path.join(out, "sinusoid.csv"))
    tool_csv(tool)
    qs = ["time.scheme=quasi-static"]
    cases = [
        ("default: 64 x 12, graded 2, 5 contact points/span, penalty 2e18, steps <= 4 ns", []),
        ("through the thickness: 64 x 24", ["discretisation.elements_y=24"]),
        ("through the thickness: 64 x 48", ["discretisation.elements_y=48"]),
        ("along x: 128 x 12", ["discretisation.elements_x=128"]),
        ("uniform across the thickness (grading 1)", ["discretisation.grading=1"]),
        ("uniform, 64 x 48", ["discretisation.grading=1", "discretisation.elements_y=48"]),
        ("contact quadrature 10 points/span", ["discretisation.contact_points_per_span=10"]),
        ("penalty 2e19", ["contact.penalty=2e19"]),
        ("penalty 2e17", ["contact.penalty=2e17"]),
        ("pressing steps <= 0.5 ns", ["time.step=0.5ns", "time.max_step=0.5ns"]),
        ("pressing 4x slower (ramp 100 ns)", ["load.ramp=100ns"]),
        ("sliding steps 5 nm", ["protocol.step_distance=5nm"]),
        ("cubic elements", ["discretisation.degree=3"]),
        ("128 x 48 (both refined)", ["discretisation.elements_x=128", "discretisation.elements_y=48"]),
        ("quasi-static: 64 x 12", qs),
        ("quasi-static: pressing steps <= 0.5 ns", qs + ["time.step=0.5ns", "time.max_step=0.5ns"]),
        ("quasi-static: ramp 100 ns", qs + ["load.ramp=100ns"]),
        ("quasi-static: 64 x 24", qs + ["discretisation.elements_y=24"]),
        ("quasi-static: 64 x 48", qs + ["discretisation.elements_y=48"]),
        ("quasi-static: 128 x 12", qs + ["discretisation.elements_x=128"]),
        ("quasi-static: 128 x 48", qs + ["discretisation.elements_x=128", "discretisation.elements_y=48"]),
        ("quasi-static: cubic", qs + ["discretisation.degree=3"]),
        ("quasi-static: contact quadrature 10 points/span", qs + ["discretisation.contact_points_per_span=10"]),
        ("quasi-static: penalty 2e19", qs + ["contact.penalty=2e19"]),
        ("quasi-static: elastic (A = 100 GPa)", qs + ["material.a=100GPa"]),
    ]
    print("| case | mean pressure after pressing [MPa] | mu at 0.125 um | mu at 0.25 um | mu at 0.5 um | wall [s] |")
    print("|---|---|---|---|---|---|")
    for k, (name, extra) in enumerate(cases):
        r, err = run(mufric, out, f"case{k}", tool, extra)
        if r is None or not r["completed"]:
            print(f"| {name} | failed: {(r or {}).get('reason', err)[:100]} | | | | |")
            continue
        draw = r["draws"][0]
        h = draw["history"]
        pressed = [s for s in h if s["sliding_distance_m"] == 0.0][-1]
        mean_p = pressed["force_y_n_per_m"] / 10e-6
        row = [name, f"{abs(mean_p) / 1e6:.1f}"] + [f"{at_distance(h, d):.4f}" for d in (0.125e-6, 0.25e-6, 0.5e-6)]
        print("| " + " | ".join(row) + f" | {r['diagnostics']['wall_seconds']:.0f} |", flush=True)


if __name__ == "__main__":
    main()
