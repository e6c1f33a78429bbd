//! The lockstep ensemble (dopri5 or dop853, `lanes::methods`): W runs of one class integrated
//! at once, one per lane
//! ([`Lane`]), whatever the class ([`LaneRun`]: one run's parameters and start; its
//! [`LaneSystem`]: the runs' parameters in lanes, their right-hand side and observation).
//!
//! Each lane has its own initial state, parameters, end time, step size, error control,
//! accept/reject and work counters. Every lane evaluates every stage (lockstep, as
//! DiffEqGPU.jl's `EnsembleGPUKernel` does on GPUs: U. Utkarsh et al., "Automated translation
//! and accelerated solving of differential equations on multiple GPU platforms", Comput.
//! Methods Appl. Mech. Eng. 419 (2024) 116591); the decisions are taken per lane under masks.
//! A lane whose run has ended takes the next run. The arithmetic is the scalar path's, generic
//! over the lane (the method's stages, error estimate and controller in `integrate::dopri5`
//! and `integrate::dop853`; the class's right-hand side and observation, which its
//! [`LaneSystem`] writes with the scalar path's operations), so each lane's steps, rejections,
//! right-hand-side count and final state are bit for bit those of the scalar method on that
//! run's `Spacecraft`, stepped to the same end time. The engine knows no class: a class joins
//! the lanes by implementing the two traits ([`super::damper`], the nutation-damper class,
//! [`super::energy_sink`], a rigid body with an energy sink, and [`super::hinged_rods`], a hub
//! with four flap–lag rods).
//!
//! [`integrate_runs`] picks the engine at run time: eight f64 lanes compiled for AVX-512
//! where the processor has it ([`Engine::Avx512`]), else four compiled for AVX2
//! ([`Engine::Avx2`]), both asked through [`crate::cpu`], otherwise one lane
//! ([`Engine::Scalar`]). Everything an engine steps with is inlined into its one function,
//! compiled for its instruction set, except the right-hand side of a class that asks for it
//! out of line ([`LaneRun::RHS_OUT_OF_LINE`]): then each engine has one copy of it, compiled
//! for the same instruction set, where inlined it would be copied into every stage.
//! [`integrate_runs_observed`] also hands each accepted step of each lane ([`LaneStep`], with
//! the rest of it read out of the lanes on request: [`StepInLanes`]) to an observer that may
//! end the run: the campaigns' run monitor (samples, events,
//! invariants, checks) reads the lanes' steps through it (`polhode::sim`'s lane runs).
//!
//! A class whose runs have breakpoints ([`LaneRun::BREAKPOINTS`]) has each lane's steps end
//! exactly on its run's next breakpoint, as the scalar loop's do; there the lane restarts
//! before its next step (held states updated, first stage evaluated afresh, the step size
//! kept), while the other lanes step on.

use super::methods::{Dop853, Dopri5, LaneMethod, MethodFamily};
pub use super::methods::{LaneInterpolant, LaneMethodKind};
use super::{F64x4, Lane, LaneMask, linalg};
use crate::integrate::dopri5::{MAX_REJECTIONS, StageRhs, kept_proposal, non_finite_step_size};
use crate::integrate::{Stats, StepError, Tolerances, adaptive_step_end};

/// One run of a class the lanes integrate, whose state has `DIM` components (the scalar
/// `Spacecraft`'s layout for the class's scene).
pub trait LaneRun<const DIM: usize>: Sized {
    /// The class's runs in lanes of type `L`.
    type System<L: Lane>: LaneSystem<L, DIM, Self>;
    /// The state at t = 0.
    fn initial_state(&self) -> [f64; DIM];
    /// End time (s); the run starts at t = 0.
    fn t_end(&self) -> f64;
    /// Rate of the output grid k / `sample_rate` (Hz) on which an observed integration also
    /// hands the observer the state and its observation at the step's first grid time
    /// ([`LaneStep::sample`]); 0 (or not finite): none.
    fn sample_rate(&self) -> f64;
    /// Whether the lanes take the run at all; one they do not take ends at t = 0 as
    /// [`LaneStatus::Declined`]. Every run, unless the class says otherwise.
    fn admitted(&self) -> bool {
        true
    }
    /// Whether the stages call the class's right-hand side out of line (one copy per lane
    /// type, compiled for the engine's instruction set) rather than inlined into each stage:
    /// for a right-hand side long enough that a call costs nothing beside it, and whose
    /// fifteen-odd inlined copies per method and lane type would make the engines' code
    /// megabytes long and the build minutes longer.
    const RHS_OUT_OF_LINE: bool = false;
    /// Whether the class's runs may stop at breakpoints ([`LaneRun::next_stop`]); without
    /// them the engine does no breakpoint work at all.
    const BREAKPOINTS: bool = false;
    /// Where a step from `t` (s) must end at the latest: the run's first breakpoint after
    /// `t`, where its right-hand side jumps (merged with any a few ulps from it, as the scalar
    /// loop merges them: `sim::next_stop_of`), or its end time.
    fn next_stop(&self, _t: f64) -> f64 {
        self.t_end()
    }
    /// At the breakpoint `t` (s) the run has stopped on, its held states in `y` take their
    /// new values (the scalar `Spacecraft::at_breakpoint`).
    fn at_breakpoint(&self, _t: f64, _y: &mut [f64; DIM]) {}
}

/// The parameters of the runs of class `R` in the lanes, one run per lane, and what the
/// lanes compute from them. Both are written with the operations (and their order) of the
/// scalar path's code for the class, so that every lane's numbers are the scalar path's, bit
/// for bit.
pub trait LaneSystem<L: Lane, const DIM: usize, R> {
    /// Every lane empty (zero parameters).
    fn idle() -> Self;
    /// Puts `run`'s parameters into lane `i`.
    fn load(&mut self, i: usize, run: &R);
    /// The right-hand side at `y` (`DIM` components) into `dy`; returns the lanes whose
    /// closed form was solved (the others declined the state: [`LaneStatus::Declined`]).
    fn rhs(&self, y: &[L], dy: &mut [L]) -> L::Mask;
    /// The observation at `y`, as `Spacecraft::observe` forms it (the nutation angle's
    /// arctangent by [`super::elementary::half_plane_atan2`], the scalar path's too).
    fn observe(&self, y: &[L; DIM]) -> LaneObservation<L>;
    /// The state components the observation's nutation angle reads: the others may hold
    /// anything when only the nutation angle is read (a grid observation of
    /// [`GridObservation::NutationAngle`] interpolates only these).
    const NUTATION_READS: [bool; DIM] = [true; DIM];
}

/// The integration settings every run of a campaign shares (as the scalar `Dopri5::new` and
/// `Dop853::new` take them, with the first step chosen automatically).
#[derive(Debug, Clone, Copy)]
pub struct LaneSettings {
    /// The method.
    pub method: LaneMethodKind,
    /// Tolerances of the error control.
    pub tolerances: Tolerances,
    /// Largest step (s); `f64::INFINITY` for none.
    pub h_max: f64,
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum LaneStatus {
    /// Reached its end time.
    Complete,
    /// Failed as the scalar `Dopri5::step` would have (the same error).
    Failed(StepError),
    /// The class's closed form declined a state (for the nutation damper: a direction that is
    /// not a unit vector, a 3 × 3 system that is not positive definite, a non-finite state)
    /// at time `t` (s), or the run itself ([`LaneRun::admitted`], `t` = 0): the scalar path
    /// would have taken the general right-hand side there, which the lanes do not have.
    /// Integrate this run through the scalar path.
    Declined {
        /// Start of the step in which it happened (s).
        t: f64,
    },
    /// Ended by the observer of [`integrate_runs_observed`] after an accepted step (a
    /// terminal event, a failed check, an interrupt).
    Ended,
}

/// An accepted step of one lane, as [`integrate_runs_observed`] hands it to its observer: the
/// few numbers a run monitor reads at every step (the step's ends, its work, its drift, the
/// nutation angle at its end and at its first grid time). The rest (the state, the whole
/// observations, the dense output) stays in the lanes, read out for that lane only when asked
/// ([`StepInLanes`]).
#[derive(Debug, Clone, Default)]
pub struct LaneStep {
    /// Start of the step (s).
    pub t_prev: f64,
    /// End of the step (s).
    pub t: f64,
    /// Whether every component of the state at the end of the step is finite.
    pub finite: bool,
    /// Work so far: accepted and rejected steps, right-hand-side evaluations.
    pub stats: Stats,
    /// The nutation angle (rad) of the observation at the end of the step (of an observed
    /// integration).
    pub end_nutation_angle: f64,
    /// The kinetic energy (J) of that observation.
    pub end_kinetic_energy: f64,
    /// The run's drift at the end of the step from its start (of an observed integration).
    pub drift: LaneDrift,
    /// The first time of the run's output grid strictly inside the step, if there is one, with
    /// the nutation angle there (of an observed integration; the state and the whole
    /// observation there: [`StepInLanes::sample`]).
    pub sample: Option<GridAngle>,
    /// The later times of the run's output grid strictly inside the step, in order, with the
    /// nutation angle at each (of an observed integration whose grid observation is
    /// [`GridObservation::NutationAngle`]; empty otherwise).
    pub later_samples: Vec<GridAngle>,
    /// Whether the run restarted at a breakpoint before this step (its held states updated,
    /// its first stage evaluated afresh), as the scalar loop's `Stepper::restart` does.
    pub restarted: bool,
}

/// What an observed integration computes at the output grid time inside a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GridObservation {
    /// The state there and its whole observation ([`StepInLanes::sample`]).
    Full,
    /// The nutation angle alone ([`LaneStep::sample`]), for an observer that reads nothing
    /// else there; [`StepInLanes::sample`] is `None`. The operations are [`Full`]'s (the
    /// compiler drops what the angle does not need), so the angle is the same.
    ///
    /// [`Full`]: GridObservation::Full
    NutationAngle,
}

