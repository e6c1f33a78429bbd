#!/usr/bin/env python3
"""Campaign throughput on one thread: the nutation-damper campaign of
scenarios/nutation-damper.yaml (its `montecarlo:` block: 200 runs of 600 s, dopri5 at rtol
1e-11, atol 1e-13, dispersed initial.omega[0], initial.omega[2] and the dashpot) three ways:

  lanes    polhode montecarlo SCENARIO --threads 1 --shard 1/1 --out TMP
           (eight runs at once in SIMD lanes with AVX-512, four with AVX2; shard 1/1 writes the table and the
           summaries but no charts and no MCAP of the worst/median/best runs)
  scalar   the same with --no-lanes (one run after another; the same rows)
  SciPy    solve_ivp, RK45 (the same Dormand-Prince 5(4) pair) and DOP853, over the same
           draws (read from the table the lanes run wrote), same rtol and atol, one run
           after another in this process, no events and no dense output

Each is reported as runs per second of wall time and per second of CPU time (user + system),
on one core; for polhode the best of REPEATS campaigns each way, lanes and scalar alternated
(and the ratio of each adjacent pair, whose median is steadier on a loaded machine). polhode's figures are whole campaigns (process start, parsing, drawing, the
20 Hz samples, the two events, the drift checks, writing runs.csv, runs.parquet and the
summaries); SciPy's are the solve_ivp calls alone. SciPy at rtol 1e-11 takes seconds a run,
so it integrates the first SCIPY_RUNS runs of the campaign.

Writes results/campaign.json and prints a table. The polhode binary is $POLHODE_BIN if set,
else target/release/polhode. Run through peers/run.sh.
"""
import csv
import json
import os
import platform
import re
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy.integrate import solve_ivp

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
RESULTS = os.path.join(HERE, "results")
SCENARIO = "scenarios/nutation-damper.yaml"
POLHODE = os.environ.get("POLHODE_BIN") or os.path.join(ROOT, "target", "release", "polhode")
REPEATS = int(os.environ.get("CAMPAIGN_REPEATS", "5"))     # polhode: lanes and scalar alternated
SCIPY_RUNS = int(os.environ.get("CAMPAIGN_SCIPY_RUNS", "10"))
SCIPY_METHODS = ["RK45", "DOP853"]
DISPERSED = ["initial.omega[0]", "initial.omega[2]", "effectors[damper].damping"]
sys.path.insert(0, HERE)
import scipy_models  # noqa: E402

CLOSING = re.compile(r"^(\d+) runs in ([0-9.]+) s \(([0-9.]+) runs/s on (\d+) thread")


def log(msg):
    print(f"[campaign {time.strftime('%H:%M:%S')}] {msg}", flush=True)


def polhode_campaign(out, lanes):
    """One campaign on one thread; returns its figures (the closing line's and the CPU time of
    the process, from wait4) and the header line that names the path taken."""
    cmd = [POLHODE, "montecarlo", SCENARIO, "--threads", "1", "--shard", "1/1", "--out", out]
    if not lanes:
        cmd.append("--no-lanes")
    with tempfile.TemporaryFile("w+") as err, open(os.devnull, "w") as null:
        t0 = time.perf_counter()
        p = subprocess.Popen(cmd, cwd=ROOT, stdout=null, stderr=err)
        _, status, usage = os.wait4(p.pid, 0)
        wall = time.perf_counter() - t0
        p.returncode = os.waitstatus_to_exitcode(status)
        err.seek(0)
        text = err.read()
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {p.returncode}: {text.strip()}")
    lines = text.splitlines()
    path = next((l.strip() for l in lines if l.strip().startswith("integrated ")
                 or l.strip().startswith("one run at a time")), "?")
    m = next((CLOSING.match(l.strip()) for l in lines if CLOSING.match(l.strip())), None)
    if m is None:
        raise RuntimeError(f"no closing line in the stderr of {' '.join(cmd)}:\n{text}")
    runs, secs, rate, threads = int(m[1]), float(m[2]), float(m[3]), int(m[4])
    cpu = usage.ru_utime + usage.ru_stime
    return {"runs": runs, "seconds": secs, "runs_per_s": rate, "threads": threads,
            "process_wall_seconds": wall, "cpu_seconds": cpu, "runs_per_cpu_s": runs / cpu,
            "path": path}


