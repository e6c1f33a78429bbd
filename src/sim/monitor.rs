//! What a run does around each accepted step: sample the output grid, locate events, track
//! invariant drift, check the models' validity ranges and the step size. One code for every
//! path that integrates a run: the scalar loop ([`super::drive`]) and the lockstep lanes of a
//! campaign ([`super::lanes`]) both hand it their steps through [`StepView`].

use super::events::{Watch, far_from_crossing};
use super::{
    COLLAPSE_WINDOW, Condition, DIVERGENCE_ENERGY_REL, Drift, EventRecord, MAX_STEPS_TO_GO,
    OnBreach, Outcome, Quantity, Reference, Simulation, Sink, Status, Warning, check_validity,
    dense_failure, diagnose, drift_excess, drift_message, keep_event,
};
use crate::integrate::{OdeSystem, Stats, Stepper};
use crate::model::{Observation, Spacecraft};
use crate::timefmt::seconds;
use std::time::Instant;

/// What the monitor reads of an integrator that has just taken an accepted step, from
/// [`StepView::t_prev`] to [`StepView::t`].
pub(crate) trait StepView {
    /// End of the step (s).
    fn t(&self) -> f64;
    /// Start of the step (s).
    fn t_prev(&self) -> f64;
    /// State at the end of the step.
    fn y(&self) -> &[f64];
    /// Whether every component of the state at the end of the step is finite.
    fn state_is_finite(&self) -> bool {
        self.y().iter().all(|v| v.is_finite())
    }
    /// The state at `t` in the step, from its dense output.
    fn interpolate(&self, t: f64, out: &mut [f64]);
    /// Makes the dense output inside the step available; false if it came out non-finite.
    fn prepare_interpolation(&mut self, sc: &Spacecraft) -> bool;
    /// Work so far.
    fn stats(&self) -> Stats;
    /// The observation at the end of the step, if the integrator made it already (as
    /// `Spacecraft::observe_for_events(t, y, angles)` would, bit for bit).
    fn end_observation(&self, _sc: &Spacecraft, _angles: bool) -> Option<Observation> {
        None
    }
    /// The value of `quantity` at the end of the step, if the integrator has it without
    /// forming the observation there (as `quantity.value` of that observation would give it,
    /// bit for bit).
    fn end_value(&self, _quantity: Quantity) -> Option<f64> {
        None
    }
    /// The nutation angle (rad) at `t`, the step's end or a time inside it, if the
    /// integrator has it without forming the observation there (as that observation's
    /// `nutation_angle`, bit for bit).
    fn nutation_at(&self, _t: f64) -> Option<f64> {
        None
    }
    /// The drift at the end of the step from the run's start, if the integrator computed it
    /// already (as `Reference::terms` of the end state's invariants would, bit for bit).
    fn end_drift(&self) -> Option<Drift> {
        None
    }
    /// The state at `t` inside the step into `out` and its observation, if the integrator
    /// made them already (as `interpolate(t, out)` and then
    /// `Spacecraft::observe_for_events(t, out, angles)` would, bit for bit).
    fn observe_at(
        &self,
        _t: f64,
        _sc: &Spacecraft,
        _angles: bool,
        _out: &mut [f64],
    ) -> Option<Observation> {
        None
    }
}

impl<M: Stepper> StepView for M {
    #[inline(always)]
    fn t(&self) -> f64 {
        Stepper::t(self)
    }
    #[inline(always)]
    fn t_prev(&self) -> f64 {
        Stepper::t_prev(self)
    }
    #[inline(always)]
    fn y(&self) -> &[f64] {
        Stepper::y(self)
    }
    #[inline(always)]
    fn interpolate(&self, t: f64, out: &mut [f64]) {
        Stepper::interpolate(self, t, out)
    }
    #[inline(always)]
    fn prepare_interpolation(&mut self, sc: &Spacecraft) -> bool {
        Stepper::prepare_interpolation(self, sc)
    }
    #[inline(always)]
    fn stats(&self) -> Stats {
        Stepper::stats(self)
    }
}

