//! `polhode compare`: several fidelities of one scene side by side — the quantities that
//! matter (when each event first happens, the final spin axis, the energy lost) against the
//! cost (states, steps, right-hand-side evaluations, wall time).
//!
//! The event columns are the scenarios' own `events:` (their union, in first-seen order), or
//! the `--event` conditions when given; with neither, the nutation angle passing 45° and 80°.

use crate::integrate::OdeSystem;
use crate::model::Observation;
use crate::plot::{Axis, Chart, ReferenceLine, Series, Style};
use crate::scenario::{Condition, Quantity, Scenario};
use crate::sim::{self, Control, EventRecord, Outcome, Reference, Sink};
use std::sync::atomic::AtomicBool;

/// Nutation angles (degrees) whose first crossing is reported when neither the scenarios nor
/// `--event` name any event.
pub const MILESTONES_DEG: [f64; 2] = [45.0, 80.0];

/// Where the event columns come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EventSource {
    /// The `--event` options (they replace the scenarios' events).
    Option,
    /// The union of the scenarios' `events:` lists.
    Scenarios,
    /// None given: the nutation angle passing [`MILESTONES_DEG`].
    Default,
}

impl EventSource {
    /// The word used in the JSON (`option`, `scenarios`, `default`).
    pub fn label(&self) -> &'static str {
        match self {
            EventSource::Option => "option",
            EventSource::Scenarios => "scenarios",
            EventSource::Default => "default",
        }
    }
}

/// The event columns of a comparison.
#[derive(Debug, Clone, PartialEq)]
pub struct Columns {
    /// The conditions, one per column, distinct by [`Condition::describe`].
    pub conditions: Vec<Condition>,
    /// Short titles for the text table and the chart (`θ > 45°`, `θ < 1° for 60 s`).
    pub titles: Vec<String>,
    /// Where they come from.
    pub source: EventSource,
}

impl Columns {
    /// The columns: `option` (the `--event` conditions) when not empty, else the union of the
    /// scenarios' `events:` in first-seen order, else the nutation angle passing 45° and 80°.
    pub fn new(scenarios: &[Scenario], option: &[Condition]) -> Self {
        let mut conditions: Vec<Condition> = Vec::new();
        let add = |list: &mut Vec<Condition>, c: &Condition| {
            if !list.iter().any(|d| d.describe() == c.describe()) {
                list.push(*c);
            }
        };
        let source = if !option.is_empty() {
            option.iter().for_each(|c| add(&mut conditions, c));
            EventSource::Option
        } else {
            for c in scenarios.iter().flat_map(|s| &s.events) {
                add(&mut conditions, c);
            }
            if conditions.is_empty() {
                for deg in MILESTONES_DEG {
                    let c = Condition::crossing(Quantity::NutationAngleDeg, deg, true);
                    add(&mut conditions, &c);
                }
                EventSource::Default
            } else {
                EventSource::Scenarios
            }
        };
        let short: Vec<String> = conditions.iter().map(|c| short_title(c, false)).collect();
        let titles = conditions
            .iter()
            .enumerate()
            .map(|(i, c)| {
                // `once` does not change the first time; it is shown only to tell two
                // columns apart.
                if c.once && short.iter().filter(|t| **t == short[i]).count() > 1 {
                    short_title(c, true)
                } else {
                    short[i].clone()
                }
            })
            .collect();
        Columns {
            conditions,
            titles,
            source,
        }
    }

    /// The full texts ([`Condition::describe`]) of the columns.
    pub fn keys(&self) -> Vec<String> {
        self.conditions.iter().map(Condition::describe).collect()
    }

    /// A line saying where the columns come from when they are the fallback, else `None`.
    pub fn note(&self) -> Option<String> {
        (self.source == EventSource::Default).then(|| {
            "events: none in the scenarios and no --event; showing the nutation angle passing \
             45° and 80°"
                .to_string()
        })
    }
}

/// The short form of a condition: `θ > 45°`, `θ < 1° for 60 s`, `ω_z > 2`, `T < 5 J`.
pub fn short_title(c: &Condition, with_once: bool) -> String {
    let (symbol, unit) = match c.quantity {
        Quantity::NutationAngleDeg => ("θ".to_string(), "°"),
        Quantity::AngleToPrincipalDeg(i) => (format!("∠ω,e{}", i + 1), "°"),
        Quantity::Omega(i) => (format!("ω_{}", ["x", "y", "z"][i.min(2)]), ""),
        Quantity::KineticEnergy => ("T".to_string(), " J"),
        Quantity::RateDegS => ("|ω|".to_string(), "°/s"),
        Quantity::FieldAngleDeg => ("∠m,B".to_string(), "°"),
    };
    let op = if c.above { ">" } else { "<" };
    let mut text = format!("{symbol} {op} {}{unit}", c.threshold);
    if c.hold > 0.0 {
        text += &format!(" for {} s", c.hold);
    }
    if with_once && c.once {
        text += " once";
    }
    text
}

