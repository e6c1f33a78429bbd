#!/usr/bin/env python3
"""Basilisk peer: a hub with one linear spring-mass-damper (Basilisk's
linearSpringMassDamper state effector on spacecraft.Spacecraft, no gravity) against polhode's
spring_mass_damper on the same hub (peers/smd.yaml), both with fixed-step RK4.

(a) time per RK4 step: Basilisk's ExecuteSimulation over the whole run with nothing recorded,
    divided by the steps; polhode's `bench point --method rk4` time divided by its steps. Both
    wall clock, minimum over repeats, in this one script run.
(b) trajectories: hub w (body axes), the SMD displacement rho and the attitude at common times,
    each side at each step size against a tight reference (polhode dopri5 rtol 1e-13, or dop853
    when built), and Basilisk against polhode at the same step.

Writes results/basilisk.json and results/basilisk_trajectory.csv.
"""
import json
import math
import os
import subprocess
import sys
import time

import numpy as np
import yaml
from Basilisk.simulation import linearSpringMassDamper, spacecraft
from Basilisk.utilities import SimulationBaseClass, macros
from peer_common import attitude_error

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
RESULTS = os.path.join(HERE, "results")
POLHODE = os.path.join(ROOT, "target", "release", "polhode")
SCENARIO = "peers/smd.yaml"
STEPS = [0.1, 0.01]        # s, RK4 steps compared
TIMING_STEP = 0.01         # s, the step timed (10 000 steps over 100 s)
SAMPLE_EVERY = 5.0         # s, trajectory comparison times
REPEATS = 5


def log(msg):
    print(f"[basilisk {time.strftime('%H:%M:%S')}] {msg}", flush=True)


def scenario():
    with open(os.path.join(ROOT, SCENARIO)) as fh:
        s = yaml.safe_load(fh)
    e = s["effectors"][0]["spring_mass_damper"]
    return s, e


def build(dt):
    """A fresh Basilisk simulation of peers/smd.yaml with one task of period dt."""
    s, e = scenario()
    sim = SimulationBaseClass.SimBaseClass()
    proc = sim.CreateNewProcess("dynamicsProcess")
    proc.addTask(sim.CreateNewTask("dynamicsTask", macros.sec2nano(dt)))
    sc = spacecraft.Spacecraft()
    sc.ModelTag = "hub"
    smd = linearSpringMassDamper.LinearSpringMassDamper()
    smd.k = float(e["stiffness"])
    smd.c = float(e["damping"])
    smd.r_PB_B = [[float(x)] for x in e["position"]]
    p = np.array(e["direction"], dtype=float)
    smd.pHat_B = [[float(x)] for x in p / np.linalg.norm(p)]
    smd.rhoInit = float(e.get("initial_offset", 0.0))
    smd.rhoDotInit = float(e.get("initial_rate", 0.0))
    # The mass is a state of Basilisk's effector (fuel slosh: it drains with a fuel tank); its
    # initial value defaults to 0 and its rate stays 0 when no tank is attached.
    smd.massInit = float(e["mass"])
    sc.addStateEffector(smd)
    sc.hub.mHub = float(s["body"]["mass"])
    sc.hub.r_BcB_B = [[0.0], [0.0], [0.0]]
    sc.hub.IHubPntBc_B = np.diag(s["body"]["principal"]).tolist()
    sc.hub.r_CN_NInit = [[0.0], [0.0], [0.0]]
    sc.hub.v_CN_NInit = [[0.0], [0.0], [0.0]]      # system centre of mass at rest
    att = s["initial"].get("attitude", {"w": 1.0, "x": 0.0, "y": 0.0, "z": 0.0})
    q = np.array([att["w"], att["x"], att["y"], att["z"]])
    sigma = q[1:] / (1.0 + q[0])                     # MRP of the same rotation
    sc.hub.sigma_BNInit = [[float(x)] for x in sigma]
    sc.hub.omega_BN_BInit = [[float(x)] for x in s["initial"]["omega"]]
    sim.AddModelToTask("dynamicsTask", sc)
    sim.InitializeSimulation()
    states = {
        "omega": sc.dynManager.getStateObject(sc.hub.nameOfHubOmega),
        "sigma": sc.dynManager.getStateObject(sc.hub.nameOfHubSigma),
        "rho": sc.dynManager.getStateObject(smd.nameOfRhoState),
        "rhoDot": sc.dynManager.getStateObject(smd.nameOfRhoDotState),
        "mass": sc.dynManager.getStateObject(smd.nameOfMassState),
    }
    return sim, sc, smd, states


def read(states):
    g = {k: np.array(v.getState(), dtype=float).ravel() for k, v in states.items()}
    s = g["sigma"]
    s2 = float(s @ s)
    q = np.concatenate([[(1 - s2) / (1 + s2)], 2 * s / (1 + s2)])
    return {"omega": g["omega"], "q": q, "rho": float(g["rho"][0]), "rho_dot": float(g["rhoDot"][0]),
            "mass": float(g["mass"][0])}


def polhode(method, duration, repeats=1, dt=None, rtol=None, atol=None):
    cmd = [POLHODE, "bench", "point", SCENARIO, "--method", method, "--duration", repr(duration),
           "--repeats", str(repeats)]
    if dt is not None:
        cmd += ["--dt", repr(dt)]
    if rtol is not None:
        cmd += ["--rtol", repr(rtol), "--atol", repr(atol)]
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: {p.stderr.strip()}")
    d = json.loads(p.stdout)
    y = d["final_state"]
    d["omega"], d["q"], d["rho"], d["rho_dot"] = np.array(y[:3]), np.array(y[3:7]), y[7], y[8]
    return d




