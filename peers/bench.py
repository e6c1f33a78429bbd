#!/usr/bin/env python3
"""Peer comparison: polhode against a Rust ODE crate (same right-hand side) and SciPy's
solve_ivp on the same problems and tolerances. Writes results/runs.json, results/runs.csv and
results/summary.json (read by report.py). Run through peers/run.sh, which builds everything.

Timings are the minimum over repeats of one solve, integration only, each side measuring its
own solve the same way (wall clock: polhode and the Rust peer with std::time::Instant, SciPy
with time.perf_counter around solve_ivp), all in one script run so that the machine's load is
shared alike.
"""
import json
import math
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
RESULTS = os.path.join(HERE, "results")
POLHODE = os.path.join(ROOT, "target", "release", "polhode")
RUST_PEER = os.path.join(HERE, "rust-ode", "target", "release", "polhode-peer-rust-ode")
sys.path.insert(0, HERE)
import scipy_models  # noqa: E402
from peer_common import attitude_error

RTOLS = [1e-6, 1e-8, 1e-10, 1e-12]
ATOL_FACTOR = 1e-2          # atol = rtol * ATOL_FACTOR for every run
REF_RTOL, REF_ATOL = 1e-13, 1e-15
FAST_REPEATS = 5            # polhode and the Rust peer (milliseconds a solve) ...
FAST_ROUNDS = 3             # ... in this many sweeps over the tolerances
SCIPY_REPEAT_BELOW = 0.5    # SciPy: 3 repeats for a solve under this many seconds, else 1
SCIPY_CAP = 15.0            # s: a SciPy run predicted to take longer than this is skipped
SCIPY_METHODS = {"DOP853": 8, "RK45": 5, "Radau": 5}     # nominal orders (for the prediction)
RUST_METHODS = ["dop853", "dopri5"]


def problems():
    sep = os.path.join(ROOT, "scenarios", "near-separatrix.yaml")
    near = ({"key": "near-separatrix", "scenario": "scenarios/near-separatrix.yaml",
             "duration": None, "kind": "rigid"} if os.path.exists(sep) else
            {"key": "near-separatrix", "scenario": "scenarios/tennis-racket.yaml",
             "duration": 100.0, "kind": "rigid",
             "note": "tennis-racket.yaml run for 100 s (about 22 flips), standing in for "
                     "scenarios/near-separatrix.yaml until it exists"})
    return [
        {"key": "generic-tumble", "scenario": "scenarios/generic-tumble.yaml", "duration": None,
         "kind": "rigid"},
        near,
        {"key": "tennis-racket", "scenario": "scenarios/tennis-racket.yaml", "duration": None,
         "kind": "rigid"},
        {"key": "nutation-damper", "scenario": "scenarios/nutation-damper.yaml",
         "duration": None, "kind": "nutation_damper"},
        {"key": "explorer1-pydy", "scenario": "peers/explorer1-pydy.yaml", "duration": None,
         "kind": "explorer1",
         "note": "peers/explorer1-pydy.yaml: scenarios/explorer1-pydy.yaml shortened from 150 s "
                 "to 10 s (125 spins), hull inertia to full precision"},
    ]


def log(msg):
    print(f"[bench {time.strftime('%H:%M:%S')}] {msg}", flush=True)


def run_json(cmd):
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {p.returncode}: {p.stderr.strip()}")
    return json.loads(p.stdout)


def polhode_point(prob, method, rtol=None, atol=None, repeats=FAST_REPEATS, duration=None):
    cmd = [POLHODE, "bench", "point", prob["scenario"], "--method", method,
           "--repeats", str(repeats)]
    if rtol is not None:
        cmd += ["--rtol", repr(rtol), "--atol", repr(atol)]
    d = duration if duration is not None else prob["duration"]
    if d is not None:
        cmd += ["--duration", repr(d)]
    return run_json(cmd)


def rust_point(prob, method, rtol, atol, repeats=FAST_REPEATS):
    cmd = [RUST_PEER, prob["scenario"], "--method", method, "--rtol", repr(rtol),
           "--atol", repr(atol), "--repeats", str(repeats)]
    if prob["duration"] is not None:
        cmd += ["--duration", repr(prob["duration"])]
    return run_json(cmd)


