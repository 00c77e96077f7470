#!/usr/bin/env bash
# What the Ti6Al4V rake-face friction is made of at each cutting speed (issue 60: through which
# mechanism μ falls with speed): the micro-model on the Ti6Al4V scene at each speed's rake-face state
# (data/cirp2022_ti6al4v_tin/rake_face_mu_0deg.csv: p, v, T as derived from the measured cuts), the
# scene's draws each, with the interface given by --set (default: frictionless, so μ is what the
# tool's asperities ploughing the chip give); prints and writes OUT/mechanism.csv: μ, its standard
# error and the work split (the interface's frictional dissipation, the chip's plastic work, per unit
# sliding distance and normal force).
#   bash bench/studies/ti6al4v/ti6al4v_ploughing.sh --out /tmp/ploughing                                   # ~15 min, one core
#   bash bench/studies/ti6al4v/ti6al4v_ploughing.sh --out /tmp/calibrated --set contact.adhesive_coefficient=0.8 \
#        --set contact.shear_factor=0.9                                   # at calibrated coefficients
set -euo pipefail
here=$(cd "$(dirname "$0")/../../.." && pwd)
mufric=$here/build/app/mufric
out=${TMPDIR:-/tmp}/mufric-ti6al4v-mechanism
sets=()
while [[ $# -gt 0 ]]; do
  case $1 in
    --mufric) mufric=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --set) sets+=(--set "$2"); shift 2 ;;
    -h|--help) sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "ti6al4v_ploughing.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
done
((${#sets[@]} > 0)) || sets=(--set contact.law=frictionless)
mkdir -p "$out"
echo "# bench/studies/ti6al4v/ti6al4v_ploughing.sh ${sets[*]}" > "$out/mechanism.csv"
echo "cutting_speed[m/min],contact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu,mu_std_error,mu_interface,mu_bulk_plastic" >> "$out/mechanism.csv"
/usr/bin/python3 - "$here/data/cirp2022_ti6al4v_tin/rake_face_mu_0deg.csv" <<'PY' > "$out/states.txt"
import csv, sys
rows = list(csv.DictReader(line for line in open(sys.argv[1]) if not line.startswith("#")))
for speed, r in zip((5, 7.5, 10, 20, 30, 40), rows):  # the file's row order (its header says so)
    print(speed, r["contact_pressure[MPa]"], r["sliding_velocity[m/min]"], r["temperature[C]"])
PY
while read -r speed p v T; do
  run=$out/run-$speed
  if [[ ! -s $run/result.json ]]; then  # resumable: a finished state is not run again
    OMP_NUM_THREADS=1 "$mufric" micro run "$here/micro/scene/ti6al4v_tin.json" --quiet --out "$run" "${sets[@]}" \
      --set "load.pressure=${p}MPa" --set "load.velocity=${v}m/min" --set "load.temperature=${T}C" > "$run.log" 2>&1 ||
      { echo "the run at $speed m/min failed: $run.log" >&2; exit 1; }
  fi
  /usr/bin/python3 - "$run/result.json" "$speed,$p,$v,$T" <<'PY' | tee -a "$out/mechanism.csv"
import json, sys
r = json.load(open(sys.argv[1]))
w = r.get("work_split", {})
print(f"{sys.argv[2]},{r['mu']:.6g},{r['mu_std_error']:.3g},{w.get('mu_interface', float('nan')):.6g},{w.get('mu_bulk_plastic', float('nan')):.6g}")
PY
done < "$out/states.txt"
