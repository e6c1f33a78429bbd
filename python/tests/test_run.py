"""Scenario.run against the CLI (a subprocess: the independent path), bit for bit."""

import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import polhode
from conftest import REPO

# Keys of the summary that differ between two runs of the same numbers: the wall-clock time,
# and where the log and scenario were (the CLI is given the file, Python too, but no log).
RUN_SPECIFIC = {"wall_time_s", "mcap"}


def comparable(summary):
    return {k: v for k, v in summary.items() if k not in RUN_SPECIFIC}


CASES = [
    # (scenario, run() keyword arguments, the same as CLI options)
    ("scenarios/tennis-racket.yaml", {}, []),
    ("scenarios/explorer1-pydy-energy-sink.yaml", {}, []),
    ("scenarios/nutation-damper.yaml", {"duration": 20.0}, ["--duration", "20"]),
    (
        "scenarios/tennis-racket.yaml",
        {"method": "rk4", "dt": 1e-3, "duration": 3.0},
        ["--method", "rk4", "--dt", "0.001", "--duration", "3"],
    ),
    (
        "scenarios/tennis-racket.yaml",
        {"method": "dop853", "rtol": 1e-9, "atol": 1e-11},
        ["--method", "dop853", "--rtol", "1e-9", "--atol", "1e-11"],
    ),
]


@pytest.mark.parametrize("scenario,kwargs,options", CASES)
def test_run_equals_the_cli_bit_for_bit(cli_summary, scenario, kwargs, options):
    expected = cli_summary(scenario, *options)
    result = polhode.load(REPO / scenario).run(**kwargs)

    assert comparable(result.summary) == comparable(expected)
    # The arrays end where the CLI's summary says the run ended, to the last bit.
    final = expected["final"]
    assert result.t[-1] == final["t"]
    assert result.omega[-1].tolist() == final["omega"]
    assert result.q[-1].tolist() == [final["q"][k] for k in "wxyz"]
    assert result.telemetry["nutation_angle_deg"][-1] == final["nutation_angle_deg"]
    assert [e["t"] for e in result.events] == [e["t"] for e in expected["events"]]
    assert [e["condition"] for e in result.events] == [e["condition"] for e in expected["events"]]
    assert result.status == expected["status"]["kind"]
    assert len(result.t) == expected["samples"]


def test_tennis_racket_flips_where_the_cli_says():
    # The racket's first flip is near 1.15 s (k = 5 1/s from a 1 % disturbance).
    result = polhode.load(REPO / "scenarios/tennis-racket.yaml").run()
    assert len(result.events) >= 2
    assert 1.1 < result.events[0]["t"] < 1.2
    assert result.events[0]["condition"] == "nutation_angle_deg above 90"


def test_result_arrays_shapes_and_conventions():
    result = polhode.load(REPO / "scenarios/tennis-racket.yaml").run(duration=1.0)
    n = len(result.t)
    assert n == 101  # 100 samples per second over 1 s, both ends
    assert result.t.shape == (n,) and result.t.dtype == np.float64
    assert result.omega.shape == (n, 3)
    assert result.q.shape == (n, 4)
    # Scalar-first, starting at the identity attitude the scenario gives.
    assert result.q[0].tolist() == [1.0, 0.0, 0.0, 0.0]
    assert result.omega[0].tolist() == [0.1, 10.0, 0.0]
    # Every /telemetry field, each as long as t, and the arrays agree with it.
    assert list(result.telemetry) == [
        "sim_time", "omega_x", "omega_y", "omega_z", "q_w", "q_x", "q_y", "q_z",
        "h_body_x", "h_body_y", "h_body_z", "h_inertial_x", "h_inertial_y", "h_inertial_z",
        "h_norm", "kinetic_energy", "nutation_angle_deg", "angle_to_principal_1_deg",
        "angle_to_principal_2_deg", "angle_to_principal_3_deg", "drift_h_rel",
        "drift_energy_rel", "q_norm_error", "elastic_energy", "dissipated_energy",
        "dissipation_power",
    ]
    for column in result.telemetry.values():
        assert column.shape == (n,)
    assert np.array_equal(result.telemetry["sim_time"], result.t)
    assert np.array_equal(result.telemetry["omega_y"], result.omega[:, 1])
    assert np.array_equal(result.telemetry["q_z"], result.q[:, 3])


