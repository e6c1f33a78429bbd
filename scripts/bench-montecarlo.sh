#!/usr/bin/env bash
# Monte Carlo throughput and memory (docs/montecarlo.md, "Performance"):
#   - runs per second of the explorer1-energy-sink and explorer1-pydy campaigns on 1 and 2
#     threads, and the speed-up, measured back to back in this script (the ratio is what
#     counts on a shared machine);
#   - peak resident memory of campaigns of 1,000, 10,000 and 40,000 runs of a fast scene.
#
#   [REPEATS=2] scripts/bench-montecarlo.sh [RUNS]   (RUNS per throughput campaign, default 16)
#
# Shard 1/1 is the whole campaign written as a shard: the same runs, without the charts and
# the MCAP of the worst, median and best runs, which are not part of the throughput.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
runs=${1:-16}
cargo build --release --locked --quiet
bin=target/release/polhode
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Prints "<runs/s> <peak MiB>" from polhode's closing line.
measure() {
    local line
    line=$("$bin" montecarlo "$@" --out "$work/out" 2>&1 >/dev/null | grep ' runs in ')
    sed -E 's/.*\(([0-9.]+) runs\/s.*peak memory ([0-9]+) MiB.*/\1 \2/' <<<"$line"
}

echo "| campaign | runs | 1 thread (runs/s) | 2 threads (runs/s) | speed-up |"
echo "|---|---:|---:|---:|---:|"
# Best of REPEATS timings per setting (default 1), taken interleaved: 1, 2, 1, 2 threads.
repeats=${REPEATS:-1}
best() { python3 -c "import sys; print(max(float(x) for x in sys.argv[1:]))" "$@"; }
for scenario in explorer1-energy-sink explorer1-pydy; do
    ones=() twos=()
    for _ in $(seq "$repeats"); do
        read -r r _ < <(measure "scenarios/$scenario.yaml" --runs "$runs" --threads 1 --shard 1/1)
        ones+=("$r")
        read -r r _ < <(measure "scenarios/$scenario.yaml" --runs "$runs" --threads 2 --shard 1/1)
        twos+=("$r")
    done
    one=$(best "${ones[@]}")
    two=$(best "${twos[@]}")
    speedup=$(python3 -c "print(f'{$two / $one:.2f}')")
    echo "| $scenario | $runs | $one | $two | ${speedup}× |"
done

echo
echo "| runs (tests/data/montecarlo-sink.yaml, 2 threads, full outputs) | peak memory (MiB) |"
echo "|---:|---:|"
for n in 1000 10000 40000; do
    read -r _ mib < <(measure tests/data/montecarlo-sink.yaml --runs "$n" --threads 2)
    echo "| $n | $mib |"
done
