"""The example notebook python/examples/first-day.ipynb, executed as Jupyter would execute it
(nbclient, a python3 kernel from this venv, matplotlib on Agg), so that it cannot rot."""

import os
import sys
import time

import pytest

from conftest import REPO

NOTEBOOK = REPO / "python/examples/first-day.ipynb"

# Appended to the executed copy only: what the notebook left behind, as one JSON line.
CHECK = """
import json, sys
print(json.dumps({
    "prefix": sys.prefix,
    "backend": __import__("matplotlib").get_backend(),
    "figure": type(fig).__name__,
    "axes": len(fig.axes),
    "status": result.status,
    "columns": list(frame.columns[:2]),
    "campaign_runs": campaign.runs,
    "table_rows": len(runs),
}))
"""


def test_the_committed_notebook_has_no_outputs():
    nbformat = pytest.importorskip("nbformat")
    nb = nbformat.read(NOTEBOOK, as_version=4)
    nbformat.validate(nb)
    for cell in nb.cells:
        if cell.cell_type == "code":
            assert cell.outputs == [] and cell.execution_count is None, cell.source[:40]


def test_the_example_notebook_runs(monkeypatch):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    pytest.importorskip("ipykernel")
    import json

    # The kernel spec of this venv's ipykernel before any in the user's own Jupyter folders.
    monkeypatch.setenv("JUPYTER_PREFER_ENV_PATH", "1")
    nb = nbformat.read(NOTEBOOK, as_version=4)
    nb.cells.append(nbformat.v4.new_code_cell(CHECK))
    client = nbclient.NotebookClient(
        nb,
        kernel_name="python3",
        timeout=120,
        resources={"metadata": {"path": str(NOTEBOOK.parent)}},
    )
    start = time.perf_counter()
    client.execute()  # CellExecutionError on any cell's exception
    seconds = time.perf_counter() - start
    print(f"first-day.ipynb executed in {seconds:.1f} s")

    code = [c for c in nb.cells if c.cell_type == "code"]
    last = [o for o in code[-1].outputs if o.output_type == "stream"]
    state = json.loads(last[0].text)
    assert state["prefix"] == sys.prefix  # the kernel ran in this venv
    assert state["backend"].lower() == "agg"
    assert state["figure"] == "Figure" and state["axes"] == 4
    assert state["status"] == "complete"
    assert state["columns"] == ["sim_time [s]", "omega_x [rad/s]"]
    assert state["campaign_runs"] == 50 and state["table_rows"] == 50

    def html(cell):
        return "".join(
            o.data.get("text/html", "") for o in cell.outputs if o.output_type == "execute_result"
        )

    assert "polhode Scenario" in html(code[0]) and "explorer1-energy-sink" in html(code[0])
    assert "polhode Result" in html(code[1]) and "complete" in html(code[1])
    assert "nutation_angle_deg [deg]" in html(code[2])  # the DataFrame's table
    assert "<table" in html(code[4])  # the campaign's describe()
    assert os.environ["MPLBACKEND"] == "Agg"
