#!/usr/bin/env python3
"""Regenerates the tables of docs/peers.md from peers/results/*.json.

docs/peers.md keeps its prose; every generated part sits between
`<!-- generated:NAME -->` and `<!-- /generated:NAME -->` and is replaced whole.
"""
import json
import math
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
RESULTS = os.path.join(HERE, "results")
DOC = os.path.join(ROOT, "docs", "peers.md")

PEERS = [("rust-ode", "dop853", "Rust DOP853"), ("rust-ode", "dopri5", "Rust DOPRI5"),
         ("scipy", "DOP853", "SciPy DOP853"), ("scipy", "RK45", "SciPy RK45"),
         ("scipy", "Radau", "SciPy Radau")]
LABEL = {("polhode", "dop853"): "polhode dop853", ("polhode", "dopri5"): "polhode dopri5",
         **{(s, m): l for s, m, l in PEERS}}


def e(x, digits=1):
    return "—" if x is None else f"{x:.{digits}e}"


def ms(sec):
    if sec is None:
        return "—"
    v = sec * 1e3
    if v >= 1000:
        return f"{v:,.0f}".replace(",", " ")
    if v >= 100:
        return f"{v:.0f}"
    if v >= 10:
        return f"{v:.1f}"
    return f"{v:.2f}"


def ratio_cell(r):
    if r is None or r.get("speedup") is None:
        return "—" if r is None else f"— ({r['how']})"
    s = r["speedup"]
    txt = f"{s:.0f}" if s >= 10 else f"{s:.2f}" if s < 1 else f"{s:.1f}"
    return ("~" if r["how"] == "extrapolated" else "") + txt


def fmt_rtol(r):
    return f"{r:.0e}".replace("e-0", "e-")


def block_versions(summary, bsk):
    v = summary["versions"]
    lines = [
        f"- Generated {summary['generated']} by `peers/run.sh` (benchmarks {summary['wall_seconds']:.0f} s"
        + (f", Basilisk part {bsk['wall_seconds']:.0f} s" if bsk and 'wall_seconds' in bsk else "") + ").",
        f"- Machine: {v.get('cpu', '?')}, {v.get('cores', '?')} cores, shared with other work "
        "(hence minima of repeats, and every ratio taken within this one run).",
        f"- polhode: `{v.get('polhode', '?')}`, commit {v.get('polhode_commit', '?')}"
        + (" with uncommitted changes in src/" if v.get("polhode_src_modified") else "")
        + f", release build; {v.get('rustc', '?')}.",
        f"- Rust peer: differential-equations {v.get('differential_equations', '?')} (`peers/rust-ode/`), same compiler, release profile.",
        f"- Python {v['python']}, NumPy {v['numpy']}, SciPy {v['scipy']}"
        + (f", Basilisk (bsk) {bsk['basilisk']}" if bsk else "") + " (`peers/requirements.txt`).",
        f"- Tolerances: rtol {', '.join(fmt_rtol(r) for r in summary['rtols'])}, atol = "
        f"{summary['atol_factor']:g} × rtol, the same for every integrator. A SciPy run predicted "
        f"to take over {summary['scipy_cap']:g} s is skipped (marked in the run tables).",
        f"- polhode methods in this run: {', '.join(summary['polhode_methods'])}.",
    ]
    return "\n".join(lines)


def block_problems(summary):
    rows = ["| problem | scenario | sim time | reference for the errors | note |",
            "|---|---|---|---|---|"]
    for p in summary["problems"]:
        ref = p.get("reference", {})
        dur = ref.get("point", {}).get("duration", p.get("duration"))
        rows.append(f"| {p['key']} | `{p['scenario']}` | {dur:g} s | {ref.get('description', '?')} | "
                    f"{p.get('note', '')} |")
    return "\n".join(rows)


def block_refcheck(summary):
    rows = ["| problem | reference | SciPy DOP853 rtol 1e-13 (independent model) vs reference: attitude, ω | "
            "polhode dopri5 rtol 1e-13 vs reference: attitude, ω |",
            "|---|---|---|---|"]
    for c in summary["reference_checks"]:
        s = c["scipy_dop853_ref"]
        o = c.get("polhode_dopri5_ref")
        rows.append(f"| {c['problem']} | {c['reference']} | {e(s['attitude_error'])} rad, "
                    f"{e(s['omega_error'])} rad/s | "
                    + (f"{e(o['attitude_error'])} rad, {e(o['omega_error'])} rad/s |" if o else "— |"))
    return "\n".join(rows)


def find_ratio(summary, key, pm, rtol, side, method):
    for r in summary["ratios"]:
        if (r["problem"] == key and r["polhode_method"] == pm and r["rtol"] == rtol
                and r["peer"] == side and r["peer_method"] == method):
            return r
    return None


