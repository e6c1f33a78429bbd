"""Scenario.from_dict: the CLI's loader and messages, the field named, never a crash."""

import math
import subprocess

import numpy as np
import pytest

import polhode
from conftest import REPO

RACKET = REPO / "scenarios/tennis-racket.yaml"


def racket():
    """The tennis racket (scenarios/tennis-racket.yaml) as a dict, written out by hand."""
    return {
        "name": "tennis-racket",
        "description": "the racket as a dict",
        "body": {"inertia": [[1.0, 0, 0], [0, 2.5, 0], [0, 0, 3.0]], "spin_axis": [0, 1, 0]},
        "initial": {
            "omega": [0.1, 10.0, 0.0],
            "attitude": {"w": 1.0, "x": 0.0, "y": 0.0, "z": 0.0},
        },
        "duration": 10.0,
        "integrator": {"method": "dopri5", "rtol": 1e-10, "atol": 1e-12},
        "output": {"rate": 100, "mcap": "logs/tennis-racket.mcap"},
        "events": [{"nutation_angle_deg": {"above": 90.0}}],
    }


def test_a_dict_runs_as_the_file_does():
    from_file = polhode.load(RACKET).run(duration=2.0)
    from_dict = polhode.Scenario.from_dict(racket()).run(duration=2.0)
    assert from_dict.summary["final"] == from_file.summary["final"]
    assert np.array_equal(from_dict.omega, from_file.omega)
    assert [e["t"] for e in from_dict.events] == [e["t"] for e in from_file.events]


def test_numpy_values_and_tuples_are_lists_and_numbers():
    d = racket()
    d["body"]["inertia"] = np.diag([1.0, 2.5, 3.0])
    d["initial"]["omega"] = (np.float64(0.1), np.float32(10.0), 0)
    d["duration"] = np.int64(10)
    d["output"]["rate"] = np.float64(100.0)
    s = polhode.Scenario.from_dict(d)
    assert s.path == "<dict>" and s.duration == 10.0
    assert "inertia: [[1.0, 0.0, 0.0], [0.0, 2.5, 0.0], [0.0, 0.0, 3.0]]" in s.source
    plain = polhode.Scenario.from_dict(racket()).run(duration=1.0)
    assert s.run(duration=1.0).summary["final"] == plain.summary["final"]


def test_text_that_reads_as_a_number_stays_text():
    d = racket()
    d["name"] = "1e2"
    assert polhode.Scenario.from_dict(d).name == "1e2"


def set_path(d, dotted, value):
    *parents, last = dotted.split(".")
    for p in parents:
        d = d[p]
    d[last] = value


# (what is wrong, the field, the value given, the field ScenarioError names)
BAD = [
    ("wrong type", "duration", "ten", "duration"),
    ("NaN", "duration", math.nan, "duration"),
    ("infinity in a list", "initial.omega", [0.1, math.inf, 0.0], "initial.omega"),
    ("numpy NaN", "body.spin_axis", np.array([0.0, np.nan, 0.0]), "body.spin_axis"),
    ("unknown key", "duraton", 10.0, "duraton"),
    ("unknown nested key", "body.principle", [1.0, 2.0, 3.0], "body.principle"),
    ("two values for three", "initial.omega", np.array([0.1, 10.0]), "initial.omega"),
    ("a matrix for a vector", "body.spin_axis", np.eye(3), "body.spin_axis"),
    ("2x2 inertia", "body.inertia", [[1.0, 0.0], [0.0, 1.0]], "body.inertia"),
    ("text in a vector", "initial.omega", [0.1, "fast", 0.0], "initial.omega"),
]


def cli_message(polhode_cli, tmp_path, d):
    """`polhode check`'s message for the same scenario written as a file by hand-made YAML."""
    path = tmp_path / "bad.yaml"
    path.write_text(_as_yaml(d))
    check = subprocess.run([str(polhode_cli), "check", str(path)], capture_output=True, text=True)
    assert check.returncode == 2, check.stderr
    return check.stderr


def _as_yaml(d):
    # The dict as YAML by a writer independent of polhode's: JSON (a subset of YAML) with
    # non-finite floats spelled as YAML spells them.
    import json

    def clean(v):
        if hasattr(v, "tolist"):
            v = v.tolist()
        if isinstance(v, dict):
            return {k: clean(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [clean(x) for x in v]
        return v

    text = json.dumps(clean(d), allow_nan=True)
    return text.replace("NaN", ".nan").replace("-Infinity", "-.inf").replace("Infinity", ".inf")


@pytest.mark.parametrize("what,dotted,value,field", BAD, ids=[b[0] for b in BAD])
def test_bad_values_raise_scenario_error_naming_the_field(polhode_cli, tmp_path, what, dotted, value, field):
    d = racket()
    set_path(d, dotted, value)
    with pytest.raises(polhode.ScenarioError) as caught:
        polhode.Scenario.from_dict(d)
    e = caught.value
    assert isinstance(e, ValueError)
    assert e.path == "<dict>"
    assert e.line is None and e.column is None
    assert e.field == field
    assert str(e) == f"<dict>: field `{field}`: {e.message}"
    # The loader's own message: `polhode check` says the same about the same scenario.
    assert e.message in cli_message(polhode_cli, tmp_path, d)


@pytest.mark.parametrize(
    "value,kind",
    [({1, 2, 3}, "set"), (b"\x00", "bytes"), (1 + 2j, "complex"), (object(), "object")],
)
def test_values_yaml_cannot_hold_name_their_field(value, kind):
    d = racket()
    d["initial"]["omega"] = [0.1, value, 0.0]
    with pytest.raises(polhode.ScenarioError) as caught:
        polhode.Scenario.from_dict(d)
    assert caught.value.field == "initial.omega[1]"
    assert kind in caught.value.message
    assert caught.value.path == "<dict>"


def test_not_a_dict_and_non_text_keys():
    # Not a mapping at all: a TypeError naming the argument (test_arguments.py has the text).
    with pytest.raises(TypeError, match=r"^Scenario\.from_dict\(\): d must be a dict"):
        polhode.Scenario.from_dict([1, 2, 3])
    d = racket()
    d["body"][3] = 1.0
    with pytest.raises(polhode.ScenarioError) as caught:
        polhode.Scenario.from_dict(d)
    assert caught.value.field == "body"
    assert "keys must be text" in caught.value.message


def test_a_list_of_mappings_names_the_item():
    d = racket()
    d["effectors"] = [{"energy_sink": {"name": "sink", "time_constant": -1.0}}]
    with pytest.raises(polhode.ScenarioError) as caught:
        polhode.Scenario.from_dict(d)
    assert caught.value.field.startswith("effectors[0]"), caught.value.field
    assert "time_constant" in str(caught.value)


def test_deeply_nested_input_is_an_error_not_a_crash():
    deep = [0.0]
    for _ in range(200):
        deep = [deep]
    d = racket()
    d["initial"]["omega"] = deep
    with pytest.raises(polhode.ScenarioError) as caught:
        polhode.Scenario.from_dict(d)
    assert caught.value.field.startswith("initial.omega")
