#!/usr/bin/env bash
# Builds and runs the cargo-fuzz targets of fuzz/ (fuzz/README.md) for a while each, on the
# stable toolchain that rust-toolchain.toml pins (1.97.1).
#
#   scripts/fuzz.sh [SECONDS_PER_TARGET]        (default 30)
#
# Installs cargo-fuzz from crates.io if it is missing. The targets run side by side, one per
# core (in turn on one core), each with libFuzzer's -max_total_time=SECONDS, -rss_limit_mb=2048
# and -timeout=10 (30 for scenario_loader, see run_target), from the corpus in
# fuzz/corpus/TARGET (kept between runs, not committed),
# seeded with scenarios/*.yaml and tests/data/*.yaml. Exits non-zero if a target finds a crash,
# a hang or an out-of-memory input, printing the input's path and how to reproduce it.
#
# No nightly is needed: without a sanitizer cargo-fuzz passes rustc no -Z flag, so the targets
# build on plain stable; with FUZZ_SANITIZER=address the script sets RUSTC_BOOTSTRAP=1, with
# which stable rustc accepts -Zsanitizer=address. Settings (environment):
#   FUZZ_SANITIZER=none|address   default none: polhode has no unsafe code, and without ASan
#                                 the build is faster and the fuzzer faster
#   FUZZ_KEEP_GOING=1             keep fuzzing past a finding (-fork=1 -ignore_crashes=1 ...),
#                                 for long local runs; every finding is still saved and reported
#   FUZZ_JOBS=N                   targets run at once (default: 2 if there are 2 cores or more)
#   FUZZ_TOOLCHAIN=NAME           rustup toolchain (default: the one rust-toolchain.toml pins)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
root=$(pwd)
fuzz_dir="$root/fuzz"

CARGO_FUZZ_VERSION=0.13.2
TARGETS=(scenario_loader writers method_pairs)

seconds=${1:-30}
if ! [[ $seconds =~ ^[0-9]+$ ]] || ((seconds < 1)); then
    echo "usage: scripts/fuzz.sh [SECONDS_PER_TARGET]  (a whole number of seconds, at least 1)" >&2
    exit 2
fi
sanitizer=${FUZZ_SANITIZER:-none}
case $sanitizer in
none | address) ;;
*)
    echo "FUZZ_SANITIZER must be none or address, not $sanitizer" >&2
    exit 2
    ;;
esac
if [[ -n ${FUZZ_JOBS:-} ]]; then
    jobs=$FUZZ_JOBS
elif (($(nproc) >= 2)); then
    jobs=2
else
    jobs=1
fi

toolchain=()
if [[ -n ${FUZZ_TOOLCHAIN:-} ]]; then
    toolchain=("+$FUZZ_TOOLCHAIN")
fi
cargo_() { cargo "${toolchain[@]}" "$@"; }

if ! cargo_ fuzz --version 2>/dev/null | grep -qF "$CARGO_FUZZ_VERSION"; then
    echo "== installing cargo-fuzz $CARGO_FUZZ_VERSION from crates.io"
    cargo_ install cargo-fuzz --version "$CARGO_FUZZ_VERSION" --locked
fi

# cargo-fuzz passes no -Z flag without a sanitizer, so `none` builds on plain stable; ASan
# needs -Zsanitizer=address, which stable rustc accepts with RUSTC_BOOTSTRAP=1 (its runtime
# ships with the stable toolchain). Set only then: it makes build scripts that probe for
# nightly features see a nightly compiler.
bootstrap=()
if [[ $sanitizer == address ]]; then
    export RUSTC_BOOTSTRAP=1
    bootstrap=(RUSTC_BOOTSTRAP=1)
fi
# The same flags for build, reproduction and minimisation, so that nothing is rebuilt in
# between: release with debug assertions and overflow checks, and 16 codegen units instead of
# cargo-fuzz's default of 1, so that both cores compile the large polhode crate (the last one
# built, alone), for a fuzzer about 20% slower. Changing a flag or the sanitizer rebuilds all.
flags=(--sanitizer "$sanitizer" --debug-assertions --codegen-units 16)
cargo_fuzz="${bootstrap[*]}${bootstrap:+ }cargo ${toolchain[*]}${toolchain:+ }fuzz"
repro="$cargo_fuzz run ${flags[*]}"

echo "== building the fuzz targets ($(cargo_ --version), sanitizer $sanitizer)"
build_start=$(date +%s)
(cd "$fuzz_dir" && cargo_ fuzz build "${flags[@]}")
echo "build: $(($(date +%s) - build_start)) s"
host=$(rustc "${toolchain[@]}" -vV | sed -n 's/^host: //p')
bin_dir="$fuzz_dir/target/$host/release"

