#!/usr/bin/env bash
# Recovery on the micro-model (issue 51): calibrate Childs' shear factor m back from "measurements"
# the micro-model made at m* = 0.55 (campaigns/recovery_childs/measure.sh), through the GP of the
# campaign over (p, v, T, m) (campaigns/recovery_childs/run.sh; its samples so far). Prints m's
# posterior with and without the discrepancy delta, whether m* lies inside its 95 % credible
# interval, writes the calibrated models and draws recovery.png (bench/plot_calibration.py); figures go to
# bench/RESULTS.md by hand.
#   bash bench/recovery_calibration.sh [--mufric PATH] [--out DIR]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
mufric=$here/build/app/mufric
out=${TMPDIR:-/tmp}/mufric-recovery
m_star=0.55
while [[ $# -gt 0 ]]; do
  case $1 in
    --mufric) mufric=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    -h|--help) sed -n '2,8p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "recovery_calibration.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
done
campaign=$here/campaigns/recovery_childs/db.h5
measured=$here/campaigns/recovery_childs/measure-db.h5
for f in "$campaign" "$measured"; do
  [[ -f $f ]] || { echo "recovery_calibration.sh: $f is missing: run campaigns/recovery_childs/run.sh and measure.sh" >&2; exit 2; }
done
mkdir -p "$out"
"$mufric" dataset status "$campaign" | grep -E "^samples|draws" || true
# The measurements as a calibration reads them: SI columns, each sample's mean over its draws and its
# standard error as the measurement's SD.
/usr/bin/python3 - "$measured" "$out/measured.csv" <<'PY'
import sys, h5py
db, path = sys.argv[1], sys.argv[2]
with h5py.File(db, "r") as f:
    names = [n.decode() for n in f["inputs/names"][:]]
    units = [u.decode() for u in f["inputs/units"][:]]
    s = f["samples"]
    x, mu, sd, status = s["inputs"][:], s["mu"][:], s["mu_std"][:], s["status"][:]
with open(path, "w") as out:
    out.write(f"# micro-model measurements from {db}: Childs' law, shear factor 0.55, a sample's mean over its draws and its standard error\n")
    out.write(",".join(f"{n}[{u}]" for n, u in zip(names, units)) + ",mu,mu_sd\n")
    for row, m, e, st in zip(x, mu, sd, status):
        if st == 0:
            out.write(",".join(f"{v:.17g}" for v in row) + f",{m:.17g},{e:.17g}\n")
PY
echo "measurements: $(($(grep -vc '^#' "$out/measured.csv") - 1)) rows"
"$mufric" train --data "$campaign" --out "$out/campaign-gp.h5" | grep -E "stochastic kriging|length scale|leave-one-out" || true
for variant in "" "--discrepancy"; do
  echo "== calibrate ${variant:-(no discrepancy)}"
  # A refused posterior (exit 2: the chains fail the limits) is a result too: say so and go on.
  if ! "$mufric" calibrate --model "$out/campaign-gp.h5" --data "$out/measured.csv" --seed 1 $variant \
      --out "$out/posterior${variant}.csv" --model-out "$out/calibrated${variant}.h5" \
      > "$out/calibrate${variant}.txt" 2>&1; then
    grep -v "% of the steps" "$out/calibrate${variant}.txt"
    echo "calibrate refused the posterior: no credible interval to judge m* by"
    continue
  fi
  grep -v "% of the steps" "$out/calibrate${variant}.txt"
  awk -v m="$m_star" '$1 == "shear_factor" { lo = $4; hi = $6;
    printf "m* = %s %s the 95 %% credible interval %s .. %s\n", m, (lo <= m && m <= hi) ? "inside" : "OUTSIDE", lo, hi }' \
    "$out/calibrate${variant}.txt"
done
# The picture: m's posterior against m*, and what each calibrated model serves at the measured conditions.
models=() posteriors=()
for variant in "" "--discrepancy"; do
  if [[ -f $out/calibrated${variant}.h5 ]]; then
    models+=(--model "$out/calibrated${variant}.h5" --model-label "calibrated, δ ${variant:+on}${variant:-off}")
    posteriors+=(--posterior "$out/posterior${variant}.csv")
  fi
done
((${#models[@]} > 0)) && /usr/bin/python3 "$here/bench/plot_calibration.py" --mufric "$mufric" "${models[@]}" "${posteriors[@]}" \
  --data "$out/measured.csv" --label "micro-model at m*" --x temperature --truth "shear_factor=$m_star" \
  --title "recovery: served at the measured conditions (a fit, not a held-out check)" --out "$out/recovery.png"
