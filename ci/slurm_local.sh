#!/usr/bin/env bash
# A one-node Slurm cluster on this machine (localhost), for `verdem ensemble --engine slurm` and
# tests/ensemble.rs: munge's key, /etc/slurm/slurm.conf, then munged, slurmctld and slurmd,
# started as root. Settings that need no cgroups, so that it runs in a container: process
# tracking by the process tree (proctrack/linuxproc), no task plugin, no accounting. Needs Debian's
# `slurm-wlm` and `munge` (ci/test.sh installs them). Idempotent: when the daemons already answer
# and the configuration is unchanged, it only checks the node and returns. docs/ensembles.md.
set -euo pipefail

if [ "$(id -u)" != 0 ]; then
  echo "slurm_local.sh: must run as root (it writes /etc/slurm and starts the daemons)" >&2
  exit 1
fi
for bin in munged slurmctld slurmd sbatch squeue sinfo scontrol; do
  command -v "$bin" >/dev/null || {
    echo "slurm_local.sh: $bin not found; install Debian's slurm-wlm and munge" >&2
    exit 1
  }
done

nproc=$(nproc)
cpus=$(( nproc < 2 ? nproc : 2 ))
conf=/etc/slurm/slurm.conf
want=$(cat <<EOF
# One-node cluster on localhost for verdem's ensembles (written by ci/slurm_local.sh).
ClusterName=verdem
SlurmctldHost=localhost
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
# no cgroups (containers): track a job's processes by their parent, bind nothing
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
NodeName=localhost NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=debug Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
)

changed=0
if [ "$(cat "$conf" 2>/dev/null)" != "$want" ]; then
  mkdir -p /etc/slurm
  printf '%s\n' "$want" > "$conf"
  changed=1
fi
mkdir -p /var/spool/slurmctld /var/spool/slurmd /var/log/slurm

# munge: a key readable by the munge user only, and its daemon
if [ ! -s /etc/munge/munge.key ]; then
  mungekey --create --keyfile=/etc/munge/munge.key
fi
chown munge:munge /etc/munge/munge.key
chmod 0400 /etc/munge/munge.key
mkdir -p /run/munge /var/log/munge /var/lib/munge
chown munge:munge /run/munge /var/log/munge /var/lib/munge
if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
  runuser -u munge -- munged
  for _ in $(seq 50); do
    munge -n 2>/dev/null | unmunge >/dev/null 2>&1 && break
    sleep 0.1
  done
  munge -n | unmunge >/dev/null
fi

# a daemon runs when the process of its pid file is alive
pid_of() { cat "/run/$1.pid" 2>/dev/null || true; }
running() { local p; p=$(pid_of "$1"); [ -n "$p" ] && kill -0 "$p" 2>/dev/null; }
if [ "$changed" = 1 ]; then
  # a new configuration: restart the daemons that run with the old one
  for d in slurmd slurmctld; do
    if running "$d"; then
      kill "$(pid_of "$d")"
      for _ in $(seq 50); do running "$d" || break; sleep 0.1; done
    fi
  done
fi
running slurmctld || slurmctld
running slurmd || slurmd -N localhost

# the node must be idle (or busy with jobs) before jobs can run on it
state=
for _ in $(seq 100); do
  state=$(sinfo -h -n localhost -o %t 2>/dev/null || true)
  case "$state" in
    idle|mix|alloc) break ;;
    down*|drain*|drng*|inval*) scontrol update nodename=localhost state=resume 2>/dev/null || true ;;
  esac
  sleep 0.2
done
case "$state" in
  idle|mix|alloc) echo "slurm: node localhost $state ($cpus CPUs)" ;;
  *)
    echo "slurm_local.sh: node localhost is '$state', not idle; see /var/log/slurm/slurmd.log and slurmctld.log" >&2
    exit 1
    ;;
esac