/// A time of a run's output grid and the nutation angle there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridAngle {
    /// The grid time (s): k / `sample_rate`.
    pub t: f64,
    /// The nutation angle there (rad).
    pub nutation_angle: f64,
}

/// The state at one time of the output grid inside a step, from the step's dense output (as
/// [`LaneInterpolant::value`] gives it), and its observation.
#[derive(Debug, Clone, Copy)]
pub struct LaneSample<const DIM: usize> {
    /// The grid time (s): k / `sample_rate`.
    pub t: f64,
    /// The state there.
    pub y: [f64; DIM],
    /// Its observation.
    pub observation: LaneObservation,
}

/// What the run monitor observes of a lane's state, computed in the lanes with the operations
/// of `Spacecraft::observe` for the run's class ([`LaneSystem::observe`]), so that each value
/// is bit for bit the scalar observation's (the rest of the observation is formed from these per lane). `T` is one
/// value ([`f64`]) or one per lane.
#[derive(Debug, Clone, Copy, Default)]
pub struct LaneObservation<T = f64> {
    /// Attitude, the state's quaternion divided by its norm (w, x, y, z).
    pub attitude: [T; 4],
    /// `|q| − 1`.
    pub q_norm_error: T,
    /// Angular momentum about the system's centre of mass, body axes (N m s).
    pub h_body: [T; 3],
    /// The same in inertial axes (N m s).
    pub h_inertial: [T; 3],
    /// Kinetic energy (J).
    pub kinetic_energy: T,
    /// The effectors' elastic energy (J).
    pub elastic_energy: T,
    /// Energy the effectors have dissipated (J).
    pub dissipated_energy: T,
    /// The effectors' dissipation rate (W).
    pub dissipation_power: T,
    /// The work done on the spacecraft from outside its energy account (J): a motor's
    /// (`EnergyAccount::work`).
    pub external_work: T,
    /// |H| (N m s), nalgebra's norm of `h_body`.
    pub h_norm: T,
    /// The nutation angle (rad), between the spin axis a and H, from |a × H| and a · H, as
    /// `observe::angle_between` forms it (the arctangent in the lanes:
    /// [`crate::lanes::elementary::half_plane_atan2`]).
    pub nutation_angle: T,
}

/// Asserts that lane `i` of the lanes' observation `o` is the scalar observation `s`, bit for
/// bit: H in both frames, the energies, |q| − 1, |H|, the nutation angle and the attitude.
#[cfg(test)]
pub(crate) fn assert_lane_is_observation(
    o: &LaneObservation<super::F64x4>,
    i: usize,
    s: &crate::model::Observation,
) {
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let lane = |v: super::F64x4| v.lane(i);
    assert_eq!(
        bits(&o.h_body.map(lane)),
        bits(s.h_body.as_slice()),
        "H, lane {i}"
    );
    assert_eq!(bits(&o.h_inertial.map(lane)), bits(s.h_inertial.as_slice()));
    let scalars = [
        (o.kinetic_energy, s.kinetic_energy),
        (o.elastic_energy, s.elastic_energy),
        (o.dissipated_energy, s.dissipated_energy),
        (o.dissipation_power, s.dissipation_power),
        (o.external_work, s.external_work),
        (o.q_norm_error, s.q_norm_error),
        (o.h_norm, s.h_norm),
        (o.nutation_angle, s.nutation_angle),
    ];
    for (k, (a, b)) in scalars.into_iter().enumerate() {
        assert_eq!(a.lane(i).to_bits(), b.to_bits(), "quantity {k}, lane {i}");
    }
    let q = s.attitude.quaternion();
    let attitude = o.attitude.map(lane);
    assert_eq!(
        bits(&attitude),
        bits(&[q.w, q.i, q.j, q.k]),
        "attitude, lane {i}"
    );
}

/// Asserts that the right-hand side and observation of `system` (four runs of class `R`
/// loaded) at the states `states` are each lane's scalar `Spacecraft` (`spacecraft[i]`) bit
/// for bit, every lane solved; `case` names the states in a failure.
#[cfg(test)]
pub(crate) fn assert_lanes_are_the_spacecrafts<R: LaneRun<DIM>, const DIM: usize>(
    system: &R::System<F64x4>,
    spacecraft: &[&crate::model::Spacecraft],
    states: &[[f64; DIM]],
    case: &str,
) {
    use crate::integrate::OdeSystem;
    let y: [F64x4; DIM] = std::array::from_fn(|j| F64x4(std::array::from_fn(|i| states[i][j])));
    let mut dy = [F64x4::splat(0.0); DIM];
    let solved = system.rhs(&y, &mut dy);
    let o = system.observe(&y);
    for (i, sc) in spacecraft.iter().enumerate() {
        assert!(solved.test(i), "solved, {case}, lane {i}");
        let mut expected = [0.0; DIM];
        sc.rhs(0.0, &states[i], &mut expected);
        let got: [f64; DIM] = std::array::from_fn(|j| dy[j].lane(i));
        assert_eq!(
            got.map(f64::to_bits),
            expected.map(f64::to_bits),
            "rhs, {case}, lane {i}"
        );
        assert_lane_is_observation(&o, i, &sc.observe(0.0, &states[i]));
    }
    // The components the nutation angle does not read (`NUTATION_READS`) may hold anything:
    // with them not a number, its bits are the same.
    let reads = <R::System<F64x4> as LaneSystem<F64x4, DIM, R>>::NUTATION_READS;
    let mut masked = y;
    for (m, &read) in masked.iter_mut().zip(&reads) {
        if !read {
            *m = F64x4::splat(f64::NAN);
        }
    }
    let angle = system.observe(&masked).nutation_angle;
    for i in 0..spacecraft.len() {
        assert_eq!(
            angle.lane(i).to_bits(),
            o.nutation_angle.lane(i).to_bits(),
            "nutation angle from the components it reads, {case}, lane {i}"
        );
    }
}

