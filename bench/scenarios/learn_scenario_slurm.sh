#!/usr/bin/env bash
# Issue 62: the learning scenario (bench/scenarios/learn_scenario.sh, the real micro-model on the coarse scene)
# through a Slurm array and through the local pool from the same seeds; the served models must be
# the same bit for bit, round by round. Brings up a single-node cluster of its own
# (deploy/slurm/single-node-cluster.sh; root, slurm-wlm and munge), runs the scenario twice, compares
# every round's candidate and the served file with h5diff (provenance apart: creation times, run times, the
# database's path and hash), and the meso trace's passes. Writes OUT/local, OUT/slurm and OUT/compare.txt.
#   bash bench/scenarios/learn_scenario_slurm.sh [--out /tmp/learn-scenario-slurm] [--slurm-tasks 2] [learn_scenario.sh arguments...]
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
out=/tmp/learn-scenario-slurm tasks=2 pass=()
while (($#)); do
  case $1 in
    --out) out=$2; shift 2 ;;
    --slurm-tasks) tasks=$2; shift 2 ;;
    -h|--help) sed -n '2,8p' "$0"; exit 0 ;;
    *) pass+=("$1"); shift ;;
  esac
done
source "$here/deploy/slurm/single-node-cluster.sh"
single_node_slurm_until_exit
rm -rf "$out" && mkdir -p "$out"

started=$SECONDS
echo "== the scenario through the local pool"
bash "$here/bench/scenarios/learn_scenario.sh" --out "$out/local" "${pass[@]}" | tee "$out/local.txt"
local_wall=$((SECONDS - started))
echo "== the scenario through a Slurm array of $tasks tasks"
bash "$here/bench/scenarios/learn_scenario.sh" --out "$out/slurm" --slurm-tasks "$tasks" "${pass[@]}" | tee "$out/slurm.txt"
slurm_wall=$((SECONDS - started - local_wall))

{
  echo "wall: local pool $local_wall s, Slurm array $slurm_wall s"
  same=yes
  # Each round's candidate (published or kept aside) and the served file; versions/ names files by a
  # hash that covers their creation time, so those names differ by design.
  for f in "$out"/local/served/*.h5 "$out"/local/learner/candidates/*.h5; do
    [[ -e $f ]] || continue
    g=$out/slurm/${f#"$out"/local/}
    if [[ ! -e $g ]]; then echo "only through the local pool: ${f#"$out"/local/}"; same=no; continue; fi
    # Provenance differs by design: when the file and its database were written, how long runs took.
    if differing=$(bash "$here/tests/same_model_file.sh" "$f" "$g"); then
      echo "same: ${f#"$out"/local/}"
    else
      echo "differs: ${f#"$out"/local/}: $differing"; same=no
    fi
  done
  for g in "$out"/slurm/learner/candidates/*.h5; do
    [[ -e $g ]] || continue
    [[ -e $out/local/${g#"$out"/slurm/} ]] || { echo "only through Slurm: ${g#"$out"/slurm/}"; same=no; }
  done
  if cmp -s <(cut -d, -f1,3- "$out/local/passes.csv") <(cut -d, -f1,3- "$out/slurm/passes.csv"); then
    echo "the meso trace's passes: the same"
  else
    echo "the meso trace's passes differ:"; diff "$out/local/passes.csv" "$out/slurm/passes.csv" || true; same=no
  fi
  echo "bit for bit: $same"
} | tee "$out/compare.txt"
grep -q "bit for bit: yes" "$out/compare.txt"
