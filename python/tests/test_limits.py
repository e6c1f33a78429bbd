"""Run arguments refused before anything is integrated, and a run too large for memory refused
with the numbers instead of aborting the interpreter (docs/cli.md, docs/reliability.md)."""

import os
import subprocess
import sys

import pytest

import polhode
from conftest import REPO


def test_a_boolean_duration_is_refused():
    # Before: run(duration=True) ran for 1 s (from_dict refused True).
    s = polhode.load(REPO / "scenarios/tennis-racket.yaml")
    with pytest.raises(TypeError):
        s.run(duration=True)


def test_an_empty_log_name_is_refused_before_the_run(tmp_path):
    # Before: run(log="") integrated the whole run and only then failed.
    s = polhode.load(REPO / "scenarios/tennis-racket.yaml")
    with pytest.raises(ValueError):
        s.run(duration=1e6, log="")


def test_a_run_past_the_memory_limit_raises_memory_error_in_a_live_interpreter():
    # Before: 4.9e7 samples passed validation and the interpreter aborted (exit 134). Run in a
    # child with a 1 MB limit, so that the refusal, not the allocator, is what is tested.
    code = (
        "import polhode, sys\n"
        f"s = polhode.load({str(REPO / 'scenarios/tennis-racket.yaml')!r})\n"
        "try:\n"
        "    s.run(duration=1e5)\n"
        "except MemoryError as e:\n"
        "    print('refused:', e)\n"
        "    sys.exit(0)\n"
        "sys.exit(1)\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code],
        env={**os.environ, "POLHODE_MAX_MEMORY_MB": "1"},
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stdout + out.stderr
    assert "refused:" in out.stdout
