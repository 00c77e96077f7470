#!/usr/bin/env bash
# Issue 62: the on-line learner on a served calibrated model, the shipped Ti6Al4V one
# (models/ti6al4v_tin.h5, Childs' law calibrated on measured cuts through campaigns/ti6al4v_tin's GP).
# A meso trace (bench/scenarios/learn_trace.py) asks below the campaign's pressures (REGION, default 200-300 MPa,
# first contact) and over its box; the learner, on copies of the campaign database and of the model,
# runs ROUNDS rounds: picks at the queried conditions and the coefficients' posterior samples, runs
# them with the Ti6Al4V scene, retrains the campaign's GP, recalibrates on the model's own measurements
# and gates. Prints each round's status, the posterior before and after, and the trace's passes
# (OUT/passes.csv).
#   bash bench/scenarios/learn_calibrated.sh [--mufric build/app/mufric] [--out /tmp/learn-calibrated] [--rounds 1]
#        [--round-samples 4] [--jobs 2] [--region 200e6:300e6]
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
mufric=$here/build/app/mufric out=/tmp/learn-calibrated rounds=1 round_samples=4 jobs=2 region=200e6:300e6
# shellcheck source=bench/tools/learn_common.sh
source "$here/bench/tools/learn_common.sh"
while (($#)); do
  learn_common_option "$@" && { shift 2; continue; }
  case $1 in
    --region) region=$2; shift 2 ;;
    -h|--help) sed -n '2,11p' "$0"; exit 0 ;;
    *) echo "unknown argument $1 (--help)"; exit 2 ;;
  esac
done
prepare_learn_dir
cp "$here/campaigns/ti6al4v_tin/db.h5" "$out/db.h5"
cp "$here/models/ti6al4v_tin.h5" "$out/served/ti.h5"
server_start_seconds=60 start_learning_server --models "$out/served" --poll 0.5 --log-uncertain "$out/logs"
# The campaign's box: p 300-2000 MPa, v 1-60 m/min, T 100-1100 C (SI below).
trace() { "$py" "$here/bench/scenarios/learn_trace.py" "$address" ti --region "$region" \
            --box 300e6:2000e6,0.016667:1,373.15:1373.15 --pass-number "$1" "${@:2}"; }
trace 0 --header > "$out/passes.csv"
"$mufric" learn init "$out/learner" --db "$out/db.h5" --model "$out/served/ti.h5" --log "$out/logs/ti.csv" \
  --round-samples "$round_samples" --budget-core-hours 2
"$mufric" describe "$out/served/ti.h5" | grep -E "posterior|interval at the box centre" > "$out/before.txt"
started=$SECONDS
for r in $(seq 1 "$rounds"); do
  "$mufric" learn run "$out/learner" --jobs "$jobs" | grep -vE "sample [0-9]+/" || true
  sleep 2
  trace "$r" >> "$out/passes.csv"
done
echo "== wall $((SECONDS - started)) s for $rounds round(s)"
"$mufric" learn status "$out/learner"
echo "== the served model before:"; cat "$out/before.txt"
echo "== after:"; "$mufric" describe "$out/served/ti.h5" | grep -E "posterior|interval at the box centre"
echo "== the meso trace's passes:"; cat "$out/passes.csv"
