//! A smooth function of one variable on an interval, held as its Chebyshev interpolant, with
//! exact derivatives of the interpolant.
//!
//! On [a, b], with s = (2x − a − b)/(b − a), the interpolant through the N Chebyshev points
//! of the first kind s_j = cos(π (j + ½)/N) is p(s) = Σ_{k<N} c_k T_k(s) with
//! c_k = (2 − δ_k0)/N Σ_j f(x_j) cos(π k (j + ½)/N) (Trefethen, *Approximation Theory and
//! Approximation Practice*, 2013, ch. 3–4; for an analytic f the error falls geometrically
//! with N). The derivative's coefficients follow from d_{k−1} = d_{k+1} + 2k c_k, d_N =
//! d_{N+1} = 0, with d_0 halved (Mason & Handscomb, *Chebyshev Polynomials*, 2003, §2.4.5), and
//! the series are summed by Clenshaw's recurrence. Used where a model's parameters, slow to
//! compute, must be followed along a run with their rates: the derivatives are those of the
//! interpolant itself, so equations built from p, p′ and p″ are consistent with each other to
//! rounding, and the interpolant's distance from the function is measured at load
//! ([`Chebyshev::max_error`]).

use std::f64::consts::PI;

/// A Chebyshev interpolant on [a, b] with its first two derivatives' series.
#[derive(Debug, Clone, PartialEq)]
pub struct Chebyshev {
    a: f64,
    b: f64,
    value: Vec<f64>,
    first: Vec<f64>,
    second: Vec<f64>,
}

/// The coefficients c_k of the interpolant through `values` at the n Chebyshev points of the
/// first kind s_j = cos(π (j + ½)/n) of [−1, 1] (n = `values.len()`).
pub fn coefficients(values: &[f64]) -> Vec<f64> {
    let n = values.len();
    (0..n)
        .map(|k| {
            let sum: f64 = values
                .iter()
                .enumerate()
                .map(|(j, f)| f * (PI * k as f64 * (j as f64 + 0.5) / n as f64).cos())
                .sum();
            (if k == 0 { 1.0 } else { 2.0 }) * sum / n as f64
        })
        .collect()
}

/// The coefficients of the derivative (with respect to s) of Σ c_k T_k(s).
fn derivative(c: &[f64]) -> Vec<f64> {
    let n = c.len();
    if n < 2 {
        return vec![0.0];
    }
    let mut d = vec![0.0; n + 1];
    for k in (1..n).rev() {
        d[k - 1] = d[k + 1] + 2.0 * k as f64 * c[k];
    }
    d[0] *= 0.5;
    d.truncate(n - 1);
    d
}

/// Σ c_k T_k(s) by Clenshaw's recurrence (`c` not empty).
#[inline]
pub fn clenshaw(c: &[f64], s: f64) -> f64 {
    let (mut b1, mut b2) = (0.0, 0.0);
    for &ck in c.iter().skip(1).rev() {
        let b0 = ck + 2.0 * s * b1 - b2;
        b2 = b1;
        b1 = b0;
    }
    c[0] + s * b1 - b2
}

impl Chebyshev {
    /// The `n` Chebyshev points of the first kind on [a, b], in decreasing order.
    pub fn nodes(a: f64, b: f64, n: usize) -> Vec<f64> {
        (0..n)
            .map(|j| {
                let s = (PI * (j as f64 + 0.5) / n as f64).cos();
                0.5 * (a + b) + 0.5 * (b - a) * s
            })
            .collect()
    }

    /// The interpolant on [a, b] (a < b) through `values` at [`Chebyshev::nodes`]`(a, b, n)`,
    /// n = `values.len()` ≥ 1.
    pub fn from_samples(a: f64, b: f64, values: &[f64]) -> Chebyshev {
        let value = coefficients(values);
        let scale = 2.0 / (b - a);
        let first: Vec<f64> = derivative(&value).iter().map(|d| d * scale).collect();
        let second: Vec<f64> = derivative(&first).iter().map(|d| d * scale).collect();
        Chebyshev {
            a,
            b,
            value,
            first,
            second,
        }
    }

    /// The interval [a, b].
    pub fn interval(&self) -> (f64, f64) {
        (self.a, self.b)
    }

    /// p(x), p′(x) and p″(x).
    pub fn at(&self, x: f64) -> [f64; 3] {
        let s = (2.0 * x - self.a - self.b) / (self.b - self.a);
        [
            clenshaw(&self.value, s),
            clenshaw(&self.first, s),
            clenshaw(&self.second, s),
        ]
    }

    /// Σ |c_k| over the last `k` coefficients of the series: for a smooth function, an
    /// estimate of the interpolant's distance from it (the series has converged when its tail
    /// is at the function's own noise).
    pub fn tail(&self, k: usize) -> f64 {
        let n = self.value.len();
        self.value[n.saturating_sub(k)..]
            .iter()
            .map(|c| c.abs())
            .sum()
    }

    /// The largest |p(x) − f(x)| over `checks` points (x, f(x)).
    pub fn max_error(&self, checks: &[(f64, f64)]) -> f64 {
        checks
            .iter()
            .map(|&(x, f)| (self.at(x)[0] - f).abs())
            .fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_analytic_function_and_its_derivatives_are_reproduced() {
        // f = e^x sin 3x on [0.2, 1.1]: f′ and f″ by hand.
        let f = |x: f64| x.exp() * (3.0 * x).sin();
        let df = |x: f64| x.exp() * ((3.0 * x).sin() + 3.0 * (3.0 * x).cos());
        let d2f = |x: f64| x.exp() * (6.0 * (3.0 * x).cos() - 8.0 * (3.0 * x).sin());
        let (a, b) = (0.2, 1.1);
        let values: Vec<f64> = Chebyshev::nodes(a, b, 24).iter().map(|&x| f(x)).collect();
        let p = Chebyshev::from_samples(a, b, &values);
        for k in 0..=50 {
            let x = a + (b - a) * k as f64 / 50.0;
            let [v, d1, d2] = p.at(x);
            assert!((v - f(x)).abs() < 1e-13, "p at {x}: {v} against {}", f(x));
            assert!(
                (d1 - df(x)).abs() < 1e-11,
                "p′ at {x}: {d1} against {}",
                df(x)
            );
            assert!(
                (d2 - d2f(x)).abs() < 1e-8,
                "p″ at {x}: {d2} against {}",
                d2f(x)
            );
        }
    }

    #[test]
    fn a_polynomial_is_exact_and_low_orders_have_their_derivatives() {
        // 1 + 2x − x³ on [−1, 3] from 4 points: exact.
        let f = |x: f64| 1.0 + 2.0 * x - x * x * x;
        let values: Vec<f64> = Chebyshev::nodes(-1.0, 3.0, 4)
            .iter()
            .map(|&x| f(x))
            .collect();
        let p = Chebyshev::from_samples(-1.0, 3.0, &values);
        let [v, d1, d2] = p.at(2.0);
        assert!((v + 3.0).abs() < 1e-13);
        assert!((d1 + 10.0).abs() < 1e-12);
        assert!((d2 + 12.0).abs() < 1e-11);
        let constant = Chebyshev::from_samples(0.0, 1.0, &[5.0]);
        assert_eq!(constant.at(0.3), [5.0, 0.0, 0.0]);
    }
}
