#!/usr/bin/env bash
# Slurm integration test: a single-node cluster (munge + slurmctld + slurmd, state in a temp
# directory, config passed by SLURM_CONF so /etc/slurm is untouched) runs a small array job of the
# real micro-model through deploy/slurm/submit-dataset.sh; the dependent merge job must produce a
# database in which every planned sample is present (converged or failed with a reason).
# Usage: tests/slurm_integration_test.sh MUFRIC_EXE. Needs root and Debian's slurm-wlm + munge
# (deploy/install-deps.sh); exits 77 (skipped) without them.
set -euo pipefail
mufric=$(realpath "$1")
repo=$(cd "$(dirname "$0")/.." && pwd)
if [[ $(id -u) -ne 0 ]] || ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
  echo "skipped: needs root, slurm-wlm and munge"
  exit 77
fi
S=$(mktemp -d /tmp/mufric-slurm.XXXXXX)
chmod 755 "$S"
started_munge=""
cleanup() {
  # The daemons were started with our config file: stop exactly those (SIGKILL if they linger).
  pkill -TERM -f "$S/slurm.conf" 2>/dev/null || true
  for _ in 1 2 3 4 5; do pgrep -f "$S/slurm.conf" >/dev/null || break; sleep 1; done
  pkill -KILL -f "$S/slurm.conf" 2>/dev/null || true
  [[ -n $started_munge && -s /run/munge/munged.pid ]] && kill "$(cat /run/munge/munged.pid)" 2>/dev/null || true
  rm -rf "$S"
}
trap cleanup EXIT

# munge: reuse a daemon that answers, else start one (--force: a dead daemon may have left its socket).
if ! munge -n >/dev/null 2>&1; then
  mkdir -p /run/munge && chown munge:munge /run/munge
  su -s /bin/sh munge -c "munged --force"
  started_munge=yes
  munge -n >/dev/null || { echo "FAIL: munged does not answer"; exit 1; }
fi

host=$(hostname -s)
export SLURM_CONF=$S/slurm.conf
cat > "$SLURM_CONF" <<CONF
ClusterName=mufrictest
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
ReturnToService=2
SlurmctldPidFile=$S/slurmctld.pid
SlurmdPidFile=$S/slurmd.pid
SlurmdSpoolDir=$S/slurmd
StateSaveLocation=$S/state
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SlurmctldLogFile=$S/ctld.log
SlurmdLogFile=$S/slurmd.log
NodeName=$host CPUs=$(nproc) RealMemory=2000 State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
mkdir -p "$S/slurmd" "$S/state"
slurmctld -c -f "$SLURM_CONF"
slurmd -c -f "$SLURM_CONF"
for _ in $(seq 1 60); do
  sinfo -h -o %T 2>/dev/null | grep -qE '^(idle|mixed)' && break
  sleep 1
done
sinfo -h -o %T | grep -qE '^(idle|mixed)' || { echo "FAIL: the node did not come up"; cat "$S"/*.log; exit 1; }

# A small plan of the real micro-model (a coarse, short scene: seconds per sample).
tiny=(--set geometry.chip_surface.fit.control_points=16 --set geometry.tool_surface.fit.control_points=16
      --set discretisation.elements_x=16 --set discretisation.elements_y=4 --set load.ramp=4ns
      --set protocol.press_hold=4ns --set protocol.run_in=0.05um --set protocol.window=0.1um
      --set protocol.step_distance=50nm --set protocol.phases=2 --set protocol.realisations=1)
"$mufric" dataset plan --out "$S/plan.h5" --samples 7 --design sobol "${tiny[@]}"
submitted=$(MUFRIC="$mufric" "$repo/deploy/slurm/submit-dataset.sh" "$S/plan.h5" "$S/out" 3)
echo "$submitted"
merge_job=$(sed -n 's/.*merge job \([0-9]*\).*/\1/p' <<<"$submitted")
[[ -n $merge_job ]] || { echo "FAIL: no merge job id in: $submitted"; exit 1; }

state=""
for _ in $(seq 1 300); do
  state=$(scontrol show job "$merge_job" 2>/dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p')
  [[ $state == COMPLETED || $state == FAILED || $state == CANCELLED || $state == TIMEOUT ]] && break
  sleep 1
done
echo "merge job $merge_job: $state"
cat "$S"/out/*.out 2>/dev/null | tail -20
[[ $state == COMPLETED ]] || { echo "FAIL: merge job ended $state"; tail -30 "$S/ctld.log"; exit 1; }

check=$("$mufric" dataset merge --out "$S/check.h5" "$S/out/db.h5")
echo "$check"
grep -q "0 duplicates removed -> 7 samples" <<<"$check" || { echo "FAIL: not 7 samples"; exit 1; }
grep -q "0 of 7 plan rows not yet run" <<<"$check" || { echo "FAIL: plan rows missing"; exit 1; }
ls "$S"/out/shard-{0,1,2}.h5 >/dev/null || { echo "FAIL: one shard per array task expected"; exit 1; }
echo "PASS: 3 array tasks + afterok merge, all 7 planned samples present"

# The learner (issue 62) through a Slurm array gives the same model, bit for bit, as through the
# local pool: one round on a simulator campaign (the shipped model standing in for the micro-model),
# run once each way from the same files. The model files differ only in their provenance: creation
# times, and the path and hash of their database file (its own creation time differs).
sim="$repo/models/dry_default.h5"
for engine in local slurm; do
  d=$S/learn-$engine
  mkdir -p "$d/served" "$d/logs"
  "$mufric" dataset plan --out "$d/plan.h5" --samples 12 --p 500MPa:1100MPa >/dev/null
  "$mufric" dataset run --plan "$d/plan.h5" --db "$d/db.h5" --simulator "$sim" >/dev/null
  "$mufric" train --data "$d/db.h5" --out "$d/served/gp.h5" --restarts 0 >/dev/null
  { echo "contact_pressure[Pa],sliding_velocity[m/s],temperature[K],ci95_width,outside_inputs"
    for i in 0 1 2 3 4 5; do echo "$((300 + 20 * i))e6,1.5,700,0.1,1"; done; } >"$d/logs/gp.csv"
  echo '{"queries": 60}' >"$d/logs/gp.outside.json"
  "$mufric" learn init "$d/learner" --db "$d/db.h5" --model "$d/served/gp.h5" --log "$d/logs/gp.csv" \
    --round-samples 4 --restarts 0 >/dev/null
done
"$mufric" learn run "$S/learn-local/learner" --simulator "$sim" | grep -E "planned|published|kept aside"
"$mufric" learn run "$S/learn-slurm/learner" --simulator "$sim" --slurm-tasks 2 --slurm-poll 0.5 |
  grep -E "submitted|planned|published|kept aside"
ls "$S"/learn-slurm/learner/round-1-runs/shard-{0,1}.h5 >/dev/null || { echo "FAIL: the round did not run as 2 shards"; exit 1; }
differing=$(h5diff -r "$S/learn-local/served/gp.h5" "$S/learn-slurm/served/gp.h5" 2>&1 |
  grep -E "^(attribute|dataset)|differences found" | grep -B1 -E "^[1-9][0-9]* differences" | grep -E "^(attribute|dataset)" |
  grep -vE "<(created_utc|seconds|dataset_path|dataset_sha256) of" || true)
[[ -z $differing ]] || { echo "FAIL: the Slurm round's model differs from the local one's: $differing"; exit 1; }
echo "PASS: a learner round through a 2-task Slurm array gives the local pool's model bit for bit"