def main():
    wall0 = time.time()
    os.makedirs(RESULTS, exist_ok=True)
    s, _ = scenario()
    duration = float(s["duration"])
    import Basilisk
    bsk_version = getattr(Basilisk, "__version__", None)
    if bsk_version is None:
        from importlib.metadata import version
        bsk_version = version("bsk")
    ref_method = "dop853"
    try:
        polhode(ref_method, 1.0, rtol=1e-10, atol=1e-12)
    except RuntimeError:
        ref_method = "dopri5"

    # (a) time per step.
    n_steps = int(round(duration / TIMING_STEP))
    bsk_times = []
    for _ in range(REPEATS):
        sim, sc, smd, states = build(TIMING_STEP)
        sim.ConfigureStopTime(macros.sec2nano(duration))
        t0 = time.perf_counter()
        sim.ExecuteSimulation()
        bsk_times.append(time.perf_counter() - t0)
    bsk_final = read(states)
    ph = polhode("rk4", duration, repeats=REPEATS, dt=TIMING_STEP)
    timing = {
        "dt": TIMING_STEP, "steps": n_steps, "duration": duration,
        "basilisk_seconds": min(bsk_times), "basilisk_seconds_all": bsk_times,
        "basilisk_us_per_step": min(bsk_times) / n_steps * 1e6,
        "polhode_seconds": ph["cpu_seconds"], "polhode_seconds_all": ph["cpu_seconds_all"],
        "polhode_steps": ph["steps"], "polhode_us_per_step": ph["cpu_seconds"] / ph["steps"] * 1e6,
        "final_omega_difference": float(np.linalg.norm(bsk_final["omega"] - ph["omega"])),
        "final_rho_difference": abs(bsk_final["rho"] - ph["rho"]),
        "basilisk_mass_at_end": bsk_final["mass"],
    }
    timing["ratio"] = timing["basilisk_us_per_step"] / timing["polhode_us_per_step"]
    log(f"per RK4 step: Basilisk {timing['basilisk_us_per_step']:.2f} us, polhode "
        f"{timing['polhode_us_per_step']:.3f} us (x{timing['ratio']:.0f})")

    # (b) trajectories at common times.
    times = [SAMPLE_EVERY * k for k in range(1, int(round(duration / SAMPLE_EVERY)) + 1)]
    ref = {t: polhode(ref_method, t, rtol=1e-13, atol=1e-15) for t in times}
    rows, per_step = [], []
    for dt in STEPS:
        sim, sc, smd, states = build(dt)
        stats = {"dt": dt, "basilisk_vs_ref": {}, "polhode_vs_ref": {}, "basilisk_vs_polhode": {}}
        mx = {k: {"omega": 0.0, "rho": 0.0, "attitude": 0.0} for k in
              ("basilisk_vs_ref", "polhode_vs_ref", "basilisk_vs_polhode")}
        for t in times:
            sim.ConfigureStopTime(macros.sec2nano(t))
            sim.ExecuteSimulation()
            b = read(states)
            p = polhode("rk4", t, dt=dt)
            r = ref[t]
            for key, (x, y) in {"basilisk_vs_ref": (b, r), "polhode_vs_ref": (p, r),
                                "basilisk_vs_polhode": (b, p)}.items():
                mx[key]["omega"] = max(mx[key]["omega"], float(np.linalg.norm(x["omega"] - y["omega"])))
                mx[key]["rho"] = max(mx[key]["rho"], abs(x["rho"] - y["rho"]))
                mx[key]["attitude"] = max(mx[key]["attitude"], attitude_error(y["q"], x["q"]))
            rows.append([dt, t, *b["omega"], b["rho"], *p["omega"], p["rho"], *r["omega"], r["rho"],
                         attitude_error(r["q"], b["q"]), attitude_error(r["q"], p["q"])])
        stats.update(mx)
        per_step.append(stats)
        log(f"dt {dt:g}: max over {len(times)} times: |w_B - w_ref| {mx['basilisk_vs_ref']['omega']:.2e}, "
            f"|w_P - w_ref| {mx['polhode_vs_ref']['omega']:.2e}, |w_B - w_P| "
            f"{mx['basilisk_vs_polhode']['omega']:.2e} rad/s; rho {mx['basilisk_vs_ref']['rho']:.2e} / "
            f"{mx['polhode_vs_ref']['rho']:.2e} / {mx['basilisk_vs_polhode']['rho']:.2e} m")
    out = {"scenario": SCENARIO, "basilisk": bsk_version, "reference": f"polhode {ref_method} rtol 1e-13 atol 1e-15",
           "sample_times": times, "timing": timing, "trajectories": per_step,
           "wall_seconds": time.time() - wall0}
    with open(os.path.join(RESULTS, "basilisk.json"), "w") as fh:
        json.dump(out, fh, indent=1)
    with open(os.path.join(RESULTS, "basilisk_trajectory.csv"), "w") as fh:
        fh.write("dt,t,bsk_wx,bsk_wy,bsk_wz,bsk_rho,pol_wx,pol_wy,pol_wz,pol_rho,ref_wx,ref_wy,"
                 "ref_wz,ref_rho,bsk_attitude_err,pol_attitude_err\n")
        for r in rows:
            fh.write(",".join(repr(float(x)) for x in r) + "\n")
    log("wrote results/basilisk.json, results/basilisk_trajectory.csv")


if __name__ == "__main__":
    main()
