"""load/loads and ScenarioError: the CLI's validation and messages."""

import subprocess

import pytest

import polhode
from conftest import REPO

RACKET = REPO / "scenarios/tennis-racket.yaml"


def test_load_and_loads_give_the_same_scenario():
    from_file = polhode.load(RACKET)
    from_text = polhode.loads(RACKET.read_text())
    assert from_file.name == from_text.name == "tennis-racket"
    assert from_file.duration == from_text.duration == 10.0
    assert from_file.method == "dopri5"
    assert from_file.path == str(RACKET)
    assert from_text.path == "<string>"
    assert from_file.run(duration=1.0).summary["final"] == from_text.run(duration=1.0).summary["final"]
    assert polhode.load(str(RACKET)).name == "tennis-racket"


# (what is wrong, replace this, with this, the field named, its line)
BAD = [
    ("wrong type", "duration: 10.0 ", "duration: ten ", "duration", 14),
    ("unknown key", "duration: 10.0 ", "duraton: 10.0 ", None, 14),
    ("NaN", "duration: 10.0 ", "duration: .nan ", "duration", 14),
]


@pytest.mark.parametrize("what,old,new,field,line", BAD, ids=[b[0] for b in BAD])
def test_scenario_error_on_a_bad_file(polhode_cli, tmp_path, what, old, new, field, line):
    text = RACKET.read_text()
    assert old in text
    bad = tmp_path / "bad.yaml"
    bad.write_text(text.replace(old, new, 1))

    with pytest.raises(polhode.ScenarioError) as caught:
        polhode.load(bad)
    e = caught.value
    assert isinstance(e, ValueError)
    assert e.path == str(bad)
    assert e.line == line
    assert isinstance(e.column, int) and e.column >= 1
    if field is not None:
        assert e.field == field
    assert e.message and e.message in str(e)

    # The message is the CLI's, word for word.
    check = subprocess.run(
        [str(polhode_cli), "check", str(bad)], capture_output=True, text=True
    )
    assert check.returncode == 2
    assert f"error: {e}" in check.stderr

    # loads names the text <string>, and says the same thing.
    with pytest.raises(polhode.ScenarioError) as from_text:
        polhode.loads(bad.read_text())
    assert from_text.value.path == "<string>"
    assert str(from_text.value) == str(e).replace(str(bad), "<string>", 1)


def test_unknown_key_suggests_the_right_one():
    with pytest.raises(polhode.ScenarioError) as caught:
        polhode.loads(RACKET.read_text().replace("duration: 10.0 ", "duraton: 10.0 "))
    assert "duration" in str(caught.value)


def test_missing_file_is_a_scenario_error_without_location(tmp_path):
    with pytest.raises(polhode.ScenarioError) as caught:
        polhode.load(tmp_path / "missing.yaml")
    assert caught.value.line is None and caught.value.column is None
    assert caught.value.field is None
    assert "cannot read the file" in str(caught.value)


def test_bad_overrides_raise_scenario_error():
    scenario = polhode.load(RACKET)
    with pytest.raises(polhode.ScenarioError):
        scenario.run(method="no-such-method")
    with pytest.raises(polhode.ScenarioError):
        scenario.run(duration=float("nan"))
    with pytest.raises(polhode.ScenarioError):
        scenario.run(rtol=-1.0)
