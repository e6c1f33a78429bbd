"""SciPy peer: the benchmark problems as a SciPy user would write them, timed with solve_ivp.

Rigid bodies: Euler's equations and q' = 1/2 q (x) (0, w) in plain numpy (state [w, q], the
same as polhode's). Nutation damper and Explorer 1: the right-hand sides of the project's
independent reference models (tests/reference/*.py: sympy.physics.mechanics, Kane's method,
hub translation as generalised speeds), wrapped here into a state [w, q, ...].

Every model returns (y0, rhs, extract) where extract(y) gives (w_hub, q) from a final state.
"""
import os
import sys
import time

import numpy as np
import yaml
from scipy.integrate import solve_ivp

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
# The reference models are imported from tests/reference/; leave no bytecode there.
sys.dont_write_bytecode = True
sys.path.insert(0, os.path.join(ROOT, "tests", "reference"))


def load_yaml(path):
    with open(path) as fh:
        return yaml.safe_load(fh)


def rigid_model(scenario_path):
    """Torque-free rigid body from a polhode scenario (inertia matrix or principal moments)."""
    s = load_yaml(scenario_path)
    body = s["body"]
    if "inertia" in body:
        inertia = np.array(body["inertia"], dtype=float)
        if inertia.ndim == 1:
            inertia = np.diag(inertia)
    else:
        inertia = np.diag(np.array(body["principal"], dtype=float))
    if s.get("effectors"):
        raise ValueError(f"{scenario_path}: not a rigid body")
    init = s["initial"]
    if "omega" in init:
        w0 = np.array(init["omega"], dtype=float)
    else:
        w0 = np.array(init["omega_rpm"], dtype=float) * 2 * np.pi / 60
    att = init.get("attitude", {"w": 1.0, "x": 0.0, "y": 0.0, "z": 0.0})
    q0 = np.array([att["w"], att["x"], att["y"], att["z"]], dtype=float)
    inv = np.linalg.inv(inertia)

    # Written the way a careful numpy user would: the cross product by components (np.cross on
    # 3-vectors costs ~5x the whole right-hand side), matrix-vector products by numpy.
    def rhs(t, y):
        w1, w2, w3, q0_, q1, q2, q3 = y
        h = inertia @ y[:3]
        wd = inv @ np.array([h[1] * w3 - h[2] * w2, h[2] * w1 - h[0] * w3, h[0] * w2 - h[1] * w1])
        out = np.empty(7)
        out[:3] = wd
        out[3] = 0.5 * (-q1 * w1 - q2 * w2 - q3 * w3)
        out[4] = 0.5 * (q0_ * w1 + q2 * w3 - q3 * w2)
        out[5] = 0.5 * (q0_ * w2 + q3 * w1 - q1 * w3)
        out[6] = 0.5 * (q0_ * w3 + q1 * w2 - q2 * w1)
        return out

    y0 = np.concatenate([w0, q0])
    return y0, rhs, lambda y: (y[:3], y[3:7])


def quat_rate(q, w):
    q0, q1, q2, q3 = q
    w1, w2, w3 = w
    return 0.5 * np.array([
        -q1 * w1 - q2 * w2 - q3 * w3,
        q0 * w1 + q2 * w3 - q3 * w2,
        q0 * w2 + q3 * w1 - q1 * w3,
        q0 * w3 + q1 * w2 - q2 * w1,
    ])


def multibody_model(module, nq, damping_rate, total_mass, momentum0, derived=None, omega0=None):
    """State [q (4), joint coordinates (nq), generalised speeds u (nu), dissipated energy]
    from a reference module with derive() -> (fM, fF, fKE), P, OMEGA0, NU and mechanics().
    `derived` is (fM, fF) if already derived, `omega0` the hub's initial rate if not OMEGA0."""
    fM, fF = derived if derived is not None else module.derive()[:2]
    omega0 = module.OMEGA0 if omega0 is None else np.asarray(omega0, dtype=float)
    nu = module.NU
    iq, ic, iu = 0, 4, 4 + nq
    ie = iu + nu
    n = ie + 1

    def rhs(t, y):
        c = y[ic:ic + nq]
        u = y[iu:iu + nu]
        M = np.array(fM(c)).reshape(nu, nu)
        ud = np.linalg.solve(M, np.array(fF(c, u)))
        dy = np.empty(n)
        dy[iq:iq + 4] = quat_rate(y[iq:iq + 4], u[:3])
        dy[ic:ic + nq] = u[6:]
        dy[iu:iu + nu] = ud
        dy[ie] = damping_rate(u)
        return dy

    # Initial state: coordinates and rates zero, attitude identity, hub velocity such that the
    # total linear momentum is zero (the system's centre of mass stays put, as in polhode).
    v0 = -momentum0 / total_mass
    y0 = np.zeros(n)
    y0[iq] = 1.0
    y0[iu:iu + nu] = np.concatenate([omega0, v0, np.zeros(nu - 6)])
    return y0, rhs, lambda y: (y[iu:iu + 3], y[iq:iq + 4])


