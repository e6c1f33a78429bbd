"""polhode: spacecraft attitude dynamics with energy dissipation, from Python.

Load a scenario (the same YAML files and validation as the ``polhode`` command) and run it::

    import polhode
    result = polhode.load("scenarios/tennis-racket.yaml").run()
    result.t, result.omega, result.q      # s; rad/s (body); body->inertial, scalar-first
    result.events, result.summary         # as `polhode run --summary` reports them
    result.telemetry                      # the columns of `polhode run --csv`, by name
    result.to_pandas(), result.plot()     # a DataFrame (pandas), a Figure (matplotlib)

A scenario can also come from a dict (``Scenario.from_dict``); ``montecarlo`` runs its
campaign (``Campaign.table`` is a pyarrow Table equal to the CLI's ``runs.parquet``).
In Jupyter a Result and a Scenario show an HTML summary; python/examples/first-day.ipynb
walks through them.

Units are SI (s, rad/s, N m s, J). Quaternions are scalar-first (w, x, y, z) and map body
vectors to inertial vectors. See docs/python.md.
"""

from ._campaign import Campaign, montecarlo
from ._polhode import Result, Scenario, ScenarioError, __version__, linearize, load, loads

__all__ = [
    "Campaign",
    "Result",
    "Scenario",
    "ScenarioError",
    "__version__",
    "linearize",
    "load",
    "loads",
    "montecarlo",
]
