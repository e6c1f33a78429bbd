"""Scenario.run(log=...) never writes over the scenario, and threads sharing one log= leave
one whole log (docs/cli.md, "Where polhode writes, and what it never overwrites")."""

import os
import threading

import pytest

import polhode
from conftest import REPO


def test_a_log_that_is_the_scenario_is_refused(tmp_path):
    # Before: run(log=<the scenario>) replaced the scenario file with the MCAP log.
    scenario = tmp_path / "t.yaml"
    text = (REPO / "scenarios/tennis-racket.yaml").read_text()
    scenario.write_text(text)
    os.link(scenario, tmp_path / "hard.yaml")
    os.symlink(scenario, tmp_path / "link.yaml")
    s = polhode.load(scenario)
    for alias in [scenario, tmp_path / "sub" / ".." / "t.yaml", tmp_path / "hard.yaml", tmp_path / "link.yaml"]:
        with pytest.raises(ValueError, match="the scenario"):
            s.run(duration=0.5, log=alias)
        assert scenario.read_text() == text
    assert sorted(p.name for p in tmp_path.iterdir()) == ["hard.yaml", "link.yaml", "t.yaml"]


def test_threads_sharing_one_log_leave_one_whole_log(tmp_path):
    # Before: the temporary name was unique per process only, so threads wrote into one file.
    from mcap import reader as mcap_reader

    log = tmp_path / "shared.mcap"
    s = polhode.load(REPO / "scenarios/tennis-racket.yaml")
    errors = []

    def one():
        try:
            s.run(duration=5.0, log=log)
        except Exception as e:  # noqa: BLE001 - any failure fails the test below
            errors.append(e)

    threads = [threading.Thread(target=one) for _ in range(6)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    assert [p.name for p in tmp_path.iterdir()] == ["shared.mcap"], "temporaries left"
    with open(log, "rb") as f:
        reader = mcap_reader.make_reader(f)
        metadata = {m.name: m.metadata for m in reader.iter_metadata()}
    assert metadata["polhode"]["status"] == "complete"