/// One run's watch over its steps: begun at t = 0 ([`Monitor::start`]), fed each accepted
/// step ([`Monitor::after_step`]), and closed into the run's [`Outcome`] ([`Monitor::finish`]).
pub(crate) struct Monitor<'a> {
    started: Instant,
    sim: &'a Simulation,
    /// Scratch state; at the end, the last state read (event, last finite state).
    buf: Vec<f64>,
    o0: Observation,
    inv: Reference,
    drift: Drift,
    events: Vec<EventRecord>,
    events_not_kept: u64,
    warnings: Vec<Warning>,
    /// Invariants already warned about (momentum, energy, quaternion norm).
    warned: [bool; 3],
    /// (steps, t) at the start of the current step-size window.
    window: (u64, f64),
    collapsed_windows: u32,
    watches: Vec<Watch<'a>>,
    /// The event checks' observations compute the angles to the principal axes only when a
    /// condition watches one (three arctangents a check).
    watched_angles: bool,
    /// Effectors whose models have a validity range, and how far each has been reported
    /// (0: not yet, 1: warned, 2: warned past the limit).
    ranged: Vec<usize>,
    validity_reported: Vec<u8>,
    samples: u64,
    /// Index k of the next time of the output grid, and that time k / rate (s), kept
    /// together so that the division is made once per sample, not at every step.
    next_k: u64,
    next_t: f64,
    last_sample_t: f64,
    last_obs: Observation,
    /// Times of the current step's interior event-check points (its ends are the step's).
    grid: Vec<f64>,
    /// Each watch's margin at each point of `grid`, point by point (`grid[p]`'s margins at
    /// `p * watches.len()..`): each margin computed once, and no observation kept.
    grid_margins: Vec<f64>,
    /// Each watch's margin at the current step's start (the last step's end, or t = 0), and
    /// at its end.
    prev_margins: Vec<f64>,
    end_margins: Vec<f64>,
    /// Each condition's margin at the start of the last step, and that step's size (s), for
    /// `far_from_crossing`; NaN: not known (the first step, or after a breakpoint).
    margins_before: Vec<f64>,
    h_before: f64,
    /// Set when the state went non-finite: the time of the last finite state (held in `buf`).
    last_good: Option<f64>,
    /// Scenes without a prescribed motion conserve the energy balance.
    passive: bool,
    /// Interior event checks in a step where a margin could cross and re-cross.
    interior_checks: usize,
    /// Whether the samples carry the angles to the principal axes (the sink reads them).
    sample_angles: bool,
}

impl<'a> Monitor<'a> {
    /// Begins watching `sim` from its initial state `y0`: the first sample, the conditions
    /// already true at t = 0, a model already outside its range. A status means the run ends
    /// at t = 0.
    pub(crate) fn start(
        sim: &'a Simulation,
        y0: &[f64],
        sink: &mut dyn Sink,
        interior_checks: usize,
    ) -> std::io::Result<(Self, Option<Status>)> {
        let started = Instant::now();
        let sc = &sim.spacecraft;
        let o0 = sc.observe(0.0, y0);
        let inv = Reference::of(&o0);
        let mut watches: Vec<Watch> = sim
            .stop
            .iter()
            .map(|c| Watch::new(c, true))
            .chain(sim.events.iter().map(|c| Watch::new(c, false)))
            .collect();
        let watched_angles = watches
            .iter()
            .any(|w| matches!(w.condition.quantity, Quantity::AngleToPrincipalDeg(_)));
        let ranged: Vec<usize> = (0..sc.effectors().len())
            .filter(|&k| {
                sc.effectors()[k]
                    .validity_at(&sc.hub_state(0.0, y0), sc.effector_states(k, y0))
                    .is_some()
            })
            .collect();
        let mut validity_reported = vec![0u8; sc.effectors().len()];
        sink.sample(&o0, y0, &inv)?;
        let mut events = Vec::new();
        let mut events_not_kept = 0u64;
        let mut warnings = Vec::new();

        // Conditions already true at t = 0 start holding there (and fire, without `for:`).
        let mut status = None;
        for w in watches.iter_mut() {
            if w.start(w.condition.margin(&o0)).is_some() {
                let e = EventRecord {
                    t: 0.0,
                    confirmed: 0.0,
                    condition: w.condition.describe(),
                    terminal: w.terminal,
                };
                sink.event(&e, &o0)?;
                keep_event(&mut events, &mut events_not_kept, e);
                if w.terminal && status.is_none() {
                    status = Some(Status::Stopped {
                        condition: w.condition.describe(),
                    });
                }
            }
        }
        // A model already outside its range at t = 0.
        if status.is_none()
            && let Some(s) = check_validity(
                sim,
                &ranged,
                &mut validity_reported,
                0.0,
                y0,
                sink,
                &mut warnings,
            )?
        {
            status = Some(s);
        }
        let n_watches = watches.len();
        let prev_margins = watches.iter().map(|w| w.condition.margin(&o0)).collect();
        let monitor = Monitor {
            started,
            sim,
            buf: y0.to_vec(),
            last_obs: o0.clone(),
            o0,
            inv,
            drift: Drift::default(),
            events,
            events_not_kept,
            warnings,
            warned: [false; 3],
            window: (0, 0.0),
            collapsed_windows: 0,
            watches,
            watched_angles,
            ranged,
            validity_reported,
            samples: 1,
            next_k: 1,
            next_t: 1.0 / sim.output_rate,
            last_sample_t: 0.0,
            grid: Vec::with_capacity(interior_checks),
            grid_margins: Vec::with_capacity(interior_checks * n_watches),
            prev_margins,
            end_margins: vec![f64::NAN; n_watches],
            margins_before: vec![f64::NAN; n_watches],
            h_before: 0.0,
            last_good: None,
            passive: sc.conserves_energy(),
            interior_checks,
            sample_angles: sink.reads_principal_angles(),
        };
        Ok((monitor, status))
    }

