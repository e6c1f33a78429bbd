//! A spacecraft is a rigid hub plus effectors.
//!
//! The hub carries 7 states, body rates ω (rad/s) and the attitude quaternion `(w, x, y, z)`
//! (body → inertial). Each [`Effector`] appends its own states and couples to the hub through
//! [`HubCoupling`]: it may add torque and (for internal degrees of freedom, by back-substitution
//! of its own accelerations) effective inertia to the hub's rotational equation
//!
//! ```text
//! (I + Σ ΔI_e) ω̇ = −ω × (I ω) + Σ τ_e,
//! ```
//!
//! after which each effector computes its own state derivatives from ω̇. A scene without
//! effectors integrates exactly 7 numbers and takes a path with no matrix solve.

mod body;
mod observe;

pub use body::{InertiaError, RigidBody};
pub use observe::{Invariants, Observation};

use crate::integrate::OdeSystem;
use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use std::fmt::Debug;

/// Number of hub states: ω (3) and q (4).
pub const HUB_STATES: usize = 7;

/// What effectors add to the hub's rotational equation `inertia · ω̇ = torque` (body frame,
/// about the system centre of mass).
#[derive(Debug, Clone, PartialEq)]
pub struct HubCoupling {
    /// Effective inertia (kg m²): starts as the hub's tensor; internal degrees of freedom add
    /// their back-substituted coupling.
    pub inertia: Matrix3<f64>,
    /// Torque (N m): starts as the gyroscopic term −ω × (Iω); effectors add theirs.
    pub torque: Vector3<f64>,
}

/// Read-only view of the hub state an effector sees.
#[derive(Debug, Clone, Copy)]
pub struct HubState<'a> {
    /// Simulation time (s).
    pub t: f64,
    /// Body rates (rad/s).
    pub omega: Vector3<f64>,
    /// Attitude quaternion (w, x, y, z), body → inertial, as integrated (not normalised).
    pub attitude: &'a [f64],
}

/// A part of the spacecraft with its own states and couplings (dampers, appendages, torques).
///
/// Implementations must keep `num_states()` fixed for their lifetime.
pub trait Effector: Debug + Send + Sync {
    /// Unique name within the spacecraft (used for telemetry topics).
    fn name(&self) -> &str;
    /// Number of states this effector appends to the state vector.
    fn num_states(&self) -> usize;
    /// Names of its states, for logs (length `num_states()`).
    fn state_names(&self) -> Vec<String>;
    /// Initial values of its states.
    fn initial_state(&self) -> Vec<f64>;
    /// Adds torque and effective inertia to the hub equation, given its own states `x`.
    fn couple(&self, hub: &HubState, x: &[f64], coupling: &mut HubCoupling);
    /// Writes the derivatives of its own states given the hub acceleration `omega_dot`.
    fn derivatives(&self, hub: &HubState, omega_dot: &Vector3<f64>, x: &[f64], dx: &mut [f64]);
    /// Angular momentum it carries beyond the rigid hub's (N m s, body frame).
    fn angular_momentum(&self, _hub: &HubState, _x: &[f64]) -> Vector3<f64> {
        Vector3::zeros()
    }
    /// Kinetic energy it carries beyond the rigid hub's (J).
    fn kinetic_energy(&self, _hub: &HubState, _x: &[f64]) -> f64 {
        0.0
    }
}

/// The hub plus its effectors: an [`OdeSystem`] over `[ω, q, effector states…]`.
#[derive(Debug)]
pub struct Spacecraft {
    /// The rigid hub.
    pub hub: RigidBody,
    /// Unit vector in body axes whose angle to H is the reported nutation angle.
    pub spin_axis: Vector3<f64>,
    effectors: Vec<Box<dyn Effector>>,
    /// When the body axes are principal: `[(I2−I3)/I1, (I3−I1)/I2, (I1−I2)/I3]`, the
    /// coefficients of Euler's equations in their 3-term form (exact, fewer operations).
    euler_coefficients: Option<[f64; 3]>,
    /// Offset of each effector's states in the state vector.
    offsets: Vec<usize>,
    dim: usize,
}

