#!/bin/bash
# A one-node Slurm cluster on this machine, to try deploy/slurm-array.sh on
# (and for its test in host/tests/cli.rs). Needs root and the distribution's
# packages (Debian: `apt-get install slurm-wlm munge`).
#
#     deploy/slurm-local.sh start DIR   # then: export SLURM_CONF=DIR/slurm.conf
#     deploy/slurm-local.sh stop DIR
set -euo pipefail
dir=$(mkdir -p "${2:?usage: $0 start|stop DIR}" && cd "$2" && pwd)
case "${1:-}" in
  start)
    mkdir -p "$dir/spool" "$dir/state" "$dir/log"
    host=$(hostname -s)
    cat > "$dir/slurm.conf" <<CONF
ClusterName=treelet-local
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
# No cgroups or accounting: a plain machine or container has neither set up.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
NodeName=$host CPUs=$(nproc) State=UNKNOWN
PartitionName=local Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
    # munge authenticates Slurm's messages; the package makes its key.
    mkdir -p /run/munge
    if ! pgrep -x munged >/dev/null; then munged --force; fi
    slurmctld -f "$dir/slurm.conf"
    slurmd -f "$dir/slurm.conf"
    for _ in $(seq 50); do
      if SLURM_CONF="$dir/slurm.conf" sinfo -h -o %t 2>/dev/null | grep -q idle; then
        echo "export SLURM_CONF=$dir/slurm.conf"
        exit 0
      fi
      sleep 0.2
    done
    echo "the node did not come up; see $dir/log" >&2
    exit 1
    ;;
  stop)
    for d in slurmd slurmctld; do
      [ -f "$dir/$d.pid" ] || continue
      pid=$(cat "$dir/$d.pid")
      kill "$pid" 2>/dev/null || continue
      # Gone before the next cluster takes its ports.
      for _ in $(seq 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    done
    ;;
  *)
    echo "usage: $0 start|stop DIR" >&2
    exit 2
    ;;
esac
