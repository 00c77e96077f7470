#!/usr/bin/env python3
"""The press-slide protocol's studies (bench/studies/press_slide_protocol/README.md, "What mu means"): each run is one `mufric
micro run` of the default scene with overrides; prints markdown tables.

  /usr/bin/python3 bench/studies/press_slide_protocol/mu_protocol.py MUFRIC OUT_DIR [STUDY ...] [--set key=value ...]

Studies: ramp (pressing ramp and hold x4, paired per draw), window (block means over a long slide),
step (sliding step 12.5/25/50 nm), heat (adiabatic / conduction / isothermal, paired), draws
(variance of mu over tool phases and realisations), seed000 (the paper's protocol beside), trends
(mu(p), mu(v), mu(T) through the box centre, both protocols), mesh (32 x 6 to 128 x 24, paired over
8 tools, with the one-core cost of each). The first five ran with the scene's
protocol set to 4 tool phases, 0.5 um run-in (the values before the study chose the default). Extra
--set overrides apply to every run (e.g. the mesh). Every result.json is kept in OUT_DIR.
"""
import json
import math
import os
import subprocess
import sys
import time


def run(mufric, out, name, overrides, scene=None):
    """One `mufric micro run` of `scene` (a JSON file; None: the default dry scene) with overrides."""
    d = os.path.join(out, name)
    cmd = [mufric, "micro", "run"] + ([scene] if scene else []) + ["--quiet", "--out", d]
    for o in overrides:
        cmd += ["--set", o]
    # A run whose result is already there with the same command is read back (a study resumes).
    stamp = os.path.join(d, "command.txt")
    if os.path.exists(stamp) and open(stamp).read() == " ".join(cmd[1:]) and os.path.exists(os.path.join(d, "result.json")):
        r = json.load(open(os.path.join(d, "result.json")))
        r["_wall"] = r["diagnostics"]["wall_seconds"]
        r["_cmd"] = " ".join(cmd)
        return r
    start = time.time()
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode not in (0, 3) or not os.path.exists(os.path.join(d, "result.json")):
        sys.exit(f"{name}: exit {p.returncode}: {p.stdout[-500:]} {p.stderr[-500:]}")
    open(stamp, "w").write(" ".join(cmd[1:]))
    r = json.load(open(os.path.join(d, "result.json")))
    r["_wall"] = time.time() - start
    r["_cmd"] = " ".join(cmd)
    return r


def draw_mus(r):
    return [d["mu"] for d in r["draws"]]


def mean_se(xs):
    n = len(xs)
    m = sum(xs) / n
    if n < 2:
        return m, float("nan")
    return m, math.sqrt(sum((x - m) ** 2 for x in xs) / (n - 1) / n)


def fmt(r):
    se = r["mu_std_error"]
    return f'{r["mu"]:.5f} ± {se:.5f} ({100 * se / r["mu"]:.2f} %)' if se else f'{r["mu"]:.5f}'


def paired(base, other):
    diffs = [b - a for a, b in zip(draw_mus(base), draw_mus(other))]
    m, se = mean_se(diffs)
    return f"{100 * m / base['mu']:+.2f} % ± {100 * se / base['mu']:.2f} %"


def table(rows, header):
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for row in rows:
        print("| " + " | ".join(str(c) for c in row) + " |")
    print()


def study_ramp(m, out, extra):
    print("### Pressing: ramp and hold x4 (paired per draw, 4 tool phases)\n")
    base = run(m, out, "ramp-25-hold-25", extra)
    rows = [("25 ns", "25 ns", fmt(base), "", f'{base["_wall"]:.0f}')]
    for ramp, hold in (("100ns", "25ns"), ("25ns", "100ns"), ("6.25ns", "25ns")):
        r = run(m, out, f"ramp-{ramp}-hold-{hold}", extra + [f"load.ramp={ramp}", f"protocol.press_hold={hold}"])
        rows.append((ramp, hold, fmt(r), paired(base, r), f'{r["_wall"]:.0f}'))
    table(rows, ["ramp", "hold", "mu ± s.e.", "paired change vs 25/25", "wall [s]"])


