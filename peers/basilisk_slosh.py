#!/usr/bin/env python3
"""Basilisk peer for polhode's slosh_pendulum: a spinning prolate hub with one spherical
pendulum (Basilisk's sphericalPendulum state effector on spacecraft.Spacecraft, no gravity, no
fuel tank), in three scenes:

  spinner-damped    peers/slosh.yaml as written (pivot off the spin axis, rest direction radial)
  spinner-undamped  the same with damping 0 (the kinetic energy is then conserved too)
  oblique           the pivot on the -y side below the hub's centre of mass, an oblique rest
                    direction (Basilisk's P0 frame then has no axis along a body axis),
                    heavier damping, another start

Each scene is integrated with Basilisk's svIntegratorRKF78 (relTol 1e-13, absTol 1e-15, task
step 0.1 s: each task step is one call of the adaptive integrator, which starts from the task
step and shortens it to meet the tolerances), shown converged against the same integrator at
tolerances ten times tighter, at half the task step, and against Basilisk's RK4 at 0.5 ms.
(With a task step of 1 s and relTol 1e-12, the angular momentum drifts by 2e-11 of |H| over
80 s; with 0.1 s and 1e-13 by 6e-15.) Writes
results/basilisk_slosh.json: per scene its parameters in polhode's keys and as given to
Basilisk, and at every sample (1 s apart) the hub's omega (body), sigma_BN and the quaternion
of the same rotation, phi, theta, their rates, and Basilisk's own totRotAngMomPntC_N (the
angular momentum about the system's centre of mass, inertial axes) and totRotEnergy (the
kinetic energy relative to the centre of mass), both also recomputed from the sampled states
(facts.outputs_against_states). tests/basilisk_slosh.rs compares polhode with these numbers.
"""
import copy
import json
import math
import os
import time

import numpy as np
import yaml
from Basilisk.simulation import spacecraft, sphericalPendulum, svIntegrators
from Basilisk.utilities import SimulationBaseClass, macros
from peer_common import attitude_error, compact_json

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
RESULTS = os.path.join(HERE, "results")
SCENARIO = "peers/slosh.yaml"
SAMPLE_EVERY = 1.0                      # s
PRODUCTION = {"integrator": "RKF78", "relTol": 1e-13, "absTol": 1e-15, "task_step": 0.1}
CHECKS = [
    {"integrator": "RKF78", "relTol": 1e-14, "absTol": 1e-16, "task_step": 0.1},
    {"integrator": "RKF78", "relTol": 1e-13, "absTol": 1e-15, "task_step": 0.05},
    {"integrator": "RK4", "task_step": 5e-4},
]


def log(msg):
    print(f"[basilisk-slosh {time.strftime('%H:%M:%S')}] {msg}", flush=True)


def scenes():
    """The three scenes, as polhode scenario dictionaries."""
    with open(os.path.join(ROOT, SCENARIO)) as fh:
        main = yaml.safe_load(fh)
    out = [("spinner-damped", "peers/slosh.yaml as written", main)]
    undamped = copy.deepcopy(main)
    undamped["effectors"][0]["slosh_pendulum"]["damping"] = 0.0
    out.append(("spinner-undamped", "peers/slosh.yaml with damping 0", undamped))
    oblique = copy.deepcopy(main)
    e = oblique["effectors"][0]["slosh_pendulum"]
    e.update({
        "pivot": [0.0, -0.45, -0.3],
        "rest_direction": [0.15, -1.0, 0.1],
        "damping": 5.0,
        "initial_angles": [-0.05, 0.08],
        "initial_rates": [0.03, 0.0],
    })
    oblique["initial"]["omega"] = [-0.04, 0.06, 3.0]
    out.append(("oblique", "pivot on the -y side below the centre of mass, oblique rest direction "
                "[0.15, -1, 0.1], damping 5 N s/m, another start", oblique))
    return out


def pendulum_frame(rest):
    """polhode's convention: p1 the rest direction, e the body axis least aligned with it (lowest
    index on ties), p3 = normalise(p1 x e), p2 = p3 x p1."""
    p1 = np.array(rest, dtype=float)
    p1 /= np.linalg.norm(p1)
    k = min(range(3), key=lambda i: (abs(p1[i]), i))
    p3 = np.cross(p1, np.eye(3)[k])
    p3 /= np.linalg.norm(p3)
    p2 = np.cross(p3, p1)
    return p1, p2, p3


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


