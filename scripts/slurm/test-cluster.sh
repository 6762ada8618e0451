#!/usr/bin/env bash
# End-to-end test of the Slurm scripts on a one-node cluster started on this machine: installs
# Slurm and MUNGE from Debian's packages if they are missing (as root), writes a slurm.conf for
# this host (its hostname, its `nproc` CPUs, proctrack/linuxproc, task/none), starts munged,
# slurmctld and slurmd, submits a grid as a job array with scripts/slurm/submit-grid.sh --wait
# (then its dependent merge), and checks that the merged map equals a single-process
# `drumroll grid` byte for byte (cmp), and again after one task's part file is deleted and the
# task resubmitted alone, as docs/guide/grid.md tells. Stops the daemons it started, whatever happens.
#
#   bash scripts/slurm/test-cluster.sh        # exit status 0: the maps are identical
#
# Uses ports 6817 and 6818 and a scratch directory under /tmp; needs root and apt-get.
set -euo pipefail

repo=$(cd "$(dirname "$0")/../.." && pwd)
started=()
work=$(mktemp -d /tmp/drumroll-slurm.XXXXXX)

stop_daemons() {
    local status=$?
    for pid in "${started[@]}"; do
        kill "$pid" 2>/dev/null || true
    done
    for pid in "${started[@]}"; do
        for _ in $(seq 50); do
            kill -0 "$pid" 2>/dev/null || break
            sleep 0.1
        done
        kill -9 "$pid" 2>/dev/null || true
    done
    if [ "$status" -ne 0 ]; then
        echo "test-cluster.sh: FAILED (status $status); logs in $work" >&2
        tail -n 20 "$work"/*.log 2>/dev/null >&2 || true
    else
        rm -rf "$work"
    fi
    exit "$status"
}
trap stop_daemons EXIT

if [ "$(id -u)" -ne 0 ]; then
    echo "test-cluster.sh: needs root (it installs packages and starts slurmd)" >&2
    exit 2
fi

# Slurm and MUNGE from Debian, once.
if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null \
    || ! command -v sbatch >/dev/null || ! command -v munged >/dev/null; then
    apt-get update
    DEBIAN_FRONTEND=noninteractive apt-get install -y slurmctld slurmd slurm-client munge
fi

# The binary under test.
(cd "$repo" && cargo build --release -p drumroll)
export DRUMROLL="${CARGO_TARGET_DIR:-$repo/target}/release/drumroll"

# MUNGE: a key of this test's own, and a daemon on a socket of its own, run as user munge
# (setpriv execs it: the PID started is the daemon's own).
chmod 755 "$work"
# The key's directory is private, the socket's open to every user.
mkdir -p "$work/munge" "$work/munge-socket"
dd if=/dev/urandom of="$work/munge/munge.key" bs=1024 count=1 status=none
chown -R munge:munge "$work/munge" "$work/munge-socket"
chmod 700 "$work/munge"
chmod 755 "$work/munge-socket"
chmod 400 "$work/munge/munge.key"
socket="$work/munge-socket/munge.socket"
setpriv --reuid=munge --regid=munge --init-groups \
    munged --foreground --key-file="$work/munge/munge.key" \
    --socket="$socket" --pid-file="$work/munge/munged.pid" \
    --log-file="$work/munge/munged.log" --seed-file="$work/munge/munged.seed" \
    >"$work/munged.stderr.log" 2>&1 &
started+=($!)

# A single-node cluster on this host.
host=$(hostname -s)
cpus=$(nproc)
mkdir -p "$work/state" "$work/spool"
cat >"$work/slurm.conf" <<CONF
ClusterName=drumroll-test
SlurmctldHost=${host}(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=${socket}
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
ReturnToService=2
StateSaveLocation=${work}/state
SlurmdSpoolDir=${work}/spool
SlurmctldPidFile=${work}/slurmctld.pid
SlurmdPidFile=${work}/slurmd.pid
SlurmctldLogFile=${work}/slurmctld.log
SlurmdLogFile=${work}/slurmd.log
SlurmctldPort=6817
SlurmdPort=6818
NodeName=${host} NodeAddr=127.0.0.1 CPUs=${cpus} State=UNKNOWN
PartitionName=test Nodes=${host} Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$work/slurm.conf"
for attempt in $(seq 50); do
    [ -S "$socket" ] && break
    if [ "$attempt" -eq 50 ]; then
        echo "test-cluster.sh: munged did not start" >&2
        exit 1
    fi
    sleep 0.1
done
slurmctld -D -i -f "$SLURM_CONF" >"$work/slurmctld.stderr.log" 2>&1 &
started+=($!)
slurmd -D -f "$SLURM_CONF" >"$work/slurmd.stderr.log" 2>&1 &
started+=($!)

# Wait for the node to be idle.
for attempt in $(seq 60); do
    state=$(sinfo -h -n "$host" -o %T 2>/dev/null || true)
    [ "$state" = idle ] && break
    if [ "$attempt" -eq 60 ]; then
        echo "test-cluster.sh: the node did not come up (state '${state}')" >&2
        exit 1
    fi
    sleep 0.5
done

# The grid: the Biolever on mica over A0, through G1, G2 and G3, with the retract.
grid=(--case biolever-mica --vary a0 --from 8 --to 12 --steps 9
    --z-from 12.5 --z-to 2 --z-steps 106 --retract)
started_at=$(date +%s)
bash "$repo/scripts/slurm/submit-grid.sh" --tasks 4 --output "$work/map.jsonl" --wait \
    -- "${grid[@]}"
echo "array and merge: $(($(date +%s) - started_at)) s"
"$DRUMROLL" grid "${grid[@]}" --output "$work/single.jsonl"
cmp "$work/map.jsonl" "$work/single.jsonl"
# The documented recovery of a failed task: its part file lost, the task resubmitted alone
# (`--array=2`, the shard count given), then the merge again.
rm "$work/map.jsonl.parts/part-2.jsonl"
sbatch --wait --array=2 --output="$work/map.jsonl.parts/slurm-again-%A_%a.out" \
    "$repo/scripts/slurm/grid-array.sbatch" 4 "$work/map.jsonl.parts" "${grid[@]}" >/dev/null
"$DRUMROLL" grid merge "$work"/map.jsonl.parts/part-{0,1,2,3}.jsonl --output "$work/again.jsonl"
cmp "$work/again.jsonl" "$work/single.jsonl"
echo "test-cluster.sh: the Slurm map ($(wc -l <"$work/map.jsonl") lines, 4 array tasks, task 2 resubmitted alone) equals the single-process map byte for byte"
