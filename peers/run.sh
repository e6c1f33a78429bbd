#!/usr/bin/env bash
# Peer comparison: polhode against the differential-equations crate (same right-hand side),
# SciPy's solve_ivp and Basilisk, on the same problems and tolerances. Creates what it needs
# (the Python venv at peers/.venv from peers/requirements.txt, the release builds of polhode and
# of peers/rust-ode), runs everything, writes peers/results/ and regenerates the tables of
# docs/peers.md. Needs cargo and python3 >= 3.9 (bsk 2.12.1 is one abi3 wheel,
# cp39-abi3-manylinux_2_28_x86_64; used here with CPython 3.11).
#
#   peers/run.sh                 everything (about 5 min once built; the first build of
#                                peers/rust-ode compiles polhode's dependencies again: ~9 min)
#   peers/run.sh --no-basilisk   skip the Basilisk part
#   peers/run.sh --report-only   regenerate docs/peers.md from peers/results/
#
# POLHODE_BIN=PATH uses that polhode binary in peers/campaign.py instead of target/release/polhode.
set -euo pipefail
export PYTHONDONTWRITEBYTECODE=1
cd "$(dirname "$0")"
PEERS="$(pwd)"
ROOT="$(cd .. && pwd)"
VENV="$PEERS/.venv"
basilisk=1
report_only=0
for arg in "$@"; do
  case "$arg" in
    --no-basilisk) basilisk=0 ;;
    --report-only) report_only=1 ;;
    *) echo "usage: peers/run.sh [--no-basilisk] [--report-only]" >&2; exit 2 ;;
  esac
done

# Python venv, recreated when requirements.txt changes.
stamp="$VENV/.requirements.sha256"
want="$(sha256sum "$PEERS/requirements.txt" | cut -d' ' -f1)"
if [[ ! -x "$VENV/bin/python" || ! -f "$stamp" || "$(cat "$stamp")" != "$want" ]]; then
  echo "[run] creating $VENV"
  rm -rf "$VENV"
  python3 -m venv "$VENV"
  "$VENV/bin/pip" install --quiet --disable-pip-version-check -r "$PEERS/requirements.txt"
  echo "$want" > "$stamp"
fi

if [[ $report_only == 0 ]]; then
  echo "[run] building polhode (release)"
  (cd "$ROOT" && cargo build --release --quiet)
  echo "[run] building peers/rust-ode (release, own target dir)"
  (cd "$PEERS/rust-ode" && CARGO_TARGET_DIR="$PEERS/rust-ode/target" cargo build --release --quiet)
  mkdir -p "$PEERS/results"
  "$VENV/bin/python" "$PEERS/bench.py"
  # Campaign throughput on one thread: lanes, --no-lanes, SciPy (results/campaign.json).
  "$VENV/bin/python" "$PEERS/campaign.py"
  if [[ $basilisk == 1 ]]; then
    "$VENV/bin/python" "$PEERS/basilisk_smd.py"
    "$VENV/bin/python" "$PEERS/basilisk_slosh.py"
    "$VENV/bin/python" "$PEERS/basilisk_slosh_spring.py"
    "$VENV/bin/python" "$PEERS/basilisk_burn.py"
    "$VENV/bin/python" "$PEERS/basilisk_environment.py"
  fi
  # slosh_pendulum along Basilisk's sphericalPendulum trajectories (results/basilisk_slosh.json).
  echo "[run] polhode's slosh_pendulum against Basilisk's trajectories (tests/basilisk_slosh.rs)"
  (cd "$ROOT" && cargo test --release --locked --quiet --test basilisk_slosh)
  # the tank's spring_mass_damper along Basilisk's trajectories (results/basilisk_slosh_spring.json).
  echo "[run] polhode's tank spring against Basilisk's trajectories (tests/basilisk_slosh_spring.rs)"
  (cd "$ROOT" && cargo test --release --locked --quiet --test basilisk_slosh_spring)
  # polhode's environmental torques at the states of results/basilisk_environment.json.
  echo "[run] polhode's environmental torques at Basilisk's states (tests/basilisk_environment.rs)"
  (cd "$ROOT" && POLHODE_PEER_OUT="$PEERS/results/basilisk_environment_polhode.json" \
    cargo test --release --locked --quiet --test basilisk_environment)
fi
"$VENV/bin/python" "$PEERS/report.py"
