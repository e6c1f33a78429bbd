#!/usr/bin/env python3
"""Basilisk peer for polhode's spring-mass slosh analog (`spring_mass_damper: {tank: ...}`):
a spinning prolate hub carrying one tank off the spin axis, whose first lateral slosh mode
polhode stands for by a mass on a spring, with the tank's non-sloshing liquid fixed in the body.
Basilisk runs the same system on spacecraft.Spacecraft (no gravity, no fuel tank), the fixed
liquid folded into the hub, the sloshing mass on one linearSpringMassDamper when it moves on one
line. Scenes:

  sphere-tangential  peers/slosh_spring.yaml as written: a half-full sphere, the mass on the
                     tangential line (k = m_s (w1^2 + W^2))
  sphere-axial       the same tank, the mass on the line parallel to the spin axis
                     (k = m_s w1^2), another start
  cylinder-damped    a 0.6-full upright cylinder on the -x side, tangential line, its damping
                     raised 20 times by damping_factor (baffles), another start
  sphere-both        the sphere with polhode's default directions [tangential, axial]: one
                     mass on two lines, another start

Basilisk's parameters are not derived here: they are what polhode derived from each tank, read
from `polhode check` (its line "spring_mass_damper NAME from its tank: ...", docs/effectors.md):
the sloshing mass, its rest point r_PB_B, the direction pHat_B, k, c, and the fixed liquid m0
and where it sits. The hub then is polhode's hub (body.mass at the origin, body.principal)
plus the point mass m0: mHub = M + m0, r_BcB_B = m0 r_f / (M + m0), IHubPntBc_B the pair's
inertia about that point. The script asserts that Basilisk's effector holds exactly these
numbers and that the hub carries the fixed liquid's mass and first moment. The polhode it calls
is target/release/polhode (build it first: peers/run.sh does), or $POLHODE.

polhode's two-direction form is one particle with two coordinates. Two linearSpringMassDampers,
one per line, would be two particles each with its own mass (the liquid counted twice, or
split, and the offsets not coupled through the one mass): not the same system. Basilisk's
linearTranslationNDOFStateEffector is: a chain of two translating bodies with frames parallel
to B, the first massless moving along line 1 from r0 (spring k1, dashpot c), the second the
sloshing mass moving along line 2 relative to the first (k2, c), puts the mass at
r0 + rho1 p1 + rho2 p2 with polhode's forces. Basilisk requires each body to have a valid
inertia tensor; as the bodies only translate, their LINK_INERTIA (1e-3 kg m^2 each) turns with
the hub and is taken off the hub's inertia, which leaves the system's unchanged.

Each scene is integrated with Basilisk's svIntegratorRKF78 (relTol 1e-13, absTol 1e-15, task
step 0.1 s) and checked against the same integrator at tolerances ten times tighter, at half
the task step, and against Basilisk's RK4 at 0.25 ms. Writes results/basilisk_slosh_spring.json:
per scene the scenario, polhode's derived parameters and Basilisk's, and at every sample (1 s
apart) the hub's omega (body), sigma_BN and its quaternion, rho and rhoDot (one per line), Basilisk's
totRotAngMomPntC_N and totRotEnergy, both also recomputed from the sampled states
(facts.outputs_against_states; totRotEnergy includes the spring's energy k rho^2 / 2).
tests/basilisk_slosh_spring.rs compares polhode with these numbers.
"""
import copy
import os
import re
import subprocess
import tempfile
import time

import numpy as np
import yaml
from Basilisk.simulation import (linearSpringMassDamper, linearTranslationNDOFStateEffector,
                                 spacecraft, svIntegrators)
from Basilisk.utilities import SimulationBaseClass, macros
from peer_common import attitude_error, compact_json

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
RESULTS = os.path.join(HERE, "results")
SCENARIO = "peers/slosh_spring.yaml"
POLHODE = os.environ.get("POLHODE", os.path.join(ROOT, "target", "release", "polhode"))
SAMPLE_EVERY = 1.0                      # s
LINK_INERTIA = 1e-3 * np.eye(3)         # kg m^2: the two-line chain's bodies (see build)
PRODUCTION = {"integrator": "RKF78", "relTol": 1e-13, "absTol": 1e-15, "task_step": 0.1}
CHECKS = [
    {"integrator": "RKF78", "relTol": 1e-14, "absTol": 1e-16, "task_step": 0.1},
    {"integrator": "RKF78", "relTol": 1e-13, "absTol": 1e-15, "task_step": 0.05},
    {"integrator": "RK4", "task_step": 2.5e-4},
]


