//! The run loop: integrate, sample the output grid, locate events, track invariant drift.
//!
//! Output samples fall at `k / rate` seconds of sim time (plus the final instant) and are read
//! from the method's dense output, so the output rate never constrains the step. Events are
//! sign changes of `Condition::margin`, bracketed at step ends (and at interior points) and
//! located by the Illinois variant of regula falsi on the dense output.

mod checks;
mod condition;
mod events;
mod lanes;
mod memory;
mod method;
mod monitor;
mod relay;
mod simulation;
mod steppers;
mod support;

pub use checks::{DriftLimits, OnBreach};
pub use condition::{Condition, Quantity};
pub use lanes::{LaneForm, lane_form, run_in_lanes};
pub use memory::Memory;
pub use method::{Adaptive, Method};
pub use relay::{Record, Relay, Relayed, receive_run};
pub use simulation::Simulation;
pub use steppers::{AnyStepper, ExactStepper, LieStepper, SplittingStepper};
pub use support::{
    Feature, Features, Linearisation, Refusal, Support, linearize_refusal, linearize_support,
    support,
};

use crate::integrate::{OdeSystem, Stats, Stepper, same_instant};
use crate::model::{Invariants, Observation, Spacecraft};
use crate::timefmt::seconds;
use monitor::Monitor;
use nalgebra::Vector3;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// A recorded event: a condition became true (and, with `for:`, held long enough).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct EventRecord {
    /// Sim time at which the condition became true (s): with `for:`, the start of the
    /// interval that held.
    pub t: f64,
    /// Sim time at which the event was known (s): `t` plus the `for:` duration.
    #[serde(skip)]
    pub confirmed: f64,
    /// The condition, e.g. `nutation_angle_deg above 89`.
    pub condition: String,
    /// Whether it ended the run.
    pub terminal: bool,
}

/// How a run ended. The serialized `kind` and [`Status::label`] are the one word every
/// output uses (summary JSON, text, campaign tables, MCAP metadata).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Status {
    /// Reached the scenario's duration.
    Complete,
    /// A stop condition became true.
    Stopped {
        /// The condition.
        condition: String,
    },
    /// Interrupted by the user (Ctrl-C); what was computed is kept, marked partial.
    Interrupted,
    /// The integration could not continue; what was computed is kept, marked partial.
    Failed {
        /// Diagnosis: what happened, where, and what to try.
        diagnosis: String,
    },
    /// An effector left the range its model holds in (`checks.on_validity: stop`); what was
    /// computed up to there is kept, marked partial.
    InvalidModel {
        /// Diagnosis: which effector, how far out, and what to do.
        diagnosis: String,
    },
}

impl Status {
    /// The one-word status.
    pub fn label(&self) -> &'static str {
        match self {
            Status::Complete => "complete",
            Status::Stopped { .. } => "stopped",
            Status::Interrupted => "interrupted",
            Status::Failed { .. } => "failed",
            Status::InvalidModel { .. } => "invalid_model",
        }
    }

    /// Whether the run ended before its duration or a stop condition (the log is partial).
    pub fn is_partial(&self) -> bool {
        matches!(
            self,
            Status::Interrupted | Status::Failed { .. } | Status::InvalidModel { .. }
        )
    }

    /// The diagnosis of a failed or invalid-model run.
    pub fn diagnosis(&self) -> Option<&str> {
        match self {
            Status::Failed { diagnosis } | Status::InvalidModel { diagnosis } => Some(diagnosis),
            _ => None,
        }
    }
}

/// Largest deviations of the invariants over all accepted steps.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct Drift {
    /// max |(|H| − |H₀|)| / |H₀|; with a thruster, H is H_N plus the angular momentum the
    /// exhaust carried out.
    pub h_norm_rel: f64,
    /// max |H_N − H_N₀| / |H₀| (the inertial momentum vector; with a thruster, plus what the
    /// exhaust carried out).
    pub h_inertial_rel: f64,
    /// max |E − E₀| / E₀ for the energy balance E = kinetic + elastic + dissipated (just T
    /// for a rigid body).
    pub energy_rel: f64,
    /// max ||q| − 1|.
    pub q_norm: f64,
}

