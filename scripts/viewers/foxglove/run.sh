#!/usr/bin/env bash
# Opens a polhode log in Foxglove Studio (open-source studio-base 1.48, headless Chromium) with
# the shipped layout docs/viewers/polhode.foxglove-layout.json, saves two screenshots and checks
# them. Installs what is missing (Debian's chromium, the npm packages of this folder), makes
# the explorer1-pydy log, and writes $OUT/foxglove-early.png and $OUT/foxglove-late.png; then
# the same with a scenario in orbit (the orbit panel: Earth, path, marker), written to
# $OUT/foxglove-orbit-early.png and $OUT/foxglove-orbit-late.png. Last, the live view:
# `polhode run --live` of explorer1-pydy paced at LIVE_REALTIME times wall-clock time
# (default 2) on a free port, Foxglove connected to it (ds=foxglove-websocket) with the same
# layout, one screenshot $OUT/foxglove-live.png once the body and every series are drawn.
#
#   scripts/viewers/foxglove/run.sh
#
# Environment: POLHODE (the polhode binary; default target/release/polhode, built with cargo
# if missing), OUT (default docs/figures/viewing), SCENARIO (default
# scenarios/explorer1-pydy.yaml), EARLY and LATE (seconds into the log; default 10 and 120),
# CHROMIUM (default /usr/bin/chromium), ORBIT_SCENARIO (default
# scenarios/gravity-gradient-smallsat.yaml, run for ORBIT_DURATION s, default 3600),
# ORBIT_EARLY and ORBIT_LATE (default 2000 and 3400 s: a quarter of an orbit apart, both on the
# side of the Earth the orbit panel's camera looks at). The checks want every
# plotted series visible: true of explorer1-pydy, not of a rigid body, whose dissipated and
# elastic energies are both 0 and hide each other (so the orbit capture only wants the plots
# not blank).
#
# ACTUATORS=1 (scripts/viewers/screenshots.sh --actuators): instead, the actuator scenes of
# docs/actuators.md, each checked as above and with its rotor disc drawn (--effectors):
# dual-spin.yaml (150 s log, at 15 and 90 s: the nutation decaying) and
# dual-spin-rotor-damper.yaml (150 s, at 20 and 120 s: the drift toward the flat spin), written
# to $OUT/foxglove-dual-spin-{early,late}.png and $OUT/foxglove-dual-spin-rotor-damper-*.png
# (OUT defaults to docs/figures/actuators then).
set -euo pipefail

here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../../.." && pwd)"
actuators="${ACTUATORS:-}"
if [ -n "$actuators" ]; then
  out="${OUT:-$repo/docs/figures/actuators}"
else
  out="${OUT:-$repo/docs/figures/viewing}"
fi
scenario="${SCENARIO:-$repo/scenarios/explorer1-pydy.yaml}"
chromium="${CHROMIUM:-/usr/bin/chromium}"
now() { date +%s.%N; }
since() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }'; }

# Root runs apt-get directly; others need sudo.
as_root() {
  if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi
}

# 1. Install what is missing.
t_install=$(now)
if [ ! -x "$chromium" ]; then
  echo "installing chromium (apt)"
  as_root apt-get update -qq
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null
fi
# npm keeps node_modules/.package-lock.json; reinstall when the lock file is newer.
if [ ! -f "$here/node_modules/.package-lock.json" ] ||
  [ "$here/package-lock.json" -nt "$here/node_modules/.package-lock.json" ]; then
  echo "installing npm packages (npm ci)"
  (cd "$here" && npm ci --no-audit --no-fund --loglevel=error)
fi
echo "install: $(since "$t_install") s"

# 2. The polhode binary: $POLHODE, or the repository's release build (built if missing).
if [ -n "${POLHODE:-}" ]; then
  polhode="$POLHODE"
else
  polhode="$repo/target/release/polhode"
  if [ ! -x "$polhode" ]; then
    command -v cargo >/dev/null ||
      { echo "FAIL: no $polhode and no cargo to build it (set POLHODE)" >&2; exit 1; }
    echo "building polhode (cargo build --release)"
    (cd "$repo" && cargo build --release --locked --quiet)
  fi
fi
[ -x "$polhode" ] || { echo "FAIL: no polhode binary at $polhode (set POLHODE)" >&2; exit 1; }

