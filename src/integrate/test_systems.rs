//! Small ODEs with known solutions, shared by the integrators' tests.

use super::OdeSystem;

/// `y' = 1`: the solution is the elapsed time, so it measures the time actually integrated.
pub struct Clock;

impl OdeSystem for Clock {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, _t: f64, _y: &[f64], d: &mut [f64]) {
        d[0] = 1.0;
    }
}

/// `y' = λ y`: `y(t) = y(0) e^{λt}`.
pub struct Exponential(pub f64);

impl OdeSystem for Exponential {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, _t: f64, y: &[f64], d: &mut [f64]) {
        d[0] = self.0 * y[0];
    }
}

/// The harmonic oscillator `y'' = −y` as a system: from (1, 0), `(cos t, −sin t)`.
pub struct Oscillator;

impl OdeSystem for Oscillator {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, _t: f64, y: &[f64], d: &mut [f64]) {
        d[0] = y[1];
        d[1] = -y[0];
    }
}

/// The torque-free rigid body: Euler's equations for `ω_B` (rad/s) with principal moments of
/// inertia `I` (kg m²), and the attitude quaternion `q = (w, x, y, z)` (body→inertial) with
/// `q̇ = ½ q ⊗ (0, ω)`. State `[ω (3), q (4)]`, the layout of the real model. Kinetic energy
/// `½ ωᵀIω`, `|Iω|²` and `|q|²` are quadratic first integrals.
pub struct RigidBody(pub [f64; 3]);

impl RigidBody {
    /// Kinetic energy `½ ωᵀ I ω` (J).
    pub fn energy(&self, y: &[f64]) -> f64 {
        0.5 * (0..3).map(|i| self.0[i] * y[i] * y[i]).sum::<f64>()
    }
    /// Magnitude of the angular momentum `|I ω|` (N m s).
    pub fn momentum(&self, y: &[f64]) -> f64 {
        (0..3)
            .map(|i| (self.0[i] * y[i]).powi(2))
            .sum::<f64>()
            .sqrt()
    }
}

impl OdeSystem for RigidBody {
    fn dim(&self) -> usize {
        7
    }
    fn rhs(&self, _t: f64, y: &[f64], d: &mut [f64]) {
        let [i1, i2, i3] = self.0;
        let (p, r, s) = (y[0], y[1], y[2]);
        d[0] = (i2 - i3) * r * s / i1;
        d[1] = (i3 - i1) * s * p / i2;
        d[2] = (i1 - i2) * p * r / i3;
        let (w, x, yq, z) = (y[3], y[4], y[5], y[6]);
        d[3] = -0.5 * (x * p + yq * r + z * s);
        d[4] = 0.5 * (w * p + yq * s - z * r);
        d[5] = 0.5 * (w * r + z * p - x * s);
        d[6] = 0.5 * (w * s + x * r - yq * p);
    }
}

/// `y' = y²`: from `y(0) = 1`, `y = 1/(1 − t)`, which blows up at `t = 1`.
pub struct Quadratic;

impl OdeSystem for Quadratic {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, _t: f64, y: &[f64], d: &mut [f64]) {
        d[0] = y[0] * y[0];
    }
}

/// The spring `x'' = −k x` as the system `(x, v)`; energy `½ v² + ½ k x²`.
pub struct Spring(pub f64);

impl OdeSystem for Spring {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, _t: f64, y: &[f64], d: &mut [f64]) {
        d[0] = y[1];
        d[1] = -self.0 * y[0];
    }
}