/// Initial values the drift is measured against.
#[derive(Debug, Clone, Copy)]
pub struct Reference {
    h0: f64,
    h_inertial0: Vector3<f64>,
    e0: f64,
}

impl Reference {
    /// The invariants of the initial observation.
    pub fn of(o: &Observation) -> Self {
        Reference {
            h0: o.h_norm,
            h_inertial0: o.h_inertial,
            e0: o.energy_balance(),
        }
    }

    /// Signed relative change of |H| at `o` (with a thruster, of |H plus what the exhaust
    /// carried out|, the conserved quantity).
    pub fn h_rel(&self, o: &Observation) -> f64 {
        let h = if o.h_carried_out == Vector3::zeros() {
            o.h_norm
        } else {
            (o.h_inertial + o.h_carried_out).norm()
        };
        rel(h - self.h0, self.h0)
    }

    /// Signed relative change of the energy balance (kinetic + elastic + dissipated) at `o`.
    pub fn energy_rel(&self, o: &Observation) -> f64 {
        rel(o.energy_balance() - self.e0, self.e0)
    }

    /// The drift at one state with invariants `i`: each field of [`Drift`] at that state
    /// alone (the lanes compute the same terms, with the same operations:
    /// `lanes::ensemble::LaneDrift`).
    pub fn terms(&self, i: &Invariants) -> Drift {
        // With a thruster, H plus what the exhaust carried out is the conserved quantity (the
        // carried part is zero otherwise).
        let h_audited = i.h_inertial + i.h_carried_out;
        Drift {
            h_norm_rel: rel(h_audited.norm() - self.h0, self.h0).abs(),
            h_inertial_rel: rel(
                (i.h_inertial + i.h_carried_out - self.h_inertial0).norm(),
                self.h0,
            ),
            energy_rel: rel(i.energy_balance() - self.e0, self.e0).abs(),
            q_norm: i.q_norm_error.abs(),
        }
    }
}

impl Drift {
    /// Takes in one state's terms ([`Reference::terms`]): each field keeps its largest.
    fn absorb(&mut self, terms: &Drift) {
        self.h_norm_rel = self.h_norm_rel.max(terms.h_norm_rel);
        self.energy_rel = self.energy_rel.max(terms.energy_rel);
        self.h_inertial_rel = self.h_inertial_rel.max(terms.h_inertial_rel);
        self.q_norm = self.q_norm.max(terms.q_norm);
    }
}

fn rel(d: f64, reference: f64) -> f64 {
    if reference != 0.0 { d / reference } else { d }
}

/// Receives what a run produces, in time order.
pub trait Sink {
    /// One output sample: the observation and the full state vector.
    fn sample(&mut self, o: &Observation, y: &[f64], inv: &Reference) -> std::io::Result<()>;
    /// An event, at its located time.
    fn event(&mut self, e: &EventRecord, o: &Observation) -> std::io::Result<()>;
    /// A warning (the run goes on).
    fn warning(&mut self, _w: &Warning) -> std::io::Result<()> {
        Ok(())
    }
    /// Whether this sink reads the samples' angles between ω and the principal axes
    /// ([`Observation::angles_to_principal`], three arctangents a sample); a sink that says
    /// false gets them as NaN, unless an event condition needs them anyway.
    fn reads_principal_angles(&self) -> bool {
        true
    }
    /// A sample of which this sink may read only the nutation angle (rad) at `t` (s), offered
    /// where the integrator has the angle without forming the observation (a campaign's
    /// lanes). `None`: this sink reads more, and [`Sink::sample`] is called instead.
    fn nutation_sample(&mut self, _t: f64, _nutation_angle: f64) -> Option<std::io::Result<()>> {
        None
    }
    /// Whether [`Sink::nutation_sample`] takes every sample it is offered, so that the
    /// integrator need compute nothing but the nutation angle where it offers one.
    fn reads_only_nutation(&self) -> bool {
        false
    }
}

/// A sink that discards everything (runs without logging).
pub struct NullSink;

impl Sink for NullSink {
    fn sample(&mut self, _: &Observation, _: &[f64], _: &Reference) -> std::io::Result<()> {
        Ok(())
    }
    fn event(&mut self, _: &EventRecord, _: &Observation) -> std::io::Result<()> {
        Ok(())
    }
}

