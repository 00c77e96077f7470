#!/usr/bin/env bash
# The dry micro-model over the corners and the centre of seed 000's parameter box (section 4:
# 300–1300 MPa, 22.5–200 m/min, 25–900 °C): mu, contact, plastic strain, heating, Newton work and
# wall time per point, as a markdown table. Every run's result.json is kept in the output directory.
# Usage: bash bench/benchmarks/micro_sweep.sh [build-dir] [out-dir] [extra --set overrides...]
# Another box: PRESSURES="300MPa 3000MPa" VELOCITIES="1m/min 200m/min" TEMPERATURES="25C 900C"
# CENTRE="1650MPa 100.5m/min 462.5C" bash bench/benchmarks/micro_sweep.sh ... (CENTRE="" for none).
set -uo pipefail
pressures=${PRESSURES:-300MPa 1300MPa}
velocities=${VELOCITIES:-22.5m/min 200m/min}
temperatures=${TEMPERATURES:-25C 900C}
centre=${CENTRE-800MPa 111.25m/min 462.5C}
build=${1:-build}
out=${2:-micro-sweep}
shift 2 2>/dev/null || true
mufric=$build/app/mufric
mkdir -p "$out"
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'); machine: $(lscpu | sed -n 's/Model name: *//p'), $(nproc) cores; p: $pressures; v: $velocities; T: $temperatures; centre: ${centre:-none}; overrides: $*"
printf '| p | v | T | mu | contact | max p [MPa] | max plastic strain | max T [C] | Newton | cut-backs | wall [s] |\n|---|---|---|---|---|---|---|---|---|---|---|\n'
run() {
  local p=$1 v=$2 t=$3
  shift 3
  local dir="$out/p${p}_v${v//\//_}_T${t}"
  mkdir -p "$dir"
  "$mufric" micro run --quiet --out "$dir" --set "load.pressure=$p" --set "load.velocity=$v" --set "load.temperature=$t" "$@" \
    > "$dir/summary.txt" 2>&1
  if [[ ! -s $dir/result.json ]]; then
    echo "| $p | $v | $t | error: $(tail -1 "$dir/summary.txt") | | | | | | | |"
    return
  fi
  /usr/bin/python3 - "$dir/result.json" "$p" "$v" "$t" <<'PY'
import json, sys
r = json.load(open(sys.argv[1])); d = r["diagnostics"]
mu = f'{r["mu"]:.4f}' if r["completed"] else "failed: " + r.get("reason", "")[:60]
if r["completed"] and r.get("mu_std_error"):
    mu += f' ± {r["mu_std_error"]:.4f}'
if r.get("warnings"):
    mu += " (molten)" if any("melting" in w for w in r["warnings"]) else " (warning)"
print(f'| {sys.argv[2]} | {sys.argv[3]} | {sys.argv[4]} | {mu} | {100*d["contact_area_fraction"]:.1f} % | '
      f'{d["max_contact_pressure_pa"]/1e6:.0f} | {d["max_plastic_strain"]:.3f} | {d["max_temperature_k"]-273.15:.0f} | '
      f'{d["newton_iterations"]} | {d["cutbacks"]} | {d["wall_seconds"]:.1f} |')
PY
}
for p in $pressures; do
  for v in $velocities; do
    for t in $temperatures; do run $p $v $t "$@"; done
  done
done
# shellcheck disable=SC2086  # the centre is three words
[[ -n $centre ]] && run $centre "$@"