def log(msg):
    print(f"[basilisk-slosh-spring {time.strftime('%H:%M:%S')}] {msg}", flush=True)


def scenes():
    """The scenes, as polhode scenario dictionaries."""
    with open(os.path.join(ROOT, SCENARIO)) as fh:
        main = yaml.safe_load(fh)
    out = [("sphere-tangential", "peers/slosh_spring.yaml as written", main)]
    axial = copy.deepcopy(main)
    e = axial["effectors"][0]["spring_mass_damper"]
    e["directions"] = ["axial"]
    e["initial_offset"] = -0.015
    e["initial_rate"] = 0.02
    axial["initial"]["omega"] = [-0.03, 0.06, 3.0]
    out.append(("sphere-axial", "the same tank, the mass on the axial line, another start", axial))
    cyl = copy.deepcopy(main)
    e = cyl["effectors"][0]["spring_mass_damper"]
    e["tank"]["shape"] = {"cylinder": {"radius": 0.15, "height": 0.32}}
    e["tank"]["center"] = [-1.6, 0.3, -0.25]
    e["tank"]["fill"] = 0.6
    e["tank"]["damping_factor"] = 20.0
    e["initial_offset"] = 0.008
    e["initial_rate"] = -0.05
    cyl["initial"]["omega"] = [0.04, -0.05, 3.2]
    out.append(("cylinder-damped", "a 0.6-full upright cylinder (radius 0.15 m, height 0.32 m) "
                "at [-1.6, 0.3, -0.25] m, tangential line, damping_factor 20, another start", cyl))
    both = copy.deepcopy(main)
    e = both["effectors"][0]["spring_mass_damper"]
    del e["directions"]                      # the default: [tangential, axial]
    e["initial_offset"] = [0.01, -0.012]
    e["initial_rate"] = [0.0, 0.03]
    both["initial"]["omega"] = [0.06, -0.03, 2.9]
    out.append(("sphere-both", "the same tank, the default directions [tangential, axial]: one "
                "mass on two lines, another start", both))
    return out


NUM = r"([-+0-9.eE]+)"
VEC = rf"\[{NUM}, {NUM}, {NUM}\]"
LINE = re.compile(
    rf"spring_mass_damper (\S+) from its tank: sloshing mass {NUM} kg at {VEC} m; line 1 "
    rf"direction {VEC} stiffness {NUM} N/m(?:; line 2 direction {VEC} stiffness {NUM} N/m)?; "
    rf"damping {NUM} N s/m; fixed liquid {NUM} kg at {VEC} m$")


def derived(s):
    """What polhode derived from the scene's tank, from `polhode check`."""
    with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as fh:
        yaml.safe_dump(s, fh)
        path = fh.name
    try:
        text = subprocess.run([POLHODE, "check", path], check=True, capture_output=True,
                              text=True).stdout
    finally:
        os.unlink(path)
    found = [LINE.search(line) for line in text.splitlines()]
    found = [m for m in found if m]
    assert len(found) == 1, f"one tank spring expected in:\n{text}"
    g = [None if x is None else float(x) for x in found[0].groups()[1:]]
    out = {"mass": g[0], "position": g[1:4], "direction": g[4:7], "stiffness": g[7],
           "damping": g[12], "fixed_mass": g[13], "fixed_position": g[14:17]}
    if g[8] is not None:
        out["direction_2"], out["stiffness_2"] = g[8:11], g[11]
    return out


def hub_with_liquid(s, d):
    """Basilisk's hub: polhode's hub (mass M at B, inertia I about B) and the fixed liquid m0."""
    M, m0 = float(s["body"]["mass"]), d["fixed_mass"]
    rf = np.array(d["fixed_position"])
    mh = M + m0
    c = m0 * rf / mh
    pm = lambda m, r: m * (float(r @ r) * np.eye(3) - np.outer(r, r))  # noqa: E731
    inertia = np.diag([float(x) for x in s["body"]["principal"]]) + pm(M, -c) + pm(m0, rf - c)
    return mh, c, inertia


def mrp_to_quaternion(s):
    s2 = float(s @ s)
    return np.concatenate([[(1 - s2) / (1 + s2)], 2 * s / (1 + s2)])


def quaternion_to_mrp(q):
    q = np.array(q, dtype=float)
    if q[0] < 0:
        q = -q
    return q[1:] / (1.0 + q[0])