/// Run controls from the caller.
pub struct Control<'a> {
    /// Set asynchronously (e.g. by a Ctrl-C handler) to stop after the current step.
    pub interrupt: &'a AtomicBool,
    /// Called now and then with the sim time reached (s), for progress displays.
    pub progress: Option<&'a mut dyn FnMut(f64)>,
}

/// The flag behind [`Control::uninterrupted`]: never set.
static NEVER: AtomicBool = AtomicBool::new(false);

impl Control<'_> {
    /// No interrupt and no progress display: the run goes to its end.
    pub fn uninterrupted() -> Control<'static> {
        Control {
            interrupt: &NEVER,
            progress: None,
        }
    }
}

/// Something the run noticed and went on from (e.g. drift beyond a `checks:` bound with
/// `on_drift: warn`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Warning {
    /// Sim time (s).
    pub t: f64,
    /// What, the state, and what to do.
    pub message: String,
}

/// What a run did.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Outcome {
    /// How it ended.
    pub status: Status,
    /// Observation at the last instant reached.
    #[serde(skip)]
    pub final_observation: Observation,
    /// Initial observation.
    #[serde(skip)]
    pub initial_observation: Observation,
    /// State vector at the last instant reached.
    pub final_state: Vec<f64>,
    /// Work counters.
    pub stats: Stats,
    /// Invariant drift over the run.
    pub drift: Drift,
    /// Events in time order (the first [`MAX_EVENTS_KEPT`]; all are logged).
    pub events: Vec<EventRecord>,
    /// Events beyond [`MAX_EVENTS_KEPT`], logged but not kept in memory.
    pub events_not_kept: u64,
    /// Warnings, in time order.
    pub warnings: Vec<Warning>,
    /// Output samples emitted.
    pub samples: u64,
    /// Wall-clock time of the integration loop, including the sink (s).
    pub wall_time: f64,
}

/// Runs `sim` with its configured method, feeding `sink`.
pub fn run(sim: &Simulation, sink: &mut dyn Sink, ctl: Control) -> std::io::Result<Outcome> {
    let sc = &sim.spacecraft;
    let y0 = sc.initial_state(&sim.omega0, &sim.attitude0);
    match AnyStepper::for_simulation(sim, &y0, true) {
        Ok(stepper) => drive(stepper, sim, sink, ctl, interior_checks(&sim.method)),
        Err(diagnosis) => {
            let o = sc.observe(0.0, &y0);
            Ok(Outcome {
                status: Status::Failed { diagnosis },
                final_observation: o.clone(),
                initial_observation: o,
                final_state: y0,
                stats: Stats::default(),
                drift: Drift::default(),
                events: vec![],
                events_not_kept: 0,
                warnings: vec![],
                samples: 0,
                wall_time: 0.0,
            })
        }
    }
}

/// Interior event checks in a step of `method` (where steps can be long: adaptive, implicit,
/// splitting).
fn interior_checks(method: &Method) -> usize {
    match method {
        Method::Rk4 { .. } | Method::Lie { .. } => 0,
        _ => 3,
    }
}

/// What [`integrate_only`] measured.
#[derive(Debug, Clone)]
pub struct Solve {
    /// State at the end.
    pub final_state: Vec<f64>,
    /// Work counters.
    pub stats: Stats,
    /// CPU (wall-clock, single thread) time of the integration alone (s).
    pub seconds: f64,
}

