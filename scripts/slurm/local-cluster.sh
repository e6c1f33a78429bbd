#!/usr/bin/env bash
# A real one-node SLURM cluster on this machine, for testing the job-array scripts
# (docs/cluster.md). Debian only, run as root; no systemd needed: the daemons are started
# by hand and tracked by pid files.
#
#   scripts/slurm/local-cluster.sh [start]   install if missing, then start (reuses a healthy
#                                            cluster this script started earlier)
#   scripts/slurm/local-cluster.sh restart   stop, wipe the cluster state, start again
#   scripts/slurm/local-cluster.sh stop      stop the daemons this script started
#   scripts/slurm/local-cluster.sh status    exit 0 if the node is up and schedulable
#   scripts/slurm/local-cluster.sh env       print the line that points slurm commands here
#
# Environment:
#   POLHODE_SLURM_DIR   state, config and logs (default /var/tmp/polhode-slurm)
#   SLURM_START_TIMEOUT seconds to wait for the node to come up (default 60)
#
# The config lives in $POLHODE_SLURM_DIR/etc/slurm.conf. Point the client commands at it with
# `export SLURM_CONF=$POLHODE_SLURM_DIR/etc/slurm.conf`; if /etc/slurm/slurm.conf does not
# exist, it is made a symlink to it, so plain `sinfo` works too.
set -euo pipefail

STATE=${POLHODE_SLURM_DIR:-/var/tmp/polhode-slurm}
CONF=$STATE/etc/slurm.conf
NODE=$(hostname -s)
TIMEOUT=${SLURM_START_TIMEOUT:-60}
export SLURM_CONF=$CONF

log() { printf 'local-cluster: %s\n' "$*" >&2; }
die() {
    log "error: $*"
    exit 1
}

# Whether process $1 is running. Zombies count as gone: PID 1 here may be slow to reap the
# daemons' exited processes.
alive() {
    local s
    s=$(ps -o stat= -p "$1" 2>/dev/null) && [[ $s != Z* ]]
}

# The process whose pid is in file $1, if it is alive and its command is $2.
pid_of() {
    local pid
    [[ -s $1 ]] || return 1
    pid=$(<"$1")
    [[ -r /proc/$pid/comm && $(</proc/"$pid"/comm) == "$2" ]] && alive "$pid" || return 1
    printf '%s\n' "$pid"
}

# Install Debian's slurm-wlm and munge if a daemon is missing (quietly, non-interactively).
install_packages() {
    if command -v slurmctld >/dev/null && command -v slurmd >/dev/null &&
        command -v sinfo >/dev/null && command -v munged >/dev/null; then
        return
    fi
    log "installing slurm-wlm and munge with apt-get"
    local t0=$SECONDS
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null
    log "installed in $((SECONDS - t0)) s"
}

# munged runs as the munge user (as Debian's service unit does); it needs its key and the
# directories that systemd-tmpfiles would otherwise create.
start_munge() {
    local key=/etc/munge/munge.key
    install -d -o munge -g munge -m 0700 /etc/munge /var/lib/munge /var/log/munge
    install -d -o munge -g munge -m 0755 /run/munge
    if [[ ! -s $key ]]; then
        log "creating $key"
        (umask 077 && dd if=/dev/urandom of="$key" bs=1024 count=1 status=none)
    fi
    chown munge:munge "$key"
    chmod 0400 "$key"
    # A munged that already answers (ours from before, or the system's) is reused.
    if munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
        return
    fi
    rm -f /run/munge/munged.pid
    runuser -u munge -- /usr/sbin/munged
    cp /run/munge/munged.pid "$STATE/run/munged.pid"
    munge -n | unmunge >/dev/null || die "munged started but does not answer (see /var/log/munge/munged.log)"
}

