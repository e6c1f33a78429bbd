//! `method: averaged` as a [`Stepper`]: steps the slow system with DOP853 and rebuilds the
//! full state (ω, q and each effector's dissipated energy) from the exact torque-free
//! solution at the slow state, so that sampling, events and logs work as for other methods.

use super::motion::{Moments, PeriodAverages};
use super::{MAX_EPSILON, MAX_FAST_TO_FORCING, SEPARATRIX_LAYER};
use crate::exact::TorqueFreeSolution;
use crate::integrate::{Dop853, OdeSystem, Stats, StepError, Stepper, Tolerances};
use crate::model::{Forcing, Secular, SecularMotion, Spacecraft};
use crate::sim::Adaptive;
use nalgebra::{Matrix3, Quaternion, Rotation3, Unit, UnitQuaternion, Vector3};
use std::f64::consts::TAU;

/// Relative distance |H² − 2T I2| / H² from the separatrix within which its side is
/// rounding (a few ulp of the terms H² and 2T I2).
const SEPARATRIX_ROUNDING: f64 = 64.0 * f64::EPSILON;

/// Slow state layout: z = [|H|/H₀, T/T₀, polhode phase (periods), precession angle (rad),
/// W₁/T₀, …], with the unit vector Ĥ (inertial axes) after the precession angle when an
/// effector's forcing depends on the orbit (z = [.., Ĥx, Ĥy, Ĥz, W₁/T₀, …]).
const H: usize = 0;
const T: usize = 1;
const PHASE: usize = 2;
const PRECESSION: usize = 3;
const DIRECTION: usize = 4;

/// The slow system: the period-averaged rates of |H|, T, the fast phases and each effector's
/// dissipated energy, functions of (|H|, T) only.
struct SlowSystem {
    moments: Moments,
    axes: Matrix3<f64>,
    inertia: Matrix3<f64>,
    effects: Vec<Box<dyn Secular>>,
    h0: f64,
    t0: f64,
    /// Ĥ at t = 0 (inertial axes): constant unless the direction is carried.
    h_hat0: Vector3<f64>,
    /// Whether z carries Ĥ: some effector's forcing depends on the orbit.
    direction: bool,
    /// The tightest forcing: the shortest orbit period and the longest window (s).
    forcing: Option<Forcing>,
    /// Index in z of the first effector's energy.
    effectors_at: usize,
    /// An axisymmetric body whose effectors see the precession alone
    /// ([`Secular::phase_free`]): the fast period is the precession's, not the polhode's.
    precession_only: bool,
}

/// Everything the slow rates give at one slow state.
struct SlowRates {
    averages: PeriodAverages,
    h_rate: f64,
    energy_rate: f64,
    /// dĤ/dt (1/s, inertial axes).
    turn: Vector3<f64>,
}

impl SlowSystem {
    /// Ĥ (inertial axes) at slow state `z`.
    fn h_hat(&self, z: &[f64]) -> Vector3<f64> {
        if self.direction {
            Vector3::new(z[DIRECTION], z[DIRECTION + 1], z[DIRECTION + 2]).normalize()
        } else {
            self.h_hat0
        }
    }

    fn rates(&self, t: f64, z: &[f64], dissipation: Option<&mut [f64]>) -> SlowRates {
        let h = z[H] * self.h0;
        // Past a pure spin the rates are the pure spin's (zero for a passive scene), so an
        // overshoot of the slow stepper neither pumps nor drains what cannot be there.
        let energy = self.moments.admissible_energy(h, z[T] * self.t0);
        let averages = self.moments.period_averages(h, energy);
        let motion = SecularMotion {
            omega_omega: self.axes * averages.omega_omega * self.axes.transpose(),
            h,
            energy,
            inertia: &self.inertia,
            t,
            h_hat: self.h_hat(z),
        };
        let (mut h_rate, mut energy_rate) = (0.0, 0.0);
        let mut across = Vector3::zeros();
        let mut dissipation = dissipation;
        for (k, e) in self.effects.iter().enumerate() {
            let r = e.rates(&motion);
            h_rate += r.h_rate;
            energy_rate += r.energy_rate;
            across += r.torque_across;
            if let Some(d) = dissipation.as_deref_mut() {
                d[k] = r.dissipation_rate / self.t0;
            }
        }
        SlowRates {
            averages,
            h_rate,
            energy_rate,
            turn: across / h,
        }
    }

