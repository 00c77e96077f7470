#!/usr/bin/env bash
# The shipped model against held-out means: M random points of its box (seed 77), each the default
# dry scene with R independent draws of its own (the row's own tool and chip surfaces), and the
# shipped model asked there. Reports coverage of the 95 % interval of the mean (its z counts the
# held-out mean's own standard error), the mean error net of that standard error, and the served
# patch scatter against the held-out per-draw spread (bench/studies/served_interval/shipped_model_heldout.py).
# Resumable (the database resumes); JOBS samples side by side, one core each. About 35 s of one core
# per draw on this machine: M = 10, R = 32 is about 3 core-hours. Never part of CI.
#   JOBS=2 bash bench/studies/served_interval/shipped_model_heldout.sh build/app/mufric OUT [M=10] [R=32] [MODEL=dry_default]
set -euo pipefail
mufric=$(realpath "$1"); out=$2; m=${3:-10}; r=${4:-32}; model=${5:-dry_default}
cd "$(dirname "$0")/../../.."
mkdir -p "$out"
box=$("$mufric" describe "$model" | awk '/stored in/ {gsub(/[\[\],]/, ""); print $1 "=" $2 ":" $3}')
flags=()
for line in $box; do
  name=${line%%=*}; range=${line#*=}
  case $name in
    contact_pressure) flags+=(--p "$range") ;;
    sliding_velocity) flags+=(--v "$range") ;;
    temperature) flags+=(--T "${range//°/}") ;;
    *) echo "shipped_model_heldout.sh: the model has an input '$name' a micro-model plan cannot vary" >&2; exit 2 ;;
  esac
done
[[ -f $out/heldout-plan.h5 ]] || "$mufric" dataset plan --out "$out/heldout-plan.h5" --samples "$m" --design random \
  --seed 77 "${flags[@]}" --set protocol.realisations="$r" >/dev/null
OMP_NUM_THREADS=1 "$mufric" dataset run --plan "$out/heldout-plan.h5" --db "$out/heldout.h5" --jobs "${JOBS:-1}" \
  --threads 1 --sample-timeout 7200 2>&1 | tail -2
/usr/bin/python3 bench/studies/served_interval/shipped_model_heldout.py "$mufric" "$out/heldout.h5" "$model"
