#!/usr/bin/env bash
# The one test command (README): sets up what the tests need on a fresh machine, then runs
# the formatter check, clippy and the whole test suite.
#
#   scripts/test.sh
#
# Needs cargo (with rustfmt and clippy) and python3 with the venv module; installs the Python
# packages of the independent MCAP reader into .venv (tests/python/requirements.txt).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

scripts/python-venv.sh
cargo fmt --all -- --check
cargo clippy --release --all-targets --locked -- -D warnings
cargo test --release --locked --lib --bins --tests
