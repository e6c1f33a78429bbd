//! What `method: averaged` asks of an effector: its effect averaged over one period of the
//! torque-free motion at the current slow state (docs/averaging.md).

use nalgebra::Matrix3;

/// The torque-free motion an effector is averaged over.
#[derive(Debug, Clone, Copy)]
pub struct SecularMotion<'a> {
    /// ⟨ω ωᵀ⟩ over one polhode period, body axes (rad²/s²).
    pub omega_omega: Matrix3<f64>,
    /// |H| (N m s).
    pub h: f64,
    /// Rotational kinetic energy T (J).
    pub energy: f64,
    /// The hub's inertia, body axes (kg m²).
    pub inertia: &'a Matrix3<f64>,
}

/// An effector's period-averaged rates.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SecularRates {
    /// ⟨dT/dt⟩ (W) that it causes.
    pub energy_rate: f64,
    /// ⟨d|H|/dt⟩ (N m) that it causes.
    pub h_rate: f64,
    /// ⟨dW/dt⟩ (W) of its one bookkeeping state, the energy it has dissipated.
    pub dissipation_rate: f64,
}

/// An effector's averaged effect, owned by the averaged method for the whole run.
pub trait Secular: std::fmt::Debug + Send + Sync {
    /// Its rates averaged over one period of `motion`.
    fn rates(&self, motion: &SecularMotion) -> SecularRates;
}
