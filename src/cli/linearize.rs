//! `polhode linearize`: eigenvalues of the linearisation about steady spin (or about the LVLH
//! equilibrium, or of the effectors under a driven hub).

use super::{EXIT_BAD_INPUT, load};
use crate::linearize::lvlh::LvlhLinearization;
use crate::linearize::{
    DrivenLinearization, Linearization, linearize, linearize_driven, spin_rate_of,
};
use crate::log::write_atomically;
use crate::scenario::{Overrides, Scenario};
use nalgebra::Vector3;
use std::path::Path;

/// What `polhode linearize` computes for a scenario.
enum Analysis {
    /// A gravity-gradient spacecraft in orbit, about its LVLH equilibrium.
    Lvlh(LvlhLinearization),
    /// A driven hub: the effectors' modes at the rate `omega` (rad/s) the motion reaches at
    /// the end of the run.
    Driven {
        lin: DrivenLinearization,
        omega: Vector3<f64>,
    },
    /// About steady spin at the scenario's initial rate.
    Spin(Linearization),
}

impl Analysis {
    /// Linearises `s` the way its kind of scene asks for.
    fn of(s: &Scenario) -> Result<Self, String> {
        if crate::linearize::lvlh::applies(&s.spacecraft) {
            let orbit = s
                .orbit
                .as_deref()
                .ok_or("the LVLH linearisation needs an `orbit:` block")?;
            return crate::linearize::lvlh::linearize_lvlh(&s.spacecraft, orbit, &s.attitude0)
                .map(Analysis::Lvlh);
        }
        if let Some(motion) = s.spacecraft.motion() {
            let omega = motion.omega(s.duration);
            let lin = linearize_driven(&s.spacecraft, &omega)?;
            return Ok(Analysis::Driven { lin, omega });
        }
        let rate = spin_rate_of(&s.spacecraft, &s.omega0);
        linearize(&s.spacecraft, rate).map(Analysis::Spin)
    }

    /// The `--json` document (pretty-printed, no final newline).
    fn json(&self) -> String {
        match self {
            Analysis::Lvlh(lin) => serde_json::to_string_pretty(lin),
            Analysis::Driven { lin, .. } => serde_json::to_string_pretty(lin),
            Analysis::Spin(lin) => serde_json::to_string_pretty(lin),
        }
        .unwrap_or_default()
    }

    /// Prints the text report.
    fn print(&self, s: &Scenario) {
        match self {
            Analysis::Lvlh(lin) => print!("{}", lin.report(&s.name)),
            Analysis::Driven { lin, omega } => print_driven(s, lin, omega),
            Analysis::Spin(lin) => print_linearization(s, lin),
        }
    }
}

/// The `polhode linearize --json` document of `s`, exactly as the CLI writes it (shared with
/// the Python package's `polhode.linearize`), or why the scenario cannot be linearised.
pub fn linearize_json(s: &Scenario) -> Result<String, String> {
    Analysis::of(s).map(|a| a.json())
}

/// Prints the linearisation of the scenario at `path`; writes it as JSON to `json` (`-`:
/// stdout, instead of the text report).
pub(super) fn linearize_cmd(path: &Path, json: Option<&Path>) -> i32 {
    let s = match load(path, &Overrides::default()) {
        Ok(s) => s,
        Err(c) => return c,
    };
    let analysis = match Analysis::of(&s) {
        Ok(a) => a,
        Err(m) => {
            eprintln!("error: {}: {m}", path.display());
            return EXIT_BAD_INPUT;
        }
    };
    if let Some(p) = json
        && p != Path::new("-")
        && let Err(e) = crate::outputs::Plan::new()
            .input("the scenario", path)
            .output("--json", p)
            .check()
    {
        eprintln!("error: {e}");
        return EXIT_BAD_INPUT;
    }
    match json {
        Some(p) if p == Path::new("-") => println!("{}", analysis.json()),
        Some(p) => {
            if let Err(e) = write_atomically(p, analysis.json().as_bytes()) {
                eprintln!("error: cannot write {}: {e}", p.display());
                return EXIT_BAD_INPUT;
            }
            analysis.print(&s);
        }
        None => analysis.print(&s),
    }
    0
}

/// The text report of the effectors' modes under a driven hub.
fn print_driven(s: &Scenario, lin: &DrivenLinearization, omega: &Vector3<f64>) {
    let motion = s
        .spacecraft
        .motion()
        .map(|m| m.describe())
        .unwrap_or_default();
    println!(
        "{}: hub driven ({motion}); effector modes at ω = [{:.6}, {:.6}, {:.6}] rad/s (the rate \
         at t = {})",
        s.name,
        omega[0],
        omega[1],
        omega[2],
        crate::timefmt::seconds(s.duration)
    );
    println!(
        "  {:>16} {:>16}  {:<12} time constant",
        "Re (1/s)", "Im (rad/s)", "mode"
    );
    for m in &lin.modes {
        let tc = m
            .time_constant
            .map(|t| format!("{t:.6} s"))
            .unwrap_or_else(|| "-".into());
        println!("  {:>16.9e} {:>16.9e}  {:<12} {tc}", m.re, m.im, m.kind);
    }
    println!("  verdict: {}", lin.verdict);
}

