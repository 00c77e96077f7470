#!/usr/bin/env bash
# Held-out error of the GP against the number of micro-model runs: random vs Sobol' plans vs active
# learning (dataset refine), on the default press-slide protocol. SCENE "coarse" (default) is the dry
# scene made cheap enough for hundreds of runs on 2 cores (32 × 6 quadratic elements,
# deploy/coarse_scene.sh, 8–14 s of one core per run); "default" is the default 64 × 12 scene (1.25 %
# from the converged mesh, ~45 s per run). STRATEGIES is any of "random sobol active".
# Writes OUT/strategies.csv and OUT/strategies.png and prints a markdown table.
# Usage: bash bench/studies/dataset_strategies/dataset_strategies.sh [build-dir] [out-dir] [max-runs] [coarse|default] [strategies...]
set -euo pipefail
build=${1:-build}
out=${2:-dataset-strategies}
max=${3:-128}
scene_name=${4:-coarse}
strategies=("${@:5}")
((${#strategies[@]})) || strategies=(random sobol active)
mufric=$(realpath "$build/app/mufric")
source "$(dirname "$(realpath "$0")")/../../../deploy/coarse_scene.sh"
case $scene_name in
  coarse) scene=("${coarse_scene[@]}") ;;
  default) scene=() ;;
  *) echo "dataset_strategies.sh: scene must be 'coarse' or 'default', not '$scene_name'" >&2; exit 2 ;;
esac
wants() { [[ " ${strategies[*]} " == *" $1 "* ]]; }
mkdir -p "$out"
cd "$out"
run=(--jobs 2 --threads 1)
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'); machine: $(lscpu | sed -n 's/Model name: *//p'), $(nproc) cores; max runs $max; scene $scene_name; strategies ${strategies[*]}" >&2
echo "strategy,runs,converged,mean_relative_error,max_relative_error,coverage95" > strategies.csv

# Held-out set: random points, a seed no plan uses.
[[ -f test.h5 ]] || { "$mufric" dataset plan --out test-plan.h5 --samples 60 --design random --seed 99 "${scene[@]}" >/dev/null
                      "$mufric" dataset run --plan test-plan.h5 --db test.h5 "${run[@]}" >/dev/null; }

evaluate() {  # strategy runs db
  "$mufric" train --data "$3" --out "$1-$2.gp.h5" --restarts 2 >/dev/null
  local e converged
  e=$("$mufric" eval --model "$1-$2.gp.h5" --test test.h5)
  converged=$(/usr/bin/python3 -c "import h5py,sys; f=h5py.File(sys.argv[1]); print(int((f['samples/status'][:]==0).sum()))" "$3")
  echo "$1,$2,$converged,$(sed -n 's/^mean relative error *\([0-9.]*\) %.*/\1/p' <<<"$e"),$(sed -n 's/^max relative error *\([0-9.]*\) %.*/\1/p' <<<"$e"),$(sed -n 's/.*interval coverage \([0-9.]*\) %.*/\1/p' <<<"$e")" >> strategies.csv
}

sizes=()
for ((n = 16; n <= max; n *= 2)); do sizes+=("$n"); done
for design in random sobol; do
  wants "$design" || continue
  "$mufric" dataset plan --out "$design-plan.h5" --samples "$max" --design "$design" --seed 1 "${scene[@]}" >/dev/null
  done_runs=0
  for n in "${sizes[@]}"; do
    "$mufric" dataset run --plan "$design-plan.h5" --db "$design.h5" --limit $((n - done_runs)) "${run[@]}" >/dev/null
    done_runs=$n
    cp "$design.h5" "$design-$n.h5"
    evaluate "$design" "$n" "$design-$n.h5"
  done
done

# Active learning from the first 16 Sobol' points, 16 runs per round.
if wants active; then
"$mufric" dataset plan --out active-plan.h5 --samples 16 --design sobol --seed 1 "${scene[@]}" >/dev/null
rm -f active.h5
"$mufric" dataset run --plan active-plan.h5 --db active.h5 "${run[@]}" >/dev/null
n=16
evaluate active "$n" active.h5
while ((n < max)); do
  "$mufric" dataset refine --db active.h5 --budget 16 --batch 16 --restarts 2 --jobs 2 --threads 1 >/dev/null
  n=$((n + 16))
  evaluate active "$n" active.h5
done
fi

scene_name=$scene_name /usr/bin/python3 - <<'PY'
import csv, os
scene_name = os.environ["scene_name"]
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
rows = list(csv.DictReader(open("strategies.csv")))
print("| strategy | runs | converged | held-out mean rel. error [%] | max [%] | 95 % coverage [%] |")
print("|---|---|---|---|---|---|")
for r in rows:
    print(f"| {r['strategy']} | {r['runs']} | {r['converged']} | {r['mean_relative_error']} | {r['max_relative_error']} | {r['coverage95']} |")
fig, ax = plt.subplots(figsize=(6, 4))
for s, marker in (("random", "o"), ("sobol", "s"), ("active", "^")):
    pts = [(int(r["runs"]), float(r["mean_relative_error"])) for r in rows if r["strategy"] == s]
    if pts:
        ax.plot(*zip(*pts), marker=marker, label=s)
ax.axhline(1.0, color="grey", linestyle="--", label="1 % (the paper's dry error)")
ax.set_xscale("log", base=2)
ax.set_xlabel("micro-model runs")
ax.set_ylabel("held-out mean relative error [%]")
ax.set_title(f"GP surrogate of the {scene_name} dry scene: error vs runs")
ax.legend()
fig.tight_layout()
fig.savefig("strategies.png", dpi=120)
PY