impl<L: Lane> LaneObservation<L> {
    /// The observation of a hub whose integrated quaternion is `q` (w, x, y, z; not yet of
    /// unit norm) and whose system has angular momentum `h` (body axes, N m s), with the
    /// energies `[kinetic, elastic, dissipated, dissipation power, external work]` (J, J, J,
    /// W, J), the nutation
    /// angle measured from `spin_axis` (body axes, unit), with the operations of
    /// `observe::invariants` and `Observation::from_invariants`: nalgebra's 4-vector norm
    /// `(x² + z²) + (y² + w²)`, its rotation `(2 (u × h) w + u × t) + h`, its 3-vector norm,
    /// and the arctangent of [`super::elementary::half_plane_atan2`].
    #[inline(always)]
    pub fn of_hub(q: [L; 4], h: [L; 3], energies: [L; 5], spin_axis: [L; 3]) -> Self {
        use linalg::cross;
        let [qw, qi, qj, qk] = q;
        let q_norm = ((qi * qi + qk * qk) + (qj * qj + qw * qw)).sqrt();
        let attitude = [qw / q_norm, qi / q_norm, qj / q_norm, qk / q_norm];
        let axis = [attitude[1], attitude[2], attitude[3]];
        let two = L::splat(2.0);
        let t = cross(axis, h);
        let t = [t[0] * two, t[1] * two, t[2] * two];
        let ut = cross(axis, t);
        let h_inertial: [L; 3] = linalg::each3(|k| t[k] * attitude[0] + ut[k] + h[k]);
        let [
            kinetic_energy,
            elastic_energy,
            dissipated_energy,
            dissipation_power,
            external_work,
        ] = energies;
        let a = spin_axis;
        LaneObservation {
            attitude,
            q_norm_error: q_norm - L::splat(1.0),
            h_body: h,
            h_inertial,
            kinetic_energy,
            elastic_energy,
            dissipated_energy,
            dissipation_power,
            external_work,
            h_norm: linalg::norm(h),
            nutation_angle: super::elementary::half_plane_atan2(
                linalg::norm(cross(a, h)),
                linalg::dot(a, h),
            ),
        }
    }

    /// Lane `i`'s values.
    #[inline(always)]
    fn lane(&self, i: usize) -> LaneObservation {
        let mut o = LaneObservation {
            q_norm_error: read(&self.q_norm_error, i),
            kinetic_energy: read(&self.kinetic_energy, i),
            elastic_energy: read(&self.elastic_energy, i),
            dissipated_energy: read(&self.dissipated_energy, i),
            dissipation_power: read(&self.dissipation_power, i),
            external_work: read(&self.external_work, i),
            h_norm: read(&self.h_norm, i),
            nutation_angle: read(&self.nutation_angle, i),
            ..LaneObservation::default()
        };
        L::gather_lane(&self.attitude, i, &mut o.attitude);
        L::gather_lane(&self.h_body, i, &mut o.h_body);
        L::gather_lane(&self.h_inertial, i, &mut o.h_inertial);
        o
    }
}

/// A run's drift at a state from its start (t = 0), computed in the lanes with the operations
/// (and their order) of the run monitor's drift check (`sim::Reference`), so that each term is
/// bit for bit the scalar path's: |H₀| is the body-frame |H| at t = 0 (nalgebra's norm,
/// `√(0 + ((x² + y²) + z²))`), E is kinetic + elastic + dissipated energy less the external
/// work, and no class carries momentum out (the scalar sum adds its zeros). `T` is one value
/// ([`f64`]) or one per lane.
#[derive(Debug, Clone, Copy, Default)]
pub struct LaneDrift<T = f64> {
    /// |(|H_N| − |H₀|)| / |H₀| (|H₀| = 0: not divided).
    pub h_norm_rel: T,
    /// |H_N − H_N₀| / |H₀|.
    pub h_inertial_rel: T,
    /// |E − E₀| / E₀ (E₀ = 0: not divided).
    pub energy_rel: T,
    /// ||q| − 1|.
    pub q_norm: T,
}

impl<L: Lane> LaneDrift<L> {
    /// Lane `i`'s terms.
    #[inline(always)]
    fn lane(&self, i: usize) -> LaneDrift {
        LaneDrift {
            h_norm_rel: read(&self.h_norm_rel, i),
            h_inertial_rel: read(&self.h_inertial_rel, i),
            energy_rel: read(&self.energy_rel, i),
            q_norm: read(&self.q_norm, i),
        }
    }
}

/// What the drift is measured against, per lane: the observation at t = 0.
#[derive(Debug, Clone, Copy)]
struct DriftReference<L: Lane> {
    /// |H| at t = 0, body axes (N m s).
    h0: L,
    /// H at t = 0, inertial axes (N m s).
    h_inertial0: [L; 3],
    /// The energy balance at t = 0 (J).
    e0: L,
}

/// `d / reference`, or `d` where the reference is zero (the monitor's `rel`).
#[inline(always)]
fn relative<L: Lane>(d: L, reference: L) -> L {
    L::select(!reference.equals(L::splat(0.0)), d / reference, d)
}

impl<L: Lane> LaneObservation<L> {
    /// The energy balance, kinetic + elastic + dissipated − external work, in the order of
    /// `Invariants::energy_balance`.
    #[inline(always)]
    fn energy_balance(&self) -> L {
        self.kinetic_energy + self.elastic_energy + self.dissipated_energy - self.external_work
    }

    /// H_N plus the (zero) momentum carried out, as the monitor audits it.
    #[inline(always)]
    fn h_audited(&self) -> [L; 3] {
        linalg::add(self.h_inertial, [L::splat(0.0); 3])
    }

    /// What the drift of later states is measured against, this being the state at t = 0.
    #[inline(always)]
    fn drift_reference(&self) -> DriftReference<L> {
        DriftReference {
            h0: linalg::norm(self.h_body),
            h_inertial0: self.h_inertial,
            e0: self.energy_balance(),
        }
    }

    /// The drift at this state from `reference`, as the monitor's check computes it.
    #[inline(always)]
    fn drift(&self, reference: &DriftReference<L>) -> LaneDrift<L> {
        let r = reference;
        let h = self.h_audited();
        LaneDrift {
            h_norm_rel: relative(linalg::norm(h) - r.h0, r.h0).abs(),
            h_inertial_rel: relative(linalg::norm(linalg::sub(h, r.h_inertial0)), r.h0),
            energy_rel: relative(self.energy_balance() - r.e0, r.e0).abs(),
            q_norm: self.q_norm_error.abs(),
        }
    }
}

/// The rest of the step a lane has just accepted ([`LaneStep`]), still in the lanes: read out
/// of them for that lane only when asked, since a run monitor rarely needs more than the
/// step hands it (copying it all out at every step cost a tenth of a campaign).
pub trait StepInLanes<const DIM: usize> {
    /// The state at the end of the step (the class's layout, [`LaneRun::initial_state`]), into `out`.
    fn state(&self, out: &mut [f64; DIM]);
    /// The observation at the end of the step (of an observed integration).
    fn end(&self) -> LaneObservation;
    /// The step's first grid time strictly inside it, if there is one, with the state there
    /// and its observation (of an observed integration).
    fn sample(&self) -> Option<LaneSample<DIM>>;
    /// Makes the step's dense output available (dop853's dense stages, evaluated and counted
    /// as the scalar `Dop853::prepare_interpolation` does); false where it is not finite.
    fn prepare_interpolation(&mut self) -> bool;
    /// The step's dense output, as the scalar method forms it (prepared first).
    fn interpolant(&self) -> LaneInterpolant<DIM>;
}

/// Lane `i` of `value`, read where it lies (a method called outside the engine's compiled
/// instruction set may not hold the lane type in a register).
#[inline(always)]
fn read<L: Lane>(value: &L, i: usize) -> f64 {
    let mut x = [0.0];
    L::gather_lane(std::slice::from_ref(value), i, &mut x);
    x[0]
}

/// Lane `lane`'s step in the lanes.
struct LaneRest<'a, L: Lane, R: LaneRun<DIM>, M: LaneMethod<L, DIM>, const DIM: usize> {
    lanes: &'a mut Lanes<L, R, M, DIM>,
    lane: usize,
}