    /// ε: the fast period over the dissipation time, and the period compared (s). The fast period
    /// is the longer of the spin period about H, 2π|H|/(2T), and the polhode period (left out
    /// within the separatrix layer, where it diverges); the dissipation time is the shorter of
    /// (T_max − T_min)/|dT/dt|, |H|/|d|H|/dt| and 1/|dĤ/dt|. With an orbit-driven forcing the
    /// period compared is at least its averaging window, and T's rate is taken at fixed
    /// 2T/|H|², the shape of the polhode: |H| and T then fall together, and the polhode's
    /// shape changes only through the difference, (dT/dt − (2T/|H|) d|H|/dt).
    fn epsilon(&self, t: f64, z: &[f64]) -> (f64, f64) {
        let r = self.rates(t, z, None);
        let h = z[H] * self.h0;
        let energy = z[T] * self.t0;
        let [i1, _, i3] = self.moments.i;
        let fast = self.fast_period(&r.averages, h, energy);
        let band = h * h * (1.0 / (2.0 * i1) - 1.0 / (2.0 * i3));
        let (tau_t, slowest) = match self.forcing {
            Some(f) => {
                let shape_rate = r.energy_rate - 2.0 * energy / h * r.h_rate;
                (band / shape_rate.abs(), fast.max(f.window))
            }
            None => (band / r.energy_rate.abs(), fast),
        };
        let tau_h = h / r.h_rate.abs();
        let tau_turn = 1.0 / r.turn.norm();
        (slowest / tau_t.min(tau_h).min(tau_turn), slowest)
    }

    /// The fast period (s): the longer of the spin period about H and the polhode period (or,
    /// with [`SlowSystem::precession_only`], the precession period).
    fn fast_period(&self, averages: &PeriodAverages, h: f64, energy: f64) -> f64 {
        let fast = TAU * h / (2.0 * energy).max(f64::MIN_POSITIVE);
        if self.precession_only {
            fast.max(TAU / averages.precession_rate)
        } else if averages.m < 1.0 - SEPARATRIX_LAYER && averages.period.is_finite() {
            fast.max(averages.period)
        } else {
            fast
        }
    }

    /// What [`SlowSystem::epsilon`] compares with the dissipation time, in words.
    fn period_name(&self) -> &'static str {
        if self.forcing.is_some_and(|f| f.window > 0.0) {
            "field's averaging window (one orbit and one sidereal day) or the fast period"
        } else {
            "fast period"
        }
    }

    /// Where averaging over the orbit-driven forcing fails, in words: the fast motion (the
    /// longer of the spin period about H and the polhode period) must be short against the
    /// orbit period, so that the field is independent of the fast phases.
    fn forcing_refusal(&self, z: &[f64]) -> Option<String> {
        let f = self.forcing.filter(|f| f.period > 0.0)?;
        let h = z[H] * self.h0;
        let energy = self.moments.admissible_energy(h, z[T] * self.t0);
        let averages = self.moments.period_averages(h, energy);
        let fast = self.fast_period(&averages, h, energy);
        let ratio = fast / f.period;
        (ratio.is_nan() || ratio > MAX_FAST_TO_FORCING).then(|| {
            format!(
                "the fast period ({fast:.3e} s) is {ratio:.2e} of the orbit period ({:.3e} s), \
                 and averaging the field over the orbit independently of the body's motion \
                 needs it below {MAX_FAST_TO_FORCING:e}",
                f.period
            )
        })
    }
}

