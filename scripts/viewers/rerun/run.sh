#!/usr/bin/env bash
# polhode logs in Rerun, end to end, in one command (root on Debian 12; python3 >= 3.11):
#
#   scripts/viewers/rerun/run.sh
#
# 1. installs what is missing: Debian packages for a headless viewer (Xvfb, Mesa's software
#    Vulkan) and the pinned Python venv in scripts/viewers/rerun/.venv (rerun-sdk, mcap);
# 2. logs every shipped scenario (5 s of sim time; explorer1-pydy in full) and runs
#    `rerun mcap check --full` on each;
# 3. converts every log to .rrd (mcap_to_rrd.py), `rerun rrd verify` on each, and check.py:
#    /tf arrives as Transform3D and every telemetry field is there with the MCAP's values,
#    both in the raw MCAP as Rerun reads it and in the converted recording;
# 4. a headless screenshot of explorer1-pydy's recording, checked (body, plots), to OUT, and one
#    of a scenario in orbit (gravity-gradient-smallsat, ORBIT_DURATION s), checked (body, Earth,
#    orbit path, marker, plots), to OUT_ORBIT.
# Prints PASS or FAIL with timings; exit code 0 only on PASS. Idempotent.
#
# Environment: POLHODE (binary; default <repo>/target/release/polhode, built if missing and
# cargo exists), OUT (default <repo>/docs/figures/viewing/rerun.png), OUT_ORBIT (default
# rerun-orbit.png beside OUT), LOGS (work directory, default scripts/viewers/rerun/out),
# DURATION (default 5), ORBIT_DURATION (default 3400), PYTHON (default python3).
#
# ACTUATORS=1 (scripts/viewers/screenshots.sh --actuators): instead of every scenario, the
# actuator scenes of docs/actuators.md, through the same steps 2 to 4: rwa-rate-damping.yaml
# (120 s: the four wheel discs drawn, |ω| down to a tenth) and cubesat-detumble.yaml (its 4
# orbits: the orbit view, and |ω| down to a tenth), written to
# $OUT_DIR/rerun-rwa-rate-damping.png and $OUT_DIR/rerun-cubesat-detumble.png (OUT_DIR
# defaults to docs/figures/actuators). The X screen is made wider than the viewer's window
# there, so that the pointer (at the screen's centre) is off the window and no hover tooltip
# is drawn over the views.
set -euo pipefail