def polhode_has(method):
    """True if this build of polhode integrates with `method` (tried on a short run)."""
    try:
        polhode_point({"scenario": "scenarios/tennis-racket.yaml", "duration": 0.1}, method,
                      1e-8, 1e-10, repeats=1)
        return True
    except RuntimeError:
        return False




def omega_q(point):
    """(w, q) of a polhode-shaped result (state [w, q, ...]) or a SciPy result."""
    if "final_q" in point:
        return np.array(point["final_omega"]), np.array(point["final_q"])
    y = point["final_state"]
    return np.array(y[:3]), np.array(y[3:7])


def errors(ref, point):
    w_ref, q_ref = omega_q(ref)
    w, q = omega_q(point)
    return attitude_error(q_ref, q), float(np.linalg.norm(w - w_ref))


def pareto(curve):
    """The work-precision front of [(err, time)]: each kept run is more accurate than every
    cheaper one (a run that costs more for a larger error, e.g. on an error floor, is dropped)."""
    front = []
    for e, t in sorted([(e, t) for e, t in curve if e > 0 and t > 0], key=lambda p: p[1]):
        if not front or e < front[-1][0]:
            front.append((e, t))
    return sorted(front)


def interp_time(curve, err, order):
    """Time a peer would take for attitude error `err`, from its runs `curve` [(err, time)].
    On the front of the curve (see pareto), linear in (log err, log time) between the two runs
    that bracket `err` ('interpolated'). Up to one decade outside the front, along the method's
    nominal convergence, time ~ err^(-1/order) from the nearest end ('extrapolated'); beyond
    that, None."""
    pts = pareto(curve)
    if not pts or err <= 0:
        return None, "no data"
    le = math.log10(err)
    xs = [math.log10(e) for e, _ in pts]
    ys = [math.log10(t) for _, t in pts]
    for i in range(len(pts) - 1):
        if xs[i] <= le <= xs[i + 1]:
            f = (le - xs[i]) / (xs[i + 1] - xs[i])
            return 10 ** (ys[i] + f * (ys[i + 1] - ys[i])), "interpolated"
    if len(pts) == 1 and xs[0] == le:
        return 10 ** ys[0], "interpolated"
    end = 0 if le < xs[0] else -1
    if abs(le - xs[end]) > 1.0:
        return None, "beyond range"
    return 10 ** (ys[end] - (le - xs[end]) / order), "extrapolated"


NOMINAL_ORDER = {"dop853": 8, "DOP853": 8, "dopri5": 5, "RK45": 5, "Radau": 5}


def compute_ratios(runs, problem_keys):
    """For every polhode run, each peer's time at polhode's attitude error."""
    ratios = []
    for key in problem_keys:
        pr = [r for r in runs if r["problem"] == key and "skipped" not in r]
        peers = sorted({(r["side"], r["method"]) for r in pr if r["side"] != "polhode"})
        for p in [r for r in pr if r["side"] == "polhode"]:
            for side, m in peers:
                curve = [(r["attitude_error"], r["cpu_seconds"]) for r in pr
                         if r["side"] == side and r["method"] == m]
                t, how = interp_time(curve, p["attitude_error"], NOMINAL_ORDER.get(m, 5))
                ratios.append({"problem": key, "polhode_method": p["method"], "rtol": p["rtol"],
                               "polhode_error": p["attitude_error"],
                               "polhode_seconds": p["cpu_seconds"], "peer": side,
                               "peer_method": m, "peer_seconds_at_error": t, "how": how,
                               "speedup": (t / p["cpu_seconds"]) if t else None})
    return ratios


def scipy_point(prob, method, rtol, atol):
    scenario = os.path.join(ROOT, prob["scenario"])
    duration = prob["duration"]
    if duration is None:
        duration = float(scipy_models.load_yaml(scenario)["duration"])
    r = scipy_models.solve(prob["kind"], scenario, duration, method, rtol, atol, 1)
    if r["cpu_seconds"] < SCIPY_REPEAT_BELOW:
        r2 = scipy_models.solve(prob["kind"], scenario, duration, method, rtol, atol, 2)
        r["cpu_seconds_all"] += r2["cpu_seconds_all"]
        r["cpu_seconds"] = min(r["cpu_seconds_all"])
    return r