def dcm_nb(sigma):
    """Body -> inertial direction cosines of the MRP sigma_BN."""
    s = np.array(sigma, dtype=float)
    s2 = float(s @ s)
    t = np.array([[0, -s[2], s[1]], [s[2], 0, -s[0]], [-s[1], s[0], 0]])
    c_bn = np.eye(3) + (8 * t @ t - 4 * (1 - s2) * t) / (1 + s2) ** 2
    return c_bn.T


def lines(d):
    """The mass's lines: [(direction, stiffness)], one or two."""
    out = [(np.array(d["direction"]), d["stiffness"])]
    if "direction_2" in d:
        out.append((np.array(d["direction_2"]), d["stiffness_2"]))
    return out


def initial_rho(s, d):
    """The offsets and their rates at t = 0, one per line."""
    e = s["effectors"][0]["spring_mass_damper"]
    n = len(lines(d))
    q, u = e.get("initial_offset", 0.0), e.get("initial_rate", 0.0)
    q = [float(x) for x in (q if isinstance(q, list) else [q] * n)]
    u = [float(x) for x in (u if isinstance(u, list) else [u] * n)]
    return np.array(q), np.array(u)


def mass_offset(d, rho, rho_dot):
    """The sloshing mass's position (from B) and velocity relative to the body."""
    r = np.array(d["position"], dtype=float)
    v = np.zeros(3)
    for (p, _), x, xd in zip(lines(d), rho, rho_dot):
        r = r + x * p
        v = v + xd * p
    return r, v


def centre_of_mass(s, d, rho, rho_dot, omega):
    """The system's centre of mass from B (body axes) and its velocity relative to B as seen
    in the inertial frame (body axes)."""
    M, m0, ms = float(s["body"]["mass"]), d["fixed_mass"], d["mass"]
    rs, vs = mass_offset(d, rho, rho_dot)
    total = M + m0 + ms
    c = (m0 * np.array(d["fixed_position"]) + ms * rs) / total
    return c, ms * vs / total + np.cross(omega, c)


def build(s, d, settings):
    """A fresh Basilisk simulation of scene s with the integrator settings."""
    sim = SimulationBaseClass.SimBaseClass()
    proc = sim.CreateNewProcess("dynamicsProcess")
    proc.addTask(sim.CreateNewTask("dynamicsTask", macros.sec2nano(settings["task_step"])))
    sc = spacecraft.Spacecraft()
    sc.ModelTag = "hub"
    rho0, rho_dot0 = initial_rho(s, d)
    if len(lines(d)) == 1:
        smd = linearSpringMassDamper.LinearSpringMassDamper()
        smd.massInit = d["mass"]
        smd.k = d["stiffness"]
        smd.c = d["damping"]
        smd.r_PB_B = [[x] for x in d["position"]]
        smd.pHat_B = [[x] for x in d["direction"]]
        smd.rhoInit = rho0[0]
        smd.rhoDotInit = rho_dot0[0]
    else:
        # One mass on two lines: a chain of two translating bodies, all frames parallel to B,
        # the first massless (it carries the second along line 1), the second the sloshing mass
        # (moving along line 2 relative to the first): the mass is at r0 + rho1 p1 + rho2 p2.
        smd = linearTranslationNDOFStateEffector.LinearTranslationNDOFStateEffector()
        for i, (p, k) in enumerate(lines(d)):
            body = linearTranslationNDOFStateEffector.TranslatingBody()
            body.setMass(d["mass"] if i == 1 else 0.0)
            body.setK(k)
            body.setC(d["damping"])
            body.setRhoInit(float(rho0[i]))
            body.setRhoDotInit(float(rho_dot0[i]))
            body.setFHat_P([[float(x)] for x in p])
            body.setR_FcF_F([[0.0], [0.0], [0.0]])
            body.setR_F0P_P([[float(x)] for x in (d["position"] if i == 0 else [0.0] * 3)])
            body.setIPntFc_F(LINK_INERTIA.tolist())
            body.setDCM_FP(np.eye(3).tolist())
            smd.addTranslatingBody(body)
    smd.ModelTag = "slosh"
    sc.addStateEffector(smd)
    mh, c_hub, inertia = hub_with_liquid(s, d)
    if len(lines(d)) == 2:
        # Basilisk refuses a translating body without a valid inertia tensor; the bodies do
        # not rotate relative to the hub, so each one's LINK_INERTIA about its centre of mass
        # is taken off the hub's (one about its own centre of mass, the other parallel: equal).
        inertia = inertia - 2 * LINK_INERTIA
    sc.hub.mHub = mh
    sc.hub.r_BcB_B = [[float(x)] for x in c_hub]
    sc.hub.IHubPntBc_B = inertia.tolist()
    sc.hub.r_CN_NInit = [[0.0], [0.0], [0.0]]
    sc.hub.v_CN_NInit = [[0.0], [0.0], [0.0]]
    att = s["initial"]["attitude"]
    sigma0 = quaternion_to_mrp([att[k] for k in "wxyz"])
    sc.hub.sigma_BNInit = [[float(x)] for x in sigma0]
    w0 = np.array(s["initial"]["omega"], dtype=float)
    sc.hub.omega_BN_BInit = [[float(x)] for x in w0]
    integrator = None
    if settings["integrator"] == "RKF78":
        integrator = svIntegrators.svIntegratorRKF78(sc)
        integrator.relTol = settings["relTol"]
        integrator.absTol = settings["absTol"]
        sc.setIntegrator(integrator)
    elif settings["integrator"] != "RK4":        # RK4 is Spacecraft's default
        raise ValueError(settings["integrator"])
    sim.AddModelToTask("dynamicsTask", sc)
    sim.InitializeSimulation()
    dm = sc.dynManager
    states = {
        "omega": dm.getStateObject(sc.hub.nameOfHubOmega),
        "sigma": dm.getStateObject(sc.hub.nameOfHubSigma),
        "r": dm.getStateObject(sc.hub.nameOfHubPosition),
        "v": dm.getStateObject(sc.hub.nameOfHubVelocity),
    }
    if len(lines(d)) == 1:
        states.update({
            "rho": dm.getStateObject(smd.nameOfRhoState),
            "rho_dot": dm.getStateObject(smd.nameOfRhoDotState),
            "mass": dm.getStateObject(smd.nameOfMassState),
        })
    else:
        states.update({
            "rho": dm.getStateObject(smd.getNameOfRhoState()),
            "rho_dot": dm.getStateObject(smd.getNameOfRhoDotState()),
        })
    # The system's centre of mass at rest at the origin, as in polhode: the hub's inertial
    # position and velocity (of B) set from the states at t = 0.
    c, cdot = centre_of_mass(s, d, rho0, rho_dot0, w0)
    C = dcm_nb(sigma0)
    states["r"].setState([[float(x)] for x in -C @ c])
    states["v"].setState([[float(x)] for x in -C @ cdot])
    sc.updateSCMassProps(0.0)
    sc.computeEnergyMomentum(0.0)
    return sim, sc, smd, states


