#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, for the campaign's tests and for trying
# `subfric campaign --emit-slurm` / `--submit` without a cluster (docs/campaign.md).
#
#   scripts/slurm-local.sh start  [DIR]   install Slurm and munge if missing, start the cluster
#   scripts/slurm-local.sh status [DIR]   say what runs; exit 0 when the node answers
#   scripts/slurm-local.sh stop   [DIR]   cancel its jobs, stop exactly the daemons it started
#   scripts/slurm-local.sh env    [DIR]   print the line that points Slurm's commands at it
#
# DIR (default $SUBFRIC_SLURM_DIR, else ${TMPDIR:-/tmp}/subfric-slurm) holds everything: the
# configuration (DIR/slurm.conf), the munge key and socket, the daemons' state, pid files and
# logs. Nothing is written to /etc: Slurm's commands find the cluster through
# SLURM_CONF=DIR/slurm.conf (`eval "$(scripts/slurm-local.sh env DIR)"`). Each DIR is a cluster
# of its own, on ports free when it starts, so two can run side by side.
#
# The daemons run without systemd: munged, slurmctld and slurmd started here, on localhost,
# with proctrack/linuxproc and task/none (no cgroups), one node with this machine's CPUs and one
# partition. Jobs run as the user who submits them, so starting needs root (slurmd changes to
# the job's user); so does installing Slurm and munge from Debian's packages (apt-get), which
# `start` does only when a command is missing.
set -euo pipefail

die() {
	echo "slurm-local: $*" >&2
	exit 1
}

