"""Result.telemetry against `polhode run --csv`, Result.to_pandas and units, and how the arrays
are held."""

import csv
import subprocess
import sys

import numpy as np
import pytest

import polhode
from conftest import REPO

# Scenarios with effectors: a despun platform (a wheel with a motor) and a spring-mass damper;
# a wheel damper; a nutation damper.
WITH_EFFECTORS = [
    ("scenarios/dual-spin-rotor-damper.yaml", []),
    ("scenarios/wheel-damper.yaml", ["--duration", "100"]),
    ("scenarios/nutation-damper.yaml", ["--duration", "20"]),
]


def read_cli_csv(path):
    """The CLI's sample table: plain column names (the header's ` [unit]` cut) and floats."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    names = [h.rsplit(" [", 1)[0] if h.endswith("]") else h for h in rows[0]]
    values = np.array([[float(v) for v in row] for row in rows[1:]])
    return names, values


@pytest.mark.parametrize("scenario,options", WITH_EFFECTORS, ids=[w[0] for w in WITH_EFFECTORS])
def test_telemetry_equals_the_cli_csv_bit_for_bit(polhode_cli, tmp_path, scenario, options):
    out = tmp_path / "samples.csv"
    subprocess.run(
        [str(polhode_cli), "run", str(REPO / scenario), "--no-log", "--quiet", "--csv", str(out)]
        + options,
        check=True,
    )
    names, values = read_cli_csv(out)
    kwargs = {"duration": float(options[1])} if options else {}
    result = polhode.load(REPO / scenario).run(**kwargs)
    assert list(result.telemetry) == names
    assert any("." in n for n in names), "the scenario must have effector columns"
    assert len(result.t) == len(values)
    for k, name in enumerate(names):
        # Bit for bit: the CSV holds Rust's shortest round-trip text of each double.
        assert np.array_equal(result.telemetry[name], values[:, k]), name


def test_effector_columns_are_prefixed_by_the_effector_name():
    result = polhode.load(REPO / "scenarios/dual-spin-rotor-damper.yaml").run(duration=10.0)
    effector_columns = [n for n in result.telemetry if "." in n]
    assert {n.split(".")[0] for n in effector_columns} == {"platform", "damper"}
    assert "damper.offset" in result.telemetry and "platform.rate" in result.telemetry


def test_to_pandas_columns_are_the_cli_csv_header_and_its_values(polhode_cli, tmp_path):
    """The DataFrame is the CLI's --csv table: the same header (units in it), the same numbers."""
    pd = pytest.importorskip("pandas")
    out = tmp_path / "samples.csv"
    subprocess.run(
        [str(polhode_cli), "run", str(REPO / "scenarios/dual-spin-rotor-damper.yaml"),
         "--no-log", "--quiet", "--csv", str(out), "--duration", "10"],
        check=True,
    )
    with open(out, newline="") as f:
        rows = list(csv.reader(f))
    header = rows[0]
    values = np.array([[float(v) for v in row] for row in rows[1:]])
    assert "omega_x [rad/s]" in header and "damper.offset [m]" in header

    result = polhode.load(REPO / "scenarios/dual-spin-rotor-damper.yaml").run(duration=10.0)
    frame = result.to_pandas()
    assert isinstance(frame, pd.DataFrame)
    assert list(frame.columns) == header
    assert len(frame) == len(values)
    for k, name in enumerate(header):
        assert np.array_equal(frame[name].to_numpy(), values[:, k]), name
    # A copy: changing the frame leaves the result alone.
    frame.iloc[0, 1] = 123.0
    assert result.omega[0, 0] != 123.0


def test_to_pandas_without_units_has_the_bare_names():
    pytest.importorskip("pandas")
    result = polhode.load(REPO / "scenarios/nutation-damper.yaml").run(duration=2.0)
    frame = result.to_pandas(units=False)
    assert list(frame.columns) == list(result.telemetry)
    for name, column in result.telemetry.items():
        assert np.array_equal(frame[name].to_numpy(), column), name
    with pytest.raises(TypeError, match=r"^Result\.to_pandas\(\): units must be True or False"):
        result.to_pandas(units="yes")