# 3. The log, in a temporary folder removed on exit.
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# The actuator scenes (ACTUATORS=1): NAME DURATION EARLY LATE MIN_EFFECTOR_PIXELS per line.
if [ -n "$actuators" ]; then
  status=0
  written=()
  t_shots=$(now)
  while read -r name duration early late min_effector; do
    alog="$work/$name.mcap"
    if ! "$polhode" run "$repo/scenarios/$name.yaml" --out "$alog" --duration "$duration" \
      </dev/null >"$work/polhode-$name.txt" 2>&1; then
      cat "$work/polhode-$name.txt" >&2
      echo "FAIL: polhode could not make the log of $name" >&2
      status=1
      continue
    fi
    echo "== $name: $(du -h "$alog" | cut -f1) log of $duration s"
    if node "$here/screenshots.mjs" --log "$alog" --out "$out" --chromium "$chromium" \
      --name "foxglove-$name" --early "$early" --late "$late" --effectors "$min_effector" </dev/null; then
      written+=("$out/foxglove-$name-early.png" "$out/foxglove-$name-late.png")
    else
      status=1
    fi
  done <<'SCENES'
dual-spin 150 15 90 2000
dual-spin-rotor-damper 150 20 120 2000
SCENES
  echo "screenshots: $(since "$t_shots") s"
  if [ "$status" -eq 0 ]; then
    echo "PASS (foxglove, actuators): ${written[*]}"
  else
    echo "FAIL (foxglove, actuators)"
  fi
  exit "$status"
fi
log="$work/$(basename "$scenario" .yaml).mcap"
t_log=$(now)
if ! "$polhode" run "$scenario" --out "$log" >"$work/polhode.txt" 2>&1; then
  cat "$work/polhode.txt" >&2
  echo "FAIL: polhode could not make the log" >&2
  exit 1
fi
echo "log: $(basename "$log"), $(du -h "$log" | cut -f1), $(since "$t_log") s"
orbit_scenario="${ORBIT_SCENARIO:-$repo/scenarios/gravity-gradient-smallsat.yaml}"
orbit_log="$work/$(basename "$orbit_scenario" .yaml).mcap"
if ! "$polhode" run "$orbit_scenario" --out "$orbit_log" --duration "${ORBIT_DURATION:-3600}" \
  >"$work/polhode-orbit.txt" 2>&1; then
  cat "$work/polhode-orbit.txt" >&2
  echo "FAIL: polhode could not make the orbit log" >&2
  exit 1
fi
echo "log: $(basename "$orbit_log"), $(du -h "$orbit_log" | cut -f1)"

# 4. Screenshots and checks.
t_shots=$(now)
status=0
node "$here/screenshots.mjs" --log "$log" --out "$out" --chromium "$chromium" \
  --early "${EARLY:-10}" --late "${LATE:-120}" || status=$?
node "$here/screenshots.mjs" --log "$orbit_log" --out "$out" --chromium "$chromium" --orbit \
  --early "${ORBIT_EARLY:-2000}" --late "${ORBIT_LATE:-3400}" || status=$?

# The live view: the run serves on a free port (--port 0) and says which on stderr; it stays
# up after the run (no --live-linger) until it is stopped here.
"$polhode" run "$scenario" --no-log --live --port 0 --realtime "${LIVE_REALTIME:-2}" \
  </dev/null >"$work/polhode-live.txt" 2>"$work/polhode-live.err" &
live_pid=$!
live_url=""
for _ in $(seq 1 300); do
  live_url=$(grep -o 'ws://localhost:[0-9]*' "$work/polhode-live.err" | head -n 1 || true)
  [ -n "$live_url" ] || ! kill -0 "$live_pid" 2>/dev/null && break
  sleep 0.1
done
if [ -z "$live_url" ]; then
  cat "$work/polhode-live.err" >&2
  echo "FAIL: polhode run --live did not announce its address" >&2
  status=1
else
  echo "live: $live_url (polhode pid $live_pid)"
  # The page is served from 127.0.0.1 and reaches nothing else.
  node "$here/screenshots.mjs" --live "${live_url/localhost/127.0.0.1}" --out "$out" \
    --chromium "$chromium" --timeout 150 || status=$?
fi
kill "$live_pid" 2>/dev/null || true
wait "$live_pid" 2>/dev/null || true
echo "screenshots: $(since "$t_shots") s"
if [ "$status" -eq 0 ]; then
  echo "PASS (foxglove): $out/foxglove-early.png, $out/foxglove-late.png," \
    "$out/foxglove-orbit-early.png, $out/foxglove-orbit-late.png, $out/foxglove-live.png"
else
  echo "FAIL (foxglove)"
fi
exit "$status"