impl Spacecraft {
    /// A rigid spacecraft with no effectors. `spin_axis` is normalised here.
    pub fn new(hub: RigidBody, spin_axis: Vector3<f64>) -> Self {
        let i = &hub.inertia;
        let diagonal = (0..3).all(|r| (0..3).all(|c| r == c || i[(r, c)] == 0.0));
        let euler_coefficients = diagonal.then(|| {
            let (a, b, c) = (i[(0, 0)], i[(1, 1)], i[(2, 2)]);
            [(b - c) / a, (c - a) / b, (a - b) / c]
        });
        Spacecraft {
            euler_coefficients,
            hub,
            spin_axis: spin_axis.normalize(),
            effectors: Vec::new(),
            offsets: Vec::new(),
            dim: HUB_STATES,
        }
    }

    /// Appends an effector; its states follow those already present.
    pub fn add_effector(&mut self, effector: Box<dyn Effector>) {
        self.offsets.push(self.dim);
        self.dim += effector.num_states();
        self.effectors.push(effector);
    }

    /// The effectors, in state order.
    pub fn effectors(&self) -> &[Box<dyn Effector>] {
        &self.effectors
    }

    /// The initial state vector for body rates `omega` (rad/s) and attitude `q`.
    pub fn initial_state(&self, omega: &Vector3<f64>, q: &UnitQuaternion<f64>) -> Vec<f64> {
        let mut y = Vec::with_capacity(self.dim);
        y.extend_from_slice(omega.as_slice());
        y.extend_from_slice(&[q.w, q.i, q.j, q.k]);
        for e in &self.effectors {
            y.extend(e.initial_state());
        }
        y
    }

    /// The slice of `y` holding effector `index`'s states.
    pub fn effector_states<'a>(&self, index: usize, y: &'a [f64]) -> &'a [f64] {
        let start = self.offsets[index];
        &y[start..start + self.effectors[index].num_states()]
    }

    /// Derived quantities (momentum, energy, angles) at state `y`.
    pub fn observe(&self, t: f64, y: &[f64]) -> Observation {
        observe::observe(self, t, y)
    }

    /// Momentum, energy and `|q|` only (no angles): cheap enough for every step.
    pub fn invariants(&self, t: f64, y: &[f64]) -> Invariants {
        observe::invariants(self, t, y).0
    }

    /// Hub acceleration ω̇ (rad/s²) for the hub-only case: `I⁻¹ (−ω × Iω)`.
    #[inline(always)]
    fn rigid_omega_dot(&self, omega: &Vector3<f64>) -> Vector3<f64> {
        if let Some([c1, c2, c3]) = self.euler_coefficients {
            return Vector3::new(
                c1 * omega[1] * omega[2],
                c2 * omega[2] * omega[0],
                c3 * omega[0] * omega[1],
            );
        }
        let h = self.hub.inertia * omega;
        self.hub.inertia_inv * (-omega.cross(&h))
    }
}

/// `q̇ = ½ q ⊗ (0, ω)` for `q = (w, x, y, z)`, written into `dq`.
#[inline(always)]
pub fn quaternion_rate(q: &[f64], omega: &Vector3<f64>, dq: &mut [f64]) {
    let (w, x, y, z) = (q[0], q[1], q[2], q[3]);
    let (p, r, s) = (omega[0], omega[1], omega[2]);
    dq[0] = -0.5 * (x * p + y * r + z * s);
    dq[1] = 0.5 * (w * p + y * s - z * r);
    dq[2] = 0.5 * (w * r + z * p - x * s);
    dq[3] = 0.5 * (w * s + x * r - y * p);
}

impl OdeSystem for Spacecraft {
    fn dim(&self) -> usize {
        self.dim
    }

