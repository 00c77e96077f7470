#!/usr/bin/env bash
# The main job on a fresh Debian 12 machine: installs dependencies, builds mufric, and runs
#   1. μ for a few contact states from the empirical laws of seed 001 (Seward et al. 2022);
#   2. a dataset sampled from the Table 4 law (with measurement-like scatter), a Gaussian-process
#      surrogate trained on it, its held-out accuracy, and μ with its 95 % interval.
# Files go to ${MUFRIC_OUT:-mufric-out}/.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=${MUFRIC_JOBS:-2}
out=${MUFRIC_OUT:-mufric-out}

bash deploy/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$jobs" --target mufric
mufric=build/app/mufric
mkdir -p "$out"

echo; echo "== 1. Empirical laws of seed 001 (Table 2: apparent COF, Table 4: adhesive COF)"
$mufric law seward --table 2 --out "$out/law-table2.h5" >/dev/null
$mufric law seward --table 4 --out "$out/law-table4.h5" >/dev/null
for state in "20MPa 2m/min 0deg" "80MPa 10m/min 45deg" "150MPa 15m/min 90deg" "80MPa 10m/min 100deg"; do
  read -r p v a <<<"$state"
  for table in 2 4; do
    printf 'Table %s: ' "$table"
    $mufric predict --model "$out/law-table$table.h5" --p "$p" --v "$v" --angle "$a" | paste -sd ' '
  done
done

echo; echo "== 2. Gaussian-process surrogate fitted to a dataset file"
$mufric dataset from-model --model "$out/law-table4.h5" --samples 400 --seed 1 --noise 0.002 --out "$out/dataset.h5"
$mufric dataset from-model --model "$out/law-table4.h5" --samples 200 --seed 2 --out "$out/test.h5"
$mufric train --data "$out/dataset.h5" --out "$out/gp.h5" --restarts 4
$mufric eval --model "$out/gp.h5" --test "$out/test.h5"
for state in "20MPa 2m/min 0deg" "80MPa 10m/min 45deg" "150MPa 15m/min 90deg" "250MPa 10m/min 90deg"; do
  read -r p v a <<<"$state"
  $mufric predict --model "$out/gp.h5" --p "$p" --v "$v" --angle "$a" | paste -sd ' '
done
echo; echo "files: $(ls "$out" | tr '\n' ' ')in $out/"
