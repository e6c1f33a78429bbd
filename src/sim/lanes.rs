//! Runs integrated in lockstep lanes ([`crate::lanes`]), each watched by the run monitor the
//! scalar loop uses: the same samples, events, invariants and checks, from the same steps and
//! the same dense output, so a run's outcome is the scalar path's (docs/montecarlo.md, "Lanes
//! in a campaign").
//!
//! Four classes have a lane form ([`LaneForm`]), each integrated by dopri5 or dop853: the
//! nutation-damper class ([`crate::lanes::damper`], a rigid hub with one spring–mass damper),
//! the energy-sink class ([`crate::lanes::energy_sink`], a rigid hub with principal axes and
//! one energy sink), the hinged-rods class ([`crate::lanes::hinged_rods`], a hub with four
//! flap–lag rods) and the driven-wheel class ([`crate::lanes::wheel`], a hub with one wheel
//! whose motor holds a command between breakpoints, stopping at each: a stepped profile's
//! steps, a rate-damping law's ticks). [`lane_form`] says why another scene has none; such a
//! run, or one the lanes decline part-way, takes the scalar path.

use super::method::Adaptive;
use super::monitor::{Monitor, StepView};
use super::{
    Drift, Method, Outcome, Quantity, Simulation, Sink, Status, diagnose, interior_checks,
};
use crate::effectors::energy_sink::EnergySink;
use crate::effectors::motor_wheel::MotorWheel;
use crate::effectors::particles::ParticleEffector;
use crate::effectors::spring_mass::SpringMass;
use crate::integrate::{Stats, Tolerances};
use crate::lanes::damper::{self, DamperRun};
use crate::lanes::energy_sink::{self, SinkRun};
use crate::lanes::ensemble::{
    Engine, GridObservation, LaneInterpolant, LaneMethodKind, LaneObservation, LaneRun,
    LaneSettings, LaneStatus, LaneStep, StepInLanes, integrate_runs_observed_with,
};
use crate::lanes::hinged_rods::{self, RodsRun};
use crate::lanes::wheel::{self, WheelRun};
use crate::model::{Invariants, Observation, Spacecraft};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use std::any::Any;
use std::cell::OnceCell;
use std::sync::atomic::{AtomicBool, Ordering};

/// A lane's step as the monitor reads it: the state at its end and its dense output are
/// read out of the lanes the first time the monitor asks for them.
struct LaneView<'s, const DIM: usize> {
    step: &'s LaneStep,
    rest: &'s mut dyn StepInLanes<DIM>,
    y: OnceCell<[f64; DIM]>,
    interpolant: OnceCell<LaneInterpolant<DIM>>,
}

impl<'s, const DIM: usize> LaneView<'s, DIM> {
    fn new(step: &'s LaneStep, rest: &'s mut dyn StepInLanes<DIM>) -> Self {
        LaneView {
            step,
            rest,
            y: OnceCell::new(),
            interpolant: OnceCell::new(),
        }
    }

    fn state(&self) -> &[f64; DIM] {
        self.y.get_or_init(|| {
            let mut y = [0.0; DIM];
            self.rest.state(&mut y);
            y
        })
    }
}