/// Integrates `sim` from 0 to `t_end` (s) with its method and nothing else: no output
/// samples, events, invariant tracking or logging (`exact` evaluates the end directly). The
/// cost of the method alone, for benchmarks (`polhode bench`). `Err` is a diagnosis.
pub fn integrate_only(sim: &Simulation, t_end: f64) -> Result<Solve, String> {
    let sc = &sim.spacecraft;
    let y0 = sc.initial_state(&sim.omega0, &sim.attitude0);
    let started = Instant::now();
    let mut stepper = AnyStepper::for_simulation(sim, &y0, false)?;
    if let AnyStepper::Exact(exact) = &stepper {
        // The closed form jumps to the end in one evaluation.
        let final_state = exact.state_at(t_end);
        let seconds = started.elapsed().as_secs_f64();
        return Ok(Solve {
            final_state,
            stats: Stats {
                steps: 1,
                ..Stats::default()
            },
            seconds,
        });
    }
    while stepper.t() < t_end {
        let t0 = stepper.t();
        let stop = next_stop(sc, t0, t_end);
        stepper
            .step(sc, stop)
            .map_err(|e| diagnose(&e.to_string(), t0, stepper.y(), sim))?;
        if stepper.t() == stop && stop < t_end {
            let mut y = stepper.y().to_vec();
            sc.at_breakpoint(stop, &mut y);
            stepper.restart(sc, &y);
        }
        if !stepper.y().iter().all(|v| v.is_finite()) {
            let what = format!(
                "the state became non-finite in the step from t = {} to t = {}",
                seconds(stepper.t_prev()),
                seconds(stepper.t())
            );
            // Without dense output only the step's ends can be read: report the start.
            let mut buf = vec![0.0; y0.len()];
            stepper.interpolate(stepper.t_prev(), &mut buf);
            return Err(diagnose(&what, stepper.t_prev(), &buf, sim));
        }
    }
    let seconds = started.elapsed().as_secs_f64();
    Ok(Solve {
        final_state: stepper.y().to_vec(),
        stats: stepper.stats(),
        seconds,
    })
}

/// A run whose energy balance moves by more than this fraction of its initial value stops as
/// diverging (scenes without a prescribed motion conserve it; only numerical instability or a
/// grossly loose tolerance changes it this much). Caught this early, the state is still
/// finite and the diagnosis can measure the stiffness there.
pub const DIVERGENCE_ENERGY_REL: f64 = 0.5;

/// Events kept in [`Outcome::events`]; later ones are logged but only counted, so that an
/// event that fires every period of a very long run cannot use unbounded memory.
pub const MAX_EVENTS_KEPT: usize = 10_000;

/// A run whose average step, over two consecutive windows of `COLLAPSE_WINDOW` steps, is
/// so small that its whole duration would take more than this many steps stops as failed
/// (the bound the scenario checks put on the work a file may ask for): a singularity of the
/// model, or stiffness an explicit method crawls through.
pub const MAX_STEPS_TO_GO: f64 = 1e11;

/// Steps over which the average step size is measured for [`MAX_STEPS_TO_GO`].
const COLLAPSE_WINDOW: u64 = 10_000;

/// Where the next step must end at the latest: the run's end, or the first breakpoint of an
/// effector after `t` (a commanded torque's step), where the right-hand side jumps and the
/// integrator stops exactly and restarts ([`Stepper::restart`]).
///
/// Breakpoints a few ulps apart (a tick k·Δt and a step time m/f that are the same instant in
/// exact arithmetic) are one stop, at the latest of them, where every effector takes its new
/// value; a breakpoint within a few ulps of the end is the end
/// ([`crate::integrate::same_instant`]). Otherwise the step between them would be below the
/// resolution of t and an adaptive method would fail with a step-size underflow.
fn next_stop(sc: &crate::model::Spacecraft, t: f64, t_end: f64) -> f64 {
    next_stop_of(|t| sc.next_breakpoint(t), t, t_end)
}

/// [`next_stop`] for breakpoints given by `next_breakpoint(t)`, the first after `t` (s): the
/// scalar loop's with a scene's, the lanes' with a run's ([`crate::lanes::ensemble::LaneRun`]).
pub(crate) fn next_stop_of(
    next_breakpoint: impl Fn(f64) -> Option<f64>,
    t: f64,
    t_end: f64,
) -> f64 {
    let Some(mut b) = next_breakpoint(t) else {
        return t_end;
    };
    while let Some(next) = next_breakpoint(b)
        && crate::integrate::same_instant(b, next)
    {
        b = next;
    }
    if b >= t_end || crate::integrate::same_instant(b, t_end) {
        t_end
    } else {
        b
    }
}

/// How often (in steps) the interrupt flag and the wall clock are looked at.
const POLL_STEPS: u64 = 64;

