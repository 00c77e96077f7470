# shellcheck shell=bash
# Sourced by the service benchmarks (service_study.sh, grpc_budget.sh) and the learning scenarios.

# seward_gp MUFRIC WORK SAMPLES OUT: seed 001's Table 4 law sampled at SAMPLES points (noise 0.002)
# and fitted by `mufric train`, which builds the certified fast evaluator, into OUT.
seward_gp() {
  local mufric=$1 work=$2 samples=$3 out=$4
  "$mufric" law seward --table 4 --out "$work/law.h5" >/dev/null
  "$mufric" dataset from-model --model "$work/law.h5" --samples "$samples" --noise 0.002 --out "$work/db.h5" >/dev/null
  "$mufric" train --data "$work/db.h5" --out "$out" >/dev/null
}

# start_server WORK COMMAND...: runs COMMAND (a `mufric serve` with its options, behind any env or
# taskset) on a free loopback port; sets `server` (its pid) and `address` (host:port). Waits up to
# server_start_seconds (default 10) for it to listen: a calibrated model takes longer to load.
# shellcheck disable=SC2034  # server and address are for the sourcing script
start_server() {
  local work=$1
  shift
  "$@" --listen 127.0.0.1:0 --ready-file "$work/address" 2>"$work/server.log" &
  server=$!
  for _ in $(seq $((${server_start_seconds:-10} * 20))); do [[ -s $work/address ]] && break; sleep 0.05; done
  [[ -s $work/address ]] || { echo "the server did not start:" >&2; cat "$work/server.log" >&2; exit 1; }
  address=$(cat "$work/address")
}