def main():
    os.makedirs(RESULTS, exist_ok=True)
    t_start = time.time()
    main_method = "dop853" if polhode_has("dop853") else "dopri5"
    polhode_methods = [main_method] + (["dopri5"] if main_method != "dopri5" else [])
    log(f"polhode methods: {polhode_methods}")
    runs, checks = [], []
    for prob in problems():
        key = prob["key"]
        log(f"{key}: reference")
        if prob["kind"] == "rigid":
            ref = polhode_point(prob, "exact", repeats=1)
            ref_desc = "polhode exact (closed-form torque-free solution)"
        else:
            ref = polhode_point(prob, main_method, REF_RTOL, REF_ATOL, repeats=1)
            ref_desc = f"polhode {main_method} rtol {REF_RTOL:g} atol {REF_ATOL:g}"
            # The reference must be converged: an independent model and integrator agree.
            t0 = time.time()
            sp = scipy_point(prob, "DOP853", REF_RTOL, REF_ATOL)
            ea, ew = errors(ref, sp)
            other = polhode_point(prob, "dopri5", REF_RTOL, REF_ATOL, repeats=1) \
                if main_method != "dopri5" else None
            checks.append({
                "problem": key, "reference": ref_desc,
                "scipy_dop853_ref": {"attitude_error": ea, "omega_error": ew,
                                     "seconds": sp["cpu_seconds"]},
                "polhode_dopri5_ref": (dict(zip(("attitude_error", "omega_error"),
                                                errors(ref, other))) if other else None),
            })
            log(f"{key}: SciPy DOP853 at rtol {REF_RTOL:g} differs from the reference by "
                f"{ea:.2e} rad, {ew:.2e} rad/s ({time.time() - t0:.1f} s)")
        w_ref, _ = omega_q(ref)
        prob_runs = []

        def add(side, method, rtol, atol, point):
            ea, ew = errors(ref, point)
            rec = {"problem": key, "side": side, "method": method, "rtol": rtol, "atol": atol,
                   "cpu_seconds": point["cpu_seconds"], "cpu_seconds_all": point["cpu_seconds_all"],
                   "steps": point.get("steps"), "rhs_evaluations": point.get("rhs_evaluations"),
                   "attitude_error": ea, "omega_error": ew,
                   "omega_error_rel": ew / float(np.linalg.norm(w_ref))}
            prob_runs.append(rec)
            return rec

        # polhode and the Rust peer: FAST_ROUNDS sweeps over the tolerances, each point's
        # minimum taken over all rounds, so that a burst of load on the shared machine does not
        # hit every repeat of one point.
        fast = {}
        for _ in range(FAST_ROUNDS):
            for rtol in RTOLS:
                atol = rtol * ATOL_FACTOR
                todo = [("polhode", m, polhode_point) for m in polhode_methods] + \
                    [("rust-ode", m, rust_point) for m in RUST_METHODS]
                for side, m, fn in todo:
                    pt = fn(prob, m, rtol, atol)
                    k = (side, m, rtol)
                    if k in fast:
                        if pt["final_state"] != fast[k]["final_state"]:
                            raise RuntimeError(f"{key} {side} {m} rtol {rtol}: not deterministic")
                        fast[k]["cpu_seconds_all"] += pt["cpu_seconds_all"]
                        fast[k]["cpu_seconds"] = min(fast[k]["cpu_seconds_all"])
                    else:
                        fast[k] = pt
        for rtol in RTOLS:
            for side, m in [("polhode", m) for m in polhode_methods] + \
                    [("rust-ode", m) for m in RUST_METHODS]:
                add(side, m, rtol, rtol * ATOL_FACTOR, fast[(side, m, rtol)])
        log(f"{key}: polhode and Rust peer done")
        for m, order in SCIPY_METHODS.items():
            last = prev = None
            for rtol in RTOLS:
                atol = rtol * ATOL_FACTOR
                if last is not None:
                    # Next run's time: the nominal growth per factor 100 in rtol, or the growth
                    # just measured if larger (Radau grows faster than its order says).
                    growth = 100.0 ** (1.0 / order)
                    if prev:
                        growth = max(growth, last / prev)
                    predicted = last * growth
                    if predicted > SCIPY_CAP:
                        prob_runs.append({"problem": key, "side": "scipy", "method": m,
                                          "rtol": rtol, "atol": atol, "skipped":
                                          f"predicted {predicted:.0f} s > cap {SCIPY_CAP:g} s"})
                        continue
                r = scipy_point(prob, m, rtol, atol)
                rec = add("scipy", m, rtol, atol, r)
                prev, last = last, r["cpu_seconds"]
                log(f"{key}: SciPy {m} rtol {rtol:g}: {last:.3f} s, error {rec['attitude_error']:.2e} rad")
        runs += prob_runs
        ref_out = {k: v for k, v in ref.items() if k != "initial_state"}
        _refs[key] = {"description": ref_desc, "point": ref_out}

    ratios = compute_ratios(runs, [p["key"] for p in problems()])

    versions = versions_info()
    summary = {"generated": time.strftime("%Y-%m-%d %H:%M:%S %Z"),
               "wall_seconds": time.time() - t_start, "polhode_methods": polhode_methods,
               "rtols": RTOLS, "atol_factor": ATOL_FACTOR, "scipy_cap": SCIPY_CAP,
               "problems": problems_with_refs(runs), "reference_checks": checks,
               "ratios": ratios, "versions": versions}
    with open(os.path.join(RESULTS, "runs.json"), "w") as fh:
        json.dump(runs, fh, indent=1)
    with open(os.path.join(RESULTS, "summary.json"), "w") as fh:
        json.dump(summary, fh, indent=1)
    with open(os.path.join(RESULTS, "runs.csv"), "w") as fh:
        cols = ["problem", "side", "method", "rtol", "atol", "cpu_seconds", "steps",
                "rhs_evaluations", "attitude_error", "omega_error", "omega_error_rel", "skipped"]
        fh.write(",".join(cols) + "\n")
        for r in runs:
            fh.write(",".join("" if r.get(c) is None else str(r.get(c)) for c in cols) + "\n")
    with open(os.path.join(RESULTS, "ratios.csv"), "w") as fh:
        cols = ["problem", "polhode_method", "rtol", "polhode_error", "polhode_seconds", "peer",
                "peer_method", "peer_seconds_at_error", "how", "speedup"]
        fh.write(",".join(cols) + "\n")
        for r in ratios:
            fh.write(",".join("" if r.get(c) is None else str(r.get(c)) for c in cols) + "\n")
    log(f"done in {time.time() - t_start:.0f} s: results/runs.json, runs.csv, ratios.csv, summary.json")


_refs = {}


def problems_with_refs(runs):
    out = []
    for p in problems():
        p = dict(p)
        if p["key"] in _refs:
            p["reference"] = _refs[p["key"]]
        out.append(p)
    return out


def versions_info():
    import platform
    import scipy
    v = {"python": platform.python_version(), "numpy": np.__version__, "scipy": scipy.__version__}
    for cmd, key in [([POLHODE, "--version"], "polhode"), (["rustc", "--version"], "rustc")]:
        try:
            v[key] = subprocess.run(cmd, capture_output=True, text=True).stdout.strip()
        except OSError:
            v[key] = "?"
    try:
        v["polhode_commit"] = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"],
                                             capture_output=True, text=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", ROOT, "status", "--porcelain", "--", "src"],
                               capture_output=True, text=True).stdout.strip()
        v["polhode_src_modified"] = bool(dirty)
    except OSError:
        pass
    v["differential_equations"] = "0.7.0"
    try:
        with open("/proc/cpuinfo") as fh:
            v["cpu"] = next(l.split(":", 1)[1].strip() for l in fh if l.startswith("model name"))
    except (OSError, StopIteration):
        v["cpu"] = platform.processor()
    v["cores"] = os.cpu_count()
    return v


if __name__ == "__main__":
    main()