/// The text report of a linearisation about steady spin.
fn print_linearization(s: &Scenario, lin: &Linearization) {
    let a = lin.spin_axis;
    println!(
        "{}: steady spin {:.6} rad/s about [{:.4}, {:.4}, {:.4}] (principal axis {} of \
         I = {:.6}, {:.6}, {:.6} kg m²)",
        s.name,
        lin.spin_rate,
        a[0],
        a[1],
        a[2],
        lin.principal_axis,
        lin.principal_moments[0],
        lin.principal_moments[1],
        lin.principal_moments[2]
    );
    println!(
        "  {:>16} {:>16}  {:<12} {:<10} time constant",
        "Re (1/s)", "Im (rad/s)", "mode", "role"
    );
    for m in &lin.modes {
        let tc = m
            .time_constant
            .map(|t| format!("{t:.6} s"))
            .unwrap_or_else(|| "-".into());
        println!(
            "  {:>16.9e} {:>16.9e}  {:<12} {:<10} {tc}",
            m.re, m.im, m.kind, m.role
        );
    }
    println!("  verdict: {}", lin.verdict);
    if let Some(d) = &lin.deciding_mode {
        println!("  decided by: {d}");
    }
    print_spin_decay_and_gyrostat(lin);
    if let Some(n) = &lin.nutation {
        let what = if n.rate > 0.0 { "grows" } else { "decays" };
        match n.time_constant {
            Some(tc) => println!(
                "  nutation {what} at {:.9e} 1/s (time constant {tc:.6} s), frequency {:.6e} \
                 rad/s",
                n.rate, n.frequency
            ),
            None => println!("  nutation: neutral, frequency {:.6e} rad/s", n.frequency),
        }
        if let Some(warning) = &n.energy_sink_warning {
            println!("  energy-sink estimate: none (outside its assumptions here)");
            println!("  warning: {warning}");
        } else if let (Some(r), Some(tc), Some(d)) = (
            n.energy_sink_rate,
            n.energy_sink_time_constant,
            n.energy_sink_difference(),
        ) {
            println!(
                "  energy-sink estimate: {r:.9e} 1/s (time constant {tc:.6} s), {:+.1}% from \
                 the eigenvalue",
                100.0 * d
            );
        }
        if let Some(w) = &n.dual_spin_energy_sink {
            if let Some(warning) = &w.warning {
                println!(
                    "  weighted (dual-spin) energy-sink estimate: none (outside its assumptions \
                     here)"
                );
                println!("  warning: {warning}");
            } else {
                let tc = w
                    .time_constant
                    .map(|t| format!(" (time constant {t:.6} s)"))
                    .unwrap_or_default();
                println!(
                    "  weighted (dual-spin) energy-sink estimate: {:.9e} 1/s{tc}, {:+.1}% from \
                     the eigenvalue",
                    w.rate,
                    100.0 * w.relative_difference
                );
            }
            for b in &w.bodies {
                println!(
                    "    nutation seen in {} (spin {:.6e} rad/s): λ = {:+.6e} rad/s",
                    if b.body == "hub" {
                        "the hub".to_string()
                    } else {
                        format!("`{}`", b.body)
                    },
                    b.spin_rate,
                    b.nutation_frequency
                );
            }
            // Each sink's share of the estimate, only when there is one.
            for k in w.sinks.iter().filter(|_| w.valid) {
                println!(
                    "    `{}` on the {}: {:+.9e} 1/s",
                    k.effector, k.body, k.rate
                );
            }
        }
    } else if let Some(tc) = lin.time_constant {
        let what = if lin.max_growth_rate > 0.0 {
            "growth"
        } else {
            "decay"
        };
        println!(
            "  {what} rate {:.9e} 1/s, time constant {tc:.6} s",
            lin.max_growth_rate
        );
    }
    if lin.equilibrium_residual > 1e-9 {
        println!(
            "  warning: the effectors at rest are not in equilibrium under this spin (residual \
             {:.3e}); the linearisation is about a point that is not steady",
            lin.equilibrium_residual
        );
    }
    let r = &lin.rigid_body_prediction;
    let form = if lin.gyrostat.is_some() {
        "gyrostat closed form (rotors locked at their relative rates)"
    } else {
        "rigid-body closed form"
    };
    if r.growth_rate > 0.0 {
        println!("  {form}: k = {:.9e} 1/s", r.growth_rate);
    } else {
        println!("  {form}: nutation frequency {:.9e} rad/s", r.frequency);
    }
}

/// The `linearize` lines on the spin's own decay (an external torque) and on a gyrostat's
/// spinning rotors.
fn print_spin_decay_and_gyrostat(lin: &Linearization) {
    if let Some(m) = lin.modes.iter().find(|m| m.role == "spin_decay") {
        let tc = m
            .time_constant
            .map(|t| format!(" (time constant {t:.6} s)"))
            .unwrap_or_default();
        println!(
            "  spin decay: {:.9e} 1/s{tc}; an external torque drains |H|, so the spin is not \
             steady but decays (expected): the modes are those about the spin at this rate",
            m.re
        );
    }
    let Some(g) = &lin.gyrostat else { return };
    println!(
        "  gyrostat: rotor momentum h = {:.9e} N m s along the spin axis",
        g.rotor_momentum
    );
    match (g.rotor_decay_rate, g.rotor_decay_time_constant) {
        (Some(r), Some(tc)) => {
            let periods = g
                .nutation_periods_per_decay
                .map(|n| format!(", {n:.3e} nutation periods"))
                .unwrap_or_default();
            println!(
                "  {}: a damped rotor's relative rate decays at {r:.9e} 1/s (time constant \
                 {tc:.6} s{periods}); linearised about the rate frozen at its initial value",
                g.equilibrium
            );
            if g.equilibrium == "not steady" {
                println!(
                    "  warning: the rotor's relative rate decays within {} nutation periods, \
                     so the frozen-rate linearisation does not describe the motion; give the \
                     rotor less damping, or start it at rest",
                    crate::linearize::QUASI_STEADY_PERIODS
                );
            }
        }
        _ => println!("  {}: every spinning rotor is frictionless", g.equilibrium),
    }
}