    /// After an effector's breakpoint the conditions' margins before the next step are not
    /// known.
    pub(crate) fn restarted(&mut self) {
        self.margins_before.fill(f64::NAN);
    }

    /// Reads the accepted step that `stepper` has just taken: the invariants' drift, the
    /// checks, the events inside it and the output samples up to its end (or to a terminal
    /// event). A status ends the run.
    pub(crate) fn after_step<V: StepView>(
        &mut self,
        stepper: &mut V,
        sink: &mut dyn Sink,
    ) -> std::io::Result<Option<Status>> {
        let Monitor {
            sim,
            ref mut buf,
            ref inv,
            ref mut drift,
            ref mut events,
            ref mut events_not_kept,
            ref mut warnings,
            ref mut warned,
            ref mut window,
            ref mut collapsed_windows,
            ref mut watches,
            watched_angles,
            ref ranged,
            ref mut validity_reported,
            ref mut samples,
            ref mut next_k,
            ref mut next_t,
            ref mut last_sample_t,
            ref mut last_obs,
            ref mut grid,
            ref mut grid_margins,
            ref mut prev_margins,
            ref mut end_margins,
            ref mut margins_before,
            ref mut h_before,
            ref mut last_good,
            passive,
            interior_checks,
            sample_angles,
            ..
        } = *self;
        let sc = &sim.spacecraft;
        let t_end = sim.duration;
        let rate = sim.output_rate;
        let limits = &sim.drift_limits;
        let n = sc.dim();
        let observe_for_events = |t: f64, y: &[f64]| sc.observe_for_events(t, y, watched_angles);
        let t0 = stepper.t_prev();
        let t1 = stepper.t();
        if !stepper.state_is_finite() {
            // Report the last finite state: the start of the failed step.
            let t_good = stepper.t_prev();
            stepper.interpolate(t_good, buf);
            let what = format!(
                "the state became non-finite in the step from t = {} to t = {}",
                seconds(t_good),
                seconds(t1)
            );
            *last_good = Some(t_good);
            return Ok(Some(Status::Failed {
                diagnosis: diagnose(&what, t_good, buf, sim),
            }));
        }
        // Each watch's margin at the step's end, from the value the stepper hands where it has
        // it (the lanes), from the observation there otherwise: formed once, only then (with
        // the angles when a watch needs them). The drift check reads its invariants if it
        // was formed, and computes them alone otherwise.
        let mut o1: Option<Observation> = None;
        for (end_margin, watch) in end_margins.iter_mut().zip(watches.iter()) {
            let c = watch.condition;
            let value = match stepper.end_value(c.quantity) {
                Some(v) => v,
                None => c.quantity.value(o1.get_or_insert_with(|| {
                    stepper
                        .end_observation(sc, watched_angles)
                        .unwrap_or_else(|| observe_for_events(t1, stepper.y()))
                })),
            };
            *end_margin = c.margin_of_value(value);
        }
        let terms = match (stepper.end_drift(), &o1) {
            (Some(terms), _) => terms,
            (None, Some(o)) => inv.terms(&o.invariants()),
            (None, None) => inv.terms(&sc.invariants(t1, stepper.y())),
        };
        drift.absorb(&terms);
        if passive && drift.energy_rel > DIVERGENCE_ENERGY_REL {
            let what = format!(
                "the energy balance (kinetic + elastic + dissipated) changed by {:.0}% by \
                 t = {}, which no passive scene can do: the integration is diverging",
                100.0 * drift.energy_rel,
                seconds(t1)
            );
            return Ok(Some(Status::Failed {
                diagnosis: diagnose(&what, t1, stepper.y(), sim),
            }));
        }
        if let Some((which, what)) = drift_excess(limits, drift, warned, t1) {
            let message = drift_message(&what, t1, stepper.y(), sim);
            match limits.on_drift {
                OnBreach::Stop => return Ok(Some(Status::Failed { diagnosis: message })),
                OnBreach::Warn => {
                    warned[which] = true;
                    let w = Warning { t: t1, message };
                    sink.warning(&w)?;
                    warnings.push(w);
                }
            }
        }
        let steps = stepper.stats().steps;
        if steps >= window.0 + COLLAPSE_WINDOW {
            let h_avg = (t1 - window.1) / (steps - window.0) as f64;
            let whole = t_end / h_avg;
            *collapsed_windows = if whole > MAX_STEPS_TO_GO {
                *collapsed_windows + 1
            } else {
                0
            };
            if *collapsed_windows >= 2 {
                let what = format!(
                    "the step size collapsed: the last {} steps averaged h = {h_avg:.3e} s, a \
                     step at which the {t_end} s run would take {whole:.1e} steps (limit \
                     {MAX_STEPS_TO_GO:e})",
                    COLLAPSE_WINDOW
                );
                return Ok(Some(Status::Failed {
                    diagnosis: diagnose(&what, t1, stepper.y(), sim),
                }));
            }
            *window = (steps, t1);
        }
        if !ranged.is_empty()
            && let Some(s) = check_validity(
                sim,
                ranged,
                validity_reported,
                t1,
                stepper.y(),
                sink,
                warnings,
            )?
        {
            return Ok(Some(s));
        }
        // Events inside (t0, t1]: check interior points too, so that a quantity that crosses
        // and re-crosses within one long step is not missed.
        // (event time, time known, condition, terminal)
        let mut found: Vec<(f64, f64, &Condition, bool)> = Vec::new();
        if !watches.is_empty() {
            'watching: {
                // Interior points only where a margin could cross and re-cross inside the step
                // (`far_from_crossing`): elsewhere the step's ends decide, and the dense output
                // is not needed.
                let h = t1 - t0;
                let mut near = false;
                // Whether, without interior points, every watch would come out of the step as it
                // went in (the common step, far from every threshold): then the general pass
                // below would change nothing but the margins' swap.
                let mut unmoved = true;
                let n_watches = watches.len();
                for (((watch, g_before), &ga), &gb) in watches
                    .iter()
                    .zip(margins_before.iter_mut())
                    .zip(prev_margins.iter())
                    .zip(end_margins.iter())
                {
                    if watch.active() {
                        near |= !far_from_crossing(*g_before, ga, gb, *h_before, h);
                        unmoved &= watch.unmoved(ga, gb, t1);
                    }
                    *g_before = ga;
                }
                *h_before = h;
                if !near && unmoved {
                    break 'watching;
                }
                let checks = if near { interior_checks } else { 0 };
                if checks > 0 && !stepper.prepare_interpolation(sc) {
                    return Ok(Some(dense_failure(t0, t1, stepper.y(), sim)));
                }
                // The interior points (reused across steps: no allocation per step once they have
                // grown); the points are t0, the interior ones, t1.
                grid.clear();
                grid_margins.clear();
                for j in 1..=checks {
                    let t = t0 + (t1 - t0) * j as f64 / (checks + 1) as f64;
                    stepper.interpolate(t, buf);
                    let o = observe_for_events(t, buf);
                    grid_margins.extend(watches.iter().map(|w| w.condition.margin(&o)));
                    grid.push(t);
                }
                let last = checks + 1;
                let time_at = |p: usize| match p {
                    0 => t0,
                    p if p == last => t1,
                    p => grid[p - 1],
                };
                let margin_at = |p: usize, w: usize| match p {
                    0 => prev_margins[w],
                    p if p == last => end_margins[w],
                    p => grid_margins[(p - 1) * n_watches + w],
                };
                // A sign change is located on the dense output.
                let bracketed = watches.iter().enumerate().any(|(k, w)| {
                    w.active()
                        && (1..=last)
                            .any(|p| (margin_at(p - 1, k) > 0.0) != (margin_at(p, k) > 0.0))
                });
                if bracketed && !stepper.prepare_interpolation(sc) {
                    return Ok(Some(dense_failure(t0, t1, stepper.y(), sim)));
                }
                for (k, watch) in watches.iter_mut().enumerate() {
                    if !watch.active() {
                        continue;
                    }
                    let c = watch.condition;
                    for p in 1..=last {
                        let (a, b) = (time_at(p - 1), time_at(p));
                        let (ga, gb) = (margin_at(p - 1, k), margin_at(p, k));
                        let crossing = |up: bool| {
                            let mut scratch = vec![0.0; n];
                            let margin = |t: f64, y: &[f64]| c.margin(&observe_for_events(t, y));
                            if up {
                                locate(&*stepper, &margin, a, b, ga, gb, &mut scratch)
                            } else {
                                locate(
                                    &*stepper,
                                    &|t, y| -margin(t, y),
                                    a,
                                    b,
                                    -ga,
                                    -gb,
                                    &mut scratch,
                                )
                            }
                        };
                        if let Some(f) = watch.advance(a, b, ga, gb, crossing) {
                            found.push((f.t, f.confirmed, c, watch.terminal));
                            if watch.terminal || !watch.active() {
                                break;
                            }
                        }
                    }
                }
                if !found.is_empty() {
                    found.sort_by(|a, b| a.1.total_cmp(&b.1));
                    if let Some(i) = found.iter().position(|f| f.3) {
                        found.truncate(i + 1);
                    }
                }
            }
            std::mem::swap(prev_margins, end_margins);
        }
        let stop_at = found.last().filter(|f| f.3).map(|f| f.1);
        let horizon = stop_at.unwrap_or(t1);
        // Samples and events inside the step are read from the dense output.
        let inside = *next_t < horizon.min(t1) || !found.is_empty();
        if inside && !stepper.prepare_interpolation(sc) {
            return Ok(Some(dense_failure(t0, t1, stepper.y(), sim)));
        }

