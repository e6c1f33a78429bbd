//! The explicit Runge–Kutta methods the lockstep ensemble ([`super::ensemble`]) steps with,
//! in lanes: dopri5 ([`Dopri5Lanes`]) and dop853 ([`Dop853Lanes`]). Each holds its stages in
//! lanes and calls the arithmetic the scalar method calls at `f64` (`integrate::dopri5`,
//! `integrate::dop853`), so that a lane's steps are the scalar method's, bit for bit; the
//! engine takes the decisions (accept, reject, the step size) the same way for both.
//!
//! dop853 evaluates stage 13 (f at the new point, the next step's first) only for a step that
//! passed its error test, and its three dense-output stages only for a step whose interior is
//! read (the scalar `Dop853::with_lazy_dense_output`): the lanes evaluate them for every lane
//! at once and count them for the lanes that needed them, as the scalar method would have.

use super::{Lane, LaneMask};
use crate::integrate::StepControl;
use crate::integrate::dop853::{self, PlainCombine};
use crate::integrate::dopri5::{self, StageRhs};

/// The method a campaign's runs are integrated with in the lanes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LaneMethodKind {
    /// Dormand–Prince 5(4), as the scalar `Dopri5`.
    Dopri5,
    /// Dormand–Prince 8(5,3), as the scalar `Dop853` with lazy dense output.
    Dop853,
}

/// A lane's dense output over its last accepted step, formed as the scalar method forms it.
#[derive(Debug, Clone)]
pub enum LaneInterpolant<const DIM: usize> {
    /// dopri5's five coefficient vectors (`dopri5::dense_coefficients`).
    Dopri5([[f64; DIM]; 5]),
    /// dop853's eight (`dop853::dense_coefficients`).
    Dop853([[f64; DIM]; 8]),
}

impl<const DIM: usize> LaneInterpolant<DIM> {
    /// The state at `t` (s) in the step from `t_prev` to `t_now` that ended at `y_now`, into
    /// `out`, as the scalar method's `interpolate` gives it (the step's ends as stored).
    pub fn value(&self, t: f64, t_prev: f64, t_now: f64, y_now: &[f64; DIM], out: &mut [f64]) {
        match self {
            LaneInterpolant::Dopri5(cont) => {
                dopri5::dense_value(t, t_prev, t_now, y_now, cont, out)
            }
            LaneInterpolant::Dop853(cont) => {
                dop853::dense_value(t, t_prev, t_now, y_now, cont, out)
            }
        }
    }
}

