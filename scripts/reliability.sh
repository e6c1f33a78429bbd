#!/usr/bin/env bash
# Regenerates the tables of docs/reliability.md from what actually happens: runs the bad-input
# corpus (tests/corpus.rs) and the fault tests (tests/faults.rs) with each case's observed
# outcome recorded, measures peak memory against run length and the log-size estimate against
# real logs, and rewrites the tables between the markers in docs/reliability.md.
#
#   scripts/reliability.sh            (about 2 minutes with the build warm)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
rows=$(mktemp -d)
trap 'rm -rf "$rows"' EXIT
POLHODE_RELIABILITY_DIR="$rows" cargo test --release --locked -q --test corpus --test faults
cargo build --release --locked -q
python3 scripts/reliability/tables.py "$rows" target/release/polhode docs/reliability.md
echo "docs/reliability.md: tables regenerated"
