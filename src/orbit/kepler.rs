//! Kepler's equation `E − e sin E = M` for closed orbits, `0 ≤ e < 1`.
//!
//! The solver is stateless (the result depends only on `(M, e)`, never on earlier calls),
//! so reruns are bit-for-bit identical.
//!
//! Method:
//! 1. Reduce `M` to `[−π, π]` (Cody–Waite, with 2π split in two parts) and use the odd
//!    symmetry `E(−M) = −E(M)`, so the core works on `M ∈ [0, π]`, where the root lies in
//!    the bracket `[M, min(M + e, π)]` (because `E − M = e sin E ∈ [0, e]`).
//! 2. Starter: Mikkola's cubic approximation (S. Mikkola, "A cubic approximation for
//!    Kepler's equation", *Celestial Mechanics* 40, 329–334, 1987), in which
//!    `s ≈ sin(E/3)` solves `s³ + 3αs − 2β = 0` with `α = (1 − e)/(4e + ½)`,
//!    `β = (M/2)/(4e + ½)`, corrected by `−0.078 s⁵/(1 + e)`, and `E₀ = M + e(3s − 4s³)`.
//!    Its error is below about 10⁻³ rad over the whole domain, including the hard corner
//!    `e → 1`, `M → 0` (the concern behind the starters of Vallado, *Fundamentals of
//!    Astrodynamics and Applications*, 4th ed., Algorithm 2, and of Danby and Markley).
//! 3. Halley iterations (Newton's method with the second derivative: cubic convergence),
//!    safeguarded by the bracket: every residual tightens it, and a step that would leave
//!    it is replaced by bisection, so the iteration cannot
//!    diverge; at most [`MAX_ITERATIONS`] are taken (bisection alone would reach the
//!    resolution of `f64` well before that).
//! 4. Near `e → 1` and small `E`, `E − e sin E` and `1 − e cos E` lose every digit to
//!    cancellation when evaluated directly; for `e ≥ 0.5` and `E < 1` they are evaluated
//!    as `(1 − e)E + e(E − sin E)` and `(1 − e) + e(1 − cos E)` with Taylor series for
//!    `E − sin E` and `1 − cos E` (`1 − e` is exact in floating point for `e ≥ ½`), so the
//!    relative accuracy of `E` is kept down to the smallest `M`.
//! 5. Stop when the predicted error after the last Halley step,
//!    `(f''²/(4f'²) + |f'''/(6f')|) |Δ|³`, is below ¼ ulp of `E` (and `|Δ| < 10⁻⁴`); `sin E` and `cos E` at the returned `E` are then updated from the last
//!    evaluation by a third-order Taylor step (error `< Δ⁴/24 < 10⁻¹⁷`).

use std::f64::consts::{PI, TAU};

/// Iteration cap (never reached in tests: see `docs/environment.md` for the counts).
pub const MAX_ITERATIONS: u32 = 100;

/// The low part of 2π: `2π − TAU` (TAU rounded to `f64`), for Cody–Waite reduction.
const TAU_LO: f64 = 2.449_293_598_294_706_4e-16;

/// Reduces an angle to `[−π, π]`, returning `(x − 2πk, k)` with `k` the number of turns
/// removed (as `f64`). The reduction error is about one ulp of `x`, which is the
/// resolution `x` itself carries.
pub fn reduce_angle(x: f64) -> (f64, f64) {
    if (-PI..=PI).contains(&x) {
        return (x, 0.0);
    }
    let k = (x / TAU).round();
    let r = (x - k * TAU) - k * TAU_LO;
    // Rounding can leave r a hair outside [−π, π]; that is harmless for the solver,
    // which only needs |r| ≤ π + a few ulp, but clamp so the symmetry argument holds.
    (r.clamp(-PI, PI), k)
}

/// Result of [`solve`]: the eccentric anomaly with its sine and cosine.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeplerSolution {
    /// Eccentric anomaly `E` (rad), in the same turn as `M`: `E = E_red + 2πk`.
    pub eccentric_anomaly: f64,
    /// `sin E`.
    pub sin_e: f64,
    /// `cos E`.
    pub cos_e: f64,
    /// `1 − cos E`, to full relative precision also where `cos E` rounds to 1 (small `E`):
    /// `2 sin²(E/2)` of the reduced `E`. With it `cos E − e = (1 − e) − (1 − cos E)` and
    /// `1 − e cos E = (1 − e) + e(1 − cos E)` keep their digits as `e → 1`.
    pub one_minus_cos_e: f64,
    /// Halley (or bisection) iterations taken (0 for `e = 0`, `M = 0` or `|M| = π`).
    pub iterations: u32,
}

/// Eccentric anomaly `E` (rad) solving `E − e sin E = M` for `0 ≤ e < 1` and any finite `M`.
pub fn eccentric_anomaly(mean_anomaly: f64, e: f64) -> f64 {
    solve(mean_anomaly, e).eccentric_anomaly
}

/// Solves Kepler's equation, returning `E`, `sin E`, `cos E` and the iteration count.
///
/// `e` must lie in `[0, 1)` and `mean_anomaly` must be finite (the orbit's constructor
/// guarantees both; here they are debug-asserted).
pub fn solve(mean_anomaly: f64, e: f64) -> KeplerSolution {
    debug_assert!((0.0..1.0).contains(&e), "eccentricity {e} outside [0, 1)");
    debug_assert!(mean_anomaly.is_finite(), "mean anomaly {mean_anomaly}");
    let (m_red, k) = reduce_angle(mean_anomaly);
    let (sign, m) = if m_red < 0.0 {
        (-1.0, -m_red)
    } else {
        (1.0, m_red)
    };
    let (e_red, sin_e, cos_e, iterations) = solve_reduced(m, e);
    let half_sin = (0.5 * e_red).sin();
    KeplerSolution {
        eccentric_anomaly: sign * e_red + k * TAU,
        sin_e: sign * sin_e,
        cos_e,
        one_minus_cos_e: 2.0 * half_sin * half_sin,
        iterations,
    }
}