/// A method's stages in lanes and the arithmetic of its step, as the engine calls them.
pub(crate) trait LaneMethod<L: Lane, const DIM: usize> {
    /// The step-size controller's settings (the scalar method's).
    const CONTROL: StepControl;
    /// Right-hand-side evaluations of an attempt's stages ([`LaneMethod::attempt`]).
    const ATTEMPT_EVALUATIONS: f64;
    /// Right-hand-side evaluations of the dense-output stages
    /// ([`LaneMethod::dense_stages`]; 0: the dense output needs none).
    const DENSE_EVALUATIONS: f64;
    /// Every stage zero.
    fn zeroed() -> Self;
    /// The first stage, f at the step's start (kept across steps: first same as last).
    fn first_stage(&mut self) -> &mut [L; DIM];
    /// The initial step (s) from `(t, y)` with the first stage in place, for a span `span`
    /// and a cap `h_max` (s), as the scalar method chooses it; evaluates `rhs` once.
    #[allow(clippy::too_many_arguments)]
    fn initial_step(
        &mut self,
        rhs: &mut impl StageRhs<L>,
        t: L,
        y: &[L; DIM],
        stage: &mut [L; DIM],
        tolerances: (L, L),
        h_max: L,
        span: L,
    ) -> L;
    /// The stages of a step `h` (s) from `(t, y)`, the solution into `y_new`; returns the
    /// step's scaled error (≤ 1 passes; non-finite if the stages were).
    #[allow(clippy::too_many_arguments)]
    fn attempt(
        &mut self,
        rhs: &mut impl StageRhs<L>,
        t: L,
        h: L,
        y: &[L; DIM],
        y_new: &mut [L; DIM],
        stage: &mut [L; DIM],
        tolerances: (L, L),
    ) -> L;
    /// Whether a step that passed its error test evaluates a stage at its end
    /// ([`LaneMethod::end_stage`]).
    const END_STAGE: bool;
    /// The stage at the end `(t_new, y_new)` of a step that passed its error test; returns
    /// the lanes where it is finite.
    fn end_stage(&mut self, rhs: &mut impl StageRhs<L>, t_new: L, y_new: &[L; DIM]) -> L::Mask;
    /// The error's factor in the step-size control.
    fn error_factor(err: L) -> L;
    /// After an attempt: the lanes of `accept` take the new state `y_new` into `y` and the
    /// next step's first stage (first same as last); with `observed`, the attempt's first
    /// stage is kept for its dense output.
    fn accept(&mut self, accept: L::Mask, observed: bool, y: &mut [L; DIM], y_new: &[L; DIM]);
    /// The dense-output stages of the last attempted step `h` (s) from `(t, y)`, for every
    /// lane; returns the lanes where they are finite.
    fn dense_stages(
        &mut self,
        rhs: &mut impl StageRhs<L>,
        t: L,
        h: L,
        y: &[L; DIM],
        stage: &mut [L; DIM],
    ) -> L::Mask;
    /// The dense-output coefficients of the last attempted step `h` (s) from `y` to `y_new`
    /// (its dense stages evaluated), in lanes.
    type Dense;
    /// [`LaneMethod::Dense`] of the last attempted step.
    fn dense(&self, h: L, y: &[L; DIM], y_new: &[L; DIM]) -> Self::Dense;
    /// The dense output at `t` (s) strictly inside the step from `t_prev` to `t_now` whose
    /// coefficients are `dense`, into `out`.
    fn dense_at(dense: &Self::Dense, t: L, t_prev: L, t_now: L, out: &mut [L; DIM]);
    /// The components of `components` of the dense output at `t` (s) strictly inside the last
    /// attempted step `h` (s) from `(t_prev, y)` to `(t_now, y_new)` (its dense stages
    /// evaluated), into `out` (the others are left as they are): [`LaneMethod::dense`] and
    /// then [`LaneMethod::dense_at`], bit for bit, without keeping the coefficients.
    #[inline(always)]
    fn dense_point(
        &self,
        h: L,
        y: &[L; DIM],
        y_new: &[L; DIM],
        (t, t_prev, t_now): (L, L, L),
        components: &[bool; DIM],
        out: &mut [L; DIM],
    ) {
        let mut all = *out;
        Self::dense_at(&self.dense(h, y, y_new), t, t_prev, t_now, &mut all);
        for ((o, a), &wanted) in out.iter_mut().zip(all).zip(components) {
            if wanted {
                *o = a;
            }
        }
    }
    /// Lane `i`'s dense output over the last attempted step `h` (s) from `y` to `y_new`
    /// (that lane's values), as the scalar method forms it.
    fn interpolant(
        &self,
        i: usize,
        h: f64,
        y: &[f64; DIM],
        y_new: &[f64; DIM],
    ) -> LaneInterpolant<DIM>;
}

/// A method at every lane type: what the engine is instantiated with.
pub(crate) trait MethodFamily {
    /// The method's stages in lanes of type `L`.
    type In<L: Lane, const DIM: usize>: LaneMethod<L, DIM>;
}

/// Lane `i` of each of `stages`, as `f64`.
#[inline(always)]
fn gather<L: Lane, const DIM: usize, const S: usize>(
    stages: [&[L; DIM]; S],
    i: usize,
) -> [[f64; DIM]; S] {
    let mut out = [[0.0; DIM]; S];
    for (o, s) in out.iter_mut().zip(stages) {
        L::gather_lane(s, i, o);
    }
    out
}

/// A method's `S` stages in lanes (`k[0]` the step's first, f at its start), and the first
/// stage of the last attempt, kept for its dense output once `k[0]` holds the next step's.
pub(crate) struct Stages<L: Lane, const DIM: usize, const S: usize> {
    k: [[L; DIM]; S],
    k_start: [L; DIM],
}

impl<L: Lane, const DIM: usize, const S: usize> Stages<L, DIM, S> {
    /// Every stage zero.
    #[inline(always)]
    fn zeroed() -> Self {
        let z = L::splat(0.0);
        Stages {
            k: [[z; DIM]; S],
            k_start: [z; DIM],
        }
    }

    /// The last attempt's stages as its dense output reads them: its first stage, then the
    /// others as they stand.
    #[inline(always)]
    fn step_stages(&self) -> [&[L; DIM]; S] {
        std::array::from_fn(|j| if j == 0 { &self.k_start } else { &self.k[j] })
    }

    /// After an attempt: the lanes of `accept` take the new state `y_new` into `y` and, first
    /// same as last, the next step's first stage from stage `last` (f at the new point); with
    /// `observed`, the attempt's first stage is kept for its dense output.
    #[inline(always)]
    fn accept(
        &mut self,
        accept: L::Mask,
        observed: bool,
        y: &mut [L; DIM],
        y_new: &[L; DIM],
        last: usize,
    ) {
        if observed {
            self.k_start = self.k[0];
        }
        for j in 0..DIM {
            y[j] = L::select(accept, y_new[j], y[j]);
            self.k[0][j] = L::select(accept, self.k[last][j], self.k[0][j]);
        }
    }
}

