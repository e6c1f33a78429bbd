"""Monte Carlo campaigns in process: :func:`montecarlo` and :class:`Campaign`.

The runs, their table and their summary are those of ``polhode montecarlo`` for the same
scenario, seed and shard: the extension runs the campaign with the CLI's library code
(``polhode::montecarlo``) and hands back the bytes of ``runs.parquet`` and the text of
``summary.json`` as the CLI would write them; no file is written.
"""

from __future__ import annotations

import json
import numbers
import os
import sys
from typing import TYPE_CHECKING, Any, Callable, Optional, Tuple, Union

from ._args import integer, is_path, optional_import, type_error
from ._polhode import Scenario, _montecarlo, load

if TYPE_CHECKING:
    import pandas
    import pyarrow

__all__ = ["Campaign", "montecarlo"]


class Campaign:
    """The finished runs of a Monte Carlo campaign.

    - ``table``: a ``pyarrow.Table``, one row per finished run in run order, the columns of
      ``runs.parquet`` (``run``, ``status``, ``message``, the drawn inputs, the event times
      in s, the final and largest nutation in degrees, ...; docs/montecarlo.md);
    - ``to_pandas()``: the table as a pandas DataFrame;
    - ``summary``: the ``summary.json`` document as a dict (statistics, event probabilities
      with 95 % intervals, ranking, failures);
    - ``parquet``: the ``runs.parquet`` bytes, as ``polhode montecarlo`` writes them;
    - ``partial``: whether runs of the range are missing (the campaign was interrupted);
    - ``integration``: how the runs were integrated, as ``polhode montecarlo``'s header says
      it (in lockstep lanes, or one at a time per thread and why).
    """

    parquet: bytes
    summary: dict
    partial: bool
    integration: str

    def __init__(self, parquet: bytes, summary: dict, partial: bool, integration: str = "") -> None:
        self.parquet = parquet
        self.summary = summary
        self.partial = partial
        self.integration = integration
        self._table = None

    @property
    def table(self) -> pyarrow.Table:
        """The runs as a ``pyarrow.Table`` (pyarrow imported on first use)."""
        if self._table is None:
            pa = optional_import("pyarrow", "Campaign.table")
            pq = optional_import("pyarrow.parquet", "Campaign.table")
            # Read from a copy in an Arrow-owned buffer, not from the Python bytes: a table
            # whose columns still point into a Python object aborts the interpreter at exit
            # ("terminate called without an active exception", as in apache/arrow#34314;
            # seen with pyarrow 22). The copy is the size of the Parquet file.
            stream = pa.BufferOutputStream()
            stream.write(self.parquet)
            self._table = pq.read_table(pa.BufferReader(stream.getvalue()))
        return self._table

    def to_pandas(self) -> pandas.DataFrame:
        """The runs as a pandas DataFrame (needs pyarrow and pandas)."""
        optional_import("pandas", "Campaign.to_pandas()")
        return self.table.to_pandas()

    @property
    def runs(self) -> int:
        """How many runs finished (rows of the table)."""
        return self.summary["runs_in_table"]

    def __len__(self) -> int:
        return self.runs

    def __repr__(self) -> str:
        partial = ", partial" if self.partial else ""
        return (
            f"Campaign(scenario={self.summary['scenario']!r}, seed={self.summary['seed']}, "
            f"runs={self.runs} of {self.summary['runs']}{partial})"
        )


def _in_jupyter():
    """Whether this runs in a Jupyter (IPython) kernel."""
    if "ipykernel" not in sys.modules:
        return False
    try:
        from IPython import get_ipython

        shell = get_ipython()
    except Exception:
        return False
    return shell is not None and hasattr(shell, "kernel")


def _stderr_is_terminal():
    try:
        return sys.stderr is not None and sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False


class _Bar:
    """``on_progress(done, total)`` drawing a tqdm bar, made on the first call."""

    def __init__(self, tqdm, description):
        self._tqdm = tqdm
        self._description = description
        self._bar = None

    def __call__(self, done, total):
        if self._bar is None:
            self._bar = self._tqdm(total=total, unit="run", desc=self._description)
        self._bar.update(done - self._bar.n)

    def close(self):
        if self._bar is not None:
            self._bar.close()


def _progress(progress, description):
    """The progress callback for ``progress=`` (None: auto), and how to close it."""
    if progress is False:
        return None
    if not (progress is None or progress is True or callable(progress)):
        raise type_error(
            "montecarlo", "progress", "True, False, None or a callable f(done, total)", progress
        )
    if callable(progress) and progress is not True:
        return progress
    if progress is None and not (_stderr_is_terminal() or _in_jupyter()):
        return None
    try:
        from tqdm.auto import tqdm
    except ImportError:
        if progress is None:
            return None
        raise ImportError(
            "montecarlo(progress=True) needs tqdm, which is not installed: `pip install tqdm`"
        ) from None
    return _Bar(tqdm, description)