def test_no_file_is_written_without_log(tmp_path):
    text = (REPO / "scenarios/tennis-racket.yaml").read_text()
    configured = tmp_path / "configured.mcap"
    text = text.replace("logs/tennis-racket.mcap", str(configured))
    assert str(configured) in text
    scenario = polhode.loads(text)
    before = sorted(p.name for p in tmp_path.iterdir())
    result = scenario.run(duration=0.5)
    assert result.summary["mcap"] is None
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    assert not configured.exists()

    named = tmp_path / "named.mcap"
    result = scenario.run(duration=0.5, log=named)
    assert named.is_file() and named.stat().st_size > 0
    assert result.summary["mcap"] == str(named)
    assert not configured.exists()


def test_telemetry_equals_the_logs_own(tmp_path):
    """Every /telemetry field of the MCAP log, decoded by the mcap packages, equals the arrays."""
    # Installed with the venv (tests/python/requirements.txt), as for the independent reader.
    from mcap import reader as mcap_reader
    from mcap_protobuf import decoder
    log = tmp_path / "racket.mcap"
    result = polhode.load(REPO / "scenarios/tennis-racket.yaml").run(duration=2.0, log=log)
    rows = []
    with open(log, "rb") as f:
        reader = mcap_reader.make_reader(f, decoder_factories=[decoder.DecoderFactory()])
        for _, _, _, message in reader.iter_decoded_messages(topics=["/telemetry"]):
            rows.append([getattr(message, name) for name in result.telemetry])
    assert len(rows) == len(result.t)
    logged = np.array(rows)
    for i, (name, column) in enumerate(result.telemetry.items()):
        assert np.array_equal(logged[:, i], column), name


def test_the_gil_is_released_during_a_run():
    """Another Python thread keeps running (no gap over 0.25 s) while a long run goes."""
    scenario = polhode.load(REPO / "scenarios/tennis-racket.yaml")
    done = threading.Event()
    outcome = {}

    def work():
        start = time.perf_counter()
        # Long enough to last over 0.5 s on a fast machine: since the event checks skip
        # the interior points far from a crossing, 2000 s took 0.37 s here.
        outcome["result"] = scenario.run(duration=10000.0)
        outcome["seconds"] = time.perf_counter() - start
        done.set()

    ticks = []
    worker = threading.Thread(target=work)
    worker.start()
    while not done.is_set():
        ticks.append(time.perf_counter())
        # Pure Python work between ticks, holding the GIL as it goes.
        sum(i * i for i in range(2000))
    worker.join()
    assert outcome["seconds"] > 0.5, "the run must last long enough to tell"
    gaps = np.diff(ticks)
    assert len(ticks) > 10
    assert gaps.max() < 0.25, f"this thread stalled {gaps.max():.3f} s during the run"
    assert outcome["result"].status == "complete"


def test_ctrl_c_raises_keyboard_interrupt_within_a_second(tmp_path):
    script = (
        # Python's own Ctrl-C handler, as in an interactive session, even when this test
        # runs as a background job (whose shell starts it with SIGINT ignored).
        "import signal, sys, time, polhode\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        f"s = polhode.load({str(REPO / 'scenarios/tennis-racket.yaml')!r})\n"
        "print('running', flush=True)\n"
        "try:\n"
        "    s.run(duration=1.0e5)\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted', time.perf_counter(), flush=True)\n"
        "    sys.exit(3)\n"
    )
    child = subprocess.Popen(
        [sys.executable, "-c", script], stdout=subprocess.PIPE, text=True
    )
    assert child.stdout.readline().strip() == "running"
    time.sleep(0.5)
    sent = time.perf_counter()
    child.send_signal(signal.SIGINT)
    out, _ = child.communicate(timeout=30)
    assert child.returncode == 3, out
    word, when = out.split()
    assert word == "interrupted"
    assert float(when) - sent < 1.0
