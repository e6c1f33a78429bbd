#!/usr/bin/env bash
# End-to-end test of the SLURM scripts on a real one-node cluster on this machine
# (docs/cluster.md): runs a campaign as a SLURM job array plus merge job, runs the same
# campaign in one process, and checks that the two agree byte for byte.
#
#   scripts/slurm/test-local.sh [SCENARIO]     (as root, on Debian)
#
#   SCENARIO  default scenarios/explorer1-energy-sink.yaml
# Environment:
#   POLHODE   polhode binary, default target/release/polhode (relative to the repo root);
#             this script builds nothing
#   SHARDS    array tasks (default 3); RUNS runs (default 12); SEED seed (default 42)
#   KEEP=1    keep the work directory instead of deleting it
#
# Starts the cluster with local-cluster.sh if it is not already up, and stops it again at the
# end if it started it. Prints PASS or FAIL and the time taken; exits 0 only on PASS.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
t0=$SECONDS

scenario=$(realpath "${1:-$root/scenarios/explorer1-energy-sink.yaml}")
POLHODE=$(realpath "${POLHODE:-$root/target/release/polhode}")
export POLHODE
shards=${SHARDS:-3} runs=${RUNS:-12} seed=${SEED:-42}
[[ -x $POLHODE ]] || {
    echo "test-local: no polhode binary at $POLHODE (build it, or set POLHODE)" >&2
    exit 2
}

started_cluster=false
work=
jobs_file=

# On any exit: cancel our jobs if they are still queued, stop the cluster if we started it,
# delete the work directory.
cleanup() {
    local id
    if [[ -n $jobs_file && -f $jobs_file ]]; then
        while IFS='=' read -r _ id; do
            scancel "$id" 2>/dev/null || true
        done <"$jobs_file"
    fi
    if $started_cluster; then
        "$here/local-cluster.sh" stop || true
    fi
    if [[ -n $work && ${KEEP:-0} != 1 ]]; then
        rm -rf "$work"
    elif [[ -n $work ]]; then
        echo "test-local: kept $work" >&2
    fi
}
trap cleanup EXIT

eval "$("$here/local-cluster.sh" env)" # SLURM_CONF for the cluster local-cluster.sh runs
if "$here/local-cluster.sh" status; then
    echo "test-local: using the cluster that is already running"
else
    started_cluster=true
    t=$SECONDS
    "$here/local-cluster.sh" start
    echo "test-local: cluster up in $((SECONDS - t)) s"
fi

# The jobs run on this machine, so any local directory is "shared".
work=$(mktemp -d /var/tmp/polhode-slurm-test.XXXXXX)
chmod 755 "$work"
jobs_file=$work/jobs

echo "test-local: ${shards} shards of $(basename "$scenario"), --runs $runs --seed $seed, polhode $POLHODE"
t=$SECONDS
submit_ok=true
"$here/submit.sh" --wait "$scenario" "$work" "$shards" --runs "$runs" --seed "$seed" |
    tee "$jobs_file" || submit_ok=false
slurm_s=$((SECONDS - t))

t=$SECONDS
single_ok=true
"$POLHODE" montecarlo "$scenario" --runs "$runs" --seed "$seed" --threads 2 --out "$work/single" ||
    single_ok=false
single_s=$((SECONDS - t))

failed=0
$submit_ok || failed=1
$single_ok || {
    echo "test-local: the single-process run failed" >&2
    failed=1
}
if $submit_ok && $single_ok; then
    # Every file of the single-process result: table, summary, manifest, charts, MCAP.
    for f in $(cd "$work/single" && ls); do
        if cmp "$work/merged/$f" "$work/single/$f"; then
            echo "  same: $f"
        else
            echo "  DIFFERENT: $f" >&2
            failed=1
        fi
    done
fi

echo "test-local: SLURM array + merge ${slurm_s} s, single process ${single_s} s"
if ((failed)); then
    echo "FAIL ($((SECONDS - t0)) s in all)"
    exit 1
fi
echo "PASS ($((SECONDS - t0)) s in all)"
