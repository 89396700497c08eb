# A one-node Slurm cluster on localhost for the farm test, in a temporary folder: munged,
# slurmctld and slurmd with a generated configuration. Sourced by slurm_test.sh:
#   slurm_start DIR   -- starts the daemons (returns non-zero when they do not come up)
#   slurm_stop        -- stops every daemon it started (safe to call twice)
# Commands then need SLURM_CONF, which slurm_start exports.

slurm_free_port() {
  local port
  for port in $(shuf -i 20000-60000 -n 50); do
    if ! (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null; then
      echo "$port"
      return 0
    fi
  done
  return 1
}

slurm_start() {
  SLURM_DIR=$1
  local host cpus ctld_port slurmd_port
  host=$(hostname -s)
  cpus=$(nproc)
  mkdir -p "$SLURM_DIR/state" "$SLURM_DIR/spool" "$SLURM_DIR/munge"
  chmod 700 "$SLURM_DIR/munge"
  dd if=/dev/urandom of="$SLURM_DIR/munge/munge.key" bs=1024 count=1 status=none
  chmod 400 "$SLURM_DIR/munge/munge.key"
  munged --force --key-file="$SLURM_DIR/munge/munge.key" \
    --socket="$SLURM_DIR/munge/munge.socket" --pid-file="$SLURM_DIR/munge/munged.pid" \
    --log-file="$SLURM_DIR/munge/munged.log" --seed-file="$SLURM_DIR/munge/munged.seed" ||
    return 1
  ctld_port=$(slurm_free_port) || return 1
  slurmd_port=$(slurm_free_port) || return 1
  cat >"$SLURM_DIR/slurm.conf" <<CONF
ClusterName=dispextest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$SLURM_DIR/munge/munge.socket
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$SLURM_DIR/state
SlurmdSpoolDir=$SLURM_DIR/spool
SlurmctldPidFile=$SLURM_DIR/slurmctld.pid
SlurmdPidFile=$SLURM_DIR/slurmd.pid
SlurmctldLogFile=$SLURM_DIR/slurmctld.log
SlurmdLogFile=$SLURM_DIR/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
JobRequeue=1
MinJobAge=3600
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=1000 State=UNKNOWN
PartitionName=dispextest Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF="$SLURM_DIR/slurm.conf"
  slurmctld -D -i -f "$SLURM_CONF" >"$SLURM_DIR/slurmctld.out" 2>&1 &
  SLURM_CTLD_PID=$!
  slurmd -D -f "$SLURM_CONF" -N "$host" >"$SLURM_DIR/slurmd.out" 2>&1 &
  SLURM_SLURMD_PID=$!
  local i
  for i in $(seq 1 60); do
    if sinfo -h -o '%T' 2>/dev/null | grep -qE '^(idle|mixed|allocated)'; then return 0; fi
    sleep 0.5
  done
  echo "slurm did not come up; slurmctld.log:" >&2
  tail -n 20 "$SLURM_DIR/slurmctld.log" "$SLURM_DIR/slurmd.log" "$SLURM_DIR/slurmctld.out" \
    "$SLURM_DIR/slurmd.out" >&2 2>/dev/null
  return 1
}

slurm_stop() {
  local pid
  for pid in ${SLURM_SLURMD_PID:-} ${SLURM_CTLD_PID:-}; do
    kill "$pid" 2>/dev/null
  done
  for pid in ${SLURM_SLURMD_PID:-} ${SLURM_CTLD_PID:-}; do
    wait "$pid" 2>/dev/null
  done
  SLURM_SLURMD_PID=
  SLURM_CTLD_PID=
  if [ -n "${SLURM_DIR:-}" ] && [ -S "$SLURM_DIR/munge/munge.socket" ]; then
    munged --stop --socket="$SLURM_DIR/munge/munge.socket" >/dev/null 2>&1
  fi
}
