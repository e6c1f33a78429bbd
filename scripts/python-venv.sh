#!/usr/bin/env bash
# Create (or reuse) the Python virtualenv used by the independent MCAP test reader.
#
#   scripts/python-venv.sh        # from any working directory
#
# - creates <repo>/.venv with `python3 -m venv` if it does not exist yet;
# - installs tests/python/requirements.txt into it;
# - skips the install when <repo>/.venv/.requirements.sha256 already holds the
#   sha256 of requirements.txt (so running it again is cheap and idempotent).
# Prints one line saying what it did. Set PYTHON to use another interpreter.
set -euo pipefail

script_dir="$(cd -- "$(dirname -- "${BASH_SOURCE[0]}")" && pwd)"
repo_root="$(cd -- "${script_dir}/.." && pwd)"
venv="${repo_root}/.venv"
requirements="${repo_root}/tests/python/requirements.txt"
stamp="${venv}/.requirements.sha256"
python="${PYTHON:-python3}"

if [[ ! -f "${requirements}" ]]; then
    echo "python-venv: missing ${requirements}" >&2
    exit 1
fi

want="$(sha256sum "${requirements}" | cut -d' ' -f1)"

created=""
if [[ ! -x "${venv}/bin/python" ]]; then
    "${python}" -m venv "${venv}"
    created="created ${venv} and "
fi

if [[ -f "${stamp}" && "$(cat "${stamp}")" == "${want}" ]]; then
    echo "python-venv: ${venv} is up to date (requirements ${want:0:12}), nothing to do"
    exit 0
fi

# A failed install leaves no stamp, so the next run retries.
rm -f "${stamp}"
"${venv}/bin/python" -m pip install --quiet --disable-pip-version-check \
    --requirement "${requirements}"
printf '%s\n' "${want}" > "${stamp}"
echo "python-venv: ${created}installed ${requirements#"${repo_root}"/} into ${venv} (requirements ${want:0:12})"
