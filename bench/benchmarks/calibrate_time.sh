#!/usr/bin/env bash
# calibrate's time on one core, two builds side by side (ratios, not absolute times: the machine is
# shared), alternated round by round; each run writes its model with the grid, as a user's would.
#   bash bench/benchmarks/calibrate_time.sh OLD_MUFRIC NEW_MUFRIC GP.h5 DATA.csv [ROUNDS] [-- CALIBRATE-ARGS...]
# e.g. the Ti6Al4V model's calibration (bench/studies/ti6al4v/README.md, "calibrate's time with δ"):
#   mufric train --data campaigns/ti6al4v_tin/db.h5 --out gp.h5 --no-fast-evaluator
#   /usr/bin/python3 bench/studies/ti6al4v/ti6al4v_validation.py --write-measurements rf.csv
#   bash bench/benchmarks/calibrate_time.sh old/app/mufric build/app/mufric gp.h5 rf.csv 2 -- --discrepancy
set -euo pipefail
if [ $# -lt 4 ]; then sed -n 2,8p "$0" >&2; exit 2; fi
old=$1 new=$2 gp=$3 data=$4
rounds=${5:-2}
shift $(( $# >= 5 ? 5 : 4 ))
[ "${1:-}" = "--" ] && shift
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'); machine: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores;" \
     "load before: $(cut -d' ' -f1-3 /proc/loadavg); one core (taskset -c 0, OMP_NUM_THREADS=1)"
echo "| round | build | total | sampler | grid |"
echo "|---|---|---|---|---|"
for round in $(seq 1 "$rounds"); do
  for which in old new; do
    bin=$old; [ "$which" = new ] && bin=$new
    start=$(date +%s.%N)
    OMP_NUM_THREADS=1 taskset -c 0 "$bin" calibrate --model "$gp" --data "$data" "$@" --model-out "$work/$which.h5" \
      > "$work/$which.log" 2>&1 || { tail -5 "$work/$which.log" >&2; exit 1; }
    end=$(date +%s.%N)
    sampler=$(grep -o 'acceptance [0-9.]*; [0-9.]* s' "$work/$which.log" | awk '{print $3}')
    grid=$(grep -o 'built in [0-9.]* s' "$work/$which.log" | awk '{print $3}')
    printf '| %s | %s | %.1f s | %s s | %s s |\n' "$round" "$which" "$(echo "$end - $start" | bc)" "$sampler" "${grid:-none}"
  done
done
