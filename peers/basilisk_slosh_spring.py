#!/usr/bin/env python3
"""Basilisk peer for polhode's spring-mass slosh analog (`spring_mass_damper: {tank: ...}`):
a spinning prolate hub carrying one tank off the spin axis, whose first lateral slosh mode
polhode stands for by a mass on a spring, with the tank's non-sloshing liquid fixed in the body.
Basilisk runs the same system as one linearSpringMassDamper state effector on
spacecraft.Spacecraft (no gravity, no fuel tank), the fixed liquid folded into the hub. Scenes:

  sphere-tangential  peers/slosh_spring.yaml as written: a half-full sphere, the mass on the
                     tangential line (k = m_s (w1^2 + W^2))
  sphere-axial       the same tank, the mass on the line parallel to the spin axis
                     (k = m_s w1^2), another start
  cylinder-damped    a 0.6-full upright cylinder on the -x side, tangential line, its damping
                     raised 20 times by damping_factor (baffles), another start

Basilisk's parameters are not derived here: they are what polhode derived from each tank, read
from `polhode check` (its line "spring_mass_damper NAME from its tank: ...", docs/effectors.md):
the sloshing mass, its rest point r_PB_B, the direction pHat_B, k, c, and the fixed liquid m0
and where it sits. The hub then is polhode's hub (body.mass at the origin, body.principal)
plus the point mass m0: mHub = M + m0, r_BcB_B = m0 r_f / (M + m0), IHubPntBc_B the pair's
inertia about that point. The script asserts that Basilisk's effector holds exactly these
numbers and that the system's mass and centre of mass at t = 0 are the scene's.

polhode's two-direction form (directions: [tangential, axial], the default) is one particle
with two coordinates. Two linearSpringMassDampers, one per line, would be two particles each
with its own mass: the liquid counted twice (or split), and no inertial coupling of the two
offsets; it is not the same system, so it is not compared (docs/peers.md).

Each scene is integrated with Basilisk's svIntegratorRKF78 (relTol 1e-13, absTol 1e-15, task
step 0.1 s) and checked against the same integrator at tolerances ten times tighter, at half
the task step, and against Basilisk's RK4 at 0.5 ms. Writes results/basilisk_slosh_spring.json:
per scene the scenario, polhode's derived parameters and Basilisk's, and at every sample (1 s
apart) the hub's omega (body), sigma_BN and its quaternion, rho and rhoDot, Basilisk's
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
from Basilisk.simulation import linearSpringMassDamper, spacecraft, svIntegrators
from Basilisk.utilities import SimulationBaseClass, macros
from peer_common import attitude_error, compact_json

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
RESULTS = os.path.join(HERE, "results")
SCENARIO = "peers/slosh_spring.yaml"
POLHODE = os.environ.get("POLHODE", os.path.join(ROOT, "target", "release", "polhode"))
SAMPLE_EVERY = 1.0                      # s
PRODUCTION = {"integrator": "RKF78", "relTol": 1e-13, "absTol": 1e-15, "task_step": 0.1}
CHECKS = [
    {"integrator": "RKF78", "relTol": 1e-14, "absTol": 1e-16, "task_step": 0.1},
    {"integrator": "RKF78", "relTol": 1e-13, "absTol": 1e-15, "task_step": 0.05},
    {"integrator": "RK4", "task_step": 5e-4},
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
    return out


NUM = r"([-+0-9.eE]+)"
VEC = rf"\[{NUM}, {NUM}, {NUM}\]"
LINE = re.compile(
    rf"spring_mass_damper (\S+) from its tank: sloshing mass {NUM} kg at {VEC} m; line 1 "
    rf"direction {VEC} stiffness {NUM} N/m; damping {NUM} N s/m; fixed liquid {NUM} kg at "
    rf"{VEC} m$")


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
    assert len(found) == 1, f"one single-line tank spring expected in:\n{text}"
    g = [float(x) for x in found[0].groups()[1:]]
    return {"mass": g[0], "position": g[1:4], "direction": g[4:7], "stiffness": g[7],
            "damping": g[8], "fixed_mass": g[9], "fixed_position": g[10:13]}


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


def initial_rho(s):
    e = s["effectors"][0]["spring_mass_damper"]
    return float(e.get("initial_offset", 0.0)), float(e.get("initial_rate", 0.0))


def centre_of_mass(s, d, rho, rho_dot, omega):
    """The system's centre of mass from B (body axes) and its velocity relative to B as seen
    in the inertial frame (body axes)."""
    M, m0, ms = float(s["body"]["mass"]), d["fixed_mass"], d["mass"]
    p = np.array(d["direction"])
    rs = np.array(d["position"]) + rho * p
    total = M + m0 + ms
    c = (m0 * np.array(d["fixed_position"]) + ms * rs) / total
    cp = ms * rho_dot * p / total
    return c, cp + np.cross(omega, c)


def build(s, d, settings):
    """A fresh Basilisk simulation of scene s with the integrator settings."""
    sim = SimulationBaseClass.SimBaseClass()
    proc = sim.CreateNewProcess("dynamicsProcess")
    proc.addTask(sim.CreateNewTask("dynamicsTask", macros.sec2nano(settings["task_step"])))
    sc = spacecraft.Spacecraft()
    sc.ModelTag = "hub"
    smd = linearSpringMassDamper.LinearSpringMassDamper()
    smd.ModelTag = "slosh"
    smd.massInit = d["mass"]
    smd.k = d["stiffness"]
    smd.c = d["damping"]
    smd.r_PB_B = [[x] for x in d["position"]]
    smd.pHat_B = [[x] for x in d["direction"]]
    rho0, rho_dot0 = initial_rho(s)
    smd.rhoInit = rho0
    smd.rhoDotInit = rho_dot0
    sc.addStateEffector(smd)
    mh, c_hub, inertia = hub_with_liquid(s, d)
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
        "rho": dm.getStateObject(smd.nameOfRhoState),
        "rho_dot": dm.getStateObject(smd.nameOfRhoDotState),
        "mass": dm.getStateObject(smd.nameOfMassState),
    }
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
        "rho": float(g["rho"][0]), "rho_dot": float(g["rho_dot"][0]),
        "h_inertial": np.array(sc.totRotAngMomPntC_N, dtype=float).ravel(),
        "energy": float(sc.totRotEnergy), "mass": float(g["mass"][0]),
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
    rs = np.array(d["position"]) + o["rho"] * np.array(d["direction"])
    v_b = -cdot                                   # B relative to the centre of mass
    v_f = v_b + np.cross(w, rf)
    v_s = v_b + np.cross(w, rs) + o["rho_dot"] * np.array(d["direction"])
    h = inertia @ w + M * np.cross(-c, v_b) + m0 * np.cross(rf - c, v_f) + ms * np.cross(rs - c, v_s)
    t = 0.5 * w @ inertia @ w + 0.5 * (M * v_b @ v_b + m0 * v_f @ v_f + ms * v_s @ v_s)
    return dcm_nb(o["sigma"]) @ h, float(t), 0.5 * d["stiffness"] * o["rho"] ** 2


def run(s, d, settings, times):
    """The samples of scene s at the given times, and facts about the run."""
    sim, sc, smd, states = build(s, d, settings)
    out = [read(sc, states)]
    t0 = time.perf_counter()
    for t in times[1:]:
        sim.ConfigureStopTime(macros.sec2nano(t))
        sim.ExecuteSimulation()
        out.append(read(sc, states))
    wall = time.perf_counter() - t0
    last = out[-1]
    c, _ = centre_of_mass(s, d, last["rho"], 0.0, np.zeros(3))
    facts = {
        "wall_seconds": wall,
        "mass_at_end": last["mass"],
        "centre_of_mass_at_end": [float(x) for x in last["r_hub"] + dcm_nb(last["sigma"]) @ c],
        "max_abs_rho": max(abs(o["rho"]) for o in out),
        "effector_as_set": {
            "massInit": float(smd.massInit), "k": float(smd.k), "c": float(smd.c),
            "r_PB_B": [float(x) for x in np.array(smd.r_PB_B).ravel()],
            "pHat_B": [float(x) for x in np.array(smd.pHat_B).ravel()],
        },
        "system_mass": float(sc.m_SC[0][0]) if hasattr(sc, "m_SC") else None,
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


def differences(a, b):
    """Largest differences between two runs' samples."""
    h = max(float(np.linalg.norm(o["h_inertial"])) for o in b)
    e = max(o["energy"] for o in b)
    return {
        "omega": max(float(np.linalg.norm(x["omega"] - y["omega"])) for x, y in zip(a, b)),
        "attitude": max(attitude_error(x["q"], y["q"]) for x, y in zip(a, b)),
        "rho": max(abs(x["rho"] - y["rho"]) for x, y in zip(a, b)),
        "rho_dot": max(abs(x["rho_dot"] - y["rho_dot"]) for x, y in zip(a, b)),
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
        assert a["massInit"] == d["mass"] and a["k"] == d["stiffness"] and a["c"] == d["damping"], a
        assert a["r_PB_B"] == d["position"] and a["pHat_B"] == d["direction"], a
        mh, c_hub, _ = hub_with_liquid(s, d)
        assert abs(mh - float(s["body"]["mass"]) - d["fixed_mass"]) <= 1e-12 * mh
        assert np.allclose(mh * c_hub, d["fixed_mass"] * np.array(d["fixed_position"]), rtol=1e-15, atol=1e-15)
        assert facts["mass_at_end"] == d["mass"], "Basilisk's sloshing mass changed"
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
        rho0, rho_dot0 = initial_rho(s)
        out_scenes.append({
            "name": name,
            "what": what,
            "scenario": s,
            "polhode_derived": d,
            "basilisk_parameters": {
                "hub.mHub": mh,
                "hub.r_BcB_B": [float(x) for x in c_hub],
                "hub.IHubPntBc_B": hub_with_liquid(s, d)[2].tolist(),
                "hub.omega_BN_BInit": [float(x) for x in s["initial"]["omega"]],
                "hub.sigma_BNInit": [float(x) for x in quaternion_to_mrp(
                    [s["initial"]["attitude"][k] for k in "wxyz"])],
                **{k: v for k, v in facts["effector_as_set"].items()},
                "rhoInit": rho0, "rhoDotInit": rho_dot0,
                "fuel tank": None,
            },
            "facts": facts,
            "convergence": checks,
            "samples": [{
                "t": t,
                "omega": [float(x) for x in o["omega"]],
                "sigma_BN": [float(x) for x in o["sigma"]],
                "quaternion": [float(x) for x in o["q"]],
                "rho": o["rho"], "rho_dot": o["rho_dot"],
                "h_inertial": [float(x) for x in o["h_inertial"]],
                "energy": o["energy"],
            } for t, o in zip(times, samples)],
        })
    out = {
        "basilisk": bsk_version,
        "module": "linearSpringMassDamper on spacecraft.Spacecraft, no gravity, no fuel tank; "
                  "the fixed liquid in the hub",
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