def mass_offset(e, frame, phi, theta, phi_dot, theta_dot):
    """The pendulum mass's position from the hub's centre of mass and its body-frame rate."""
    p1, p2, p3 = frame
    L = float(e["length"])
    r = np.array(e["pivot"], dtype=float) + L * (
        math.cos(phi) * math.cos(theta) * p1 + math.sin(phi) * math.cos(theta) * p2
        - math.sin(theta) * p3)
    rp = L * ((-math.sin(phi) * math.cos(theta) * phi_dot - math.cos(phi) * math.sin(theta) * theta_dot) * p1
              + (math.cos(phi) * math.cos(theta) * phi_dot - math.sin(phi) * math.sin(theta) * theta_dot) * p2
              - math.cos(theta) * theta_dot * p3)
    return r, rp


def build(s, settings):
    """A fresh Basilisk simulation of scene s with the integrator settings."""
    e = s["effectors"][0]["slosh_pendulum"]
    frame = pendulum_frame(e["rest_direction"])
    sim = SimulationBaseClass.SimBaseClass()
    proc = sim.CreateNewProcess("dynamicsProcess")
    proc.addTask(sim.CreateNewTask("dynamicsTask", macros.sec2nano(settings["task_step"])))
    sc = spacecraft.Spacecraft()
    sc.ModelTag = "hub"
    sp = sphericalPendulum.SphericalPendulum()
    sp.ModelTag = "slosh"
    sp.massInit = float(e["mass"])
    sp.pendulumRadius = float(e["length"])
    sp.d = [[float(x)] for x in e["pivot"]]
    sp.D = (float(e["damping"]) * np.eye(3)).tolist()
    sp.pHat_01, sp.pHat_02, sp.pHat_03 = ([[float(x)] for x in p] for p in frame)
    sp.phiDotInit = float(e["initial_rates"][0])
    sp.thetaDotInit = float(e["initial_rates"][1])
    sc.addStateEffector(sp)
    sc.hub.mHub = float(s["body"]["mass"])
    sc.hub.r_BcB_B = [[0.0], [0.0], [0.0]]
    sc.hub.IHubPntBc_B = np.diag([float(x) for x in s["body"]["principal"]]).tolist()
    sc.hub.r_CN_NInit = [[0.0], [0.0], [0.0]]
    sc.hub.v_CN_NInit = [[0.0], [0.0], [0.0]]
    att = s["initial"].get("attitude", {"w": 1.0, "x": 0.0, "y": 0.0, "z": 0.0})
    sigma0 = quaternion_to_mrp([att["w"], att["x"], att["y"], att["z"]])
    sc.hub.sigma_BNInit = [[float(x)] for x in sigma0]
    sc.hub.omega_BN_BInit = [[float(x)] for x in s["initial"]["omega"]]
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
        "phi": dm.getStateObject(sp.nameOfPhiState),
        "theta": dm.getStateObject(sp.nameOfThetaState),
        "phi_dot": dm.getStateObject(sp.nameOfPhiDotState),
        "theta_dot": dm.getStateObject(sp.nameOfThetaDotState),
        "mass": dm.getStateObject(sp.nameOfMassState),
    }
    # The initial angles: Basilisk's phiInit and thetaInit are private (0), so the states are
    # written after initialisation. The hub's inertial position and velocity, which Basilisk
    # derived from r_CN_NInit = v_CN_NInit = 0 with the pendulum at zero angles, are then set
    # again so that the system's centre of mass is at rest at the origin, as in polhode.
    phi0, theta0 = (float(x) for x in e["initial_angles"])
    states["phi"].setState([[phi0]])
    states["theta"].setState([[theta0]])
    m, M = float(e["mass"]), float(s["body"]["mass"])
    r, rp = mass_offset(e, frame, phi0, theta0, sp.phiDotInit, sp.thetaDotInit)
    c, cp = m * r / (m + M), m * rp / (m + M)
    w0 = np.array(s["initial"]["omega"], dtype=float)
    C = dcm_nb(sigma0)
    states["r"].setState([[float(x)] for x in -C @ c])
    states["v"].setState([[float(x)] for x in -C @ (cp + np.cross(w0, c))])
    # Energy and momentum at t = 0 from these states (Reset computed them at zero angles).
    sc.updateSCMassProps(0.0)
    sc.computeEnergyMomentum(0.0)
    return sim, sc, sp, states, integrator