def read_draws(table):
    with open(table, newline="") as fh:
        rows = list(csv.DictReader(fh))
    missing = [c for c in DISPERSED if c not in rows[0]]
    if missing:
        raise RuntimeError(f"{table}: no column {missing}; columns: {list(rows[0])}")
    return rows


def scipy_campaign(rows, method, rtol, atol, duration, omega_nominal):
    """solve_ivp over the draws of `rows`, one after another; times each call."""
    wall = cpu = 0.0
    steps = nfev = 0
    diffs = []
    for row in rows:
        w0 = np.array(omega_nominal, dtype=float)
        w0[0] = float(row["initial.omega[0]"])
        w0[2] = float(row["initial.omega[2]"])
        y0, rhs, _ = scipy_models.nutation_damper_draw_model(
            w0, float(row["effectors[damper].damping"]))
        end = float(row["end_time"])
        c0, p0 = time.perf_counter(), time.process_time()
        sol = solve_ivp(rhs, (0.0, end), y0, method=method, rtol=rtol, atol=atol)
        cpu += time.process_time() - p0
        wall += time.perf_counter() - c0
        if not sol.success:
            raise RuntimeError(f"run {row['run']}: solve_ivp {method} failed: {sol.message}")
        steps += len(sol.t) - 1
        nfev += sol.nfev
        # The last state is the dissipated energy: the same quantity as polhode's row, from an
        # independent model, so that the draws are shown to be the same runs.
        pol = float(row["energy_dissipated"])
        diffs.append(abs(sol.y[-1, -1] - pol) / abs(pol))
    n = len(rows)
    return {"runs": n, "seconds": wall, "runs_per_s": n / wall, "cpu_seconds": cpu,
            "runs_per_cpu_s": n / cpu, "steps_per_run": steps / n, "rhs_evaluations_per_run": nfev / n,
            "energy_dissipated_max_rel_diff_vs_polhode": max(diffs),
            "runs_used": [int(r["run"]) for r in rows]}


def versions():
    import scipy
    v = {"python": platform.python_version(), "numpy": np.__version__, "scipy": scipy.__version__,
         "polhode_bin": "$POLHODE_BIN" if os.environ.get("POLHODE_BIN") else "target/release/polhode"}
    for cmd, key in [([POLHODE, "--version"], "polhode"), (["rustc", "--version"], "rustc")]:
        try:
            v[key] = subprocess.run(cmd, capture_output=True, text=True).stdout.strip()
        except OSError:
            v[key] = "?"
    try:
        # The last commit that changed polhode itself (not peers/ or docs/).
        v["polhode_commit"] = subprocess.run(
            ["git", "-C", ROOT, "log", "-1", "--format=%h", "--", "src", "Cargo.toml", "Cargo.lock"],
            capture_output=True, text=True).stdout.strip()
    except OSError:
        pass
    try:
        with open("/proc/cpuinfo") as fh:
            info = fh.read()
        v["cpu"] = re.search(r"^model name\s*:\s*(.*)$", info, re.M)[1].strip()
        flags = re.search(r"^flags\s*:\s*(.*)$", info, re.M)[1].split()
        v["avx2"] = "avx2" in flags
        v["avx512f"] = "avx512f" in flags
    except (OSError, TypeError):
        v["cpu"] = platform.processor()
    v["cores"] = os.cpu_count()
    v["load_average_at_start"] = list(os.getloadavg())
    return v


def best(trials, key="runs_per_cpu_s"):
    return max(trials, key=lambda t: t[key])