impl<const DIM: usize> StepView for LaneView<'_, DIM> {
    fn t(&self) -> f64 {
        self.step.t
    }
    fn t_prev(&self) -> f64 {
        self.step.t_prev
    }
    fn y(&self) -> &[f64] {
        self.state()
    }
    fn state_is_finite(&self) -> bool {
        self.step.finite
    }
    fn interpolate(&self, t: f64, out: &mut [f64]) {
        let interpolant = self.interpolant.get_or_init(|| self.rest.interpolant());
        interpolant.value(t, self.step.t_prev, self.step.t, self.state(), out);
    }
    fn prepare_interpolation(&mut self, _: &Spacecraft) -> bool {
        let finite = self.rest.prepare_interpolation();
        // An interpolant formed before the dense stages were is formed again (set anew rather
        // than taken: `take` would copy it out).
        if self.interpolant.get().is_some() {
            self.interpolant = OnceCell::new();
        }
        finite
    }
    fn stats(&self) -> Stats {
        self.step.stats
    }
    fn end_drift(&self) -> Option<Drift> {
        let d = &self.step.drift;
        Some(Drift {
            h_norm_rel: d.h_norm_rel,
            h_inertial_rel: d.h_inertial_rel,
            energy_rel: d.energy_rel,
            q_norm: d.q_norm,
        })
    }
    /// The quantities the lanes computed at the step's end, as `Quantity::value` reads them
    /// from the observation formed of them (`observation`): ω from the state, the kinetic
    /// energy and the nutation angle from the lanes' observation.
    fn end_value(&self, quantity: Quantity) -> Option<f64> {
        let step = self.step;
        match quantity {
            Quantity::NutationAngleDeg => Some(step.end_nutation_angle.to_degrees()),
            Quantity::Omega(i) => Some(self.state()[i]),
            Quantity::KineticEnergy => Some(step.end_kinetic_energy),
            _ => None,
        }
    }
    fn nutation_at(&self, t: f64) -> Option<f64> {
        if t.to_bits() == self.step.t.to_bits() {
            return Some(self.step.end_nutation_angle);
        }
        let sample = self.step.sample.as_ref()?;
        if sample.t.to_bits() == t.to_bits() {
            return Some(sample.nutation_angle);
        }
        self.step
            .later_samples
            .iter()
            .find(|s| s.t.to_bits() == t.to_bits())
            .map(|s| s.nutation_angle)
    }
    fn end_observation(&self, sc: &Spacecraft, angles: bool) -> Option<Observation> {
        let (step, y) = (self.step, self.state());
        Some(observation(sc, step.t, y, &self.rest.end(), angles))
    }
    fn observe_at(
        &self,
        t: f64,
        sc: &Spacecraft,
        angles: bool,
        out: &mut [f64],
    ) -> Option<Observation> {
        if self.step.sample?.t.to_bits() != t.to_bits() {
            return None;
        }
        let sample = self.rest.sample()?;
        out.copy_from_slice(&sample.y);
        Some(observation(sc, t, &sample.y, &sample.observation, angles))
    }
}

/// The run monitor's observation of a lane's state `y` at `t` (s) from what the lanes computed
/// of it (`lane`), as `Spacecraft::observe_for_events(t, y, angles)` would give it.
fn observation(
    sc: &Spacecraft,
    t: f64,
    y: &[f64],
    lane: &LaneObservation,
    angles: bool,
) -> Observation {
    let [w, i, j, k] = lane.attitude;
    let invariants = Invariants {
        h_body: Vector3::from(lane.h_body),
        h_inertial: Vector3::from(lane.h_inertial),
        // No class carries anything out: the scalar sum starts from zero and stays there.
        h_carried_out: Vector3::zeros(),
        kinetic_energy: lane.kinetic_energy,
        elastic_energy: lane.elastic_energy,
        dissipated_energy: lane.dissipated_energy,
        dissipation_power: lane.dissipation_power,
        external_work: lane.external_work,
        q_norm_error: lane.q_norm_error,
    };
    let attitude = UnitQuaternion::new_unchecked(Quaternion::new(w, i, j, k));
    Observation::from_invariants(
        sc,
        t,
        y,
        &invariants,
        attitude,
        angles,
        lane.h_norm,
        lane.nutation_angle,
    )
}

/// A run of a class the lanes integrate.
#[derive(Debug, Clone)]
pub enum LaneForm {
    /// A rigid hub with one spring–mass damper ([`crate::lanes::damper`]).
    Damper(DamperRun),
    /// A rigid hub with principal axes and one energy sink ([`crate::lanes::energy_sink`]).
    EnergySink(SinkRun),
    /// A hub with four flap–lag hinged rods ([`crate::lanes::hinged_rods`]).
    HingedRods(Box<RodsRun>),
    /// A hub with one wheel whose motor holds a command between breakpoints: a stepped torque
    /// profile or a rate-damping law ([`crate::lanes::wheel`]).
    Wheel(Box<WheelRun>),
}

