//! Numerical integrators behind one interface.
//!
//! Every method implements [`Stepper`]: it owns the current `(t, y)`, advances by one accepted
//! step, and can interpolate anywhere inside its last step (dense output). The simulation
//! driver samples the output grid and locates events on that interpolant, so a new method
//! (fixed-step, adaptive, implicit, a closed-form propagator) only has to provide these few
//! operations.

pub(crate) mod dop853;
pub(crate) mod dopri5;
mod gauss;
mod grid;
pub mod jacobian;
mod radau5;
mod rk4;
#[cfg(test)]
mod test_systems;

pub use dop853::Dop853;
pub use dopri5::Dopri5;
pub use gauss::{Gauss, GaussStages};
pub use grid::FixedGrid;
pub use radau5::Radau5;
pub use rk4::Rk4;

use crate::lanes::Lane;
use std::fmt;

/// A first-order ODE system `dy/dt = f(t, y)` of fixed dimension.
pub trait OdeSystem {
    /// Number of state components.
    fn dim(&self) -> usize;
    /// Writes `f(t, y)` into `dydt` (both of length [`OdeSystem::dim`]).
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]);
}

/// Work counters of a run, reported in summaries (so accuracy can be charted against cost).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct Stats {
    /// Accepted steps.
    pub steps: u64,
    /// Rejected steps (adaptive methods).
    pub rejected_steps: u64,
    /// Right-hand-side evaluations (including those spent on finite-difference Jacobians).
    pub rhs_evaluations: u64,
    /// Newton iterations (implicit methods).
    pub newton_iterations: u64,
    /// Jacobian evaluations (implicit methods).
    pub jacobian_evaluations: u64,
    /// LU factorisations of the iteration matrix (implicit methods).
    pub factorizations: u64,
}

/// Why a step could not be taken.
#[derive(Debug, Clone, PartialEq)]
pub enum StepError {
    /// The adaptive controller asked for a step below the resolution of `t`.
    StepSizeUnderflow {
        /// Time at which the step failed (s).
        t: f64,
        /// Step size that was requested (s).
        h: f64,
    },
    /// The right-hand side returned a non-finite value.
    NonFiniteDerivative {
        /// Time at which it happened (s).
        t: f64,
    },
    /// The Newton iteration of an implicit method did not converge, even after the step was
    /// reduced (or, for a fixed-step method, at the given step).
    NewtonFailure {
        /// Time at which the step failed (s).
        t: f64,
        /// Step size that was tried last (s).
        h: f64,
    },
    /// A sub-flow of a composition method could not be evaluated.
    SubFlow {
        /// Time at which the step started (s).
        t: f64,
        /// What failed.
        what: String,
    },
}

impl fmt::Display for StepError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StepError::StepSizeUnderflow { t, h } => write!(
                f,
                "step size underflow at t = {} (h = {h:e} s): the tolerance cannot be met; \
                 loosen rtol/atol or check the model for a singularity",
                crate::timefmt::seconds(*t)
            ),
            StepError::NonFiniteDerivative { t } => write!(
                f,
                "the right-hand side became non-finite at t = {}: the state left the domain \
                 of the model",
                crate::timefmt::seconds(*t)
            ),
            StepError::NewtonFailure { t, h } => write!(
                f,
                "the Newton iteration of the implicit method did not converge at t = {} \
                 (h = {h:e} s): reduce the step, or check the model for a singularity",
                crate::timefmt::seconds(*t)
            ),
            StepError::SubFlow { t, what } => {
                write!(
                    f,
                    "a sub-flow failed in the step from t = {}: {what}",
                    crate::timefmt::seconds(*t)
                )
            }
        }
    }
}

impl std::error::Error for StepError {}