def read(sc, states):
    g = {k: np.array(v.getState(), dtype=float).ravel() for k, v in states.items()}
    return {
        "omega": g["omega"], "sigma": g["sigma"], "q": mrp_to_quaternion(g["sigma"]),
        "rho": g["rho"], "rho_dot": g["rho_dot"],
        "h_inertial": np.array(sc.totRotAngMomPntC_N, dtype=float).ravel(),
        "energy": float(sc.totRotEnergy), "mass": float(g["mass"][0]) if "mass" in g else None,
        "r_hub": g["r"], "v_hub": g["v"],
    }


def momentum_and_energy(s, d, o):
    """H about the system's centre of mass (inertial axes), the kinetic energy relative to it
    and the spring's energy, from the sampled states alone (polhode's hub, the fixed liquid
    and the sloshing mass as three bodies)."""
    M, m0, ms = float(s["body"]["mass"]), d["fixed_mass"], d["mass"]
    inertia = np.diag([float(x) for x in s["body"]["principal"]])
    w = o["omega"]
    c, cdot = centre_of_mass(s, d, o["rho"], o["rho_dot"], w)
    rf = np.array(d["fixed_position"])
    rs, vs = mass_offset(d, o["rho"], o["rho_dot"])
    v_b = -cdot                                   # B relative to the centre of mass
    v_f = v_b + np.cross(w, rf)
    v_s = v_b + np.cross(w, rs) + vs
    h = inertia @ w + M * np.cross(-c, v_b) + m0 * np.cross(rf - c, v_f) + ms * np.cross(rs - c, v_s)
    t = 0.5 * w @ inertia @ w + 0.5 * (M * v_b @ v_b + m0 * v_f @ v_f + ms * v_s @ v_s)
    spring = sum(0.5 * k * x * x for (_, k), x in zip(lines(d), o["rho"]))
    return dcm_nb(o["sigma"]) @ h, float(t), float(spring)