/// One event column of one scenario.
#[derive(Debug, Clone, serde::Serialize)]
pub struct EventCell {
    /// The condition in full ([`Condition::describe`]), as in `polhode run --summary`.
    pub condition: String,
    /// The column's short title.
    pub title: String,
    /// Whether this scenario's run watched the condition (false: not among its `events:`).
    pub watched: bool,
    /// The first time the condition held (s; with `for:`, the start of the interval), if it
    /// did.
    pub t: Option<f64>,
    /// Nutation angle at that time (degrees): exact for a condition without `for:`,
    /// interpolated between output samples otherwise.
    pub nutation_deg: Option<f64>,
}

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
    /// Where the event columns come from: `scenarios`, `option` (`--event`) or `default`
    /// (none given: the nutation angle passing 45° and 80°).
    pub event_source: &'static str,
    /// The event columns, in order.
    pub events: Vec<EventCell>,
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

/// Keeps (t, nutation angle) of every output sample, and the nutation angle at each event.
struct NutationRecorder {
    samples: Vec<(f64, f64)>,
    /// (condition, t, confirmed, nutation angle at `confirmed` in degrees).
    events: Vec<(String, f64, f64, f64)>,
}

impl Sink for NutationRecorder {
    fn sample(&mut self, o: &Observation, _y: &[f64], _r: &Reference) -> std::io::Result<()> {
        self.samples.push((o.t, o.nutation_angle.to_degrees()));
        Ok(())
    }
    fn event(&mut self, e: &EventRecord, o: &Observation) -> std::io::Result<()> {
        if !self.events.iter().any(|x| x.0 == e.condition) {
            self.events.push((
                e.condition.clone(),
                e.t,
                e.confirmed,
                o.nutation_angle.to_degrees(),
            ));
        }
        Ok(())
    }
}