/// One integration method advancing a state in time.
pub trait Stepper {
    /// Current time (s).
    fn t(&self) -> f64;
    /// Current state.
    fn y(&self) -> &[f64];
    /// Takes one accepted step, never past `t_end`. Returns the time reached.
    fn step<S: OdeSystem + ?Sized>(&mut self, sys: &S, t_end: f64) -> Result<f64, StepError>;
    /// Start time of the last accepted step (equals `t()` before the first step).
    fn t_prev(&self) -> f64;
    /// Interpolates the state at `t` within the last accepted step `[t_prev, t]`. A stepper
    /// with deferred dense output needs [`Stepper::prepare_interpolation`] first for a `t`
    /// strictly inside the step.
    fn interpolate(&self, t: f64, out: &mut [f64]);
    /// Completes the last accepted step's dense output if the method defers it (dop853's
    /// lazy stages); `false` when that work came out non-finite. Cheap when done already.
    fn prepare_interpolation<S: OdeSystem + ?Sized>(&mut self, _sys: &S) -> bool {
        true
    }
    /// Work counters so far.
    fn stats(&self) -> Stats;
    /// Continues from the current time with the state `y` (the integrated one, with held
    /// states updated at a breakpoint) and forgets what the method carries over from before
    /// (a first-same-as-last stage, the derivative at the step's start, a starting guess
    /// extrapolated from the last step): the next step starts afresh from `f(t, y)`. The last
    /// step's dense output stays as it was (the left side of the breakpoint).
    fn restart<S: OdeSystem + ?Sized>(&mut self, sys: &S, y: &[f64]);
}

/// Where an adaptive step ends, per lane; see [`adaptive_step_end`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct StepEnd<L: Lane = f64> {
    /// End time (s).
    pub t_new: L,
    /// Step taken, `t_new − t` (s): steps add up to the times exactly.
    pub h: L,
    /// The step was stretched or cut to land exactly on `t_end`.
    pub last: L::Mask,
    /// `h` is below the resolution of `t` (step-size underflow).
    pub underflow: L::Mask,
}

/// A step no longer than this many units of `f64::EPSILON` relative to `|t|` is below the
/// resolution of `t`: an adaptive method reports a step-size underflow.
pub const UNDERFLOW_EPS: f64 = 16.0;

/// Two instants closer than this many units of `f64::EPSILON` relative to the larger are one
/// instant for the integration: four times [`UNDERFLOW_EPS`], so that no stop is ever asked for
/// that a step could not reach without underflowing.
pub const SAME_INSTANT_EPS: f64 = 4.0 * UNDERFLOW_EPS;

/// Whether `a` and `b` (s) are the same instant for the integration: within a few ulps
/// ([`SAME_INSTANT_EPS`]) of each other, as a controller tick k·Δt and the duration m/f can be.
/// A breakpoint within that distance of the end, or of another breakpoint, is merged with it.
pub fn same_instant(a: f64, b: f64) -> bool {
    same_instant_lanes(a, b)
}

/// [`same_instant`] per lane.
#[inline(always)]
pub(crate) fn same_instant_lanes<L: Lane>(a: L, b: L) -> L::Mask {
    (b - a)
        .abs()
        .at_most(L::splat(SAME_INSTANT_EPS * f64::EPSILON) * a.abs().max(b.abs()))
}

/// Where an adaptive step of size `h_wanted` (s) from `t` ends: exactly on `t_end` when it
/// would reach within 1e-12 of the remaining span, or within a few ulps of `t_end`
/// ([`same_instant`]) (no sliver of a step is left that could not be taken), else at
/// `t + h_wanted`. Per lane: the scalar methods call it at `f64`, the lanes at theirs.
#[inline(always)]
pub(crate) fn adaptive_step_end<L: Lane>(t: L, h_wanted: L, t_end: L) -> StepEnd<L> {
    let last = h_wanted.at_least((t_end - t) * L::splat(1.0 - 1e-12))
        | same_instant_lanes(t + h_wanted, t_end);
    let t_new = L::select(last, t_end, t + h_wanted);
    let h = t_new - t;
    StepEnd {
        t_new,
        h,
        last,
        underflow: h
            .abs()
            .at_most(L::splat(UNDERFLOW_EPS * f64::EPSILON) * t.abs().max(L::splat(1e-300))),
    }
}

