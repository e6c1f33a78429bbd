//! `polhode compare`: several fidelities of one scene side by side — the quantities that
//! matter (when the nutation angle passes 45° and 80°, the final spin axis, the energy lost)
//! against the cost (states, steps, right-hand-side evaluations, wall time).

use crate::integrate::OdeSystem;
use crate::model::Observation;
use crate::plot::{Axis, Chart, ReferenceLine, Series, Style};
use crate::scenario::{Condition, Quantity, Scenario};
use crate::sim::{self, Control, EventRecord, Outcome, Reference, Sink};
use std::sync::atomic::AtomicBool;

/// Nutation angles (degrees) whose first crossing is reported.
pub const MILESTONES_DEG: [f64; 2] = [45.0, 80.0];

/// One scenario's results.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Row {
    /// Scenario name.
    pub name: String,
    /// Effector kinds, e.g. `4 × hinged_rod`.
    pub model: String,
    /// Number of states integrated.
    pub states: usize,
    /// How the run ended.
    pub status: String,
    /// Sim time reached (s).
    pub t_end: f64,
    /// First time the nutation angle passes each of [`MILESTONES_DEG`] (s), if it does.
    pub nutation_crossings: Vec<Option<f64>>,
    /// Nutation angle at the end (degrees).
    pub final_nutation_deg: f64,
    /// Angle of H from the maximum-inertia axis (or plane) at the end (degrees).
    pub final_angle_to_max_axis_deg: f64,
    /// Kinetic energy at the start and at the end (J).
    pub kinetic_energy: [f64; 2],
    /// Fraction of the initial kinetic energy lost.
    pub energy_lost_fraction: f64,
    /// Accepted steps.
    pub steps: u64,
    /// Right-hand-side evaluations.
    pub rhs_evaluations: u64,
    /// Wall time of the run (s).
    pub wall_time: f64,
    /// Largest relative drift of the energy balance (kinetic + elastic + dissipated).
    pub energy_balance_drift: f64,
    /// Sampled nutation angle (t in s, degrees), for the chart.
    #[serde(skip)]
    pub nutation_series: Vec<(f64, f64)>,
}

/// Keeps (t, nutation angle) of every output sample.
struct NutationRecorder(Vec<(f64, f64)>);

impl Sink for NutationRecorder {
    fn sample(&mut self, o: &Observation, _y: &[f64], _r: &Reference) -> std::io::Result<()> {
        self.0.push((o.t, o.nutation_angle.to_degrees()));
        Ok(())
    }
    fn event(&mut self, _e: &EventRecord, _o: &Observation) -> std::io::Result<()> {
        Ok(())
    }
}

