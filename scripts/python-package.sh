#!/usr/bin/env bash
# Builds and installs the Python package (`pip install ./python`, PyO3 + maturin) into the
# test venv, then runs its tests (python/tests) against the CLI.
#
#   scripts/python-package.sh
#
# The wheel is compiled into the repository's target/ (CARGO_TARGET_DIR), so the crates that
# `cargo test --release` already built are reused; maturin comes from PyPI through pip's build
# isolation. Prints how long the install took.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
repo_root="$(pwd)"

scripts/python-venv.sh
start=$(date +%s)
CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-${repo_root}/target}" \
    .venv/bin/python -m pip install --quiet --disable-pip-version-check ./python
echo "python-package: pip install ./python took $(( $(date +%s) - start )) s"
.venv/bin/python -m pytest python/tests -q
