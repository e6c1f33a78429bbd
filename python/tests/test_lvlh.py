"""Result.q_lvlh, lvlh_rpy and omega_lvlh: the attitude relative to LVLH of a scenario in orbit.

Checked against the log's /orbit channel decoded by the mcap packages (bit for bit), and
against the same quantities computed here from the body attitude and rates and the logged
orbit position and velocity; `None` for a scenario without an orbit.
"""

import numpy as np

import polhode
from conftest import REPO

GG = REPO / "scenarios/gravity-gradient-smallsat.yaml"


def orbit_messages(log):
    """The /orbit messages of a log as a dict of arrays, by field name."""
    from mcap import reader as mcap_reader
    from mcap_protobuf import decoder

    columns = {}
    with open(log, "rb") as f:
        reader = mcap_reader.make_reader(f, decoder_factories=[decoder.DecoderFactory()])
        for _, _, _, message in reader.iter_decoded_messages(topics=["/orbit"]):
            for field in message.DESCRIPTOR.fields:
                columns.setdefault(field.name, []).append(getattr(message, field.name))
    return {name: np.array(values) for name, values in columns.items()}


def rotation(q):
    """Rotation matrices (n, 3, 3) of scalar-first unit quaternions (n, 4), Hamilton."""
    w, x, y, z = q.T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        -2,
    )


def test_lvlh_arrays_equal_the_logs_orbit_channel(tmp_path):
    log = tmp_path / "gg.mcap"
    result = polhode.load(GG).run(duration=600.0, log=log)
    orbit = orbit_messages(log)
    n = len(result.t)
    assert result.q_lvlh.shape == (n, 4)
    assert result.lvlh_rpy.shape == (n, 3)
    assert result.omega_lvlh.shape == (n, 3)
    for k, axis in enumerate("wxyz"):
        assert np.array_equal(result.q_lvlh[:, k], orbit[f"q_lvlh_{axis}"])
    for k, angle in enumerate(["roll_deg", "pitch_deg", "yaw_deg"]):
        assert np.array_equal(result.lvlh_rpy[:, k], orbit[angle])
        # The same numbers are the `polhode run --csv` columns, under the /orbit names.
        assert np.shares_memory(result.lvlh_rpy, result.telemetry[angle])
        assert np.array_equal(result.telemetry[angle], orbit[angle])
    for k, axis in enumerate("xyz"):
        assert np.array_equal(result.omega_lvlh[:, k], orbit[f"omega_lvlh_{axis}"])


def test_lvlh_angles_and_rates_from_the_attitude_and_the_orbit(tmp_path):
    """Recomputed from q_NB, ω_BN and the logged r, v: the LVLH axes o3 = −r̂ (nadir),
    o2 = −ĥ, o1 = o2 × o3; R_OB = C_ON R_NB = R_z(yaw) R_y(pitch) R_x(roll); the frame's rate
    of the two-body orbit r × v / |r|²; ω_BO = ω_BN − R_NBᵀ ω_ON."""
    log = tmp_path / "gg.mcap"
    result = polhode.load(GG).run(duration=17400.0, log=log)
    orbit = orbit_messages(log)
    r = np.stack([orbit[f"r_eci_{a}"] for a in "xyz"], -1)
    v = np.stack([orbit[f"v_eci_{a}"] for a in "xyz"], -1)
    h = np.cross(r, v)
    o3 = -r / np.linalg.norm(r, axis=1)[:, None]
    o2 = -h / np.linalg.norm(h, axis=1)[:, None]
    o1 = np.cross(o2, o3)
    c_on = np.stack([o1, o2, o3], -2)
    r_nb = rotation(result.q)
    r_ob = c_on @ r_nb
    roll = np.degrees(np.arctan2(r_ob[:, 2, 1], r_ob[:, 2, 2]))
    pitch = np.degrees(-np.arcsin(np.clip(r_ob[:, 2, 0], -1, 1)))
    yaw = np.degrees(np.arctan2(r_ob[:, 1, 0], r_ob[:, 0, 0]))
    expect = np.stack([roll, pitch, yaw], -1)
    assert np.max(np.abs(result.lvlh_rpy - expect)) < 1e-8
    # The librating smallsat stays within tens of degrees of LVLH over the 3 orbits.
    assert np.max(np.abs(result.lvlh_rpy[:, :2])) < 60.0
    w_on = h / np.sum(r * r, axis=1)[:, None]
    w_on_body = np.einsum("nji,nj->ni", r_nb, w_on)
    expect = result.omega - w_on_body
    assert np.max(np.abs(result.omega_lvlh - expect)) < 1e-12
    # Relative to LVLH the body turns slowly; inertially it turns once per orbit, ~1.1e-3 rad/s.
    assert np.max(np.abs(result.omega_lvlh)) < 0.5 * np.max(np.linalg.norm(result.omega, axis=1))


def test_without_an_orbit_there_is_no_lvlh():
    result = polhode.load(REPO / "scenarios/tennis-racket.yaml").run(duration=1.0)
    assert result.q_lvlh is None
    assert result.lvlh_rpy is None
    assert result.omega_lvlh is None
    assert not any("lvlh" in name or name == "roll_deg" for name in result.telemetry)