fn drive<M: Stepper>(
    mut stepper: M,
    sim: &Simulation,
    sink: &mut dyn Sink,
    mut ctl: Control,
    interior_checks: usize,
) -> std::io::Result<Outcome> {
    let sc = &sim.spacecraft;
    let t_end = sim.duration;
    let mut kinks = KinkForecast::for_run(sim, stepper.t(), stepper.y());
    let (mut monitor, mut status) = Monitor::start(sim, stepper.y(), sink, interior_checks)?;
    let mut scratch = vec![0.0; sc.dim()];
    let mut last_poll = Instant::now();
    // Set when the last step ended on an effector's breakpoint.
    let mut at_breakpoint = false;
    while status.is_none() && stepper.t() < t_end {
        if stepper.stats().steps.is_multiple_of(POLL_STEPS) {
            if ctl.interrupt.load(Ordering::Relaxed) {
                status = Some(Status::Interrupted);
                break;
            }
            if let Some(p) = ctl.progress.as_mut()
                && last_poll.elapsed() > Duration::from_millis(100)
            {
                p(stepper.t());
                last_poll = Instant::now();
            }
        }
        let t0 = stepper.t();
        if at_breakpoint {
            // Held states take their new values; the next step starts afresh on the far side.
            scratch.copy_from_slice(stepper.y());
            sc.at_breakpoint(t0, &mut scratch);
            stepper.restart(sc, &scratch);
            monitor.restarted();
        }
        let stop = next_stop(sc, t0, t_end);
        let stop = kinks.as_ref().map_or(stop, |k| k.stop(t0, stop));
        if let Err(e) = stepper.step(sc, stop) {
            status = Some(Status::Failed {
                diagnosis: diagnose(&e.to_string(), t0, stepper.y(), sim),
            });
            break;
        }
        if let Some(k) = kinks.as_mut() {
            k.after_step(sc, t0, stepper.t(), stepper.y());
        }
        // A breakpoint reached: restart before the next step (this step's samples and events
        // are read from its dense output first, on the breakpoint's near side).
        at_breakpoint = stepper.t() == stop && stop < t_end;
        status = monitor.after_step(&mut stepper, sink)?;
    }
    let outcome = monitor.finish(&stepper, status, sink)?;
    if let Some(p) = ctl.progress.as_mut() {
        p(outcome.final_observation.t);
    }
    Ok(outcome)
}

/// Where the effectors' right-hand sides will kink next ([`Effector::switching`] crossing
/// zero), extrapolated from each step's two ends by the secant through them, so that an
/// adaptive method ends a step there instead of straddling the kink (a step across a kink
/// fails its error test until it is short). A forecast is only a stop: the right-hand side
/// stays the effectors' own, so a kink forecast a little early or late, or not at all, is met
/// by the error control as before.
///
/// [`Effector::switching`]: crate::model::Effector::switching
struct KinkForecast {
    /// Each effector's switching function at the start of the coming step.
    last: Vec<f64>,
    /// The same at the end of the step just taken.
    now: Vec<f64>,
    /// The first kink forecast after the last step (s), if any.
    next: Option<f64>,
}

impl KinkForecast {
    /// For a run of `sim` at `(t, y)` if its scene has switching functions and its method is
    /// adaptive (a fixed-step method keeps its grid).
    fn for_run(sim: &Simulation, t: f64, y: &[f64]) -> Option<Self> {
        let sc = &sim.spacecraft;
        if !sc.has_switching() || !matches!(sim.method, Method::Dopri5(_) | Method::Dop853(_)) {
            return None;
        }
        let mut last = vec![0.0; sc.effectors().len()];
        sc.switching_values(t, y, &mut last);
        Some(KinkForecast {
            now: last.clone(),
            last,
            next: None,
        })
    }

    /// Where a step from `t0` (s) that would end at `stop` ends: at the forecast kink if it
    /// falls strictly between (and is not the same instant as either).
    fn stop(&self, t0: f64, stop: f64) -> f64 {
        match self.next {
            Some(t) if t > t0 && t < stop && !same_instant(t0, t) && !same_instant(t, stop) => t,
            _ => stop,
        }
    }

