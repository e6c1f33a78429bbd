"""A notebook's views of a run: ``Result.to_pandas``, ``Result.plot`` and the HTML summaries
Jupyter shows for a ``Result`` and a ``Scenario`` (their ``_repr_html_``).

The extension's classes call these functions (``python/src/result.rs``, ``py_scenario.rs``).
pandas and matplotlib are optional: imported here, on first use, with an ``ImportError``
saying what to install when missing.
"""

import html

from ._args import optional_import, type_error

__all__ = ["column_name", "plot", "result_html", "scenario_html", "to_pandas"]

# Events listed in a Result's HTML summary at most (the rest are counted).
_EVENTS_SHOWN = 20

# The summary's work counters, in the order shown, and how each is called there.
_WORK = [
    ("steps", "steps"),
    ("rejected_steps", "rejected steps"),
    ("rhs_evaluations", "right-hand-side evaluations"),
    ("newton_iterations", "Newton iterations"),
    ("jacobian_evaluations", "Jacobian evaluations"),
    ("factorizations", "factorizations"),
]

# The summary's drift entries (relative, dimensionless), and what each measures.
_DRIFT = [
    ("h_norm_rel", "|H| (relative)"),
    ("h_inertial_rel", "H inertial (relative)"),
    ("energy_rel", "energy (relative)"),
    ("q_norm", "quaternion norm error"),
]


def column_name(name, unit):
    """A column's name as the ``polhode run --csv`` header writes it: ``omega_x [rad/s]``, or
    the bare name when it has no unit."""
    return f"{name} [{unit}]" if unit else name


def to_pandas(result, units=None):
    """``Result.to_pandas(units=True)``: a DataFrame, one column per ``telemetry`` column in
    its order (so any series the run records joins it), one row per sample; the columns are
    named as the CSV header names them, or by their bare names with ``units=False``."""
    if units is None:
        units = True
    if not isinstance(units, bool):
        raise type_error("Result.to_pandas", "units", "True or False (bool)", units)
    pandas = optional_import("pandas", "Result.to_pandas()")
    unit_of = result.units
    columns = {
        (column_name(name, unit_of.get(name, "")) if units else name): values.copy()
        for name, values in result.telemetry.items()
    }
    return pandas.DataFrame(columns)


def _label(result, name, text):
    unit = result.units.get(name, "")
    return f"{text} ({unit})" if unit else text


def plot(result, figsize=None):
    """``Result.plot()``: four panels against sim time, the events as dashed lines; returns
    the matplotlib Figure (made with pyplot, so Jupyter shows it below the cell)."""
    if figsize is not None:
        try:
            width, height = (float(v) for v in figsize)
        except (TypeError, ValueError):
            raise type_error(
                "Result.plot", "figsize", "a (width, height) pair in inches", figsize
            ) from None
        figsize = (width, height)
    optional_import("matplotlib", "Result.plot()")
    pyplot = optional_import("matplotlib.pyplot", "Result.plot()")
    series = result.telemetry
    t = result.t
    fig, axes = pyplot.subplots(
        4, 1, sharex=True, figsize=figsize or (8.0, 9.0), layout="constrained"
    )
    rates, nutation, energy, drift = axes

    for k, axis in enumerate("xyz"):
        rates.plot(t, result.omega[:, k], lw=1.0, label=f"ω_{axis}")
    rates.set_ylabel(_label(result, "omega_x", "body rate"))
    rates.legend(loc="upper right", fontsize=8)

    nutation.plot(t, series["nutation_angle_deg"], lw=1.0, color="tab:purple")
    nutation.set_ylabel(_label(result, "nutation_angle_deg", "nutation angle"))

    energy.plot(t, series["kinetic_energy"], lw=1.0, label="kinetic T")
    if series["elastic_energy"].any():
        energy.plot(t, series["elastic_energy"], lw=1.0, label="elastic")
    energy.plot(t, series["dissipated_energy"], lw=1.0, label="dissipated")
    energy.set_ylabel(_label(result, "kinetic_energy", "energy"))
    energy.legend(loc="upper right", fontsize=8)

    drift.plot(t, series["drift_h_rel"], lw=1.0, color="tab:gray")
    drift.set_ylabel("|H| drift (relative)")
    drift.set_xlabel(_label(result, "sim_time", "sim time"))

    for axes_ in axes:
        axes_.grid(alpha=0.3)
        for event in result.events:
            axes_.axvline(event["t"], color="tab:red", lw=0.8, ls="--")
    summary = result.summary
    fig.suptitle(f"{summary['scenario']} ({summary['method']}): {result.status}")
    return fig


def _table(rows):
    cells = "".join(
        f"<tr><th style='text-align:left'>{html.escape(str(k))}</th>"
        f"<td style='text-align:left'>{html.escape(str(v))}</td></tr>"
        for k, v in rows
    )
    return f"<table>{cells}</table>"


def _status_text(status):
    """``complete``, or the kind with what the summary says of it."""
    kind = status.get("kind", "?")
    details = "; ".join(f"{k}: {v}" for k, v in status.items() if k != "kind")
    return f"{kind} ({details})" if details else kind


def result_html(result):
    """``Result._repr_html_``: status, method, duration, drift, work and events as tables."""
    s = result.summary
    final_t = s.get("final", {}).get("t")
    overview = [
        ("scenario", s.get("scenario")),
        ("status", _status_text(s.get("status", {}))),
        ("method", s.get("method_settings", s.get("method"))),
        ("duration", f"{final_t:g} s of sim time" if final_t is not None else "?"),
        ("samples", s.get("samples")),
        ("wall time", f"{s['wall_time_s']:.3g} s" if "wall_time_s" in s else "?"),
    ]
    drift = [(label, f"{s['drift'][key]:.3e}") for key, label in _DRIFT if key in s.get("drift", {})]
    work = [(label, s[key]) for key, label in _WORK if key in s]
    events = s.get("events", [])
    rows = [
        (f"{e['t']:.6g} s", e["condition"] + (" (terminal)" if e["terminal"] else ""))
        for e in events[:_EVENTS_SHOWN]
    ]
    more = len(events) - _EVENTS_SHOWN + s.get("events_not_kept", 0)
    if more > 0:
        rows.append(("…", f"{more} more"))
    warnings = s.get("warnings", [])
    parts = [
        f"<b>polhode Result</b>{_table(overview)}",
        f"<b>drift</b>{_table(drift)}",
        f"<b>work</b>{_table(work)}",
        f"<b>events</b> ({len(events)}){_table(rows)}",
    ]
    if warnings:
        parts.append(f"<b>warnings</b> ({len(warnings)})")
    return "<div>" + "".join(parts) + "</div>"


def scenario_html(scenario):
    """``Scenario._repr_html_``: name, file, method and duration."""
    rows = [
        ("name", scenario.name),
        ("file", scenario.path),
        ("method", scenario.method),
        ("duration", f"{scenario.duration:g} s"),
    ]
    return f"<div><b>polhode Scenario</b>{_table(rows)}</div>"
