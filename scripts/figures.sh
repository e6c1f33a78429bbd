#!/usr/bin/env bash
# Regenerates the charts and tables of docs/choosing-a-method.md into docs/figures/
# (SVG, PNG and CSV): work-precision on five problems, long-horizon invariant drift, the
# stability map and error growth near the separatrix. About 2 minutes on 2 cores; timings are
# minima of repeats, and meaningful only as ratios within one run (shared, noisy machines).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --locked --quiet
bin=target/release/polhode
"$bin" bench work-precision --out docs/figures "$@"
"$bin" bench drift --out docs/figures
"$bin" bench stability --out docs/figures
"$bin" bench separatrix --out docs/figures
