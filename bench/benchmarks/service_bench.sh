#!/usr/bin/env bash
# The friction service against the in-process evaluator, same model, same run (issue 3):
#   1. batch sizes 1, 64, 1024, 4096, 16384, mean only and with a 95 % interval: in-process (file://),
#      unary gRPC and EvaluateStream over loopback, one client;
#   2. a meso-trace replay (2000 points drifting over 300 increments) on the three transports;
#   3. soak: 32 concurrent clients for 60 s (batch 64, with interval), errors counted, server
#      resident memory sampled every 10 s.
# Usage: bash bench/benchmarks/service_bench.sh [build-dir] [model.h5]   (default: a GP fitted to 900 points)
set -euo pipefail
build=${1:-build}
mufric=$build/app/mufric
work=$(mktemp -d)
trap 'kill $server 2>/dev/null || true; rm -rf "$work"' EXIT
mkdir "$work/models"
if [[ -n ${2:-} ]]; then
  cp "$2" "$work/models/gp.h5"
else
  /usr/bin/python3 - "$work/train.csv" <<'PY'
import sys, numpy as np
rng = np.random.default_rng(2026)
raw = np.column_stack([rng.uniform(300, 1300, 900), rng.uniform(22.5, 200, 900), rng.uniform(25, 900, 900)])
ps, vs, ts = (raw[:, 0] - 300) / 1000, (raw[:, 1] - 22.5) / 177.5, (raw[:, 2] - 25) / 875
mu = 0.3 - 0.08 * ps + 0.05 * np.sin(3 * vs) + 0.1 * np.exp(-2 * ts) * (1 + 0.3 * ps * vs) + rng.normal(0, 5e-4, 900)
with open(sys.argv[1], "w") as f:
    f.write("contact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu\n")
    for r, m in zip(raw, mu): f.write(f"{r[0]!r},{r[1]!r},{r[2]!r},{m!r}\n")
PY
  "$mufric" train --data "$work/train.csv" --out "$work/models/gp.h5" >/dev/null
fi
"$mufric" serve --models "$work/models" --listen 127.0.0.1:0 --ready-file "$work/address" 2>"$work/server.log" &
server=$!
for _ in $(seq 100); do [[ -s $work/address ]] && break; sleep 0.05; done
address=$(cat "$work/address")
batches="1 64 1024 4096 16384"
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'); machine: $(lscpu | sed -n 's/Model name: *//p'), $(nproc) cores"
for ci in "" "--std"; do
  echo; echo "== ${ci:-mean only}"
  printf '| batch | in-process points/s | unary gRPC points/s | ratio | unary p50 [us] | stream points/s | ratio | stream p50 [us] |\n|---|---|---|---|---|---|---|---|\n'
  local_json=$("$mufric" bench --model "$work/models/gp.h5" --batch $batches --seconds 1 --json $ci)
  unary_json=$("$mufric" bench --model "grpc://$address/gp" --batch $batches --seconds 1 --json $ci)
  stream_json=$("$mufric" bench --model "grpc://$address/gp" --batch $batches --seconds 1 --json --stream $ci)
  /usr/bin/python3 - "$local_json" "$unary_json" "$stream_json" <<'PY'
import json, sys
rows = [[json.loads(l) for l in block.splitlines()] for block in sys.argv[1:4]]
for l, u, s in zip(*rows):
    print(f"| {l['batch']} | {l['points_per_second']:.4g} | {u['points_per_second']:.4g} | "
          f"{u['points_per_second'] / l['points_per_second']:.0%} | {u['p50_us']:.4g} | "
          f"{s['points_per_second']:.4g} | {s['points_per_second'] / l['points_per_second']:.0%} | {s['p50_us']:.4g} |")
PY
done
echo; echo "== meso-trace replay: 2000 contact points x 300 increments, drifting states, mean + 95 % interval"
for uri in "$work/models/gp.h5" "grpc://$address/gp"; do
  "$mufric" bench --model "$uri" --replay 2000,300 --std
done
"$mufric" bench --model "grpc://$address/gp" --replay 2000,300 --std --stream | sed 's/$/ (stream)/'

echo; echo "== soak: 32 clients x 60 s, batch 64, mean + 95 % interval"
rss() { awk '/VmRSS/ {print $2 " kB"}' /proc/$server/status; }
echo "server RSS before: $(rss)"
"$mufric" bench --model "grpc://$address/gp" --batch 64 --clients 32 --seconds 60 --std &
bench=$!
for t in 10 20 30 40 50; do sleep 10; echo "server RSS at ${t} s: $(rss)"; done
wait $bench
echo "server RSS after: $(rss)"
kill -TERM $server
wait $server && echo "server drained and exited 0"
tail -1 "$work/server.log"