cmd=${1:-}
[ $# -ge 1 ] && shift
dir=${1:-${SUBFRIC_SLURM_DIR:-${TMPDIR:-/tmp}/subfric-slurm}}
case "$dir" in
/*) ;;
*) dir="$PWD/$dir" ;;
esac
conf="$dir/slurm.conf"
socket="$dir/munge/socket"
export SLURM_CONF="$conf"

# The daemons, by pid file: name, pid file.
daemons() {
	printf '%s\n' "slurmd $dir/run/slurmd.pid" "slurmctld $dir/run/slurmctld.pid" "munged $dir/munge/munged.pid"
}

# The pid in $1 if that process is alive and was started for this DIR (its command line names
# DIR), so that a pid reused by another process is never signalled.
ours() {
	local pid
	pid=$(cat "$1" 2>/dev/null) || return 1
	[[ "$pid" =~ ^[0-9]+$ ]] || return 1
	[ -r "/proc/$pid/cmdline" ] || return 1
	tr '\0' ' ' <"/proc/$pid/cmdline" | grep -qF -- "$dir/" || return 1
	echo "$pid"
}

node_state() {
	sinfo -h -o '%T' 2>/dev/null | head -n 1
}

status() {
	local any=1 name file pid
	while read -r name file; do
		if pid=$(ours "$file"); then
			echo "$name: running (process $pid)"
			any=0
		else
			echo "$name: not running"
		fi
	done < <(daemons)
	[ -f "$conf" ] || {
		echo "no cluster in $dir"
		return 1
	}
	[ "$any" = 0 ] || return 1
	local state
	state=$(node_state)
	echo "node: ${state:-no answer} (SLURM_CONF=$conf)"
	case "$state" in
	idle* | mixed* | allocated* | completing*) return 0 ;;
	*) return 1 ;;
	esac
}

missing_commands() {
	local c
	for c in munged mungekey munge unmunge slurmctld slurmd sbatch squeue sinfo scancel sacct scontrol; do
		command -v "$c" >/dev/null 2>&1 || echo "$c"
	done
}

install_packages() {
	local missing
	missing=$(missing_commands | tr '\n' ' ')
	[ -n "$missing" ] || return 0
	echo "slurm-local: installing Slurm and munge from Debian's packages (missing: $missing)"
	command -v apt-get >/dev/null 2>&1 ||
		die "missing $missing and no apt-get (expected Debian or Ubuntu; install slurm-wlm and munge by hand)"
	local apt=(env DEBIAN_FRONTEND=noninteractive apt-get -y -q -o DPkg::Lock::Timeout=600
		--no-install-recommends)
	# The package lists may be absent (a fresh container) or stale: refresh them once if the
	# first attempt fails.
	if ! "${apt[@]}" install slurm-wlm munge >"$dir/log/apt.log" 2>&1; then
		"${apt[@]}" update >>"$dir/log/apt.log" 2>&1 &&
			"${apt[@]}" install slurm-wlm munge >>"$dir/log/apt.log" 2>&1 || {
			tail -n 20 "$dir/log/apt.log" >&2
			die "apt-get install slurm-wlm munge failed (its log: $dir/log/apt.log)"
		}
	fi
	missing=$(missing_commands | tr '\n' ' ')
	[ -z "$missing" ] || die "still missing after installing slurm-wlm and munge: $missing"
}

# A TCP port of localhost nobody listens on, from $1 up.
free_port() {
	local p=$1
	while ss -Htln "sport = :$p" 2>/dev/null | grep -q . || (exec 3<>"/dev/tcp/127.0.0.1/$p") 2>/dev/null; do
		p=$((p + 1))
	done
	echo "$p"
}

write_conf() {
	local user ctld_port slurmd_port node cpus base
	user=$(id -un)
	# Ports from a range chosen by DIR, so that clusters started side by side rarely probe the
	# same ones; each is checked free.
	base=$((20000 + $(printf '%s' "$dir" | cksum | cut -d ' ' -f 1) % 20000))
	ctld_port=$(free_port "$base")
	slurmd_port=$(free_port $((ctld_port + 1)))
	node=$(hostname -s)
	# The node as slurmd sees this machine (CPUs, sockets, cores, threads), less its memory:
	# memory is not scheduled here.
	cpus=$(slurmd -C | head -n 1 | tr ' ' '\n' | grep -E '^(CPUs|Boards|SocketsPerBoard|CoresPerSocket|ThreadsPerCore)=' | tr '\n' ' ')
	[ -n "$cpus" ] || cpus="CPUs=$(nproc)"
	cat >"$conf" <<EOF
# Written by scripts/slurm-local.sh: a one-node cluster on localhost, state in $dir.
ClusterName=subfric$((base % 10000))
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=$user
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$socket
StateSaveLocation=$dir/ctld
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/run/slurmctld.pid
SlurmdPidFile=$dir/run/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=$dir/log/jobcomp.log
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
# Ended jobs stay visible to squeue and scontrol for an hour (there is no accounting database).
MinJobAge=3600
SlurmctldTimeout=30
SlurmdTimeout=30
NodeName=$node NodeAddr=127.0.0.1 $cpus State=UNKNOWN
PartitionName=local Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
}

start_daemon() {
	local name=$1
	shift
	# Its own session, no terminal, the test's pipes closed: the daemon outlives this script.
	setsid "$@" </dev/null >>"$dir/log/$name.out" 2>&1 ||
		{ tail -n 20 "$dir/log/$name.out" >&2; die "$name did not start (its output: $dir/log/$name.out)"; }
}

wait_for() {
	local what=$1 seconds=$2
	shift 2
	local i
	for ((i = 0; i < seconds * 5; i++)); do
		"$@" && return 0
		sleep 0.2
	done
	echo "slurm-local: $what: not after ${seconds} s" >&2
	return 1
}

munge_ok() {
	munge -n -S "$socket" 2>/dev/null | unmunge -S "$socket" >/dev/null 2>&1
}

node_idle() {
	case "$(node_state)" in
	idle*) return 0 ;;
	*) return 1 ;;
	esac
}

show_logs() {
	local f
	for f in "$dir"/log/*.log "$dir"/log/*.out; do
		[ -f "$f" ] || continue
		echo "--- $f (last lines)" >&2
		tail -n 15 "$f" >&2
	done
}

start() {
	if status >/dev/null 2>&1; then
		echo "slurm-local: already running in $dir"
		echo "SLURM_CONF=$conf"
		return 0
	fi
	# Leftovers of a cluster that did not stop cleanly are stopped first.
	stop >/dev/null 2>&1 || true
	mkdir -p "$dir/log" "$dir/run" "$dir/ctld" "$dir/spool" "$dir/munge"
	chmod 700 "$dir/munge"
	[ "$(id -u)" = 0 ] ||
		die "starting the cluster needs root (slurmd runs each job as its user); run as root"
	install_packages
	if [ ! -s "$dir/munge/munge.key" ]; then
		mungekey --create --keyfile="$dir/munge/munge.key" 2>/dev/null ||
			dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
	fi
	chmod 400 "$dir/munge/munge.key"
	write_conf
	start_daemon munged munged --force --key-file="$dir/munge/munge.key" --socket="$socket" \
		--pid-file="$dir/munge/munged.pid" --log-file="$dir/log/munged.log" \
		--seed-file="$dir/munge/munged.seed"
	wait_for "munged answering on $socket" 20 munge_ok || {
		show_logs
		stop >/dev/null 2>&1 || true
		die "munged did not start"
	}
	start_daemon slurmctld slurmctld -f "$conf"
	start_daemon slurmd slurmd -f "$conf"
	wait_for "the node idle in sinfo" 90 node_idle || {
		sinfo >&2 || true
		show_logs
		stop >/dev/null 2>&1 || true
		die "the cluster did not come up (logs above, in $dir/log)"
	}
	echo "slurm-local: running in $dir: $(sinfo -h -o '%P %D node %N %T, %c CPUs')"
	echo "SLURM_CONF=$conf"
}

# Cancels the cluster's jobs and waits for them to end (their steps are slurmd's children),
# then stops the three daemons it started, by their pid files.
stop() {
	local ids i name file pid stopped=()
	if [ -f "$conf" ] && ours "$dir/run/slurmctld.pid" >/dev/null; then
		ids=$(squeue -h -o '%A' 2>/dev/null | sort -u | tr '\n' ' ')
		if [ -n "${ids// /}" ]; then
			# shellcheck disable=SC2086
			scancel $ids 2>/dev/null || true
			for ((i = 0; i < 150; i++)); do
				[ -z "$(squeue -h -t running,completing,pending -o '%A' 2>/dev/null)" ] && break
				sleep 0.2
			done
		fi
	fi
	while read -r name file; do
		pid=$(ours "$file") || continue
		kill -TERM "$pid" 2>/dev/null || true
		stopped+=("$name:$pid")
	done < <(daemons)
	for entry in "${stopped[@]}"; do
		pid=${entry#*:}
		for ((i = 0; i < 100; i++)); do
			[ -d "/proc/$pid" ] || break
			sleep 0.1
		done
		if [ -d "/proc/$pid" ]; then
			kill -KILL "$pid" 2>/dev/null || true
			echo "${entry%%:*}: killed (process $pid did not end on TERM)"
		else
			echo "${entry%%:*}: stopped (process $pid)"
		fi
	done
	[ ${#stopped[@]} -gt 0 ] || echo "slurm-local: nothing of $dir was running"
}

case "$cmd" in
start) start ;;
stop) stop ;;
status) status ;;
env) echo "export SLURM_CONF=$conf" ;;
*)
	echo "usage: $0 start|stop|status|env [DIR]" >&2
	exit 2
	;;
esac