def main():
    os.makedirs(RESULTS, exist_ok=True)
    t_start = time.time()
    info = versions()
    scen = scipy_models.load_yaml(os.path.join(ROOT, SCENARIO))
    integ = scen["integrator"]
    rtol, atol = float(integ["rtol"]), float(integ["atol"])
    mc = scen["montecarlo"]
    out = {"generated": time.strftime("%Y-%m-%d %H:%M:%S %Z"), "scenario": SCENARIO,
           "campaign": {"runs": mc["runs"], "seed": mc["seed"], "duration": scen["duration"],
                        "method": integ["method"], "rtol": rtol, "atol": atol,
                        "dispersions": mc["dispersions"]},
           "versions": info, "repeats": REPEATS}
    trials = {"lanes": [], "scalar": []}
    with tempfile.TemporaryDirectory(prefix="polhode-campaign-") as tmp:
        for i in range(REPEATS):
            for name, lanes in [("lanes", True), ("scalar", False)]:
                d = os.path.join(tmp, f"{name}-{i}")
                t = polhode_campaign(d, lanes)
                trials[name].append(t)
                log(f"polhode {name} #{i + 1}: {t['runs']} runs in {t['seconds']:.2f} s "
                    f"({t['runs_per_s']:.1f} runs/s wall, {t['runs_per_cpu_s']:.1f} runs/CPU-s)")
                if i == 0:
                    with open(os.path.join(d, "runs.csv")) as fh:
                        table = fh.read()
                    if name == "lanes":
                        lanes_table = table
                    elif table != lanes_table:
                        raise RuntimeError("runs.csv of --no-lanes differs from the lanes' one")
        rows = read_draws(os.path.join(tmp, "lanes-0", "runs.csv"))
    if "lockstep lanes" not in trials["lanes"][0]["path"]:
        log(f"warning: the lanes run did not take the lanes: {trials['lanes'][0]['path']}")
    out["polhode"] = {name: {**best(ts), "all_runs_per_cpu_s": [t["runs_per_cpu_s"] for t in ts],
                             "all_runs_per_s": [t["runs_per_s"] for t in ts]}
                      for name, ts in trials.items()}
    out["tables_identical"] = True
    for name in trials:
        out["polhode"][name]["steps_per_run"] = sum(float(r["steps"]) for r in rows) / len(rows)
        out["polhode"][name]["rhs_evaluations_per_run"] = \
            sum(float(r["rhs_evaluations"]) for r in rows) / len(rows)
    log("SciPy: deriving the reference model (sympy)")
    subset = rows[:SCIPY_RUNS]
    out["scipy"] = {}
    for m in SCIPY_METHODS:
        r = scipy_campaign(subset, m, rtol, atol, float(scen["duration"]), scen["initial"]["omega"])
        out["scipy"][m] = r
        log(f"SciPy {m}: {r['runs']} runs in {r['seconds']:.2f} s ({r['runs_per_s']:.3f} runs/s wall, "
            f"{r['runs_per_cpu_s']:.3f} runs/CPU-s); energy dissipated within "
            f"{r['energy_dissipated_max_rel_diff_vs_polhode']:.1e} of polhode's rows")
    lanes, scalar = out["polhode"]["lanes"], out["polhode"]["scalar"]
    paired = sorted(a["runs_per_cpu_s"] / b["runs_per_cpu_s"]
                    for a, b in zip(trials["lanes"], trials["scalar"]))
    out["ratios"] = {
        "lanes_over_scalar": lanes["runs_per_cpu_s"] / scalar["runs_per_cpu_s"],
        "lanes_over_scalar_paired": paired,
        "lanes_over_scalar_paired_median": paired[len(paired) // 2],
        "lanes_over_scalar_wall": lanes["runs_per_s"] / scalar["runs_per_s"],
        **{f"lanes_over_scipy_{m}": lanes["runs_per_cpu_s"] / out["scipy"][m]["runs_per_cpu_s"]
           for m in SCIPY_METHODS},
        **{f"scalar_over_scipy_{m}": scalar["runs_per_cpu_s"] / out["scipy"][m]["runs_per_cpu_s"]
           for m in SCIPY_METHODS},
    }
    out["wall_seconds"] = time.time() - t_start
    with open(os.path.join(RESULTS, "campaign.json"), "w") as fh:
        json.dump(out, fh, indent=1)
    print(f"\n{'one thread':<22}{'runs':>6}{'runs/s (wall)':>15}{'runs/CPU-s':>12}{'lanes ÷ it':>12}")
    for label, r in [("polhode lanes", lanes), ("polhode --no-lanes", scalar),
                     *[(f"SciPy {m}", out["scipy"][m]) for m in SCIPY_METHODS]]:
        ratio = lanes["runs_per_cpu_s"] / r["runs_per_cpu_s"]
        print(f"{label:<22}{r['runs']:>6}{r['runs_per_s']:>15.3f}{r['runs_per_cpu_s']:>12.3f}{ratio:>12.1f}")
    log(f"done in {out['wall_seconds']:.0f} s: results/campaign.json")


if __name__ == "__main__":
    main()
