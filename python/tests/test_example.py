"""The example script python/examples/explorer1.py, run as a user would, into a scratch dir."""

import subprocess
import sys

import pytest

from conftest import REPO

SCRIPT = REPO / "python/examples/explorer1.py"


def test_the_explorer1_example_draws_its_two_plots(tmp_path):
    pytest.importorskip("matplotlib")
    pytest.importorskip("pyarrow")
    import matplotlib.image

    out = tmp_path / "plots"
    done = subprocess.run(
        [sys.executable, str(SCRIPT), str(out)], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert "72001 samples" in lines[0]  # 4 h at 5 samples per second, both ends
    assert "200 runs" in lines[1]
    for name in ["explorer1_nutation.png", "campaign_flat_spin_time.png"]:
        png = out / name
        assert png.is_file(), name
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name
        image = matplotlib.image.imread(png)
        assert image.shape[:2] == (450, 800), name  # 8 x 4.5 in at 100 dpi
        # Not a blank canvas: a good share of the pixels differ from the background.
        background = image[0, 0]
        drawn = (abs(image - background).sum(axis=2) > 0.1).mean()
        assert drawn > 0.02, f"{name}: only {drawn:.3%} of the pixels are drawn"