def run(s, d, settings, times):
    """The samples of scene s at the given times, and facts about the run."""
    sim, sc, smd, states = build(s, d, settings)
    n = len(lines(d))
    out = [read(sc, states)]
    t0 = time.perf_counter()
    for t in times[1:]:
        sim.ConfigureStopTime(macros.sec2nano(t))
        sim.ExecuteSimulation()
        out.append(read(sc, states))
    wall = time.perf_counter() - t0
    last = out[-1]
    c, _ = centre_of_mass(s, d, last["rho"], np.zeros(n), np.zeros(3))
    facts = {
        "wall_seconds": wall,
        "mass_at_end": last["mass"],
        "centre_of_mass_at_end": [float(x) for x in last["r_hub"] + dcm_nb(last["sigma"]) @ c],
        "max_abs_rho": float(max(np.max(np.abs(o["rho"])) for o in out)),
        "effector_as_set": as_set(smd, n),
        "hub_inertia_as_set": np.array(sc.hub.IHubPntBc_B, dtype=float).tolist(),
    }
    by_hand = [momentum_and_energy(s, d, o) for o in out]
    facts["outputs_against_states"] = {
        "h_relative": max(float(np.linalg.norm(h - o["h_inertial"]) / np.linalg.norm(o["h_inertial"]))
                          for (h, _, _), o in zip(by_hand, out)),
        "energy_relative (totRotEnergy against kinetic + spring)":
            max(abs(t + v - o["energy"]) / o["energy"] for (_, t, v), o in zip(by_hand, out)),
    }
    for o, (_, t, v) in zip(out, by_hand):
        o["kinetic"], o["spring"] = t, v
    return out, facts


def as_set(smd, n):
    """What Basilisk's effector holds, in the form of polhode's derived parameters."""
    col = lambda v: [float(x) for x in np.array(v).ravel()]  # noqa: E731
    if n == 1:
        return {"mass": float(smd.massInit), "position": col(smd.r_PB_B),
                "direction": col(smd.pHat_B), "stiffness": float(smd.k), "damping": float(smd.c)}
    b = [smd.getTranslatingBody(i) for i in range(n)]
    assert b[0].getMass() == 0.0 and col(b[1].getR_F0P_P()) == [0.0] * 3
    assert b[0].getC() == b[1].getC()
    assert all(col(x.getDCM_FP()) == col(np.eye(3)) and col(x.getIPntFc_F()) == col(LINK_INERTIA)
               and not any(col(x.getR_FcF_F())) for x in b)
    return {"mass": float(b[1].getMass()), "position": col(b[0].getR_F0P_P()),
            "direction": col(b[0].getFHat_P()), "stiffness": float(b[0].getK()),
            "direction_2": col(b[1].getFHat_P()), "stiffness_2": float(b[1].getK()),
            "damping": float(b[1].getC())}


def differences(a, b):
    """Largest differences between two runs' samples."""
    h = max(float(np.linalg.norm(o["h_inertial"])) for o in b)
    e = max(o["energy"] for o in b)
    return {
        "omega": max(float(np.linalg.norm(x["omega"] - y["omega"])) for x, y in zip(a, b)),
        "attitude": max(attitude_error(x["q"], y["q"]) for x, y in zip(a, b)),
        "rho": max(float(np.max(np.abs(x["rho"] - y["rho"]))) for x, y in zip(a, b)),
        "rho_dot": max(float(np.max(np.abs(x["rho_dot"] - y["rho_dot"]))) for x, y in zip(a, b)),
        "h_relative": max(float(np.linalg.norm(x["h_inertial"] - y["h_inertial"])) for x, y in zip(a, b)) / h,
        "energy_relative": max(abs(x["energy"] - y["energy"]) for x, y in zip(a, b)) / e,
    }


def settings_label(st):
    if st["integrator"] == "RKF78":
        return f"RKF78 relTol {st['relTol']:g} absTol {st['absTol']:g}, task step {st['task_step']:g} s"
    return f"RK4 step {st['task_step']:g} s"