/// Tolerances of an adaptive method: the local error estimate of component `i` is kept below
/// `atol + rtol·|y_i|`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// Relative tolerance (dimensionless).
    pub rtol: f64,
    /// Absolute tolerance (units of the state).
    pub atol: f64,
}

/// The PI step-size controller of Hairer's codes (Hairer, Nørsett & Wanner, "Solving
/// Ordinary Differential Equations I", §II.4): its safety factor, the bounds on a step's
/// change and its stabilisation β (0: the classical controller). Each method has its own
/// settings (`dopri5::CONTROL`, `dop853::CONTROL`); the arithmetic is the same, per lane.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StepControl {
    /// Safety factor on the proposed step.
    pub safety: f64,
    /// The step shrinks to no less than `fac_min` times itself after a rejection…
    pub fac_min: f64,
    /// …and grows to no more than `fac_max` times itself after an acceptance.
    pub fac_max: f64,
    /// PI stabilisation β.
    pub beta: f64,
}

impl StepControl {
    /// After an accepted step `h` (s) with error `err` and its factor `fac11` (the method's
    /// `error_factor`): the next step (no longer than `h` where the step followed
    /// rejections) and the new `fac_old`.
    #[inline(always)]
    pub(crate) fn accepted_step_size<L: Lane>(
        &self,
        err: L,
        fac11: L,
        h: L,
        fac_old: L,
        after_rejections: L::Mask,
    ) -> (L, L) {
        let fac = if self.beta == 0.0 {
            fac11
        } else {
            fac11 / crate::lanes::elementary::positive_powf(fac_old, self.beta)
        };
        let fac = (fac / L::splat(self.safety)).clamp(1.0 / self.fac_max, 1.0 / self.fac_min);
        let h_new = h / fac;
        let h_new = L::select(after_rejections, h_new.min(h), h_new);
        (h_new, err.max(L::splat(1e-4)))
    }

    /// The next step (s) after a rejected step `h` whose error had factor `fac11`.
    #[inline(always)]
    pub(crate) fn rejected_step_size<L: Lane>(&self, fac11: L, h: L) -> L {
        h / L::splat(1.0 / self.fac_min).min(fac11 / L::splat(self.safety))
    }
}

/// [`combine`] through its build for AVX2 when `avx2` (the caller asked
/// [`crate::cpu::avx2_available`] once): the same bits, four lanes per instruction.
#[inline(always)]
pub(crate) fn combine_on<const M: usize>(
    avx2: bool,
    out: &mut [f64],
    base: &[f64],
    h: f64,
    a: [f64; M],
    k: [&[f64]; M],
) {
    #[cfg(target_arch = "x86_64")]
    if avx2 {
        // SAFETY: `avx2` is true only where the processor has AVX2.
        unsafe { combine_avx2(out, base, h, a, k) };
        return;
    }
    let _ = avx2;
    combine::<f64, M>(out, base, h, a, k)
}

/// [`combine`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn combine_avx2<const M: usize>(
    out: &mut [f64],
    base: &[f64],
    h: f64,
    a: [f64; M],
    k: [&[f64]; M],
) {
    combine::<f64, M>(out, base, h, a, k)
}

/// `out = base + h·Σⱼ a[j]·k[j]` (a stage argument), per lane. The slices are cut to
/// `out.len()` first so the loops carry no bounds checks; the `M` terms are unrolled; the
/// increments are summed before they are added to `base`, as in the textbook formula.
#[inline(always)]
pub(crate) fn combine<L: Lane, const M: usize>(
    out: &mut [L],
    base: &[L],
    h: L,
    a: [f64; M],
    mut k: [&[L]; M],
) {
    let n = out.len();
    for kj in k.iter_mut() {
        *kj = &kj[..n];
    }
    for (i, o) in out.iter_mut().enumerate() {
        let mut acc = L::splat(a[0]) * k[0][i];
        for j in 1..M {
            acc += L::splat(a[j]) * k[j][i];
        }
        *o = h * acc;
    }
    for (o, &b) in out.iter_mut().zip(&base[..n]) {
        *o += b;
    }
}
