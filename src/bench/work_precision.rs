//! Work-precision: error against CPU time for every method on a set of problems.
//!
//! Each method sweeps its accuracy knob (tolerance for adaptive methods, step for fixed-step
//! ones) from coarse to fine, stopping once a solve exceeds its time budget or reaches the
//! reference's own accuracy. Errors are measured at the end of the run against the exact
//! solution (torque-free problems) or against a reference shown converged: two different
//! methods at tight tolerance, whose disagreement is reported and drawn as a floor.

use super::{Budget, MethodSpec, attitude_error, load_with, svg_and_png};
use crate::plot::{Axis, Chart, ReferenceLine, Scale, Series, Style};
use crate::scenario::Scenario;
use crate::sim::{self, Control, NullSink, Status};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

/// A problem of the work-precision set: a shipped scenario over a chosen span.
#[derive(Debug, Clone, Copy)]
pub struct Problem {
    /// Short name, used in file names.
    pub name: &'static str,
    /// Scenario file, relative to the repository root.
    pub scenario: &'static str,
    /// Simulated span (s).
    pub duration: f64,
}

/// The set charted in docs/choosing-a-method.md.
pub const PROBLEMS: [Problem; 5] = [
    Problem {
        name: "generic-tumble",
        scenario: "scenarios/generic-tumble.yaml",
        duration: 100.0,
    },
    Problem {
        name: "near-separatrix",
        scenario: "scenarios/near-separatrix.yaml",
        duration: 100.0,
    },
    Problem {
        name: "tennis-racket",
        scenario: "scenarios/tennis-racket.yaml",
        duration: 10.0,
    },
    Problem {
        name: "damper",
        scenario: "scenarios/nutation-damper.yaml",
        duration: 100.0,
    },
    Problem {
        name: "explorer1-pydy",
        scenario: "scenarios/explorer1-pydy.yaml",
        duration: 20.0,
    },
];

/// The final state every error is measured against.
#[derive(Debug, Clone)]
pub struct ReferenceSolution {
    /// State at the end of the span.
    pub state: Vec<f64>,
    /// How it was obtained.
    pub how: String,
    /// Attitude (rad) and relative ω disagreement of the two references (0 for `exact`).
    pub disagreement: (f64, f64),
}

/// One measured point.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Measurement {
    /// Problem name.
    pub problem: String,
    /// Method label (e.g. `gauss-2`).
    pub method: String,
    /// Method and settings as run.
    pub settings: String,
    /// Step (s) of a fixed-step method, else NaN.
    pub dt: f64,
    /// Relative tolerance of an adaptive method, else NaN.
    pub rtol: f64,
    /// Fastest of the repeated solves (s).
    pub cpu_seconds: f64,
    /// Final attitude error (rad), `2·atan2` form.
    pub attitude_error: f64,
    /// Final |ω − ω_ref| / |ω_ref|.
    pub omega_error: f64,
    /// Largest relative drift of the energy balance over the run.
    pub drift_energy: f64,
    /// Largest relative drift of |H| over the run.
    pub drift_momentum: f64,
    /// Largest ||q| − 1| over the run.
    pub drift_q_norm: f64,
    /// Accepted steps.
    pub steps: u64,
    /// Rejected steps.
    pub rejected_steps: u64,
    /// Right-hand-side evaluations.
    pub rhs_evaluations: u64,
    /// Newton iterations.
    pub newton_iterations: u64,
    /// `ok`, or why the point failed.
    pub status: String,
}

/// Loads `problem` over its span with `method` at accuracy `knob` (dt or rtol).
fn scenario_for(
    root: &Path,
    problem: &Problem,
    method: &MethodSpec,
    knob: Option<f64>,
) -> Result<Scenario, String> {
    load_with(
        &root.join(problem.scenario),
        method,
        knob,
        Some(problem.duration),
    )
}

/// The reference final state of `problem`.
pub fn reference(root: &Path, problem: &Problem) -> Result<ReferenceSolution, String> {
    let exact = MethodSpec::by_label("exact").expect("exact is a method");
    let probe = scenario_for(root, problem, &exact, None);
    if let Ok(s) = probe {
        let solve = sim::integrate_only(&s, s.duration)?;
        return Ok(ReferenceSolution {
            state: solve.final_state,
            how: "exact (closed-form torque-free solution)".into(),
            disagreement: (0.0, 0.0),
        });
    }
    let a = MethodSpec::by_label("dop853").expect("dop853 is a method");
    let b = MethodSpec::by_label("dopri5").expect("dopri5 is a method");
    let sa = scenario_for(root, problem, &a, Some(1e-13))?;
    let sb = scenario_for(root, problem, &b, Some(1e-13))?;
    let ya = sim::integrate_only(&sa, sa.duration)?.final_state;
    let yb = sim::integrate_only(&sb, sb.duration)?.final_state;
    let disagreement = errors(&ya, &yb);
    Ok(ReferenceSolution {
        state: ya,
        how: format!(
            "dop853 at rtol 1e-13 (dopri5 at 1e-13 agrees to {:.1e} rad in attitude, {:.1e} in ω)",
            disagreement.0, disagreement.1
        ),
        disagreement,
    })
}