def study_window(m, out, extra):
    print("### Window: 8 blocks of 0.625 um over a 5 um slide after a 0.5 um run-in (4 tool phases)\n")
    r = run(m, out, "window-5um", extra + ["protocol.window=5um", "protocol.blocks=8"])
    blocks = [d["block_means"] for d in r["draws"]]
    rows = []
    for k in range(8):
        col = [b[k] for b in blocks]
        mm, se = mean_se(col)
        rows.append((f"{0.5 + 0.625 * k:.3f}-{0.5 + 0.625 * (k + 1):.3f}", f"{mm:.5f} ± {se:.5f}"))
    table(rows, ["sliding distance [um]", "mean over phases ± s.e."])
    first = [sum(b[:4]) / 4 for b in blocks]
    second = [sum(b[4:]) / 4 for b in blocks]
    diffs = [b - a for a, b in zip(first, second)]
    md, sd = mean_se(diffs)
    print(f"first half (0.5-3.0 um) {mean_se(first)[0]:.5f}, second half (3.0-5.5 um) {mean_se(second)[0]:.5f}: "
          f"paired difference {100 * md / r['mu']:+.2f} % ± {100 * sd / r['mu']:.2f} %; max temperature "
          f"{r['diagnostics']['max_temperature_k'] - 273.15:.0f} C; wall {r['_wall']:.0f} s\n")


def study_step(m, out, extra):
    print("### Sliding step (4 tool phases, paired against 12.5 nm)\n")
    base = run(m, out, "step-12.5nm", extra + ["protocol.step_distance=12.5nm"])
    rows = [("12.5 nm", fmt(base), "", base["diagnostics"]["newton_iterations"], f'{base["_wall"]:.0f}')]
    for s in ("25nm", "50nm", "100nm"):
        r = run(m, out, f"step-{s}", extra + [f"protocol.step_distance={s}"])
        rows.append((s, fmt(r), paired(base, r), r["diagnostics"]["newton_iterations"], f'{r["_wall"]:.0f}'))
    table(rows, ["step", "mu ± s.e.", "paired change", "Newton iterations", "wall [s]"])


def study_heat(m, out, extra):
    print("### Heat (4 tool phases, paired against conduction)\n")
    base = run(m, out, "heat-conduction", extra)
    rows = [("conduction (k = 50 W/m K)", fmt(base), "", f'{base["diagnostics"]["max_temperature_k"] - 273.15:.0f}')]
    for name, o in (("adiabatic", ["thermal.model=adiabatic"]), ("isothermal (no heating)", ["material.heat_fraction=0"])):
        r = run(m, out, "heat-" + name.split()[0], extra + o)
        rows.append((name, fmt(r), paired(base, r), f'{r["diagnostics"]["max_temperature_k"] - 273.15:.0f}'))
    table(rows, ["heat", "mu ± s.e.", "paired change", "max T [C]"])


def study_draws(m, out, extra):
    print("### Draws: 4 tool realisations x 4 phases\n")
    r = run(m, out, "draws-4x4", extra + ["protocol.phases=4", "protocol.realisations=4"])
    mus = draw_mus(r)
    by_real = [mus[4 * k:4 * k + 4] for k in range(4)]
    rows = []
    for k, xs in enumerate(by_real):
        mm, se = mean_se(xs)
        rows.append((f"seed {r['draws'][4 * k]['tool_seed']}", " ".join(f"{x:.4f}" for x in xs), f"{mm:.5f} ± {se:.5f}"))
    table(rows, ["tool", "mu of phases 0, 1/4, 1/2, 3/4", "mean ± s.e. over phases"])
    within = sum(sum((x - sum(xs) / 4) ** 2 for x in xs) for xs in by_real) / (4 * 3)
    means = [sum(xs) / 4 for xs in by_real]
    between = sum((x - sum(means) / 4) ** 2 for x in means) / 3 - within / 4
    print(f"all 16: {fmt(r)}; variance components: phase within a tool {math.sqrt(within):.4f} (std), "
          f"between tools {math.sqrt(max(between, 0)):.4f} (std of a tool's full-period mean); wall {r['_wall']:.0f} s\n")
    for nr, npz in ((1, 4), (2, 2), (4, 1), (8, 1), (16, 1)):
        se = math.sqrt(max(between, 0) / nr + within / (nr * npz))
        print(f"- predicted s.e. with {nr} realisations x {npz} phases: {se:.4f} ({100 * se / r['mu']:.1f} %)")
    print()