here="$(cd -- "$(dirname -- "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd -- "${here}/../../.." && pwd)"
venv="${here}/.venv"
logs="${LOGS:-${here}/out}"
out="${OUT:-${repo}/docs/figures/viewing/rerun.png}"
duration="${DURATION:-5}"
python="${PYTHON:-python3}"
flagship="explorer1-pydy"
orbit_flagship="gravity-gradient-smallsat"
out_orbit="${OUT_ORBIT:-$(dirname "${out}")/rerun-orbit.png}"
orbit_duration="${ORBIT_DURATION:-3400}"
actuators="${ACTUATORS:-}"
out_dir="${OUT_DIR:-${repo}/docs/figures/actuators}"
xvfb_screen="1920x1200x24"
# The actuator scenes and their sim durations (empty: the scenario's own).
declare -A actuator_duration=([rwa-rate-damping]=120 [cubesat-detumble]="")
if [[ -n "${actuators}" ]]; then
    xvfb_screen="7200x2000x24"
fi
# Largest PNG to keep as it is (bytes; 0: any); a larger one is written with 256 colours.
max_png=0
[[ -n "${actuators}" ]] && max_png=399000

now_ms() { echo $(($(date +%s%N) / 1000000)); }
seconds() { local d=$(($(now_ms) - $1)); printf '%d.%01d s' $((d / 1000)) $((d % 1000 / 100)); }
t_start=$(now_ms)
timings=()
failed=()
phase_t0=0
phase() { phase_t0=$(now_ms); echo "== $*"; }
done_phase() { timings+=("$(printf '%-28s %s' "$1" "$(seconds "${phase_t0}")")"); }
fail() { echo "FAIL: $*" >&2; failed+=("$*"); }

# --- 1. Debian packages (only what is missing) ----------------------------------------------
phase "system packages"
pkgs=(xvfb xauth mesa-vulkan-drivers libgl1-mesa-dri libvulkan1 libx11-xcb1 libxcursor1 libxi6
      libxkbcommon-x11-0 libfontconfig1)
# python3 -m venv needs ensurepip (Debian's python3-venv) unless the interpreter brings it.
"${python}" -c 'import ensurepip, venv' 2>/dev/null || pkgs+=(python3-venv)
missing=()
for p in "${pkgs[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if ((${#missing[@]})); then
    echo "installing: ${missing[*]}"
    sudo=""; [[ $(id -u) -eq 0 ]] || sudo="sudo"
    ${sudo} apt-get update -qq
    DEBIAN_FRONTEND=noninteractive ${sudo} apt-get install -y -qq --no-install-recommends \
        "${missing[@]}" >/dev/null
else
    echo "all present: ${pkgs[*]}"
fi
done_phase "system packages"

# --- Python venv (reinstalled only when requirements.txt changes) -----------------------------
phase "python venv"
want="$(sha256sum "${here}/requirements.txt" | cut -d' ' -f1)"
stamp="${venv}/.requirements.sha256"
[[ -x "${venv}/bin/python" ]] || "${python}" -m venv "${venv}"
if [[ -f "${stamp}" && "$(cat "${stamp}")" == "${want}" ]]; then
    echo "venv up to date (${want:0:12})"
else
    rm -f "${stamp}"
    "${venv}/bin/python" -m pip install --quiet --disable-pip-version-check \
        --requirement "${here}/requirements.txt"
    "${venv}/bin/python" -m pip check
    printf '%s\n' "${want}" > "${stamp}"
fi
py="${venv}/bin/python"
rerun="${venv}/bin/rerun"
"${rerun}" --version
"${rerun}" analytics disable >/dev/null
done_phase "python venv"

# --- polhode binary --------------------------------------------------------------------------
polhode="${POLHODE:-${repo}/target/release/polhode}"
if [[ ! -x "${polhode}" ]]; then
    if [[ -z "${POLHODE:-}" ]] && command -v cargo >/dev/null; then
        phase "cargo build"
        (cd "${repo}" && cargo build --release --locked --quiet)
        done_phase "cargo build"
    else
        echo "FAIL: no polhode binary at ${polhode} (set POLHODE or build with cargo)" >&2
        exit 1
    fi
fi

# --- 2. logs of every scenario, checked by Rerun ---------------------------------------------
phase "logs + rerun mcap check"
mkdir -p "${logs}"
shopt -s nullglob
scenarios=("${repo}"/scenarios/*.yaml)
if [[ -n "${actuators}" ]]; then
    scenarios=("${repo}/scenarios/rwa-rate-damping.yaml" "${repo}/scenarios/cubesat-detumble.yaml")
fi
((${#scenarios[@]})) || { echo "FAIL: no scenarios in ${repo}/scenarios" >&2; exit 1; }
names=()
for s in "${scenarios[@]}"; do
    n="$(basename "$s" .yaml)"
    names+=("$n")
    rm -f "${logs}/${n}.mcap" "${logs}/${n}.rrd" "${logs}/${n}.check.txt"  # no stale results
    args=(run "$s" --out "${logs}/${n}.mcap" --quiet)
    if [[ -n "${actuators}" ]]; then
        [[ -n "${actuator_duration[$n]}" ]] && args+=(--duration "${actuator_duration[$n]}")
    elif [[ "$n" == "${orbit_flagship}" ]]; then
        args+=(--duration "${orbit_duration}")
    elif [[ "$n" != "${flagship}" ]]; then
        args+=(--duration "${duration}")
    fi
    if ! "${polhode}" "${args[@]}"; then fail "polhode run ${n}"; continue; fi
    # Every topic row of the report must say ok (the exit code covers structural errors).
    if report="$("${rerun}" mcap check --full "${logs}/${n}.mcap" 2>&1)" &&
        ! awk '/^─/{t=1; next} t && NF && $1 != "ok"' <<<"${report}" | grep -q .; then
        printf '  %-28s mcap check ok (%s topics)\n' "$n" "$(awk '/^─/{t=1; next} t && NF' <<<"${report}" | wc -l)"
    else
        echo "${report}"; fail "rerun mcap check ${n}"
    fi
done
done_phase "logs + rerun mcap check"

# --- 3. conversion, rrd verify, checks -------------------------------------------------------
phase "convert + verify + check"
for n in "${names[@]}"; do
    [[ -f "${logs}/${n}.mcap" ]] || continue
    extra=()
    # The flagship's recording is the one shot: start with the time cursor at the end.
    [[ "$n" == "${flagship}" || "$n" == "${orbit_flagship}" || -n "${actuators}" ]] && extra=(--play-state following)
    if ! "${py}" "${here}/mcap_to_rrd.py" "${logs}/${n}.mcap" -o "${logs}/${n}.rrd" "${extra[@]}"; then
        fail "convert ${n}"; continue
    fi
    "${rerun}" rrd verify "${logs}/${n}.rrd" >/dev/null 2>&1 || fail "rerun rrd verify ${n}"
    if ! "${py}" "${here}/check.py" "${logs}/${n}.mcap" --rrd "${logs}/${n}.rrd" \
        --fields "${repo}/src/log/telemetry.rs" > "${logs}/${n}.check.txt"; then
        cat "${logs}/${n}.check.txt"; fail "check.py ${n}"
    else
        tail -n 1 "${logs}/${n}.check.txt"
    fi
done
[[ -f "${logs}/${flagship}.check.txt" ]] && sed -n '1,200p' "${logs}/${flagship}.check.txt" | grep -v '^check:' || true
done_phase "convert + verify + check"

# Rerun's own CLI, without the Python SDK: the raw MCAP converted by Rerun has /tf as
# Transform3D and the telemetry as a decoded message; ours has Transform3D and Scalars.
if [[ -z "${actuators}" ]]; then
phase "rerun rrd print"
flag="${logs}/${flagship}"
"${rerun}" mcap convert "${flag}.mcap" -o "${flag}.raw.rrd" >/dev/null 2>&1 || fail "rerun mcap convert"
raw_print="$("${rerun}" rrd print "${flag}.raw.rrd" 2>/dev/null || true)"
grep -q ' - /tf - data columns: \[Transform3D:' <<<"${raw_print}" && echo "  raw MCAP: /tf -> Transform3D" ||
    fail "raw MCAP: /tf is not Transform3D"
grep -q ' - /telemetry - data columns: \[polhode.Telemetry:message\]' <<<"${raw_print}" &&
    echo "  raw MCAP: /telemetry -> polhode.Telemetry:message (struct)" || fail "raw MCAP: /telemetry not decoded"
conv_print="$("${rerun}" rrd print "${flag}.rrd" 2>/dev/null || true)"
grep -q ' - /world/body - data columns: \[Transform3D:' <<<"${conv_print}" &&
    echo "  converted: /world/body -> Transform3D" || fail "converted: no Transform3D at /world/body"
n_fields=$(sed -n '/pub const FIELDS/,/];/p' "${repo}/src/log/telemetry.rs" | grep -c '^ *"' || true)
# Entities may be split over several chunks: count distinct ones.
n_series=$( (grep -o ' - /telemetry/[a-z0-9_]* - data columns: \[Scalars:scalars' <<<"${conv_print}" || true) | sort -u | wc -l)
[[ "${n_fields}" -gt 0 && "${n_series}" -eq "${n_fields}" ]] && echo "  converted: ${n_series} /telemetry Scalars series = ${n_fields} FIELDS" ||
    fail "converted: ${n_series} /telemetry series for ${n_fields} FIELDS"
rm -f "${flag}.raw.rrd"
done_phase "rerun rrd print"
fi

# --- 4. headless screenshots ----------------------------------------------------------------
phase "screenshot"
if [[ -n "${actuators}" ]]; then
    mkdir -p "${out_dir}"
else
    mkdir -p "$(dirname "${out}")" "$(dirname "${out_orbit}")"
fi
xdg="$(mktemp -d)"; chmod 700 "${xdg}"
# shoot NAME OUT [check.py options]: the recording NAME.rrd on screen, checked, written to OUT.
shoot() {
    local name="$1" dest="$2"; shift 2
    local rec="${logs}/${name}" shot="${logs}/${name}.screenshot.png" ok="" attempt
    local attempts=(1 2)
    [[ -s "${rec}.rrd" ]] || { echo "no ${rec}.rrd to show"; attempts=(); }
    for attempt in "${attempts[@]}"; do
        rm -f "${shot}"
        # --new: a viewer of its own even if one already listens on the default port.
        # RUST_LOG=error: no notification toasts over the views.
        if XDG_RUNTIME_DIR="${xdg}" RUST_LOG=error timeout 300 xvfb-run -a -s "-screen 0 ${xvfb_screen}" \
            "${rerun}" "${rec}.rrd" --new --bind 127.0.0.1 --renderer vulkan \
            --window-size 1600x1000 --screenshot-to "${shot}" > "${logs}/screenshot.log" 2>&1 &&
            [[ -s "${shot}" ]]; then
            # The viewer renders at 2 pixels per point: scale to 1600 px wide, and write the
            # destination only once the image passes.
            local small="${logs}/${name}.screenshot.small.png"
            "${py}" -c 'import sys; from PIL import Image; im = Image.open(sys.argv[1]).convert("RGB")
if im.width > 1600: im = im.resize((1600, round(im.height * 1600 / im.width)), Image.LANCZOS)
im.save(sys.argv[2], optimize=True)' \
                "${shot}" "${small}"
            if "${py}" "${here}/check.py" "${rec}.mcap" --no-raw --png "${small}" "$@" > "${logs}/${name}.screenshot.check.txt"; then
                if ((max_png)) && (($(stat -c %s "${small}") > max_png)); then
                    # Checked in full colour; written with 256 colours to stay under max_png.
                    "${py}" -c 'import sys; from PIL import Image
Image.open(sys.argv[1]).quantize(256).save(sys.argv[2], format="PNG", optimize=True)' \
                        "${small}" "${dest}.tmp"
                    echo "  $(stat -c %s "${small}") bytes > ${max_png}: written with 256 colours"
                else
                    cp "${small}" "${dest}.tmp"
                fi
                mv "${dest}.tmp" "${dest}"
                ok=1; break
            fi
            cat "${logs}/${name}.screenshot.check.txt"
        else
            tail -n 20 "${logs}/screenshot.log"
        fi
        echo "screenshot ${name} attempt ${attempt} failed"
    done
    if [[ -n "${ok}" ]]; then
        grep -v '^check:' "${logs}/${name}.screenshot.check.txt"
        echo "  wrote ${dest} ($(stat -c %s "${dest}") bytes)"
    else
        fail "screenshot ${name}"
    fi
}
if [[ -n "${actuators}" ]]; then
    shoot rwa-rate-damping "${out_dir}/rerun-rwa-rate-damping.png" --effectors 1000 --omega-decays 0.1
    shoot cubesat-detumble "${out_dir}/rerun-cubesat-detumble.png" --orbit --omega-decays 0.1
else
    shoot "${flagship}" "${out}"
    shoot "${orbit_flagship}" "${out_orbit}" --orbit
fi
rm -rf "${xdg}"
done_phase "screenshot"

# --- summary ---------------------------------------------------------------------------------
echo "== timings"
printf '  %s\n' "${timings[@]}"
printf '  %-28s %s\n' "total" "$(seconds "${t_start}")"
if ((${#failed[@]})); then
    echo "FAIL (${#failed[@]}):"
    printf '  %s\n' "${failed[@]}"
    exit 1
fi
if [[ -n "${actuators}" ]]; then
    echo "PASS (actuators): ${names[*]} logged, checked by Rerun, converted and verified; screenshots" \
        "${out_dir}/rerun-rwa-rate-damping.png, ${out_dir}/rerun-cubesat-detumble.png"
else
    echo "PASS: ${#names[@]} scenarios logged, checked by Rerun, converted and verified; screenshots ${out}, ${out_orbit}"
fi