    /// After the step from `t0` to `t1` (s), ending at `y`: the next forecast.
    fn after_step(&mut self, sc: &crate::model::Spacecraft, t0: f64, t1: f64, y: &[f64]) {
        sc.switching_values(t1, y, &mut self.now);
        self.next = None;
        for (&g0, &g1) in self.last.iter().zip(&self.now) {
            // Moving towards zero without reaching it: where the secant crosses it.
            if g0 * g1 > 0.0 && g1.abs() < g0.abs() {
                let t = t1 + g1 * (t1 - t0) / (g0 - g1);
                if t.is_finite() {
                    self.next = Some(self.next.map_or(t, |n: f64| n.min(t)));
                }
            }
        }
        std::mem::swap(&mut self.last, &mut self.now);
    }
}

/// The diagnosis when a step's deferred dense output comes out non-finite.
fn dense_failure(t0: f64, t1: f64, y: &[f64], sim: &Simulation) -> Status {
    let what = format!(
        "the dense output of the step from t = {} to t = {} came out non-finite",
        seconds(t0),
        seconds(t1)
    );
    Status::Failed {
        diagnosis: diagnose(&what, t1, y, sim),
    }
}

/// Where an explicit method's stability region meets the negative real axis, in units of
/// h·|λ| (classical RK4: 2.785, Hairer, Nørsett & Wanner, *Solving ODEs I*, §IV.2; Strang's
/// RK4 sub-steps take h/2, hence twice that).
fn stability_bound(m: &Method) -> Option<f64> {
    const RK4: f64 = 2.785;
    match m {
        Method::Rk4 { .. } | Method::Lie { .. } => Some(RK4),
        Method::Splitting { order: 2, .. } => Some(2.0 * RK4),
        // The triple jump's backward middle sub-step amplifies decaying modes: measured 2.85
        // on the stability map (docs/choosing-a-method.md), not RK4's bound scaled by γ₁.
        Method::Splitting { .. } => Some(2.85),
        Method::Dopri5(_) => Some(3.3),
        Method::Dop853(_) => Some(6.0),
        _ => None,
    }
}

/// A diagnosis for a failed integration: what, when, the state, the suspected cause and what
/// to try.
pub fn diagnose(what: &str, t: f64, y: &[f64], sim: &Simulation) -> String {
    let state = hub_state_text(y);
    // `t` and `y` are the last finite state known: how stiff are the equations there?
    let sc = &sim.spacecraft;
    let stiffness = y
        .iter()
        .all(|v| v.is_finite())
        .then(|| crate::linearize::stiffness(sc, t, y, sim.duration));
    let rho = stiffness.map_or(f64::NAN, |s| s.spectral_radius);
    let m = &sim.method;
    let (cause, remedy) = if let Some(found) = model_outside_range(sc, t, y) {
        found
    } else if let Some(found) = unstable_sampled_loop(sc) {
        found
    } else {
        match (m.fixed_step(), stability_bound(m)) {
            (Some(h), Some(bound)) if rho.is_finite() && h * rho > 0.8 * bound => (
                format!(
                    "numerical instability: the fastest eigenvalue of the equations has \
                 |λ| = {rho:.4e} 1/s, so h·|λ| = {:.3} is beyond {}'s stability bound ≈ \
                 {bound:.2} (largest stable step ≈ {:.3e} s)",
                    h * rho,
                    m.name(),
                    bound / rho
                ),
                format!(
                    "reduce dt below {:.3e} s, or use an implicit method: radau5 (adaptive) or \
                 gauss (fixed step, A-stable)",
                    0.8 * bound / rho
                ),
            ),
            (Some(h), _) => (
                format!(
                    "the fixed step dt = {h:e} s is too coarse for this scene (fastest |λ| = \
                 {rho:.4e} 1/s)"
                ),
                "reduce dt, or use an adaptive method (dop853, or radau5 when stiff)".into(),
            ),
            (None, _) if matches!(m, Method::Exact) => (
                "the closed-form solution failed".into(),
                "report this as a bug with the scenario attached".into(),
            ),
            (None, _) if matches!(m, Method::Averaged(_)) => (
                "the averaged method's assumptions failed here (the message above says which)"
                    .into(),
                "run this scene, or its remaining part, with dop853".into(),
            ),
            (None, _) if !m.is_implicit() && stiffness.is_some_and(|s| s.ratio() > 1e3) => (
                format!(
                    "stiffness: the fastest eigenvalue |λ| = {rho:.4e} 1/s is {:.1e} times the \
                 motion's rate, so an explicit method crawls at its stability limit",
                    stiffness.map_or(f64::NAN, |s| s.ratio())
                ),
                "use radau5 (or auto, which picks it for stiff scenes)".into(),
            ),
            (None, _) => (
                "a singularity of the model, or a tolerance that cannot be met".into(),
                "check the model parameters (e.g. a vanishing inertia or mass); loosen rtol/atol"
                    .into(),
            ),
        }
    };
    crate::timefmt::tidy(&format!(
        "{what}; state at t = {} [ω (rad/s), q (w,x,y,z)] = [{state}]; suspected cause: \
         {cause}; suggested remedy: {remedy}",
        seconds(t)
    ))
}