def study_seed000(m, out, extra):
    print("### Seed 000's protocol beside (one draw, ramp while sliding, 250 ns)\n")
    rows = []
    for ramp in ("12.5ns", "25ns", "50ns"):
        r = run(m, out, f"seed000-ramp-{ramp}", extra + ["protocol.name=seed-000", f"load.ramp={ramp}"])
        rows.append((ramp, fmt(r), f'{r["_wall"]:.0f}'))
    table(rows, ["ramp", "mu", "wall [s]"])


def study_trends(m, out, extra):
    print("### Trends through the box centre (800 MPa, 111.25 m/min, 462.5 C), both protocols\n")
    centre = {"p": "800MPa", "v": "111.25m/min", "T": "462.5C"}
    keys = {"p": "load.pressure", "v": "load.velocity", "T": "load.temperature"}
    values = {"p": ["300MPa", "800MPa", "1300MPa"], "v": ["22.5m/min", "111.25m/min", "200m/min"],
              "T": ["25C", "462.5C", "900C"]}
    cache = {}
    rows = []
    for axis in ("p", "v", "T"):
        for value in values[axis]:
            point = dict(centre, **{axis: value})
            key = tuple(sorted(point.items()))
            if key not in cache:
                sets = [f"{keys[k]}={point[k]}" for k in ("p", "v", "T")]
                tag = "-".join(point[k].replace("/", "_") for k in ("p", "v", "T"))
                ps = run(m, out, "trend-ps-" + tag, extra + sets)
                s0 = run(m, out, "trend-s0-" + tag, extra + sets + ["protocol.name=seed-000"])
                cache[key] = (ps, s0)
            ps, s0 = cache[key]
            molten = " (molten)" if any("melting" in w for w in ps.get("warnings", [])) else ""
            rows.append((axis, value, fmt(ps) + molten, fmt(s0), f'{ps["_wall"]:.0f}'))
    table(rows, ["varied", "value", "press-slide mu ± s.e.", "seed 000 protocol mu", "press-slide wall [s]"])


def study_mesh(m, out, extra):
    print("### Mesh, paired over 8 tools (the default protocol otherwise)\n")
    finest = run(m, out, "mesh-128x24", extra + ["protocol.realisations=8", "discretisation.elements_x=128",
                                                   "discretisation.elements_y=24"])
    rows = []
    for nx, ny in ((32, 6), (64, 12), (96, 18)):
        # 32 elements along x need the 32-point surface fits of deploy/coarse_scene.sh
        fits = [f"geometry.{s}_surface.fit.control_points=32" for s in ("chip", "tool")] if nx < 64 else []
        r = run(m, out, f"mesh-{nx}x{ny}", extra + fits + ["protocol.realisations=8", f"discretisation.elements_x={nx}",
                                                             f"discretisation.elements_y={ny}"])
        rows.append((f"{nx} x {ny}", fmt(r), paired(finest, r), f'{r["diagnostics"]["draw_seconds_sum"]:.0f}'))
    rows.append(("128 x 24", fmt(finest), "", f'{finest["diagnostics"]["draw_seconds_sum"]:.0f}'))
    table(rows, ["mesh", "mu ± s.e.", "paired change vs 128 x 24", "one-core seconds (sum over draws)"])


STUDIES = {"ramp": study_ramp, "window": study_window, "step": study_step, "heat": study_heat,
           "draws": study_draws, "seed000": study_seed000, "trends": study_trends,
           "mesh": study_mesh}


def study_arguments(usage):
    """MUFRIC OUT_DIR [words ...] [--set key=value ...] from the command line: the executable, the output
    directory (created), the words that are not --set pairs, and the --set overrides."""
    if len(sys.argv) < 3:
        sys.exit(usage)
    mufric, out = sys.argv[1], sys.argv[2]
    args = sys.argv[3:]
    extra = [args[i + 1] for i, a in enumerate(args) if a == "--set"]
    words = [a for i, a in enumerate(args) if a != "--set" and (i == 0 or args[i - 1] != "--set")]
    os.makedirs(out, exist_ok=True)
    return mufric, out, words, extra


def main():
    mufric, out, names, extra = study_arguments(__doc__)
    names = names or list(STUDIES)
    print(f"`{' '.join(sys.argv)}` on {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {os.cpu_count()} cores\n")
    for n in names:
        if n not in STUDIES:
            sys.exit(f"unknown study '{n}'; one of {', '.join(STUDIES)}")
        STUDIES[n](mufric, out, extra)


if __name__ == "__main__":
    main()
