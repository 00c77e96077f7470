#!/usr/bin/env bash
# What a gRPC call costs beside the evaluation it carries, with the certified fast evaluator: the
# server pinned to core 0 (--threads 1), the client to core 1, μ with its 95 % interval. Measures
# in-process, unary and stream calls at batches 1 … 65536 (the client with glibc's defaults and with
# freed heap kept, MALLOC_TRIM_THRESHOLD_ / MALLOC_MMAP_THRESHOLD_), then splits a call's time into a
# fixed part (batch 1) and a per-point part, and prints what the 80 %-of-in-process goal leaves for
# both at batch 4096. Needs 2 cores and a quiet machine.
# Usage: bash bench/benchmarks/grpc_budget.sh [build-dir] [seconds-per-point] [rounds]
set -euo pipefail
build=${1:-build}
seconds=${2:-1}
rounds=${3:-2}
mufric=$(realpath "$build/app/mufric")
# shellcheck source=bench/tools/service_common.sh
source "$(dirname "$0")/../tools/service_common.sh"
work=$(mktemp -d)
server=
trap '[[ -n $server ]] && kill $server 2>/dev/null; rm -rf "$work"' EXIT
mkdir "$work/models"
seward_gp "$mufric" "$work" 900 "$work/models/gp.h5"
start_server "$work" env OMP_NUM_THREADS=1 taskset -c 0 "$mufric" serve --models "$work/models" --threads 1
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'); machine: $(lscpu | sed -n 's/Model name: *//p'), $(nproc) cores;" \
  "load before: $(cut -d' ' -f1-3 /proc/loadavg); $seconds s per point, $rounds rounds"
batches="1 256 4096 16384 65536"
keep_heap="MALLOC_TRIM_THRESHOLD_=268435456 MALLOC_MMAP_THRESHOLD_=33554432"
measure() {  # variant uri [client-options] [env...]: one JSON line per batch, tagged with the variant
  local variant=$1 uri=$2 options=${3:-}
  shift 3
  # shellcheck disable=SC2086  # $batches: one word per batch size
  env "$@" OMP_NUM_THREADS=1 taskset -c 1 "$mufric" bench --model "$uri" --batch $batches --seconds "$seconds" \
    --std --json ${options:+--client-options "$options"} |
    sed "s/^{/{\"variant\":\"$variant\",/"
}
for _ in $(seq "$rounds"); do  # the variants alternate, so a drifting machine shows as spread, not bias
  measure in-process "$work/models/gp.h5" ""
  measure unary "grpc://$address/gp" ""
  measure stream "grpc://$address/gp" "stream=1"
  # shellcheck disable=SC2086  # two VAR=value words
  measure "unary, heap kept" "grpc://$address/gp" "" $keep_heap
  # shellcheck disable=SC2086
  measure "stream, heap kept" "grpc://$address/gp" "stream=1" $keep_heap
done >"$work/runs.json"
/usr/bin/python3 - "$work/runs.json" <<'PY'
import json, sys
from collections import defaultdict
runs = defaultdict(list)  # (variant, batch) -> p50 latencies [us], one per round
for line in open(sys.argv[1]):
    r = json.loads(line)
    runs[(r["variant"], r["batch"])].append(r["p50_us"])
variants = ["in-process", "unary", "stream", "unary, heap kept", "stream, heap kept"]
batches = sorted({b for _, b in runs})
med = lambda xs: sorted(xs)[len(xs) // 2]
print("p50 latency per call [us] (each round's value) and throughput against in-process (median rounds):\n")
print("| batch | " + " | ".join(variants) + " |")
print("|---|" + "---|" * len(variants))
for b in batches:
    cells = []
    for v in variants:
        xs = runs[(v, b)]
        ratio = "" if v == "in-process" else " (%.0f %%)" % (100 * med(runs[("in-process", b)]) / med(xs))
        cells.append(", ".join("%.1f" % x for x in xs) + ratio)
    print("| %d | %s |" % (b, " | ".join(cells)))
inproc = med(runs[("in-process", 4096)])
budget = inproc / 0.8 - inproc
print("\nAt batch 4096 in-process takes %.0f us per call; 80 %% of its throughput leaves %.0f us per call for "
      "everything gRPC adds." % (inproc, budget))
print("\n| transport | fixed (batch 1) [us] | per point at 4096 [ns] | overhead at 4096 [us] | of the budget |")
print("|---|---|---|---|---|")
for v in variants[1:]:
    fixed = med(runs[(v, 1)]) - med(runs[("in-process", 1)])
    overhead = med(runs[(v, 4096)]) - inproc
    per_point = 1e3 * (overhead - fixed) / 4096
    print("| %s | %.0f | %.1f | %.0f | %.1fx |" % (v, fixed, per_point, overhead, overhead / budget))
PY
