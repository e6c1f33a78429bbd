"""polhode.montecarlo against `polhode montecarlo` (its runs.parquet and summary.json)."""

import json
import signal
import subprocess
import sys
import time

import pytest

import polhode
from conftest import REPO

pa = pytest.importorskip("pyarrow")
pq = pytest.importorskip("pyarrow.parquet")

SINK = REPO / "tests/data/montecarlo-sink.yaml"


def cli_campaign(polhode_cli, out, *options):
    return cli_campaign_of(polhode_cli, SINK, out, *options)


def cli_campaign_of(polhode_cli, scenario, out, *options):
    subprocess.run(
        [str(polhode_cli), "montecarlo", str(scenario), "--quiet", "--out", str(out)] + list(options),
        check=True,
        cwd=REPO,
    )
    return out


@pytest.fixture(scope="module")
def cli_seed3(polhode_cli, tmp_path_factory):
    return cli_campaign(polhode_cli, tmp_path_factory.mktemp("cli"), "--seed", "3", "--runs", "60")


def test_the_table_equals_the_cli_runs_parquet(cli_seed3):
    campaign = polhode.montecarlo(polhode.load(SINK), runs=60, seed=3, threads=2)
    assert isinstance(campaign, polhode.Campaign)
    assert not campaign.partial and campaign.runs == 60 == len(campaign)
    # The same bytes as the CLI's file, and the same rows read back by pyarrow.
    assert campaign.parquet == (cli_seed3 / "runs.parquet").read_bytes()
    expected = pq.read_table(cli_seed3 / "runs.parquet")
    assert isinstance(campaign.table, pa.Table)
    assert campaign.table.num_rows == 60
    assert campaign.table.equals(expected)
    assert campaign.table.column_names[:3] == ["run", "status", "message"]
    assert campaign.summary == json.loads((cli_seed3 / "summary.json").read_text())


def test_the_thread_count_changes_nothing(cli_seed3):
    one = polhode.montecarlo(polhode.load(SINK), runs=60, seed=3, threads=1)
    assert one.parquet == (cli_seed3 / "runs.parquet").read_bytes()


@pytest.mark.parametrize("shard", ["2/3", (2, 3)])
def test_a_shard_equals_the_cli_shard(polhode_cli, tmp_path, shard):
    out = cli_campaign(polhode_cli, tmp_path / "shard", "--seed", "3", "--runs", "30", "--shard", "2/3")
    campaign = polhode.montecarlo(polhode.load(SINK), runs=30, seed=3, shard=shard)
    assert campaign.parquet == (out / "runs.parquet").read_bytes()
    assert campaign.summary == json.loads((out / "summary.json").read_text())
    assert campaign.summary["run_range"] == [10, 20]
    assert campaign.table.column("run").to_pylist() == list(range(10, 20))


def test_the_averaged_method_equals_the_cli_with_method(polhode_cli, tmp_path):
    out = cli_campaign(polhode_cli, tmp_path / "avg", "--seed", "3", "--runs", "40", "--method", "averaged")
    campaign = polhode.montecarlo(polhode.load(SINK), runs=40, seed=3, method="averaged")
    assert campaign.parquet == (out / "runs.parquet").read_bytes()
    assert campaign.summary == json.loads((out / "summary.json").read_text())
    full = polhode.montecarlo(polhode.load(SINK), runs=40, seed=3)
    assert campaign.table.column("steps").to_pylist() != full.table.column("steps").to_pylist()
    with pytest.raises(polhode.ScenarioError, match="unknown method"):
        polhode.montecarlo(polhode.load(SINK), runs=4, method="avergaed")


DAMPER = REPO / "scenarios/nutation-damper.yaml"


def test_a_damper_campaign_runs_in_lanes_with_the_scalar_rows(polhode_cli, tmp_path):
    lanes = polhode.montecarlo(polhode.load(DAMPER), runs=12, seed=5, threads=2)
    assert lanes.integration.startswith("in lockstep lane"), lanes.integration
    scalar = polhode.montecarlo(polhode.load(DAMPER), runs=12, seed=5, threads=1, lanes=False)
    assert scalar.integration.startswith("one run at a time"), scalar.integration
    assert lanes.parquet == scalar.parquet
    out = cli_campaign_of(polhode_cli, DAMPER, tmp_path / "damper", "--seed", "5", "--runs", "12")
    assert lanes.parquet == (out / "runs.parquet").read_bytes()
    with pytest.raises(TypeError, match="lanes"):
        polhode.montecarlo(polhode.load(DAMPER), runs=2, lanes="no")


def test_a_scene_without_a_lane_form_says_why():
    campaign = polhode.montecarlo(polhode.load(SINK), runs=2, method="radau5")
    assert "no lane form" in campaign.integration, campaign.integration
    assert "radau5" in campaign.integration, campaign.integration


def test_an_energy_sink_campaign_runs_in_lanes_with_the_scalar_rows():
    lanes = polhode.montecarlo(polhode.load(SINK), runs=12, seed=5, threads=2)
    assert lanes.integration.startswith("in lockstep lane"), lanes.integration
    scalar = polhode.montecarlo(polhode.load(SINK), runs=12, seed=5, threads=1, lanes=False)
    assert lanes.parquet == scalar.parquet


