//! Gauss–Legendre implicit Runge–Kutta methods (collocation at the Gauss points) with a fixed
//! step: the 1-stage implicit midpoint rule (order 2) and the 2-stage method (order 4).
//!
//! Their selling point is geometric: every Gauss method is symplectic and conserves every
//! *quadratic* first integral `yᵀCy` of the ODE exactly (Hairer, Lubich & Wanner, *Geometric
//! Numerical Integration*, 2nd ed., Thm. IV.2.2: it holds because `bᵢaᵢⱼ + bⱼaⱼᵢ = bᵢbⱼ`). For
//! the torque-free rigid body that covers the kinetic energy `½ωᵀIω`, `|Iω|²` and `|q|²`, so
//! over arbitrarily long runs they drift only by roundoff — provided that
//!
//! * the stage equations are solved to machine precision (not to a tolerance): the simplified
//!   Newton iteration below runs until its increment is a few ulps of the stage values or stops
//!   decreasing (see [`Gauss`]);
//! * the stage unknowns are `Zᵢ = Yᵢ − yₙ` (small quantities, Hairer, Lubich & Wanner §VIII.5,
//!   and Hairer & Wanner, *Solving ODEs II*, §IV.8), not the stage values themselves;
//! * the increment `yₙ₊₁ − yₙ` is added with compensated (Kahan) summation (Hairer, Lubich &
//!   Wanner §VIII.5), so the rounding of `yₙ + δ` does not random-walk the invariants;
//! * the coefficients used satisfy the conservation condition exactly in binary. The 2-stage
//!   `a₂₁` is the rounded `¼ + √3/6` and `a₁₂ = ½ − a₂₁` is computed exactly (Sterbenz), so
//!   with `b = (½, ½)` and `a₁₁ = a₂₂ = ¼` the stored tableau satisfies
//!   `bᵢaᵢⱼ + bⱼaⱼᵢ = bᵢbⱼ` exactly.
//!
//! The increment is formed the way that is exact in binary for each method (measured on the
//! tests below):
//! * 1 stage: `yₙ₊₁ = yₙ + 2Z₁` (`d = bᵀA⁻¹ = 2`, Hairer & Wanner *Solving ODEs II* §IV.8):
//!   exact coefficients *and* no amplification of the stage's roundoff on stiff problems;
//! * 2 stages: `yₙ₊₁ = yₙ + h(k₁ + k₂)/2` with the `kᵢ = f(Yᵢ)` of the last iteration. The
//!   `Z`-form `yₙ + √3(Z₂ − Z₁)` is better on stiff problems, but the rounded `√3` is not exactly
//!   `bᵀA⁻¹` of the stored tableau, which shows as a systematic drift: max `|ΔT|/T` 5e-13 over
//!   2·10⁵ steps against 3e-14 here. The price of `h Σ bᵢkᵢ` is that it multiplies the stages'
//!   roundoff by `h‖J‖` (a stiff spring at `ωh = 10³` keeps its energy to 2e-12, not 1e-14).
//!
//! Tableaux (Hairer, Lubich & Wanner §II.1.3, Table 1.1; Hairer & Wanner, *Solving ODEs II*,
//! Table IV.5.1):
//!
//! ```text
//!  s = 1:   ½ | ½          s = 2:   ½ − √3/6 | ¼          ¼ − √3/6
//!           --+--                   ½ + √3/6 | ¼ + √3/6   ¼
//!             | 1                   ---------+--------------------
//!                                            | ½          ½
//! ```
//!
//! Dense output is the collocation polynomial of the step (order `s` uniformly in the step),
//! which also provides the starting guess of the next step's iteration by extrapolation
//! (Hairer, Lubich & Wanner §VIII.6.1).

use super::grid::FixedGrid;
use super::jacobian::forward_difference;
use super::{OdeSystem, Stats, StepError, Stepper};
use nalgebra::DMatrix;

/// √3, for the 2-stage tableau and its collocation polynomial.
const SQRT3: f64 = 1.732_050_807_568_877_2;
/// √3/6.
const SQRT3_6: f64 = 0.288_675_134_594_812_9;
/// Nodes of the 2-stage method, `½ ∓ √3/6`.
const C2_1: f64 = 0.5 - SQRT3_6;
const C2_2: f64 = 0.5 + SQRT3_6;
/// `a₂₁ = ¼ + √3/6` rounded once; `a₁₂ = ½ − a₂₁` is exact (Sterbenz), so the stored
/// coefficients satisfy `a₁₂ + a₂₁ = ½` exactly.
const A2_21: f64 = 0.25 + SQRT3_6;
const A2_12: f64 = 0.5 - A2_21;
/// Lagrange-basis factors of the 2-stage collocation polynomial through `(0, 0)`, `(c₁, Z₁)`,
/// `(c₂, Z₂)`: `1/(c₁(c₂ − c₁)) = 3 + 3√3` and `1/(c₂(c₂ − c₁)) = 3√3 − 3`.
const E2_1: f64 = 3.0 + 3.0 * SQRT3;
const E2_2: f64 = 3.0 * SQRT3 - 3.0;
/// `d = bᵀA⁻¹`, `yₙ₊₁ = yₙ + Σ dᵢ Zᵢ` (for `s = 2`, `A⁻¹ = [[3, 2√3 − 3], [−3 − 2√3, 3]]`):
/// the collocation polynomial at θ = 1, used to extrapolate from the last step.
const D1: [f64; 2] = [2.0, 0.0];
const D2: [f64; 2] = [-SQRT3, SQRT3];

