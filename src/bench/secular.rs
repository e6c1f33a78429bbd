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

/// One point of the long-horizon work-precision chart.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PrecisionPoint {
    /// `dop853` or `averaged`.
    pub method: String,
    /// Its rtol.
    pub rtol: f64,
    /// Fastest timed run (s): events, no output sampling.
    pub seconds: f64,
    /// Largest relative error of T over the times asked, against the reference.
    pub energy_error: f64,
    /// Largest relative error of the events' first times, against the reference.
    pub event_error: f64,
}

/// Work-precision on a long-horizon dissipating scene: the largest relative error of the
/// kinetic energy at `times` (and of the event times) against dop853 at rtol 1e-12, against
/// the wall time of the run with its events, for dop853 and `averaged` each over a range of
/// rtol. Writes `long-horizon-<stem>.svg|png|csv` into `out`; returns the files.
pub fn long_horizon(
    path: &Path,
    times: &[f64],
    out: &Path,
    mut progress: impl FnMut(&str),
) -> Result<Vec<std::path::PathBuf>, String> {
    use crate::plot::{Chart, Scale, Series, Style};
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "scene".into());
    progress(&format!("{stem}: reference (dop853, rtol 1e-12)"));
    let reference = load(path, "dop853", Some(1e-12))?;
    let conditions: Vec<String> = reference.events.iter().map(|c| c.describe()).collect();
    let reference = side(reference, &conditions, times, 1)?;
    let mut points = Vec::new();
    let sweeps: [(&str, &[f64]); 2] = [
        ("dop853", &[1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10]),
        (
            "averaged",
            &[1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10],
        ),
    ];
    for (method, rtols) in sweeps {
        for &rtol in rtols {
            let s = load(path, method, Some(rtol))?;
            let r = side(s, &conditions, times, 3)?;
            let energy_error = r
                .kinetic_energy
                .iter()
                .zip(&reference.kinetic_energy)
                .map(|(a, f)| ((a - f) / f).abs())
                .fold(0.0, f64::max);
            let event_error = r
                .first_events
                .iter()
                .zip(&reference.first_events)
                .filter_map(|(a, f)| Some(((a.as_ref()? - f.as_ref()?) / f.as_ref()?).abs()))
                .fold(0.0, f64::max);
            progress(&format!(
                "{stem}: {method} rtol {rtol:e} → T {energy_error:.1e}, events \
                 {event_error:.1e} in {:.3e} s",
                r.seconds
            ));
            points.push(PrecisionPoint {
                method: method.into(),
                rtol,
                seconds: r.seconds,
                energy_error,
                event_error,
            });
        }
    }
    let mut chart = Chart::new(
        format!("Long horizon: {stem}"),
        "wall time of the run with its events (s), fastest of 3",
        "largest relative error of T at the compared times",
    );
    chart.x_scale = Scale::Log10;
    chart.y_scale = Scale::Log10;
    for method in ["dop853", "averaged"] {
        let pts: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| p.method == method)
            .map(|p| (p.seconds, p.energy_error.max(1e-16)))
            .collect();
        chart
            .series
            .push(Series::new(method, pts, Style::LineMarkers));
    }
    let base = out.join(format!("long-horizon-{stem}"));
    let mut files = crate::plot::svg_and_png(&chart, &base)?;
    let mut csv = String::from("method,rtol,seconds,energy_error,event_error\n");
    for p in &points {
        csv.push_str(&format!(
            "{},{:e},{:e},{:e},{:e}\n",
            p.method, p.rtol, p.seconds, p.energy_error, p.event_error
        ));
    }
    let path = base.with_extension("csv");
    crate::outputs::write_atomically(&path, csv.as_bytes())
        .map_err(|e| format!("{}: {e}", path.display()))?;
    files.push(path);
    Ok(files)
}