impl OdeSystem for SlowSystem {
    fn dim(&self) -> usize {
        self.effectors_at + self.effects.len()
    }
    fn rhs(&self, t: f64, z: &[f64], dz: &mut [f64]) {
        let (head, tail) = dz.split_at_mut(self.effectors_at);
        let r = self.rates(t, z, Some(tail));
        head[H] = r.h_rate / self.h0;
        head[T] = r.energy_rate / self.t0;
        head[PHASE] = if r.averages.period.is_finite() {
            1.0 / r.averages.period
        } else {
            0.0
        };
        head[PRECESSION] = r.averages.precession_rate;
        if self.direction {
            head[DIRECTION..DIRECTION + 3].copy_from_slice(r.turn.as_slice());
        }
    }
}

/// The averaged method as a stepper over the spacecraft's state vector.
pub struct AveragedStepper {
    system: SlowSystem,
    slow: Dop853,
    /// Columns X, Y, Ĥ_N: the inertial frame the precession angle is measured in.
    frame_n: Matrix3<f64>,
    /// Sign of the rate about the circulation axis after the last step.
    branch: f64,
    /// Before the separatrix crossing inside the last step, if there was one.
    branch_before: f64,
    /// When the last step crossed the separatrix (s).
    crossing: Option<f64>,
    /// Offsets of each effector's dissipated energy in the state vector.
    offsets: Vec<usize>,
    /// The initial state: the effectors' dynamic states are shown as they started.
    rest: Vec<f64>,
    y: Vec<f64>,
    stats: Stats,
}

/// Why `method: averaged` cannot treat `sc`, naming the effector and the reason.
pub fn refusal(sc: &Spacecraft) -> Option<String> {
    if sc.motion().is_some() {
        return Some(
            "method `averaged` averages over the torque-free motion, and the hub's rotation \
             here is prescribed (`hub_motion`); use dop853"
                .into(),
        );
    }
    let internal = sc.effectors().iter().any(|e| e.num_dynamic_states() > 0);
    for e in sc.effectors() {
        if let Some(mut s) = e.secular()
            && !internal
        {
            if let Err(why) = s.prepare(&sc.hub.inertia) {
                return Some(refused(e.as_ref(), &why));
            }
            continue;
        }
        if internal && is_internal(e.as_ref()) {
            continue;
        }
        let why = if internal && e.secular().is_some() {
            "is a torque, and this spacecraft also has effectors with internal degrees of \
             freedom: averaging the two kinds together is not implemented"
        } else if e.num_dynamic_states() > 0 {
            "has internal degrees of freedom that have no conservative counterpart to average \
             its dissipation over (only spring–mass dampers, hinged rods and modal appendages \
             do)"
        } else {
            "applies an environmental or control torque, which does not average over the \
             torque-free motion (it depends on the orbit, the field or a controller's state)"
        };
        return Some(format!(
            "method `averaged` cannot treat effector `{}` ({}): it {why}; use dop853",
            e.name(),
            e.kind()
        ));
    }
    None
}

/// An effector whose dissipation is averaged over the coupled periodic orbits
/// ([`super::forced`]): dynamic states, then one bookkeeping state (the energy it dissipated),
/// and a conservative counterpart.
fn is_internal(e: &dyn crate::model::Effector) -> bool {
    e.num_dynamic_states() > 0
        && e.num_states() == e.num_dynamic_states() + 1
        && e.without_dissipation().is_some()
}