/// Iteration cap of the Newton iteration per attempt.
const MAX_ITERATIONS: u32 = 50;
/// Converged when every increment is at most this multiple of its stage value
/// (`|ΔZᵢⱼ| ≤ 2ε max(|Yᵢⱼ|, |Zᵢⱼ|)`, i.e. one or two ulps).
const CONVERGED_RELATIVE: f64 = 2.0 * f64::EPSILON;
/// An increment that stops decreasing is the roundoff floor (accepted) when its norm-wise size
/// `max|ΔZ| / max(|Y|, |Z|)` is below this, and divergence otherwise.
const STAGNATION_NORMWISE: f64 = 1e-13;
/// Contraction rates are measured only while the norm-wise increment is above this (below it,
/// roundoff makes the ratios noise).
const RATE_MEASURABLE: f64 = 1e-10;
/// A step whose contraction rate exceeded this asks for a fresh Jacobian for the next step.
const REFRESH_RATE: f64 = 0.01;
/// With an old Jacobian, an iteration contracting slower than this is abandoned at once and the
/// step restarted with a fresh one.
const GIVE_UP_RATE: f64 = 0.5;
/// The iteration matrix is refactorised when the step differs from the one it was built with
/// by more than this fraction (the shortened last step).
const STEP_CHANGE_REFACTOR: f64 = 1e-3;

/// Which Gauss–Legendre method: the number of stages `s` (the order is `2s`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GaussStages {
    /// The implicit midpoint rule: 1 stage, order 2.
    One,
    /// The 2-stage Gauss method (Hammer & Hollingsworth 1955): order 4.
    Two,
}

impl GaussStages {
    /// Number of stages `s`.
    pub fn count(self) -> usize {
        match self {
            GaussStages::One => 1,
            GaussStages::Two => 2,
        }
    }

    /// Classical order `2s`.
    pub fn order(self) -> usize {
        2 * self.count()
    }
}

/// Gauss–Legendre implicit Runge–Kutta, fixed step `h` (the last step is shortened to land on
/// `t_end`).
///
/// **Stage equations**, in the unknowns `Zᵢ = Yᵢ − yₙ`:
/// `Zᵢ = h Σⱼ aᵢⱼ f(tₙ + cⱼh, yₙ + Zⱼ)`, solved by simplified Newton with the iteration matrix
/// `M = I − h A⊗J` (`sn × sn`, LU with partial pivoting; for `s = 2` the real `2n × 2n` system is
/// solved directly). `J ≈ ∂f/∂y` comes from [`forward_difference`] at `(tₙ, yₙ)`; `J` and the
/// LU factors are kept over steps, and recomputed (for the next step) when a step's iteration
/// contracted slower than 0.01 per iteration, or at once (restarting the step) when an iteration
/// with an old `J` diverges or contracts slower than 0.5. Starting guess: the previous step's
/// collocation polynomial extrapolated to the new nodes (zero on the first step).
///
/// **Stopping rule.** Each iteration evaluates `kᵢ = f(tₙ + cᵢh, yₙ + Zᵢ)`, solves for the
/// increment `ΔZ` and applies it. The iteration is converged when
/// * every increment is within a couple of ulps of its stage value,
///   `|ΔZᵢⱼ| ≤ 2ε max(|Yᵢⱼ|, |Zᵢⱼ|, ε‖yₙ‖∞)` (`Zᵢⱼ` too because `Yᵢⱼ = yₙⱼ + Zᵢⱼ` can be near
///   zero by cancellation, as in a stiff decay; the last term resolves a component whose
///   solution is exactly zero, which the iteration approaches geometrically), or
/// * the increment stops decreasing (`‖ΔZ‖ ≥ ‖ΔZ_prev‖`, norm-wise
///   `max|ΔZ| / max(|Y|, |Z|)`) while below 1e-13: the roundoff floor (a component passing
///   through zero never reaches the first test).
///
/// An increment that stops decreasing above 1e-13, a non-finite value, or 50 iterations
/// without convergence is a failure: with an old Jacobian the step is retried once with a
/// fresh one, otherwise it returns [`StepError::NewtonFailure`] and the state is unchanged.
/// On convergence the step adds `2Z₁` (1 stage) or `h Σ bᵢ kᵢ` with the `kᵢ` of the last
/// iteration (2 stages; their residual is at roundoff level) with compensated summation; see
/// the module documentation for why.
///
/// Cost per step: `s` right-hand-side evaluations per Newton iteration, plus `n + 1` and one
/// LU factorisation whenever the Jacobian is refreshed; no allocation after construction
/// except inside [`forward_difference`] (on a refresh).
#[derive(Debug, Clone)]
pub struct Gauss {
    stages: GaussStages,
    s: usize,
    c: [f64; 2],
    a: [[f64; 2]; 2],
    b: [f64; 2],
    d: [f64; 2],
    /// Step n ends at `t0 + n·h` (see [`FixedGrid`]).
    grid: FixedGrid,
    t: f64,
    t_prev: f64,
    y: Vec<f64>,
    y_prev: Vec<f64>,
    /// Kahan compensation of `y`: the stored `y` minus the exact sum of the increments.
    comp: Vec<f64>,
    /// Stage unknowns `Zᵢ` (stage-major, `s·n`).
    z: Vec<f64>,
    /// Residual, then Newton increment (`s·n`).
    dz: Vec<f64>,
    /// Stage derivatives of the current iteration (`s·n`).
    k: Vec<f64>,
    /// Stage unknowns `Zᵢ` of the last accepted step: its collocation polynomial.
    z_step: Vec<f64>,
    /// A stage value `yₙ + Zᵢ`.
    y_stage: Vec<f64>,
    f0: Vec<f64>,
    jac: DMatrix<f64>,
    /// LU factors of `I − h A⊗J`, column-major `sn × sn`, and the row interchanges.
    lu: Vec<f64>,
    piv: Vec<usize>,
    /// Step the factors were built with; NaN when there are none.
    h_lu: f64,
    have_jacobian: bool,
    refresh_next: bool,
    /// Whether the starting guess extrapolates the last collocation polynomial (else zero).
    extrapolate: bool,
    /// Set by [`Stepper::restart`]: the next starting guess is zero.
    restarted: bool,
    /// Whether the increment is `h Σ bᵢ kᵢ` (2 stages) rather than `Σ dᵢ Zᵢ` (1 stage).
    update_from_k: bool,
    stats: Stats,
}

