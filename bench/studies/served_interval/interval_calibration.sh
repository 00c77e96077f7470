#!/usr/bin/env bash
# Is the served interval calibrated? Trains the main job's design twice on the coarse scene over seed
# 000's box -- N Sobol' samples of 4 draws, every row its own surfaces (stochastic kriging, the
# default) and the same rows with the scene's common surfaces (the design before independent draws,
# trained as it was) -- and asks both at M held-out random points whose own mean comes from R draws.
# Per point z = (held-out mean - served mu) / sqrt(served std^2 + held-out standard error^2): a
# calibrated interval covers |z| <= 1.96 at about 95 %; at growing budgets (bench/studies/served_interval/interval_calibration.py).
# Resumable (each database resumes); one core.
#   bash bench/studies/served_interval/interval_calibration.sh build/app/mufric OUT [N=32] [M=10] [R=32]
set -euo pipefail
mufric=$(realpath "$1"); out=$2; n=${3:-32}; m=${4:-10}; r=${5:-32}
cd "$(dirname "$0")/../../.."
source deploy/coarse_scene.sh
mkdir -p "$out"
plan() {  # name, extra plan options...
  local name=$1; shift
  [[ -f $out/$name-plan.h5 ]] || "$mufric" dataset plan --out "$out/$name-plan.h5" "${coarse_scene[@]}" "$@" >/dev/null
}
plan independent --samples "$n" --design sobol
plan common --samples "$n" --design sobol --common-tools
plan heldout --samples "$m" --design random --seed 77 --set protocol.realisations="$r"
for name in independent common heldout; do
  echo "== $name: $(date -u +%H:%M:%S)"
  OMP_NUM_THREADS=1 "$mufric" dataset run --plan "$out/$name-plan.h5" --db "$out/$name.h5" --jobs 1 --threads 1 \
    --sample-timeout 1800 2>&1 | tail -2
done
/usr/bin/python3 bench/studies/served_interval/interval_calibration.py "$mufric" "$out"