impl<L: Lane, R: LaneRun<DIM>, M: LaneMethod<L, DIM>, const DIM: usize> StepInLanes<DIM>
    for LaneRest<'_, L, R, M, DIM>
{
    fn state(&self, out: &mut [f64; DIM]) {
        L::gather_lane(&self.lanes.y, self.lane, out);
    }
    fn end(&self) -> LaneObservation {
        self.lanes
            .end
            .as_ref()
            .map_or_else(LaneObservation::default, |e| e.lane(self.lane))
    }
    fn sample(&self) -> Option<LaneSample<DIM>> {
        let i = self.lane;
        match &self.lanes.sample {
            Some(SampleLanes {
                due,
                t,
                full: Some((y, observation)),
                ..
            }) if due.test(i) => {
                let mut sample = LaneSample {
                    t: read(t, i),
                    y: [0.0; DIM],
                    observation: observation.lane(i),
                };
                L::gather_lane(y, i, &mut sample.y);
                Some(sample)
            }
            _ => None,
        }
    }
    fn prepare_interpolation(&mut self) -> bool {
        let i = self.lane;
        let needed = L::Mask::splat(false).with_lane(i, true);
        // Called by the monitor, outside the engine: compiled for the engine's instruction set
        // again, or the eight lanes' operations would be calls (the stages are a system's
        // right-hand side three times).
        #[cfg(target_arch = "x86_64")]
        if L::WIDTH == 8 {
            // SAFETY: eight lanes are made only where the processor has AVX-512F (`f64x8`).
            unsafe { prepare_dense_avx512(self.lanes, needed) };
            return self.lanes.dense_finite.test(i);
        } else if L::WIDTH == 4 && crate::cpu::avx2_available() {
            // SAFETY: the processor has AVX2.
            unsafe { prepare_dense_avx2(self.lanes, needed) };
            return self.lanes.dense_finite.test(i);
        }
        self.lanes.prepare_dense(needed);
        self.lanes.dense_finite.test(i)
    }
    fn interpolant(&self) -> LaneInterpolant<DIM> {
        // The scalar method's arithmetic on this lane's stages (the lanes' arithmetic is the
        // same, lane by lane).
        let (lanes, i) = (&*self.lanes, self.lane);
        let (mut y_start, mut y_new) = ([0.0; DIM], [0.0; DIM]);
        L::gather_lane(&lanes.y_start, i, &mut y_start);
        L::gather_lane(&lanes.y_new, i, &mut y_new);
        lanes
            .method
            .interpolant(i, read(&lanes.h_step, i), &y_start, &y_new)
    }
}

/// [`Lanes::prepare_dense`] compiled for AVX-512F (the eight lanes' intrinsics inline).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn prepare_dense_avx512<
    L: Lane,
    R: LaneRun<DIM>,
    M: LaneMethod<L, DIM>,
    const DIM: usize,
>(
    lanes: &mut Lanes<L, R, M, DIM>,
    needed: L::Mask,
) {
    lanes.prepare_dense(needed)
}

/// [`Lanes::prepare_dense`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn prepare_dense_avx2<L: Lane, R: LaneRun<DIM>, M: LaneMethod<L, DIM>, const DIM: usize>(
    lanes: &mut Lanes<L, R, M, DIM>,
    needed: L::Mask,
) {
    lanes.prepare_dense(needed)
}

/// A run's state where it stands, with no step in the lanes: at its start, or at its end
/// ([`LaneStep::at_end`]). There is nothing to interpolate in (`t_prev = t`).
#[derive(Debug, Clone)]
pub struct Settled<const DIM: usize>(pub [f64; DIM]);

impl<const DIM: usize> StepInLanes<DIM> for Settled<DIM> {
    fn state(&self, out: &mut [f64; DIM]) {
        *out = self.0;
    }
    fn end(&self) -> LaneObservation {
        LaneObservation::default()
    }
    fn sample(&self) -> Option<LaneSample<DIM>> {
        None
    }
    fn prepare_interpolation(&mut self) -> bool {
        true
    }
    fn interpolant(&self) -> LaneInterpolant<DIM> {
        // Read at the step's ends only (it has no interior).
        LaneInterpolant::Dopri5([[0.0; DIM]; 5])
    }
}

impl LaneStep {
    /// The step view of a run standing at `t` (s) in state `y` after the work `stats`, with
    /// its state: no step to interpolate in.
    pub fn settled<const DIM: usize>(t: f64, y: [f64; DIM], stats: Stats) -> (Self, Settled<DIM>) {
        let step = LaneStep {
            t_prev: t,
            t,
            finite: y.iter().all(|v| v.is_finite()),
            stats,
            ..LaneStep::default()
        };
        (step, Settled(y))
    }

    /// [`LaneStep::settled`] at a run's end (`outcome`).
    pub fn at_end<const DIM: usize>(outcome: &LaneOutcome<DIM>) -> (Self, Settled<DIM>) {
        Self::settled(outcome.t, outcome.y, outcome.stats)
    }
}

/// What a run ended with.
#[derive(Debug, Clone, PartialEq)]
pub struct LaneOutcome<const DIM: usize> {
    /// How it ended.
    pub status: LaneStatus,
    /// Time reached (s).
    pub t: f64,
    /// State reached (the class's layout).
    pub y: [f64; DIM],
    /// Work: accepted and rejected steps, right-hand-side evaluations (the rest zero).
    pub stats: Stats,
}

/// What [`integrate_runs_observed`] calls after each accepted step of a run: `(run, step,
/// rest)`, the run's index, its step and the rest of the step in the lanes; false ends the
/// run there.
pub type Observer<'o, const DIM: usize> =
    &'o mut dyn FnMut(usize, &LaneStep, &mut dyn StepInLanes<DIM>) -> bool;

/// Which compiled engine runs the lanes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Engine {
    /// The widest the processor has: [`Engine::Avx512`], else [`Engine::Avx2`], else
    /// [`Engine::Scalar`].
    Auto,
    /// One lane (`f64`): the same lockstep code at width 1.
    Scalar,
    /// Four lanes ([`F64x4`]) compiled for the baseline target (SSE2 on x86-64): for
    /// comparison only.
    Portable4,
    /// Four lanes compiled for AVX2; falls back to [`Engine::Scalar`] on a processor
    /// without it.
    Avx2,
    /// Eight lanes in AVX-512 registers (intrinsics, x86-64 only); falls back to
    /// [`Engine::Avx2`] (and on to [`Engine::Scalar`]) on a processor without it.
    Avx512,
}

impl Engine {
    /// Runs integrated at once on one thread.
    pub fn width(self) -> usize {
        match resolved(self) {
            Engine::Portable4 | Engine::Avx2 => 4,
            Engine::Avx512 => 8,
            _ => 1,
        }
    }
}

/// Integrates every run to its end time with the engine chosen at run time
/// ([`Engine::Auto`]); the outcomes are in the order of `runs`.
pub fn integrate_runs<R: LaneRun<DIM>, const DIM: usize>(
    runs: &[R],
    settings: &LaneSettings,
) -> Vec<LaneOutcome<DIM>> {
    integrate_runs_with(Engine::Auto, runs, settings)
}

/// [`integrate_runs`] with a given engine.
pub fn integrate_runs_with<R: LaneRun<DIM>, const DIM: usize>(
    engine: Engine,
    runs: &[R],
    settings: &LaneSettings,
) -> Vec<LaneOutcome<DIM>> {
    run_engine(engine, runs, settings, None)
}

/// [`integrate_runs`], handing every accepted step of every run to `observe(run, step)` (the
/// run's index in `runs`), with what `grid` asks at its output grid; when it returns false,
/// the run ends there with [`LaneStatus::Ended`].
pub fn integrate_runs_observed<R: LaneRun<DIM>, const DIM: usize>(
    runs: &[R],
    settings: &LaneSettings,
    grid: GridObservation,
    observe: Observer<'_, DIM>,
) -> Vec<LaneOutcome<DIM>> {
    run_engine(Engine::Auto, runs, settings, Some((grid, observe)))
}

/// [`integrate_runs_observed`] with a given engine.
pub fn integrate_runs_observed_with<R: LaneRun<DIM>, const DIM: usize>(
    engine: Engine,
    runs: &[R],
    settings: &LaneSettings,
    grid: GridObservation,
    observe: Observer<'_, DIM>,
) -> Vec<LaneOutcome<DIM>> {
    run_engine(engine, runs, settings, Some((grid, observe)))
}

/// An observer and what it reads at the output grid.
type Observing<'o, const DIM: usize> = Option<(GridObservation, Observer<'o, DIM>)>;

/// The engine actually run for `engine` on this processor.
pub fn resolved(engine: Engine) -> Engine {
    use crate::cpu::{avx2_available, avx512_available};
    match engine {
        Engine::Auto | Engine::Avx512 if avx512_available() => Engine::Avx512,
        Engine::Auto | Engine::Avx512 | Engine::Avx2 if avx2_available() => Engine::Avx2,
        Engine::Auto | Engine::Avx512 | Engine::Avx2 => Engine::Scalar,
        e => e,
    }
}