/// `sim` as a run of a class of the lanes and the integration settings it needs, or why it is
/// not one (a sentence fragment: "its method is radau5, …").
pub fn lane_form(sim: &Simulation) -> Result<(LaneForm, LaneSettings), String> {
    let sc = &sim.spacecraft;
    let (method, a) = match sim.method {
        Method::Dopri5(a) => (LaneMethodKind::Dopri5, a),
        Method::Dop853(a) => (LaneMethodKind::Dop853, a),
        _ => {
            return Err(format!(
                "its method is {}, and the lanes integrate with dopri5 and dop853 only",
                sim.method.name()
            ));
        }
    };
    if let Some(refusal) = sim.method.refusal(sc, sim.duration) {
        return Err(format!("{} refuses it ({refusal})", sim.method.name()));
    }
    if let Some(e) = sc.effectors().iter().find(|e| e.has_switching()) {
        // The scalar loop forecasts its kinks and stops there; the lanes do not.
        return Err(format!(
            "its effector `{}` ({}) has a switching function, whose kinks the lanes do not \
             stop at",
            e.name(),
            e.kind()
        ));
    }
    if sc.effectors().len() == hinged_rods::RODS {
        if let Some(reason) = breakpoints_without_lane_form(sc) {
            return Err(reason);
        }
        let form = LaneForm::HingedRods(Box::new(rods_run(sim)?));
        return Ok((form, settings(method, a)));
    }
    let one = match sc.effectors() {
        [one] => one,
        list => {
            return Err(format!(
                "it has {} effectors, and the lanes have a hub with one spring_mass_damper, \
                 one energy_sink, one wheel or {} flap–lag hinged_rods only",
                list.len(),
                hinged_rods::RODS
            ));
        }
    };
    let any: &dyn Any = one.as_ref();
    if any.downcast_ref::<MotorWheel>().is_some() {
        // The one class whose runs stop at breakpoints (a profile's steps, a law's ticks).
        let y0 = sc.initial_state(&sim.omega0, &sim.attitude0);
        let run = WheelRun::new(sc, &y0, sim.duration, sim.output_rate)?;
        return Ok((LaneForm::Wheel(Box::new(run)), settings(method, a)));
    }
    if let Some(reason) = breakpoints_without_lane_form(sc) {
        return Err(reason);
    }
    let form = if let Some(d) = any.downcast_ref::<ParticleEffector<SpringMass>>() {
        LaneForm::Damper(damper_run(sim, d.model())?)
    } else if let Some(sink) = any.downcast_ref::<EnergySink>() {
        LaneForm::EnergySink(sink_run(sim, sink)?)
    } else {
        return Err(format!(
            "its effector `{}` ({}) has no lane form (the lanes have the spring_mass_damper, \
             the energy_sink, the wheel and four flap–lag hinged_rods together)",
            one.name(),
            one.kind()
        ));
    };
    Ok((form, settings(method, a)))
}

/// Why `sc` has no lane form if it has breakpoints (a scene of a class without them): the
/// effector that has them, and the one class of the lanes that stops at its own.
fn breakpoints_without_lane_form(sc: &Spacecraft) -> Option<String> {
    let e = sc
        .effectors()
        .iter()
        .find(|e| e.next_breakpoint(0.0).is_some())?;
    Some(format!(
        "its effector `{}` ({}) has breakpoints, and the one class of the lanes that stops at \
         its own is a hub with one wheel",
        e.name(),
        e.kind()
    ))
}

/// The lanes' settings for `method` with the scalar method's settings `a`.
fn settings(method: LaneMethodKind, a: Adaptive) -> LaneSettings {
    LaneSettings {
        method,
        tolerances: Tolerances {
            rtol: a.rtol,
            atol: a.atol,
        },
        h_max: a.max_step,
    }
}

/// Whether `run` starts where the scalar path starts `sim`, bit for bit (the lanes' layout is
/// the scalar state's).
fn same_start<const DIM: usize>(sim: &Simulation, run: &impl LaneRun<DIM>) -> bool {
    let y0 = sim.spacecraft.initial_state(&sim.omega0, &sim.attitude0);
    y0.len() == DIM
        && run
            .initial_state()
            .iter()
            .zip(&y0)
            .all(|(a, b)| a.to_bits() == b.to_bits())
}