def read(sc, states):
    g = {k: np.array(v.getState(), dtype=float).ravel() for k, v in states.items()}
    return {
        "omega": g["omega"], "sigma": g["sigma"], "q": mrp_to_quaternion(g["sigma"]),
        "phi": float(g["phi"][0]), "theta": float(g["theta"][0]),
        "phi_dot": float(g["phi_dot"][0]), "theta_dot": float(g["theta_dot"][0]),
        "h_inertial": np.array(sc.totRotAngMomPntC_N, dtype=float).ravel(),
        "energy": float(sc.totRotEnergy), "mass": float(g["mass"][0]),
        "r_hub": g["r"], "v_hub": g["v"],
    }


def momentum_and_energy(s, o):
    """H about the system's centre of mass (inertial axes) and the kinetic energy relative to
    it, from the sampled states alone: a check of what Basilisk's outputs mean."""
    e = s["effectors"][0]["slosh_pendulum"]
    m, M = float(e["mass"]), float(s["body"]["mass"])
    inertia = np.diag([float(x) for x in s["body"]["principal"]])
    w = o["omega"]
    r, rp = mass_offset(e, pendulum_frame(e["rest_direction"]), o["phi"], o["theta"],
                        o["phi_dot"], o["theta_dot"])
    c, cp = m * r / (m + M), m * rp / (m + M)
    v_hub = -(cp + np.cross(w, c))                  # hub's velocity relative to the centre of mass
    v_mass = rp + np.cross(w, r) + v_hub
    h_b = inertia @ w + M * np.cross(-c, v_hub) + m * np.cross(r - c, v_mass)
    energy = 0.5 * w @ inertia @ w + 0.5 * M * v_hub @ v_hub + 0.5 * m * v_mass @ v_mass
    return dcm_nb(o["sigma"]) @ h_b, float(energy)


def run(s, settings, times):
    """The samples of scene s at the given times, and facts about the run."""
    sim, sc, sp, states, _integrator = build(s, settings)
    frame0 = [np.array(p, dtype=float).ravel() for p in (sp.pHat_01, sp.pHat_02, sp.pHat_03)]
    out = [read(sc, states)]
    t0 = time.perf_counter()
    for t in times[1:]:
        sim.ConfigureStopTime(macros.sec2nano(t))
        sim.ExecuteSimulation()
        out.append(read(sc, states))
    wall = time.perf_counter() - t0
    frame1 = [np.array(p, dtype=float).ravel() for p in (sp.pHat_01, sp.pHat_02, sp.pHat_03)]
    e = s["effectors"][0]["slosh_pendulum"]
    m, M = float(e["mass"]), float(s["body"]["mass"])
    last = out[-1]
    r, _ = mass_offset(e, pendulum_frame(e["rest_direction"]), last["phi"], last["theta"], 0.0, 0.0)
    r_cn = last["r_hub"] + dcm_nb(last["sigma"]) @ (m * r / (m + M))
    facts = {
        "wall_seconds": wall,
        "rebased": any(float(np.linalg.norm(a - b)) > 0.0 for a, b in zip(frame0, frame1)),
        "mass_at_end": last["mass"],
        "centre_of_mass_at_end": [float(x) for x in r_cn],
        "max_abs_phi": max(abs(o["phi"]) for o in out),
        "max_abs_theta": max(abs(o["theta"]) for o in out),
        "min_abs_cos_theta": min(abs(math.cos(o["theta"])) for o in out),
    }
    by_hand = [momentum_and_energy(s, o) for o in out]
    facts["outputs_against_states"] = {
        "h_relative": max(float(np.linalg.norm(h - o["h_inertial"]) / np.linalg.norm(o["h_inertial"]))
                          for (h, _), o in zip(by_hand, out)),
        "energy_relative": max(abs(t - o["energy"]) / o["energy"] for (_, t), o in zip(by_hand, out)),
    }
    return out, facts




