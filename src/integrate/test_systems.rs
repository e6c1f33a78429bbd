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
