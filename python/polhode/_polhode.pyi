"""Type stubs of the extension module polhode._polhode (re-exported by polhode)."""

from os import PathLike
from typing import Any, Callable, Dict, List, Mapping, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

class ScenarioError(ValueError):
    """A scenario that does not validate; ``str(e)`` is the CLI's message."""

    path: str
    """The scenario file, or ``"<string>"`` for :func:`loads`."""
    line: Optional[int]
    """1-based line of the problem, None when unknown."""
    column: Optional[int]
    """1-based column of the problem, None when unknown."""
    field: Optional[str]
    """Dotted path of the field (``body.inertia``), None when unknown."""
    message: str
    """What is wrong and what was expected, without the location."""

class Result:
    """What :meth:`Scenario.run` computed, over the n output samples."""

    @property
    def t(self) -> npt.NDArray[np.float64]:
        """Sim time of each sample (s), shape (n,)."""
    @property
    def omega(self) -> npt.NDArray[np.float64]:
        """Body rates in the body frame (rad/s), shape (n, 3)."""
    @property
    def q(self) -> npt.NDArray[np.float64]:
        """Attitude quaternion body->inertial, scalar-first (w, x, y, z), shape (n, 4)."""
    @property
    def q_lvlh(self) -> Optional[npt.NDArray[np.float64]]:
        """Attitude relative to LVLH, body->LVLH, scalar-first, w >= 0, shape (n, 4).

        The ``/orbit`` fields ``q_lvlh_*``; None for a scenario without an orbit.
        """
    @property
    def lvlh_rpy(self) -> Optional[npt.NDArray[np.float64]]:
        """Roll, pitch, yaw relative to LVLH (deg, 3-2-1 Euler angles), shape (n, 3).

        The ``/orbit`` fields ``roll_deg``, ``pitch_deg``, ``yaw_deg``; None without an orbit.
        """
    @property
    def omega_lvlh(self) -> Optional[npt.NDArray[np.float64]]:
        """Body rates relative to LVLH in the body frame (rad/s), shape (n, 3).

        The ``/orbit`` fields ``omega_lvlh_*``; None for a scenario without an orbit.
        """
    @property
    def telemetry(self) -> Dict[str, npt.NDArray[np.float64]]:
        """The columns of ``polhode run --csv`` by name, each of shape (n,).

        Every ``/telemetry`` field of the MCAP log (``sim_time`` s, ``omega_x`` rad/s,
        ``h_norm`` N m s, ``kinetic_energy`` J, ``nutation_angle_deg`` deg, ...; units in
        docs/logs.md), then each effector's fields as ``<effector>.<field>``
        (``wheel.rate`` rad/s, ``damper.offset`` m, ...), then with an orbit the attitude
        relative to LVLH (``q_lvlh_*``, ``roll_deg``, ``pitch_deg``, ``yaw_deg``,
        ``omega_lvlh_*``). Views of one buffer, no copy.
        """
    @property
    def events(self) -> List[Dict[str, Any]]:
        """Events in time order: ``t`` (s), ``condition`` (str), ``terminal`` (bool)."""
    @property
    def summary(self) -> Dict[str, Any]:
        """The ``polhode run --summary`` JSON document."""
    @property
    def status(self) -> str:
        """complete, stopped, interrupted, failed or invalid_model."""
    @property
    def units(self) -> Dict[str, str]:
        """The unit of each ``telemetry`` column by name (``"rad/s"``; ``""`` for none)."""
    def to_pandas(self, units: bool = True) -> Any:
        """A ``pandas.DataFrame``, one column per ``telemetry`` column in its order, one row
        per sample (a copy).

        Columns named as the ``polhode run --csv`` header names them (``sim_time [s]``,
        ``omega_x [rad/s]``, ``damper.offset [m]``), or by the bare ``telemetry`` names with
        ``units=False``. Imports pandas (not a dependency of polhode; ImportError saying what
        to install when missing).
        """
    def plot(self, figsize: Optional[Tuple[float, float]] = None) -> Any:
        """A ``matplotlib.figure.Figure`` (made with pyplot) of four panels against sim time:
        the body rates (rad/s), the nutation angle (deg), the kinetic, elastic (when not
        zero) and dissipated energies (J), and the relative drift of |H|; events as dashed
        lines. ``figsize`` in inches, (8, 9) by default. Imports matplotlib (ImportError
        saying what to install when missing).
        """
    def _repr_html_(self) -> str:
        """Jupyter's view: status, method, duration, drift, work counters and events."""

