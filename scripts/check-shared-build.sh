#!/usr/bin/env bash
# Checks that the main job's build (`cargo run --release`, the polhode package alone) and the
# Python wheel's build (`pip install ./python`, the polhode-python package) resolve every
# dependency they share with the same features. Then the wheel reuses the main job's compiled
# library instead of compiling it again (docs/python.md, "Build time").
#
#   scripts/check-shared-build.sh
#
# Cargo unifies features over the packages a command selects, so a feature that only the
# Python crate's dependencies turn on (pyo3's proc-macros want more of syn, numpy more of
# matrixmultiply) changes the hash of everything above it. polhode's Cargo.toml asks for
# those features itself; this check fails, naming the package, when a dependency update adds
# another one.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

features_of() {
    # One line per package and build kind: "name@version features", without the feature
    # nodes themselves; the main job's view excludes dev-dependencies, as `cargo run` does.
    cargo tree --locked -e normal,build,features -p "$1" --prefix none -f '{p} {f}' \
        | grep -v ' feature "' | awk '{print $1 "@" $2, $3}' | sort -u
}

main_job=$(mktemp)
wheel=$(mktemp)
trap 'rm -f "$main_job" "$wheel"' EXIT
features_of polhode >"$main_job"
features_of polhode-python >"$wheel"

# Packages in both builds whose sets of feature lists differ.
mismatched=$(join <(cut -d' ' -f1 "$main_job" | sort -u) <(cut -d' ' -f1 "$wheel" | sort -u) |
    while read -r package; do
        if ! diff -q <(grep "^$package " "$main_job") <(grep "^$package " "$wheel") >/dev/null; then
            echo "  $package: main job [$(grep "^$package " "$main_job" | cut -d' ' -f2 | paste -sd'|')]" \
                "wheel [$(grep "^$package " "$wheel" | cut -d' ' -f2 | paste -sd'|')]"
        fi
    done)
if [[ -n "$mismatched" ]]; then
    echo "check-shared-build: the main job and the Python wheel resolve shared dependencies" \
        "with different features, so \`pip install ./python\` would compile polhode again:" >&2
    echo "$mismatched" >&2
    echo "Ask for the wheel's features in polhode's Cargo.toml (see its comment there)." >&2
    exit 1
fi
echo "check-shared-build: the main job and the Python wheel share every dependency build"
