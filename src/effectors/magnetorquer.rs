//! `magnetorquer`: three coils along the body axes whose dipole m (A m², body axes) is
//! commanded by a discrete B-dot detumbling law, saturated per axis, in the Earth's field.
//!
//! The torque on the hub is τ = m × B_body (Wertz (ed.), *Spacecraft Attitude Determination
//! and Control*, 1978, §17.2), external, so the effector integrates its work W = ∫ τ·ω dt,
//! which the energy balance subtracts.
//!
//! **The law** (Avanzini & Giulietti, "Magnetic detumbling of a rigid spacecraft", *JGCD*
//! 35(4), 2012; Markley & Crassidis, *Fundamentals of Spacecraft Attitude Determination and
//! Control*, 2014, §7.5.1). With b = B/|B| the field's direction in body axes, the continuous
//! law m = (k/|B|) ω × b gives τ = k (ω × b) × b = −k ω⊥, which drains the rate across the
//! field. Its B-dot form uses ḃ ≈ −ω × b (valid while the field turns slowly next to the
//! body): m = −(k/|B|) ḃ. The controller samples the field at its ticks t_j = j Δt, estimates
//! ḃ by the backward difference of the sampled directions, and holds
//!
//! ```text
//! m_j = sat(−(k/|B_j|) (b_j − b_{j−1})/Δt),   sat: each axis clipped to ±m_max
//! ```
//!
//! until the next tick (zero-order hold); the first tick (t = 0) has no difference yet and
//! commands m = 0. The gain's unit is N m s (kg m²/s).
//!
//! **Where the law holds.** Between samples the body turns by φ = |ω| Δt. The backward
//! difference is the chord of the sampled directions: it lags the rate it estimates by φ/2
//! and shortens it by 2 sin(φ/2)/φ, so the torque's damping part falls as cos(φ/2) and
//! vanishes at φ = π, where the samples alias; beyond, the law pumps energy in. The run warns
//! once past φ = 1 rad (a lag of 29°) and stops past π (`checks.on_validity`).
//!
//! States, all held between ticks but the last: m (3, A m²); the last sampled direction b
//! (3); the number of samples taken; the rotation per sample φ at the last tick (rad); the
//! work W (J).

use super::clock::SampleClock;
use super::magnetic_dipole::field_body;
use crate::model::{Effector, EnergyAccount, HubAcceleration, HubCoupling, HubState, Validity};
use crate::orbit::{GeomagneticField, Orbit};
use nalgebra::Vector3;
use std::sync::Arc;

/// Avanzini & Giulietti's gain k = 2 n (1 + sin ξ_m) J_min (N m s) for the law
/// m = −(k/|B|) ḃ: n the orbit's mean motion (rad/s), J_min the smallest principal moment of
/// `inertia` (kg m²), and ξ_m, the orbit's inclination to the geomagnetic equator, taken as
/// its inclination to the equator (the dipole's tilt, about 10°, is neglected).
pub fn optimal_gain(orbit: &Orbit, inertia: &nalgebra::Matrix3<f64>) -> f64 {
    let j_min = inertia.symmetric_eigenvalues().min();
    let xi = orbit.elements().inclination;
    2.0 * orbit.mean_motion() * (1.0 + xi.sin()) * j_min
}

/// Index of the rotation-per-sample state.
const TURN: usize = 7;
/// Index of the work state.
const WORK: usize = 8;

/// Rotation per sample φ = |ω| Δt (rad) past which the run warns: the difference lags by 29°.
pub const TURN_WARN: f64 = 1.0;
/// Rotation per sample past which the samples alias and the law no longer damps (rad).
pub const TURN_LIMIT: f64 = std::f64::consts::PI;

/// Magnetorquer coils under B-dot control.
#[derive(Debug, Clone)]
pub struct Magnetorquer {
    /// Name (telemetry topic).
    pub name: String,
    /// The orbit of the spacecraft's centre of mass.
    pub orbit: Arc<Orbit>,
    /// The geomagnetic field along the run (carries the scenario epoch).
    pub field: GeomagneticField,
    /// Largest dipole per body axis (A m², each > 0).
    pub max_dipole: Vector3<f64>,
    /// The B-dot gain k (N m s).
    pub gain: f64,
    /// When the controller samples.
    pub clock: SampleClock,
}

impl Magnetorquer {
    /// The held dipole command (A m², body axes) in the states `x`.
    #[inline]
    pub fn dipole(x: &[f64]) -> Vector3<f64> {
        Vector3::new(x[0], x[1], x[2])
    }

