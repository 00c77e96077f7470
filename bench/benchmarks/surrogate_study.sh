#!/usr/bin/env bash
# The surrogate's run time against its error: held-out error of the GP against training size, and
# the cost per point of μ with its 95 % interval on one core, exact GP against the certified fast
# evaluator (batch of 10 000 and a single point). The data: seed 001's Table 4 law sampled with
# noise 0.002 (training) and without (2000 held-out points), so the error is the surrogate's own.
# Writes OUT/surrogate_study.csv, a markdown table on stdout and OUT/surrogate_study.png.
# Usage: bash bench/benchmarks/surrogate_study.sh [build-dir] [out-dir] [sizes...]   (default 60 120 250 500 900 1600)
set -euo pipefail
build=${1:-build}
out=${2:-bench/studies/surrogate_error_and_cost}
shift 2 2>/dev/null || true
sizes=${*:-60 120 250 500 900 1600}
mufric=$(realpath "$build/app/mufric")
mkdir -p "$out"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'); machine: $(lscpu | sed -n 's/Model name: *//p'), $(nproc) cores;" \
  "load before: $(cut -d' ' -f1-3 /proc/loadavg); costs on core 1, OMP_NUM_THREADS=1"
"$mufric" law seward --table 4 --out law.h5 >/dev/null
"$mufric" dataset from-model --model law.h5 --samples 2000 --seed 99 --out test.h5 >/dev/null
csv=$out/surrogate_study.csv
echo "n,train_s,mean_rel_err,max_rel_err,coverage95,fast_mb,fast_build_s,fast_certified,exact_us,fast_us,exact_single_us,fast_single_us" >"$csv"
cost() {  # µs per point: model, batch, extra flag
  # shellcheck disable=SC2086
  OMP_NUM_THREADS=1 taskset -c 1 "$mufric" bench --model "$1" --batch "$2" --seconds 1 --json --std $3 |
    /usr/bin/python3 -c 'import json, sys; r = json.loads(sys.stdin.readline()); print("%.4g" % (1e6 / r["points_per_second"]))'
}
for n in $sizes; do
  "$mufric" dataset from-model --model law.h5 --samples "$n" --noise 0.002 --seed 7 --out "d$n.h5" >/dev/null
  start=$(date +%s.%N)
  "$mufric" train --data "d$n.h5" --out "g$n.h5" >"train$n.log"
  train_s=$(echo "$(date +%s.%N) - $start" | bc)
  "$mufric" eval --model "g$n.h5" --test test.h5 >"eval$n.log"
  mean=$(sed -n 's/^mean relative error *\([0-9.]*\) %/\1/p' "eval$n.log")
  max=$(sed -n 's/^max relative error *\([0-9.]*\) %/\1/p' "eval$n.log")
  coverage=$(sed -n 's/^95 % interval coverage *\([0-9.]*\) %/\1/p' "eval$n.log")
  fast_mb=$(sed -n 's/^fast evaluator (model): \([0-9.]*\) MB, built in .*/\1/p' "train$n.log")
  fast_s=$(sed -n 's/^fast evaluator (model): .* built in \([0-9.]*\) s.*/\1/p' "train$n.log")
  certified=$(grep -q "does NOT meet" "train$n.log" && echo no || echo yes)
  echo "$n,$train_s,$mean,$max,$coverage,$fast_mb,$fast_s,$certified,$(cost "g$n.h5" 10000 --exact),$(cost "g$n.h5" 10000 ""),$(cost "g$n.h5" 1 --exact),$(cost "g$n.h5" 1 "")" >>"$csv"
  tail -1 "$csv" >&2
done
/usr/bin/python3 - "$csv" "$out/surrogate_study.png" <<'PY'
import csv, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
rows = list(csv.DictReader(open(sys.argv[1])))
print("| n | train [s] | held-out mean / max rel. error | 95 % coverage | grid [MB] | grid certified | exact [us/pt] | fast [us/pt] | exact single [us] | fast single [us] |")
print("|---|---|---|---|---|---|---|---|---|---|")
for r in rows:
    print(f"| {r['n']} | {float(r['train_s']):.1f} | {r['mean_rel_err']} % / {r['max_rel_err']} % | {r['coverage95']} % | "
          f"{r['fast_mb']} | {r['fast_certified']} | {r['exact_us']} | {r['fast_us']} | {r['exact_single_us']} | {r['fast_single_us']} |")
n = [int(r["n"]) for r in rows]
err = [float(r["mean_rel_err"]) for r in rows]
fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
axes[0].loglog(n, err, "o-", label="held-out mean relative error [%]")
axes[0].loglog(n, [float(r["max_rel_err"]) for r in rows], "s--", label="held-out max relative error [%]")
axes[0].set(xlabel="training points n", ylabel="error [%]", title="surrogate error against training size")
axes[0].legend(fontsize=8)
for key, style, label in [("exact_us", "o--", "exact GP, batch 10 000"), ("fast_us", "o-", "fast evaluator, batch 10 000"),
                          ("exact_single_us", "s--", "exact GP, one point"), ("fast_single_us", "s-", "fast evaluator, one point")]:
    axes[1].loglog([float(r[key]) for r in rows], err, style, label=label)
    for r, e in zip(rows, err):
        axes[1].annotate(r["n"], (float(r[key]), e), fontsize=6, alpha=0.6)
uncertified = [r for r in rows if r["fast_certified"] != "yes"]
if uncertified:
    axes[1].loglog([float(r["fast_us"]) for r in uncertified], [float(r["mean_rel_err"]) for r in uncertified], "rx",
                   markersize=10, label="grid not certified: exact answers")
axes[1].set(xlabel="cost of mu + 95 % CI per point, one core [us]", ylabel="held-out mean relative error [%]",
            title="error against evaluation cost")
axes[1].legend(fontsize=7)
for a in axes:
    a.grid(True, which="both", alpha=0.3)
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=120)
PY
echo "wrote $csv and $out/surrogate_study.png"
