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
source "$repo/deploy/slurm/single-node-cluster.sh"
cleanup() {
  single_node_slurm_stop "$S"
  rm -rf "$S"
}
trap cleanup EXIT
single_node_slurm_start "$S" || { echo "FAIL: the cluster did not start"; exit 1; }

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
differing=$(bash "$repo/tests/same_model_file.sh" "$S/learn-local/served/gp.h5" "$S/learn-slurm/served/gp.h5") ||
  { echo "FAIL: the Slurm round's model differs from the local one's: $differing"; exit 1; }
echo "PASS: a learner round through a 2-task Slurm array gives the local pool's model bit for bit"