# What montecarlo's shard= takes, in its TypeError.
_SHARD_EXPECTED = "'K/N' (str) or a pair (K, N) of ints"


def _shard(shard):
    if shard is None:
        return None
    if not isinstance(shard, (str, tuple, list)):
        raise type_error("montecarlo", "shard", _SHARD_EXPECTED, shard)
    if isinstance(shard, str):
        k, sep, n = shard.partition("/")
        try:
            if not sep:
                raise ValueError
            return int(k), int(n)
        except ValueError:
            raise ValueError(f"shard {shard!r}: expected 'K/N' or (K, N), e.g. '2/8'") from None
    if len(shard) != 2:
        raise ValueError(f"shard {shard!r}: expected 'K/N' or (K, N), e.g. '2/8'")
    for part in shard:
        if isinstance(part, bool) or not isinstance(part, numbers.Integral):
            raise type_error("montecarlo", "shard", _SHARD_EXPECTED, shard)
    k, n = shard
    return int(k), int(n)


def montecarlo(
    scenario: Union[Scenario, str, os.PathLike],
    runs: Optional[int] = None,
    seed: Optional[int] = None,
    threads: Optional[int] = None,
    shard: Union[str, Tuple[int, int], None] = None,
    progress: Union[bool, None, Callable[[int, int], Any]] = None,
    method: Optional[str] = None,
    lanes: bool = True,
) -> Campaign:
    """Run the scenario's Monte Carlo campaign (its ``montecarlo:`` block) in process.

    ``scenario`` is a :class:`Scenario` or a scenario file's path (str or os.PathLike),
    loaded as :func:`load` does. The same runs, table and summary as ``polhode montecarlo
    FILE --runs R --seed S --shard K/N`` (any thread count gives the same numbers).

    - ``runs``, ``seed``: override the block's; ``threads``: worker threads (default: every
      core; more than 4 per logical core are capped there, with a ``RuntimeWarning``); ``shard``: ``"K/N"`` or ``(K, N)``, 1 <= K <= N, to run only the K-th of N
      contiguous slices of the runs, as ``--shard`` does.
    - ``progress``: None (default) shows a tqdm bar when stderr is a terminal or in a
      Jupyter kernel and tqdm is installed, nothing otherwise; True always (needs tqdm);
      False never; or a callable ``f(done, total)``, called from the calling thread about
      every 0.1 s while the count changes.
    - ``method``: every run's integration method instead of the scenario's, as ``--method``
      (e.g. ``"averaged"``, docs/averaging.md).
    - ``lanes``: False integrates one run after another on each thread even where the scene
      has a lane form, as ``--no-lanes`` (the rows are the same; docs/montecarlo.md). The
      returned campaign's ``integration`` says which path ran.

    Returns a :class:`Campaign`. The GIL is released while the runs go. Ctrl-C stops the
    campaign within a fraction of a second and raises ``KeyboardInterrupt`` whose
    ``partial`` attribute is the :class:`Campaign` of the runs that finished.
    Raises ``ScenarioError`` when the scenario has no valid ``montecarlo:`` block or
    ``runs`` is out of range, ``ValueError`` for a bad ``shard`` or ``threads``, and
    ``TypeError`` naming the argument for one of the wrong type.
    """
    if is_path(scenario):
        scenario = load(scenario)
    elif not isinstance(scenario, Scenario):
        raise type_error(
            "montecarlo",
            "scenario",
            "a Scenario or a scenario file's path (str or os.PathLike)",
            scenario,
        )
    runs = integer("montecarlo", "runs", "a number of runs (int)", runs, 0)
    seed = integer("montecarlo", "seed", "a seed (int)", seed, 0)
    threads = integer("montecarlo", "threads", "a number of threads (int)", threads, 0)
    if method is not None and not isinstance(method, str):
        raise type_error(
            "montecarlo", "method", "an integration method's name (str, e.g. \"averaged\")", method
        )
    if not isinstance(lanes, bool):
        raise type_error("montecarlo", "lanes", "True or False (bool)", lanes)
    pair = _shard(shard)
    name = getattr(scenario, "name", "montecarlo")
    report = _progress(progress, name)
    try:
        parquet, summary, partial, raised, integration = _montecarlo(
            scenario, runs, seed, threads, pair, report, method, lanes
        )
    finally:
        if isinstance(report, _Bar):
            report.close()
    campaign = Campaign(parquet, json.loads(summary), partial, integration)
    if raised is not None:
        raised.partial = campaign
        raise raised
    return campaign
