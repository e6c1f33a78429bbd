"""What a notebook shows: Result.plot (matplotlib, Agg here), and the HTML summaries of a
Result and a Scenario, checked against the CLI's own summary of the same run."""

import html.parser
import io
import subprocess
import sys

import numpy as np
import pytest

import polhode
from conftest import REPO

RACKET = REPO / "scenarios/tennis-racket.yaml"


class Cells(html.parser.HTMLParser):
    """The (th, td) rows of every table in an HTML fragment, and all its text."""

    def __init__(self):
        super().__init__()
        self.rows, self.text, self._cell, self._row = [], [], None, []

    def handle_starttag(self, tag, attrs):
        if tag in ("th", "td"):
            self._cell = ""
        elif tag == "tr":
            self._row = []

    def handle_endtag(self, tag):
        if tag in ("th", "td"):
            self._row.append(self._cell)
            self._cell = None
        elif tag == "tr":
            self.rows.append(tuple(self._row))

    def handle_data(self, data):
        self.text.append(data)
        if self._cell is not None:
            self._cell += data


def parse(fragment):
    cells = Cells()
    cells.feed(fragment)
    return cells


def test_result_html_summary_says_what_the_cli_summary_says(cli_summary):
    expected = cli_summary("scenarios/tennis-racket.yaml")
    result = polhode.load(RACKET).run()
    cells = parse(result._repr_html_())
    rows = dict(r for r in cells.rows if len(r) == 2)
    assert rows["scenario"] == "tennis-racket"
    assert rows["status"] == "complete"
    assert rows["method"] == "dopri5 (rtol 1e-10, atol 1e-12)"
    assert rows["duration"] == "10 s of sim time"
    assert rows["samples"] == "1001"
    assert rows["steps"] == str(expected["steps"])
    assert rows["rejected steps"] == str(expected["rejected_steps"])
    assert rows["right-hand-side evaluations"] == str(expected["rhs_evaluations"])
    # Drifts to four significant digits.
    for label, key in [("|H| (relative)", "h_norm_rel"), ("energy (relative)", "energy_rel")]:
        shown = float(rows[label])
        assert shown == pytest.approx(expected["drift"][key], rel=1e-3), label
    # Both flips, at the CLI's times to six significant digits.
    event_rows = [r for r in cells.rows if r[1] == "nutation_angle_deg above 90"]
    assert len(event_rows) == 2
    for row, event in zip(event_rows, expected["events"]):
        assert float(row[0].removesuffix(" s")) == pytest.approx(event["t"], rel=1e-5)


def test_result_html_lists_twenty_events_and_counts_the_rest():
    result = polhode.load(RACKET).run(duration=200.0)
    assert len(result.events) > 30  # a flip every 4.6 s
    rows = parse(result._repr_html_()).rows
    assert sum(r[1] == "nutation_angle_deg above 90" for r in rows) == 20
    assert ("…", f"{len(result.events) - 20} more") in rows


def test_scenario_html_escapes_what_it_shows():
    text = RACKET.read_text().replace("name: tennis-racket", 'name: "<script>x</script>"')
    scenario = polhode.loads(text)
    fragment = scenario._repr_html_()
    assert "<script>" not in fragment
    rows = dict(r for r in parse(fragment).rows if len(r) == 2)
    assert rows == {
        "name": "<script>x</script>",
        "file": "<string>",
        "method": "dopri5",
        "duration": "10 s",
    }


def test_plot_draws_the_usual_series_against_time():
    pytest.importorskip("matplotlib")
    import matplotlib
    import matplotlib.figure
    import matplotlib.pyplot as plt

    assert matplotlib.get_backend().lower() == "agg"  # conftest: no window in tests
    result = polhode.load(REPO / "scenarios/nutation-damper.yaml").run(duration=20.0)
    fig = result.plot()
    try:
        assert isinstance(fig, matplotlib.figure.Figure)
        rates, nutation, energy, drift = fig.axes
        lines = [line for line in rates.lines if line.get_label().startswith("ω")]
        assert len(lines) == 3
        for k, line in enumerate(lines):
            assert np.array_equal(line.get_xdata(), result.t)
            assert np.array_equal(line.get_ydata(), result.omega[:, k])
        assert np.array_equal(nutation.lines[0].get_ydata(), result.telemetry["nutation_angle_deg"])
        by_label = {line.get_label(): line for line in energy.lines}
        assert np.array_equal(by_label["kinetic T"].get_ydata(), result.telemetry["kinetic_energy"])
        assert np.array_equal(
            by_label["dissipated"].get_ydata(), result.telemetry["dissipated_energy"]
        )
        assert np.array_equal(drift.lines[0].get_ydata(), result.telemetry["drift_h_rel"])
        assert rates.get_ylabel() == "body rate (rad/s)"
        assert nutation.get_ylabel() == "nutation angle (deg)"
        assert energy.get_ylabel() == "energy (J)"
        assert drift.get_xlabel() == "sim time (s)"
        # The damper dissipates: the drawn curve rises from zero.
        assert result.telemetry["dissipated_energy"][-1] > 0.0
        png = io.BytesIO()
        fig.savefig(png, format="png", dpi=50)
        assert png.getvalue()[:8] == b"\x89PNG\r\n\x1a\n"
    finally:
        plt.close(fig)


def test_plot_marks_the_events():
    pytest.importorskip("matplotlib")
    import matplotlib.pyplot as plt

    result = polhode.load(RACKET).run()
    fig = result.plot(figsize=(6, 6))
    try:
        assert tuple(fig.get_size_inches()) == (6.0, 6.0)
        marks = [line for line in fig.axes[1].lines if line.get_linestyle() == "--"]
        assert [m.get_xdata()[0] for m in marks] == [e["t"] for e in result.events]
    finally:
        plt.close(fig)
    with pytest.raises(TypeError, match=r"^Result\.plot\(\): figsize must be a \(width, height\)"):
        result.plot(figsize="big")


def test_plot_without_matplotlib_says_what_to_install():
    script = (
        "import sys\n"
        "sys.modules['matplotlib'] = None\n"
        "import polhode\n"
        f"r = polhode.load({str(RACKET)!r}).run(duration=0.1)\n"
        "try:\n"
        "    r.plot()\n"
        "except ImportError as e:\n"
        "    print(e)\n"
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True)
    assert "Result.plot() needs matplotlib" in out.stdout
    assert 'pip install "./python[all]"' in out.stdout