# Seeds: the shipped scenarios for the loader; a few random inputs of several sizes for the
# structured writers target (any bytes make a valid input; they give it long inputs to start).
mkdir -p "$fuzz_dir/corpus/scenario_loader" "$fuzz_dir/corpus/writers" "$fuzz_dir/corpus/method_pairs"
cp "$root"/scenarios/*.yaml "$root"/tests/data/*.yaml "$fuzz_dir/corpus/scenario_loader/"
for size in 256 1024 4096 8192; do
    for k in 1 2 3; do
        seed="$fuzz_dir/corpus/writers/seed-$size-$k"
        [[ -e $seed ]] || head -c "$size" /dev/urandom >"$seed"
    done
done
# method_pairs builds its scenario from structured input: any bytes make one.
for size in 32 64 128 256; do
    for k in 1 2 3; do
        seed="$fuzz_dir/corpus/method_pairs/seed-$size-$k"
        [[ -e $seed ]] || head -c "$size" /dev/urandom >"$seed"
    done
done

# Scratch space of the targets (they write scenario files, logs and tables there).
if [[ -d /dev/shm && -w /dev/shm ]]; then
    scratch=$(mktemp -d /dev/shm/polhode-fuzz.XXXXXX)
else
    scratch=$(mktemp -d)
fi
trap 'rm -rf "$scratch"' EXIT
export POLHODE_FUZZ_TMP="$scratch"

run_target() {
    local target=$1 log=$2
    local extra=()
    # Per-input time limit (s), a hang detector. The loader's is longer: in this build (debug
    # assertions) loading scenarios/liquid-stage-burn.yaml, whose draining tanks fit their fill
    # curves from 24 slosh-analog solutions each, takes about 13 s (0.8 s in release).
    local timeout=10
    if [[ $target == scenario_loader ]]; then
        timeout=30
    fi
    if [[ $target == writers ]]; then
        # Structured input: long inputs from the start (a logged sample alone is ~200 bytes).
        extra=(-max_len=8192 -len_control=0)
    fi
    if [[ -f $fuzz_dir/dictionaries/$target.dict ]]; then
        extra+=(-dict="dictionaries/$target.dict")
    fi
    if [[ -n ${FUZZ_KEEP_GOING:-} ]]; then
        extra+=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1)
    fi
    # The binary cargo fuzz built, run as `cargo fuzz run` would (which would first check the
    # build again, and rebuild if the sources changed meanwhile).
    (cd "$fuzz_dir" && "$bin_dir/$target" -artifact_prefix="artifacts/$target/" \
        -max_total_time="$seconds" -rss_limit_mb=2048 -timeout="$timeout" -print_final_stats=1 \
        "${extra[@]}" "corpus/$target") >"$log" 2>&1
}

mkdir -p "$fuzz_dir/artifacts"
for target in "${TARGETS[@]}"; do mkdir -p "$fuzz_dir/artifacts/$target"; done
stamp="$fuzz_dir/artifacts/.run-start"
touch "$stamp"
echo "== fuzzing ${TARGETS[*]} for $seconds s each, $jobs at a time (logs in fuzz/artifacts/)"
run_start=$(date +%s)
declare -A status
pids=()
for target in "${TARGETS[@]}"; do
    log="$fuzz_dir/artifacts/$target.log"
    if ((jobs > 1)); then
        run_target "$target" "$log" &
        pids+=("$target:$!")
        while (($(jobs -rp | wc -l) >= jobs)); do sleep 1; done
    else
        if run_target "$target" "$log"; then status[$target]=0; else status[$target]=$?; fi
    fi
done
for entry in "${pids[@]}"; do
    if wait "${entry#*:}"; then status[${entry%%:*}]=0; else status[${entry%%:*}]=$?; fi
done
echo "fuzzing: $(($(date +%s) - run_start)) s"

failed=0
for target in "${TARGETS[@]}"; do
    log="$fuzz_dir/artifacts/$target.log"
    last=$(grep -E '^#[0-9]+' "$log" | tail -n 1 || true)
    rate=$(grep -oE 'stat::average_exec_per_sec: *[0-9]+' "$log" | tail -n 1 | grep -oE '[0-9]+$' || true)
    [[ ${rate:-0} == 0 ]] && rate=
    echo "$target: ${last:-no libFuzzer status line}${rate:+ (average $rate exec/s)}"
    mapfile -t found < <(find "$fuzz_dir/artifacts/$target" -maxdepth 1 -type f \
        \( -name 'crash-*' -o -name 'timeout-*' -o -name 'oom-*' -o -name 'leak-*' \) \
        -newer "$stamp" 2>/dev/null | sort)
    if ((${status[$target]} != 0 || ${#found[@]} > 0)); then
        failed=1
        echo "  FAILED (exit status ${status[$target]}); the end of $log:" >&2
        grep -E -A3 'panicked at|^==[0-9]+== ERROR|libFuzzer: (timeout|out-of-memory)' "$log" |
            grep -vE '^\s+[0-9]+: |^stack backtrace' | head -n 12 | sed 's/^/    /' >&2 || true
        for a in "${found[@]}"; do
            echo "  input: $a" >&2
            echo "  reproduce: (cd fuzz && $repro $target ${a#"$fuzz_dir/"})" >&2
            echo "  minimise:  (cd fuzz && $cargo_fuzz tmin ${flags[*]} $target ${a#"$fuzz_dir/"})" >&2
            if [[ $target == writers ]]; then
                echo "  show it:   (cd fuzz && $cargo_fuzz fmt ${flags[*]} $target ${a#"$fuzz_dir/"})" >&2
            fi
        done
    fi
done
rm -f "$stamp"
exit "$failed"