/// `x − sin x` for `|x| < 1`, by its Taylor series (terms to x¹⁹/19!, relative error
/// below 10⁻¹⁶).
fn x_minus_sin(x: f64) -> f64 {
    let z = x * x;
    // Coefficients 1/(2k+1)! with alternating signs, k = 1..9, in Horner form.
    let p = 1.0 / 121_645_100_408_832_000.0;
    let p = -1.0 / 355_687_428_096_000.0 + z * p;
    let p = 1.0 / 1_307_674_368_000.0 + z * p;
    let p = -1.0 / 6_227_020_800.0 + z * p;
    let p = 1.0 / 39_916_800.0 + z * p;
    let p = -1.0 / 362_880.0 + z * p;
    let p = 1.0 / 5040.0 + z * p;
    let p = -1.0 / 120.0 + z * p;
    let p = 1.0 / 6.0 + z * p;
    x * z * p
}

/// `1 − cos x` for `|x| < 1`, by its Taylor series (terms to x¹⁸/18!).
fn one_minus_cos(x: f64) -> f64 {
    let z = x * x;
    let p = 1.0 / 6_402_373_705_728_000.0;
    let p = -1.0 / 20_922_789_888_000.0 + z * p;
    let p = 1.0 / 87_178_291_200.0 + z * p;
    let p = -1.0 / 479_001_600.0 + z * p;
    let p = 1.0 / 3_628_800.0 + z * p;
    let p = -1.0 / 40_320.0 + z * p;
    let p = 1.0 / 720.0 + z * p;
    let p = -1.0 / 24.0 + z * p;
    let p = 0.5 + z * p;
    z * p
}

/// Mikkola's starter for `M ∈ [0, π]`.
fn starter(m: f64, e: f64) -> f64 {
    let d = 4.0 * e + 0.5;
    let alpha = (1.0 - e) / d;
    let beta = 0.5 * m / d;
    let z = (beta + (alpha * alpha * alpha + beta * beta).sqrt()).cbrt();
    // s = z − α/z, written without the cancellation of that difference when α³ ≫ β².
    let mut s = 2.0 * beta / (z * z + alpha + alpha * alpha / (z * z));
    let s2 = s * s;
    s -= 0.078 * s2 * s2 * s / (1.0 + e);
    m + e * s * (3.0 - 4.0 * s * s)
}

/// The core solver for `M ∈ [0, π]`: returns `(E, sin E, cos E, iterations)`.
fn solve_reduced(m: f64, e: f64) -> (f64, f64, f64, u32) {
    if e == 0.0 || m == 0.0 {
        let (s, c) = m.sin_cos();
        return (m, s, c, 0);
    }
    if m == PI {
        return (PI, PI.sin(), -1.0, 0);
    }
    let (mut lo, mut hi) = (m, (m + e).min(PI));
    let mut x = starter(m, e).clamp(lo, hi);
    let one_minus_e = 1.0 - e;
    let careful = e >= 0.5;
    let mut iterations = 0;
    loop {
        iterations += 1;
        let (s, c) = x.sin_cos();
        let (f, fp) = if careful && x < 1.0 {
            (
                one_minus_e * x + e * x_minus_sin(x) - m,
                one_minus_e + e * one_minus_cos(x),
            )
        } else {
            (x - e * s - m, 1.0 - e * c)
        };
        if f == 0.0 {
            return (x, s, c, iterations);
        }
        if f < 0.0 {
            lo = lo.max(x);
        } else {
            hi = hi.min(x);
        }
        // Halley's step, with f'' = e sin E (cubic convergence).
        let fpp = e * s;
        let delta = -2.0 * f * fp / (2.0 * fp * fp - f * fpp);
        let x_new = x + delta;
        // Halley's error after this step is about |f''²/(4f'²) − f'''/(6f')| |Δ|³, with
        // f''' = e cos E; bounded here by the sum of the magnitudes.
        let g = (fpp / fp).abs();
        let predicted = (0.25 * g * g + (e * c / (6.0 * fp)).abs()) * delta.abs().powi(3);
        let within = x_new >= lo && x_new <= hi;
        if within && delta.abs() < 1e-4 && predicted <= 0.25 * f64::EPSILON * x_new {
            let d2 = 0.5 * delta * delta;
            let d3 = delta - delta * d2 / 3.0;
            let sin_new = s * (1.0 - d2) + c * d3;
            let cos_new = c * (1.0 - d2) - s * d3;
            return (x_new, sin_new, cos_new, iterations);
        }
        let inside = x_new > lo && x_new < hi;
        if !inside && hi - lo <= 2.0 * f64::EPSILON * hi {
            // The bracket is down to the resolution of f64: x is the root.
            return (x, s, c, iterations);
        }
        if iterations >= MAX_ITERATIONS {
            return (x, s, c, iterations);
        }
        x = if inside { x_new } else { 0.5 * (lo + hi) };
    }
}

/// Mean anomaly `M = E − e sin E` (rad) from the eccentric anomaly, evaluated without
/// cancellation for `e ≥ ½` and `|E| < 1` (same series as the solver).
pub fn mean_from_eccentric(eccentric_anomaly: f64, e: f64) -> f64 {
    let x = eccentric_anomaly;
    if e >= 0.5 && x.abs() < 1.0 {
        (1.0 - e) * x + e * x_minus_sin(x)
    } else {
        x - e * x.sin()
    }
}