/// `sim` as a run of the nutation-damper class.
fn damper_run(sim: &Simulation, damper: &SpringMass) -> Result<DamperRun, String> {
    let sc = &sim.spacecraft;
    if !sc.takes_lone_closed_form() {
        return Err("its right-hand side is not the damper's closed form alone".into());
    }
    let hub_mass = sc
        .hub_mass
        .ok_or_else(|| "its hub has no mass".to_string())?;
    let y0 = sc.initial_state(&sim.omega0, &sim.attitude0);
    let run = DamperRun {
        hub_inertia: sc.hub.inertia,
        hub_mass,
        damper: damper.clone(),
        omega0: sim.omega0,
        attitude0: sim.attitude0,
        offset0: y0.get(7).copied().unwrap_or(f64::NAN),
        rate0: y0.get(8).copied().unwrap_or(f64::NAN),
        spin_axis: sc.spin_axis,
        t_end: sim.duration,
        sample_rate: sim.output_rate,
    };
    if !same_start(sim, &run) {
        return Err("its state is not laid out as the lanes' (ω, q, ρ, ρ̇, E)".into());
    }
    Ok(run)
}

/// `sim` as a run of the energy-sink class.
fn sink_run(sim: &Simulation, sink: &EnergySink) -> Result<SinkRun, String> {
    let sc = &sim.spacecraft;
    let Some(euler_coefficients) = sc.euler_coefficients() else {
        return Err(
            "its body axes are not principal (the lanes take Euler's equations in \
                    their three-term form)"
                .into(),
        );
    };
    if !sc.takes_torque_closed_form() {
        return Err("its right-hand side is not Euler's equations with the sink's torque".into());
    }
    let inverse = &sc.hub.inertia_inv;
    let run = SinkRun {
        hub_inertia: sc.hub.inertia,
        inverse_inertia: [inverse[(0, 0)], inverse[(1, 1)], inverse[(2, 2)]],
        euler_coefficients,
        sink: sink.clone(),
        omega0: sim.omega0,
        attitude0: sim.attitude0,
        spin_axis: sc.spin_axis,
        t_end: sim.duration,
        sample_rate: sim.output_rate,
    };
    if !same_start(sim, &run) {
        return Err("its state is not laid out as the lanes' (ω, q, E)".into());
    }
    Ok(run)
}

/// `sim` as a run of the hinged-rods class.
fn rods_run(sim: &Simulation) -> Result<RodsRun, String> {
    let y0 = sim.spacecraft.initial_state(&sim.omega0, &sim.attitude0);
    RodsRun::new(&sim.spacecraft, &y0, sim.duration, sim.output_rate)
}

/// One run in the lanes: its monitor, its sink, and the status its monitor ended it with.
struct Watched<'a, S> {
    index: usize,
    monitor: Monitor<'a>,
    sink: S,
    status: Option<Status>,
}

/// Runs `sims` (the runs of one campaign) in lockstep lanes with `engine`, each feeding a sink
/// of its own. Returns, in the order of `sims`, each run's outcome and sink, or `None` for a
/// run that must take the scalar path: it has no lane form ([`lane_form`]), its class or
/// settings differ from the first lane run's, or the lanes declined it part-way (its sink is
/// then dropped, so a scalar run starts afresh). `interrupt` ends the runs after their current
/// step with [`Status::Interrupted`].
pub fn run_in_lanes<S: Sink + Default>(
    engine: Engine,
    sims: &[&Simulation],
    interrupt: &AtomicBool,
) -> std::io::Result<Vec<Option<(Outcome, S)>>> {
    let forms: Vec<_> = sims.iter().map(|sim| lane_form(sim).ok()).collect();
    match forms.iter().flatten().next() {
        Some((LaneForm::Damper(_), _)) => run_class::<S, DamperRun, { damper::DIM }>(
            engine,
            sims,
            forms,
            |f| match f {
                LaneForm::Damper(run) => Some(run),
                _ => None,
            },
            interrupt,
        ),
        Some((LaneForm::EnergySink(_), _)) => run_class::<S, SinkRun, { energy_sink::DIM }>(
            engine,
            sims,
            forms,
            |f| match f {
                LaneForm::EnergySink(run) => Some(run),
                _ => None,
            },
            interrupt,
        ),
        Some((LaneForm::HingedRods(_), _)) => run_class::<S, RodsRun, { hinged_rods::DIM }>(
            engine,
            sims,
            forms,
            |f| match f {
                LaneForm::HingedRods(run) => Some(*run),
                _ => None,
            },
            interrupt,
        ),
        Some((LaneForm::Wheel(_), _)) => run_class::<S, WheelRun, { wheel::DIM }>(
            engine,
            sims,
            forms,
            |f| match f {
                LaneForm::Wheel(run) => Some(*run),
                _ => None,
            },
            interrupt,
        ),
        None => Ok((0..sims.len()).map(|_| None).collect()),
    }
}