/// Attitude error (rad) and relative ω error of `y` against `reference`.
pub fn errors(reference: &[f64], y: &[f64]) -> (f64, f64) {
    let att = attitude_error(&reference[3..7], &y[3..7]);
    let w_ref = (reference[0].powi(2) + reference[1].powi(2) + reference[2].powi(2)).sqrt();
    let dw = ((y[0] - reference[0]).powi(2)
        + (y[1] - reference[1]).powi(2)
        + (y[2] - reference[2]).powi(2))
    .sqrt();
    (att, dw / w_ref.max(f64::MIN_POSITIVE))
}

/// Measures `method` at `knob` on `problem`: timed solves (minimum of repeats), then one
/// untimed run through the run loop for the largest invariant drift.
pub fn measure(
    root: &Path,
    problem: &Problem,
    method: &MethodSpec,
    knob: Option<f64>,
    reference: &ReferenceSolution,
) -> Measurement {
    let mut m = Measurement {
        problem: problem.name.into(),
        method: method.label.into(),
        settings: String::new(),
        dt: if method.fixed_step {
            knob.unwrap_or(f64::NAN)
        } else {
            f64::NAN
        },
        rtol: if method.adaptive {
            knob.unwrap_or(f64::NAN)
        } else {
            f64::NAN
        },
        cpu_seconds: f64::NAN,
        attitude_error: f64::NAN,
        omega_error: f64::NAN,
        drift_energy: f64::NAN,
        drift_momentum: f64::NAN,
        drift_q_norm: f64::NAN,
        steps: 0,
        rejected_steps: 0,
        rhs_evaluations: 0,
        newton_iterations: 0,
        status: "ok".into(),
    };
    let mut s = match scenario_for(root, problem, method, knob) {
        Ok(s) => s,
        Err(e) => {
            m.status = format!("not applicable: {e}");
            return m;
        }
    };
    m.settings = s.method.describe();
    let point = match super::point(&s, 0) {
        Ok(p) => p,
        Err(e) => {
            m.status = format!("failed: {e}");
            return m;
        }
    };
    m.cpu_seconds = point.cpu_seconds;
    m.steps = point.steps;
    m.rejected_steps = point.rejected_steps;
    m.rhs_evaluations = point.rhs_evaluations;
    m.newton_iterations = point.newton_iterations;
    (m.attitude_error, m.omega_error) = errors(&reference.state, &point.final_state);
    // Drift over the run: one sample at the end, the loop still checks every step.
    s.output_rate = 1.0 / s.duration;
    s.stop.clear();
    s.events.clear();
    let interrupt = AtomicBool::new(false);
    let ctl = Control {
        interrupt: &interrupt,
        progress: None,
    };
    if let Ok(o) = sim::run(&s, &mut NullSink, ctl) {
        m.drift_energy = o.drift.energy_rel;
        m.drift_momentum = o.drift.h_norm_rel;
        m.drift_q_norm = o.drift.q_norm;
        if let Status::Failed { diagnosis } = o.status {
            m.status = format!("failed: {diagnosis}");
        }
    }
    if !(m.attitude_error.is_finite() && m.omega_error.is_finite()) {
        m.status = "failed: non-finite final state".into();
    }
    m
}

/// Sweeps every method of `methods` on `problem` within `budget`, reporting progress.
pub fn sweep(
    root: &Path,
    problem: &Problem,
    methods: &[MethodSpec],
    budget: &Budget,
    mut progress: impl FnMut(&Measurement),
) -> Result<(ReferenceSolution, Vec<Measurement>), String> {
    let reference = reference(root, problem)?;
    let base = scenario_for(
        root,
        problem,
        &MethodSpec::by_label("dopri5").expect("dopri5"),
        Some(1e-6),
    )?;
    let spin = base.omega0.norm().max(1.0 / problem.duration);
    let y0 = base.spacecraft.initial_state(&base.omega0, &base.attitude0);
    let stiff = crate::linearize::stiffness(&base.spacecraft, 0.0, &y0, problem.duration);
    // Coarsest fixed step: a radian of rotation, or the explicit stability bound.
    let dt_coarse = (1.0 / spin).min(2.5 / stiff.spectral_radius.max(spin));
    let floor = reference.disagreement.0.max(1e-15);
    let mut out = Vec::new();
    for method in methods {
        let knobs: Vec<Option<f64>> = if method.fixed_step {
            (0..budget.max_points)
                .map(|k| Some(dt_coarse / 2f64.powi(k as i32)))
                .collect()
        } else if method.adaptive {
            (0..budget.max_points)
                .map(|k| Some(10f64.powi(-3 - k as i32)))
                .filter(|k| k.is_some_and(|r| r >= 1e-14))
                .collect()
        } else {
            vec![None]
        };
        for knob in knobs {
            let m = measure(root, problem, method, knob, &reference);
            progress(&m);
            let stop = m.status.starts_with("not applicable")
                || m.cpu_seconds > budget.seconds_per_point
                || (m.status == "ok" && m.attitude_error < 10.0 * floor);
            out.push(m);
            if stop {
                break;
            }
        }
    }
    Ok((reference, out))
}

