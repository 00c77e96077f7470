#!/usr/bin/env bash
# How mufric degrades when it gets fewer cores than it asked for: each command is timed with its
# default threads beside 0, 1 and 2 competing CPU-bound processes (busy loops), and once alone on one
# core with one thread (its single-core time, the reference). Goal: with one competing process on
# 2 cores, no command takes more than 2.2x its single-core time. Prints a markdown table.
# Usage: bash bench/benchmarks/busy_machine.sh [BUILD]          (BUILD defaults to build)
# Set GOMP_SPINCOUNT or OMP_WAIT_POLICY yourself to measure a wait policy other than mufric's own.
set -euo pipefail
if [[ ${1:-} == -h || ${1:-} == --help ]]; then sed -n '2,7p' "$0" | sed 's/^# \{0,1\}//'; exit 0; fi
build=${1:-build}
mufric=$(realpath "$build/app/mufric")
work=$(mktemp -d)
competitors=()
stop_competitors() { ((${#competitors[@]})) && kill "${competitors[@]}" 2>/dev/null; competitors=(); }
trap 'stop_competitors; kill ${servers[*]:-} 2>/dev/null || true; rm -rf "$work"' EXIT
cd "$work"
# Inputs: a 400-point dataset from seed 001's law (training), a 4-point micro plan (dataset run).
"$mufric" law seward --table 4 --out law.h5 >/dev/null
"$mufric" dataset from-model --model law.h5 --samples 400 --noise 0.002 --out db.h5 >/dev/null
"$mufric" train --data db.h5 --out gp.h5 >/dev/null
"$mufric" dataset plan --out plan.h5 --samples 4 >/dev/null
mkdir models && cp gp.h5 models/
seconds() { local s e; s=$(date +%s.%N); "$@" >/dev/null 2>&1; e=$(date +%s.%N); awk -v s="$s" -v e="$e" 'BEGIN { printf "%.3f", e - s }'; }
micro_run() { "$mufric" micro run --quiet --out run; }
dataset_run() { rm -f ds.h5; "$mufric" dataset run --plan plan.h5 --db ds.h5 --jobs 2; }
train() { "$mufric" train --data db.h5 --out trained.h5; }
# The service is measured by throughput, not time: 4 concurrent clients for 3 s, batch 1024 with the
# interval; its "time" is the seconds per million points.
serve_load() {  # ADDRESS
  "$mufric" bench --model "grpc://$1/gp" --batch 1024 --seconds 3 --std --clients 4 --json |
    sed -n 's/.*"points_per_second": \([0-9.e+]*\).*/\1/p' | awk '{ printf "%.4f", 1e6 / $1 }'
}
start_server() {  # NAME [PREFIX...]: starts a server in the background; its address goes to NAME.address
  local name=$1; shift
  "$@" "$mufric" serve --models models --listen 127.0.0.1:0 --ready-file "$name.address" >"$name.out" 2>"$name.log" &
  servers+=($!)
}
servers=()
start_server default
start_server one env OMP_NUM_THREADS=1 taskset -c 0
for _ in $(seq 100); do [[ -s default.address && -s one.address ]] && break; sleep 0.05; done
address=$(cat default.address) address_one_core=$(cat one.address)
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'); machine: $(lscpu | sed -n 's/Model name: *//p'), $(nproc) cores; load before: $(cut -d' ' -f1 /proc/loadavg)"
echo
echo "serve_load: seconds per million points (4 clients, batch 1024, mean + 95 % interval); its one-core"
echo "reference is a server pinned to one core with one thread."
echo
echo "| command | one core, one thread [s] | default, idle [s] | + 1 busy process [s] | + 2 busy [s] | 1 busy / one core |"
echo "|---|---|---|---|---|---|"
for command in micro_run dataset_run train serve_load; do
  if [[ $command == serve_load ]]; then
    reference=$(serve_load "$address_one_core")
  else
    reference=$(OMP_NUM_THREADS=1 seconds taskset -c 0 bash -c "$(declare -f $command); mufric=$mufric; $command")
  fi
  row=()
  for busy in 0 1 2; do
    for ((k = 0; k < busy; ++k)); do (while :; do :; done) & competitors+=($!); done
    if [[ $command == serve_load ]]; then row+=("$(serve_load "$address")"); else row+=("$(seconds $command)"); fi
    stop_competitors
  done
  ratio=$(awk -v a="${row[1]}" -v b="$reference" 'BEGIN { print a / b }')
  printf '| %s | %.2f | %.2f | %.2f | %.2f | %.2f |\n' "$command" "$reference" "${row[0]}" "${row[1]}" "${row[2]}" "$ratio"
done