impl Gauss {
    /// Starts at `(t0, y0)` with step `h` (s, > 0) and the given method.
    pub fn new(t0: f64, y0: &[f64], h: f64, stages: GaussStages) -> Self {
        assert!(
            h > 0.0 && h.is_finite(),
            "the step must be positive, got {h}"
        );
        let n = y0.len();
        let s = stages.count();
        let m = s * n;
        let (c, a, b, d) = match stages {
            GaussStages::One => ([0.5, 0.0], [[0.5, 0.0], [0.0, 0.0]], [1.0, 0.0], D1),
            GaussStages::Two => ([C2_1, C2_2], [[0.25, A2_12], [A2_21, 0.25]], [0.5, 0.5], D2),
        };
        Gauss {
            stages,
            s,
            c,
            a,
            b,
            d,
            grid: FixedGrid::new(t0, h),
            t: t0,
            t_prev: t0,
            y: y0.to_vec(),
            y_prev: y0.to_vec(),
            comp: vec![0.0; n],
            z: vec![0.0; m],
            dz: vec![0.0; m],
            k: vec![0.0; m],
            z_step: vec![0.0; m],
            update_from_k: stages == GaussStages::Two,
            y_stage: vec![0.0; n],
            f0: vec![0.0; n],
            jac: DMatrix::zeros(n, n),
            lu: vec![0.0; m * m],
            piv: vec![0; m],
            h_lu: f64::NAN,
            have_jacobian: false,
            refresh_next: false,
            extrapolate: true,
            restarted: false,
            stats: Stats::default(),
        }
    }

    /// The nominal step (s).
    pub fn dt(&self) -> f64 {
        self.grid.dt()
    }

    /// The method.
    pub fn stages(&self) -> GaussStages {
        self.stages
    }

    /// Weights of the collocation polynomial at `θ = (t − tₙ)/h` in terms of the stages:
    /// `u(tₙ + θh) = yₙ + Σᵢ Eᵢ(θ) Zᵢ`, the Lagrange interpolant through `(0, yₙ)` and
    /// `(cᵢ, Yᵢ)` (the collocation polynomial has degree `s`; Hairer & Wanner, *Solving ODEs
    /// II*, §IV.8). `E(cⱼ) = eⱼ`, `E(1) = d`.
    #[inline]
    fn weights(&self, theta: f64) -> [f64; 2] {
        match self.stages {
            GaussStages::One => [2.0 * theta, 0.0],
            GaussStages::Two => [
                -E2_1 * theta * (theta - C2_2),
                E2_2 * theta * (theta - C2_1),
            ],
        }
    }

    /// Evaluates `J = ∂f/∂y` at the current `(t, y)`.
    fn refresh_jacobian<S: OdeSystem + ?Sized>(&mut self, sys: &S) -> Result<(), StepError> {
        sys.rhs(self.t, &self.y, &mut self.f0);
        self.stats.rhs_evaluations += 1;
        if !self.f0.iter().all(|v| v.is_finite()) {
            return Err(StepError::NonFiniteDerivative { t: self.t });
        }
        forward_difference(
            sys,
            self.t,
            &self.y,
            &self.f0,
            &mut self.jac,
            &mut self.stats,
        );
        self.have_jacobian = true;
        Ok(())
    }

