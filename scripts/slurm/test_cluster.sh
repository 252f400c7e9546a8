#!/usr/bin/env bash
# The Slurm scripts tested for real: starts a one-node Slurm cluster on this machine (Debian's
# slurmctld, slurmd and slurm-client; a generated slurm.conf with auth/none and cred/none, for
# a cluster that only listens on this host; state and spool folders under a temporary
# folder; the daemons in the foreground, stopped by their process ids), renders a scene as a
# 4-task job array with render.sbatch, merges with merge.sbatch chained by
# --dependency=afterok, and compares the merged EXR byte for byte with a single-process
# render. Prints both times (docs/parts.md quotes them).
#
# Usage: scripts/slurm/test_cluster.sh [TWINPATH_BINARY]   (default: target/debug/twinpath)
# Needs root (the daemons run as root) and the three packages (scripts/setup.sh installs them).
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
bin=$(realpath "${1:-$repo/target/debug/twinpath}")
for tool in slurmctld slurmd sbatch squeue scontrol sinfo; do
    command -v "$tool" >/dev/null || {
        echo "test_cluster: $tool missing (apt-get install slurmctld slurmd slurm-client)" >&2
        exit 1
    }
done
[ -x "$bin" ] || { echo "test_cluster: no twinpath binary at $bin" >&2; exit 1; }

tmp=$(mktemp -d /tmp/twinpath-slurm.XXXXXX)
node=$(hostname -s)
# Ports off the Slurm defaults, so a real cluster on this host is left alone.
port=$((20000 + $$ % 20000))
mkdir -p "$tmp/state" "$tmp/spool" "$tmp/work"
cat > "$tmp/slurm.conf" <<CONF
ClusterName=twinpathtest
SlurmctldHost=$node
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/none
CredType=cred/none
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
JobCompType=jobcomp/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
NodeName=$node CPUs=$(nproc) State=UNKNOWN
PartitionName=twinpath Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$tmp/slurm.conf

pids=()
stop() {
    for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
    for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
    rm -rf "$tmp"
}
trap stop EXIT
slurmctld -D -f "$SLURM_CONF" >"$tmp/slurmctld.log" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" -N "$node" >"$tmp/slurmd.log" 2>&1 &
pids+=($!)

fail() {
    echo "test_cluster: $*" >&2
    for log in "$tmp"/*.log "$tmp"/work/*.log; do
        [ -f "$log" ] && { echo "--- $log" >&2; tail -20 "$log" >&2; }
    done
    exit 1
}
# Wait for the node to report idle (a guard against a daemon that never starts, not a
# measurement).
for _ in $(seq 120); do
    state=$(sinfo -h -n "$node" -o %t 2>/dev/null || true)
    [ "$state" = idle ] && break
    sleep 0.5
done
[ "$state" = idle ] || fail "the node did not become idle (state '$state')"

# The scene and flags (TWINPATH_SLURM_SCENE, TWINPATH_SLURM_FLAGS: for measuring larger renders).
scene=${TWINPATH_SLURM_SCENE:-$repo/scenes/textures.toml}
read -r -a flags <<<"${TWINPATH_SLURM_FLAGS:---backend cpu --spp 16 --width 160}"
cd "$tmp/work"
start=$(date +%s%N)
jid=$(TWINPATH=$bin sbatch --parsable --array=0-3 --export=ALL \
    "$repo/scripts/slurm/render.sbatch" "$scene" parts "${flags[@]}")
mid=$(TWINPATH=$bin sbatch --parsable --dependency=afterok:"$jid" --export=ALL \
    "$repo/scripts/slurm/merge.sbatch" parts merged.exr merged.png)
# Wait for both jobs to leave the queue.
for _ in $(seq 1800); do
    [ -z "$(squeue -h -j "$jid,$mid" 2>/dev/null)" ] && break
    sleep 0.5
done
slurm_ms=$((($(date +%s%N) - start) / 1000000))
merge_state=$(scontrol show job "$mid" | grep -o 'JobState=[A-Z_]*' | head -1)
[ "$merge_state" = JobState=COMPLETED ] || fail "merge job $mid: $merge_state"
[ "$(ls parts/part-*.exr | wc -l)" = 4 ] || fail "expected 4 part files"

start=$(date +%s%N)
"$bin" render "$scene" "${flags[@]}" --quiet -o single.exr -o single.png 2>/dev/null
single_ms=$((($(date +%s%N) - start) / 1000000))
cmp merged.exr single.exr || fail "the merged EXR differs from the single-process render"
cmp merged.png single.png || fail "the merged PNG differs from the single-process render"
echo "test_cluster: ok: ${scene#"$repo"/} ${flags[*]}: 4-part Slurm array + merge ${slurm_ms} ms," \
    "one process ${single_ms} ms, merged image byte-identical"