/// A discrete rate loop that overcorrects: with the hub torque −G ω sampled every Δt and
/// held, the rate about an axis of moment I goes as ω_{k+1} = (1 − g Δt / I) ω_k, which
/// diverges when g Δt / I > 2 (g the loop's gain about that axis). Checked with the largest
/// gain against the smallest principal moment, the worst case. The cause and the remedy.
fn unstable_sampled_loop(sc: &Spacecraft) -> Option<(String, String)> {
    let mut gain = nalgebra::Matrix3::zeros();
    let mut period: f64 = 0.0;
    for e in sc.effectors() {
        if let Some((g, dt)) = e.sampled_rate_loop() {
            gain += g;
            period = period.max(dt);
        }
    }
    if period <= 0.0 {
        return None;
    }
    let sym = (gain + gain.transpose()) * 0.5;
    let k = sym.symmetric_eigenvalues().amax();
    let inertia = sc.hub.principal_moments.min();
    let ratio = k * period / inertia;
    if ratio.is_nan() || ratio <= 2.0 {
        return None;
    }
    let n = crate::timefmt::number;
    Some((
        format!(
            "the discrete rate-damping loop is unstable: gain {} N m s sampled every {} s \
             against a moment of inertia of {} kg m² gives gain × interval / inertia = {} > 2, \
             so each tick overcorrects the rate and the oscillation grows",
            crate::timefmt::approx(k),
            n(period),
            n(inertia),
            crate::timefmt::approx(ratio)
        ),
        format!(
            "lower the gain below {} N m s, or raise sample_rate above {} Hz",
            crate::timefmt::approx(2.0 * inertia / period),
            crate::timefmt::approx(k / (2.0 * inertia))
        ),
    ))
}

fn keep_event(events: &mut Vec<EventRecord>, not_kept: &mut u64, e: EventRecord) {
    if events.len() < MAX_EVENTS_KEPT {
        events.push(e);
    } else {
        *not_kept += 1;
    }
}

/// The first invariant (index, description) beyond its bound and not yet warned about.
#[inline(always)]
fn drift_excess(
    limits: &DriftLimits,
    drift: &Drift,
    warned: &[bool; 3],
    t: f64,
) -> Option<(usize, String)> {
    let values = [
        drift.h_norm_rel.max(drift.h_inertial_rel),
        drift.energy_rel,
        drift.q_norm,
    ];
    let bounds = [limits.momentum, limits.energy, limits.quaternion_norm];
    let (i, bound) = (0..3).find_map(|i| match bounds[i] {
        Some(b) if !warned[i] && values[i] > b => Some((i, b)),
        _ => None,
    })?;
    Some((i, excess_description(i, values[i], bound, t)))
}

/// What [`drift_excess`] says of invariant `i` (0: angular momentum, 1: energy balance,
/// 2: quaternion norm) at `value`, beyond its bound `b`, at `t` (s).
#[cold]
#[inline(never)]
fn excess_description(i: usize, value: f64, b: f64, t: f64) -> String {
    let name = [
        "angular momentum (relative)",
        "energy balance (relative)",
        "quaternion norm ||q| − 1|",
    ][i];
    format!(
        "the {name} drifted by {value:.3e} by t = {}, beyond the bound {b:e} \
         (checks.max_drift)",
        seconds(t)
    )
}