impl AveragedStepper {
    /// Starts at `(0, y0)` with the tolerances `a` on the slow variables; `Err` (a diagnosis)
    /// when the spacecraft or the initial state cannot be averaged.
    pub fn new(sc: &Spacecraft, y0: &[f64], a: Adaptive) -> Result<Self, String> {
        if let Some(why) = refusal(sc) {
            return Err(why);
        }
        // With internal degrees of freedom the averaged body is the spacecraft locked in its
        // initial configuration, and the effectors' dissipation comes from a table of the
        // coupled periodic orbits.
        let internal = sc.effectors().iter().any(|e| e.num_dynamic_states() > 0);
        let hub = if internal {
            crate::model::RigidBody::new(sc.system_inertia(y0))
                .map_err(|e| format!("the locked spacecraft's inertia: {e}"))?
        } else {
            sc.hub.clone()
        };
        let Some(moments) = Moments::new(&hub.principal_moments) else {
            return Err(
                "method `averaged`: the body is spherical, so its rates never change and there \
                 is nothing to average; use exact or dop853"
                    .into(),
            );
        };
        let inertia = hub.inertia;
        let axes = hub.principal_axes;
        let omega0 = Vector3::new(y0[0], y0[1], y0[2]);
        let q0 = UnitQuaternion::from_quaternion(Quaternion::new(y0[3], y0[4], y0[5], y0[6]));
        let w_p = axes.transpose() * omega0;
        let [i1, i2, i3] = moments.i;
        let h_p = Vector3::new(i1 * w_p.x, i2 * w_p.y, i3 * w_p.z);
        let h0 = h_p.norm();
        let t0 = 0.5 * w_p.dot(&h_p);
        if h0 == 0.0 || t0 <= 0.0 {
            return Err(
                "method `averaged`: the body is at rest, so there is nothing to average; use \
                 dop853"
                    .into(),
            );
        }
        let h_hat_n = q0 * (axes * h_p) / h0;
        let frame_n = inertial_frame(&h_hat_n);
        // Where each effector's dissipated energy is: after its dynamic states.
        let offsets: Vec<usize> = sc
            .effectors()
            .iter()
            .enumerate()
            .map(|(k, e)| sc.effector_offset(k) + e.num_dynamic_states())
            .collect();
        let effects: Vec<Box<dyn Secular>> = if internal {
            let mut layout = super::forced::Layout {
                dynamic: Vec::new(),
                dissipated: offsets.clone(),
            };
            for (k, e) in sc.effectors().iter().enumerate() {
                let o = sc.effector_offset(k);
                layout.dynamic.extend(o..o + e.num_dynamic_states());
            }
            let table = std::sync::Arc::new(super::forced::DissipationTable::new(
                sc,
                y0,
                &layout,
                (1e-2 * a.rtol).clamp(1e-11, 1e-8),
            )?);
            (0..sc.effectors().len())
                .map(|index| {
                    Box::new(super::forced::Tabulated {
                        table: table.clone(),
                        index,
                    }) as Box<dyn Secular>
                })
                .collect()
        } else {
            let mut effects: Vec<Box<dyn Secular>> =
                sc.effectors().iter().filter_map(|e| e.secular()).collect();
            for (e, s) in sc.effectors().iter().zip(effects.iter_mut()) {
                s.prepare(&inertia)
                    .map_err(|why| refused(e.as_ref(), &why))?;
            }
            effects
        };
        // The tightest forcing: the shortest orbit period, the longest window.
        let forcings: Vec<Forcing> = effects.iter().filter_map(|e| e.forcing()).collect();
        let direction = !forcings.is_empty();
        let forcing = forcings.into_iter().reduce(|a, b| Forcing {
            period: if a.period > 0.0 && b.period > 0.0 {
                a.period.min(b.period)
            } else {
                a.period.max(b.period)
            },
            window: a.window.max(b.window),
        });
        let precession_only =
            direction && (i1 == i2 || i2 == i3) && effects.iter().all(|e| e.phase_free());
        let system = SlowSystem {
            moments,
            axes,
            inertia,
            effects,
            h0,
            t0,
            h_hat0: h_hat_n,
            direction,
            forcing,
            effectors_at: if direction { DIRECTION + 3 } else { DIRECTION },
            precession_only,
        };
        let (phase, branch) = moments.phase_of(&w_p);
        let mut z0 = vec![0.0; system.dim()];
        z0[H] = 1.0;
        z0[T] = 1.0;
        z0[PHASE] = phase;
        if direction {
            z0[DIRECTION..DIRECTION + 3].copy_from_slice(h_hat_n.as_slice());
        }
        for (k, &o) in offsets.iter().enumerate() {
            z0[system.effectors_at + k] = y0[o] / t0;
        }
        // On the separatrix the averaged rates vanish (the period is infinite and ω sits on
        // the intermediate axis), so the slow system would stay there for ever while the full
        // motion leaves it within a few periods. Δ2 = H² − 2T I2 is known to a few ulp of H²:
        // inside that, the side of the separatrix is not known either.
        let (_, d2, _) = moments.deltas(h0, t0);
        if i1 < i2 && i2 < i3 && d2.abs() <= SEPARATRIX_ROUNDING * h0 * h0 {
            return Err(format!(
                "method `averaged`: the initial state is on the separatrix to the precision of \
                 |H| and T (|H² − 2T I2| / H² = {:.1e}, within {SEPARATRIX_ROUNDING:.0e} of \
                 rounding), where the averaged rates vanish and the averaged motion cannot \
                 leave it while the full motion does; use dop853",
                d2.abs() / (h0 * h0)
            ));
        }
        if let Some(why) = system.forcing_refusal(&z0) {
            return Err(format!(
                "method `averaged`: at the start, {why}; use dop853"
            ));
        }
        let (epsilon, fast) = system.epsilon(0.0, &z0);
        if epsilon.is_nan() || epsilon > MAX_EPSILON {
            return Err(format!(
                "method `averaged` needs dissipation slow next to the motion it averages over, \
                 and here the {} ({fast:.3e} s) is {epsilon:.2e} of the dissipation \
                 time (the limit is {MAX_EPSILON:e}); use dop853",
                system.period_name()
            ));
        }
        let mut stepper = AveragedStepper {
            system,
            slow: slow_stepper(&z0, &a),
            frame_n,
            branch,
            branch_before: branch,
            crossing: None,
            offsets,
            rest: y0.to_vec(),
            y: y0.to_vec(),
            stats: Stats::default(),
        };
        // The precession angle that puts the rebuilt attitude on q0.
        let mut y = y0.to_vec();
        stepper.rebuild(&z0, branch, &mut y)?;
        let q_test = UnitQuaternion::from_quaternion(Quaternion::new(y[3], y[4], y[5], y[6]));
        let d = q0 * q_test.inverse();
        z0[PRECESSION] = 2.0 * d.imag().dot(&h_hat_n).atan2(d.w);
        stepper.slow = slow_stepper(&z0, &a);
        stepper.rebuild(&z0, branch, &mut y)?;
        stepper.y = y;
        Ok(stepper)
    }

