#!/usr/bin/env bash
# CI: a real one-node Slurm cluster on this machine (localhost), from Debian's slurm-wlm and
# munge packages: installs them if needed, starts munged, slurmctld and slurmd as plain
# daemons (no systemd here), and waits until the node is idle. Safe to run again while the
# cluster runs: then it checks it and returns at once.
# Usage: .ci/slurm-up.sh   (as root; daemon logs go to /var/log/slurm-ci)
set -euo pipefail
log_dir=/var/log/slurm-ci
conf=/etc/slurm/slurm.conf # where Debian 12's slurm-wlm (22.05) looks

# 1. The packages.
if ! command -v sbatch >/dev/null || ! command -v slurmctld >/dev/null \
  || ! command -v slurmd >/dev/null || ! command -v munged >/dev/null; then
  apt-get update -qq || echo 'apt-get update failed; installing from the lists there are'
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge
fi
for c in sbatch sinfo scontrol slurmctld slurmd munged munge unmunge; do
  command -v "$c" >/dev/null || { echo "slurm-up: $c is missing after installing slurm-wlm and munge"; exit 1; }
done
mkdir -p "$log_dir"

# 2. munge, which Slurm uses to authenticate its messages.
if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
  if [ ! -s /etc/munge/munge.key ]; then
    mkdir -p /etc/munge
    dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none
  fi
  chown -R munge:munge /etc/munge
  chmod 700 /etc/munge
  chmod 400 /etc/munge/munge.key
  mkdir -p /run/munge /var/lib/munge /var/log/munge
  chown munge:munge /run/munge /var/lib/munge /var/log/munge
  chmod 755 /run/munge
  runuser -u munge -- munged || true # a failure shows in the check below
  for _ in $(seq 1 50); do
    munge -n 2>/dev/null | unmunge >/dev/null 2>&1 && break
    sleep 0.2
  done
  munge -n | unmunge >/dev/null || { echo "slurm-up: munge does not work"; tail -n 20 /var/log/munge/munged.log || true; exit 1; }
fi

# 3. slurm.conf: one node, this host, its real CPUs and most of its memory; no cgroups
# (containers often lack cgroup delegation) and no accounting database.
host=$(hostname -s)
cpus=$(env -u OMP_NUM_THREADS -u OMP_THREAD_LIMIT nproc)
mem_mb=$(awk '/^MemTotal:/ { print int($2 / 1024 * 0.9) }' /proc/meminfo)
new_conf=$(cat <<EOF
# Written by .ci/slurm-up.sh: a one-node cluster for CI.
ClusterName=ci
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmctldLogFile=$log_dir/slurmctld.log
SlurmdLogFile=$log_dir/slurmd.log
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MailProg=/bin/true
SchedulerType=sched/backfill
# Each task gets one CPU, so the node runs as many tasks at once as it has CPUs.
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
)
# Whether daemon $1 runs: the process in its pid file has its name and is not a zombie.
running() {
  local pid
  pid=$(cat "/run/$1.pid" 2>/dev/null) || return 1
  [ "$(ps -o comm= -p "$pid" 2>/dev/null)" = "$1" ] && [[ $(ps -o stat= -p "$pid") != Z* ]]
}
mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd
if [ "$(cat "$conf" 2>/dev/null)" != "$new_conf" ]; then
  # A new configuration: stop the daemons that run with the old one, then write it.
  for d in slurmctld slurmd; do
    running "$d" || continue
    kill "$(cat "/run/$d.pid")"
    for _ in $(seq 1 150); do running "$d" || break; sleep 0.2; done
  done
  printf '%s\n' "$new_conf" > "$conf"
fi

# 4. The daemons, started when not running, then a wait (60 s at most) for the node to be up.
fail() {
  echo "slurm-up: $1; logs in $log_dir"
  for f in "$log_dir"/slurmctld.log "$log_dir"/slurmd.log; do echo "== $f"; tail -n 30 "$f" 2>/dev/null || true; done
  exit 1
}
running slurmctld || slurmctld || fail "slurmctld did not start"
running slurmd || slurmd || fail "slurmd did not start"
up='^(idle|mixed|allocated|completing)$'
state=
for _ in $(seq 1 60); do
  state=$(sinfo -h -o %T 2>/dev/null | head -n 1 || true)
  [[ $state =~ $up ]] && break
  sleep 1
done
[[ $state =~ $up ]] || fail "the node is not up after 60 s (state: '${state:-none}')"
echo "slurm-up: cluster up, logs in $log_dir"
sinfo