    #[inline(always)]
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        let hub_y = &y[..HUB_STATES];
        let omega = Vector3::new(hub_y[0], hub_y[1], hub_y[2]);
        let omega_dot = if self.effectors.is_empty() {
            self.rigid_omega_dot(&omega)
        } else {
            let hub = HubState {
                t,
                omega,
                attitude: &y[3..7],
            };
            let mut coupling = HubCoupling {
                inertia: self.hub.inertia,
                torque: -omega.cross(&(self.hub.inertia * omega)),
            };
            for (e, &off) in self.effectors.iter().zip(&self.offsets) {
                e.couple(&hub, &y[off..off + e.num_states()], &mut coupling);
            }
            let omega_dot = coupling
                .inertia
                .lu()
                .solve(&coupling.torque)
                .unwrap_or_else(|| Vector3::repeat(f64::NAN));
            for (e, &off) in self.effectors.iter().zip(&self.offsets) {
                let n = e.num_states();
                e.derivatives(&hub, &omega_dot, &y[off..off + n], &mut dydt[off..off + n]);
            }
            omega_dot
        };
        let hub_dy = &mut dydt[..HUB_STATES];
        hub_dy[0] = omega_dot[0];
        hub_dy[1] = omega_dot[1];
        hub_dy[2] = omega_dot[2];
        quaternion_rate(&hub_y[3..7], &omega, &mut hub_dy[3..7]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A body-fixed constant external torque with one bookkeeping state: the work it has done
    /// (J), so W' = τ·ω. Exercises the effector interface: coupling, own states, layout.
    #[derive(Debug)]
    struct ConstantTorque(Vector3<f64>);
    impl Effector for ConstantTorque {
        fn name(&self) -> &str {
            "constant_torque"
        }
        fn num_states(&self) -> usize {
            1
        }
        fn state_names(&self) -> Vec<String> {
            vec!["work".into()]
        }
        fn initial_state(&self) -> Vec<f64> {
            vec![0.0]
        }
        fn couple(&self, _hub: &HubState, _x: &[f64], c: &mut HubCoupling) {
            c.torque += self.0;
        }
        fn derivatives(&self, hub: &HubState, _wd: &Vector3<f64>, _x: &[f64], dx: &mut [f64]) {
            dx[0] = self.0.dot(&hub.omega);
        }
    }

    #[test]
    fn quaternion_rate_is_half_q_times_omega() {
        let q = UnitQuaternion::from_euler_angles(0.3, -0.2, 1.1);
        let w = Vector3::new(0.4, -1.3, 0.7);
        let expected = q.quaternion() * nalgebra::Quaternion::from_imag(w) * 0.5;
        let mut dq = [0.0; 4];
        quaternion_rate(&[q.w, q.i, q.j, q.k], &w, &mut dq);
        let got = nalgebra::Quaternion::new(dq[0], dq[1], dq[2], dq[3]);
        approx::assert_relative_eq!(got, expected, epsilon = 1e-15);
    }

    #[test]
    fn effector_states_follow_the_hub_and_work_balances_energy() {
        use crate::integrate::{Dopri5, Stepper, Tolerances};
        let hub = RigidBody::from_principal([1.0, 2.0, 3.0]).unwrap();
        let mut sc = Spacecraft::new(hub, Vector3::z());
        let tau = Vector3::new(0.01, -0.02, 0.005);
        sc.add_effector(Box::new(ConstantTorque(tau)));
        assert_eq!(sc.dim(), 8);
        let y0 = sc.initial_state(&Vector3::new(0.3, 0.5, 0.8), &UnitQuaternion::identity());
        let t0 = sc.observe(0.0, &y0).kinetic_energy;
        let tol = Tolerances {
            rtol: 1e-12,
            atol: 1e-14,
        };
        let mut s = Dopri5::new(0.0, &y0, tol, f64::INFINITY, None);
        while s.t() < 20.0 {
            s.step(&sc, 20.0).unwrap();
        }
        let y = s.y();
        let t1 = sc.observe(20.0, y).kinetic_energy;
        // Work–energy theorem: the change in T equals the work done by the torque.
        approx::assert_relative_eq!(t1 - t0, y[7], max_relative = 1e-9);
        assert!(y[7].abs() > 1e-3, "the torque must have done work");
    }
}