fn run_engine<R: LaneRun<DIM>, const DIM: usize>(
    engine: Engine,
    runs: &[R],
    settings: &LaneSettings,
    observe: Observing<'_, DIM>,
) -> Vec<LaneOutcome<DIM>> {
    match settings.method {
        LaneMethodKind::Dopri5 => run_method::<R, Dopri5, DIM>(engine, runs, settings, observe),
        LaneMethodKind::Dop853 => run_method::<R, Dop853, DIM>(engine, runs, settings, observe),
    }
}

fn run_method<R: LaneRun<DIM>, F: MethodFamily, const DIM: usize>(
    engine: Engine,
    runs: &[R],
    settings: &LaneSettings,
    observe: Observing<'_, DIM>,
) -> Vec<LaneOutcome<DIM>> {
    match resolved(engine) {
        Engine::Portable4 => {
            lockstep::<F64x4, R, F, DIM>(runs, settings, observe, rhs_baseline::<F64x4, R, DIM>)
        }
        #[cfg(target_arch = "x86_64")]
        Engine::Avx2 => {
            // SAFETY: `resolved` chose AVX2 only where the processor has it.
            unsafe { lockstep_avx2::<R, F, DIM>(runs, settings, observe) }
        }
        #[cfg(target_arch = "x86_64")]
        Engine::Avx512 => {
            // SAFETY: `resolved` chose AVX-512F only where the processor has it.
            unsafe { lockstep_avx512::<R, F, DIM>(runs, settings, observe) }
        }
        _ => lockstep::<f64, R, F, DIM>(runs, settings, observe, rhs_baseline::<f64, R, DIM>),
    }
}

/// [`lockstep`] at four lanes, compiled for AVX2 and FMA (everything below is inlined into
/// it). Only a written `mul_add` is fused, as the scalar path fuses it: the bits are the
/// scalar path's.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn lockstep_avx2<R: LaneRun<DIM>, F: MethodFamily, const DIM: usize>(
    runs: &[R],
    settings: &LaneSettings,
    observe: Observing<'_, DIM>,
) -> Vec<LaneOutcome<DIM>> {
    lockstep::<F64x4, R, F, DIM>(runs, settings, observe, rhs_avx2::<R, DIM>)
}

/// [`lockstep`] at eight lanes, compiled for AVX-512F so that the lane type's intrinsics
/// inline into it: one 512-bit instruction per element-wise operation. Only a written
/// `mul_add` is fused (`vfmadd`, as the scalar path fuses it; Rust contracts nothing else):
/// the bits are the scalar path's.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn lockstep_avx512<R: LaneRun<DIM>, F: MethodFamily, const DIM: usize>(
    runs: &[R],
    settings: &LaneSettings,
    observe: Observing<'_, DIM>,
) -> Vec<LaneOutcome<DIM>> {
    lockstep::<super::f64x8::F64x8, R, F, DIM>(runs, settings, observe, rhs_avx512::<R, DIM>)
}

/// A class's right-hand side ([`LaneSystem::rhs`]) in a function of its own, compiled for the
/// engine's instruction set: what the stages call for a class with
/// [`LaneRun::RHS_OUT_OF_LINE`]. Unsafe to call only in that an engine's copy may be made for
/// an instruction set the processor must have; each engine makes its own.
type CompiledRhs<L, R, const DIM: usize> =
    unsafe fn(&<R as LaneRun<DIM>>::System<L>, &[L], &mut [L]) -> <L as Lane>::Mask;

/// [`LaneSystem::rhs`] out of line, compiled for the baseline instruction set (the scalar
/// engine and the portable four lanes).
#[inline(never)]
fn rhs_baseline<L: Lane, R: LaneRun<DIM>, const DIM: usize>(
    system: &R::System<L>,
    y: &[L],
    dy: &mut [L],
) -> L::Mask {
    system.rhs(y, dy)
}

/// [`LaneSystem::rhs`] out of line at four lanes, compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline(never)]
unsafe fn rhs_avx2<R: LaneRun<DIM>, const DIM: usize>(
    system: &R::System<F64x4>,
    y: &[F64x4],
    dy: &mut [F64x4],
) -> <F64x4 as Lane>::Mask {
    system.rhs(y, dy)
}

/// [`LaneSystem::rhs`] out of line at eight lanes, compiled for AVX-512F.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
#[inline(never)]
unsafe fn rhs_avx512<R: LaneRun<DIM>, const DIM: usize>(
    system: &R::System<super::f64x8::F64x8>,
    y: &[super::f64x8::F64x8],
    dy: &mut [super::f64x8::F64x8],
) -> <super::f64x8::F64x8 as Lane>::Mask {
    system.rhs(y, dy)
}

/// The system as the stages' right-hand side, noting the lanes whose closed form was solved
/// at every stage.
struct Solving<'a, L: Lane, R: LaneRun<DIM>, const DIM: usize> {
    system: &'a R::System<L>,
    /// The engine's out-of-line copy of the right-hand side.
    compiled: CompiledRhs<L, R, DIM>,
    solved: L::Mask,
}

impl<'a, L: Lane, R: LaneRun<DIM>, const DIM: usize> Solving<'a, L, R, DIM> {
    /// `system`'s right-hand side as the stages call it (`compiled`: the engine's copy), no
    /// lane declined yet.
    #[inline(always)]
    fn new(system: &'a R::System<L>, compiled: CompiledRhs<L, R, DIM>) -> Self {
        Solving {
            system,
            compiled,
            solved: L::Mask::splat(true),
        }
    }

    /// The right-hand side at `y` into `dydt`: inlined, or the engine's copy out of line
    /// ([`LaneRun::RHS_OUT_OF_LINE`]); the lanes whose closed form was solved.
    #[inline(always)]
    fn call(&self, y: &[L], dydt: &mut [L]) -> L::Mask {
        if R::RHS_OUT_OF_LINE {
            // SAFETY: `compiled` is the copy the running engine made for its own instruction
            // set, which the processor has (`run_method`).
            unsafe { (self.compiled)(self.system, y, dydt) }
        } else {
            self.system.rhs(y, dydt)
        }
    }
}

impl<L: Lane, R: LaneRun<DIM>, const DIM: usize> StageRhs<L> for Solving<'_, L, R, DIM> {
    #[inline(always)]
    fn eval(&mut self, _t: L, y: &[L], dydt: &mut [L]) {
        self.solved = self.solved & self.call(y, dydt);
    }
}

/// [`LaneSample`] in lanes, for the lanes of `due`: the nutation angle, and the state and
/// its whole observation where the grid observation is [`GridObservation::Full`].
struct SampleLanes<L: Lane, const DIM: usize> {
    due: L::Mask,
    t: L,
    nutation_angle: L,
    full: Option<([L; DIM], LaneObservation<L>)>,
}

/// The lanes' integration state: each field holds one value per lane.
struct Lanes<L: Lane, R: LaneRun<DIM>, M: LaneMethod<L, DIM>, const DIM: usize> {
    system: R::System<L>,
    /// The running engine's out-of-line copy of the system's right-hand side.
    compiled_rhs: CompiledRhs<L, R, DIM>,
    /// The method's stages.
    method: M,
    /// The shared settings, splat.
    atol: L,
    rtol: L,
    h_max: L,
    t: L,
    /// Start of the last accepted step (s), when observed.
    t_prev: L,
    t_end: L,
    /// Where the next step must end at the latest: the run's next breakpoint, or `t_end`
    /// ([`LaneRun::next_stop`]).
    t_stop: L,
    /// The lanes whose last accepted step ended on a breakpoint, to restart before their
    /// next step ([`Lanes::restart_at_breakpoints`]).
    on_breakpoint: L::Mask,
    /// The lanes that restarted at a breakpoint since their last accepted step.
    restarted: L::Mask,
    /// The controller's proposal (s).
    h: L,
    fac_old: L,
    y: [L; DIM],
    y_new: [L; DIM],
    stage: [L; DIM],
    /// The state at the start of the last attempted step and its size (s), when observed:
    /// with the method's stages and `y_new`, what its dense output is formed of (only where
    /// it is read: [`Lanes::sample_inside`], [`LaneRest`]).
    y_start: [L; DIM],
    h_step: L,
    /// The lanes whose last step's dense stages are evaluated (all, for a method whose dense
    /// output needs none), and those where they came out finite.
    dense_ready: L::Mask,
    dense_finite: L::Mask,
    /// The observation at the end of the last accepted step, when observed, and the drift
    /// there from each run's start.
    end: Option<LaneObservation<L>>,
    drift: Option<LaneDrift<L>>,
    /// What each run's drift is measured against (its observation at t = 0), when observed.
    reference: Option<DriftReference<L>>,
    /// Each run's output grid (Hz; 0: none) and the index k of its next grid time
    /// k / rate after the last accepted step's end, when observed.
    sample_rate: L,
    next_sample: L,
    /// The lanes whose last accepted step holds a grid time strictly inside it, with that
    /// time, the state there and its observation, when observed.
    sample: Option<SampleLanes<L, DIM>>,
    /// The later grid times strictly inside the last accepted step, one entry per further
    /// time: the lanes that have it, the time and the nutation angle there (with
    /// [`GridObservation::NutationAngle`]).
    later: Vec<(L::Mask, L, L)>,
    /// Work counters, as exact integers in f64.
    steps: L,
    rejected: L,
    rhs_evaluations: L,
    rejected_in_a_row: L,
    saw_non_finite: L::Mask,
    /// Lanes holding a run that is still stepping.
    running: L::Mask,
    /// What an observed integration computes at the output grid.
    grid: GridObservation,
    /// Lanes that ended in the last phase, with their status, to be collected.
    ended: Vec<(usize, LaneStatus)>,
}

