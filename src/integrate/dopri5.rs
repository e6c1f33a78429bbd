//! Dormand–Prince 5(4) with PI step-size control and fourth-order dense output.
//!
//! Coefficients: J. R. Dormand & P. J. Prince, "A family of embedded Runge–Kutta formulae",
//! J. Comput. Appl. Math. 6 (1980); dense-output coefficients and the PI controller as
//! described in Hairer, Nørsett & Wanner, *Solving ODEs I* (2nd ed.), §II.4–II.6.

use super::{OdeSystem, Stats, StepControl, StepError, Stepper, Tolerances, combine};
use crate::lanes::Lane;
use crate::lanes::elementary::positive_powf;

const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
// Error weights: fifth-order minus embedded fourth-order solution.
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
// Dense output.
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

const SAFETY: f64 = 0.9;
const FAC_MIN: f64 = 0.2; // the step shrinks by at most 5×
const FAC_MAX: f64 = 10.0; // and grows by at most 10×
const BETA: f64 = 0.04; // PI-control stabilisation
/// The step-size controller with these settings.
pub(crate) const CONTROL: StepControl = StepControl {
    safety: SAFETY,
    fac_min: FAC_MIN,
    fac_max: FAC_MAX,
    beta: BETA,
};
const MAX_REJECTIONS_IN_A_ROW: u32 = 100;

/// Adaptive Dormand–Prince 5(4) ("dopri5", the method behind MATLAB's ode45 and SciPy's RK45).
#[derive(Debug, Clone)]
pub struct Dopri5 {
    tol: Tolerances,
    h_max: f64,
    t: f64,
    t_prev: f64,
    h: f64,
    y: Vec<f64>,
    k: [Vec<f64>; 7],
    y_new: Vec<f64>,
    stage: Vec<f64>,
    /// Dense-output coefficients of the last accepted step.
    cont: [Vec<f64>; 5],
    fac_old: f64,
    first_step: bool,
    stats: Stats,
}

impl Dopri5 {
    /// Starts at `(t0, y0)`. `h_max` (s) caps the step (use `f64::INFINITY` for none);
    /// `h0` is the first step, or `None` to choose it automatically.
    pub fn new(t0: f64, y0: &[f64], tol: Tolerances, h_max: f64, h0: Option<f64>) -> Self {
        let n = y0.len();
        let z = || vec![0.0; n];
        Dopri5 {
            tol,
            h_max,
            t: t0,
            t_prev: t0,
            h: h0.unwrap_or(0.0),
            y: y0.to_vec(),
            k: [z(), z(), z(), z(), z(), z(), z()],
            y_new: z(),
            stage: z(),
            cont: [z(), z(), z(), z(), z()],
            fac_old: 1e-4,
            first_step: true,
            stats: Stats::default(),
        }
    }

    /// Step size the controller proposes next (s).
    pub fn proposed_step(&self) -> f64 {
        self.h
    }

    /// Initial step by the heuristic of Hairer, Nørsett & Wanner (§II.4, "starting step size").
    fn initial_step<S: OdeSystem + ?Sized>(&mut self, sys: &S, span: f64) -> f64 {
        let [k1, k2, ..] = &mut self.k;
        self.stats.rhs_evaluations += 1;
        initial_step(
            &mut SystemRhs(sys),
            self.t,
            &self.y,
            k1,
            k2,
            &mut self.stage,
            self.tol.atol,
            self.tol.rtol,
            self.h_max,
            span,
        )
    }

    /// Evaluates stages 2–7 for step `h` from `(t, y)` with `k[0] = f(t, y)`; returns the
    /// scaled RMS error estimate (non-finite if the stages were).
    fn attempt<S: OdeSystem + ?Sized>(&mut self, sys: &S, h: f64) -> f64 {
        stages(
            &mut SystemRhs(sys),
            self.t,
            h,
            &self.y,
            &mut self.k,
            &mut self.stage,
            &mut self.y_new,
        );
        self.stats.rhs_evaluations += 6;
        error_norm(
            h,
            &self.k,
            &self.y,
            &self.y_new,
            self.tol.atol,
            self.tol.rtol,
        )
    }

    fn store_dense_output(&mut self, h: f64) {
        dense_coefficients(h, &self.k, &self.y, &self.y_new, &mut self.cont);
    }
}