    /// Builds and factorises `I − h A⊗J`. False when it is singular or not finite.
    fn factorize(&mut self, h: f64) -> bool {
        let (n, s) = (self.y.len(), self.s);
        let m = s * n;
        // Column (l, col) of block (i, l) holds −h aᵢₗ J[·, col], plus the identity.
        for l in 0..s {
            for col in 0..n {
                let column = &mut self.lu[(l * n + col) * m..(l * n + col + 1) * m];
                for i in 0..s {
                    let ha = h * self.a[i][l];
                    for (r, v) in column[i * n..(i + 1) * n].iter_mut().enumerate() {
                        *v = -ha * self.jac[(r, col)];
                    }
                }
                column[l * n + col] += 1.0;
            }
        }
        self.stats.factorizations += 1;
        self.h_lu = f64::NAN;
        if !lu_factorize(&mut self.lu, &mut self.piv, m) {
            return false;
        }
        self.h_lu = h;
        true
    }

    /// Starting guess for `Z`: the last collocation polynomial at the new nodes, minus `yₙ`
    /// (`Zᵢ⁰ = Σₗ (Eₗ(1 + cᵢh/h_p) − dₗ) Zₗ`, from the last step's stages, no cancellation).
    fn starting_guess(&mut self, h: f64) {
        let hp = self.t - self.t_prev;
        if !self.extrapolate || hp == 0.0 || self.restarted {
            self.restarted = false;
            self.z.fill(0.0);
            return;
        }
        let n = self.y.len();
        for i in 0..self.s {
            let w = self.weights(1.0 + self.c[i] * h / hp);
            let w = [w[0] - self.d[0], w[1] - self.d[1]];
            let zi = &mut self.z[i * n..(i + 1) * n];
            for (j, zij) in zi.iter_mut().enumerate() {
                let mut acc = 0.0;
                for (l, wl) in w.iter().enumerate().take(self.s) {
                    acc += wl * self.z_step[l * n + j];
                }
                *zij = acc;
            }
        }
    }

    /// Simplified Newton iteration on the stage equations (see [`Gauss::newton_sized`]), with
    /// the rigid body's sizes (n = 7) as compile-time constants: the small loops are unrolled.
    fn newton<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        h: f64,
        fresh: bool,
    ) -> Result<f64, ()> {
        match (self.s, self.y.len()) {
            (1, 7) => self.newton_sized(sys, t, h, fresh, 1, 7),
            (2, 7) => self.newton_sized(sys, t, h, fresh, 2, 7),
            (s, n) => self.newton_sized(sys, t, h, fresh, s, n),
        }
    }

    /// Simplified Newton iteration on the stage equations from the guess in `z`, with the
    /// current factors. On success the stages are in `z`, their derivatives (at the previous
    /// iterate, within roundoff of `z`) in `k`, and the largest measurable contraction rate is
    /// returned.
    ///
    /// `(s, n)` are the method's stage count and the state's length, passed in so that the
    /// common sizes can be instantiated with constants (see [`Gauss::newton`]).
    #[inline(always)]
    fn newton_sized<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        h: f64,
        fresh: bool,
        s: usize,
        n: usize,
    ) -> Result<f64, ()> {
        let m = s * n;
        let mut prev = f64::INFINITY;
        let mut rate_max: f64 = 0.0;
        // A stage component below the rounding of the state's largest component, ε |yₙ|∞,
        // is resolved at that floor: a component whose solution is exactly zero (a quaternion
        // component that stays zero by symmetry) is approached geometrically by the iteration,
        // its increment always about the size of the last value, and would otherwise never
        // meet the relative test nor stagnate (found by the `method_pairs` fuzz target).
        let floor = f64::EPSILON * self.y.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        for it in 0..MAX_ITERATIONS {
            for i in 0..s {
                let zi = &self.z[i * n..(i + 1) * n];
                for ((ys, &yj), &zj) in self.y_stage.iter_mut().zip(&self.y).zip(zi) {
                    *ys = yj + zj;
                }
                sys.rhs(
                    t + self.c[i] * h,
                    &self.y_stage,
                    &mut self.k[i * n..(i + 1) * n],
                );
            }
            self.stats.rhs_evaluations += s as u64;
            // Residual h (A⊗I) k − Z.
            let mut finite = true;
            for i in 0..s {
                let ha = [h * self.a[i][0], h * self.a[i][1]];
                for j in 0..n {
                    let mut acc = ha[0] * self.k[j];
                    if s == 2 {
                        acc += ha[1] * self.k[n + j];
                    }
                    let r = acc - self.z[i * n + j];
                    finite &= r.is_finite();
                    self.dz[i * n + j] = r;
                }
            }
            if !finite {
                return Err(());
            }
            lu_solve(&self.lu, &self.piv, m, &mut self.dz);
            self.stats.newton_iterations += 1;
            let (mut d_max, mut y_max): (f64, f64) = (0.0, 0.0);
            let mut converged = true;
            for i in 0..s {
                for j in 0..n {
                    let idx = i * n + j;
                    let d = self.dz[idx];
                    let zn = self.z[idx] + d;
                    self.z[idx] = zn;
                    // The resolution of the stage: of Yᵢ = yₙ + Zᵢ and of Zᵢ itself (Yᵢ can
                    // be near zero by cancellation, as in a stiff decay).
                    let scale = (self.y[j] + zn).abs().max(zn.abs());
                    d_max = d_max.max(d.abs());
                    y_max = y_max.max(scale);
                    // Never true for a nonzero increment to a zero stage: left to the
                    // stagnation test.
                    converged &= d.abs() <= CONVERGED_RELATIVE * scale.max(floor);
                }
            }
            if !d_max.is_finite() || !y_max.is_finite() {
                return Err(());
            }
            if converged {
                return Ok(rate_max);
            }
            let size = d_max / y_max.max(f64::MIN_POSITIVE);
            if it > 0 {
                let rate = size / prev;
                if rate >= 1.0 {
                    return if size <= STAGNATION_NORMWISE {
                        Ok(rate_max)
                    } else {
                        Err(())
                    };
                }
                if prev > RATE_MEASURABLE {
                    rate_max = rate_max.max(rate);
                    if !fresh && rate > GIVE_UP_RATE {
                        return Err(());
                    }
                }
            }
            prev = size;
        }
        Err(())
    }
}