        // Samples on the grid up to the horizon, interleaved with events in time order.
        let mut pending = found.iter().peekable();
        loop {
            let tk = *next_t;
            let next_event_t = pending.peek().map(|f| f.1);
            let sample_due = tk <= horizon && tk <= t_end;
            match (sample_due, next_event_t) {
                (true, Some(te)) if te < tk => {}
                (true, _) => {
                    // A sink that reads only the nutation angle takes it as the stepper hands
                    // it, without an observation.
                    let taken_as_angle = stepper
                        .nutation_at(tk)
                        .and_then(|angle| sink.nutation_sample(tk, angle));
                    if let Some(taken) = taken_as_angle {
                        taken?;
                    } else {
                        let o = if tk == t1 {
                            buf.copy_from_slice(stepper.y());
                            match &o1 {
                                Some(o) if watched_angles || !sample_angles => o.clone(),
                                Some(o) => Observation {
                                    angles_to_principal: sc.angles_to_principal(&o.omega),
                                    ..o.clone()
                                },
                                None => stepper.end_observation(sc, sample_angles).unwrap_or_else(
                                    || sc.observe_for_events(t1, buf, sample_angles),
                                ),
                            }
                        } else if let Some(o) = stepper.observe_at(tk, sc, sample_angles, buf) {
                            o
                        } else {
                            stepper.interpolate(tk, buf);
                            sc.observe_for_events(tk, buf, sample_angles)
                        };
                        sink.sample(&o, buf, inv)?;
                    }
                    *samples += 1;
                    *next_k += 1;
                    *next_t = *next_k as f64 / rate;
                    *last_sample_t = tk;
                    continue;
                }
                (false, None) => break,
                (false, Some(_)) => {}
            }
            // An event comes first.
            let Some(&(t_event, te, c, terminal)) = pending.next() else {
                break;
            };
            stepper.interpolate(te, buf);
            let o = sc.observe(te, buf);
            let e = EventRecord {
                t: t_event,
                confirmed: te,
                condition: c.describe(),
                terminal,
            };
            sink.event(&e, &o)?;
            keep_event(events, events_not_kept, e);
            if terminal {
                if te > *last_sample_t {
                    sink.sample(&o, buf, inv)?;
                    *samples += 1;
                    *last_sample_t = te;
                }
                *last_obs = o;
                return Ok(Some(Status::Stopped {
                    condition: c.describe(),
                }));
            }
        }
        Ok(None)
    }

    /// Closes the run that ended with `status` (`None`: it reached its end) with `stepper`
    /// where it stopped: the last instant reached is sampled, on the grid or not.
    pub(crate) fn finish<V: StepView>(
        mut self,
        stepper: &V,
        status: Option<Status>,
        sink: &mut dyn Sink,
    ) -> std::io::Result<Outcome> {
        let sc = &self.sim.spacecraft;
        let status = status.unwrap_or(Status::Complete);
        // With `for:`, events are known out of time order; list them in time order.
        self.events.sort_by(|a, b| a.t.total_cmp(&b.t));
        let stopped = matches!(status, Status::Stopped { .. });
        let final_state = if stopped || self.last_good.is_some() {
            self.buf.clone()
        } else {
            stepper.y().to_vec()
        };
        if let Some(t_good) = self.last_good {
            self.last_obs = sc.observe(t_good, &self.buf);
            if t_good > self.last_sample_t {
                sink.sample(&self.last_obs, &self.buf, &self.inv)?;
                self.samples += 1;
            }
        } else if !stopped {
            let o = sc.observe(stepper.t(), stepper.y());
            if stepper.t() > self.last_sample_t && stepper.y().iter().all(|v| v.is_finite()) {
                sink.sample(&o, stepper.y(), &self.inv)?;
                self.samples += 1;
            }
            self.last_obs = o;
        }
        Ok(Outcome {
            status,
            final_observation: self.last_obs,
            initial_observation: self.o0,
            final_state,
            stats: stepper.stats(),
            drift: self.drift,
            events: self.events,
            events_not_kept: self.events_not_kept,
            warnings: self.warnings,
            samples: self.samples,
            wall_time: self.started.elapsed().as_secs_f64(),
        })
    }
}