/// A right-hand side `f(t, y)` evaluated at the stages, per lane.
pub(crate) trait StageRhs<L: Lane> {
    /// Writes `f(t, y)` into `dydt`.
    fn eval(&mut self, t: L, y: &[L], dydt: &mut [L]);
}

/// An [`OdeSystem`] as the scalar stages' right-hand side (inlined into them, as the system's
/// `rhs` was before the stages were generic).
pub(crate) struct SystemRhs<'a, S: ?Sized>(pub(crate) &'a S);

impl<S: OdeSystem + ?Sized> StageRhs<f64> for SystemRhs<'_, S> {
    #[inline(always)]
    fn eval(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) {
        self.0.rhs(t, y, dydt);
    }
}

// The step's arithmetic, generic over the lane type: at `f64` it is the scalar `Dopri5`'s,
// at a wider lane the lockstep ensembles' (crate::lanes), one lane per run. Each function
// rounds as the scalar method always has, so a lane's numbers are the scalar run's.

/// Initial step (s) by the heuristic of Hairer, Nørsett & Wanner (§II.4, "starting step
/// size") from `(t, y)` with `k1 = f(t, y)`, for a span `span` (s) and a cap `h_max` (s);
/// evaluates `rhs` once (into `k2`, with `stage` as scratch).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(crate) fn initial_step<L: Lane>(
    rhs: &mut impl StageRhs<L>,
    t: L,
    y: &[L],
    k1: &mut [L],
    k2: &mut [L],
    stage: &mut [L],
    atol: L,
    rtol: L,
    h_max: L,
    span: L,
) -> L {
    let n = y.len();
    let (k1, k2, stage) = (&k1[..n], &mut k2[..n], &mut stage[..n]);
    let count = L::splat(n as f64);
    let scale = |yi: L| atol + rtol * yi.abs().max(yi.abs());
    let (mut d0, mut d1) = (L::splat(0.0), L::splat(0.0));
    for i in 0..n {
        let sc = scale(y[i]);
        let (a, b) = (y[i] / sc, k1[i] / sc);
        d0 += a * a;
        d1 += b * b;
    }
    let (d0, d1) = ((d0 / count).sqrt(), (d1 / count).sqrt());
    let tiny = L::splat(1e-10);
    let h0 = L::select(
        d0.less_than(tiny) | d1.less_than(tiny),
        L::splat(1e-6),
        L::splat(0.01) * d0 / d1,
    );
    let h0 = h0.min(h_max).min(span);
    for i in 0..n {
        stage[i] = y[i] + h0 * k1[i];
    }
    rhs.eval(t + h0, stage, k2);
    let mut d2 = L::splat(0.0);
    for i in 0..n {
        let sc = scale(y[i]);
        let a = (k2[i] - k1[i]) / sc;
        d2 += a * a;
    }
    let d2 = (d2 / count).sqrt() / h0;
    let d12 = d1.max(d2);
    let h1 = L::select(
        d12.at_most(L::splat(1e-15)),
        (h0 * L::splat(1e-3)).max(L::splat(1e-6)),
        (L::splat(0.01) / d12).powf(1.0 / 5.0),
    );
    let h = (L::splat(100.0) * h0).min(h1).min(h_max).min(span);
    // Scaled norms can overflow (tiny atol, huge states): fall back to a small step and let
    // the controller find its way from there.
    L::select(
        h.is_finite() & h.greater_than(L::splat(0.0)),
        h,
        (L::splat(1e-6) * span).min(h_max),
    )
}

