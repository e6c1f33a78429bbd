#!/usr/bin/env bash
# Opens an Explorer 1 log in the real viewers and checks what they show (docs/viewing.md):
#   - Foxglove Studio (the last open-source release, in headless Chromium) with the shipped
#     layout docs/viewers/polhode.foxglove-layout.json, at two times: the body is drawn and has
#     turned, the plots are drawn; then a scenario in orbit (gravity-gradient-smallsat): the
#     orbit panel draws the Earth, the orbit path and the spacecraft marker, and they moved;
#   - Rerun: `rerun mcap check` on a log of every shipped scenario, the MCAP converted to a
#     native recording (`rerun rrd verify`, transforms and telemetry compared with the MCAP),
#     and headless screenshots with the body and the plots, and (in orbit) the Earth, the orbit
#     path and the marker.
#
#   scripts/viewers/screenshots.sh [OUT_DIR]     (default docs/figures/viewing)
#   scripts/viewers/screenshots.sh --actuators [OUT_DIR]   (default docs/figures/actuators)
#
# --actuators: the pictures of docs/actuators.md instead (not run by scripts/test.sh; about
# 4 minutes): the dual-spin scenes in Foxglove (the rotor disc drawn, the nutation decaying or
# growing), the reaction-wheel pyramid (four discs) and the CubeSat detumbling in orbit in
# Rerun, each checked as the ones above and for the effectors' red and the decay of |ω|.
#
# Installs what is missing (Debian packages, npm and PyPI packages; needs root for apt).
# Exits non-zero if any check fails. POLHODE selects the binary (default target/release/polhode).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
if [ "${1:-}" = "--actuators" ]; then
  out=$(realpath -m "${2:-docs/figures/actuators}")
  mkdir -p "$out"
  status=0
  ACTUATORS=1 OUT="$out" scripts/viewers/foxglove/run.sh || status=$?
  ACTUATORS=1 OUT_DIR="$out" scripts/viewers/rerun/run.sh || status=$?
  exit "$status"
fi
out=$(realpath -m "${1:-docs/figures/viewing}")
mkdir -p "$out"
OUT="$out" scripts/viewers/foxglove/run.sh
OUT="$out/rerun.png" scripts/viewers/rerun/run.sh