def test_to_pandas_is_the_table():
    pytest.importorskip("pandas")
    campaign = polhode.montecarlo(polhode.load(SINK), runs=10)
    frame = campaign.to_pandas()
    assert list(frame.columns) == campaign.table.column_names
    assert frame["run"].tolist() == list(range(10))
    assert frame.equals(campaign.table.to_pandas())


@pytest.mark.parametrize(
    "kwargs,error",
    [
        ({"shard": "0/3"}, ValueError),
        ({"shard": "4/3"}, ValueError),
        ({"shard": "2-3"}, ValueError),
        ({"shard": (1, 2, 3)}, ValueError),
        ({"runs": 3, "shard": "1/4"}, ValueError),
        ({"threads": 0}, ValueError),
        ({"runs": 0}, polhode.ScenarioError),
    ],
)
def test_bad_arguments(kwargs, error):
    with pytest.raises(error):
        polhode.montecarlo(polhode.load(SINK), **kwargs)


def test_a_scenario_without_a_campaign_is_a_scenario_error():
    with pytest.raises(polhode.ScenarioError) as caught:
        polhode.montecarlo(polhode.load(REPO / "scenarios/tennis-racket.yaml"))
    assert "montecarlo" in str(caught.value)


def test_progress_callable_sees_every_run_from_the_calling_thread():
    import threading

    calls = []
    caller = threading.get_ident()

    def progress(done, total):
        calls.append((done, total, threading.get_ident()))

    polhode.montecarlo(polhode.load(SINK), runs=40, progress=progress)
    assert calls[0][:2] == (0, 40) and calls[-1][:2] == (40, 40)
    dones = [c[0] for c in calls]
    assert dones == sorted(set(dones)), "called only when the count changes, never backwards"
    assert all(c[2] == caller for c in calls)


def test_progress_is_quiet_when_stderr_is_no_terminal(capfd):
    polhode.montecarlo(polhode.load(SINK), runs=10)
    assert capfd.readouterr().err == ""


def test_progress_true_draws_a_tqdm_bar(capfd):
    pytest.importorskip("tqdm")
    polhode.montecarlo(polhode.load(SINK), runs=10, progress=True)
    err = capfd.readouterr().err
    assert "10/10" in err and "run" in err


def test_ctrl_c_raises_keyboard_interrupt_with_the_finished_runs():
    # 100 000 runs take minutes: SIGINT after 1 s stops the campaign.
    script = (
        # Python's own Ctrl-C handler, as in an interactive session, even when this test
        # runs as a background job (whose shell starts it with SIGINT ignored).
        "import signal, sys, time, polhode\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        f"s = polhode.load({str(SINK)!r})\n"
        "print('running', flush=True)\n"
        "try:\n"
        "    polhode.montecarlo(s, runs=100000, threads=2, progress=False)\n"
        "except KeyboardInterrupt as e:\n"
        "    t = time.perf_counter()\n"
        "    c = e.partial\n"
        "    runs = c.table.column('run').to_pylist()\n"
        "    print('interrupted', t, c.partial, c.runs, len(runs), c.summary['partial'], flush=True)\n"
        "    sys.exit(3)\n"
    )
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    assert child.stdout.readline().strip() == "running"
    time.sleep(1.0)
    sent = time.perf_counter()
    child.send_signal(signal.SIGINT)
    out, _ = child.communicate(timeout=60)
    assert child.returncode == 3, out
    word, when, partial, runs, rows, summary_partial = out.split()
    assert word == "interrupted"
    assert float(when) - sent < 1.0
    assert partial == "True" and summary_partial == "True"
    assert 0 < int(runs) == int(rows) < 100000


def test_the_interpreter_exits_cleanly_after_reading_the_table():
    # A pyarrow table whose columns point into Python bytes aborts the interpreter at exit
    # (status 134); the table and a column of it stay alive until then here.
    script = (
        "import sys, polhode\n"
        f"c = polhode.montecarlo(polhode.load({str(SINK)!r}), runs=5, progress=False)\n"
        "runs = c.table.column('run')\n"
        "print(c.table.num_rows, len(c.to_pandas()), len(runs.to_pylist()))\n"
        "sys.exit(0)\n"
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["5", "5", "5"]


def test_the_gil_is_released_during_a_campaign():
    """Another Python thread keeps running while a campaign goes (stalled under half of it)."""
    import threading

    import numpy as np

    scenario = polhode.load(SINK)
    done = threading.Event()
    outcome = {}

    def work():
        start = time.perf_counter()
        # 6000 runs: in lanes the sink's campaign runs some 2500 a second on one thread.
        outcome["campaign"] = polhode.montecarlo(scenario, runs=6000, threads=1, progress=False)
        outcome["seconds"] = time.perf_counter() - start
        done.set()

    ticks = []
    worker = threading.Thread(target=work)
    worker.start()
    while not done.is_set():
        ticks.append(time.perf_counter())
        sum(i * i for i in range(2000))
    worker.join()
    assert outcome["seconds"] > 0.5, "the campaign must last long enough to tell"
    assert len(ticks) > 10
    gaps = np.diff(ticks)
    # Held through the campaign, the GIL would stall this thread for all of it. A busy machine
    # may deschedule it now and then, so the test bounds the total of the long gaps rather than
    # the longest one.
    stalled = gaps[gaps > 0.1].sum()
    assert stalled < 0.5 * outcome["seconds"], (
        f"this thread stalled {stalled:.3f} s of the campaign's {outcome['seconds']:.3f} s"
    )
    assert outcome["campaign"].runs == 6000
