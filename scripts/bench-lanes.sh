#!/usr/bin/env bash
# The figures of issue 39 (campaigns in lanes, the main job at its floor) for this build
# against a baseline build of polhode (docs/benchmarks.md, docs/montecarlo.md):
#   - runs per second on one thread of the nutation-damper campaign (rigid bus and one
#     spring–mass damper, dispersed wobble, spin and dashpot: scenarios/nutation-damper.yaml)
#     and of the explorer1-pydy campaign (four hinged rods), each as shard 1/1 (the runs
#     without the charts and the MCAP of the worst, median and best runs);
#   - the whole-process wall time of the main job, `polhode run scenarios/explorer1.yaml
#     --no-log -q`.
# Each figure is taken from the two builds in turn, REPEATS pairs (default 3), and the ratio
# is taken pair by pair, so that a shared machine's drift cancels; the table gives medians.
#
#   [REPEATS=3] [RUNS=200] [PYDY_RUNS=16] scripts/bench-lanes.sh BASELINE_BINARY
#
# BASELINE_BINARY: a polhode binary of the build to compare against (for example one built
# from the commit before the issue with `cargo build --release` in a worktree).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
if [[ $# -ne 1 || ! -x "$1" ]]; then
    echo "usage: scripts/bench-lanes.sh BASELINE_BINARY (an executable polhode)" >&2
    exit 2
fi
baseline=$(realpath "$1")
cargo build --release --locked --quiet
candidate=$PWD/target/release/polhode
repeats=${REPEATS:-3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Runs per second from a campaign's closing line.
runs_per_second() {
    local bin=$1
    shift
    rm -rf "$work/out"
    "$bin" montecarlo "$@" --threads 1 --shard 1/1 --out "$work/out" 2>&1 >/dev/null |
        sed -nE 's/.* runs in .*\(([0-9.]+) runs\/s.*/\1/p'
}

# Whole-process wall seconds of one command.
wall_seconds() {
    python3 - "$@" <<'EOF'
import subprocess, sys, time
start = time.monotonic()
subprocess.run(sys.argv[1:], check=True, stdout=subprocess.DEVNULL)
print(f"{time.monotonic() - start:.3f}")
EOF
}

# "median(a) median(b) median(a/b) min(a/b) max(a/b)" of paired figures "a b" on stdin.
summarise() {
    python3 -c '
import statistics, sys
pairs = [tuple(map(float, line.split())) for line in sys.stdin if line.strip()]
a, b = zip(*pairs)
r = [x / y for x, y in pairs]
print(f"{statistics.median(a):.4g} {statistics.median(b):.4g} {statistics.median(r):.3f} {min(r):.3f} {max(r):.3f}")
'
}

row() {
    local what=$1 unit=$2 figures=$3
    read -r this base ratio low high < <(summarise <<<"$figures")
    echo "| $what | $unit | $base | $this | $ratio ($low–$high) |"
}

# Paired figures, "this baseline" a line, of MEASURE (runs_per_second or wall_seconds) on
# each build in turn, with the rest of the arguments.
paired() {
    local measure=$1
    shift
    for _ in $(seq "$repeats"); do
        local b a
        b=$("$measure" "$baseline" "$@")
        a=$("$measure" "$candidate" "$@")
        echo "$a $b"
    done
}

echo "| figure | unit | baseline | this build | this / baseline, paired median (range) |"
echo "|---|---|---:|---:|---:|"
row "nutation-damper campaign, ${RUNS:-200} runs, 1 thread" "runs/s" \
    "$(paired runs_per_second scenarios/nutation-damper.yaml --runs "${RUNS:-200}")"
row "explorer1-pydy campaign, ${PYDY_RUNS:-16} runs, 1 thread" "runs/s" \
    "$(paired runs_per_second scenarios/explorer1-pydy.yaml --runs "${PYDY_RUNS:-16}")"
row "main job (explorer1.yaml --no-log)" "s" \
    "$(paired wall_seconds run scenarios/explorer1.yaml --no-log -q)"