/// [`run_in_lanes`] for the runs of the first lane run's class (`of_class` picks them out of
/// their lane forms `forms`).
fn run_class<S: Sink + Default, R: LaneRun<DIM>, const DIM: usize>(
    engine: Engine,
    sims: &[&Simulation],
    forms: Vec<Option<(LaneForm, LaneSettings)>>,
    of_class: impl Fn(LaneForm) -> Option<R>,
    interrupt: &AtomicBool,
) -> std::io::Result<Vec<Option<(Outcome, S)>>> {
    let mut results: Vec<Option<(Outcome, S)>> = (0..sims.len()).map(|_| None).collect();
    let mut shared: Option<LaneSettings> = None;
    let mut runs = Vec::new();
    let mut watched: Vec<Watched<S>> = Vec::new();
    for (index, (sim, form)) in sims.iter().zip(forms).enumerate() {
        let Some((form, settings)) = form else {
            continue;
        };
        let Some(run) = of_class(form) else {
            continue;
        };
        let same = |s: &LaneSettings| {
            s.method == settings.method
                && s.tolerances == settings.tolerances
                && s.h_max.to_bits() == settings.h_max.to_bits()
        };
        if !same(shared.get_or_insert(settings)) {
            continue;
        }
        let y0 = run.initial_state();
        let mut sink = S::default();
        let (monitor, status) = Monitor::start(sim, &y0, &mut sink, interior_checks(&sim.method))?;
        let steps_ahead = sim.duration > 0.0;
        if status.is_some() || !steps_ahead {
            // Ended at t = 0, as the scalar loop does without a step.
            let (start, mut state) = LaneStep::settled(0.0, y0, Stats::default());
            let outcome = monitor.finish(&LaneView::new(&start, &mut state), status, &mut sink)?;
            results[index] = Some((outcome, sink));
            continue;
        }
        runs.push(run);
        watched.push(Watched {
            index,
            monitor,
            sink,
            status: None,
        });
    }
    let Some(settings) = shared else {
        return Ok(results);
    };
    let mut io_error = None;
    // A sink that reads only the nutation angle of a sample is offered nothing else.
    let grid = match watched.first() {
        Some(w) if w.sink.reads_only_nutation() => GridObservation::NutationAngle,
        _ => GridObservation::Full,
    };
    let outcomes =
        integrate_runs_observed_with(engine, &runs, &settings, grid, &mut |k, step, rest| {
            let w = &mut watched[k];
            if interrupt.load(Ordering::Relaxed) {
                w.status = Some(Status::Interrupted);
                return false;
            }
            if step.restarted {
                // As the scalar loop tells its monitor after a restart at a breakpoint.
                w.monitor.restarted();
            }
            match w
                .monitor
                .after_step(&mut LaneView::new(step, rest), &mut w.sink)
            {
                Ok(None) => true,
                Ok(Some(status)) => {
                    w.status = Some(status);
                    false
                }
                Err(e) => {
                    w.status = Some(Status::Interrupted);
                    io_error.get_or_insert(e);
                    false
                }
            }
        });
    if let Some(e) = io_error {
        return Err(e);
    }
    for (w, outcome) in watched.into_iter().zip(outcomes) {
        let sim = sims[w.index];
        let status = match &outcome.status {
            LaneStatus::Declined { .. } => continue,
            LaneStatus::Complete | LaneStatus::Ended => w.status,
            LaneStatus::Failed(e) => Some(Status::Failed {
                diagnosis: diagnose(&e.to_string(), outcome.t, &outcome.y, sim),
            }),
        };
        let mut sink = w.sink;
        let (end, mut state) = LaneStep::at_end(&outcome);
        let result = w
            .monitor
            .finish(&LaneView::new(&end, &mut state), status, &mut sink)?;
        results[w.index] = Some((result, sink));
    }
    Ok(results)
}