def block_headline(summary, runs):
    pm = summary["polhode_methods"][0]
    head = ["problem", "rtol", f"polhode {pm} (ms)", "attitude error (rad)"] + \
        [l for _, _, l in PEERS]
    if pm != "dopri5":
        head.append("polhode dopri5 vs Rust DOPRI5")
    rows = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for p in summary["problems"]:
        key = p["key"]
        for rtol in summary["rtols"]:
            run = next((r for r in runs if r["problem"] == key and r["side"] == "polhode"
                        and r["method"] == pm and r["rtol"] == rtol), None)
            if run is None:
                continue
            cells = [key, fmt_rtol(rtol), ms(run["cpu_seconds"]), e(run["attitude_error"])]
            cells += [ratio_cell(find_ratio(summary, key, pm, rtol, s, m)) for s, m, _ in PEERS]
            if pm != "dopri5":
                cells.append(ratio_cell(find_ratio(summary, key, "dopri5", rtol, "rust-ode", "dopri5")))
            rows.append("| " + " | ".join(cells) + " |")
    return "\n".join(rows)


def block_target(summary):
    pm = summary["polhode_methods"][0]
    out = []
    for side, m, label, target, word in [("scipy", "DOP853", "SciPy DOP853", 100.0, "≥ 100× faster"),
                                         ("rust-ode", "dop853", "the Rust crate's DOP853", 1.0, "no slower")]:
        rs = [r for r in summary["ratios"] if r["polhode_method"] == pm and r["peer"] == side
              and r["peer_method"] == m and r.get("speedup")]
        if not rs:
            out.append(f"- polhode {pm} against {label}: no comparable runs.")
            continue
        interp = [r for r in rs if r["how"] == "interpolated"] or rs
        lo = min(interp, key=lambda r: r["speedup"])
        hi = max(interp, key=lambda r: r["speedup"])
        met = all(r["speedup"] >= target for r in interp)
        failing = [r for r in interp if r["speedup"] < target]
        med = sorted(r["speedup"] for r in interp)[len(interp) // 2]
        txt = (f"- **polhode {pm} against {label}** (target: {word} at equal error): "
               f"{'met on all' if met else 'met on ' + str(len(interp) - len(failing)) + ' of'} "
               f"{len(interp)} interpolated points; median {med:.3g}×, lowest {lo['speedup']:.3g}× "
               f"({lo['problem']}, rtol {fmt_rtol(lo['rtol'])}), highest {hi['speedup']:.3g}× "
               f"({hi['problem']}, rtol {fmt_rtol(hi['rtol'])}).")
        if failing:
            txt += " Below target: " + ", ".join(
                f"{r['problem']} rtol {fmt_rtol(r['rtol'])} ({r['speedup']:.3g}×)" for r in failing) + "."
        out.append(txt)
    return "\n".join(out)


def block_runs(summary, runs):
    pm = summary["polhode_methods"][0]
    out = []
    for p in summary["problems"]:
        key = p["key"]
        out.append(f"**{key}**\n")
        out.append("| rtol | integrator | time (ms) | steps | RHS evals | attitude error (rad) | "
                   f"ω error (rad/s) | peer time at polhode {pm}'s error ÷ polhode time |")
        out.append("|---|---|---|---|---|---|---|---|")
        for rtol in summary["rtols"]:
            for r in [r for r in runs if r["problem"] == key and r["rtol"] == rtol]:
                label = LABEL.get((r["side"], r["method"]), f"{r['side']} {r['method']}")
                if "skipped" in r:
                    out.append(f"| {fmt_rtol(rtol)} | {label} | skipped: {r['skipped']} | | | | | |")
                    continue
                rr = None if r["side"] == "polhode" else find_ratio(summary, key, pm, rtol, r["side"], r["method"])
                out.append(f"| {fmt_rtol(rtol)} | {label} | {ms(r['cpu_seconds'])} | {r['steps']} | "
                           f"{r['rhs_evaluations']} | {e(r['attitude_error'])} | {e(r['omega_error'])} | "
                           f"{'' if r['side'] == 'polhode' else ratio_cell(rr)} |")
        out.append("")
    return "\n".join(out).rstrip()


def block_basilisk(bsk):
    if bsk is None:
        return "_Not run (see below)._"
    t = bsk["timing"]
    lines = [
        f"Reference for the trajectories: {bsk['reference']}. Sampled every "
        f"{bsk['sample_times'][1] - bsk['sample_times'][0]:g} s over {t['duration']:g} s "
        f"({len(bsk['sample_times'])} times).",
        "",
        "| | Basilisk | polhode | Basilisk ÷ polhode |",
        "|---|---|---|---|",
        f"| time per RK4 step (dt {t['dt']:g} s, {t['steps']} steps, min of {len(t['basilisk_seconds_all'])}) | "
        f"{t['basilisk_us_per_step']:.2f} µs | {t['polhode_us_per_step']:.3f} µs | {t['ratio']:.0f} |",
        f"| whole run | {ms(t['basilisk_seconds'])} ms | {ms(t['polhode_seconds'])} ms | |",
        "",
        "| RK4 step | max \\|ω − ω_ref\\| Basilisk | polhode | max \\|ω_Basilisk − ω_polhode\\| | "
        "max \\|ρ − ρ_ref\\| Basilisk | polhode | max \\|ρ_B − ρ_P\\| | attitude error Basilisk (MRP) | polhode (quaternion) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for s in bsk["trajectories"]:
        b, p, d = s["basilisk_vs_ref"], s["polhode_vs_ref"], s["basilisk_vs_polhode"]
        lines.append(f"| {s['dt']:g} s | {e(b['omega'])} rad/s | {e(p['omega'])} | {e(d['omega'])} | "
                     f"{e(b['rho'])} m | {e(p['rho'])} | {e(d['rho'])} | {e(b['attitude'])} rad | "
                     f"{e(p['attitude'])} |")
    lines.append("")
    lines.append(f"Final state at dt {t['dt']:g} s: |ω_B − ω_P| = {e(t['final_omega_difference'])} rad/s, "
                 f"|ρ_B − ρ_P| = {e(t['final_rho_difference'])} m; Basilisk's SMD mass state at the end: "
                 f"{t['basilisk_mass_at_end']:g} kg (constant).")
    return "\n".join(lines)


def vec_cell(v, digits=6):
    return "(" + ", ".join(f"{x:.{digits - 1}e}" for x in v) + ")"


ENV_TITLES = {"gravity_gradient": ("Gravity gradient", "GravityGradientEffector"),
              "magnetic_dipole": ("Magnetic dipole", "MagneticFieldCenteredDipole + MtbEffector"),
              "aerodynamic": ("Aerodynamic", "ExponentialAtmosphere + ZeroWindModel + FacetDragDynamicEffector"),
              "solar_pressure": ("Solar pressure", "FacetSRPDynamicEffector + Eclipse")}


def env_context(kind, fed):
    """A short column of what Basilisk computed on the way (the state's scale)."""
    if kind == "gravity_gradient":
        return f"r = {sum(x * x for x in fed['r_eci']) ** 0.5 / 1e3:.1f} km"
    if kind == "magnetic_dipole":
        b = sum(x * x for x in fed["b_eci"]) ** 0.5
        return f"{fed['decimal_year']:.3f}, \\|B\\| = {b * 1e6:.2f} µT"
    if kind == "aerodynamic":
        return f"h = {fed['altitude'] / 1e3:.1f} km, ρ = {fed['density']:.4e} kg/m³"
    return f"shadow factor {fed['shadow_factor']:g}, {fed['sun_distance_au']:.5f} AU"


def block_environment(bsk_env, pol_env):
    if bsk_env is None or pol_env is None:
        return "_Not run (see below)._"
    lines = [f"Basilisk (bsk) {bsk_env['basilisk']}, generated {bsk_env['generated']}; torques in N m, "
             f"body axes; relative difference \\|τ_polhode − τ_Basilisk\\| / \\|τ_Basilisk\\| "
             f"(0 where both are exactly zero); the test's tolerance is {pol_env['tolerance']:.0e}."]
    for kind, (title, modules) in ENV_TITLES.items():
        fed = bsk_env["effectors"][kind]
        rows = pol_env["effectors"][kind]
        lines += ["", f"**{title}** ({modules})", "",
                  "| state | Basilisk computed | Basilisk torque | polhode torque | relative difference |",
                  "|---|---|---|---|---|"]
        for f_row, p_row in zip(fed, rows):
            assert f_row["input"]["label"] == p_row["label"], (f_row["input"]["label"], p_row["label"])
            lines.append(f"| {p_row['label']} | {env_context(kind, f_row['basilisk'])} | "
                         f"{vec_cell(p_row['basilisk'])} | {vec_cell(p_row['polhode'])} | "
                         f"{p_row['relative_difference']:.1e} |")
    return "\n".join(lines)


def rate(x):
    return f"{x:.3g}" if x < 10 else f"{x:.0f}" if x >= 100 else f"{x:.1f}"


def block_campaign(camp):
    if camp is None:
        return "_Not run (peers/campaign.py writes peers/results/campaign.json)._"
    c, v = camp["campaign"], camp["versions"]
    lanes, scalar = camp["polhode"]["lanes"], camp["polhode"]["scalar"]
    load = v.get("load_average_at_start")
    lines = [
        f"Generated {camp['generated']} by `peers/campaign.py` ({camp['wall_seconds']:.0f} s): "
        f"`{camp['scenario']}`, {c['runs']} runs of {c['duration']:g} s (seed {c['seed']}), "
        f"{c['method']} at rtol {c['rtol']:g}, atol {c['atol']:g}; {v.get('cpu', '?')}, "
        f"{v.get('cores', '?')} cores, AVX2 {'yes' if v.get('avx2') else 'no'}"
        + (f", AVX-512 {'yes' if v['avx512f'] else 'no'}" if "avx512f" in v else "")
        + (f", load average {load[0]:.2f} at the start" if load else "")
        + f"; `{v.get('polhode', '?')}` (source of commit {v.get('polhode_commit', '?')}), SciPy {v['scipy']}. "
        f"polhode: best of {camp['repeats']} campaigns each way, alternated; SciPy: once.",
        "",
        "| one thread | runs | steps a run | seconds | runs/s (wall) | runs per CPU-second | "
        "lanes ÷ it (CPU) |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    rows = [("polhode, lanes (`--threads 1 --shard 1/1`)", lanes),
            ("polhode, `--no-lanes`", scalar)]
    rows += [(f"SciPy `solve_ivp` {m} (first {r['runs']} runs)", r) for m, r in camp["scipy"].items()]
    for label, r in rows:
        lines.append(f"| {label} | {r['runs']} | {r['steps_per_run']:.0f} | {r['seconds']:.2f} | "
                     f"{rate(r['runs_per_s'])} | {rate(r['runs_per_cpu_s'])} | "
                     f"{rate(lanes['runs_per_cpu_s'] / r['runs_per_cpu_s'])} |")
    lo_hi = {k: (min(t["all_runs_per_cpu_s"]), max(t["all_runs_per_cpu_s"]))
             for k, t in camp["polhode"].items()}
    lines += [
        "",
        f"Every repeat, runs per CPU-second: lanes {lo_hi['lanes'][0]:.0f}–{lo_hi['lanes'][1]:.0f}, "
        f"`--no-lanes` {lo_hi['scalar'][0]:.0f}–{lo_hi['scalar'][1]:.0f}; lanes ÷ `--no-lanes` "
        f"within each adjacent pair: "
        + ", ".join(f"{x:.2f}" for x in camp["ratios"]["lanes_over_scalar_paired"])
        + f" (median {camp['ratios']['lanes_over_scalar_paired_median']:.2f}). Header lines: "
        f"`{lanes['path']}` and `{scalar['path']}`. The two paths' `runs.csv` are identical"
        + ("" if camp.get("tables_identical") else " (NOT checked)") + ". SciPy's dissipated energy "
        "at the end of each run is within "
        + ", ".join(f"{r['energy_dissipated_max_rel_diff_vs_polhode']:.0e} ({m})"
                    for m, r in camp["scipy"].items())
        + " of polhode's `energy_dissipated` column, relative: the same draws.",
    ]
    return "\n".join(lines)


def load_optional(name):
    path = os.path.join(RESULTS, name)
    if not os.path.exists(path):
        return None
    with open(path) as fh:
        return json.load(fh)


def replace_block(text, name, content):
    pat = re.compile(rf"(<!-- generated:{name} -->).*?(<!-- /generated:{name} -->)", re.S)
    if not pat.search(text):
        raise SystemExit(f"docs/peers.md has no generated:{name} block")
    return pat.sub(lambda m: m.group(1) + "\n" + content + "\n" + m.group(2), text)


def main():
    with open(os.path.join(RESULTS, "summary.json")) as fh:
        summary = json.load(fh)
    with open(os.path.join(RESULTS, "runs.json")) as fh:
        runs = json.load(fh)
    bsk = None
    bp = os.path.join(RESULTS, "basilisk.json")
    if os.path.exists(bp):
        with open(bp) as fh:
            bsk = json.load(fh)
    bsk_env, pol_env = (load_optional(n) for n in ("basilisk_environment.json",
                                                   "basilisk_environment_polhode.json"))
    camp = load_optional("campaign.json")
    # Ratios afresh from the runs (so a change of method here needs no re-run).
    sys.path.insert(0, HERE)
    from bench import compute_ratios
    summary["ratios"] = compute_ratios(runs, [p["key"] for p in summary["problems"]])
    with open(DOC) as fh:
        text = fh.read()
    blocks = {"versions": block_versions(summary, bsk), "problems": block_problems(summary),
              "refcheck": block_refcheck(summary), "headline": block_headline(summary, runs),
              "target": block_target(summary), "runs": block_runs(summary, runs),
              "campaign": block_campaign(camp), "basilisk": block_basilisk(bsk),
              "environment": block_environment(bsk_env, pol_env)}
    for name, content in blocks.items():
        text = replace_block(text, name, content)
    with open(DOC, "w") as fh:
        fh.write(text)
    print(f"[report] updated {os.path.relpath(DOC, ROOT)}: {', '.join(blocks)}")


if __name__ == "__main__":
    main()