/// LU factorisation with partial pivoting, in place, of the column-major `m × m` matrix `a`
/// (Golub & Van Loan, *Matrix Computations*, Alg. 3.4.1): `P a = L U`, unit `L` below the
/// diagonal, `U` on and above; `piv[k]` is the row swapped with row `k` at step `k`, and the
/// diagonal of `U` is replaced by its reciprocal (the solve then multiplies). Column-major so
/// that the substitutions run down columns: independent multiply-adds rather than dependent
/// dot-product chains. False when a pivot is zero or not finite.
fn lu_factorize(a: &mut [f64], piv: &mut [usize], m: usize) -> bool {
    for col in 0..m {
        let column = &a[col * m..(col + 1) * m];
        let mut p = col;
        let mut best = column[col].abs();
        for (r, v) in column.iter().enumerate().skip(col + 1) {
            if v.abs() > best {
                best = v.abs();
                p = r;
            }
        }
        if best == 0.0 || !best.is_finite() {
            return false;
        }
        piv[col] = p;
        if p != col {
            for c in 0..m {
                a.swap(c * m + col, c * m + p);
            }
        }
        let (left, right) = a.split_at_mut((col + 1) * m);
        let column = &mut left[col * m..];
        let inv = 1.0 / column[col];
        column[col] = inv;
        for l in &mut column[col + 1..] {
            *l *= inv;
        }
        let column = &left[col * m..];
        for other in right.chunks_exact_mut(m) {
            let u = other[col];
            if u != 0.0 {
                for (x, &l) in other[col + 1..].iter_mut().zip(&column[col + 1..]) {
                    *x -= l * u;
                }
            }
        }
    }
    true
}

/// Solves `a x = b` in place with the factors of [`lu_factorize`].
#[inline(always)]
fn lu_solve(lu: &[f64], piv: &[usize], m: usize, b: &mut [f64]) {
    let (lu, piv, b) = (&lu[..m * m], &piv[..m], &mut b[..m]);
    for (k, &p) in piv.iter().enumerate() {
        b.swap(k, p);
    }
    for c in 0..m {
        let x = b[c];
        let column = &lu[c * m..(c + 1) * m];
        for (bi, &l) in b[c + 1..].iter_mut().zip(&column[c + 1..]) {
            *bi -= l * x;
        }
    }
    for c in (0..m).rev() {
        let column = &lu[c * m..(c + 1) * m];
        let x = b[c] * column[c];
        b[c] = x;
        for (bi, &u) in b[..c].iter_mut().zip(&column[..c]) {
            *bi -= u * x;
        }
    }
}

impl Stepper for Gauss {
    fn t(&self) -> f64 {
        self.t
    }

    fn y(&self) -> &[f64] {
        &self.y
    }

    fn t_prev(&self) -> f64 {
        self.t_prev
    }

    fn stats(&self) -> Stats {
        self.stats
    }

