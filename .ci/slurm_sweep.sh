#!/usr/bin/env bash
# Cluster test of `rotorsim sweep`: a real single-node Slurm (slurmctld + slurmd on localhost,
# 2 CPUs, munge authentication) runs the emitted job array of a small rigid-model plan; the
# merged sweep.csv must equal a local sweep of the same plan value for value (wall times
# aside). Any failure to install or start the cluster fails the script: it is never skipped.
# Needs root (or passwordless sudo) to install packages and start the daemons.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
PLAN=sweeps/ci_rigid.toml
SUDO=""
if [ "$(id -u)" != 0 ]; then
    command -v sudo >/dev/null || { echo "slurm_sweep: needs root or sudo to start a cluster" >&2; exit 1; }
    SUDO="sudo -n"
fi
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$ROOT/target}
# The binary `cargo test --release` built: the same build (tests/one_build.rs), so this is a
# no-op after the tests, and builds the binary only when the script runs alone.
built=$SECONDS
cargo build --release --quiet
echo "rotorsim binary ready in $((SECONDS - built)) s"
EXE=$CARGO_TARGET_DIR/release/rotorsim

if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null || ! command -v munged >/dev/null; then
    $SUDO apt-get update -q
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q slurm-wlm munge
fi

HOST=$(hostname)
WORK=$(mktemp -d "${TMPDIR:-/tmp}/rotorsim-slurm.XXXXXX")
chmod 755 "$WORK"
PIDS=()
cleanup() {
    # stop only the daemons this script started, by their pids
    for p in "${PIDS[@]}"; do $SUDO kill "$p" 2>/dev/null || true; done
}
trap cleanup EXIT

$SUDO mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd /var/log/slurm /run/munge
$SUDO tee /etc/slurm/slurm.conf >/dev/null <<CONF
ClusterName=local
SlurmctldHost=$HOST
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SwitchType=switch/none
MpiDefault=none
ReturnToService=2
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmdSpoolDir=/var/spool/slurmd
StateSaveLocation=/var/spool/slurmctld
SlurmUser=root
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
NodeName=$HOST CPUs=2 State=UNKNOWN
PartitionName=debug Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
CONF
$SUDO chown munge:munge /run/munge
if [ ! -s /etc/munge/munge.key ]; then
    $SUDO mungekey --create 2>/dev/null || $SUDO /usr/sbin/create-munge-key -f
    $SUDO chown munge:munge /etc/munge/munge.key
fi
# start each daemon unless one is already serving (then it is left alone at the end)
if ! munge -n >/dev/null 2>&1; then
    $SUDO munged --force
    sleep 1
    PIDS+=("$(cat /run/munge/munged.pid)")
fi
munge -n | unmunge >/dev/null || { echo "slurm_sweep: munge does not authenticate" >&2; exit 1; }
if ! scontrol ping 2>/dev/null | grep -q UP; then
    $SUDO slurmctld
    sleep 1
    PIDS+=("$(cat /run/slurmctld.pid)")
fi
if [ ! -s /run/slurmd.pid ] || ! kill -0 "$(cat /run/slurmd.pid)" 2>/dev/null; then
    $SUDO slurmd
    sleep 1
    PIDS+=("$(cat /run/slurmd.pid)")
fi
up=""
for _ in $(seq 1 30); do
    if sinfo -h -N -o '%T' 2>/dev/null | grep -Eq '^(idle|mixed|allocated)'; then up=1; break; fi
    sleep 1
done
if [ -z "$up" ]; then
    echo "slurm_sweep: the single-node cluster did not come up:" >&2
    sinfo -N -l >&2 || true
    tail -20 /var/log/slurm/slurmctld.log /var/log/slurm/slurmd.log >&2 || true
    exit 1
fi
echo "slurm_sweep: cluster up: $(sinfo -h -N -o '%N %T %c CPUs')"

"$EXE" sweep "$PLAN" --out "$WORK/cluster" --emit-slurm "$WORK/job.sh"
sbatch --wait "$WORK/job.sh"
cat "$WORK"/cluster/slurm-*.out
"$EXE" sweep merge "$WORK/cluster"
"$EXE" sweep "$PLAN" --out "$WORK/local" --jobs 2

# value for value, the wall-time column aside
strip() {
    awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "wall_time_s") w = i }
             { out = ""; sep = ""; for (i = 1; i <= NF; i++) if (i != w) { out = out sep $i; sep = "," }; print out }' "$1"
}
rows=$(($(wc -l < "$WORK/local/sweep.csv") - 1))
if [ "$rows" -lt 4 ]; then echo "slurm_sweep: only $rows rows" >&2; exit 1; fi
if ! diff <(strip "$WORK/cluster/sweep.csv") <(strip "$WORK/local/sweep.csv"); then
    echo "slurm_sweep: the merged cluster sweep.csv differs from the local sweep" >&2
    exit 1
fi
echo "slurm_sweep: OK: $rows rows, the Slurm array's merged sweep.csv equals the local sweep (wall times aside)"
rm -rf "$WORK"