impl<L: Lane, R: LaneRun<DIM>, M: LaneMethod<L, DIM>, const DIM: usize> Lanes<L, R, M, DIM> {
    /// Every lane empty, holding `run`'s values (finite, so that idle lanes compute harmless
    /// numbers).
    #[inline(always)]
    fn new(run: &R, settings: &LaneSettings, compiled_rhs: CompiledRhs<L, R, DIM>) -> Self {
        let z = L::splat(0.0);
        let mut lanes = Lanes {
            system: R::System::<L>::idle(),
            compiled_rhs,
            method: M::zeroed(),
            atol: L::splat(settings.tolerances.atol),
            rtol: L::splat(settings.tolerances.rtol),
            h_max: L::splat(settings.h_max),
            t: z,
            t_prev: z,
            t_end: z,
            t_stop: z,
            on_breakpoint: L::Mask::splat(false),
            restarted: L::Mask::splat(false),
            h: z,
            fac_old: z,
            y: [z; DIM],
            y_new: [z; DIM],
            stage: [z; DIM],
            y_start: [z; DIM],
            h_step: z,
            dense_ready: L::Mask::splat(true),
            dense_finite: L::Mask::splat(true),
            end: None,
            drift: None,
            reference: None,
            sample_rate: z,
            next_sample: z,
            sample: None,
            later: Vec::new(),
            steps: z,
            rejected: z,
            rhs_evaluations: z,
            rejected_in_a_row: z,
            saw_non_finite: L::Mask::splat(false),
            running: L::Mask::splat(false),
            grid: GridObservation::Full,
            ended: Vec::with_capacity(L::WIDTH),
        };
        for i in 0..L::WIDTH {
            lanes.load(i, run);
        }
        lanes.running = L::Mask::splat(false);
        lanes
    }

    /// Puts `run` into lane `i`, at its start.
    #[inline(always)]
    fn load(&mut self, i: usize, run: &R) {
        let set = |x: &mut L, v: f64| *x = x.with_lane(i, v);
        self.system.load(i, run);
        for (j, &v) in run.initial_state().iter().enumerate() {
            set(&mut self.y[j], v);
        }
        set(&mut self.t, 0.0);
        set(&mut self.t_end, run.t_end());
        set(&mut self.t_stop, run.next_stop(0.0));
        self.on_breakpoint = self.on_breakpoint.with_lane(i, false);
        self.restarted = self.restarted.with_lane(i, false);
        // Finite and non-negative, or no grid.
        let rate = run.sample_rate();
        let rate = if rate > 0.0 && rate.is_finite() {
            rate
        } else {
            0.0
        };
        set(&mut self.sample_rate, rate);
        // The monitor samples t = 0 itself at the start.
        set(&mut self.next_sample, 1.0);
        set(&mut self.h, 0.0);
        set(&mut self.fac_old, 1e-4);
        set(&mut self.steps, 0.0);
        set(&mut self.rejected, 0.0);
        set(&mut self.rhs_evaluations, 0.0);
        set(&mut self.rejected_in_a_row, 0.0);
        self.saw_non_finite = self.saw_non_finite.with_lane(i, false);
        self.running = self.running.with_lane(i, true);
    }

    /// Lane `i`'s outcome with `status`.
    fn outcome(&self, i: usize, status: LaneStatus) -> LaneOutcome<DIM> {
        LaneOutcome {
            status,
            t: self.t.lane(i),
            y: std::array::from_fn(|j| self.y[j].lane(i)),
            stats: Stats {
                steps: self.steps.lane(i) as u64,
                rejected_steps: self.rejected.lane(i) as u64,
                rhs_evaluations: self.rhs_evaluations.lane(i) as u64,
                ..Stats::default()
            },
        }
    }

    /// Lane `i`'s last accepted step (of an observed integration), into `step`: the numbers
    /// read at every step, the rest left in the lanes ([`LaneRest`]); `finite` holds the lanes
    /// whose every state component is finite.
    #[inline(always)]
    fn step_of(&self, i: usize, finite: L::Mask, step: &mut LaneStep) {
        step.t_prev = read(&self.t_prev, i);
        step.t = read(&self.t, i);
        step.finite = finite.test(i);
        if let Some(e) = &self.end {
            step.end_nutation_angle = read(&e.nutation_angle, i);
            step.end_kinetic_energy = read(&e.kinetic_energy, i);
        }
        if let Some(d) = &self.drift {
            step.drift = d.lane(i);
        }
        step.sample = match &self.sample {
            Some(SampleLanes {
                due,
                t,
                nutation_angle,
                ..
            }) if due.test(i) => Some(GridAngle {
                t: read(t, i),
                nutation_angle: read(nutation_angle, i),
            }),
            _ => None,
        };
        step.later_samples.clear();
        for (due, t, angle) in &self.later {
            if due.test(i) {
                step.later_samples.push(GridAngle {
                    t: read(t, i),
                    nutation_angle: read(angle, i),
                });
            }
        }
        step.restarted = R::BREAKPOINTS && self.restarted.test(i);
        step.stats = Stats {
            steps: read(&self.steps, i) as u64,
            rejected_steps: read(&self.rejected, i) as u64,
            rhs_evaluations: read(&self.rhs_evaluations, i) as u64,
            ..Stats::default()
        };
    }

    /// Ends lane `i`'s run as [`LaneStatus::Ended`], whether it was still running or had just
    /// ended (reaching its end time) in the last attempt; a run the lanes declined stays
    /// declined.
    #[cold]
    #[inline(never)]
    fn end_observed(&mut self, i: usize) {
        if self.running.test(i) {
            self.end(L::Mask::splat(false).with_lane(i, true), |_, _| {
                LaneStatus::Ended
            });
        } else if let Some(e) = self
            .ended
            .iter_mut()
            .find(|e| e.0 == i && !matches!(e.1, LaneStatus::Declined { .. }))
        {
            e.1 = LaneStatus::Ended;
        }
    }

    /// Ends the runs of the lanes of `lanes` whose closed form did not solve (`solved` false)
    /// as [`LaneStatus::Declined`] at the time they stand at.
    #[inline(always)]
    fn decline_unsolved(&mut self, lanes: L::Mask, solved: L::Mask) {
        let declined = lanes & !solved;
        if declined.any() {
            self.end(declined, |s, i| LaneStatus::Declined { t: s.t.lane(i) });
        }
    }

    /// Ends the runs of the lanes in `mask` with the status `status(i)` (kept until collected).
    #[cold]
    #[inline(never)]
    fn end(&mut self, mask: L::Mask, status: impl Fn(&Self, usize) -> LaneStatus) {
        for i in 0..L::WIDTH {
            if mask.test(i) {
                let s = status(self, i);
                self.ended.push((i, s));
                self.running = self.running.with_lane(i, false);
            }
        }
    }

