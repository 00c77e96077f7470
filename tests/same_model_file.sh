#!/usr/bin/env bash
# Whether two model files hold the same model bit for bit, their provenance apart (when the file and
# its database were written, how long runs took, the database's path and hash, and the one-line
# description of the training data, which states its wall time): prints the objects
# that differ and exits 1 if any do. Used where one model is made two ways from the same seeds (the
# learner through Slurm and through the local pool).
#   bash tests/same_model_file.sh A.h5 B.h5
set -euo pipefail
[[ $# -eq 2 ]] || { sed -n 2,6p "$0" >&2; exit 2; }
differing=$(h5diff -r "$1" "$2" 2>&1 |
  grep -E "^(attribute|dataset)|differences found" | grep -B1 -E "^[1-9][0-9]* differences" | grep -E "^(attribute|dataset)" |
  grep -vE "<(created_utc|seconds|dataset_path|dataset_sha256|dataset_description) of" || true)
[[ -z $differing ]] || { echo "$differing"; exit 1; }
