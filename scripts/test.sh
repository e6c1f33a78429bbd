#!/usr/bin/env bash
# The one test command (README): sets up what the tests need on a fresh machine, then runs
# the formatter check, clippy and the whole test suite, the Python package's included.
#
#   scripts/test.sh
#
# Needs cargo (with rustfmt and clippy), python3 with the venv module, and root on Debian for
# the SLURM test; installs the Python packages of the independent MCAP and Parquet readers
# into .venv (tests/python/requirements.txt).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
# The toolchain rust-toolchain.toml pins is installed by rustup on the first cargo call, also
# where its automatic installs are turned off (RUSTUP_AUTO_INSTALL=0).
export RUSTUP_AUTO_INSTALL=1

scripts/python-venv.sh
cargo fmt --all -- --check
cargo clippy --release --workspace --all-targets --locked -- -D warnings
# The main job and `pip install ./python` share one build of the library (docs/python.md).
scripts/check-shared-build.sh
# --workspace: the Python crate's dependencies join the feature resolution, so that
# `pip install ./python` below reuses this build of the polhode library instead of compiling
# it again (docs/python.md, "Build time"). --tests covers the library's unit tests
# (every target with `test = true`); no --lib, which would also build a test harness of the
# Python crate (`test = false`), linked against libpython.
cargo test --release --locked --workspace --bins --tests
# The crate documentation's examples (the typed API's front door), and the documentation
# itself without a broken link or a missing item. --workspace for the same features as above
# (the Python crate has `doctest = false`).
cargo test --release --locked --workspace --doc
RUSTDOCFLAGS="-D warnings" cargo doc --release --no-deps --locked -p polhode
# The Python package: `pip install ./python` into the venv (sharing target/ with the build
# above), then its pytest suite against the CLI (docs/python.md).
# The binary the tests above just built is the CLI the pytest suite compares against.
POLHODE_BIN="$PWD/target/release/polhode" scripts/python-package.sh
# A Monte Carlo campaign as a SLURM job array on a real one-node cluster (installs Debian's
# slurm-wlm and munge if missing; needs root): the merged shards must equal a single-process
# run byte for byte (docs/cluster.md).
RUNS=200 SHARDS=4 SEED=3 scripts/slurm/test-local.sh tests/data/montecarlo-sink.yaml
# The logs in the real viewers (docs/viewing.md): Foxglove Studio in headless Chromium with the
# shipped layout, and Rerun (mcap check of every scenario, the converted recording verified, a
# headless screenshot), each image checked; written to a scratch directory, not docs/.
viewer_out=$(mktemp -d)
scripts/viewers/screenshots.sh "$viewer_out"
rm -rf "$viewer_out"
# Fuzzing for a bounded time (docs/reliability.md): the scenario loader and the MCAP/summary
# writers, 30 s each side by side (installs cargo-fuzz if missing; `scripts/fuzz.sh 3600` for
# longer runs on demand).
scripts/fuzz.sh 30
