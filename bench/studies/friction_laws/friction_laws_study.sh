#!/usr/bin/env bash
# μ(p), μ(v), μ(T) through the centre of seed 000's box for each interfacial law, with μ's work split
# (interfacial dissipation = the adhesive part, the chip's plastic work = ploughing, the normal
# load's work), as a markdown table and a PNG (bench/studies/friction_laws/plot_friction_laws.py). Resumable: a point whose
# result.json exists is not run again, so a stopped study continues where it stopped.
#
#   bash bench/studies/friction_laws/friction_laws_study.sh MUFRIC OUT [LAW ...]
#
# A LAW is a name and its --set overrides joined by commas, e.g.
#   frictionless
#   coulomb:contact.law=coulomb,contact.adhesive_coefficient=0.1
#   zorev:contact.law=zorev,contact.adhesive_coefficient=0.3,contact.shear_factor=0.5
# (default: frictionless and coulomb with mu_a = 0.1). Environment: PHYSICS=lubricated runs the
# lubricated scene (default dry); SCENE=file.json another base scene; PRESSURES, VELOCITIES,
# TEMPERATURES the sweeps (each through the others' centre value, the middle word); CORNERS=1 also
# the box's eight corners (the first and last words of each sweep); THREADS cores per run (default
# 1: leave a core free).
set -uo pipefail
mufric=${1:?usage: friction_laws_study.sh MUFRIC OUT [LAW ...]}
out=${2:?output directory}
shift 2
laws=("$@")
[[ ${#laws[@]} -eq 0 ]] && laws=(frictionless "coulomb:contact.law=coulomb,contact.adhesive_coefficient=0.1")
pressures=(${PRESSURES:-300MPa 800MPa 1300MPa})
velocities=(${VELOCITIES:-22.5m/min 100m/min 200m/min})
temperatures=(${TEMPERATURES:-25C 462.5C 900C})
threads=${THREADS:-1}
scene=${SCENE:-}
if [[ ${PHYSICS:-dry} == lubricated && -z $scene ]]; then
  scene=$(cd "$(dirname "$0")/../../.." && pwd)/micro/scene/lubricated_default.json
fi
mkdir -p "$out"
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'); machine: $(lscpu | sed -n 's/Model name: *//p'), $(nproc) cores; scene: ${scene:-default dry}; laws: ${laws[*]}"

run_point() {  # law-name overrides p v T
  local name=$1 overrides=$2 p=$3 v=$4 t=$5
  local dir="$out/$name/p${p}_v${v//\//_}_T${t}"
  mkdir -p "$dir"
  [[ -s $dir/result.json ]] && return
  local sets=(--set "load.pressure=$p" --set "load.velocity=$v" --set "load.temperature=$t")
  if [[ -n $overrides ]]; then
    IFS=',' read -ra pairs <<< "$overrides"
    for pair in "${pairs[@]}"; do sets+=(--set "$pair"); done
  fi
  echo "  $name at $p, $v, $t ($(date -u +%H:%M))" >&2
  OMP_NUM_THREADS=$threads "$mufric" micro run ${scene:+"$scene"} --quiet --out "$dir" "${sets[@]}" \
    > "$dir/log.txt" 2>&1 || true
}

for law in "${laws[@]}"; do
  name=${law%%:*}
  overrides=""
  [[ $law == *:* ]] && overrides=${law#*:}
  for p in "${pressures[@]}"; do run_point "$name" "$overrides" "$p" "${velocities[1]}" "${temperatures[1]}"; done
  for v in "${velocities[@]}"; do run_point "$name" "$overrides" "${pressures[1]}" "$v" "${temperatures[1]}"; done
  for t in "${temperatures[@]}"; do run_point "$name" "$overrides" "${pressures[1]}" "${velocities[1]}" "$t"; done
  if [[ ${CORNERS:-0} == 1 ]]; then
    for p in "${pressures[0]}" "${pressures[-1]}"; do
      for v in "${velocities[0]}" "${velocities[-1]}"; do
        for t in "${temperatures[0]}" "${temperatures[-1]}"; do run_point "$name" "$overrides" "$p" "$v" "$t"; done
      done
    done
  fi
done
/usr/bin/python3 "$(dirname "$0")/plot_friction_laws.py" "$out"