    /// The drift reference of the lanes of `starting`, from their state at t = 0 (the run
    /// monitor's `Reference::of` its first observation).
    #[inline(always)]
    fn take_references(&mut self, starting: L::Mask) {
        let now = self.system.observe(&self.y).drift_reference();
        self.reference = Some(match self.reference {
            None => now,
            Some(was) => DriftReference {
                h0: L::select(starting, now.h0, was.h0),
                h_inertial0: linalg::each3(|k| {
                    L::select(starting, now.h_inertial0[k], was.h_inertial0[k])
                }),
                e0: L::select(starting, now.e0, was.e0),
            },
        });
    }

    /// The first stage and the initial step of the lanes of `starting`, as the scalar
    /// `Dopri5::step` does on its first call.
    #[inline(always)]
    fn start(&mut self, starting: L::Mask) {
        self.first_stage(starting);
        let starting = starting & self.running;
        let mut rhs = Solving::<L, R, DIM>::new(&self.system, self.compiled_rhs);
        let h = self.method.initial_step(
            &mut rhs,
            self.t,
            &self.y,
            &mut self.stage,
            (self.atol, self.rtol),
            self.h_max,
            self.t_stop - self.t,
        );
        let solved = rhs.solved;
        let (zero, one) = (L::splat(0.0), L::splat(1.0));
        self.rhs_evaluations += L::select(starting, one, zero);
        self.h = L::select(starting, h, self.h);
        self.decline_unsolved(starting, solved);
    }

    /// The first stage f(t, y) of the lanes of `starting`, counted, as a scalar method's step
    /// evaluates it at a run's start and after a restart; ends the lanes where it is declined
    /// or not finite.
    #[inline(always)]
    fn first_stage(&mut self, starting: L::Mask) {
        let (zero, one) = (L::splat(0.0), L::splat(1.0));
        let mut first = [zero; DIM];
        let solved =
            Solving::<L, R, DIM>::new(&self.system, self.compiled_rhs).call(&self.y, &mut first);
        self.rhs_evaluations += L::select(starting, one, zero);
        let mut finite = L::Mask::splat(true);
        let k1 = self.method.first_stage();
        for (j, &f) in first.iter().enumerate() {
            k1[j] = L::select(starting, f, k1[j]);
            finite = finite & f.is_finite();
        }
        self.decline_unsolved(starting, solved);
        let non_finite = starting & solved & !finite;
        if non_finite.any() {
            self.end(non_finite, |s, i| {
                LaneStatus::Failed(StepError::NonFiniteDerivative { t: s.t.lane(i) })
            });
        }
    }

    /// Restarts the lanes of `stopped`, whose last accepted step ended on a breakpoint of
    /// their run (`runs[held[i]]`), as the scalar loop does before their next step: the
    /// step's dense stages evaluated if they were not (dop853's `restart` completes the dense
    /// output, counted, when observed), the held states updated
    /// ([`LaneRun::at_breakpoint`]), the next stop found, and the first stage evaluated
    /// afresh at the new state; the step size is kept. Rare (a few times in a run), so the
    /// runs' own functions are called lane by lane; inlined all the same, so that the stages
    /// it evaluates have the engine's instruction set (only a class with breakpoints
    /// compiles it).
    #[inline(always)]
    fn restart_at_breakpoints(
        &mut self,
        stopped: L::Mask,
        observed: bool,
        runs: &[R],
        held: &[Option<usize>],
    ) {
        if observed {
            self.prepare_dense(stopped);
        }
        // A lane whose dense stages were declined has ended.
        let stopped = stopped & self.running;
        let mut y = [0.0; DIM];
        for (i, slot) in held.iter().enumerate() {
            let Some(index) = *slot else { continue };
            if !stopped.test(i) {
                continue;
            }
            let (run, t) = (&runs[index], self.t.lane(i));
            L::gather_lane(&self.y, i, &mut y);
            run.at_breakpoint(t, &mut y);
            for (lane, &v) in self.y.iter_mut().zip(&y) {
                *lane = lane.with_lane(i, v);
            }
            self.t_stop = self.t_stop.with_lane(i, run.next_stop(t));
        }
        self.first_stage(stopped);
        self.on_breakpoint = self.on_breakpoint & !stopped;
        self.restarted = self.restarted | stopped;
    }

    /// For the lanes of `accepted` that have just taken a step: the first time of the run's
    /// output grid strictly inside it, the state there by the step's dense output (the
    /// operations of `dopri5::dense_value`) and its observation; then the next grid index
    /// past the step's end, as the run monitor advances it when it samples up to there. A
    /// grid time at the step's end is the end observation. The later grid times inside the
    /// same step: with [`GridObservation::NutationAngle`], the nutation angle at each (a long
    /// dop853 step holds many); otherwise they are left to the monitor.
    #[inline(always)]
    fn sample_inside(&mut self, accepted: L::Mask) {
        let (zero, one) = (L::splat(0.0), L::splat(1.0));
        let gridded = accepted & self.sample_rate.greater_than(zero);
        let t_k = self.next_sample / self.sample_rate;
        let due = gridded & t_k.less_than(self.t);
        self.later.clear();
        self.sample = if due.any() {
            // The scalar monitor prepares the dense output of a step with a grid time inside.
            self.prepare_dense(due);
            let mut y = [zero; DIM];
            // Where only the nutation angle is read, only the components it reads.
            let components = match self.grid {
                GridObservation::NutationAngle => R::System::<L>::NUTATION_READS,
                GridObservation::Full => [true; DIM],
            };
            self.method.dense_point(
                self.h_step,
                &self.y_start,
                &self.y_new,
                (t_k, self.t_prev, self.t),
                &components,
                &mut y,
            );
            let observation = self.system.observe(&y);
            // The later grid times k / rate inside the step (k an integer: exact sums).
            let next = self.next_sample + one;
            if self.grid == GridObservation::NutationAngle
                && (gridded & (next / self.sample_rate).less_than(self.t)).any()
            {
                self.later_samples(gridded, next);
            }
            Some(SampleLanes {
                due,
                t: t_k,
                nutation_angle: observation.nutation_angle,
                full: (self.grid == GridObservation::Full).then_some((y, observation)),
            })
        } else {
            None
        };
        loop {
            let passed = gridded & (self.next_sample / self.sample_rate).at_most(self.t);
            if !passed.any() {
                break;
            }
            self.next_sample += L::select(passed, one, zero);
        }
    }

    /// The nutation angle at the grid times k / rate, k = `first`, `first` + 1, …, strictly
    /// inside the last accepted step of the lanes of `gridded`, into `later` (their dense
    /// stages evaluated). Inlined (an out-of-line function would not have the engine's
    /// instruction set), but apart from the first grid time's: most steps hold one at most.
    #[inline(always)]
    fn later_samples(&mut self, gridded: L::Mask, first: L) {
        let (zero, one) = (L::splat(0.0), L::splat(1.0));
        let dense = self.method.dense(self.h_step, &self.y_start, &self.y_new);
        let mut k = first;
        loop {
            let t_j = k / self.sample_rate;
            let due_j = gridded & t_j.less_than(self.t);
            if !due_j.any() {
                break;
            }
            let mut y_j = [zero; DIM];
            M::dense_at(&dense, t_j, self.t_prev, self.t, &mut y_j);
            let angle = self.system.observe(&y_j).nutation_angle;
            self.later.push((due_j, t_j, angle));
            k += one;
        }
    }

    /// The dense-output stages of the last attempted step for the lanes of `needed` whose
    /// stages are not yet evaluated, counted for them (evaluated for every lane at once: each
    /// lane's values are its own whichever asked); notes where they came out finite.
    #[inline(always)]
    fn prepare_dense(&mut self, needed: L::Mask) {
        if M::DENSE_EVALUATIONS == 0.0 {
            return;
        }
        let needed = needed & !self.dense_ready;
        if !needed.any() {
            return;
        }
        let mut rhs = Solving::<L, R, DIM>::new(&self.system, self.compiled_rhs);
        let finite = self.method.dense_stages(
            &mut rhs,
            self.t_prev,
            self.h_step,
            &self.y_start,
            &mut self.stage,
        );
        // A lane whose closed form declined a dense stage is run again on the scalar path.
        let declined = needed & !rhs.solved;
        if declined.any() {
            self.end(declined, |s, i| LaneStatus::Declined {
                t: s.t_prev.lane(i),
            });
        }
        self.rhs_evaluations += L::select(needed, L::splat(M::DENSE_EVALUATIONS), L::splat(0.0));
        self.dense_finite = (self.dense_finite & !needed) | (finite & needed);
        self.dense_ready = self.dense_ready | needed;
    }

