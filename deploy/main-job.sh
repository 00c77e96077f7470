#!/usr/bin/env bash
# The main job on a fresh Debian 12 machine: installs dependencies, builds mufric, and runs
#   1. μ for a few contact states from the empirical laws of seed 001 (Seward et al. 2022);
#   2. the whole chain: a Sobol' plan over seed 000's box → the dry micro-model at every point (a
#      coarse scene that fits a laptop: 32 × 6 elements, deploy/coarse_scene.sh) → a Gaussian-process surrogate →
#      `mufric serve` on loopback → a meso-trace client (Python, gRPC) asking μ with its 95 % interval
#      per contact Gauss point → a short table and a plot of μ over the box with its band;
#   3. the shipped dry_default at a few states, drawn; 4. the shipped Ti6Al4V model against the
#      measured cuts it was calibrated on: a table and a plot of μ and its band.
# Files go to ${MUFRIC_OUT:-mufric-out}/. MUFRIC_SAMPLES sets the plan size (default 32).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=${MUFRIC_JOBS:-2}
out=${MUFRIC_OUT:-mufric-out}

bash deploy/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$jobs" --target mufric mufric_python_stubs
mufric=build/app/mufric
mkdir -p "$out"

echo; echo "== 1. Empirical laws of seed 001 (Table 2: apparent COF, Table 4: adhesive COF)"
$mufric law seward --table 2 --out "$out/law-table2.h5" >/dev/null
$mufric law seward --table 4 --out "$out/law-table4.h5" >/dev/null
for state in "20MPa 2m/min 0deg" "80MPa 10m/min 45deg" "150MPa 15m/min 90deg" "80MPa 10m/min 100deg"; do
  read -r p v a <<<"$state"
  for table in 2 4; do
    printf 'Table %s: ' "$table"
    $mufric predict --model "$out/law-table$table.h5" --p "$p" --v "$v" --angle "$a" | paste -sd ' '
  done
done

echo; echo "== 2. Micro-model dataset -> GP surrogate -> service -> meso-trace client"
source deploy/coarse_scene.sh  # (the working directory is the repository)
scene=("${coarse_scene[@]}")
rm -f "$out/db.h5"  # a fresh database for this plan (dataset run would resume one of the same plan)
$mufric dataset plan --out "$out/plan.h5" --samples "${MUFRIC_SAMPLES:-32}" --design sobol "${scene[@]}"
$mufric dataset run --plan "$out/plan.h5" --db "$out/db.h5" --jobs "$jobs" --threads 1
mkdir -p "$out/models"
$mufric train --data "$out/db.h5" --out "$out/models/gp.h5" --restarts 4
rm -f "$out/address"
$mufric serve --models "$out/models" --listen 127.0.0.1:0 --ready-file "$out/address" 2>"$out/serve.log" &
server=$!
trap 'kill -TERM $server 2>/dev/null || true' EXIT
for _ in $(seq 1 100); do [[ -s $out/address ]] && break; sleep 0.1; done
[[ -s $out/address ]] || { echo "the server did not start:"; cat "$out/serve.log"; exit 1; }
echo "serving $out/models on $(cat "$out/address")"
PYTHONPATH=build/python /usr/bin/python3 examples/python/meso_trace.py "$(cat "$out/address")" gp \
  --points 2000 --increments 50 --dataset "$out/db.h5" --plot "$out/mu-over-box.png"
kill -TERM $server && wait $server || true
trap - EXIT

echo; echo "== 3. The shipped model (dry_default: the default 64 x 12 scene's campaign, stochastic kriging)"
$mufric describe dry_default | grep -E "training points|leave-one-out"
for state in "300MPa 22.5m/min 25C" "800MPa 100m/min 500C" "1300MPa 200m/min 900C" "2500MPa 1000m/min 700C"; do
  read -r p v t <<<"$state"
  printf '%-8s %-10s %-6s ' "$p" "$v" "$t"
  $mufric predict --model dry_default --p "$p" --v "$v" --T "$t" | sed -n -e '2s/ *status.*//p' -e '3s/:.*//p' | paste -sd ' ' 
done
/usr/bin/python3 tools/plot/plot_model.py "$mufric" dry_default "$out/dry_default.png"

echo; echo "== 4. The shipped Ti6Al4V model (ti6al4v_tin: calibrated on measured dry cuts by a TiN-coated carbide tool)"
measured=data/cirp2022_ti6al4v_tin/rake_face_mu_0deg.csv
/usr/bin/python3 - "$mufric" "$measured" "$out/ti6al4v_tin.csv" <<'PY'
import csv, subprocess, sys
mufric, measured, out = sys.argv[1:]
with open(measured) as f:
    rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
conditions = ("contact_pressure[MPa]", "sliding_velocity[m/min]", "temperature[C]")
with open(out, "w") as f:  # each speed's rake-face state as mufric predict reads it
    f.write(",".join(conditions) + "\n" + "".join(",".join(r[c] for c in conditions) + "\n" for r in rows))
answer = subprocess.run([mufric, "predict", "--model", "ti6al4v_tin", "--csv", out], check=True,
                        capture_output=True, text=True).stdout
served = list(csv.DictReader(line for line in answer.splitlines() if not line.startswith("#")))
print("cutting speed   rake-face mu measured (95 %)   ti6al4v_tin at its state (95 %)")
for speed, m, c in zip((5, 7.5, 10, 20, 30, 40), rows, served):
    print(f"{speed:5g} m/min      {float(m['mu']):.3f} +- {1.96 * float(m['mu_sd']):.3f}"
          f"              {float(c['mu']):.3f} ({float(c['lo']):.3f} .. {float(c['hi']):.3f})")
PY
/usr/bin/python3 tools/plot/plot_calibration.py --mufric "$mufric" --model ti6al4v_tin --data "$measured" \
  --label "rake-face mu from measured forces" --x sliding_velocity --title "Ti6Al4V / TiN-coated carbide, dry" \
  --out "$out/ti6al4v_tin.png"
echo; echo "files: $(ls "$out" | tr '\n' ' ')in $out/"