def nutation_damper_model(scenario_path):
    import nutation_damper as nd
    s = load_yaml(scenario_path)
    e = s["effectors"][0]["spring_mass_damper"]
    # The reference module's parameters must be the scenario's.
    assert abs(s["body"]["mass"] - nd.P["m_bus"]) < 1e-12
    assert np.allclose(s["body"]["principal"], nd.P["I_bus"])
    assert abs(e["mass"] - nd.P["m_p"]) < 1e-12 and np.allclose(e["position"], nd.P["r0"])
    assert abs(e["stiffness"] - nd.P["k"]) < 1e-12 and abs(e["damping"] - nd.P["c"]) < 1e-12
    assert np.allclose(e["direction"], [0, 0, 1]) and np.allclose(s["initial"]["omega"], nd.OMEGA0)
    c = nd.P["c"]
    p0 = nd.mechanics(0.0, nd.OMEGA0, np.zeros(3), 0.0)["P"]
    return multibody_model(nd, 1, lambda u: c * u[6] ** 2, nd.P["m_bus"] + nd.P["m_p"], p0)


_derived = {}


def nutation_damper_draw_model(omega0, damping):
    """The nutation damper of nutation_damper_model with another initial hub rate `omega0`
    (rad/s, hub axes) and dashpot `damping` (N s/m): one draw of the scenario's campaign.
    The equations are derived once (sympy, a few seconds) at the reference damping c0. The
    damping enters Kane's equations only through the generalised active force of the damper's
    speed, -k rho - c u_rho (nutation_damper.derive asserts this form), so the forcing at c is
    the forcing at c0 with -(c - c0) u_rho added to that row."""
    import nutation_damper as nd
    if "nutation_damper" not in _derived:
        _derived["nutation_damper"] = nd.derive()[:2]
    fM, fF0 = _derived["nutation_damper"]
    dc = float(damping) - nd.P["c"]

    def fF(coords, u):
        f = list(fF0(coords, u))
        f[6] -= dc * u[6]
        return f

    omega0 = np.asarray(omega0, dtype=float)
    p0 = nd.mechanics(0.0, omega0, np.zeros(3), 0.0)["P"]
    return multibody_model(nd, 1, lambda u: damping * u[6] ** 2, nd.P["m_bus"] + nd.P["m_p"], p0,
                           derived=(fM, fF), omega0=omega0)


def explorer1_model(scenario_path):
    import explorer1_multibody as ex
    s = load_yaml(scenario_path)
    e = s["effectors"][0]["hinged_rod"]
    assert abs(s["body"]["mass"] - ex.P["m_hub"]) < 1e-12
    assert np.allclose(s["body"]["principal"], [ex.P["Ix_hub"], ex.P["Ix_hub"], ex.P["Iz_hub"]],
                       rtol=1e-14), "the hull inertia must be the reference model's to full precision"
    assert abs(e["mass"] - ex.P["m_rod"]) < 1e-12 and abs(e["length"] - ex.P["len_rod"]) < 1e-12
    assert abs(e["stiffness"] - ex.P["k"]) < 1e-12 and abs(e["damping"] - ex.P["c"]) < 1e-12
    assert np.allclose(s["initial"]["omega"], ex.OMEGA0)
    c = ex.P["c"]
    z = np.zeros(ex.NQ)
    p0 = ex.mechanics(z, ex.OMEGA0, np.zeros(3), z)["P"]
    return multibody_model(ex, ex.NQ, lambda u: c * np.sum(u[6:] ** 2),
                           ex.P["m_hub"] + ex.NROD * ex.P["m_rod"], p0)


MODELS = {"rigid": rigid_model, "nutation_damper": nutation_damper_model,
          "explorer1": explorer1_model}
_cache = {}


def model(kind, scenario_path):
    key = (kind, scenario_path)
    if key not in _cache:
        _cache[key] = MODELS[kind](scenario_path)
    return _cache[key]


def solve(kind, scenario_path, duration, method, rtol, atol, repeats):
    """Times solve_ivp (wall clock, as polhode measures; minimum over repeats) and returns a dict shaped like
    `polhode bench point`'s output, with the final hub w and q."""
    y0, rhs, extract = model(kind, scenario_path)
    calls = [0]

    def counted(t, y):
        calls[0] += 1
        return rhs(t, y)

    times = []
    sol = None
    for _ in range(repeats):
        calls[0] = 0
        c0 = time.perf_counter()
        sol = solve_ivp(counted, (0.0, duration), y0, method=method, rtol=rtol, atol=atol)
        times.append(time.perf_counter() - c0)
        if not sol.success:
            raise RuntimeError(f"solve_ivp {method} failed: {sol.message}")
    w, q = extract(sol.y[:, -1])
    return {
        "method": method, "settings": {"rtol": rtol, "atol": atol}, "duration": duration,
        "final_time": float(sol.t[-1]), "dim": len(y0),
        "final_omega": [float(x) for x in w], "final_q": [float(x) for x in q],
        "cpu_seconds": min(times), "cpu_seconds_all": times,
        "steps": int(len(sol.t) - 1), "rhs_evaluations": int(sol.nfev),
        "rhs_calls_counted": calls[0], "jacobian_evaluations": int(sol.njev),
        "lu_decompositions": int(sol.nlu),
    }