    /// The full state at slow state `z` on branch `branch`: ω and q from the exact torque-free
    /// solution through the reference point, advanced by the polhode phase and turned about
    /// Ĥ_N by the precession angle, and each effector's dissipated energy.
    fn rebuild(&self, z: &[f64], branch: f64, out: &mut [f64]) -> Result<(), String> {
        let s = &self.system;
        let h = z[H] * s.h0;
        let energy = z[T] * s.t0;
        let mut w_p = s.moments.reference_rates(h, energy, branch);
        // Never the exact pure spin: the closed form's steady case measures precession
        // differently, so keep a vanishing nutation instead.
        let floor = 1e-100 * w_p.amax();
        if w_p.x == 0.0 {
            w_p.x = floor;
        }
        if w_p.z == 0.0 {
            w_p.z = floor;
        }
        let omega_ref = s.axes * w_p;
        let h_b = s.inertia * omega_ref;
        let z_b = h_b.normalize();
        let y_b = s.axes.column(1).into_owned();
        let x_b = y_b.cross(&z_b);
        let body = Matrix3::from_columns(&[x_b, y_b, z_b]);
        let frame_n = self.frame_at(z);
        let q_ref = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(
            frame_n * body.transpose(),
        ));
        let h_hat_n = Unit::new_unchecked(frame_n.column(2).into_owned());
        let solution = TorqueFreeSolution::new(&s.inertia, &omega_ref, &q_ref)
            .map_err(|e| format!("the torque-free solution at the slow state failed: {e}"))?;
        let period = solution.polhode_period();
        let (omega, q) = if period.is_finite() && period > 0.0 {
            let frac = z[PHASE].rem_euclid(1.0);
            let (w, q) = solution.state_at(frac * period);
            let turn = z[PRECESSION] - frac * solution.precession_angle_per_period();
            (w, UnitQuaternion::from_axis_angle(&h_hat_n, turn) * q)
        } else {
            (
                omega_ref,
                UnitQuaternion::from_axis_angle(&h_hat_n, z[PRECESSION]) * q_ref,
            )
        };
        // Keep the quaternion on the hemisphere of the last state, for smooth telemetry.
        let sign = if q.w * self.y[3] + q.i * self.y[4] + q.j * self.y[5] + q.k * self.y[6] < 0.0 {
            -1.0
        } else {
            1.0
        };
        out.copy_from_slice(&self.rest);
        out[..3].copy_from_slice(omega.as_slice());
        out[3] = sign * q.w;
        out[4] = sign * q.i;
        out[5] = sign * q.j;
        out[6] = sign * q.k;
        for (k, &o) in self.offsets.iter().enumerate() {
            out[o] = z[s.effectors_at + k] * s.t0;
        }
        Ok(())
    }

    /// The inertial frame (X, Y, Ĥ_N) at slow state `z`: the initial one, turned by the
    /// smallest rotation from the initial Ĥ to the current one when the direction is carried.
    fn frame_at(&self, z: &[f64]) -> Matrix3<f64> {
        if !self.system.direction {
            return self.frame_n;
        }
        // Rodrigues' form of the smallest rotation from a to b (unit vectors, not opposite):
        // 1 + [v]× + [v]×² / (1 + a·b) with v = a × b, without cancellation as b → a.
        let (a, b) = (self.system.h_hat0, self.system.h_hat(z));
        let v = a.cross(&b);
        let k = v.cross_matrix();
        let turn = Matrix3::identity() + k + k * k / (1.0 + a.dot(&b));
        turn * self.frame_n
    }

    /// Whether the polhode circulates about axis 3 at slow state `z`.
    fn about_major(&self, z: &[f64]) -> bool {
        let s = &self.system;
        let (_, d2, _) = s.moments.deltas(z[H] * s.h0, z[T] * s.t0);
        d2 >= 0.0 || s.moments.i[1] == s.moments.i[0]
    }

    /// The slow state at `t` inside the last step.
    fn slow_at(&self, t: f64) -> Vec<f64> {
        let mut z = vec![0.0; self.system.dim()];
        if t == self.slow.t() {
            z.copy_from_slice(self.slow.y());
        } else {
            self.slow.interpolate(t, &mut z);
        }
        z
    }

    /// After a step from `t0` that changed the circulation: the crossing time, by bisection on
    /// the dense output, and the branch entered, taken from the rebuilt rates just before it.
    /// The averaged motion cannot resolve which pole the body falls toward: the fast phase at
    /// the crossing decides, and the branch follows the rebuilt phase (docs/averaging.md).
    fn cross_separatrix(&mut self, t0: f64) -> Result<(), String> {
        let major0 = self.about_major(self.slow_at(t0).as_slice());
        let (mut a, mut b) = (t0, self.slow.t());
        for _ in 0..200 {
            let mid = 0.5 * (a + b);
            if mid <= a || mid >= b {
                break;
            }
            if self.about_major(&self.slow_at(mid)) == major0 {
                a = mid;
            } else {
                b = mid;
            }
        }
        let mut y = self.y.clone();
        self.rebuild(&self.slow_at(a), self.branch, &mut y)?;
        let w_p = self.system.axes.transpose() * Vector3::new(y[0], y[1], y[2]);
        let toward = if major0 { w_p.x } else { w_p.z };
        self.branch_before = self.branch;
        self.branch = if toward < 0.0 { -1.0 } else { 1.0 };
        self.crossing = Some(b);
        Ok(())
    }
}

