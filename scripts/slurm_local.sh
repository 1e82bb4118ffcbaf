#!/usr/bin/env bash
# A throw-away single-node SLURM cluster on this host, to try `srun`/`sbatch bodyfit ensemble`
# and run the `ensemble_srun` test (docs/reference/ensembles.md). Needs root (slurmd does) and
# Debian's `slurm-wlm munge` packages. Nothing outside the state directory is touched: the munge
# key, munged's socket, slurm.conf, the spool directories, the logs and the pid files all live in
#   ${BODYFIT_SLURM_DIR:-${TMPDIR:-/tmp}/bodyfit-slurm}
# and the daemons are started directly (no systemd), so this runs beside a system SLURM or none.
#
#   scripts/slurm_local.sh start    set up and start munged, slurmctld, slurmd (idempotent)
#   scripts/slurm_local.sh status   the daemons and `sinfo`
#   scripts/slurm_local.sh env      the line to eval: export SLURM_CONF=<state dir>/slurm.conf
#   scripts/slurm_local.sh stop     stop the daemons and remove the state directory (idempotent)
#
# Then: eval "$(scripts/slurm_local.sh env)"; srun -n 2 build/bin/bodyfit ensemble ...
# The node gets this host's name, its CPUs and its memory (from `slurmd -C`); MpiDefault=pmix,
# which Debian's Open MPI needs (it has no PMI-2 client).
set -euo pipefail

state_dir=${BODYFIT_SLURM_DIR:-${TMPDIR:-/tmp}/bodyfit-slurm}
ctld_port=${BODYFIT_SLURM_PORT:-6817}   # slurmd listens on the next port
conf=$state_dir/slurm.conf
socket=$state_dir/munge/munge.socket.2

die() { echo "slurm_local.sh: $*" >&2; exit 1; }

# The pid in a pid file if that process is alive, else nothing.
live_pid() {
  local pid
  [[ -s $1 ]] || return 1
  pid=$(<"$1")
  [[ $pid =~ ^[0-9]+$ ]] && kill -0 "$pid" 2>/dev/null && echo "$pid"
}

write_config() {
  local node host
  # slurmd -C describes this host as slurm.conf wants it: NodeName, CPUs, sockets, cores, memory.
  node=$(slurmd -C | head -n 1)
  host=$(hostname -s)
  cat > "$conf" <<EOF
# Written by scripts/slurm_local.sh: a single-node test cluster, removed by its 'stop'.
ClusterName=bodyfit-local
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$ctld_port
SlurmdPort=$((ctld_port + 1))
AuthType=auth/munge
AuthInfo=socket=$socket
CryptoType=crypto/munge
StateSaveLocation=$state_dir/ctld
SlurmdSpoolDir=$state_dir/slurmd
SlurmctldPidFile=$state_dir/slurmctld.pid
SlurmdPidFile=$state_dir/slurmd.pid
SlurmctldLogFile=$state_dir/slurmctld.log
SlurmdLogFile=$state_dir/slurmd.log
PlugStackConfig=$state_dir/plugstack.conf
# No cgroups (containers rarely give them): processes tracked by their parent, no task binding.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SwitchType=switch/none
MpiDefault=pmix
# Tasks run at the nice value of the srun or sbatch that submitted them, not the daemon's.
PropagatePrioProcess=1
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MailProg=/bin/true
$node NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
  : > "$state_dir/plugstack.conf"
}

start_munge() {
  if live_pid "$state_dir/munged.pid" > /dev/null; then return; fi
  mkdir -p "$state_dir/munge"
  chmod 0700 "$state_dir/munge"
  if [[ ! -s $state_dir/munge.key ]]; then
    head -c 1024 /dev/urandom > "$state_dir/munge.key"
    chmod 0400 "$state_dir/munge.key"
  fi
  # --force: munged refuses to run as root otherwise; this one serves the test cluster alone.
  munged --force --socket="$socket" --key-file="$state_dir/munge.key" --pid-file="$state_dir/munged.pid" \
    --log-file="$state_dir/munged.log" --seed-file="$state_dir/munged.seed"
}

wait_for_node() {
  for _ in $(seq 1 60); do
    if sinfo -h -o '%T' 2>/dev/null | grep -Eq '^(idle|mixed|allocated)'; then return 0; fi
    sleep 0.5
  done
  die "the node did not come up in 30 s: see $state_dir/slurmctld.log and $state_dir/slurmd.log"
}

start() {
  [[ $(id -u) == 0 ]] || die "run as root (slurmd starts the jobs' processes as their users)"
  for program in munged slurmctld slurmd sinfo srun; do
    command -v "$program" > /dev/null || die "$program not found: apt-get install slurm-wlm munge"
  done
  mkdir -p "$state_dir/ctld" "$state_dir/slurmd"
  chmod 0755 "$state_dir"
  export SLURM_CONF=$conf
  [[ -s $conf ]] || write_config
  start_munge
  live_pid "$state_dir/slurmctld.pid" > /dev/null || slurmctld -f "$conf"
  live_pid "$state_dir/slurmd.pid" > /dev/null || slurmd -f "$conf"
  wait_for_node
  echo "SLURM is up: $(sinfo -h -o '%P %D node(s) %c CPUs %m MB %T')"
  echo "run: eval \"\$($0 env)\""
}

stop() {
  local name pid
  if [[ -s $conf ]]; then
    # Jobs first, so that no step outlives its slurmd.
    SLURM_CONF=$conf scancel --quiet --full --user="$(id -un)" 2>/dev/null || true
  fi
  for name in slurmd slurmctld munged; do
    if pid=$(live_pid "$state_dir/$name.pid"); then
      kill "$pid"
      for _ in $(seq 1 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.2; done
      if kill -0 "$pid" 2>/dev/null; then kill -KILL "$pid"; fi
      echo "stopped $name ($pid)"
    fi
  done
  rm -rf "$state_dir"
}

status() {
  local name pid
  for name in munged slurmctld slurmd; do
    if pid=$(live_pid "$state_dir/$name.pid"); then echo "$name: running ($pid)"; else echo "$name: stopped"; fi
  done
  if [[ -s $conf ]]; then SLURM_CONF=$conf sinfo || true; fi
}

case ${1:-} in
  start) start ;;
  stop) stop ;;
  status) status ;;
  env) printf 'export SLURM_CONF=%q\n' "$conf" ;;
  *) echo "usage: $0 start|status|env|stop   (state in $state_dir)" >&2; exit 2 ;;
esac
