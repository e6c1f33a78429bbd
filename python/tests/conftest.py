"""Shared fixtures: the repository, and the `polhode` CLI as the independent path."""

import json
import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]

# Matplotlib draws without a window in the tests, and in the kernels they start (the example
# notebook's), which inherit this environment.
os.environ["MPLBACKEND"] = "Agg"


@pytest.fixture(scope="session")
def polhode_cli():
    """Path of the release `polhode` binary ($POLHODE_BIN, or built here with cargo)."""
    given = os.environ.get("POLHODE_BIN")
    if given:
        return Path(given)
    subprocess.run(
        ["cargo", "build", "--release", "--locked", "--quiet", "--bin", "polhode"],
        cwd=REPO,
        check=True,
    )
    target = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    return target / "release" / "polhode"


@pytest.fixture
def cli_summary(polhode_cli, tmp_path):
    """Runs `polhode run FILE --summary ... --no-log` with extra options; returns the summary."""

    def run(scenario, *options):
        out = tmp_path / "cli-summary.json"
        subprocess.run(
            [str(polhode_cli), "run", str(REPO / scenario), "--no-log", "--quiet", "--summary", str(out)]
            + list(options),
            check=True,
            cwd=REPO,
        )
        return json.loads(out.read_text())

    return run
