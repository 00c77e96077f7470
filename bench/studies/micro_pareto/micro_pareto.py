#!/usr/bin/env python3
"""The micro-model's run time against its error (bench/studies/micro_pareto/README.md, "Run time against error"): the
well-defined mu of a shipped scene (press-slide protocol) at the box centre over spline degree x
elements x sliding step, every level on the same 4 synthetic tools so that the error against the
finest level is paired (tool by tool); and the statistical error of the mean over k tools, from the
spread of the finest level's 8 tools. The combined error of a level with k tools is
sqrt(bias^2 + se(bias)^2 + s^2/k): the paired bias over 4 tools is itself uncertain, and a level is
not credited with a small bias it cannot show. Its cost is the one-core seconds per tool times k.

  /usr/bin/python3 bench/studies/micro_pareto/micro_pareto.py MUFRIC OUT_DIR [dry|lubricated] [--set key=value ...]

dry (the default): degree 2 and 3 x 32x6 / 64x12 / 96x18 x 50 / 25 / 12.5 nm against degree 3,
128 x 24, 12.5 nm. lubricated (micro/scene/lubricated_default.json): degree 2 x 32x6 / 64x12 / 96x18
x 50 / 25 nm against degree 2, 128 x 24, 25 nm (the lubricant's coupling was built and verified at
degree 2, and its ninth pass found a finer step no help: bench/studies/lubricant/README.md).
Prints markdown tables (every level; the Pareto front) and writes OUT_DIR/micro_pareto[_lubricated].csv
and .png. Every run's result.json is kept in OUT_DIR (a study resumes).
"""
import csv
import math
import os
import sys
import time

# the press-slide studies' runner, bench/studies/press_slide_protocol/mu_protocol.py
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "press_slide_protocol"))
from mu_protocol import draw_mus, mean_se, run, study_arguments  # noqa: E402  (the same runner, resumable)

SCENE_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "micro", "scene")
# Per scene: the scene file (None: mufric's default dry scene), the levels, the finest level and the
# shipped default (degree, mesh, step [nm], tools).
STUDIES = {
    "dry": {"scene": None, "degrees": (2, 3), "meshes": ((32, 6), (64, 12), (96, 18)), "steps_nm": (50, 25, 12.5),
            "finest": (3, (128, 24), 12.5), "default": (2, "64x12", 25, 4)},
    "lubricated": {"scene": os.path.join(SCENE_DIR, "lubricated_default.json"), "degrees": (2,),
                   "meshes": ((32, 6), (64, 12), (96, 18)), "steps_nm": (50, 25),
                   "finest": (2, (128, 24), 25), "default": (2, "64x12", 25, 4)},
}
TOOLS = 4          # every level: the same 4 tools (seeds 2-5), paired against the finest level
FINEST_TOOLS = 8   # the finest level also runs 8, for the spread over tools
DRAW_COUNTS = (1, 2, 4, 8, 16)


def overrides(degree, mesh, step_nm, tools):
    nx, ny = mesh
    o = [f"discretisation.degree={degree}", f"discretisation.elements_x={nx}", f"discretisation.elements_y={ny}",
         f"protocol.step_distance={step_nm}nm", f"protocol.realisations={tools}"]
    if nx < 64:  # 32 elements along x need the 32-point surface fits of deploy/coarse_scene.sh
        o += [f"geometry.{s}_surface.fit.control_points=32" for s in ("chip", "tool")]
    return o


def name(study, degree, mesh, step_nm, tools=TOOLS):
    prefix = "" if study == "dry" else study + "-"  # the dry study's runs keep their names (it resumes)
    return f"{prefix}p{degree}-{mesh[0]}x{mesh[1]}-step{step_nm}nm-tools{tools}"


