#!/usr/bin/env bash
# Regenerates the charts and tables of docs/choosing-a-method.md into docs/figures/
# (SVG, PNG and CSV): work-precision on five problems, long-horizon invariant drift, the
# stability map, error growth near the separatrix, and the long-horizon comparison of dop853 and
# the averaged method on two dissipating scenes. About 4 minutes on 2 cores; timings are
# minima of repeats, and meaningful only as ratios within one run (shared, noisy machines).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --locked --quiet
bin=target/release/polhode
"$bin" bench work-precision --out docs/figures "$@"
"$bin" bench drift --out docs/figures
"$bin" bench stability --out docs/figures
"$bin" bench separatrix --out docs/figures
"$bin" bench long-horizon scenarios/explorer1-energy-sink.yaml --times 3600,6888,10000,14400 --out docs/figures
"$bin" bench long-horizon scenarios/triaxial-energy-sink.yaml --times 1000,2500,3000,5000 --out docs/figures