    /// The B-dot command (A m², body axes) from the field's magnitude `magnitude` (T) and
    /// direction `dir_now` (unit, body axes) now and the previous sample's direction
    /// `dir_before`, saturated per axis.
    pub fn command(
        &self,
        magnitude: f64,
        dir_now: &Vector3<f64>,
        dir_before: &Vector3<f64>,
    ) -> Vector3<f64> {
        let dir_rate = (dir_now - dir_before) / self.clock.period;
        let m = -(self.gain / magnitude) * dir_rate;
        Vector3::new(
            m.x.clamp(-self.max_dipole.x, self.max_dipole.x),
            m.y.clamp(-self.max_dipole.y, self.max_dipole.y),
            m.z.clamp(-self.max_dipole.z, self.max_dipole.z),
        )
    }

    /// The field (T, body axes) at the hub state.
    #[inline]
    pub fn field_at(&self, hub: &HubState) -> Vector3<f64> {
        field_body(&self.orbit, &self.field, hub.t, hub.attitude)
    }
}

impl Effector for Magnetorquer {
    fn name(&self) -> &str {
        &self.name
    }
    fn kind(&self) -> &'static str {
        "magnetorquer"
    }
    fn num_states(&self) -> usize {
        WORK + 1
    }
    fn num_dynamic_states(&self) -> usize {
        WORK
    }
    fn state_names(&self) -> Vec<String> {
        super::environment::names(&[
            "dipole_x",
            "dipole_y",
            "dipole_z",
            "sampled_direction_x",
            "sampled_direction_y",
            "sampled_direction_z",
            "samples",
            "rotation_per_sample",
            "work",
        ])
    }
    fn initial_state(&self) -> Vec<f64> {
        vec![0.0; WORK + 1]
    }
    fn is_external(&self) -> bool {
        true
    }
    fn next_breakpoint(&self, t: f64) -> Option<f64> {
        Some(self.clock.next_tick(t))
    }
    fn at_breakpoint(&self, hub: &HubState, x: &mut [f64]) {
        let b = self.field_at(hub);
        let magnitude = b.norm();
        let dir = b / magnitude;
        let m = if x[6] > 0.0 {
            self.command(magnitude, &dir, &Vector3::new(x[3], x[4], x[5]))
        } else {
            Vector3::zeros()
        };
        x[..3].copy_from_slice(m.as_slice());
        x[3..6].copy_from_slice(dir.as_slice());
        x[6] += 1.0;
        x[TURN] = hub.omega.norm() * self.clock.period;
    }
    fn validity(&self, x: &[f64]) -> Option<Validity> {
        Some(Validity {
            value: x[TURN],
            warn: TURN_WARN,
            limit: TURN_LIMIT,
        })
    }
    fn validity_report(&self, x: &[f64]) -> (String, String) {
        (
            format!(
                "B-dot samples the field every {} s and the body turned by {:.4} rad between                  samples (warning at {TURN_WARN} rad, limit π: the backward difference lags                  the field's rate by half of that and stops damping at π, where the samples                  alias)",
                self.clock.period, x[TURN]
            ),
            "a higher `bdot.sample_rate`".into(),
        )
    }
    fn scratch_len(&self) -> usize {
        3
    }
    fn torque_only(&self) -> bool {
        true
    }
    fn torque(&self, hub: &HubState, x: &[f64]) -> Vector3<f64> {
        Self::dipole(x).cross(&self.field_at(hub))
    }
    fn couple(&self, hub: &HubState, x: &[f64], coupling: &mut HubCoupling, scratch: &mut [f64]) {
        let tau = self.torque(hub, x);
        coupling.add_torque(&tau);
        scratch[..3].copy_from_slice(tau.as_slice());
    }
    fn derivatives(
        &self,
        hub: &HubState,
        _accel: &HubAcceleration,
        _x: &[f64],
        scratch: &[f64],
        dx: &mut [f64],
    ) {
        dx[..WORK].fill(0.0);
        dx[WORK] =
            scratch[0] * hub.omega[0] + scratch[1] * hub.omega[1] + scratch[2] * hub.omega[2];
    }
    fn energy(&self, _hub: &HubState, x: &[f64]) -> EnergyAccount {
        EnergyAccount {
            work: x[WORK],
            ..EnergyAccount::default()
        }
    }
    fn telemetry_names(&self) -> Vec<String> {
        super::environment::names(&[
            "dipole_x",
            "dipole_y",
            "dipole_z",
            "torque_x",
            "torque_y",
            "torque_z",
            "b_x",
            "b_y",
            "b_z",
            "samples",
            "rotation_per_sample",
            "work",
        ])
    }
    fn telemetry(&self, hub: &HubState, x: &[f64]) -> Vec<f64> {
        let b = self.field_at(hub);
        let m = Self::dipole(x);
        let tau = m.cross(&b);
        vec![
            m.x, m.y, m.z, tau.x, tau.y, tau.z, b.x, b.y, b.z, x[6], x[TURN], x[WORK],
        ]
    }
}
