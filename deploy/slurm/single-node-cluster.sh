#!/usr/bin/env bash
# A single-node Slurm cluster for tests and benchmarks on one Debian 12 machine (as root; slurm-wlm and
# munge from deploy/install-deps.sh): munge, slurmctld and slurmd with their state in a directory of
# their own and the config passed by SLURM_CONF, so /etc/slurm is untouched (one slurm.conf naming
# this host as controller and node, process tracking by /proc, no cgroups; munged reused or started). Source it, then
#   single_node_slurm_start DIR   # exports SLURM_CONF=DIR/slurm.conf; returns 1 (with the logs) if the node does not come up
#   single_node_slurm_stop DIR    # stops exactly the daemons started with DIR's config, and a munged it started
#   single_node_slurm_until_exit  # for a benchmark script: refuses (exit 2) without root, slurm-wlm or
#                                 # munge, starts one in a fresh directory and stops it when the script exits
# Tasks get the node's CPUs (nproc) and 2000 MB in all.

single_node_slurm_started_munge=""

single_node_slurm_start() {
  local dir=$1 host
  host=$(hostname -s)
  chmod 755 "$dir"
  # munge: reuse a daemon that answers, else start one (--force: a dead daemon may have left its socket).
  if ! munge -n >/dev/null 2>&1; then
    mkdir -p /run/munge && chown munge:munge /run/munge
    su -s /bin/sh munge -c "munged --force"
    single_node_slurm_started_munge=yes
    munge -n >/dev/null || { echo "munged does not answer"; return 1; }
  fi
  export SLURM_CONF=$dir/slurm.conf
  cat > "$SLURM_CONF" <<CONF
ClusterName=mufrictest
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
ReturnToService=2
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmdSpoolDir=$dir/slurmd
StateSaveLocation=$dir/state
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SlurmctldLogFile=$dir/ctld.log
SlurmdLogFile=$dir/slurmd.log
NodeName=$host CPUs=$(nproc) RealMemory=2000 State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
  mkdir -p "$dir/slurmd" "$dir/state"
  slurmctld -c -f "$SLURM_CONF"
  slurmd -c -f "$SLURM_CONF"
  for _ in $(seq 1 60); do
    sinfo -h -o %T 2>/dev/null | grep -qE '^(idle|mixed)' && return 0
    sleep 1
  done
  echo "the node did not come up"
  cat "$dir"/*.log
  return 1
}

single_node_slurm_stop() {
  local dir=$1
  # The daemons were started with this config file: stop exactly those (SIGKILL if they linger).
  pkill -TERM -f "$dir/slurm.conf" 2>/dev/null || true
  for _ in 1 2 3 4 5; do pgrep -f "$dir/slurm.conf" >/dev/null || break; sleep 1; done
  pkill -KILL -f "$dir/slurm.conf" 2>/dev/null || true
  if [[ -n $single_node_slurm_started_munge && -s /run/munge/munged.pid ]]; then
    kill "$(cat /run/munge/munged.pid)" 2>/dev/null || true
  fi
}

single_node_slurm_until_exit() {
  if [[ $(id -u) -ne 0 ]] || ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    echo "needs root, slurm-wlm and munge (deploy/install-deps.sh)"
    exit 2
  fi
  single_node_slurm_dir=$(mktemp -d /tmp/mufric-slurm.XXXXXX)
  trap 'single_node_slurm_stop "$single_node_slurm_dir"; rm -rf "$single_node_slurm_dir"' EXIT
  single_node_slurm_start "$single_node_slurm_dir"
}