/// Evaluates stages 2–7 of a step `h` (s) from `(t, y)` with `k[0] = f(t, y)`: the stages
/// into `k[1..]`, the fifth-order solution into `y_new` (and `k[6] = f(t + h, y_new)`, the
/// next step's first stage), with `stage` as scratch. `rhs(t, y, dydt)` is the system.
#[inline(always)]
pub(crate) fn stages<L: Lane, K: AsMut<[L]>>(
    rhs: &mut impl StageRhs<L>,
    t: L,
    h: L,
    y: &[L],
    k: &mut [K; 7],
    stage: &mut [L],
    y_new: &mut [L],
) {
    let n = y.len();
    let [k1, k2, k3, k4, k5, k6, k7] = k;
    let (k1, k2, k3, k4) = (k1.as_mut(), k2.as_mut(), k3.as_mut(), k4.as_mut());
    let (k5, k6, k7) = (k5.as_mut(), k6.as_mut(), k7.as_mut());
    let s = &mut stage[..n];
    // Stage 2 as (h a₂₁) k₁, as it has always been rounded; the others through `combine`.
    for (si, (&yi, &k1i)) in s.iter_mut().zip(y.iter().zip(&k1[..n])) {
        *si = yi + h * L::splat(A21) * k1i;
    }
    rhs.eval(t + L::splat(C2) * h, s, k2);
    combine(s, y, h, [A31, A32], [k1, k2]);
    rhs.eval(t + L::splat(C3) * h, s, k3);
    combine(s, y, h, [A41, A42, A43], [k1, k2, k3]);
    rhs.eval(t + L::splat(C4) * h, s, k4);
    combine(s, y, h, [A51, A52, A53, A54], [k1, k2, k3, k4]);
    rhs.eval(t + L::splat(C5) * h, s, k5);
    combine(s, y, h, [A61, A62, A63, A64, A65], [k1, k2, k3, k4, k5]);
    rhs.eval(t + h, s, k6);
    let y_new = &mut y_new[..n];
    combine(y_new, y, h, [A71, A73, A74, A75, A76], [k1, k3, k4, k5, k6]);
    rhs.eval(t + h, y_new, k7);
}

/// The scaled RMS of the embedded error estimate of a step `h` (s) from `y` to `y_new` with
/// stages `k`: √(Σᵢ (eᵢ / (atol + rtol·max(|yᵢ|, |y_newᵢ|)))² / n), non-finite if the stages
/// were. A step is accepted where it is at most 1.
#[inline(always)]
pub(crate) fn error_norm<L: Lane, K: AsRef<[L]>>(
    h: L,
    k: &[K; 7],
    y: &[L],
    y_new: &[L],
    atol: L,
    rtol: L,
) -> L {
    let n = y.len();
    let [k1, _, k3, k4, k5, k6, k7] = k;
    let (k1, k3, k4) = (&k1.as_ref()[..n], &k3.as_ref()[..n], &k4.as_ref()[..n]);
    let (k5, k6, k7) = (&k5.as_ref()[..n], &k6.as_ref()[..n], &k7.as_ref()[..n]);
    let y_new = &y_new[..n];
    let c = L::splat;
    let mut err = c(0.0);
    for i in 0..n {
        let e = h
            * (c(E1) * k1[i]
                + c(E3) * k3[i]
                + c(E4) * k4[i]
                + c(E5) * k5[i]
                + c(E6) * k6[i]
                + c(E7) * k7[i]);
        let sc = atol + rtol * y[i].abs().max(y_new[i].abs());
        let q = e / sc;
        err += q * q;
    }
    (err / c(n as f64)).sqrt()
}

/// The dense-output coefficients of an accepted step `h` (s) from `y` to `y_new` with stages
/// `k`, into `cont`.
#[inline(always)]
pub(crate) fn dense_coefficients<L: Lane, K: AsRef<[L]>, C: AsMut<[L]>>(
    h: L,
    k: &[K; 7],
    y: &[L],
    y_new: &[L],
    cont: &mut [C; 5],
) {
    let n = y.len();
    let [k1, _, k3, k4, k5, k6, k7] = k;
    let (k1, k3, k4) = (&k1.as_ref()[..n], &k3.as_ref()[..n], &k4.as_ref()[..n]);
    let (k5, k6, k7) = (&k5.as_ref()[..n], &k6.as_ref()[..n], &k7.as_ref()[..n]);
    let [c1, c2, c3, c4, c5] = cont;
    let (c1, c2, c3) = (
        &mut c1.as_mut()[..n],
        &mut c2.as_mut()[..n],
        &mut c3.as_mut()[..n],
    );
    let (c4, c5) = (&mut c4.as_mut()[..n], &mut c5.as_mut()[..n]);
    let y_new = &y_new[..n];
    let c = L::splat;
    for i in 0..n {
        let dy = y_new[i] - y[i];
        let bspl = h * k1[i] - dy;
        c1[i] = y[i];
        c2[i] = dy;
        c3[i] = bspl;
        c4[i] = dy - h * k7[i] - bspl;
        c5[i] = h
            * (c(D1) * k1[i]
                + c(D3) * k3[i]
                + c(D4) * k4[i]
                + c(D5) * k5[i]
                + c(D6) * k6[i]
                + c(D7) * k7[i]);
    }
}

