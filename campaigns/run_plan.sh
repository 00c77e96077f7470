#!/usr/bin/env bash
# Shared by the campaigns' run scripts: make the plan once (`mufric dataset plan` with the arguments
# after --), then run or resume it into the database, one thread per sample (the draws of a sample run
# one after the other, samples side by side). Resumable: a second call skips finished samples.
#   run_plan.sh PLAN DB SAMPLE_TIMEOUT_S -- <dataset plan arguments without --out>
# Environment: MUFRIC (the executable; default: this checkout's build/app/mufric), JOBS (samples at
# once; default 1, which leaves the other core free for builds).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
mufric=${MUFRIC:-$here/../build/app/mufric}
jobs=${JOBS:-1}
(($# >= 4)) && [[ $4 == -- ]] || { echo "usage: run_plan.sh PLAN DB SAMPLE_TIMEOUT_S -- <plan arguments>" >&2; exit 2; }
plan=$1 db=$2 timeout=$3
shift 4
if [[ ! -f $plan ]]; then
  "$mufric" dataset plan --out "$plan" "$@"
fi
OMP_NUM_THREADS=1 exec "$mufric" dataset run --plan "$plan" --db "$db" --jobs "$jobs" --threads 1 --sample-timeout "$timeout"
