//! `polhode bench averaged`: the averaged method against the full integration of the same
//! scene (dop853, rtol 1e-10, atol 1e-12), in one process (docs/averaging.md).
//!
//! Two passes per method:
//! - timed: the run with its events and no output sampling (samples only at the ends), the
//!   minimum wall time over the repeats; this is the time to the answer the events give;
//! - accuracy: once, with the scene's output rate, for the kinetic energy and |H| at the times
//!   asked (each on the output grid).

use crate::model::Observation;
use crate::scenario::{self, Overrides, Scenario};
use crate::sim::{self, Control, EventRecord, Memory, Outcome};
use std::path::Path;
use std::time::Instant;

/// The reference's tolerances: dop853 at rtol 1e-10, atol 1e-12.
pub const REFERENCE_RTOL: f64 = 1e-10;

/// One method's side of the comparison.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Side {
    /// Method and settings.
    pub method: String,
    /// Fastest timed run (s).
    pub seconds: f64,
    /// Every timed run (s).
    pub seconds_all: Vec<f64>,
    /// Accepted steps of the timed run.
    pub steps: u64,
    /// Right-hand-side evaluations of the timed run.
    pub rhs_evaluations: u64,
    /// The first time (s) each event condition fired, in the scene's order (`None`: never).
    pub first_events: Vec<Option<f64>>,
    /// Kinetic energy (J) at each time asked.
    pub kinetic_energy: Vec<f64>,
    /// |H| (N m s) at each time asked.
    pub h_norm: Vec<f64>,
}

/// The comparison on one scene.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Comparison {
    /// Scenario file.
    pub scenario: String,
    /// The event conditions, in order.
    pub conditions: Vec<String>,
    /// The times (s) of the energy and momentum comparison.
    pub times: Vec<f64>,
    /// dop853 at [`REFERENCE_RTOL`].
    pub full: Side,
    /// `averaged` with the scene's (or the given) rtol.
    pub averaged: Side,
    /// Full time over averaged time.
    pub speedup: f64,
    /// |averaged − full| / full for each event's first time (`None` if either is missing).
    pub event_error: Vec<Option<f64>>,
    /// |averaged − full| / full for the kinetic energy at each time.
    pub energy_error: Vec<f64>,
}

fn load(path: &Path, method: &str, rtol: Option<f64>) -> Result<Scenario, String> {
    let ov = Overrides {
        method: Some(method.into()),
        rtol,
        atol: rtol.map(|r| 1e-2 * r),
        ..Overrides::default()
    };
    scenario::load(path, &ov).map_err(|e| e.to_string())
}

fn first_events(conditions: &[String], events: &[EventRecord]) -> Vec<Option<f64>> {
    conditions
        .iter()
        .map(|c| events.iter().find(|e| &e.condition == c).map(|e| e.t))
        .collect()
}

fn run(s: &Scenario, sink: &mut Memory) -> Result<Outcome, String> {
    let outcome = sim::run(s, sink, Control::uninterrupted()).map_err(|e| e.to_string())?;
    if outcome.status.is_partial() {
        return Err(format!(
            "{}: the run with {} ended early: {}",
            s.path.display(),
            s.method.describe(),
            outcome.status.diagnosis().unwrap_or("interrupted")
        ));
    }
    Ok(outcome)
}

fn side(
    mut s: Scenario,
    conditions: &[String],
    times: &[f64],
    repeats: usize,
) -> Result<Side, String> {
    let mut memory = Memory::new();
    run(&s, &mut memory)?;
    let at = |t: f64| -> Result<&Observation, String> {
        memory
            .samples
            .iter()
            .find(|o| (o.t - t).abs() <= 1e-9 * t.max(1.0))
            .ok_or_else(|| format!("{t} s is not on the scene's output grid"))
    };
    let mut kinetic_energy = Vec::new();
    let mut h_norm = Vec::new();
    for &t in times {
        let o = at(t)?;
        kinetic_energy.push(o.kinetic_energy);
        h_norm.push(o.h_norm);
    }
    // Timed: no sampling between the ends.
    s.simulation.output_rate = 1.0 / s.duration;
    let mut best: Option<(f64, Outcome)> = None;
    let mut all = Vec::new();
    for _ in 0..repeats.max(1) {
        let mut sink = Memory::new();
        let start = Instant::now();
        let o = run(&s, &mut sink)?;
        let seconds = start.elapsed().as_secs_f64();
        all.push(seconds);
        if best.as_ref().is_none_or(|(b, _)| seconds < *b) {
            best = Some((seconds, o));
        }
    }
    let (seconds, outcome) = best.expect("at least one repeat");
    Ok(Side {
        method: s.method.describe(),
        seconds,
        seconds_all: all,
        steps: outcome.stats.steps,
        rhs_evaluations: outcome.stats.rhs_evaluations,
        first_events: first_events(conditions, &outcome.events),
        kinetic_energy,
        h_norm,
    })
}

/// Compares `averaged` (at `rtol`, or the scene's) with dop853 at [`REFERENCE_RTOL`] on the
/// scene at `path`, the energies at `times` (s), timing each `repeats` times.
pub fn compare(
    path: &Path,
    rtol: Option<f64>,
    times: &[f64],
    repeats: usize,
) -> Result<Comparison, String> {
    let full = load(path, "dop853", Some(REFERENCE_RTOL))?;
    let averaged = load(path, "averaged", rtol)?;
    let conditions: Vec<String> = full.events.iter().map(|c| c.describe()).collect();
    let scenario = full.path.display().to_string();
    let full = side(full, &conditions, times, repeats)?;
    let averaged = side(averaged, &conditions, times, repeats)?;
    let event_error = full
        .first_events
        .iter()
        .zip(&averaged.first_events)
        .map(|(f, a)| match (f, a) {
            (Some(f), Some(a)) => Some(((a - f) / f).abs()),
            _ => None,
        })
        .collect();
    let energy_error = full
        .kinetic_energy
        .iter()
        .zip(&averaged.kinetic_energy)
        .map(|(f, a)| ((a - f) / f).abs())
        .collect();
    Ok(Comparison {
        scenario,
        conditions,
        times: times.to_vec(),
        speedup: full.seconds / averaged.seconds,
        full,
        averaged,
        event_error,
        energy_error,
    })
}
