#!/usr/bin/env python3
"""The nutation time constant of a spinning stage with liquid in two tanks against the tanks'
fill fraction and the spin rate: scenarios/spinning-stage-tanks.yaml with its two tanks' `fill`
and its spin changed, each point from `polhode linearize` (the eigenvalue, and the energy-sink
estimate beside it), and three points also measured from nonlinear runs (the slope of the
logarithm of the nutation angle over a run of a tenth of the time constant).

Writes docs/figures/slosh-ntc.csv, .svg and .png (docs/slosh-analogs.md).

    peers/.venv/bin/python scripts/slosh-ntc.py     (PyYAML and matplotlib; about a minute)

Uses target/release/polhode (build it first: cargo build --release).
"""
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
POLHODE = os.path.join(ROOT, "target", "release", "polhode")
SCENARIO = os.path.join(ROOT, "scenarios", "spinning-stage-tanks.yaml")
OUT = os.path.join(ROOT, "docs", "figures")
FILLS = [0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8]
SPINS = [3.0, 5.0, 8.0]                       # rad/s
RUNS = [(0.3, 5.0), (0.6, 5.0), (0.6, 8.0)]   # (fill, spin) also measured from a run


def scene(fill, spin):
    with open(SCENARIO) as fh:
        s = yaml.safe_load(fh)
    for e in s["effectors"]:
        e["slosh_pendulum"]["tank"]["fill"] = fill
    w = s["initial"]["omega"]
    # The same initial nutation: the transverse rate scales with the spin.
    s["initial"]["omega"] = [w[0] * spin / w[2], w[1] * spin / w[2], spin]
    return s


def write(s, directory, name):
    path = os.path.join(directory, name)
    with open(path, "w") as fh:
        yaml.safe_dump(s, fh, sort_keys=False)
    return path


def polhode(*args):
    out = subprocess.run([POLHODE, *args], capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"polhode {' '.join(args)} failed:\n{out.stderr}")
    return out.stdout


def linearized(path):
    d = json.loads(polhode("linearize", path, "--json", "-"))
    n = d["nutation"]
    return n["time_constant"], n["energy_sink_time_constant"]


def measured(s, ntc, directory):
    """The time constant from the slope of ln(nutation angle) over a run of ntc / 10 (the first
    tenth of it left out, while the slosh modes' own transients decay)."""
    s = dict(s)
    s["duration"] = ntc / 10.0
    s["output"] = {"rate": 1.0}
    path = write(s, directory, "run.yaml")
    table = os.path.join(directory, "run.csv")
    polhode("run", path, "--csv", table, "--no-log", "-q")
    with open(table) as fh:
        rows = list(csv.DictReader(fh))
    t = [float(r["sim_time [s]"]) for r in rows]
    a = [math.log(float(r["nutation_angle_deg [deg]"])) for r in rows]
    pairs = [(x, y) for x, y in zip(t, a) if x > 0.1 * t[-1]]
    n = len(pairs)
    mx = sum(x for x, _ in pairs) / n
    my = sum(y for _, y in pairs) / n
    slope = sum((x - mx) * (y - my) for x, y in pairs) / sum((x - mx) ** 2 for x, _ in pairs)
    return 1.0 / slope


def main():
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for spin in SPINS:
            for fill in FILLS:
                s = scene(fill, spin)
                ntc, sink = linearized(write(s, tmp, "scene.yaml"))
                run = measured(s, ntc, tmp) if (fill, spin) in RUNS else None
                rows.append({"fill": fill, "spin_rad_s": spin, "ntc_s": ntc,
                             "energy_sink_ntc_s": sink, "run_ntc_s": run})
                print(f"fill {fill:.1f} spin {spin:.0f} rad/s: NTC {ntc:.1f} s "
                      f"(energy sink {sink:.1f} s" + (f", run {run:.1f} s)" if run else ")"),
                      flush=True)
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "slosh-ntc.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if v is None else (f"{v:.9g}" if isinstance(v, float) else v))
                        for k, v in r.items()})
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    matplotlib.rcParams["svg.hashsalt"] = "polhode"
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for spin in SPINS:
        mine = [r for r in rows if r["spin_rad_s"] == spin]
        f = [r["fill"] for r in mine]
        line, = ax.plot(f, [r["ntc_s"] / 3600 for r in mine], marker="o",
                        label=f"{spin:.0f} rad/s: eigenvalue")
        ax.plot(f, [r["energy_sink_ntc_s"] / 3600 for r in mine], ls="--",
                color=line.get_color(), label=f"{spin:.0f} rad/s: energy-sink estimate")
        runs = [r for r in mine if r["run_ntc_s"]]
        if runs:
            ax.plot([r["fill"] for r in runs], [r["run_ntc_s"] / 3600 for r in runs], ls="none",
                    marker="x", ms=10, color=line.get_color(), label=f"{spin:.0f} rad/s: from a run")
    ax.set_yscale("log")
    ax.set_xlabel("fill fraction of each tank (by volume)")
    ax.set_ylabel("nutation time constant (h)")
    ax.set_title("spinning-stage-tanks: two smooth spherical hydrazine tanks")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=1)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "slosh-ntc.svg"), metadata={"Date": None})
    fig.savefig(os.path.join(OUT, "slosh-ntc.png"), dpi=110, metadata={"Software": None})
    print("docs/figures/slosh-ntc.csv, .svg and .png written")


if __name__ == "__main__":
    main()