/// Linear interpolation of a sampled series at `t` (clamped to its ends).
fn interpolate(series: &[(f64, f64)], t: f64) -> Option<f64> {
    let k = series.partition_point(|p| p.0 < t);
    match (k.checked_sub(1).map(|j| series[j]), series.get(k)) {
        (_, Some(&(t1, y1))) if t1 == t => Some(y1),
        (Some((t0, y0)), Some(&(t1, y1))) => Some(y0 + (y1 - y0) * (t - t0) / (t1 - t0)),
        (Some((_, y0)), None) => Some(y0),
        (None, Some(&(_, y1))) => Some(y1),
        (None, None) => None,
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

/// Runs one scenario (no log) and extracts its row. With columns from the scenarios, the run
/// is the scenario as given (so the times are those of `polhode run`), and a column it does
/// not watch is empty; with `--event` or the fallback, the columns' conditions replace its
/// `events:`.
pub fn run_one(mut s: Scenario, columns: &Columns, interrupt: &AtomicBool) -> std::io::Result<Row> {
    if columns.source != EventSource::Scenarios {
        s.events = columns.conditions.clone();
    }
    // A `stop:` condition is recorded as an event too (the one that ends the run).
    let watched: Vec<String> = s
        .events
        .iter()
        .chain(&s.stop)
        .map(Condition::describe)
        .collect();
    let mut rec = NutationRecorder {
        samples: Vec::new(),
        events: Vec::new(),
    };
    let out: Outcome = sim::run(
        &s,
        &mut rec,
        Control {
            interrupt,
            progress: None,
        },
    )?;
    let events = columns
        .conditions
        .iter()
        .zip(&columns.titles)
        .map(|(c, title)| {
            let key = c.describe();
            let watched = watched.contains(&key);
            let t = if watched {
                out.events.iter().find(|e| e.condition == key).map(|e| e.t)
            } else {
                None
            };
            let nutation_deg = t.and_then(|t| match rec.events.iter().find(|x| x.0 == key) {
                Some(&(_, te, confirmed, deg)) if te == t && confirmed == t => Some(deg),
                _ => interpolate(&rec.samples, t),
            });
            EventCell {
                condition: key,
                title: title.clone(),
                watched,
                t,
                nutation_deg,
            }
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
        event_source: columns.source.label(),
        events,
        final_nutation_deg: out.final_observation.nutation_angle.to_degrees(),
        final_angle_to_max_axis_deg: angle.to_degrees(),
        kinetic_energy: [t0, t1],
        energy_lost_fraction: if t0 > 0.0 { (t0 - t1) / t0 } else { 0.0 },
        steps: out.stats.steps,
        rhs_evaluations: out.stats.rhs_evaluations,
        wall_time: out.wall_time,
        energy_balance_drift: out.drift.energy_rel,
        nutation_series: rec.samples,
    })
}

/// The side-by-side table as text: a line saying where the event columns come from when
/// they are the fallback, the header, one line per row, and a note when a scenario does not
/// watch a column's event.
pub fn table(rows: &[Row], columns: &Columns) -> String {
    let mut out = String::new();
    let fmt_t = |t: Option<f64>| match t {
        Some(t) if t >= 600.0 => format!("{:.1} min", t / 60.0),
        Some(t) => format!("{t:.2} s"),
        None => "—".into(),
    };
    if let Some(note) = columns.note() {
        out.push_str(&note);
        out.push('\n');
    }
    let width = rows.iter().map(|r| r.name.len()).max().unwrap_or(8).max(8);
    let widths: Vec<usize> = columns
        .titles
        .iter()
        .map(|t| t.chars().count().max(11))
        .collect();
    let events_header: String = columns
        .titles
        .iter()
        .zip(&widths)
        .map(|(t, w)| format!(" {t:>w$}"))
        .collect();
    out.push_str(&format!(
        "{:<width$}  {:<22} {:>6} {events_header}  {:>9} {:>9}  {:>7}  {:>10} {:>11} {:>9}\n",
        "scenario", "model", "states", "θ end", "H∠max", "T lost", "steps", "RHS evals", "wall"
    ));
    for r in rows {
        let cells: String = r
            .events
            .iter()
            .zip(&widths)
            .map(|(e, w)| format!(" {:>w$}", fmt_t(e.t)))
            .collect();
        out.push_str(&format!(
            "{:<width$}  {:<22} {:>6} {cells}  {:>8.3}° {:>8.3}°  {:>6.2}%  {:>10} {:>11} {:>8.2}s\n",
            r.name,
            r.model,
            r.states,
            r.final_nutation_deg,
            r.final_angle_to_max_axis_deg,
            100.0 * r.energy_lost_fraction,
            r.steps,
            r.rhs_evaluations,
            r.wall_time
        ));
    }
    if rows.iter().flat_map(|r| &r.events).any(|e| !e.watched) {
        out.push_str(
            "— : not reached, or not among that scenario's events (--event watches the same \
             events in every scenario)\n",
        );
    }
    out
}

/// Nutation angle against time, one curve per scenario, with a marker where each event
/// column's event first happens (one marker series per column), as SVG.
pub fn chart(rows: &[Row], columns: &Columns, title: &str) -> String {
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
    for (k, t) in columns.titles.iter().enumerate() {
        let points: Vec<(f64, f64)> = rows
            .iter()
            .filter_map(|r| {
                let e = r.events.get(k)?;
                Some((e.t? * scale, e.nutation_deg?))
            })
            .collect();
        if !points.is_empty() {
            c.series
                .push(Series::new(t.clone(), points, Style::Markers));
        }
    }
    c.reference_lines
        .push(ReferenceLine::new(Axis::Y, 90.0, "flat spin"));
    c.to_svg(900, 480)
}

/// The nutation series as CSV, `scenario,t_s,nutation_deg,event`: one line per output
/// sample (`event` empty) and, in time order among them, one line where each event column's
/// event first happens (`event` its full condition text).
pub fn series_csv(rows: &[Row]) -> String {
    let mut out = String::from("scenario,t_s,nutation_deg,event\n");
    let field = |s: &str| {
        if s.contains([',', '"', '\n', '\r']) {
            format!("\"{}\"", s.replace('"', "\"\""))
        } else {
            s.to_string()
        }
    };
    for r in rows {
        let name = field(&r.name);
        let mut marks: Vec<(f64, f64, &str)> = r
            .events
            .iter()
            .filter_map(|e| Some((e.t?, e.nutation_deg?, e.condition.as_str())))
            .collect();
        marks.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut marks = marks.into_iter().peekable();
        for (t, a) in &r.nutation_series {
            while let Some((te, ae, c)) = marks.next_if(|m| m.0 < *t) {
                out.push_str(&format!("{name},{te},{ae},{}\n", field(c)));
            }
            out.push_str(&format!("{name},{t},{a},\n"));
        }
        for (te, ae, c) in marks {
            out.push_str(&format!("{name},{te},{ae},{}\n", field(c)));
        }
    }
    out
}
