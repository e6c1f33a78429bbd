"""Arguments of the wrong type: a TypeError naming the function, the argument, what it takes
and what it got, before anything runs; paths accepted where a scenario is expected."""

import pathlib

import numpy as np
import pytest

import polhode
from conftest import REPO

RACKET = REPO / "scenarios/tennis-racket.yaml"
SINK = REPO / "tests/data/montecarlo-sink.yaml"


def racket():
    return polhode.load(RACKET)


# (call, the message it must give). Each message is written out here, not built by the code.
WRONG_TYPES = [
    (
        lambda: racket().run(duration="100"),
        "run(): duration must be a number of seconds (float), got str '100'",
    ),
    (
        lambda: racket().run(duration=True),
        "run(): duration must be a number of seconds (float), got bool True",
    ),
    (
        lambda: racket().run(method=4),
        'run(): method must be an integration method\'s name (str, e.g. "dop853"), got int 4',
    ),
    (
        lambda: racket().run(dt=[0.1]),
        "run(): dt must be a step in seconds (float), got list [0.1]",
    ),
    (
        lambda: racket().run(rtol="1e-9"),
        "run(): rtol must be a relative tolerance (float), got str '1e-9'",
    ),
    (
        lambda: racket().run(atol={}),
        "run(): atol must be an absolute tolerance (float), got dict {}",
    ),
    (
        lambda: racket().run(log=5),
        "run(): log must be the path of the MCAP file to write (str or os.PathLike), got int 5",
    ),
    (
        lambda: polhode.load(5),
        "load(): path must be a scenario file's path (str or os.PathLike), got int 5",
    ),
    (
        lambda: polhode.load(b"scenarios/tennis-racket.yaml"),
        "load(): path must be a scenario file's path (str or os.PathLike), got bytes "
        "b'scenarios/tennis-racket.yaml'",
    ),
    (
        lambda: polhode.loads(RACKET),
        f"loads(): yaml_text must be the scenario's YAML text (str), got PosixPath {RACKET!r}",
    ),
    (
        lambda: polhode.Scenario.from_dict([1, 2, 3]),
        "Scenario.from_dict(): d must be a dict of the scenario's top-level keys (name, body, "
        "initial, duration, ...), got list [1, 2, 3]",
    ),
    (
        lambda: polhode.linearize(42),
        "linearize(): scenario must be a Scenario or a scenario file's path (str or "
        "os.PathLike), got int 42",
    ),
    (
        lambda: polhode.montecarlo(42),
        "montecarlo(): scenario must be a Scenario or a scenario file's path (str or "
        "os.PathLike), got int 42",
    ),
    (
        lambda: polhode.montecarlo(SINK, runs="10"),
        "montecarlo(): runs must be a number of runs (int), got str '10'",
    ),
    (
        lambda: polhode.montecarlo(SINK, runs=10.0),
        "montecarlo(): runs must be a number of runs (int), got float 10.0",
    ),
    (
        lambda: polhode.montecarlo(SINK, seed=1.5),
        "montecarlo(): seed must be a seed (int), got float 1.5",
    ),
    (
        lambda: polhode.montecarlo(SINK, threads="2"),
        "montecarlo(): threads must be a number of threads (int), got str '2'",
    ),
    (
        lambda: polhode.montecarlo(SINK, shard=3.5),
        "montecarlo(): shard must be 'K/N' (str) or a pair (K, N) of ints, got float 3.5",
    ),
    (
        lambda: polhode.montecarlo(SINK, shard=(1.0, 2)),
        "montecarlo(): shard must be 'K/N' (str) or a pair (K, N) of ints, got tuple (1.0, 2)",
    ),
    (
        lambda: polhode.montecarlo(SINK, progress="yes"),
        "montecarlo(): progress must be True, False, None or a callable f(done, total), got "
        "str 'yes'",
    ),
    (
        lambda: polhode.montecarlo(SINK, method=4),
        'montecarlo(): method must be an integration method\'s name (str, e.g. "averaged"), '
        "got int 4",
    ),
]


@pytest.mark.parametrize("call,message", WRONG_TYPES, ids=[m for _, m in WRONG_TYPES])
def test_a_wrong_type_names_the_argument_and_what_it_takes(call, message):
    with pytest.raises(TypeError) as caught:
        call()
    assert str(caught.value) == message


def test_a_long_value_is_cut_in_the_message():
    with pytest.raises(TypeError) as caught:
        racket().run(duration="x" * 500)
    text = str(caught.value)
    assert text.startswith("run(): duration must be a number of seconds (float), got str 'xxx")
    assert text.endswith("…") and len(text) < 160


def test_numbers_of_every_kind_are_taken():
    # numpy scalars and Python ints are numbers; the run is the same as with floats.
    scenario = racket()
    as_float = scenario.run(duration=0.5, rtol=1e-9)
    as_numpy = scenario.run(duration=np.float64(0.5), rtol=np.float64(1e-9))
    assert np.array_equal(as_float.omega, as_numpy.omega)
    assert len(scenario.run(duration=1).t) == 101
    assert len(scenario.run(duration=np.int64(1)).t) == 101


def test_an_int_too_large_for_a_float_is_an_overflow_error():
    # Its type is right: Python's own error (int too large to convert to float), not a TypeError.
    with pytest.raises(OverflowError):
        racket().run(duration=10**400)


def test_negative_counts_are_value_errors_naming_the_argument():
    with pytest.raises(ValueError, match=r"^montecarlo\(\): runs must be at least 0, got -3$"):
        polhode.montecarlo(SINK, runs=-3)
    with pytest.raises(ValueError, match=r"^montecarlo\(\): seed must be at least 0, got -1$"):
        polhode.montecarlo(SINK, seed=-1)
    with pytest.raises(ValueError, match=r"seed must be at most 2\*\*64 - 1"):
        polhode.montecarlo(SINK, seed=2**64)


@pytest.mark.parametrize("given", [str(SINK), SINK, pathlib.PurePosixPath(SINK)], ids=["str", "Path", "PurePath"])
def test_montecarlo_takes_a_path(given):
    from_path = polhode.montecarlo(given, runs=5, seed=4, progress=False)
    from_scenario = polhode.montecarlo(polhode.load(SINK), runs=5, seed=4, progress=False)
    assert from_path.parquet == from_scenario.parquet
    assert from_path.summary == from_scenario.summary


def test_montecarlo_of_a_missing_file_is_a_scenario_error(tmp_path):
    with pytest.raises(polhode.ScenarioError) as caught:
        polhode.montecarlo(tmp_path / "missing.yaml")
    assert caught.value.path == str(tmp_path / "missing.yaml")


def test_linearize_takes_a_path():
    damper = REPO / "scenarios/nutation-damper.yaml"
    assert polhode.linearize(damper) == polhode.linearize(polhode.load(damper))
    assert polhode.linearize(str(damper)) == polhode.linearize(polhode.load(damper))
