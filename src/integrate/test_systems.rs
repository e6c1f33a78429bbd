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

/// Euler's equations of a free rigid body, `I ω̇ = (I ω) × ω`, principal inertia `I` (kg·m²),
/// state `ω` (rad/s). Smooth, nonlinear and nonstiff; kinetic energy and |Iω| are conserved.
pub struct EulerBody(pub [f64; 3]);

impl OdeSystem for EulerBody {
    fn dim(&self) -> usize {
        3
    }
    fn rhs(&self, _t: f64, w: &[f64], d: &mut [f64]) {
        let i = self.0;
        let l = [i[0] * w[0], i[1] * w[1], i[2] * w[2]];
        d[0] = (l[1] * w[2] - l[2] * w[1]) / i[0];
        d[1] = (l[2] * w[0] - l[0] * w[2]) / i[1];
        d[2] = (l[0] * w[1] - l[1] * w[0]) / i[2];
    }
}

/// A stiff damped spring driven towards a slowly moving anchor:
/// `x'' = −k (x − a sin t) − c x'`, state `(x, x')`. With `a = 0`, free decay.
pub struct StiffSpring {
    /// Stiffness per unit mass (1/s²).
    pub k: f64,
    /// Damping per unit mass (1/s).
    pub c: f64,
    /// Anchor amplitude (m).
    pub a: f64,
}

impl OdeSystem for StiffSpring {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, t: f64, y: &[f64], d: &mut [f64]) {
        d[0] = y[1];
        d[1] = -self.k * (y[0] - self.a * t.sin()) - self.c * y[1];
    }
}

/// Robertson's chemical kinetics (Hairer & Wanner, *Solving ODEs II*, §IV.1), the classic
/// stiff test: from (1, 0, 0), rate constants 0.04, 3·10⁷, 10⁴.
pub struct Robertson;

impl OdeSystem for Robertson {
    fn dim(&self) -> usize {
        3
    }
    fn rhs(&self, _t: f64, y: &[f64], d: &mut [f64]) {
        let r1 = 0.04 * y[0];
        let r2 = 3e7 * y[1] * y[1];
        let r3 = 1e4 * y[1] * y[2];
        d[0] = -r1 + r3;
        d[1] = r1 - r2 - r3;
        d[2] = r2;
    }
}

/// Van der Pol's oscillator in Hairer & Wanner's scaled form (*Solving ODEs II*, §IV.1):
/// `y₁' = y₂`, `ε y₂' = (1 − y₁²) y₂ − y₁` (ε = 1/μ²).
pub struct VanDerPol(pub f64);

impl OdeSystem for VanDerPol {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, _t: f64, y: &[f64], d: &mut [f64]) {
        d[0] = y[1];
        d[1] = ((1.0 - y[0] * y[0]) * y[1] - y[0]) / self.0;
    }
}

/// Planar two-body problem `r'' = −r/|r|³` (μ = 1), state `(x, y, vx, vy)`.
///
/// [`kepler_exact`] gives the solution from periapsis of the orbit with semi-major axis 1, so
/// the error of a nonlinear problem can be measured without a reference run.
pub struct Kepler;

impl OdeSystem for Kepler {
    fn dim(&self) -> usize {
        4
    }
    fn rhs(&self, _t: f64, y: &[f64], d: &mut [f64]) {
        let r2 = y[0] * y[0] + y[1] * y[1];
        let r3 = r2 * r2.sqrt();
        d[0] = y[2];
        d[1] = y[3];
        d[2] = -y[0] / r3;
        d[3] = -y[1] / r3;
    }
}

/// Exact state of [`Kepler`] at `t` on the orbit of eccentricity `e` (a = 1, period 2π) that
/// is at periapsis on the +x axis at t = 0.
pub fn kepler_exact(e: f64, t: f64) -> [f64; 4] {
    // Kepler's equation E − e sin E = t by Newton from E = t (converges for e < 1).
    let mut ea = t;
    for _ in 0..50 {
        let d = (ea - e * ea.sin() - t) / (1.0 - e * ea.cos());
        ea -= d;
        if d.abs() < 1e-16 {
            break;
        }
    }
    let (s, c) = ea.sin_cos();
    let b = (1.0 - e * e).sqrt();
    let edot = 1.0 / (1.0 - e * c);
    [c - e, b * s, -s * edot, b * c * edot]
}

/// Wraps a system and counts its right-hand-side calls, to check a stepper's own count.
pub struct Counted<'a, S: ?Sized> {
    /// The wrapped system.
    pub sys: &'a S,
    /// Calls so far.
    pub calls: std::cell::Cell<u64>,
}

impl<'a, S: OdeSystem + ?Sized> Counted<'a, S> {
    /// Wraps `sys` with a zero count.
    pub fn new(sys: &'a S) -> Self {
        Counted {
            sys,
            calls: std::cell::Cell::new(0),
        }
    }
}

impl<S: OdeSystem + ?Sized> OdeSystem for Counted<'_, S> {
    fn dim(&self) -> usize {
        self.sys.dim()
    }
    fn rhs(&self, t: f64, y: &[f64], d: &mut [f64]) {
        self.calls.set(self.calls.get() + 1);
        self.sys.rhs(t, y, d);
    }
}