/// DOP853 on the slow system from `z0` at t = 0: `a.rtol` on the variables scaled by their
/// initial values, so the same number serves as the absolute tolerance.
fn slow_stepper(z0: &[f64], a: &Adaptive) -> Dop853 {
    let tolerances = Tolerances {
        rtol: a.rtol,
        atol: a.rtol,
    };
    Dop853::new(0.0, z0, tolerances, a.max_step, None)
}

/// A right-handed frame whose third column is `z` (unit).
fn inertial_frame(z: &Vector3<f64>) -> Matrix3<f64> {
    let x = perpendicular(z);
    Matrix3::from_columns(&[x, z.cross(&x), *z])
}

/// A unit vector perpendicular to the unit vector `z`.
pub(crate) fn perpendicular(z: &Vector3<f64>) -> Vector3<f64> {
    let least = z.iamin();
    let mut e = Vector3::zeros();
    e[least] = 1.0;
    (e - z * z.dot(&e)).normalize()
}

/// The refusal of effector `e`, which cannot be averaged on this hub because `why`.
fn refused(e: &dyn crate::model::Effector, why: &str) -> String {
    format!(
        "method `averaged` cannot treat effector `{}` ({}): {why}; use dop853",
        e.name(),
        e.kind()
    )
}

impl Stepper for AveragedStepper {
    fn t(&self) -> f64 {
        self.slow.t()
    }
    fn y(&self) -> &[f64] {
        &self.y
    }
    fn t_prev(&self) -> f64 {
        self.slow.t_prev()
    }
    fn step<S: OdeSystem + ?Sized>(&mut self, _sys: &S, t_end: f64) -> Result<f64, StepError> {
        let t0 = self.slow.t();
        let z0_major = self.about_major(self.slow.y());
        self.slow.step(&self.system, t_end)?;
        let t1 = self.slow.t();
        self.crossing = None;
        self.branch_before = self.branch;
        let sub = |what: String| StepError::SubFlow { t: t0, what };
        if self.about_major(self.slow.y()) != z0_major {
            self.cross_separatrix(t0).map_err(sub)?;
        }
        let z = self.slow.y().to_vec();
        if let Some(why) = self.system.forcing_refusal(&z) {
            return Err(sub(format!(
                "averaging no longer holds at t = {t1:.6e} s: {why}"
            )));
        }
        let (epsilon, fast) = self.system.epsilon(t1, &z);
        if epsilon.is_nan() || epsilon > MAX_EPSILON {
            return Err(sub(format!(
                "averaging no longer holds at t = {t1:.6e} s: the {} ({fast:.3e} s) \
                 has grown to {epsilon:.2e} of the dissipation time (the limit is \
                 {MAX_EPSILON:e})",
                self.system.period_name()
            )));
        }
        let mut y = self.y.clone();
        self.rebuild(&z, self.branch, &mut y).map_err(sub)?;
        self.y = y;
        self.stats = self.slow.stats();
        Ok(t1)
    }
    fn interpolate(&self, t: f64, out: &mut [f64]) {
        let branch = match self.crossing {
            Some(tc) if t < tc => self.branch_before,
            _ => self.branch,
        };
        let z = self.slow_at(t);
        if self.rebuild(&z, branch, out).is_err() {
            out.fill(f64::NAN);
        }
    }
    fn stats(&self) -> Stats {
        self.stats
    }
    fn restart<S: OdeSystem + ?Sized>(&mut self, _sys: &S, _y: &[f64]) {
        // The averaged effectors have no breakpoints and no held states.
    }
}
