#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# A single-node Slurm cluster on localhost for tests/farm: its munge key, munged, slurm.conf, state, spool and
# logs all live in DIR; nothing outside DIR is read or changed. Needs root (slurmd runs jobs as their user).
#   local_slurm.sh start DIR   starts munged, slurmctld and slurmd; prints SLURM_CONF=DIR/slurm.conf once the
#                              node is idle; exit 77 (with the reason on stderr) when Slurm cannot start here
#   local_slurm.sh stop DIR    stops the three daemons started in DIR (by their pid files)
set -uo pipefail
action=$1
dir=$(realpath -m "$2")

skip() { echo "local_slurm.sh: $*" >&2; exit 77; }

# The three at once (each takes about 2 s to shut down), then what is left after 5 s killed outright.
stop() {
  local pids=() daemon pid
  for daemon in slurmd slurmctld munged; do
    [ -f "$dir/$daemon.pid" ] || continue
    pids+=("$(cat "$dir/$daemon.pid")")
    kill "${pids[-1]}" 2>/dev/null
    rm -f "$dir/$daemon.pid"
  done
  for pid in "${pids[@]}"; do
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null
  done
}

free_port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }

start() {
  [ "$(id -u)" -eq 0 ] || skip "needs root (slurmd starts the jobs)"
  for program in munged slurmctld slurmd sbatch squeue scancel; do
    command -v "$program" >/dev/null || skip "$program is not installed (Debian: slurm-wlm munge)"
  done
  mkdir -p "$dir"/{state,spool,log}
  head -c 1024 /dev/urandom > "$dir/munge.key"
  chmod 400 "$dir/munge.key"
  munged --key-file="$dir/munge.key" --socket="$dir/munge.socket" --pid-file="$dir/munged.pid" \
    --log-file="$dir/log/munged.log" --seed-file="$dir/munge.seed" --force 2>"$dir/log/munged.err" \
    || skip "munged did not start: $(head -1 "$dir/log/munged.err")"
  cpus=$(nproc)
  [ "$cpus" -gt 2 ] && cpus=2
  cat > "$dir/slurm.conf" <<CONF
ClusterName=chromatrace-test
SlurmctldHost=localhost
SlurmctldPort=$(free_port)
SlurmdPort=$(free_port)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$dir/munge.socket
CredType=cred/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
# Start a queued task as soon as a CPU is free: by default Slurm may wait 3 s (batch_sched_delay), most of each test.
SchedulerParameters=batch_sched_delay=0
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MpiDefault=none
MinJobAge=600
NodeName=localhost CPUs=$cpus State=UNKNOWN
PartitionName=test Nodes=localhost Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF=$dir/slurm.conf
  slurmctld -i 2>"$dir/log/slurmctld.err" || { stop; skip "slurmctld did not start: $(head -1 "$dir/log/slurmctld.err")"; }
  slurmd -N localhost 2>"$dir/log/slurmd.err" || { stop; skip "slurmd did not start: $(head -1 "$dir/log/slurmd.err")"; }
  for _ in $(seq 100); do
    state=$(sinfo --noheader --format=%T 2>/dev/null | head -1)
    if [ "$state" = idle ]; then
      # Should the caller die without stopping the cluster (a crash, a test timeout), the daemons go with it.
      caller=$PPID
      (while kill -0 "$caller" 2>/dev/null; do sleep 1; done; stop) </dev/null >/dev/null 2>&1 &
      echo "SLURM_CONF=$SLURM_CONF"
      exit 0
    fi
    sleep 0.2
  done
  stop
  skip "the node did not come up (state \"$state\"; logs in $dir/log)"
}

case "$action" in
  start) start ;;
  stop) stop ;;
  *) echo "usage: local_slurm.sh start|stop DIR" >&2; exit 2 ;;
esac