    fn step<S: OdeSystem + ?Sized>(&mut self, sys: &S, t_end: f64) -> Result<f64, StepError> {
        // The step's end from the grid, landing exactly on t_end when within a small fraction
        // of a step of it; the step size is the difference of the two times, so the
        // increments add up to the times exactly.
        // A step shortened to an earlier t_end does not advance the grid index: the next step
        // then ends on the grid point it fell short of, and no step exceeds h.
        let (t_next, on_grid) = self.grid.next(t_end);
        let t = self.t;
        let h = t_next - t;
        let failure = StepError::NewtonFailure { t, h };

        let mut need_jacobian = !self.have_jacobian || self.refresh_next;
        let mut fresh = false;
        let rate = loop {
            if need_jacobian {
                self.refresh_jacobian(sys)?;
                fresh = true;
                self.h_lu = f64::NAN;
            }
            // (NaN h_lu: no valid factors.)
            let factors_fit = (h - self.h_lu).abs() <= STEP_CHANGE_REFACTOR * h;
            if !factors_fit && !self.factorize(h) {
                if fresh {
                    return Err(failure);
                }
                need_jacobian = true;
                continue;
            }
            self.starting_guess(h);
            match self.newton(sys, t, h, fresh) {
                Ok(rate) => break rate,
                Err(()) if fresh => {
                    // Keep the fresh Jacobian: the next attempt starts from it.
                    self.refresh_next = false;
                    return Err(failure);
                }
                Err(()) => need_jacobian = true,
            }
        };
        self.refresh_next = rate > REFRESH_RATE;

        // y ← y + h Σ bᵢ kᵢ, compensated.
        let n = self.y.len();
        self.y_prev.copy_from_slice(&self.y);
        let hb = [h * self.b[0], h * self.b[1]];
        for j in 0..n {
            let mut inc;
            if self.update_from_k {
                inc = hb[0] * self.k[j];
                if self.s == 2 {
                    inc += hb[1] * self.k[n + j];
                }
            } else {
                inc = self.d[0] * self.z[j];
                if self.s == 2 {
                    inc += self.d[1] * self.z[n + j];
                }
            }
            let inc = inc - self.comp[j];
            let sum = self.y[j] + inc;
            self.comp[j] = (sum - self.y[j]) - inc;
            self.y[j] = sum;
        }
        std::mem::swap(&mut self.z, &mut self.z_step);
        self.t_prev = t;
        self.t = t_next;
        self.grid.advance(on_grid);
        self.stats.steps += 1;
        Ok(self.t)
    }

    fn restart<S: OdeSystem + ?Sized>(&mut self, _sys: &S, y: &[f64]) {
        self.y.copy_from_slice(y);
        // The next starting guess is zero, not the last polynomial extrapolated across the
        // jump.
        self.restarted = true;
    }

