//! What `method: averaged` asks of an effector: its effect averaged over one period of the
//! torque-free motion at the current slow state (docs/averaging.md).

use nalgebra::{Matrix3, Vector3};

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
    /// Time (s): an effector driven by the orbit reads its slowly varying forcing at it.
    pub t: f64,
    /// The unit vector along H in inertial axes.
    pub h_hat: Vector3<f64>,
}

/// An effector's period-averaged rates.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SecularRates {
    /// ⟨dT/dt⟩ (W) that it causes.
    pub energy_rate: f64,
    /// ⟨d|H|/dt⟩ (N m) that it causes.
    pub h_rate: f64,
    /// ⟨dW/dt⟩ (W) of its one bookkeeping state (the energy it has dissipated, or the work
    /// it has done).
    pub dissipation_rate: f64,
    /// The part of its mean torque across H (N m, inertial axes), which turns H: zero for a
    /// torque that does not depend on the attitude.
    pub torque_across: Vector3<f64>,
}

/// The orbit-driven forcing an effector is averaged over, which bounds where averaging holds
/// (docs/averaging.md, "Eddy currents").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Forcing {
    /// The shortest period of the forcing (s): the orbit period. The fast motion must be much
    /// faster than it.
    pub period: f64,
    /// The longest period it is averaged over (s): the averaging window (a sidereal day).
    /// The dissipation must be much slower than it.
    pub window: f64,
}

/// An effector's averaged effect, owned by the averaged method for the whole run.
pub trait Secular: std::fmt::Debug + Send + Sync {
    /// Its rates averaged over one period of `motion`.
    fn rates(&self, motion: &SecularMotion) -> SecularRates;
    /// Readies it for the hub of inertia `inertia` (kg m², body axes); `Err` (why, in words)
    /// when it cannot be averaged on that hub. The default accepts every hub.
    fn prepare(&mut self, _inertia: &Matrix3<f64>) -> Result<(), String> {
        Ok(())
    }
    /// The forcing it is averaged over, when it depends on the orbit (then the averaged
    /// state carries the direction of H); `None` (the default) for a torque of the rates
    /// alone.
    fn forcing(&self) -> Option<Forcing> {
        None
    }
    /// Whether, on an axisymmetric hub, its rates do not depend on the body's turn about the
    /// symmetry axis (only on the precession of that axis about H): then averaging does not
    /// need the polhode period (the period of that turn) to be short, only the precession's.
    /// `false` (the default) for any other.
    fn phase_free(&self) -> bool {
        false
    }
}