/// The dense output at `t` (s) of the accepted step from `t_prev` to `t_now` that ended at
/// `y_now`, from its coefficients `cont` ([`dense_coefficients`]), into `out`. The step's ends
/// are returned as stored.
#[inline(always)]
pub(crate) fn dense_value<C: AsRef<[f64]>>(
    t: f64,
    t_prev: f64,
    t_now: f64,
    y_now: &[f64],
    cont: &[C; 5],
    out: &mut [f64],
) {
    let h = t_now - t_prev;
    if h == 0.0 || t == t_now {
        out.copy_from_slice(y_now);
        return;
    }
    if t == t_prev {
        out.copy_from_slice(cont[0].as_ref());
        return;
    }
    dense_interior(t, t_prev, t_now, cont, out);
}

/// The dense output at `t` (s) strictly inside the accepted step from `t_prev` to `t_now`,
/// from its coefficients `cont` ([`dense_coefficients`]), into `out`, per lane: what
/// [`dense_value`] computes away from the step's ends.
#[inline(always)]
pub(crate) fn dense_interior<L: Lane, C: AsRef<[L]>>(
    t: L,
    t_prev: L,
    t_now: L,
    cont: &[C; 5],
    out: &mut [L],
) {
    let th = (t - t_prev) / (t_now - t_prev);
    let th1 = L::splat(1.0) - th;
    let [c1, c2, c3, c4, c5] = cont;
    let (c1, c2, c3, c4, c5) = (
        c1.as_ref(),
        c2.as_ref(),
        c3.as_ref(),
        c4.as_ref(),
        c5.as_ref(),
    );
    for i in 0..out.len() {
        out[i] = c1[i] + th * (c2[i] + th1 * (c3[i] + th * (c4[i] + th1 * c5[i])));
    }
}

/// `err^(1/5 − 0.75 β)`, the error's factor in the step-size control, per lane (the lanes'
/// own power, [`positive_powf`], the same at every width).
#[inline(always)]
pub(crate) fn error_factor<L: Lane>(err: L) -> L {
    positive_powf(err, 0.2 - 0.75 * BETA)
}

/// The proposal kept after an accepted step that proposes `h_new` (s): a step shortened to
/// land on the end (`last`) does not shrink the standing `proposal`.
#[inline(always)]
pub(crate) fn kept_proposal<L: Lane>(last: L::Mask, proposal: L, h_new: L) -> L {
    L::select(last, proposal.max(h_new), h_new)
}

/// The next step (s) after a step `h` whose stages were not finite (dopri5's and dop853's).
#[inline(always)]
pub(crate) fn non_finite_step_size<L: Lane>(h: L) -> L {
    L::splat(0.1) * h
}

/// At most this many rejections in a row before a step fails.
pub(crate) const MAX_REJECTIONS: u32 = MAX_REJECTIONS_IN_A_ROW;