/// dopri5 in lanes.
pub(crate) enum Dopri5 {}

impl MethodFamily for Dopri5 {
    type In<L: Lane, const DIM: usize> = Dopri5Lanes<L, DIM>;
}

/// dopri5's seven stages in lanes.
pub(crate) struct Dopri5Lanes<L: Lane, const DIM: usize>(Stages<L, DIM, 7>);

impl<L: Lane, const DIM: usize> LaneMethod<L, DIM> for Dopri5Lanes<L, DIM> {
    const CONTROL: StepControl = dopri5::CONTROL;
    const ATTEMPT_EVALUATIONS: f64 = 6.0;
    const DENSE_EVALUATIONS: f64 = 0.0;
    const END_STAGE: bool = false;

    #[inline(always)]
    fn zeroed() -> Self {
        Dopri5Lanes(Stages::zeroed())
    }

    #[inline(always)]
    fn first_stage(&mut self) -> &mut [L; DIM] {
        &mut self.0.k[0]
    }

    #[inline(always)]
    fn initial_step(
        &mut self,
        rhs: &mut impl StageRhs<L>,
        t: L,
        y: &[L; DIM],
        stage: &mut [L; DIM],
        (atol, rtol): (L, L),
        h_max: L,
        span: L,
    ) -> L {
        let [k1, k2, ..] = &mut self.0.k;
        dopri5::initial_step(rhs, t, y, k1, k2, stage, atol, rtol, h_max, span)
    }

    #[inline(always)]
    fn attempt(
        &mut self,
        rhs: &mut impl StageRhs<L>,
        t: L,
        h: L,
        y: &[L; DIM],
        y_new: &mut [L; DIM],
        stage: &mut [L; DIM],
        (atol, rtol): (L, L),
    ) -> L {
        dopri5::stages(rhs, t, h, y, &mut self.0.k, stage, y_new);
        dopri5::error_norm(h, &self.0.k, y, y_new, atol, rtol)
    }

    #[inline(always)]
    fn end_stage(&mut self, _: &mut impl StageRhs<L>, _: L, _: &[L; DIM]) -> L::Mask {
        L::Mask::splat(true)
    }

    #[inline(always)]
    fn error_factor(err: L) -> L {
        dopri5::error_factor(err)
    }

    #[inline(always)]
    fn accept(&mut self, accept: L::Mask, observed: bool, y: &mut [L; DIM], y_new: &[L; DIM]) {
        // The seventh stage is f at the new point.
        self.0.accept(accept, observed, y, y_new, 6);
    }

    #[inline(always)]
    fn dense_stages(
        &mut self,
        _: &mut impl StageRhs<L>,
        _: L,
        _: L,
        _: &[L; DIM],
        _: &mut [L; DIM],
    ) -> L::Mask {
        L::Mask::splat(true)
    }

    type Dense = [[L; DIM]; 5];

    #[inline(always)]
    fn dense(&self, h: L, y: &[L; DIM], y_new: &[L; DIM]) -> Self::Dense {
        // What the caller does not read of the coefficients is dropped by the compiler.
        let mut cont = [[L::splat(0.0); DIM]; 5];
        dopri5::dense_coefficients(h, &self.0.step_stages(), y, y_new, &mut cont);
        cont
    }

    #[inline(always)]
    fn dense_at(dense: &Self::Dense, t: L, t_prev: L, t_now: L, out: &mut [L; DIM]) {
        dopri5::dense_interior(t, t_prev, t_now, dense, out);
    }

    fn interpolant(
        &self,
        i: usize,
        h: f64,
        y: &[f64; DIM],
        y_new: &[f64; DIM],
    ) -> LaneInterpolant<DIM> {
        let k = gather(self.0.step_stages(), i);
        let mut cont = [[0.0; DIM]; 5];
        dopri5::dense_coefficients(h, &k, y, y_new, &mut cont);
        LaneInterpolant::Dopri5(cont)
    }
}

/// dop853 in lanes.
pub(crate) enum Dop853 {}

impl MethodFamily for Dop853 {
    type In<L: Lane, const DIM: usize> = Dop853Lanes<L, DIM>;
}

/// dop853's sixteen stages in lanes: 1–12 of the step, 13 at its end, 14–16 of its dense
/// output.
pub(crate) struct Dop853Lanes<L: Lane, const DIM: usize>(Stages<L, DIM, 16>);

/// Whether every component of `v` is finite, per lane.
#[inline(always)]
fn all_finite<L: Lane>(v: &[L]) -> L::Mask {
    v.iter()
        .fold(L::Mask::splat(true), |m, &x| m & x.is_finite())
}

