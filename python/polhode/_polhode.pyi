"""Type stubs of the extension module polhode._polhode (re-exported by polhode)."""

from os import PathLike
from typing import Any, Dict, List, Optional, Union

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
    def telemetry(self) -> Dict[str, npt.NDArray[np.float64]]:
        """Every ``/telemetry`` field of the MCAP log by name (units in docs/logs.md), shape (n,)."""
    @property
    def events(self) -> List[Dict[str, Any]]:
        """Events in time order: ``t`` (s), ``condition`` (str), ``terminal`` (bool)."""
    @property
    def summary(self) -> Dict[str, Any]:
        """The ``polhode run --summary`` JSON document."""
    @property
    def status(self) -> str:
        """complete, stopped, interrupted, failed or invalid_model."""

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
        """The YAML text."""
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
        cannot be written.
        """

def load(path: Union[str, "PathLike[str]"]) -> Scenario:
    """Read and validate a scenario file (YAML); raises ScenarioError."""

def loads(yaml_text: str) -> Scenario:
    """Validate a scenario given as YAML text; raises ScenarioError."""