    fn interpolate(&self, t: f64, out: &mut [f64]) {
        let h = self.t - self.t_prev;
        if h == 0.0 || t == self.t {
            out.copy_from_slice(&self.y);
            return;
        }
        if t == self.t_prev {
            out.copy_from_slice(&self.y_prev);
            return;
        }
        let n = self.y.len();
        let w = self.weights((t - self.t_prev) / h);
        for (j, o) in out.iter_mut().enumerate() {
            let mut acc = w[0] * self.z_step[j];
            if self.s == 2 {
                acc += w[1] * self.z_step[n + j];
            }
            *o = self.y_prev[j] + acc;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::test_systems::{
        Clock, Exponential, Oscillator, Quadratic, RigidBody, Spring,
    };
    use crate::integrate::{Dopri5, Tolerances};

    const BOTH: [GaussStages; 2] = [GaussStages::One, GaussStages::Two];

    fn run_to<S: OdeSystem + ?Sized>(g: &mut Gauss, sys: &S, t_end: f64) {
        while g.t() < t_end {
            g.step(sys, t_end).unwrap();
        }
    }

    /// Least-squares slope of `ln e` against `ln h`.
    fn slope(h: &[f64], e: &[f64]) -> f64 {
        let x: Vec<f64> = h.iter().map(|v| v.ln()).collect();
        let y: Vec<f64> = e.iter().map(|v| v.ln()).collect();
        let k = x.len() as f64;
        let (mx, my) = (x.iter().sum::<f64>() / k, y.iter().sum::<f64>() / k);
        let sxy: f64 = x.iter().zip(&y).map(|(a, b)| (a - mx) * (b - my)).sum();
        let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
        sxy / sxx
    }

    /// Euler's equations plus the quaternion, I = diag(1, 2, 3) kg m², over 10 s against
    /// Dopri5 at rtol 1e-13: the global error falls as h² and h⁴.
    #[test]
    fn convergence_orders_are_two_and_four() {
        let body = RigidBody([1.0, 2.0, 3.0]);
        let y0 = [0.3, 1.0, 0.2, 1.0, 0.0, 0.0, 0.0];
        let t_end = 10.0;
        let tol = Tolerances {
            rtol: 1e-13,
            atol: 1e-13,
        };
        let mut reference = Dopri5::new(0.0, &y0, tol, f64::INFINITY, None);
        while reference.t() < t_end {
            reference.step(&body, t_end).unwrap();
        }
        let cases = [
            (GaussStages::One, [0.1, 0.05, 0.025, 0.0125]),
            (GaussStages::Two, [0.4, 0.2, 0.1, 0.05]),
        ];
        for (stages, hs) in cases {
            let errors: Vec<f64> = hs
                .iter()
                .map(|&h| {
                    let mut g = Gauss::new(0.0, &y0, h, stages);
                    run_to(&mut g, &body, t_end);
                    assert_eq!(g.t(), t_end);
                    (0..7)
                        .map(|i| (g.y()[i] - reference.y()[i]).abs())
                        .fold(0.0, f64::max)
                })
                .collect();
            let p = slope(&hs, &errors);
            let shown: Vec<String> = errors.iter().map(|e| format!("{e:.2e}")).collect();
            println!("{stages:?}: h {hs:?}, errors {shown:?}, slope {p:.3}");
            // Well above the reference's own error (~1e-12) and roundoff.
            assert!(errors.iter().all(|&e| e > 1e-9), "{errors:?}");
            assert!((p - stages.order() as f64).abs() <= 0.3, "slope {p}");
        }
    }

    /// A generic torque-free tumble, I = diag(100, 200, 300) kg m², |ω| ≈ 0.7 rad/s, 1e5 s at
    /// h = 0.5 s (2e5 steps, ~10⁴ rotations): T, |H| and |q| stay at their
    /// initial values to roundoff.
    #[test]
    fn quadratic_invariants_are_conserved_to_roundoff_over_1e5_s() {
        let body = RigidBody([100.0, 200.0, 300.0]);
        let y0 = [0.3, 0.5, -0.4, 0.5, 0.5, 0.5, 0.5];
        let (t_end, h) = (1.0e5, 0.5);
        let (t0, h0) = (body.energy(&y0), body.momentum(&y0));
        for stages in BOTH {
            let start = std::time::Instant::now();
            let mut g = Gauss::new(0.0, &y0, h, stages);
            let (mut dt, mut dh, mut dq): (f64, f64, f64) = (0.0, 0.0, 0.0);
            while g.t() < t_end {
                g.step(&body, t_end).unwrap();
                let y = g.y();
                dt = dt.max((body.energy(y) - t0).abs() / t0);
                dh = dh.max((body.momentum(y) - h0).abs() / h0);
                dq = dq.max((y[3..7].iter().map(|v| v * v).sum::<f64>().sqrt() - 1.0).abs());
            }
            let s = g.stats();
            println!(
                "{stages:?}, h = {h} s, {} steps in {:.2?}: max |ΔT|/T = {dt:.2e}, \
                 |Δ|H||/|H| = {dh:.2e}, ||q|−1| = {dq:.2e}; {:.2} Newton iterations and \
                 {:.3} Jacobians per step",
                s.steps,
                start.elapsed(),
                s.newton_iterations as f64 / s.steps as f64,
                s.jacobian_evaluations as f64 / s.steps as f64,
            );
            assert_eq!(s.steps, 200_000);
            assert!(dt <= 1e-12 && dh <= 1e-12 && dq <= 1e-12);
        }
    }

    /// `y' = λy`, λ = −1e6, h = 1 (hλ = −1e6): |R(z)| < 1, the solution never grows (an
    /// explicit method would overflow within a few steps). It follows `R(z)ⁿ`.
    #[test]
    fn stiff_decay_never_grows() {
        let z: f64 = -1e6;
        for stages in BOTH {
            let r = match stages {
                GaussStages::One => (1.0 + z / 2.0) / (1.0 - z / 2.0),
                GaussStages::Two => (1.0 + z / 2.0 + z * z / 12.0) / (1.0 - z / 2.0 + z * z / 12.0),
            };
            let mut g = Gauss::new(0.0, &[1.0], 1.0, stages);
            let mut exact = 1.0;
            let mut err: f64 = 0.0;
            for _ in 0..100 {
                let before = g.y()[0].abs();
                g.step(&Exponential(z), f64::INFINITY).unwrap();
                exact *= r;
                assert!(
                    g.y()[0].abs() <= before,
                    "{stages:?}: {before} → {}",
                    g.y()[0]
                );
                err = err.max((g.y()[0] - exact).abs());
            }
        }
    }

    /// The stiff spring `x'' = −10⁸ x` at h = 0.1 s (ωh = 1000): the phase is meaningless but
    /// the energy, a quadratic invariant, is kept to roundoff.
    #[test]
    fn stiff_spring_keeps_its_energy() {
        let k = 1e8;
        let energy = |y: &[f64]| 0.5 * y[1] * y[1] + 0.5 * k * y[0] * y[0];
        let y0 = [1e-4, 1.0];
        let e0 = energy(&y0);
        for stages in BOTH {
            let mut g = Gauss::new(0.0, &y0, 0.1, stages);
            let mut drift: f64 = 0.0;
            for _ in 0..1000 {
                g.step(&Spring(k), f64::INFINITY).unwrap();
                drift = drift.max((energy(g.y()) - e0).abs() / e0);
            }
            println!("{stages:?}: stiff spring, max relative energy error {drift:.2e}");
            // The 2-stage update h Σ bᵢkᵢ amplifies the stages' roundoff by h‖J‖ = 10³ (see
            // `Gauss`): a random walk at ~1e-13 per step, still bounded far below any drift.
            let bound = match stages {
                GaussStages::One => 1e-13,
                GaussStages::Two => 1e-11,
            };
            assert!(drift <= bound, "{drift}");
        }
    }

    #[test]
    fn steps_land_exactly_on_t_end() {
        for stages in BOTH {
            let mut g = Gauss::new(0.0, &[1.0, 0.0], 0.1, stages);
            run_to(&mut g, &Oscillator, 1.05);
            assert_eq!(g.t(), 1.05);
            assert_eq!(g.stats().steps, 11);
            // An output time inside a step, then continuing on the grid.
            let mut g = Gauss::new(0.0, &[1.0, 0.0], 0.3, stages);
            assert_eq!(g.step(&Oscillator, 0.2).unwrap(), 0.2);
            assert_eq!(g.step(&Oscillator, 10.0).unwrap(), 0.3);
            assert_eq!(g.step(&Oscillator, 10.0).unwrap(), 0.6);
            assert_eq!(g.stats().steps, 3);
        }
    }

    /// y' = 1 from a large t0: the integrated time y must equal the time label at the end.
    #[test]
    fn integrated_time_matches_the_time_label() {
        let (t0, t_end) = (1.0e6, 1.0e6 + 1.0e4);
        for stages in BOTH {
            let mut g = Gauss::new(t0, &[0.0], 0.1, stages);
            run_to(&mut g, &Clock, t_end);
            assert_eq!(g.stats().steps, 100_000);
            assert_eq!(g.t(), t_end);
            assert!((g.y()[0] - 1.0e4).abs() < 1e-9, "y = {}", g.y()[0]);
        }
    }

    /// `y' = y²` from 1 blows up at t = 1: a step of 2 has no (real) stage solution, and the
    /// step fails cleanly, leaving the state as it was. Below the blow-up it works.
    #[test]
    fn a_step_across_a_blow_up_is_a_newton_failure() {
        for stages in BOTH {
            let mut g = Gauss::new(0.0, &[1.0], 2.0, stages);
            let err = g.step(&Quadratic, 10.0).unwrap_err();
            assert_eq!(err, StepError::NewtonFailure { t: 0.0, h: 2.0 });
            assert_eq!((g.t(), g.y()), (0.0, &[1.0][..]));
            assert_eq!(g.stats().steps, 0);
            assert!(g.stats().newton_iterations <= 2 * u64::from(MAX_ITERATIONS));

            let mut g = Gauss::new(0.0, &[1.0], 0.01, stages);
            run_to(&mut g, &Quadratic, 0.5);
            assert!((g.y()[0] - 2.0).abs() < 1e-3, "{}", g.y()[0]);
        }
    }

    /// The collocation polynomial: exact at the step's ends, and its error inside the step
    /// falls as h^(s+1) (local error of the stage order s).
    #[test]
    fn dense_output_is_the_collocation_polynomial() {
        for stages in BOTH {
            let dense_error = |h: f64| {
                let mut g = Gauss::new(0.0, &[1.0, 0.0], h, stages);
                let mut out = [0.0; 2];
                let mut err: f64 = 0.0;
                while g.t() < 1.0 {
                    g.step(&Oscillator, 1.0).unwrap();
                    g.interpolate(g.t(), &mut out);
                    assert_eq!(out, g.y());
                    for theta in [0.1, 0.37, 0.5, 0.8] {
                        let t = g.t_prev() + theta * (g.t() - g.t_prev());
                        g.interpolate(t, &mut out);
                        err = err.max((out[0] - t.cos()).abs().max((out[1] + t.sin()).abs()));
                    }
                }
                err
            };
            let (e1, e2) = (dense_error(0.1), dense_error(0.05));
            let p = (e1 / e2).log2();
            println!("{stages:?}: dense-output errors {e1:.2e}, {e2:.2e}, order {p:.2}");
            assert!((p - (stages.count() + 1) as f64).abs() < 0.3, "order {p}");
        }
    }

    /// Every right-hand-side evaluation is accounted for: s per Newton iteration, n + 1 per
    /// Jacobian. The Jacobian is kept over steps on an easy problem.
    #[test]
    fn work_counters_add_up() {
        for stages in BOTH {
            let mut g = Gauss::new(0.0, &[1.0, 0.0], 0.01, stages);
            run_to(&mut g, &Oscillator, 10.0);
            let s = g.stats();
            assert_eq!(s.steps, 1000);
            assert_eq!(
                s.rhs_evaluations,
                stages.count() as u64 * s.newton_iterations + 3 * s.jacobian_evaluations
            );
            assert!(s.jacobian_evaluations >= 1 && s.factorizations >= s.jacobian_evaluations);
            assert!(s.jacobian_evaluations < 10, "{s:?}");
            assert!(s.newton_iterations >= s.steps);
        }
    }

    /// Extrapolating the last collocation polynomial saves Newton iterations over starting
    /// from `yₙ` (Z = 0), on the rigid body.
    #[test]
    fn extrapolated_starting_guess_saves_iterations() {
        let body = RigidBody([100.0, 200.0, 300.0]);
        let y0 = [0.3, 0.5, -0.4, 0.5, 0.5, 0.5, 0.5];
        for stages in BOTH {
            let per_step = |extrapolate: bool| {
                let mut g = Gauss::new(0.0, &y0, 0.1, stages);
                g.extrapolate = extrapolate;
                run_to(&mut g, &body, 1000.0);
                g.stats().newton_iterations as f64 / g.stats().steps as f64
            };
            let (with, without) = (per_step(true), per_step(false));
            println!(
                "{stages:?}: Newton iterations per step {with:.2} extrapolated, {without:.2} from yₙ"
            );
            assert!(with < without);
        }
    }
}