def differences(a, b):
    """Largest differences between two runs' samples."""
    h = max(float(np.linalg.norm(o["h_inertial"])) for o in b)
    e = max(o["energy"] for o in b)
    return {
        "omega": max(float(np.linalg.norm(x["omega"] - y["omega"])) for x, y in zip(a, b)),
        "attitude": max(attitude_error(x["q"], y["q"]) for x, y in zip(a, b)),
        "phi": max(abs(x["phi"] - y["phi"]) for x, y in zip(a, b)),
        "theta": max(abs(x["theta"] - y["theta"]) for x, y in zip(a, b)),
        "phi_dot": max(abs(x["phi_dot"] - y["phi_dot"]) for x, y in zip(a, b)),
        "theta_dot": max(abs(x["theta_dot"] - y["theta_dot"]) for x, y in zip(a, b)),
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
        duration = float(s["duration"])
        n = int(round(duration / SAMPLE_EVERY))
        times = [SAMPLE_EVERY * k for k in range(n + 1)]
        e = s["effectors"][0]["slosh_pendulum"]
        frame = pendulum_frame(e["rest_direction"])
        samples, facts = run(s, PRODUCTION, times)
        checks = []
        for st in CHECKS:
            other, other_facts = run(s, st, times)
            d = differences(samples, other)
            checks.append({"against": settings_label(st), "settings": st, "max_difference": d,
                           "wall_seconds": other_facts["wall_seconds"]})
            log(f"{name}: production vs {settings_label(st)}: |dw| {d['omega']:.1e} rad/s, "
                f"att {d['attitude']:.1e} rad, phi {d['phi']:.1e}, theta {d['theta']:.1e} rad, "
                f"H {d['h_relative']:.1e}, T {d['energy_relative']:.1e} (relative)")
        h0 = samples[0]["h_inertial"]
        log(f"{name}: totRotAngMomPntC_N and totRotEnergy against H and T from the states: "
            f"{facts['outputs_against_states']['h_relative']:.1e}, "
            f"{facts['outputs_against_states']['energy_relative']:.1e} (relative)")
        log(f"{name}: max |phi| {facts['max_abs_phi']:.3f}, |theta| {facts['max_abs_theta']:.3f} rad; "
            f"re-based {facts['rebased']}; mass at end {facts['mass_at_end']}; "
            f"H drift {max(float(np.linalg.norm(o['h_inertial'] - h0)) for o in samples) / np.linalg.norm(h0):.1e}; "
            f"T {samples[0]['energy']:.6f} -> {samples[-1]['energy']:.6f} J; {facts['wall_seconds']:.2f} s")
        out_scenes.append({
            "name": name,
            "what": what,
            "scenario": s,
            "basilisk_parameters": {
                "hub.mHub": float(s["body"]["mass"]),
                "hub.IHubPntBc_B": np.diag([float(x) for x in s["body"]["principal"]]).tolist(),
                "hub.r_BcB_B": [0.0, 0.0, 0.0],
                "hub.omega_BN_BInit": [float(x) for x in s["initial"]["omega"]],
                "hub.sigma_BNInit": [float(x) for x in quaternion_to_mrp(
                    [s["initial"]["attitude"][k] for k in "wxyz"])],
                "massInit": float(e["mass"]),
                "pendulumRadius": float(e["length"]),
                "d": [float(x) for x in e["pivot"]],
                "D": (float(e["damping"]) * np.eye(3)).tolist(),
                "pHat_01": [float(x) for x in frame[0]],
                "pHat_02": [float(x) for x in frame[1]],
                "pHat_03": [float(x) for x in frame[2]],
                "phi state at t = 0": float(e["initial_angles"][0]),
                "theta state at t = 0": float(e["initial_angles"][1]),
                "phiDotInit": float(e["initial_rates"][0]),
                "thetaDotInit": float(e["initial_rates"][1]),
                "fuel tank": None,
            },
            "facts": facts,
            "convergence": checks,
            "samples": [{
                "t": t,
                "omega": [float(x) for x in o["omega"]],
                "sigma_BN": [float(x) for x in o["sigma"]],
                "quaternion": [float(x) for x in o["q"]],
                "phi": o["phi"], "theta": o["theta"],
                "phi_dot": o["phi_dot"], "theta_dot": o["theta_dot"],
                "h_inertial": [float(x) for x in o["h_inertial"]],
                "energy": o["energy"],
            } for t, o in zip(times, samples)],
        })
    out = {
        "basilisk": bsk_version,
        "module": "sphericalPendulum on spacecraft.Spacecraft, no gravity, no fuel tank",
        "integrator": {**PRODUCTION, "label": settings_label(PRODUCTION)},
        "sample_every": SAMPLE_EVERY,
        "quaternion": "[w, x, y, z] of the rotation sigma_BN (body -> inertial, as polhode's attitude)",
        "h_inertial": "Basilisk's totRotAngMomPntC_N: angular momentum about the system's centre of mass, N frame",
        "energy": "Basilisk's totRotEnergy: kinetic energy relative to the system's centre of mass",
        "scenes": out_scenes,
        "wall_seconds": time.time() - wall0,
    }
    with open(os.path.join(RESULTS, "basilisk_slosh.json"), "w") as fh:
        fh.write(compact_json(out) + "\n")
    log("wrote results/basilisk_slosh.json")


if __name__ == "__main__":
    main()