/// The chart of one problem: final attitude error against CPU time.
pub fn chart(problem: &Problem, reference: &ReferenceSolution, points: &[Measurement]) -> Chart {
    let mut c = Chart::new(
        format!("Work-precision: {} ({} s)", problem.name, problem.duration),
        "CPU time (s), fastest of repeats",
        "final attitude error (rad)",
    );
    c.x_scale = Scale::Log10;
    c.y_scale = Scale::Log10;
    let mut labels: Vec<&str> = points.iter().map(|m| m.method.as_str()).collect();
    labels.dedup();
    for (i, label) in labels.iter().enumerate() {
        let pts: Vec<(f64, f64)> = points
            .iter()
            .filter(|m| m.method == *label && m.status == "ok")
            .map(|m| (m.cpu_seconds, m.attitude_error.max(1e-16)))
            .filter(|(x, y)| x.is_finite() && *x > 0.0 && y.is_finite())
            .collect();
        if pts.is_empty() {
            continue;
        }
        let style = if i < 8 {
            Style::LineMarkers
        } else {
            Style::Dashed
        };
        c.series.push(Series::new(*label, pts, style));
    }
    if reference.disagreement.0 > 0.0 {
        c.reference_lines.push(ReferenceLine::new(
            Axis::Y,
            reference.disagreement.0,
            "reference disagreement",
        ));
    }
    c
}

/// CSV of measurements (one header line).
pub fn csv(points: &[Measurement]) -> String {
    let mut s = String::from(
        "problem,method,settings,dt_s,rtol,cpu_s,attitude_error_rad,omega_error_rel,\
         drift_energy_rel,drift_h_rel,drift_q_norm,steps,rejected_steps,rhs_evaluations,\
         newton_iterations,status\n",
    );
    for m in points {
        let _ = writeln!(
            s,
            "{},{},\"{}\",{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{},{},{},{},\"{}\"",
            m.problem,
            m.method,
            m.settings,
            m.dt,
            m.rtol,
            m.cpu_seconds,
            m.attitude_error,
            m.omega_error,
            m.drift_energy,
            m.drift_momentum,
            m.drift_q_norm,
            m.steps,
            m.rejected_steps,
            m.rhs_evaluations,
            m.newton_iterations,
            m.status.replace('"', "'")
        );
    }
    s
}

/// Runs the sweep on `problems` and writes `work-precision-<name>.svg|png` per problem and
/// `work-precision.csv` into `out`. Returns the files written.
pub fn run(
    root: &Path,
    problems: &[Problem],
    methods: &[MethodSpec],
    budget: &Budget,
    out: &Path,
    mut progress: impl FnMut(&str),
) -> Result<Vec<PathBuf>, String> {
    let mut all = Vec::new();
    let mut files = Vec::new();
    let mut notes = String::from("problem,reference\n");
    for p in problems {
        progress(&format!("{}: reference", p.name));
        let (reference, points) = sweep(root, p, methods, budget, |m| {
            progress(&format!(
                "{}: {} {} → {:.2e} rad in {:.3e} s ({})",
                p.name,
                m.method,
                if m.dt.is_finite() {
                    format!("dt {:e}", m.dt)
                } else if m.rtol.is_finite() {
                    format!("rtol {:e}", m.rtol)
                } else {
                    String::new()
                },
                m.attitude_error,
                m.cpu_seconds,
                m.status.split(';').next().unwrap_or("")
            ))
        })?;
        let _ = writeln!(notes, "{},\"{}\"", p.name, reference.how);
        let stem = out.join(format!("work-precision-{}", p.name));
        files.extend(svg_and_png(&chart(p, &reference, &points), &stem)?);
        all.extend(points);
    }
    let path = out.join("work-precision.csv");
    crate::outputs::write_atomically(&path, csv(&all).as_bytes())
        .map_err(|e| format!("{}: {e}", path.display()))?;
    files.push(path);
    let path = out.join("work-precision-references.csv");
    crate::outputs::write_atomically(&path, notes.as_bytes())
        .map_err(|e| format!("{}: {e}", path.display()))?;
    files.push(path);
    Ok(files)
}
