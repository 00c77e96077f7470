#!/usr/bin/env bash
# The Ti6Al4V law variants compared by calibrate's own held-out check (PSIS-LOO, one run each, no
# refits) on the shipped model's six rake-face rows: elpd, mean |error|, coverage, and what the cuts
# determine of each coefficient. The refit-based leave-one-speed-out study of the same variants is
# ti6al4v_validation.py (README.md here); this checks that the one-run figure tells the same story.
#   bash bench/studies/ti6al4v/law_variants_loo.sh > loo.md     # about 6 minutes on one core
set -euo pipefail
root=$(cd "$(dirname "$0")/../../.." && pwd)
mufric=${MUFRIC:-$root/build/app/mufric}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$mufric" train --data "$root/campaigns/ti6al4v_tin/db.h5" --out "$work/gp.h5" --no-fast-evaluator > "$work/train.log"
cd "$root"
variants=(
  "childs, delta, trend 0.15 (shipped)|--discrepancy --discrepancy-trend 0.15"
  "childs, delta, trend 0.30|--discrepancy --discrepancy-trend 0.30"
  "childs, delta, trend 0.05|--discrepancy --discrepancy-trend 0.05"
  "childs, delta, no trend|--discrepancy"
  "childs, no delta|"
  "coulomb-like (m = 1), delta, trend 0.15|--fix shear_factor=1 --discrepancy --discrepancy-trend 0.15"
  "shear-factor-like (mu_a = 1), delta, trend 0.15|--fix adhesive_coefficient=1 --discrepancy --discrepancy-trend 0.15"
)
echo "| law variant | elpd (SE) | p_loo | mean abs error | inside 95 % | rows k > 0.7 | what the cuts determine |"
echo "|---|---|---|---|---|---|---|"
for variant in "${variants[@]}"; do
  name=${variant%%|*}
  read -r -a extra <<< "${variant#*|}"
  log="$work/calibrate.log"
  "$mufric" calibrate --model "$work/gp.h5" --data data/cirp2022_ti6al4v_tin/rake_face_mu_calibration.csv "${extra[@]}" > "$log" 2>&1
  held=$(grep "each measurement predicted" "$log")
  elpd=$(sed -E 's/.*elpd ([-0-9.]+) \(SE ([0-9.]+)\).*/\1 (\2)/' <<< "$held")
  p_loo=$(sed -E 's/.*p_loo ([-0-9.]+);.*/\1/' <<< "$held")
  error=$(sed -E 's/.*mean \|error\| ([0-9.e-]+),.*/\1/' <<< "$held")
  inside=$(sed -E 's/.*, ([0-9]+ of [0-9]+) inside.*/\1/' <<< "$held")
  unreliable=$(grep -oE "unreliable for [0-9]+" "$log" | grep -oE "[0-9]+" || echo 0)
  determined=$(awk '/what the measurements determine/{on=1; next} on && /^  \(share/{on=0} on && !/coefficient +prior/{printf "%s%s %s (%s)", sep, $1, $0 ~ /only with/ ? "only with another" : ($0 ~ /not determined/ ? "not determined" : ($0 ~ /weakly/ ? "weakly" : "determined")), $4 " %"; sep="; "}' "$log")
  echo "| $name | $elpd | $p_loo | $error | $inside | ${unreliable:-0} | $determined |"
done