fn describe_model(s: &Scenario) -> String {
    let mut kinds: Vec<(&str, usize)> = Vec::new();
    for e in s.spacecraft.effectors() {
        match kinds.iter_mut().find(|(k, _)| *k == e.kind()) {
            Some(entry) => entry.1 += 1,
            None => kinds.push((e.kind(), 1)),
        }
    }
    if kinds.is_empty() {
        return "rigid".into();
    }
    kinds
        .iter()
        .map(|(k, n)| {
            if *n > 1 {
                format!("{n} × {k}")
            } else {
                k.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join(" + ")
}

/// Runs one scenario (no log) and extracts its row. Nutation milestones are located exactly
/// as events.
pub fn run_one(mut s: Scenario, interrupt: &AtomicBool) -> std::io::Result<Row> {
    for deg in MILESTONES_DEG {
        let c = Condition::crossing(Quantity::NutationAngleDeg, deg, true);
        if !s.events.contains(&c) {
            s.events.push(c);
        }
    }
    let mut rec = NutationRecorder(Vec::new());
    let out: Outcome = sim::run(
        &s,
        &mut rec,
        Control {
            interrupt,
            progress: None,
        },
    )?;
    let crossings = MILESTONES_DEG
        .iter()
        .map(|deg| {
            let key = format!("nutation_angle_deg above {deg}");
            out.events.iter().find(|e| e.condition == key).map(|e| e.t)
        })
        .collect();
    let (angle, _) = s.spacecraft.angle_to_max_inertia(&out.final_state);
    let t0 = out.initial_observation.kinetic_energy;
    let t1 = out.final_observation.kinetic_energy;
    Ok(Row {
        name: s.name.clone(),
        model: describe_model(&s),
        states: s.spacecraft.dim(),
        status: out.status.label().to_string(),
        t_end: out.final_observation.t,
        nutation_crossings: crossings,
        final_nutation_deg: out.final_observation.nutation_angle.to_degrees(),
        final_angle_to_max_axis_deg: angle.to_degrees(),
        kinetic_energy: [t0, t1],
        energy_lost_fraction: if t0 > 0.0 { (t0 - t1) / t0 } else { 0.0 },
        steps: out.stats.steps,
        rhs_evaluations: out.stats.rhs_evaluations,
        wall_time: out.wall_time,
        energy_balance_drift: out.drift.energy_rel,
        nutation_series: rec.0,
    })
}

/// The side-by-side table as text.
pub fn table(rows: &[Row]) -> String {
    let mut out = String::new();
    let fmt_t = |t: Option<f64>| match t {
        Some(t) if t >= 600.0 => format!("{:.1} min", t / 60.0),
        Some(t) => format!("{t:.2} s"),
        None => "—".into(),
    };
    let width = rows.iter().map(|r| r.name.len()).max().unwrap_or(8).max(8);
    out.push_str(&format!(
        "{:<width$}  {:<22} {:>6}  {:>11} {:>11}  {:>9} {:>9}  {:>7}  {:>10} {:>11} {:>9}\n",
        "scenario",
        "model",
        "states",
        "θ > 45°",
        "θ > 80°",
        "θ end",
        "H∠max",
        "T lost",
        "steps",
        "RHS evals",
        "wall"
    ));
    for r in rows {
        out.push_str(&format!(
            "{:<width$}  {:<22} {:>6}  {:>11} {:>11}  {:>8.3}° {:>8.3}°  {:>6.2}%  {:>10} {:>11} {:>8.2}s\n",
            r.name,
            r.model,
            r.states,
            fmt_t(r.nutation_crossings[0]),
            fmt_t(r.nutation_crossings[1]),
            r.final_nutation_deg,
            r.final_angle_to_max_axis_deg,
            100.0 * r.energy_lost_fraction,
            r.steps,
            r.rhs_evaluations,
            r.wall_time
        ));
    }
    out
}

/// Nutation angle against time, one curve per scenario, as SVG.
pub fn chart(rows: &[Row], title: &str) -> String {
    let minutes = rows.iter().map(|r| r.t_end).fold(0.0, f64::max) > 1200.0;
    let (scale, unit) = if minutes {
        (1.0 / 60.0, "min")
    } else {
        (1.0, "s")
    };
    let mut c = Chart::new(title, format!("time ({unit})"), "nutation angle (deg)");
    for (i, r) in rows.iter().enumerate() {
        let style = if i % 2 == 0 {
            Style::Line
        } else {
            Style::Dashed
        };
        c.series.push(Series::new(
            format!("{} ({})", r.name, r.model),
            r.nutation_series
                .iter()
                .map(|&(t, a)| (t * scale, a))
                .collect(),
            style,
        ));
    }
    c.reference_lines
        .push(ReferenceLine::new(Axis::Y, 90.0, "flat spin"));
    c.to_svg(900, 480)
}

/// The nutation series as CSV: `scenario,t,nutation_deg`.
pub fn series_csv(rows: &[Row]) -> String {
    let mut out = String::from("scenario,t_s,nutation_deg\n");
    for r in rows {
        for (t, a) in &r.nutation_series {
            out.push_str(&format!("{},{t},{a}\n", r.name));
        }
    }
    out
}
