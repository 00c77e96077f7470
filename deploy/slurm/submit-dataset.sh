#!/usr/bin/env bash
# Submits a micro-model dataset to Slurm: an array job with one shard per task and a merge job that
# runs after all of them succeeded (afterok). Prints both job ids.
# Usage: deploy/slurm/submit-dataset.sh PLAN OUT_DIR TASKS [extra sbatch options...]
#   e.g. deploy/slurm/submit-dataset.sh plan.h5 /scratch/db 64 --partition=compute --time=12:00:00
# Environment: MUFRIC (default: mufric on PATH), MUFRIC_RUN_ARGS (extra `dataset run` options).
set -euo pipefail
if (($# < 3)); then
  sed -n '2,7p' "$0" >&2
  exit 2
fi
plan=$(realpath "$1") out=$(realpath -m "$2") tasks=$3
shift 3
here=$(dirname "$(realpath "$0")")
mufric=$(realpath "${MUFRIC:-$(command -v mufric)}")
[[ -f $plan ]] || { echo "plan file '$plan' not found" >&2; exit 2; }
[[ $tasks =~ ^[1-9][0-9]*$ ]] || { echo "TASKS '$tasks' must be a positive integer" >&2; exit 2; }
mkdir -p "$out"
export MUFRIC=$mufric MUFRIC_PLAN=$plan MUFRIC_OUT=$out MUFRIC_RUN_ARGS=${MUFRIC_RUN_ARGS:-}
array=$(sbatch --parsable --chdir="$out" --array="0-$((tasks - 1))" --export=ALL "$@" "$here/dataset-array.sbatch")
array=${array%%;*}
merge=$(sbatch --parsable --chdir="$out" --dependency="afterok:$array" --export=ALL "$@" "$here/dataset-merge.sbatch")
merge=${merge%%;*}
echo "array job $array ($tasks shards) -> merge job $merge; result: $out/db.h5"