impl Stepper for Dopri5 {
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
        let span = t_end - self.t;
        if self.first_step {
            sys.rhs(self.t, &self.y, &mut self.k[0]);
            self.stats.rhs_evaluations += 1;
            if !self.k[0].iter().all(|v| v.is_finite()) {
                return Err(StepError::NonFiniteDerivative { t: self.t });
            }
            if self.h <= 0.0 {
                self.h = self.initial_step(sys, span);
            }
            self.first_step = false;
        }
        let mut rejected_in_a_row = 0;
        let mut saw_non_finite = false;
        loop {
            let super::StepEnd {
                t_new,
                h,
                last,
                underflow,
            } = super::adaptive_step_end(self.t, self.h.min(self.h_max), t_end);
            if underflow {
                return Err(if saw_non_finite {
                    StepError::NonFiniteDerivative { t: self.t }
                } else {
                    StepError::StepSizeUnderflow { t: self.t, h }
                });
            }
            let err = self.attempt(sys, h);
            if !err.is_finite() {
                saw_non_finite = true;
                self.stats.rejected_steps += 1;
                self.h = non_finite_step_size(h);
                rejected_in_a_row += 1;
                if rejected_in_a_row > MAX_REJECTIONS_IN_A_ROW {
                    return Err(StepError::NonFiniteDerivative { t: self.t });
                }
                continue;
            }
            let fac11 = error_factor(err);
            if err <= 1.0 {
                // Accepted: PI controller for the next step.
                let (h_new, fac_old) =
                    CONTROL.accepted_step_size(err, fac11, h, self.fac_old, rejected_in_a_row > 0);
                self.fac_old = fac_old;
                self.store_dense_output(h);
                std::mem::swap(&mut self.y, &mut self.y_new);
                // FSAL: the last stage is f at the new point.
                self.k.swap(0, 6);
                self.t_prev = self.t;
                self.t = t_new;
                self.stats.steps += 1;
                // Keep the proposal for the next call; a shortened last step does not shrink it.
                self.h = kept_proposal(last, self.h, h_new);
                return Ok(self.t);
            }
            self.stats.rejected_steps += 1;
            rejected_in_a_row += 1;
            if rejected_in_a_row > MAX_REJECTIONS_IN_A_ROW {
                return Err(StepError::StepSizeUnderflow { t: self.t, h });
            }
            self.h = CONTROL.rejected_step_size(fac11, h);
        }
    }

    fn restart<S: OdeSystem + ?Sized>(&mut self, _sys: &S, y: &[f64]) {
        self.y.copy_from_slice(y);
        // The first-same-as-last stage is recomputed at the next step (the step size is kept).
        self.first_step = true;
    }

    fn interpolate(&self, t: f64, out: &mut [f64]) {
        dense_value(t, self.t_prev, self.t, &self.y, &self.cont, out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::test_systems::{Clock, Exponential, Oscillator};

    #[test]
    fn meets_tolerance_on_exponential() {
        let tol = Tolerances {
            rtol: 1e-10,
            atol: 1e-12,
        };
        let mut s = Dopri5::new(0.0, &[1.0], tol, f64::INFINITY, None);
        while s.t() < 5.0 {
            s.step(&Exponential(-0.7), 5.0).unwrap();
        }
        let exact = (-0.7f64 * 5.0).exp();
        let y = s.y()[0];
        assert!((y - exact).abs() < 1e-9 * exact, "{y} vs {exact}");
        assert_eq!(s.t(), 5.0);
    }

    #[test]
    fn dense_output_is_fourth_order_accurate_inside_steps() {
        let tol = Tolerances {
            rtol: 1e-9,
            atol: 1e-9,
        };
        let mut s = Dopri5::new(0.0, &[1.0, 0.0], tol, f64::INFINITY, None);
        let mut worst: f64 = 0.0;
        let mut out = [0.0; 2];
        while s.t() < 20.0 {
            s.step(&Oscillator, 20.0).unwrap();
            let (a, b) = (s.t_prev(), s.t());
            for j in 1..10 {
                let t = a + (b - a) * j as f64 / 10.0;
                s.interpolate(t, &mut out);
                worst = worst.max((out[0] - t.cos()).abs().max((out[1] + t.sin()).abs()));
            }
        }
        assert!(worst < 1e-7, "dense output error {worst}");
    }

    /// y' = 1 from a large t0 with many steps: integrated time equals the label at the end.
    #[test]
    fn integrated_time_matches_the_time_label() {
        let (t0, t_end) = (1.0e6, 1.0e6 + 1.0e4);
        let tol = Tolerances {
            rtol: 1e-10,
            atol: 1e-10,
        };
        let mut s = Dopri5::new(t0, &[0.0], tol, 0.1, Some(0.1));
        while s.t() < t_end {
            s.step(&Clock, t_end).unwrap();
        }
        assert!((s.y()[0] - 1.0e4).abs() < 1e-9, "y = {}", s.y()[0]);
    }

    #[test]
    fn convergence_order_is_five() {
        // Fixed steps (h_max = h and loose tolerance) so the error is the method's alone.
        let err_at = |h: f64| {
            let tol = Tolerances {
                rtol: 1.0,
                atol: 1.0,
            };
            let mut s = Dopri5::new(0.0, &[1.0, 0.0], tol, h, Some(h));
            while s.t() < 10.0 {
                s.step(&Oscillator, 10.0).unwrap();
            }
            let y = s.y();
            ((y[0] - 10f64.cos()).powi(2) + (y[1] + 10f64.sin()).powi(2)).sqrt()
        };
        let (e1, e2) = (err_at(0.1), err_at(0.05));
        let order = (e1 / e2).log2();
        assert!((order - 5.0).abs() < 0.3, "measured order {order}");
    }
}
