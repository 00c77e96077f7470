#!/usr/bin/env bash
# Recovery on the micro-model: calibrate a law's coefficients back from "measurements" the micro-model
# made at known values kept out of the campaign's plan (a campaign's measure.sh), through the GP of the
# campaign (its samples so far). Prints the posterior with and without the discrepancy delta, whether
# each true value lies inside its 95 % credible interval, writes the calibrated models and draws
# recovery.png (tools/plot/plot_calibration.py); figures go to its README.md by hand.
# With --condition-sd NAME=SD (SI, repeatable) the conditions are also given as uncertain: each row's
# NAME is replaced by a draw about its true value with that SD (seeded) and NAME_sd is given, as for
# conditions estimated rather than measured; the coefficients must still be recovered.
#   bash bench/studies/calibration/recovery_calibration.sh                        # Childs' shear factor (issue 51): m* = 0.55
#   bash bench/studies/calibration/recovery_calibration.sh --campaign campaigns/ti6al4v_tin --truth adhesive_coefficient=0.45 \
#        --truth shear_factor=0.7 --condition-sd temperature=60      # Ti6Al4V (issue 60)
# Options: --mufric PATH, --out DIR, --campaign DIR (db.h5 and measure-db.h5), --truth NAME=VALUE,
# --calibrate-args "ARGS" (added to each calibrate, e.g. "--max-steps 200000" for a ridge that mixes slowly),
# --trend SD (a third calibration: δ with a linear trend, calibrate --discrepancy-trend SD).
set -euo pipefail
here=$(cd "$(dirname "$0")/../../.." && pwd)
mufric=$here/build/app/mufric
out=${TMPDIR:-/tmp}/mufric-recovery
campaign_dir=$here/campaigns/recovery_childs
truths=() condition_sds=() calibrate_args="" trend_sd=""
while [[ $# -gt 0 ]]; do
  case $1 in
    --mufric) mufric=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --campaign) campaign_dir=$2; shift 2 ;;
    --truth) truths+=("$2"); shift 2 ;;
    --condition-sd) condition_sds+=("$2"); shift 2 ;;
    --calibrate-args) calibrate_args=$2; shift 2 ;;
    --trend) trend_sd=$2; shift 2 ;;
    -h|--help) sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "recovery_calibration.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
done
((${#truths[@]} > 0)) || truths=("shear_factor=0.55")
campaign=$campaign_dir/db.h5
measured=$campaign_dir/measure-db.h5
for f in "$campaign" "$measured"; do
  [[ -f $f ]] || { echo "recovery_calibration.sh: $f is missing: run $campaign_dir/run.sh and measure.sh" >&2; exit 2; }
done
mkdir -p "$out"
"$mufric" dataset status "$campaign" | grep -E "^samples|draws" || true
# The measurements as a calibration reads them: SI columns, each sample's mean over its draws and its
# standard error as the measurement's SD; with --condition-sd, the named conditions drawn about their
# true values and given with that SD.
/usr/bin/python3 - "$measured" "$out/measured.csv" "${truths[*]}" "${condition_sds[*]:-}" <<'PY'
import sys, h5py, numpy as np
db, path, truths, sds = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4]
sd_of = dict((k, float(v)) for k, v in (item.split("=") for item in sds.split()))
with h5py.File(db, "r") as f:
    names = [n.decode() for n in f["inputs/names"][:]]
    units = [u.decode() for u in f["inputs/units"][:]]
    s = f["samples"]
    x, mu, sd, status = s["inputs"][:], s["mu"][:], s["mu_std"][:], s["status"][:]
unknown = set(sd_of) - set(names)
if unknown:
    sys.exit(f"--condition-sd: {', '.join(sorted(unknown))} is not an input of {db} ({', '.join(names)})")
rng = np.random.default_rng(7)
with open(path, "w") as out:
    out.write(f"# micro-model measurements from {db} at {truths}: a sample's mean over its draws and its standard error\n")
    if sd_of:
        out.write(f"# conditions given as uncertain: {sds} (SI), each drawn about its true value with that SD (seed 7)\n")
    columns = []
    for n, u in zip(names, units):
        columns.append(f"{n}[{u}]")
        if n in sd_of:
            columns.append(f"{n}_sd[{u}]")
    out.write(",".join(columns) + ",mu,mu_sd\n")
    for row, m, e, st in zip(x, mu, sd, status):
        if st != 0:
            continue
        values = []
        for n, v in zip(names, row):
            if n in sd_of:
                values += [rng.normal(v, sd_of[n]), sd_of[n]]
            else:
                values.append(v)
        out.write(",".join(f"{v:.17g}" for v in values) + f",{m:.17g},{e:.17g}\n")
PY
echo "measurements: $(($(grep -vc '^#' "$out/measured.csv") - 1)) rows"
"$mufric" train --data "$campaign" --out "$out/campaign-gp.h5" | grep -E "stochastic kriging|length scale|leave-one-out" || true
# Each variant's calibrate arguments, its files' tag and its label in the picture.
variants=("" "--discrepancy") tags=("" "--discrepancy") labels=("δ off" "δ on")
if [[ -n $trend_sd ]]; then
  variants+=("--discrepancy --discrepancy-trend $trend_sd") tags+=("--discrepancy-trend") labels+=("δ with a trend")
fi
for k in "${!variants[@]}"; do
  variant=${variants[$k]} tag=${tags[$k]}
  echo "== calibrate ${variant:-(no discrepancy)}"
  # A refused posterior (exit 2: the chains fail the limits) is a result too: say so and go on.
  if ! "$mufric" calibrate --model "$out/campaign-gp.h5" --data "$out/measured.csv" --seed 1 $variant $calibrate_args \
      --out "$out/posterior${tag}.csv" --model-out "$out/calibrated${tag}.h5" \
      > "$out/calibrate${tag}.txt" 2>&1; then
    grep -v "% of the steps" "$out/calibrate${tag}.txt"
    echo "calibrate refused the posterior: no credible interval to judge the truth by"
    continue
  fi
  grep -v "% of the steps" "$out/calibrate${tag}.txt"
  for truth in "${truths[@]}"; do
    awk -v name="${truth%%=*}" -v value="${truth#*=}" '$1 == name { lo = $4; hi = $6;
      printf "%s* = %s %s the 95 %% credible interval %s .. %s\n", name, value, (lo <= value && value <= hi) ? "inside" : "OUTSIDE", lo, hi }' \
      "$out/calibrate${tag}.txt"
  done
done
# The picture: the posteriors against the truth, and what each calibrated model serves at the measured conditions.
models=() posteriors=() truth_flags=()
for truth in "${truths[@]}"; do truth_flags+=(--truth "$truth"); done
for k in "${!variants[@]}"; do
  tag=${tags[$k]}
  if [[ -f $out/calibrated${tag}.h5 ]]; then
    models+=(--model "$out/calibrated${tag}.h5" --model-label "calibrated, ${labels[$k]}")
    posteriors+=(--posterior "$out/posterior${tag}.csv")
  fi
done
((${#models[@]} > 0)) && /usr/bin/python3 "$here/tools/plot/plot_calibration.py" --mufric "$mufric" "${models[@]}" "${posteriors[@]}" \
  --data "$out/measured.csv" --label "micro-model at the truth" --x temperature "${truth_flags[@]}" \
  --title "recovery: served at the measured conditions (a fit, not a held-out check)" --out "$out/recovery.png"
