#!/usr/bin/env bash
# The same commit built native (-DMUFRIC_NATIVE=ON) and portable (OFF), the GP's exact path and the
# fast evaluator on one core: points per second, each build twice, alternated. The vector exp is
# dispatched at run time in both (surrogate/core/vector_exp.cpp); what is left between them is Eigen's
# compile-time vector width in the distances and the triangular product, and the grid lookup.
# Usage: bash bench/benchmarks/portable_vs_native.sh NATIVE_BUILD PORTABLE_BUILD MODEL.h5 [FAST_MODEL.h5]
set -euo pipefail
native=$1/app/mufric portable=$2/app/mufric model=$3 fast=${4:-}
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'); machine: $(lscpu | sed -n 's/Model name: *//p'), $(nproc) cores;" \
  "load before: $(cut -d' ' -f1-3 /proc/loadavg); one core (taskset -c 1, OMP_NUM_THREADS=1)"
rate() {  # build model batch flags...
  local exe=$1 m=$2 batch=$3
  shift 3
  OMP_NUM_THREADS=1 taskset -c 1 "$exe" bench --model "$m" --batch "$batch" --seconds 2 --json "$@" |
    /usr/bin/python3 -c 'import json, sys; print("%.4g" % json.loads(sys.stdin.readline())["points_per_second"])'
}
echo "| case | portable | native | native / portable |"
echo "|---|---|---|---|"
row() {  # label model batch flags...
  local label=$1 m=$2 batch=$3
  shift 3
  local p1 n1 p2 n2
  p1=$(rate "$portable" "$m" "$batch" "$@"); n1=$(rate "$native" "$m" "$batch" "$@")
  p2=$(rate "$portable" "$m" "$batch" "$@"); n2=$(rate "$native" "$m" "$batch" "$@")
  echo "| $label | $p1, $p2 | $n1, $n2 | $(/usr/bin/python3 -c "print('%.2f' % (($n1 + $n2) / ($p1 + $p2)))") |"
}
row "exact mean, 1 point" "$model" 1 --exact
row "exact mean, 10 000 points" "$model" 10000 --exact
row "exact mean + std, 1 point" "$model" 1 --exact --std
row "exact mean + std, 10 000 points" "$model" 10000 --exact --std
if [[ -n $fast ]]; then
  row "fast mean + std, 1 point" "$fast" 1 --std
  row "fast mean + std, 10 000 points" "$fast" 10000 --std
fi