def main():
    mufric, out, words, extra = study_arguments(__doc__)
    study = words[0] if words else "dry"
    if study not in STUDIES or len(words) > 1:
        sys.exit(f"expected one scene, dry or lubricated; got {' '.join(words)}\n\n{__doc__}")
    cfg = STUDIES[study]
    scene, degrees, meshes, steps, finest_level, default_level = (
        cfg["scene"], cfg["degrees"], cfg["meshes"], cfg["steps_nm"], cfg["finest"], cfg["default"])
    suffix = "" if study == "dry" else "_" + study
    print(f"`{' '.join(sys.argv)}` on {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {os.cpu_count()} cores\n")
    # The cheap levels first, the finest last: a study cut short has the levels' runs to resume from.
    levels = [(degree, mesh, step) for degree in degrees for mesh in meshes for step in steps]
    results = [run(mufric, out, name(study, *level), extra + overrides(*level, TOOLS), scene) for level in levels]
    finest = run(mufric, out, name(study, *finest_level, FINEST_TOOLS),
                 extra + overrides(*finest_level, FINEST_TOOLS), scene)
    if not finest.get("completed"):
        sys.exit(f"the finest level did not complete: {finest.get('reason', '')}")
    finest_mus = draw_mus(finest)
    reference = finest_mus[:TOOLS]  # the same seeds as every level's 4 tools
    mu_ref = sum(reference) / TOOLS
    _, se8 = mean_se(finest_mus)
    spread = se8 * math.sqrt(len(finest_mus))  # the standard deviation of one tool's mu
    rows = []
    for (degree, mesh, step), r in zip(levels, results):
        if not r.get("completed"):
            rows.append({"degree": degree, "mesh": f"{mesh[0]}x{mesh[1]}", "step_nm": step, "failed": r.get("reason", "")})
            continue
        diffs = [b - a for a, b in zip(reference, draw_mus(r))]
        bias, bias_se = mean_se(diffs)
        rows.append({"degree": degree, "mesh": f"{mesh[0]}x{mesh[1]}", "step_nm": step, "mu": r["mu"],
                     "bias": bias, "bias_se": bias_se, "seconds_per_tool": r["diagnostics"]["draw_seconds_sum"] / TOOLS})
    finest_cost = finest["diagnostics"]["draw_seconds_sum"] / len(finest_mus)
    rows.append({"degree": finest_level[0], "mesh": f"{finest_level[1][0]}x{finest_level[1][1]}", "step_nm": finest_level[2], "mu": mu_ref,
                 "bias": 0.0, "bias_se": 0.0, "seconds_per_tool": finest_cost})
    print(f"Finest level (degree {finest_level[0]}, {finest_level[1][0]} x {finest_level[1][1]}, step {finest_level[2]} nm): mu over its first "
          f"{TOOLS} tools {mu_ref:.5f}; over {len(finest_mus)} tools {sum(finest_mus) / len(finest_mus):.5f} ± {se8:.5f}; "
          f"one tool's standard deviation {spread:.5f} ({100 * spread / mu_ref:.1f} %)\n")
    print("| degree | mesh | step [nm] | mu (4 tools) | paired change vs finest | one-core s per tool |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        if "failed" in r:
            print(f"| {r['degree']} | {r['mesh']} | {r['step_nm']} | failed: {r['failed'][:60]} | | |")
            continue
        print(f"| {r['degree']} | {r['mesh']} | {r['step_nm']} | {r['mu']:.5f} | "
              f"{100 * r['bias'] / mu_ref:+.2f} % ± {100 * r['bias_se'] / mu_ref:.2f} % | {r['seconds_per_tool']:.1f} |")
    # Every (level, k tools): the error of the mean against the converged, infinitely-many-tools mu.
    points = []
    for r in rows:
        if "failed" in r:
            continue
        for k in DRAW_COUNTS:
            error = math.sqrt(r["bias"] ** 2 + r["bias_se"] ** 2 + spread ** 2 / k) / mu_ref
            points.append({**r, "tools": k, "error": error, "cost": r["seconds_per_tool"] * k})
    points.sort(key=lambda p: p["cost"])
    front, best = [], float("inf")
    for p in points:
        if p["error"] < best:
            front.append(p)
            best = p["error"]
    with open(os.path.join(out, f"micro_pareto{suffix}.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["degree", "mesh", "step_nm", "tools", "mu", "bias", "bias_se",
                                          "seconds_per_tool", "error", "cost", "pareto"])
        w.writeheader()
        for p in points:
            w.writerow({k: p[k] for k in w.fieldnames if k != "pareto"} | {"pareto": p in front})
    print("\nPareto front (error = sqrt(bias^2 + se(bias)^2 + s^2/k) relative to mu; cost = one-core seconds for k tools):\n")
    print("| degree | mesh | step [nm] | tools k | relative error | one-core seconds |")
    print("|---|---|---|---|---|---|")
    for p in front:
        print(f"| {p['degree']} | {p['mesh']} | {p['step_nm']} | {p['tools']} | {100 * p['error']:.2f} % | {p['cost']:.0f} |")
    default = next((p for p in points if (p["degree"], p["mesh"], p["step_nm"], p["tools"]) == default_level), None)
    if default:
        dominated = [p for p in front if p["cost"] <= default["cost"] and p["error"] < default["error"]]
        print(f"\nThe default {study} scene (degree {default_level[0]}, {default_level[1]}, {default_level[2]} nm, "
              f"{default_level[3]} tools): error "
              f"{100 * default['error']:.2f} % for {default['cost']:.0f} one-core seconds; "
              + ("on the front" if not dominated else
                 "beaten by " + ", ".join(f"p{p['degree']} {p['mesh']} {p['step_nm']} nm k={p['tools']} "
                                          f"({100 * p['error']:.2f} %, {p['cost']:.0f} s)" for p in dominated)))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.3))
    for degree, colour in zip(degrees, ("C0", "C1")):
        for mesh, marker in zip([f"{a}x{b}" for a, b in meshes], ("o", "s", "^")):
            sel = [r for r in rows if "failed" not in r and r["degree"] == degree and r["mesh"] == mesh and r["bias"] != 0.0]
            if sel:
                axes[0].errorbar([r["seconds_per_tool"] for r in sel], [100 * abs(r["bias"]) / mu_ref for r in sel],
                                 yerr=[100 * r["bias_se"] / mu_ref for r in sel], fmt=marker + "-", color=colour,
                                 label=f"degree {degree}, {mesh} (steps {', '.join(str(s) for s in steps)} nm)")
    axes[0].set(xscale="log", yscale="log", xlabel="one-core seconds per tool",
                ylabel="|paired change vs finest| [%]", title="discretisation error (4 tools, paired)")
    axes[0].legend(fontsize=6.5)
    axes[1].scatter([p["cost"] for p in points], [100 * p["error"] for p in points], s=8, alpha=0.4, label="level x k tools")
    if default:
        axes[1].plot([default["cost"]], [100 * default["error"]], "k*", markersize=12, label=f"default {study} scene")
    axes[1].step([p["cost"] for p in front], [100 * p["error"] for p in front], "r-", where="post", label="Pareto front")
    for p in front:
        axes[1].annotate(f"p{p['degree']} {p['mesh']} {p['step_nm']}nm k={p['tools']}", (p["cost"], 100 * p["error"]),
                         fontsize=6)
    axes[1].set(xscale="log", yscale="log", xlabel="one-core seconds for one mu",
                ylabel="error of mu [%] (discretisation and tools)", title=f"run time against error ({study} scene)")
    axes[1].legend(fontsize=7)
    for a in axes:
        a.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(out, f"micro_pareto{suffix}.png"), dpi=120)
    print(f"\nwrote {out}/micro_pareto{suffix}.csv and {out}/micro_pareto{suffix}.png")


if __name__ == "__main__":
    main()
