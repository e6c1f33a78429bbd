//! Finite-difference Jacobians, shared by the implicit methods.
//!
//! The Jacobian `J = ∂f/∂y` is formed column by column with forward differences, the
//! increment of column `j` being `√(ε·max(1e-5, |y_j|))` as in Hairer & Wanner's RADAU5
//! (*Solving ODEs II*, §IV.8): it balances truncation against rounding error.

use super::{OdeSystem, Stats};
use nalgebra::DMatrix;

/// Writes `∂f/∂y` at `(t, y)` into `jac` (n×n), given `f0 = f(t, y)`. Costs `n` evaluations of
/// the right-hand side, which are counted in `stats`.
pub fn forward_difference<S: OdeSystem + ?Sized>(
    sys: &S,
    t: f64,
    y: &[f64],
    f0: &[f64],
    jac: &mut DMatrix<f64>,
    stats: &mut Stats,
) {
    let n = y.len();
    let mut yp = y.to_vec();
    let mut fp = vec![0.0; n];
    for j in 0..n {
        let delta = (f64::EPSILON * y[j].abs().max(1e-5)).sqrt();
        yp[j] = y[j] + delta;
        // The increment actually represented.
        let dj = yp[j] - y[j];
        sys.rhs(t, &yp, &mut fp);
        for i in 0..n {
            jac[(i, j)] = (fp[i] - f0[i]) / dj;
        }
        yp[j] = y[j];
    }
    stats.rhs_evaluations += n as u64;
    stats.jacobian_evaluations += 1;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::test_systems::Oscillator;

    #[test]
    fn jacobian_of_a_linear_system_is_its_matrix() {
        let mut jac = DMatrix::zeros(2, 2);
        let mut stats = Stats::default();
        let y = [0.3, -0.7];
        let mut f0 = [0.0; 2];
        Oscillator.rhs(0.0, &y, &mut f0);
        forward_difference(&Oscillator, 0.0, &y, &f0, &mut jac, &mut stats);
        let exact = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, 0.0]);
        assert!((jac - exact).abs().max() < 1e-7);
        assert_eq!(stats.rhs_evaluations, 2);
    }
}