    /// One attempted step in every running lane, accepted or rejected lane by lane, as the
    /// scalar `Dopri5::step` (or `Dop853::step`) takes it; returns the lanes that accepted. With `observed`, the
    /// accepted steps' dense output is kept.
    #[inline(always)]
    fn attempt(&mut self, observed: bool) -> L::Mask {
        let (zero, one) = (L::splat(0.0), L::splat(1.0));
        let end = adaptive_step_end(self.t, self.h.min(self.h_max), self.t_stop);
        let underflow = end.underflow & self.running;
        if underflow.any() {
            self.end(underflow, |s, i| {
                let t = s.t.lane(i);
                LaneStatus::Failed(if s.saw_non_finite.test(i) {
                    StepError::NonFiniteDerivative { t }
                } else {
                    StepError::StepSizeUnderflow {
                        t,
                        h: (end.t_new - s.t).lane(i),
                    }
                })
            });
        }
        let h = end.h;
        let mut rhs = Solving::<L, R, DIM>::new(&self.system, self.compiled_rhs);
        let err = self.method.attempt(
            &mut rhs,
            self.t,
            h,
            &self.y,
            &mut self.y_new,
            &mut self.stage,
            (self.atol, self.rtol),
        );
        let solved = rhs.solved;
        self.rhs_evaluations += L::select(self.running, L::splat(M::ATTEMPT_EVALUATIONS), zero);
        self.decline_unsolved(self.running, solved);
        let running = self.running;
        let err_finite = err.is_finite();
        // dop853's stage 13 (f at the new point), for the steps that passed the error test.
        let passed = running & err_finite & err.at_most(one);
        let mut end_finite = L::Mask::splat(true);
        if M::END_STAGE && passed.any() {
            let mut rhs = Solving::<L, R, DIM>::new(&self.system, self.compiled_rhs);
            let finite = self.method.end_stage(&mut rhs, end.t_new, &self.y_new);
            end_finite = !passed | finite;
            self.rhs_evaluations += L::select(passed, one, zero);
            self.decline_unsolved(passed, rhs.solved);
        }
        let running = self.running;
        let finite = err_finite & end_finite;
        let fac11 = M::error_factor(err);
        let accept = running & finite & err.at_most(one);
        let reject = running & !accept;
        let after_rejections = self.rejected_in_a_row.greater_than(zero);
        let (h_accepted, fac_old) =
            M::CONTROL.accepted_step_size(err, fac11, h, self.fac_old, after_rejections);
        let h_rejected = L::select(
            finite,
            M::CONTROL.rejected_step_size(fac11, h),
            non_finite_step_size(h),
        );
        self.h = L::select(
            accept,
            kept_proposal(end.last, self.h, h_accepted),
            L::select(reject, h_rejected, self.h),
        );
        self.fac_old = L::select(accept, fac_old, self.fac_old);
        if observed {
            // What the step's dense output is formed of where it is read (for every lane;
            // the others' are not read). Its dense stages are not evaluated yet.
            self.y_start = self.y;
            self.h_step = h;
            self.t_prev = L::select(accept, self.t, self.t_prev);
            if M::DENSE_EVALUATIONS != 0.0 {
                self.dense_ready = L::Mask::splat(false);
            }
        }
        self.method
            .accept(accept, observed, &mut self.y, &self.y_new);
        self.t = L::select(accept, end.t_new, self.t);
        if observed && accept.any() {
            let end = self.system.observe(&self.y);
            self.drift = self.reference.as_ref().map(|r| end.drift(r));
            self.end = Some(end);
            self.sample_inside(accept);
        }
        self.steps += L::select(accept, one, zero);
        self.rejected += L::select(reject, one, zero);
        self.rejected_in_a_row = L::select(
            accept,
            zero,
            L::select(reject, self.rejected_in_a_row + one, self.rejected_in_a_row),
        );
        self.saw_non_finite = (self.saw_non_finite & !accept) | (reject & !finite);
        let too_many = reject
            & self
                .rejected_in_a_row
                .greater_than(L::splat(f64::from(MAX_REJECTIONS)));
        if too_many.any() {
            self.end(too_many, |s, i| {
                let t = s.t.lane(i);
                LaneStatus::Failed(if finite.test(i) {
                    StepError::StepSizeUnderflow { t, h: h.lane(i) }
                } else {
                    StepError::NonFiniteDerivative { t }
                })
            });
        }
        let done = accept & self.t.at_least(self.t_end);
        if done.any() {
            self.end(done, |_, _| LaneStatus::Complete);
        }
        if R::BREAKPOINTS {
            // As the scalar loop: a step that ended exactly on its stop short of the end.
            self.on_breakpoint = self.on_breakpoint
                | (accept & self.t.equals(self.t_stop) & self.t_stop.less_than(self.t_end));
        }
        accept
    }
}

/// The lockstep integration of `runs` at lane type `L`; see the module documentation.
#[inline(always)]
fn lockstep<L: Lane, R: LaneRun<DIM>, F: MethodFamily, const DIM: usize>(
    runs: &[R],
    settings: &LaneSettings,
    observe: Observing<'_, DIM>,
    compiled_rhs: CompiledRhs<L, R, DIM>,
) -> Vec<LaneOutcome<DIM>> {
    let mut outcomes: Vec<Option<LaneOutcome<DIM>>> = vec![None; runs.len()];
    let Some(first) = runs.first() else {
        return Vec::new();
    };
    let mut lanes = Lanes::<L, R, F::In<L, DIM>, DIM>::new(first, settings, compiled_rhs);
    let mut observe = observe.map(|(grid, observer)| {
        lanes.grid = grid;
        observer
    });
    let mut held: Vec<Option<usize>> = vec![None; L::WIDTH];
    let mut next = 0;
    // The observed lane's step, reused.
    let mut step = LaneStep::default();
    loop {
        // Each free lane takes the next run.
        let mut starting = L::Mask::splat(false);
        for (i, slot) in held.iter_mut().enumerate() {
            while slot.is_none() && next < runs.len() {
                let (index, run) = (next, &runs[next]);
                next += 1;
                let unstarted = |status| LaneOutcome {
                    status,
                    t: 0.0,
                    y: run.initial_state(),
                    stats: Stats::default(),
                };
                if !run.admitted() {
                    outcomes[index] = Some(unstarted(LaneStatus::Declined { t: 0.0 }));
                } else if run.t_end().is_nan() || run.t_end() <= 0.0 {
                    // As the scalar loop `while t < t_end`: no step.
                    outcomes[index] = Some(unstarted(LaneStatus::Complete));
                } else {
                    lanes.load(i, run);
                    *slot = Some(index);
                    starting = starting.with_lane(i, true);
                }
            }
        }
        if held.iter().all(Option::is_none) {
            break;
        }
        if starting.any() {
            if observe.is_some() {
                lanes.take_references(starting);
            }
            lanes.start(starting);
        }
        if R::BREAKPOINTS {
            let stopped = lanes.on_breakpoint & lanes.running;
            if stopped.any() {
                lanes.restart_at_breakpoints(stopped, observe.is_some(), runs, &held);
            }
        }
        if lanes.running.any() {
            let accepted = lanes.attempt(observe.is_some());
            if let Some(observe) = observe.as_mut() {
                // Which lanes' states are finite, for every lane at once.
                let finite = lanes
                    .y
                    .iter()
                    .fold(L::Mask::splat(true), |all, y| all & y.is_finite());
                for (i, slot) in held.iter().enumerate() {
                    if let Some(index) = *slot
                        && accepted.test(i)
                    {
                        lanes.step_of(i, finite, &mut step);
                        let mut rest = LaneRest {
                            lanes: &mut lanes,
                            lane: i,
                        };
                        if !observe(index, &step, &mut rest) {
                            lanes.end_observed(i);
                        }
                    }
                }
            }
            if R::BREAKPOINTS {
                lanes.restarted = lanes.restarted & !accepted;
            }
        }
        for (i, status) in std::mem::take(&mut lanes.ended) {
            if let Some(index) = held[i].take() {
                outcomes[index] = Some(lanes.outcome(i, status));
            }
        }
    }
    outcomes
        .into_iter()
        .map(|o| o.expect("every run ends"))
        .collect()
}