/// Time, state and what to do about drift beyond a bound.
fn drift_message(what: &str, t: f64, y: &[f64], sim: &Simulation) -> String {
    let m = &sim.method;
    let remedy = match (m.fixed_step(), m.adaptive()) {
        (Some(dt), _) => format!(
            "a smaller step (dt is {dt:e} s; the drift of an order-p method shrinks as dt^p), \
             or method gauss, which keeps quadratic invariants such as |H|, T and |q| to \
             round-off for a rigid body"
        ),
        (None, Some(a)) => format!(
            "tighter tolerances (rtol {:e}, atol {:e} now; drift scales roughly with rtol), or \
             a looser bound if this accuracy is enough",
            a.rtol, a.atol
        ),
        _ => "a looser bound if this accuracy is enough".into(),
    };
    format!(
        "{what}; state at t = {} [ω (rad/s), q (w,x,y,z)] = [{}]; suggested remedy: {remedy}",
        seconds(t),
        hub_state_text(y)
    )
}

/// The first effector outside the range its model holds in at time `t` and state `y`:
/// `(cause, remedy)`.
/// A failed integration near such a state is blamed on it rather than on generic stiffness
/// (e.g. a flap–lag rod at its coordinate singularity, which no integrator gets past).
fn model_outside_range(sc: &Spacecraft, t: f64, y: &[f64]) -> Option<(String, String)> {
    let hub = sc.hub_state(t, y);
    sc.effectors().iter().enumerate().find_map(|(k, e)| {
        let x = sc.effector_states(k, y);
        let v = e.validity_at(&hub, x)?;
        v.past_limit().then(|| {
            let (state, remedy) = e.validity_report_at(&hub, x);
            (
                format!(
                    "{} `{}` left its model's range: {state}",
                    e.kind(),
                    e.name()
                ),
                remedy,
            )
        })
    })
}

/// Checks the effectors with a validity range (`ranged`) at state `y` and time `t`: warns
/// once past each one's warning threshold (and once more past its limit under
/// `checks.on_validity: warn`); past a limit under `stop`, returns the invalid-model status.
#[allow(clippy::too_many_arguments)]
fn check_validity(
    sim: &Simulation,
    ranged: &[usize],
    reported: &mut [u8],
    t: f64,
    y: &[f64],
    sink: &mut dyn Sink,
    warnings: &mut Vec<Warning>,
) -> std::io::Result<Option<Status>> {
    let sc = &sim.spacecraft;
    let hub = sc.hub_state(t, y);
    for &k in ranged {
        let e = &sc.effectors()[k];
        let x = sc.effector_states(k, y);
        let Some(v) = e.validity_at(&hub, x) else {
            continue;
        };
        let level = if v.past_limit() {
            2
        } else if v.past_warning() {
            1
        } else {
            0
        };
        if level <= reported[k] {
            continue;
        }
        let (state, remedy) = e.validity_report_at(&hub, x);
        let stop = level == 2 && sim.drift_limits.on_validity == OnBreach::Stop;
        if stop {
            return Ok(Some(Status::InvalidModel {
                diagnosis: format!(
                    "{} `{}` left the range its model holds in at t = {}: {state}; hub state \
                     [ω (rad/s), q (w,x,y,z)] = [{}]; suggested remedy: {remedy} (or \
                     `checks: {{on_validity: warn}}` to go on regardless)",
                    e.kind(),
                    e.name(),
                    seconds(t),
                    hub_state_text(y)
                ),
            }));
        }
        reported[k] = level;
        let message = if level == 2 {
            format!(
                "{} `{}` left the range its model holds in at t = {}: {state}; the run goes on \
                 (checks.on_validity: warn) but its results from here are not to be trusted; \
                 suggested remedy: {remedy}",
                e.kind(),
                e.name(),
                seconds(t)
            )
        } else {
            format!(
                "{} `{}` nears the edge of the range its model holds in at t = {}: {state}; \
                 suggested remedy: {remedy}",
                e.kind(),
                e.name(),
                seconds(t)
            )
        };
        let w = Warning { t, message };
        sink.warning(&w)?;
        warnings.push(w);
    }
    Ok(None)
}

/// The hub's rates and attitude (the first seven states) for diagnoses.
fn hub_state_text(y: &[f64]) -> String {
    y.iter()
        .take(7)
        .map(|v| format!("{v:.6e}"))
        .collect::<Vec<_>>()
        .join(", ")
}
