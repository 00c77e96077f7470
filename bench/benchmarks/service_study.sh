#!/usr/bin/env bash
# Service latency and throughput against batch size and concurrency, exact GP against the certified
# fast evaluator, in-process (file://) against unary gRPC over loopback; μ with its 95 % interval
# every time. Writes OUT/service_study.csv, a markdown table on stdout and OUT/service_study.png.
# The model: seed 001's Table 4 law sampled at 900 points with noise 0.002, fitted by `mufric train`
# (which builds the fast evaluator). Run it on a quiet machine: both cores are used.
# Usage: bash bench/benchmarks/service_study.sh [build-dir] [out-dir] [seconds-per-point]
set -euo pipefail
build=${1:-build}
out=${2:-bench/studies/service}
seconds=${3:-1}
mufric=$(realpath "$build/app/mufric")
# shellcheck source=bench/tools/service_common.sh
source "$(dirname "$0")/../tools/service_common.sh"
mkdir -p "$out"
work=$(mktemp -d)
server=
trap '[[ -n $server ]] && kill $server 2>/dev/null; rm -rf "$work"' EXIT
mkdir "$work/models"
seward_gp "$mufric" "$work" 900 "$work/models/gp.h5"
start_server "$work" "$mufric" serve --models "$work/models"
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'); machine: $(lscpu | sed -n 's/Model name: *//p'), $(nproc) cores;" \
  "load before: $(cut -d' ' -f1-3 /proc/loadavg); $seconds s per point"
csv=$out/service_study.csv
echo "transport,path,clients,batch,points_per_second,p50_us,p99_us,errors" >"$csv"
for path in exact fast; do
  flag=$([[ $path == exact ]] && echo --exact || true)
  for clients in 1 2 4; do
    for transport in in-process grpc; do
      uri=$([[ $transport == grpc ]] && echo "grpc://$address/gp" || echo "$work/models/gp.h5")
      # shellcheck disable=SC2086  # $flag is one word or none
      "$mufric" bench --model "$uri" --batch 1 16 256 4096 --clients $clients --seconds "$seconds" --json --std $flag |
        /usr/bin/python3 -c '
import json, sys
for line in sys.stdin:
    r = json.loads(line)
    print("%s,%s,%d,%d,%.6g,%.4g,%.4g,%d" % (sys.argv[1], sys.argv[2], r["clients"], r["batch"], r["points_per_second"],
                                            r["p50_us"], r["p99_us"], r["errors"]))' "$transport" "$path" >>"$csv"
    done
  done
done
/usr/bin/python3 - "$csv" "$out/service_study.png" <<'PY'
import csv, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
rows = list(csv.DictReader(open(sys.argv[1])))
key = lambda r: (r["path"], int(r["clients"]), int(r["batch"]))
by = {(r["transport"],) + key(r): r for r in rows}
print("| path | clients | batch | in-process points/s | gRPC points/s | gRPC/in-process | in-process p50 [us] | gRPC p50 [us] | gRPC p99 [us] |")
print("|---|---|---|---|---|---|---|---|---|")
for r in rows:
    if r["transport"] != "in-process":
        continue
    g = by[("grpc",) + key(r)]
    print(f"| {r['path']} | {r['clients']} | {r['batch']} | {float(r['points_per_second']):.4g} | "
          f"{float(g['points_per_second']):.4g} | {float(g['points_per_second']) / float(r['points_per_second']):.0%} | "
          f"{r['p50_us']} | {g['p50_us']} | {g['p99_us']} |")
fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
styles = {("in-process", "exact"): ("C0", "--"), ("in-process", "fast"): ("C0", "-"),
          ("grpc", "exact"): ("C3", "--"), ("grpc", "fast"): ("C3", "-")}
markers = {1: "o", 2: "s", 4: "^"}
for (transport, path), (colour, line) in styles.items():
    for clients, marker in markers.items():
        sel = sorted((int(r["batch"]), float(r["points_per_second"]), float(r["p50_us"])) for r in rows
                     if r["transport"] == transport and r["path"] == path and int(r["clients"]) == clients)
        if not sel:
            continue
        b = [s[0] for s in sel]
        label = f"{transport}, {path}, {clients} client{'s' if clients > 1 else ''}"
        axes[0].loglog(b, [s[1] for s in sel], line, color=colour, marker=marker, alpha=0.5 + 0.5 / clients, label=label)
        axes[1].loglog(b, [s[2] for s in sel], line, color=colour, marker=marker, alpha=0.5 + 0.5 / clients)
axes[0].set(xlabel="batch [points per call]", ylabel="points per second (all clients)", title="throughput, mu + 95 % CI")
axes[1].set(xlabel="batch [points per call]", ylabel="p50 latency per call [us]", title="latency")
for a in axes:
    a.grid(True, which="both", alpha=0.3)
axes[0].legend(fontsize=6.5, ncol=2)
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=120)
PY
echo "wrote $csv and $out/service_study.png"
