#!/usr/bin/env bash
# Submit a polhode Monte Carlo campaign to SLURM as a job array of SHARDS tasks, plus a merge
# job that runs once every shard has succeeded (docs/cluster.md).
#
#   scripts/slurm/submit.sh [--wait] SCENARIO OUTDIR SHARDS [extra polhode montecarlo args]
#
# e.g. scripts/slurm/submit.sh --wait scenarios/explorer1-pydy.yaml /cluster/mc1 8 --runs 1000 --seed 7
#
# Writes OUTDIR/shard-1 .. OUTDIR/shard-SHARDS, then OUTDIR/merged; SLURM logs go to
# OUTDIR/logs/slurm-<array job>_<task>.out and OUTDIR/logs/slurm-<merge job>.out.
# Prints ARRAY_JOB=<id> and MERGE_JOB=<id> on stdout.
#
#   --wait    wait for both jobs; exit non-zero (and show their logs) if either failed
#
# Environment:
#   POLHODE              polhode binary (default `polhode` on PATH; a path is made absolute)
#   POLHODE_CPUS         CPUs (and polhode threads) per shard task, default 1
#   SBATCH_PARTITION, SBATCH_ACCOUNT, SBATCH_TIMELIMIT, ...  read by sbatch itself
# OUTDIR must be on a file system that the compute nodes share with this host.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

usage() {
    sed -n '2,/^set -euo/p' "${BASH_SOURCE[0]}" | sed '$d; s/^# \{0,1\}//' >&2
    exit 2
}

wait=false
while (($#)) && [[ $1 == -* ]]; do
    case $1 in
    --wait) wait=true ;;
    -h | --help) usage ;;
    *)
        echo "submit.sh: unknown option $1" >&2
        usage
        ;;
    esac
    shift
done
(($# >= 3)) || usage
scenario=$1 outdir=$2 shards=$3
shift 3
[[ $shards =~ ^[1-9][0-9]*$ ]] || {
    echo "submit.sh: SHARDS must be a positive integer, not '$shards'" >&2
    exit 2
}
[[ -f $scenario ]] || {
    echo "submit.sh: no scenario file $scenario" >&2
    exit 2
}

# Absolute paths, so the jobs do not depend on the directory they start in.
scenario=$(realpath "$scenario")
mkdir -p "$outdir/logs"
outdir=$(realpath "$outdir")
POLHODE=${POLHODE:-polhode}
if [[ $POLHODE == */* ]]; then
    POLHODE=$(realpath "$POLHODE")
fi
export POLHODE # sbatch passes the environment on (--export=ALL is its default)
cpus=${POLHODE_CPUS:-1}

# Single-quote a word for the POSIX sh that runs sbatch --wrap.
q() { printf "'%s'" "${1//\'/\'\\\'\'}"; }

array_job=$(POLHODE_SHARDS=$shards sbatch --parsable --array="1-$shards" --cpus-per-task="$cpus" \
    --job-name=polhode-mc --output="$outdir/logs/slurm-%A_%a.out" \
    "$here/polhode-array.sbatch" "$scenario" "$outdir" "$@")
array_job=${array_job%%;*}

# The merge job names every shard (the same set as OUTDIR/shard-*, but a missing one is an
# error rather than silently skipped) and, like the shards, writes to a partial directory that
# it renames when done.
merge_cmd="set -e; cd $(q "$outdir"); rm -rf .merged.partial; $(q "$POLHODE") merge"
for ((k = 1; k <= shards; k++)); do
    merge_cmd+=" shard-$k"
done
merge_cmd+=" --out .merged.partial; rm -rf merged; mv .merged.partial merged"
merge_job=$(sbatch --parsable --dependency="afterok:$array_job" --kill-on-invalid-dep=yes \
    --job-name=polhode-merge --output="$outdir/logs/slurm-%j.out" --wrap "$merge_cmd")
merge_job=${merge_job%%;*}

echo "ARRAY_JOB=$array_job"
echo "MERGE_JOB=$merge_job"
$wait || exit 0

# States of all tasks of job $1, one a line; empty once SLURM has forgotten the job.
states() {
    local s
    s=$(scontrol -o show job "$1" 2>/dev/null | grep -o 'JobState=[A-Z_]*' | cut -d= -f2) || true
    if [[ -z $s ]] && command -v sacct >/dev/null; then
        s=$(sacct -n -X -P -j "$1" -o State 2>/dev/null | cut -d' ' -f1) || true
    fi
    printf '%s' "$s"
}

# Wait until every task of job $1 has finished; succeed if all of them COMPLETED.
wait_job() {
    local s
    while :; do
        s=$(states "$1")
        if [[ -z $s ]]; then
            echo "submit.sh: SLURM no longer knows job $1" >&2
            return 1
        fi
        if ! grep -qvE '^(COMPLETED|FAILED|CANCELLED|TIMEOUT|NODE_FAIL|OUT_OF_MEMORY|PREEMPTED|BOOT_FAIL|DEADLINE|SPECIAL_EXIT)$' <<<"$s"; then
            break
        fi
        sleep 2
    done
    echo "job $1: $(sort <<<"$s" | uniq -c | awk '{ printf "%s%s x%s", sep, $2, $1; sep = ", " }')" >&2
    ! grep -qv '^COMPLETED$' <<<"$s"
}

show_logs() {
    local f
    for f in "$outdir/logs/slurm-${array_job}"_*.out "$outdir/logs/slurm-$merge_job.out"; do
        [[ -f $f ]] || continue
        printf '\n===== %s =====\n' "$f" >&2
        cat "$f" >&2
    done
}

start=$SECONDS
if ! wait_job "$array_job"; then
    scancel "$merge_job" 2>/dev/null || true
    show_logs
    echo "submit.sh: FAILED: shard array $array_job did not complete" >&2
    exit 1
fi
if ! wait_job "$merge_job"; then
    show_logs
    echo "submit.sh: FAILED: merge job $merge_job did not complete" >&2
    exit 1
fi
echo "submit.sh: campaign done in $((SECONDS - start)) s -> $outdir/merged" >&2
