#!/usr/bin/env bash
# Tries the Slurm path for real on one machine: installs Debian's slurm-wlm (root, apt), starts
# a one-node cluster on localhost, submits the generate and eval array jobs, waits, merges, and
# compares with the unsharded runs. Run from the repository root after `cargo build --release`:
#   bash docs/scale/slurm-local.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD
export ARLPCG=$root/target/release/arlpcg
[ -x "$ARLPCG" ] || { echo "build first: cargo build --release" >&2; exit 1; }
if ! command -v slurmctld >/dev/null; then
    apt-get install -y --no-install-recommends slurm-wlm
fi
work=$(mktemp -d /tmp/arlpcg-slurm.XXXXXX)
host=$(hostname -s)
cpus=$(nproc)
mem=$(( $(free -m | awk '/Mem:/ {print $2}') - 1024 ))
mkdir -p "$work/state" "$work/spool" "$work/log"
cat > "$work/slurm.conf" <<CONF
ClusterName=arlpcg-local
SlurmctldHost=$host
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldLogFile=$work/log/slurmctld.log
SlurmdLogFile=$work/log/slurmd.log
SlurmUser=root
NodeName=$host CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$work/slurm.conf
mkdir -p /run/munge
pgrep -x munged >/dev/null || munged --force
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
trap 'scancel --quiet --user=root || true; pkill -x slurmd || true; pkill -x slurmctld || true' EXIT
for _ in $(seq 30); do sinfo -h -o %T 2>/dev/null | grep -qE 'idle|mixed' && break; sleep 1; done
sinfo

echo "== generate: 4 shards of 40 levels as a Slurm array, against one unsharded run"
job=$(sbatch --parsable --chdir="$root" --output="$work/log/gen-%a.out" --array=0-3 \
    docs/scale/slurm-array.sbatch "$work/sharded" 40 1)
"$ARLPCG" generate --game platform --policies policies/platform --aux -0.5 --verify 20 \
    --count 40 --seed 1 --format yaml,glb --out "$work/whole"

echo "== eval: 3 shards as a Slurm array, against one unsharded run"
eval_job=$(sbatch --parsable --chdir="$root" --output="$work/log/eval-%a.out" --array=0-2 \
    --export=ALL,TRACKS=6,TRIALS=10 docs/scale/slurm-eval.sbatch "$work/parts")
"$ARLPCG" eval --policies policies/platform --tracks 6 --trials 10 --out "$work/eval-whole" >/dev/null
while squeue -h -j "$job,$eval_job" 2>/dev/null | grep -q .; do sleep 2; done
sacct -j "$job,$eval_job" -X -n -o JobID,State,ExitCode 2>/dev/null || true
cat "$work"/log/gen-*.out "$work"/log/eval-*.out
"$ARLPCG" eval --merge "$work/parts/0" "$work/parts/1" "$work/parts/2" --out "$work/eval-merged" >/dev/null

echo "== compare"
diff -r "$work/whole" "$work/sharded" && echo "generate: the 4 Slurm shards wrote exactly the unsharded batch ($(ls "$work/whole" | wc -l) files)"
cmp "$work/eval-whole/results.json" "$work/eval-merged/results.json" \
    && echo "eval: the merged Slurm shards give the unsharded results.json byte for byte"