impl<L: Lane, const DIM: usize> LaneMethod<L, DIM> for Dop853Lanes<L, DIM> {
    const CONTROL: StepControl = dop853::CONTROL;
    const ATTEMPT_EVALUATIONS: f64 = 11.0;
    const DENSE_EVALUATIONS: f64 = 3.0;
    const END_STAGE: bool = true;

    #[inline(always)]
    fn zeroed() -> Self {
        Dop853Lanes(Stages::zeroed())
    }

    #[inline(always)]
    fn first_stage(&mut self) -> &mut [L; DIM] {
        &mut self.0.k[0]
    }

    #[inline(always)]
    fn initial_step(
        &mut self,
        rhs: &mut impl StageRhs<L>,
        t: L,
        y: &[L; DIM],
        stage: &mut [L; DIM],
        tolerances: (L, L),
        h_max: L,
        span: L,
    ) -> L {
        let [k1, k2, ..] = &mut self.0.k;
        dop853::initial_step(
            rhs,
            &PlainCombine,
            t,
            y,
            k1,
            k2,
            stage,
            tolerances,
            h_max,
            span,
        )
    }

    #[inline(always)]
    fn attempt(
        &mut self,
        rhs: &mut impl StageRhs<L>,
        t: L,
        h: L,
        y: &[L; DIM],
        y_new: &mut [L; DIM],
        stage: &mut [L; DIM],
        (atol, rtol): (L, L),
    ) -> L {
        dop853::stages(rhs, &PlainCombine, t, h, y, &mut self.0.k, stage);
        let k = &self.0.k;
        let stages = [&k[0], &k[5], &k[6], &k[7], &k[8], &k[9], &k[10], &k[11]].map(|s| &s[..]);
        let z = L::splat(0.0);
        let (mut scaled3, mut scaled5) = ([z; DIM], [z; DIM]);
        dop853::solution_and_errors(
            (h, atol, rtol),
            y,
            stages,
            y_new,
            &mut scaled3,
            &mut scaled5,
        );
        dop853::error_estimate(h, &scaled3, &scaled5)
    }

    #[inline(always)]
    fn end_stage(&mut self, rhs: &mut impl StageRhs<L>, t_new: L, y_new: &[L; DIM]) -> L::Mask {
        rhs.eval(t_new, y_new, &mut self.0.k[12]);
        all_finite(&self.0.k[12])
    }

    #[inline(always)]
    fn error_factor(err: L) -> L {
        dop853::error_factor(err)
    }

    #[inline(always)]
    fn accept(&mut self, accept: L::Mask, observed: bool, y: &mut [L; DIM], y_new: &[L; DIM]) {
        // Stage 13 is f at the new point.
        self.0.accept(accept, observed, y, y_new, 12);
    }

    #[inline(always)]
    fn dense_stages(
        &mut self,
        rhs: &mut impl StageRhs<L>,
        t: L,
        h: L,
        y: &[L; DIM],
        stage: &mut [L; DIM],
    ) -> L::Mask {
        // The step's first stage back in place while its dense stages are evaluated.
        let Stages { k, k_start } = &mut self.0;
        std::mem::swap(&mut k[0], k_start);
        dop853::dense_stages(rhs, &PlainCombine, t, h, y, k, stage);
        std::mem::swap(&mut k[0], k_start);
        all_finite(&k[13]) & all_finite(&k[14]) & all_finite(&k[15])
    }

    type Dense = [[L; DIM]; 8];

    #[inline(always)]
    fn dense(&self, h: L, y: &[L; DIM], y_new: &[L; DIM]) -> Self::Dense {
        let mut cont = [[L::splat(0.0); DIM]; 8];
        dop853::dense_coefficients(h, y, y_new, &self.0.step_stages(), &mut cont);
        cont
    }

    #[inline(always)]
    fn dense_at(dense: &Self::Dense, t: L, t_prev: L, t_now: L, out: &mut [L; DIM]) {
        dop853::dense_interior(t, t_prev, t_now, dense, out);
    }

    #[inline(always)]
    fn dense_point(
        &self,
        h: L,
        y: &[L; DIM],
        y_new: &[L; DIM],
        times: (L, L, L),
        components: &[bool; DIM],
        out: &mut [L; DIM],
    ) {
        dop853::dense_point(h, y, y_new, &self.0.step_stages(), times, components, out);
    }

    fn interpolant(
        &self,
        i: usize,
        h: f64,
        y: &[f64; DIM],
        y_new: &[f64; DIM],
    ) -> LaneInterpolant<DIM> {
        let k = gather(self.0.step_stages(), i);
        let mut cont = [[0.0; DIM]; 8];
        dop853::dense_coefficients(h, y, y_new, &k, &mut cont);
        LaneInterpolant::Dop853(cont)
    }
}