def test_units_are_those_of_the_logs_doc():
    result = polhode.load(REPO / "scenarios/dual-spin-rotor-damper.yaml").run(duration=1.0)
    assert list(result.units) == list(result.telemetry)
    # docs/logs.md's table.
    assert result.units["sim_time"] == "s"
    assert result.units["omega_x"] == "rad/s"
    assert result.units["h_norm"] == "N m s"
    assert result.units["kinetic_energy"] == "J"
    assert result.units["damper.offset"] == "m"
    assert result.units["platform.rate"] == "rad/s"


def test_to_pandas_without_pandas_says_what_to_install(tmp_path):
    # A child interpreter in which `import pandas` fails.
    script = (
        "import sys\n"
        "sys.modules['pandas'] = None\n"
        "import polhode\n"
        f"r = polhode.load({str(REPO / 'scenarios/tennis-racket.yaml')!r}).run(duration=0.1)\n"
        "try:\n"
        "    r.to_pandas()\n"
        "except ImportError as e:\n"
        "    print(e)\n"
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True)
    assert "Result.to_pandas() needs pandas" in out.stdout
    assert "pip install pandas" in out.stdout
    assert 'pip install "./python[all]"' in out.stdout


def root_of(array):
    """The object at the end of an array's `.base` chain, and the last ndarray before it."""
    last = array
    while isinstance(last.base, np.ndarray):
        last = last.base
    return last.base, last


def test_arrays_are_views_of_one_buffer_owned_by_rust():
    """No copy: t, omega, q and every telemetry column are views of the one float64 buffer the
    run filled, which numpy holds through the Rust container it was handed, not its own."""
    result = polhode.load(REPO / "scenarios/dual-spin-rotor-damper.yaml").run(duration=50.0)
    n, width = len(result.t), len(result.telemetry)
    container, block = root_of(result.t)
    assert type(container).__name__ == "PySliceContainer"  # the numpy crate's owner of a Vec
    assert not block.flags.owndata
    # The Vec as numpy received it: the columns back to back, nothing more.
    assert block.shape == (width * n,) and block.dtype == np.float64
    assert block.nbytes == width * n * 8
    for array in [result.omega, result.q, *result.telemetry.values()]:
        assert root_of(array)[0] is container
    # The arrays are the buffer's rows: the same memory, not equal copies of it.
    assert np.shares_memory(result.omega, result.telemetry["omega_x"])
    assert result.omega.ctypes.data == result.telemetry["omega_x"].ctypes.data
    assert result.q.ctypes.data == result.telemetry["q_w"].ctypes.data
    assert result.t.ctypes.data == result.telemetry["sim_time"].ctypes.data
    k = list(result.telemetry).index("damper.offset")
    assert result.telemetry["damper.offset"].ctypes.data == block.ctypes.data + k * n * 8
    assert np.array_equal(result.omega[:, 2], result.telemetry["omega_z"])


MEMORY_SCRIPT = """
import json, resource, sys
import polhode

def rss_kib():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])

scenario = polhode.load(sys.argv[1])
scenario.run(duration=0.01)  # load everything once
before = rss_kib()
result = scenario.run(duration=float(sys.argv[2]))
after = rss_kib()
n = len(result.t)
width = len(result.telemetry)
print(json.dumps({"n": n, "width": width, "raw": n * width * 8, "held": (after - before) * 1024}))
"""


def test_a_large_result_holds_at_most_1_2_times_its_raw_size(tmp_path):
    """Resident memory after a 300 000-sample run, less before: at most 1.2 x n x columns x 8
    bytes (python/benchmarks/memory.py measures 10^6 samples)."""
    import json

    script = tmp_path / "memory.py"
    script.write_text(MEMORY_SCRIPT)
    out = subprocess.run(
        [sys.executable, str(script), str(REPO / "scenarios/tennis-racket.yaml"), "3000"],
        capture_output=True, text=True, check=True,
    )
    m = json.loads(out.stdout)
    assert m["n"] == 300_001
    assert m["held"] <= 1.2 * m["raw"], m
    assert m["held"] >= 0.9 * m["raw"], m  # the measurement sees the arrays at all
