//! Effectors with internal degrees of freedom (dampers, hinged rods, modal appendages):
//! their dissipation averaged over their periodic response to the torque-free motion of the
//! locked spacecraft, tabulated in T at fixed |H| once per scene (docs/averaging.md).
//!
//! At a slow state (|H|, T) the locked spacecraft (effectors frozen in their initial
//! configuration, inertia J_c) turns as a torque-free rigid body with polhode period P. Its
//! rates ω(t) and ω̇(t) = J_c⁻¹((J_c ω) × ω) drive the effectors (one-way coupling: the
//! prescribed-hub equations of the full model). Their periodic response x(t + P) = x(t) is
//! found by shooting (Newton's method on the period map, its Jacobian by finite
//! differences), and each effector's dissipated energy over one period of it, divided by P,
//! is its averaged dissipation power at that T.

use crate::exact::TorqueFreeSolution;
use crate::integrate::{Dop853, OdeSystem, Stepper, Tolerances};
use crate::model::Spacecraft;
use nalgebra::{DMatrix, DVector, Matrix3, UnitQuaternion, Vector3};

/// The spacecraft's effectors driven by a prescribed torque-free hub motion.
struct Driven<'a> {
    sc: &'a Spacecraft,
    motion: &'a TorqueFreeSolution,
    inertia: Matrix3<f64>,
    inertia_inv: Matrix3<f64>,
}

impl OdeSystem for Driven<'_> {
    fn dim(&self) -> usize {
        self.sc.dim()
    }
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        let omega = self.motion.omega_at(t);
        let omega_dot = self.inertia_inv * (self.inertia * omega).cross(&omega);
        let mut state = y.to_vec();
        state[..3].copy_from_slice(omega.as_slice());
        self.sc
            .rhs_prescribed(t, &state, &omega_dot, true, dydt);
        dydt[..3].copy_from_slice(omega_dot.as_slice());
    }
}

/// The periodic response at one slow state.
#[derive(Debug, Clone)]
pub struct PeriodicResponse {
    /// Polhode period P (s).
    pub period: f64,
    /// Each dissipating effector's energy dissipated over one period, over P (W).
    pub powers: Vec<f64>,
    /// Newton iterations taken.
    pub iterations: usize,
    /// |x(P) − x(0)| at the solution, relative to max(|x|, 1e-6).
    pub residual: f64,
}

/// Which states of the spacecraft the shooting solves for, and where each effector's dissipated
/// energy is.
#[derive(Debug, Clone)]
pub struct Layout {
    /// Indices of the effectors' dynamic states in the state vector.
    pub dynamic: Vec<usize>,
    /// Index of each averaged effector's dissipated energy in the state vector.
    pub dissipated: Vec<usize>,
}

/// Integrates `y` over [0, `period`] under `system`.
fn flow(system: &Driven, y: &mut [f64], period: f64, rtol: f64) -> Result<(), String> {
    let tol = Tolerances {
        rtol,
        atol: rtol * 1e-3,
    };
    let mut stepper = Dop853::new(0.0, y, tol, f64::INFINITY, None).with_dense_output(false);
    while stepper.t() < period {
        stepper
            .step(system, period)
            .map_err(|e| format!("the driven effectors could not be integrated: {e}"))?;
    }
    y.copy_from_slice(stepper.y());
    Ok(())
}

/// The periodic response of the effectors of `sc` (state layout `layout`, starting guess
/// `guess` for the dynamic states, the rest of the state from `y0`) to the torque-free motion
/// of the locked body `inertia` with rates `omega_ref` at t = 0.
pub fn periodic_response(
    sc: &Spacecraft,
    y0: &[f64],
    layout: &Layout,
    inertia: &Matrix3<f64>,
    omega_ref: &Vector3<f64>,
    guess: &[f64],
    rtol: f64,
) -> Result<(PeriodicResponse, Vec<f64>), String> {
    let motion = TorqueFreeSolution::new(inertia, omega_ref, &UnitQuaternion::identity())
        .map_err(|e| format!("the locked spacecraft's motion: {e}"))?;
    let period = motion.polhode_period();
    if !(period.is_finite() && period > 0.0) {
        return Err("the locked spacecraft's motion has no finite period here".into());
    }
    let system = Driven {
        sc,
        motion: &motion,
        inertia: *inertia,
        inertia_inv: inertia
            .try_inverse()
            .ok_or("the locked inertia is singular")?,
    };
    let n = layout.dynamic.len();
    let start = |x: &[f64]| -> Vec<f64> {
        let mut y = y0.to_vec();
        y[..3].copy_from_slice(omega_ref.as_slice());
        for (&i, &v) in layout.dynamic.iter().zip(x) {
            y[i] = v;
        }
        for &i in &layout.dissipated {
            y[i] = 0.0;
        }
        y
    };
    let map = |x: &[f64]| -> Result<Vec<f64>, String> {
        let mut y = start(x);
        flow(&system, &mut y, period, rtol)?;
        Ok(y)
    };
    let mut x = guess.to_vec();
    let mut iterations = 0;
    let mut residual = f64::INFINITY;
    let mut end = map(&x)?;
    for _ in 0..8 {
        let g = DVector::from_iterator(n, layout.dynamic.iter().zip(&x).map(|(&i, v)| end[i] - v));
        let scale = x.iter().fold(1e-6_f64, |m, v| m.max(v.abs()));
        residual = g.amax() / scale;
        if residual < 1e-9 {
            break;
        }
        iterations += 1;
        // Jacobian of the period map minus the identity, by forward differences.
        let mut jac = DMatrix::zeros(n, n);
        for c in 0..n {
            let step = 1e-7 * scale.max(x[c].abs());
            let mut xp = x.clone();
            xp[c] += step;
            let yp = map(&xp)?;
            for (r, &i) in layout.dynamic.iter().enumerate() {
                jac[(r, c)] = (yp[i] - end[i]) / step - if r == c { 1.0 } else { 0.0 };
            }
        }
        let dx = jac
            .lu()
            .solve(&(-g))
            .ok_or("the period map's Jacobian is singular (an undamped resonance?)")?;
        for (v, d) in x.iter_mut().zip(dx.iter()) {
            *v += d;
        }
        end = map(&x)?;
    }
    if !(residual < 1e-6) {
        return Err(format!(
            "the effectors' periodic response did not converge (residual {residual:.1e})"
        ));
    }
    let powers = layout.dissipated.iter().map(|&i| end[i] / period).collect();
    Ok((
        PeriodicResponse {
            period,
            powers,
            iterations,
            residual,
        },
        x,
    ))
}
