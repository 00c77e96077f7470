#!/usr/bin/env bash
# The frictionless micro-model against the slip-line wave model of Challen & Oxley (1979, Wear
# 53:229, eq. for the wave model): a rigid wedge asperity of slope α sliding on a rigid-perfectly-
# plastic surface with interfacial shear factor f = 0 has μ = tan α (the contact pressure acts
# normal to the leading face, the only face in contact). The check issue 32 asks for before any
# friction law is added: if the frictionless code misses it, it has a defect to find first.
#
# The scene: the default dry scene with a tool of one symmetric triangle per period (flanks of slope
# α, corners rounded only by the spline fit), a flat chip, Johnson-Cook reduced to perfect plasticity
# (B = 0, C = 0, at the transition temperature, no plastic heating) with E/σ_y = 1000, a nominal
# pressure well below the indentation hardness so that only part of the leading face carries load,
# and a finer mesh along x so that the contact spans several elements.
# TOOL_CONTROL_POINTS (environment, default 256) sets how sharply the spline fit keeps the apex: a
# periodic quadratic fit rounds the kink over about two control-point spacings.
#   bash bench/studies/friction_laws/challen_oxley_check.sh build/app/mufric OUT [ALPHAS_DEG] [PRESSURES] [ELEMENTS_X]
# Prints one line per (α, p): μ, tan α and their ratio; each run's result.json stays in OUT.
set -euo pipefail
mufric=${1:?usage: challen_oxley_check.sh MUFRIC OUT [ALPHAS_DEG] [PRESSURES] [ELEMENTS_X]}
out=${2:?output directory}
alphas=${3:-"5 10"}
pressures=${4:-"50MPa"}
elements_x=${5:-128}
tool_control_points=${TOOL_CONTROL_POINTS:-256}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
printf "%-6s %-8s %-9s %-9s %-7s %s\n" "alpha" "p" "mu" "tan(a)" "ratio" "run"
for alpha in $alphas; do
  csv=$out/triangle_${alpha}deg.csv
  /usr/bin/python3 - "$csv" "$alpha" "$tool_control_points" <<'EOF'
import math, sys
path, alpha, cps = sys.argv[1], float(sys.argv[2]), int(sys.argv[3])
period = 10.0                                     # µm, one period without repeating the first point
samples = 512 if cps <= 256 else 4 * cps          # 512: the samples of the figures recorded with 256 control points
half = period / 2
with open(path, "w") as f:
    f.write("x[um],height[um]\n")
    for i in range(samples):
        x = period * i / samples
        f.write(f"{x:.9f},{abs(x - half) * math.tan(math.radians(alpha)):.9f}\n")
EOF
  for p in $pressures; do
    run=$out/a${alpha}_p${p}
    mkdir -p "$run"
    /usr/bin/python3 - "$here/../../../micro/scene/dry_default.json" "$csv" "$p" "$elements_x" "$tool_control_points" "$run/scene.json" <<'EOF'
import json, sys
base, csv, p, nx, cps, path = sys.argv[1:]
s = json.load(open(base))
s["geometry"]["tool_surface"] = {"csv": csv, "fit": {"degree": 2, "control_points": int(cps)}}
s["geometry"]["chip_surface"] = {"flat": True}
s["material"].update({"a": "205MPa", "b": "0MPa", "c": 0.0, "heat_fraction": 0.0})
s["load"].update({"pressure": p, "temperature": "20C"})
s["discretisation"]["elements_x"] = int(nx)
s["protocol"]["realisations"] = 1
json.dump(s, open(path, "w"), indent=1)
EOF
    if [[ ! -f $run/result.json ]]; then
      OMP_NUM_THREADS=1 "$mufric" micro run "$run/scene.json" --out "$run" --quiet > "$run/log.txt" 2>&1 || true
    fi
    /usr/bin/python3 - "$run/result.json" "$alpha" "$p" "$run" <<'EOF'
import json, math, sys
r = json.load(open(sys.argv[1])); alpha = float(sys.argv[2])
t = math.tan(math.radians(alpha))
mu = r.get("mu")
if mu is None:
    print(f"{alpha:<6g} {sys.argv[3]:<8} did not complete: {r.get('warnings') or r.get('reason')}  {sys.argv[4]}")
else:
    print(f"{alpha:<6g} {sys.argv[3]:<8} {mu:<9.5f} {t:<9.5f} {mu / t:<7.4f} {sys.argv[4]}")
EOF
  done
done