/// Locates the root of `margin` (of the time and the state there) in `[a, b]` on the dense
/// output (Illinois regula falsi), given `margin(a) = ga ≤ 0 < gb = margin(b)`.
fn locate<V: StepView + ?Sized>(
    stepper: &V,
    margin: &dyn Fn(f64, &[f64]) -> f64,
    mut a: f64,
    mut b: f64,
    mut ga: f64,
    mut gb: f64,
    buf: &mut [f64],
) -> f64 {
    // Relative to the time itself (documented as ~1e-13 relative), never below a few ulps.
    let tol = (1e-13 * a.abs().max(b.abs())).max(4.0 * f64::EPSILON * b.abs());
    let mut side = 0i8;
    for _ in 0..200 {
        if (b - a).abs() <= tol {
            break;
        }
        let t = ((a * gb - b * ga) / (gb - ga)).clamp(a.min(b), a.max(b));
        stepper.interpolate(t, buf);
        let g = margin(t, buf);
        if g > 0.0 {
            b = t;
            gb = g;
            if side == 1 {
                ga *= 0.5;
            }
            side = 1;
        } else {
            a = t;
            ga = g;
            if side == -1 {
                gb *= 0.5;
            }
            side = -1;
        }
        if g == 0.0 {
            return t;
        }
    }
    b
}