def main():
    wall0 = time.time()
    os.makedirs(RESULTS, exist_ok=True)
    from importlib.metadata import version
    bsk_version = version("bsk")
    out_scenes = []
    for name, what, s in scenes():
        d = derived(s)
        duration = float(s["duration"])
        n = int(round(duration / SAMPLE_EVERY))
        times = [SAMPLE_EVERY * k for k in range(n + 1)]
        samples, facts = run(s, d, PRODUCTION, times)
        # The scene Basilisk ran is polhode's: its effector holds the derived numbers exactly,
        # and the whole liquid (m_s + m0) is where polhode puts it.
        a = facts["effector_as_set"]
        assert all(a[k] == d[k] for k in a), (a, d)
        mh, c_hub, _ = hub_with_liquid(s, d)
        assert abs(mh - float(s["body"]["mass"]) - d["fixed_mass"]) <= 1e-12 * mh
        assert np.allclose(mh * c_hub, d["fixed_mass"] * np.array(d["fixed_position"]), rtol=1e-15, atol=1e-15)
        assert facts["mass_at_end"] in (None, d["mass"]), "Basilisk's sloshing mass changed"
        checks = []
        for st in CHECKS:
            other, other_facts = run(s, d, st, times)
            diff = differences(samples, other)
            checks.append({"against": settings_label(st), "settings": st, "max_difference": diff,
                           "wall_seconds": other_facts["wall_seconds"]})
            log(f"{name}: production vs {settings_label(st)}: |dw| {diff['omega']:.1e} rad/s, "
                f"att {diff['attitude']:.1e} rad, rho {diff['rho']:.1e} m, rhodot {diff['rho_dot']:.1e} m/s, "
                f"H {diff['h_relative']:.1e}, E {diff['energy_relative']:.1e} (relative)")
        h0 = samples[0]["h_inertial"]
        log(f"{name}: derived {d}")
        log(f"{name}: outputs against the states: {facts['outputs_against_states']}")
        log(f"{name}: max |rho| {facts['max_abs_rho']:.4f} m; "
            f"H drift {max(float(np.linalg.norm(o['h_inertial'] - h0)) for o in samples) / np.linalg.norm(h0):.1e}; "
            f"E {samples[0]['energy']:.6f} -> {samples[-1]['energy']:.6f} J; {facts['wall_seconds']:.2f} s")
        rho0, rho_dot0 = initial_rho(s, d)
        out_scenes.append({
            "name": name,
            "what": what,
            "scenario": s,
            "polhode_derived": d,
            "basilisk_parameters": {
                "hub.mHub": mh,
                "hub.r_BcB_B": [float(x) for x in c_hub],
                "hub.IHubPntBc_B": facts["hub_inertia_as_set"],
                "hub.omega_BN_BInit": [float(x) for x in s["initial"]["omega"]],
                "hub.sigma_BNInit": [float(x) for x in quaternion_to_mrp(
                    [s["initial"]["attitude"][k] for k in "wxyz"])],
                "effector": ("linearSpringMassDamper" if len(lines(d)) == 1 else
                             "linearTranslationNDOFStateEffector: two bodies, the first massless"),
                **{k: v for k, v in facts["effector_as_set"].items()},
                "rhoInit": [float(x) for x in rho0], "rhoDotInit": [float(x) for x in rho_dot0],
                "fuel tank": None,
            },
            "facts": facts,
            "convergence": checks,
            "samples": [{
                "t": t,
                "omega": [float(x) for x in o["omega"]],
                "sigma_BN": [float(x) for x in o["sigma"]],
                "quaternion": [float(x) for x in o["q"]],
                "rho": [float(x) for x in o["rho"]], "rho_dot": [float(x) for x in o["rho_dot"]],
                "h_inertial": [float(x) for x in o["h_inertial"]],
                "energy": o["energy"],
            } for t, o in zip(times, samples)],
        })
    out = {
        "basilisk": bsk_version,
        "module": "linearSpringMassDamper (one line) or linearTranslationNDOFStateEffector (two "
                  "lines, a massless first body) on spacecraft.Spacecraft, no gravity, no fuel "
                  "tank; the fixed liquid in the hub",
        "integrator": {**PRODUCTION, "label": settings_label(PRODUCTION)},
        "sample_every": SAMPLE_EVERY,
        "quaternion": "[w, x, y, z] of the rotation sigma_BN (body -> inertial, as polhode's attitude)",
        "h_inertial": "Basilisk's totRotAngMomPntC_N: angular momentum about the system's centre of mass, N frame",
        "energy": "Basilisk's totRotEnergy: kinetic energy relative to the system's centre of mass "
                  "plus the spring's k rho^2 / 2",
        "scenes": out_scenes,
        "wall_seconds": time.time() - wall0,
    }
    with open(os.path.join(RESULTS, "basilisk_slosh_spring.json"), "w") as fh:
        fh.write(compact_json(out) + "\n")
    log("wrote results/basilisk_slosh_spring.json")


if __name__ == "__main__":
    main()