class Scenario:
    """A validated scenario."""

    @property
    def name(self) -> str:
        """The scenario's ``name:``."""
    @property
    def path(self) -> str:
        """Its file, or ``"<string>"`` for :func:`loads`."""
    @property
    def duration(self) -> float:
        """Simulated duration (s)."""
    @property
    def method(self) -> str:
        """The integration method's name (for ``auto``, the one it picked)."""
    @property
    def source(self) -> str:
        """The YAML text (for :meth:`from_dict`, the text written from the dict)."""
    @staticmethod
    def from_dict(d: Mapping[str, Any]) -> "Scenario":
        """Validate a scenario given as a dict, as the YAML file would read.

        Values: dicts, lists/tuples, numbers, text, booleans, None; numpy arrays and scalars
        are taken as lists and numbers. SI units, as in the files (s, rad/s, kg m^2, ...).
        Validated by the CLI's loader; ``ScenarioError`` with ``path="<dict>"``, ``field``
        the dotted field (``body.inertia``, ``effectors[0].mass``), ``line``/``column``
        None, for wrong types, NaN/inf, unknown keys, wrong shapes and values YAML cannot
        hold (sets, objects); TypeError when ``d`` is not a mapping.
        """
    def _repr_html_(self) -> str:
        """Jupyter's view: name, file, method and duration."""
    def run(
        self,
        method: Optional[str] = None,
        dt: Optional[float] = None,
        rtol: Optional[float] = None,
        atol: Optional[float] = None,
        duration: Optional[float] = None,
        log: Union[str, "PathLike[str]", None] = None,
    ) -> Result:
        """Run as ``polhode run`` does with the same options.

        ``method``, ``dt`` (s), ``rtol``, ``atol`` and ``duration`` (s) override the
        scenario's; ``log`` names the MCAP file to write (none is written without it).
        Releases the GIL; Ctrl-C raises KeyboardInterrupt within 0.1 s.
        Raises ScenarioError when an override does not validate, OSError when the log
        cannot be written, TypeError naming the argument for one of the wrong type.
        """

def linearize(scenario: Union[Scenario, str, "PathLike[str]"]) -> Dict[str, Any]:
    """The JSON of ``polhode linearize FILE --json OUT`` as a dict (docs/cli.md).

    ``scenario`` is a Scenario or a scenario file's path (loaded as :func:`load` does).

    Modes about the steady spin (eigenvalues in 1/s, time constants in s), or about the LVLH
    equilibrium for a gravity-gradient spacecraft in orbit, or the effectors' modes under a
    driven hub. Raises ScenarioError, or ValueError with the CLI's message when the scenario
    cannot be linearised, TypeError when ``scenario`` is neither.
    """

def _montecarlo(
    scenario: Scenario,
    runs: Optional[int] = None,
    seed: Optional[int] = None,
    threads: Optional[int] = None,
    shard: Optional[Tuple[int, int]] = None,
    on_progress: Optional[Callable[[int, int], object]] = None,
    method: Optional[str] = None,
    lanes: bool = True,
) -> Tuple[bytes, str, bool, Optional[BaseException], str]:
    """Internal: see :func:`polhode.montecarlo`. Returns the ``runs.parquet`` bytes, the
    ``summary.json`` text, whether runs are missing, the exception raised meanwhile, and how
    the runs were integrated."""

def load(path: Union[str, "PathLike[str]"]) -> Scenario:
    """Read and validate a scenario file (YAML); raises ScenarioError, or TypeError when
    ``path`` is not a str or os.PathLike."""

def loads(yaml_text: str) -> Scenario:
    """Validate a scenario given as YAML text; raises ScenarioError, or TypeError when
    ``yaml_text`` is not a str."""