# A minimal single-node config: no accounting, no cgroups, processes tracked through /proc.
write_conf() {
    local cpus mem
    cpus=$(nproc)
    # "Modest": half the machine, at most 4 GiB (slurmd refuses a node with less than this).
    mem=$(awk '/^MemTotal:/ { m = int($2 / 1024 / 2); print (m > 4096 ? 4096 : m) }' /proc/meminfo)
    cat >"$CONF" <<EOF
# Written by scripts/slurm/local-cluster.sh: a one-node test cluster on localhost.
ClusterName=polhode-local
SlurmctldHost=$NODE(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
StateSaveLocation=$STATE/ctld
SlurmdSpoolDir=$STATE/spool
SlurmctldPidFile=$STATE/run/slurmctld.pid
SlurmdPidFile=$STATE/run/slurmd.pid
SlurmctldLogFile=$STATE/log/slurmctld.log
SlurmdLogFile=$STATE/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
MailProg=/bin/true
SwitchType=switch/none
SchedulerType=sched/backfill
# Start batch jobs as soon as they are submitted (the default waits up to 3 s).
SchedulerParameters=batch_sched_delay=0
# Schedule single CPUs, so that several array tasks share the node.
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
# Keep finished jobs visible to scontrol for an hour (there is no accounting database).
MinJobAge=3600
# A job whose afterok dependency can no longer be met is cancelled rather than left pending.
DependencyParameters=kill_invalid_depend
NodeName=$NODE NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=local Nodes=$NODE Default=YES MaxTime=INFINITE State=UP
EOF
    if [[ ! -e /etc/slurm/slurm.conf && ! -L /etc/slurm/slurm.conf ]]; then
        mkdir -p /etc/slurm
        ln -s "$CONF" /etc/slurm/slurm.conf
    fi
}

node_state() { sinfo -h -n "$NODE" -o %T 2>/dev/null | head -n1; }

healthy() {
    pid_of "$STATE/run/slurmctld.pid" slurmctld >/dev/null &&
        pid_of "$STATE/run/slurmd.pid" slurmd >/dev/null &&
        [[ $(node_state) =~ ^(idle|mixed|allocated|completing)$ ]]
}

show_logs() {
    local f
    for f in "$STATE/log/slurmctld.log" "$STATE/log/slurmd.log" /var/log/munge/munged.log; do
        [[ -f $f ]] || continue
        printf '\n===== %s (last 40 lines) =====\n' "$f" >&2
        tail -n 40 "$f" >&2
    done
}

# Stop what this script started (pid files under $STATE/run), slurmd first.
stop() {
    local name pid n
    for name in slurmd slurmctld munged; do
        pid=$(pid_of "$STATE/run/$name.pid" "$name") || {
            rm -f "$STATE/run/$name.pid"
            continue
        }
        log "stopping $name ($pid)"
        kill "$pid"
        for ((n = 0; n < 100; n++)); do
            alive "$pid" || break
            sleep 0.1
        done
        if alive "$pid"; then
            log "$name ($pid) did not stop in 10 s; killing it"
            kill -9 "$pid" 2>/dev/null || true
        fi
        rm -f "$STATE/run/$name.pid"
    done
}

start() {
    [[ $(id -u) == 0 ]] || die "run as root (slurmd must start jobs as their users)"
    install_packages
    if [[ -s $CONF ]] && healthy; then
        log "already running: node $NODE is $(node_state)"
        return
    fi
    stop
    # Start from empty state so a previous run's jobs and node state do not linger.
    rm -rf "$STATE/ctld" "$STATE/spool"
    mkdir -p "$STATE"/{etc,ctld,spool,run,log}
    write_conf
    start_munge

    local t0=$SECONDS
    : >"$STATE/log/slurmctld.log"
    : >"$STATE/log/slurmd.log"
    slurmctld -f "$CONF" || {
        show_logs
        die "slurmctld did not start"
    }
    slurmd -f "$CONF" -N "$NODE" || {
        show_logs
        die "slurmd did not start"
    }
    until [[ $(node_state) == idle ]]; do
        if ((SECONDS - t0 > TIMEOUT)); then
            show_logs
            sinfo -N -l >&2 || true
            die "node $NODE not idle after $TIMEOUT s (state: '$(node_state)')"
        fi
        sleep 0.5
    done
    log "node $NODE idle after $((SECONDS - t0)) s; export SLURM_CONF=$CONF"
}

case ${1:-start} in
start) start ;;
restart)
    stop
    start
    ;;
stop) stop ;;
status) healthy ;;
env) printf 'export SLURM_CONF=%q\n' "$CONF" ;;
*) die "usage: $0 [start|restart|stop|status|env]" ;;
esac
