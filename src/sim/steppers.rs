//! Methods that know the spacecraft's state layout, and the dispatch from a scenario's
//! [`Method`] to a [`Stepper`].
//!
//! The generic methods in [`crate::integrate`] see only `dy/dt = f(t, y)`. The ones here use
//! the structure of the attitude problem (docs/choosing-a-method.md):
//! - [`ExactStepper`]: the closed-form torque-free solution;
//! - [`LieStepper`]: Runge–Kutta–Munthe-Kaas of order 4 (RKMK4), which advances the attitude
//!   by quaternion exponentials, so the attitude is a unit quaternion by construction;
//! - [`SplittingStepper`]: compositions of the exact torque-free flow with the flow of
//!   everything else (torques, effectors), of order 2 (Strang) and 4 (triple jump).

use super::{Adaptive, Method, Simulation};
use crate::averaging::AveragedStepper;
use crate::exact::TorqueFreeSolution;
use crate::integrate::{
    Dop853, Dopri5, FixedGrid, Gauss, GaussStages, OdeSystem, Radau5, Rk4, Stats, StepError,
    Stepper, Tolerances,
};
use crate::model::Spacecraft;
use nalgebra::{Matrix3, UnitQuaternion, Vector3};

/// Any of polhode's methods behind one type, so the run loop is compiled once.
#[allow(clippy::large_enum_variant)]
pub enum AnyStepper {
    /// Classic RK4.
    Rk4(Rk4),
    /// Dormand–Prince 5(4).
    Dopri5(Dopri5),
    /// Dormand–Prince 8(5,3).
    Dop853(Dop853),
    /// Radau IIA order 5.
    Radau5(Radau5),
    /// Gauss–Legendre collocation.
    Gauss(Gauss),
    /// RKMK4 on the attitude.
    Lie(LieStepper),
    /// Exact torque-free flow composed with the rest.
    Splitting(SplittingStepper),
    /// The closed-form torque-free solution.
    Exact(ExactStepper),
    /// Averaged (secular) propagation.
    Averaged(AveragedStepper),
}

impl AnyStepper {
    /// The stepper for `scenario`'s method, starting at `(0, y0)`; `Err` (a diagnosis) when
    /// the method cannot treat this spacecraft. Without `dense_output`, a method may skip
    /// the work that only interpolation needs (dop853's three extra stages), and then
    /// `interpolate` is valid at the step's ends only. With it, that work may be deferred:
    /// call [`Stepper::prepare_interpolation`] before interpolating inside a step.
    pub fn for_simulation(
        sim: &Simulation,
        y0: &[f64],
        dense_output: bool,
    ) -> Result<Self, String> {
        let sc = &sim.spacecraft;
        // The method contract (`support.rs`): every run, whatever built it, is checked here.
        if let Some(refusal) = sim.method.refusal(sc, sim.duration) {
            return Err(refusal.to_string());
        }
        let tol = |a: Adaptive| {
            (
                Tolerances {
                    rtol: a.rtol,
                    atol: a.atol,
                },
                a.max_step,
            )
        };
        Ok(match sim.method {
            Method::Rk4 { dt } => AnyStepper::Rk4(Rk4::new(0.0, y0, dt)),
            Method::Dopri5(a) => {
                let (t, m) = tol(a);
                AnyStepper::Dopri5(Dopri5::new(0.0, y0, t, m, None))
            }
            Method::Gauss { dt, stages } => {
                let stages = if stages == 1 {
                    GaussStages::One
                } else {
                    GaussStages::Two
                };
                AnyStepper::Gauss(Gauss::new(0.0, y0, dt, stages))
            }
            Method::Radau5(a) => {
                let (t, m) = tol(a);
                AnyStepper::Radau5(Radau5::new(0.0, y0, t, m, None))
            }
            Method::Dop853(a) => {
                let (t, m) = tol(a);
                let stepper = Dop853::new(0.0, y0, t, m, None);
                AnyStepper::Dop853(if dense_output {
                    stepper.with_lazy_dense_output()
                } else {
                    stepper.with_dense_output(false)
                })
            }
            Method::Lie { dt } => AnyStepper::Lie(LieStepper::new(0.0, y0, dt)),
            Method::Splitting { dt, order } => {
                AnyStepper::Splitting(SplittingStepper::new(sc, 0.0, y0, dt, order)?)
            }
            Method::Exact => AnyStepper::Exact(ExactStepper::new(sc, y0, sim.output_rate)?),
            Method::Averaged(a) => AnyStepper::Averaged(AveragedStepper::new(sc, y0, a)?),
        })
    }
}

macro_rules! each {
    ($self:ident, $s:ident => $e:expr) => {
        match $self {
            AnyStepper::Rk4($s) => $e,
            AnyStepper::Dopri5($s) => $e,
            AnyStepper::Dop853($s) => $e,
            AnyStepper::Radau5($s) => $e,
            AnyStepper::Gauss($s) => $e,
            AnyStepper::Lie($s) => $e,
            AnyStepper::Splitting($s) => $e,
            AnyStepper::Exact($s) => $e,
            AnyStepper::Averaged($s) => $e,
        }
    };
}

impl Stepper for AnyStepper {
    fn t(&self) -> f64 {
        each!(self, s => s.t())
    }
    fn y(&self) -> &[f64] {
        each!(self, s => s.y())
    }
    fn step<S: OdeSystem + ?Sized>(&mut self, sys: &S, t_end: f64) -> Result<f64, StepError> {
        each!(self, s => s.step(sys, t_end))
    }
    fn t_prev(&self) -> f64 {
        each!(self, s => s.t_prev())
    }
    fn interpolate(&self, t: f64, out: &mut [f64]) {
        each!(self, s => s.interpolate(t, out))
    }
    fn prepare_interpolation<S: OdeSystem + ?Sized>(&mut self, sys: &S) -> bool {
        each!(self, s => s.prepare_interpolation(sys))
    }
    fn stats(&self) -> Stats {
        each!(self, s => s.stats())
    }
    fn restart<S: OdeSystem + ?Sized>(&mut self, sys: &S, y: &[f64]) {
        each!(self, s => s.restart(sys, y))
    }
}

// ---------------------------------------------------------------------------------------
// Quaternion helpers on the state layout (scalar first).

type Quat = [f64; 4];

/// Hamilton product `a ⊗ b`.
fn qmul(a: &Quat, b: &Quat) -> Quat {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// `Exp(u)`: the unit quaternion of the rotation vector `u` (rad). Written with sin(x)/x so
/// it is smooth at u = 0; its norm is 1 to rounding.
fn qexp(u: &[f64; 3]) -> Quat {
    let angle = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    let half = 0.5 * angle;
    // sin(half)/angle, by its series below 1e-4 rad (error < 1e-17).
    let s = if angle < 1e-4 {
        0.5 * (1.0 - half * half / 6.0)
    } else {
        half.sin() / angle
    };
    [half.cos(), s * u[0], s * u[1], s * u[2]]
}

/// `q*` (the inverse of a unit quaternion).
fn conjugate(q: &Quat) -> Quat {
    [q[0], -q[1], -q[2], -q[3]]
}

/// `Log(q)`: the rotation vector (rad) of a unit quaternion, the shorter way round.
fn qlog(q: &Quat) -> [f64; 3] {
    let s = if q[0] < 0.0 { -1.0 } else { 1.0 };
    let v = (q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    if v == 0.0 {
        return [0.0; 3];
    }
    let angle = 2.0 * v.atan2(s * q[0]);
    let k = s * angle / v;
    [k * q[1], k * q[2], k * q[3]]
}

fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The inverse of the right-trivialised derivative of the exponential, truncated after the
/// terms order 4 needs: `u̇ = w + ½ u×w + (1/12) u×(u×w)` for `R = R₀ exp(û)`, `Ṙ = R ŵ`
/// (Iserles, Munthe-Kaas, Nørsett & Zanna, Acta Numerica 2000, §3.3, with the sign of the
/// odd term flipped for the right action).
fn dexpinv(u: &[f64; 3], w: &[f64; 3]) -> [f64; 3] {
    let uw = cross(u, w);
    let uuw = cross(u, &uw);
    [
        w[0] + 0.5 * uw[0] + uuw[0] / 12.0,
        w[1] + 0.5 * uw[1] + uuw[1] / 12.0,
        w[2] + 0.5 * uw[2] + uuw[2] / 12.0,
    ]
}

const Q: std::ops::Range<usize> = 3..7;

fn quat_of(y: &[f64]) -> Quat {
    [y[3], y[4], y[5], y[6]]
}

// ---------------------------------------------------------------------------------------

/// Runge–Kutta–Munthe-Kaas of order 4 with the classical RK4 tableau (Munthe-Kaas, BIT 38,
/// 1998; Hairer, Lubich & Wanner, *Geometric Numerical Integration*, §IV.8.2), fixed step.
///
/// The state is split into the attitude q ∈ S³ and everything else (ω, effector states) in
/// ℝⁿ. The stages move q by `q_n ⊗ Exp(u_i)` with u_i in the Lie algebra (rotation vectors,
/// body frame), the algebra's vector field being `dexpinv(u_i, ω_i)`; the other components
/// take the ordinary RK4 stages. The step ends at `q_n ⊗ Exp(v)`: a product of unit
/// quaternions, on S³ exactly whatever the step, so the truncation error never moves q off
/// the sphere. Rounding does: each floating-point product leaves S³ by ~1e-16, and left
/// alone that random-walks to ~1e-13 after 1e6 steps (measured). So the product is divided by
/// its norm whenever it is more than 4 ulp off: a correction of accumulated rounding only,
/// whose largest size is recorded ([`LieStepper::largest_rounding_correction`]; the tests
/// bound it by a few ulp).
/// Dense output: RK4's continuous extension on ℝⁿ, and on the attitude the same weights
/// applied in the algebra.
#[derive(Debug, Clone)]
pub struct LieStepper {
    grid: FixedGrid,
    t: f64,
    t_prev: f64,
    y: Vec<f64>,
    y_prev: Vec<f64>,
    k: [Vec<f64>; 4],
    /// Algebra components of the four stages (rad/s).
    xi: [[f64; 3]; 4],
    stage: Vec<f64>,
    largest_correction: f64,
    stats: Stats,
}

impl LieStepper {
    /// The largest ||q| − 1| met after a step's quaternion product, before it was divided
    /// out: the rounding of the product, never the truncation error.
    pub fn largest_rounding_correction(&self) -> f64 {
        self.largest_correction
    }

    /// Starts at `(t0, y0)` (state layout `[ω, q, …]`) with step `dt` (s, > 0).
    pub fn new(t0: f64, y0: &[f64], dt: f64) -> Self {
        let n = y0.len();
        LieStepper {
            grid: FixedGrid::new(t0, dt),
            t: t0,
            t_prev: t0,
            y: y0.to_vec(),
            y_prev: y0.to_vec(),
            k: std::array::from_fn(|_| vec![0.0; n]),
            xi: [[0.0; 3]; 4],
            stage: vec![0.0; n],
            largest_correction: 0.0,
            stats: Stats::default(),
        }
    }

    /// Fills `self.stage` with the stage state: ℝⁿ part `y + h·a·k_j`, attitude `q ⊗ Exp(u)`.
    fn set_stage(&mut self, j: usize, a: f64, h: f64, u: &[f64; 3]) {
        let q = qmul(&quat_of(&self.y), &qexp(u));
        let (y, k, s) = (&self.y, &self.k[j], &mut self.stage);
        for i in 0..y.len() {
            s[i] = y[i] + a * h * k[i];
        }
        s[Q].copy_from_slice(&q);
    }
}

impl Stepper for LieStepper {
    fn restart<S: OdeSystem + ?Sized>(&mut self, _sys: &S, y: &[f64]) {
        // At a breakpoint the run updated the held states: continue from them. Each step
        // evaluates its own stages, so nothing else is carried over.
        self.y.copy_from_slice(y);
    }
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
        let (t_next, on_grid) = self.grid.next(t_end);
        let t = self.t;
        let h = t_next - t;
        let w = |y: &[f64]| [y[0], y[1], y[2]];
        // Stage 1: u = 0, dexpinv is the identity.
        sys.rhs(t, &self.y, &mut self.k[0]);
        self.xi[0] = w(&self.y);
        // Stages 2–4: c = ½, ½, 1 with a = ½, ½, 1 on the previous stage.
        for (j, (c, a)) in [(0.5, 0.5), (0.5, 0.5), (1.0, 1.0)].into_iter().enumerate() {
            let u = self.xi[j].map(|x| a * h * x);
            self.set_stage(j, a, h, &u);
            let mut kj = std::mem::take(&mut self.k[j + 1]);
            sys.rhs(t + c * h, &self.stage, &mut kj);
            self.k[j + 1] = kj;
            self.xi[j + 1] = dexpinv(&u, &w(&self.stage));
        }
        self.stats.rhs_evaluations += 4;
        std::mem::swap(&mut self.y_prev, &mut self.y);
        let h6 = h / 6.0;
        let [k1, k2, k3, k4] = &self.k;
        for i in 0..self.y.len() {
            self.y[i] = self.y_prev[i] + h6 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
        }
        let x = &self.xi;
        let v: [f64; 3] =
            std::array::from_fn(|i| h6 * (x[0][i] + 2.0 * (x[1][i] + x[2][i]) + x[3][i]));
        let q = qmul(&quat_of(&self.y_prev), &qexp(&v));
        let norm = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
        let off = (norm - 1.0).abs();
        self.largest_correction = self.largest_correction.max(off);
        // Rescale only once the rounding has accumulated to a few ulp: rescaling by a factor
        // within an ulp of 1 rounds the components unevenly, a tiny systematic rotation
        // that, done every step, grew to 1.5e-12 rad in 1e6 steps (measured); done rarely,
        // by a larger factor, the rounding is unbiased.
        if off > 4.0 * f64::EPSILON {
            self.y[Q].copy_from_slice(&q.map(|c| c / norm));
        } else {
            self.y[Q].copy_from_slice(&q);
        }
        self.t_prev = t;
        self.t = t_next;
        self.grid.advance(on_grid);
        self.stats.steps += 1;
        Ok(t_next)
    }

    fn interpolate(&self, t: f64, out: &mut [f64]) {
        let h = self.t - self.t_prev;
        if h == 0.0 || t == self.t {
            out.copy_from_slice(&self.y);
            return;
        }
        // RK4's continuous extension (Hairer, Nørsett & Wanner, Solving ODEs I, §II.6).
        let th = (t - self.t_prev) / h;
        let (th2, th3) = (th * th, th * th * th);
        let b1 = th - 1.5 * th2 + 2.0 / 3.0 * th3;
        let b23 = th2 - 2.0 / 3.0 * th3;
        let b4 = -0.5 * th2 + 2.0 / 3.0 * th3;
        let [k1, k2, k3, k4] = &self.k;
        for i in 0..out.len() {
            out[i] = self.y_prev[i] + h * (b1 * k1[i] + b23 * (k2[i] + k3[i]) + b4 * k4[i]);
        }
        let x = &self.xi;
        let v: [f64; 3] =
            std::array::from_fn(|i| h * (b1 * x[0][i] + b23 * (x[1][i] + x[2][i]) + b4 * x[3][i]));
        out[Q].copy_from_slice(&qmul(&quat_of(&self.y_prev), &qexp(&v)));
    }
}

// ---------------------------------------------------------------------------------------

/// Splitting `f = A + B`: A is the torque-free rigid body of inertia J (the spacecraft's
/// inertia with its effectors at rest), advanced by its exact flow; B = f − A (torques,
/// effector dynamics and their coupling), advanced by one classical RK4 step per sub-step.
///
/// Order 2 is Strang's `B(h/2) A(h) B(h/2)`; order 4 composes three Strang steps with the
/// triple-jump weights γ₁ = 1/(2 − 2^{1/3}), γ₂ = 1 − 2γ₁ (Yoshida, Phys. Lett. A 150, 1990;
/// Hairer, Lubich & Wanner, §II.4 and §III.5). RK4 on B keeps the composed order, since its
/// local error O(h⁵) is below both orders. For a torque-free rigid body B vanishes and the
/// method is the exact solution at any step. With strong dissipation the negative sub-step
/// γ₂ runs the damping backwards, which limits the step (docs/choosing-a-method.md).
///
/// Dense output follows the free flow from the step's start (built on the first
/// interpolation inside a step), plus the departure from it interpolated by cubic Hermite
/// (in the Lie algebra for q) to meet the step's end: exact for a torque-free body. The
/// effectors' states take the cubic Hermite interpolant of the step's ends (f at each end:
/// one extra evaluation per step, reused by the next).
pub struct SplittingStepper {
    grid: FixedGrid,
    /// Strang weights of the composition.
    weights: Vec<f64>,
    inertia: Matrix3<f64>,
    inertia_inv: Matrix3<f64>,
    t: f64,
    t_prev: f64,
    y: Vec<f64>,
    y_prev: Vec<f64>,
    /// f at the step's start and end, for dense output (`f_end` is empty before the first
    /// step).
    f_prev: Vec<f64>,
    f_end: Vec<f64>,
    /// The free flow from the last step's start, built on demand for dense output.
    free_flow: std::cell::OnceCell<Option<TorqueFreeSolution>>,
    scratch: RkScratch,
    stats: Stats,
}

impl SplittingStepper {
    /// Starts at `(t0, y0)` with step `dt` (s) and `order` 2 or 4.
    pub fn new(sc: &Spacecraft, t0: f64, y0: &[f64], dt: f64, order: u8) -> Result<Self, String> {
        let rest = sc.rest_state(&Vector3::zeros(), &UnitQuaternion::identity());
        let inertia = sc.system_inertia(&rest);
        let inertia_inv = inertia
            .try_inverse()
            .ok_or("the spacecraft's inertia is singular")?;
        let weights = if order == 2 {
            vec![1.0]
        } else {
            let g1 = 1.0 / (2.0 - 2f64.cbrt());
            vec![g1, 1.0 - 2.0 * g1, g1]
        };
        Ok(SplittingStepper {
            grid: FixedGrid::new(t0, dt),
            weights,
            inertia,
            inertia_inv,
            t: t0,
            t_prev: t0,
            y: y0.to_vec(),
            y_prev: y0.to_vec(),
            f_prev: vec![0.0; y0.len()],
            f_end: Vec::new(),
            free_flow: std::cell::OnceCell::new(),
            scratch: RkScratch::default(),
            stats: Stats::default(),
        })
    }

    /// The torque-free part A at `y` (ω̇ of the free body of inertia J; q̇ is all B's
    /// complement, so B's q̇ is zero).
    fn free_omega_dot(&self, y: &[f64]) -> Vector3<f64> {
        let w = Vector3::new(y[0], y[1], y[2]);
        self.inertia_inv * (self.inertia * w).cross(&w)
    }

    /// B = f − A at `(t, y)` into `d`.
    fn b_rhs<S: OdeSystem + ?Sized>(&self, sys: &S, t: f64, y: &[f64], d: &mut [f64]) {
        sys.rhs(t, y, d);
        let a = self.free_omega_dot(y);
        d[0] -= a[0];
        d[1] -= a[1];
        d[2] -= a[2];
        d[Q].fill(0.0);
    }

    /// Exact flow of A over `tau` (s), in place. The closed form's set-up rounds the
    /// invariants it is built from, and rebuilding it every sub-step from the current state
    /// would add that rounding as a bias at every step (measured: energy drift ∝ steps). So
    /// the flow is applied as an increment: ω₁ = ω + (ω_s(τ) − ω_s(0)), q₁ = q ⊗ q_s(0)⁻¹ ⊗
    /// q_s(τ), with q rescaled like [`LieStepper`]'s once rounding has moved it 4 ulp.
    fn flow_a(&self, tau: f64, y: &mut [f64]) -> Result<(), String> {
        let w = Vector3::new(y[0], y[1], y[2]);
        let q = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(y[3], y[4], y[5], y[6]));
        let sol = TorqueFreeSolution::new(&self.inertia, &w, &q).map_err(|e| e.to_string())?;
        let (w0, q0) = sol.state_at(0.0);
        let (w1, q1) = sol.state_at(tau);
        let dw = w1 - w0;
        y[0] += dw[0];
        y[1] += dw[1];
        y[2] += dw[2];
        let dq = q0.inverse() * q1;
        let qy = [y[3], y[4], y[5], y[6]];
        let qn = qmul(&qy, &[dq.w, dq.i, dq.j, dq.k]);
        let norm = (qn[0] * qn[0] + qn[1] * qn[1] + qn[2] * qn[2] + qn[3] * qn[3]).sqrt();
        let qn = if (norm - 1.0).abs() > 4.0 * f64::EPSILON {
            qn.map(|c| c / norm)
        } else {
            qn
        };
        y[Q].copy_from_slice(&qn);
        Ok(())
    }

    /// One RK4 step of B over `tau` from `(t, y)`, in place, with the stages in `scratch`;
    /// returns evaluations used.
    fn flow_b<S: OdeSystem + ?Sized>(
        &self,
        sys: &S,
        t: f64,
        tau: f64,
        y: &mut [f64],
        scratch: &mut RkScratch,
    ) -> u64 {
        let n = y.len();
        let RkScratch { k, stage } = scratch;
        for v in k.iter_mut().chain(std::iter::once(&mut *stage)) {
            v.resize(n, 0.0);
        }
        self.b_rhs(sys, t, y, &mut k[0]);
        for (j, c) in [0.5, 0.5, 1.0].into_iter().enumerate() {
            for i in 0..n {
                stage[i] = y[i] + c * tau * k[j][i];
            }
            self.b_rhs(sys, t + c * tau, stage, &mut k[j + 1]);
        }
        for i in 0..n {
            y[i] += tau / 6.0 * (k[0][i] + 2.0 * (k[1][i] + k[2][i]) + k[3][i]);
        }
        4
    }

    /// The composition over `h` from `(t, y)`, in place; returns evaluations used.
    fn compose<S: OdeSystem + ?Sized>(
        &self,
        sys: &S,
        t: f64,
        h: f64,
        y: &mut [f64],
        scratch: &mut RkScratch,
    ) -> Result<u64, String> {
        let mut evals = 0;
        let mut tt = t;
        for &g in &self.weights {
            let tau = g * h;
            evals += self.flow_b(sys, tt, 0.5 * tau, y, scratch);
            self.flow_a(tau, y)?;
            evals += self.flow_b(sys, tt + 0.5 * tau, 0.5 * tau, y, scratch);
            tt += tau;
        }
        Ok(evals)
    }
}

/// Stage buffers of the RK4 sub-steps, kept across steps.
#[derive(Debug, Clone, Default)]
struct RkScratch {
    k: [Vec<f64>; 4],
    stage: Vec<f64>,
}

impl Stepper for SplittingStepper {
    fn restart<S: OdeSystem + ?Sized>(&mut self, sys: &S, y: &[f64]) {
        // At a breakpoint the run updated the held states: continue from them, with f at the
        // new state for the next step's dense output (the right-hand side jumps there).
        self.y.copy_from_slice(y);
        if !self.f_end.is_empty() {
            sys.rhs(self.t, &self.y, &mut self.f_end);
            self.stats.rhs_evaluations += 1;
        }
    }
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
        if self.f_end.is_empty() {
            self.f_end = vec![0.0; self.y.len()];
            sys.rhs(self.t, &self.y, &mut self.f_end);
            self.stats.rhs_evaluations += 1;
        }
        let (t_next, on_grid) = self.grid.next(t_end);
        let t = self.t;
        let h = t_next - t;
        let mut y = self.y.clone();
        let mut scratch = std::mem::take(&mut self.scratch);
        let evals = self.compose(sys, t, h, &mut y, &mut scratch);
        self.scratch = scratch;
        let evals = evals.map_err(|what| StepError::SubFlow { t, what })?;
        self.free_flow = std::cell::OnceCell::new();
        self.y_prev = std::mem::replace(&mut self.y, y);
        std::mem::swap(&mut self.f_prev, &mut self.f_end);
        sys.rhs(t_next, &self.y, &mut self.f_end);
        self.stats.rhs_evaluations += evals + 1;
        self.t_prev = t;
        self.t = t_next;
        self.grid.advance(on_grid);
        self.stats.steps += 1;
        Ok(t_next)
    }

    fn interpolate(&self, t: f64, out: &mut [f64]) {
        if t == self.t || self.t == self.t_prev {
            out.copy_from_slice(&self.y);
            return;
        }
        let h = self.t - self.t_prev;
        let tau = t - self.t_prev;
        let th = tau / h;
        // Cubic Hermite basis, for the effectors' states (and everything, as a fallback).
        let h00 = (1.0 + 2.0 * th) * (1.0 - th) * (1.0 - th);
        let h10 = th * (1.0 - th) * (1.0 - th);
        let h01 = th * th * (3.0 - 2.0 * th);
        let h11 = th * th * (th - 1.0);
        for (i, o) in out.iter_mut().enumerate() {
            *o = h00 * self.y_prev[i]
                + h * h10 * self.f_prev[i]
                + h01 * self.y[i]
                + h * h11 * self.f_end[i];
        }
        let yp = &self.y_prev;
        let flow = self.free_flow.get_or_init(|| {
            let w = Vector3::new(yp[0], yp[1], yp[2]);
            let q = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
                yp[3], yp[4], yp[5], yp[6],
            ));
            TorqueFreeSolution::new(&self.inertia, &w, &q).ok()
        });
        let Some(flow) = flow else {
            return;
        };
        // Free-flow prediction from the step's start, as increments (see `flow_a`).
        let predict = |s: f64| {
            let (w0, q0) = flow.state_at(0.0);
            let (w1, q1) = flow.state_at(s);
            let dq = q0.inverse() * q1;
            let w = [
                yp[0] + w1[0] - w0[0],
                yp[1] + w1[1] - w0[1],
                yp[2] + w1[2] - w0[2],
            ];
            let q = qmul(&quat_of(yp), &[dq.w, dq.i, dq.j, dq.k]);
            (w, q)
        };
        let (w_end, q_end) = predict(h);
        let (w_t, q_t) = predict(tau);
        // The departure from the free flow, e(τ), is cubic-Hermite interpolated: for ω,
        // e(0) = 0, e(h) = the miss at the end, e'(0) = B's ω̇ there; for q, a rotation
        // a rotation u(τ) with u(0) = 0, u'(0) = 0 (B moves q only through ω) and u(h) = the
        // miss at the end.
        let b_prev =
            Vector3::new(self.f_prev[0], self.f_prev[1], self.f_prev[2]) - self.free_omega_dot(yp);
        // e'(h) = f at the end minus the free field along the prediction, at its end.
        let b_end =
            Vector3::new(self.f_end[0], self.f_end[1], self.f_end[2]) - self.free_omega_dot(&w_end);
        let dw = [
            self.y[0] - w_end[0],
            self.y[1] - w_end[1],
            self.y[2] - w_end[2],
        ];
        for i in 0..3 {
            out[i] = w_t[i] + h01 * dw[i] + h * (h10 * b_prev[i] + h11 * b_end[i]);
        }
        // q = Exp(u) ⊗ q_pred with u in inertial axes, so u̇ ≈ R(q_pred) e_ω (no frame
        // rotation term, unlike a body-axes correction): Simpson's rule on [0, s], then the
        // (higher-order) gap to the end's miss closed with the h01 weight (keeps u'(0) = 0).
        let e_w = |x: f64| {
            let (a10, a01, a11) = (
                x * (1.0 - x) * (1.0 - x),
                x * x * (3.0 - 2.0 * x),
                x * x * (x - 1.0),
            );
            Vector3::from_fn(|i, _| a01 * dw[i] + h * (a10 * b_prev[i] + a11 * b_end[i]))
        };
        let inertial = |q: &Quat, v: Vector3<f64>| {
            UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(q[0], q[1], q[2], q[3])) * v
        };
        let simpson = |x: f64, q_mid: &Quat, q_x: &Quat| {
            (x * h / 6.0) * (4.0 * inertial(q_mid, e_w(0.5 * x)) + inertial(q_x, e_w(x)))
        };
        let (_, q_half_t) = predict(0.5 * tau);
        let (_, q_half_h) = predict(0.5 * h);
        let u_t = simpson(th, &q_half_t, &q_t);
        let u_one = simpson(1.0, &q_half_h, &q_end);
        let miss = qlog(&qmul(&quat_of(&self.y), &conjugate(&q_end)));
        let u: [f64; 3] = std::array::from_fn(|i| u_t[i] + h01 * (miss[i] - u_one[i]));
        out[Q].copy_from_slice(&qmul(&qexp(&u), &q_t));
    }
}

// ---------------------------------------------------------------------------------------

/// The closed-form torque-free solution as a [`Stepper`]: steps are evaluation points
/// (at most a fraction of a polhode period apart, so events are bracketed), and
/// interpolation is exact.
pub struct ExactStepper {
    solution: TorqueFreeSolution,
    h: f64,
    t: f64,
    t_prev: f64,
    y: Vec<f64>,
    stats: Stats,
}

impl ExactStepper {
    /// Refuses spacecraft with effectors: the closed form is for the torque-free rigid body.
    pub fn new(sc: &Spacecraft, y0: &[f64], output_rate: f64) -> Result<Self, String> {
        if !sc.effectors().is_empty() || sc.motion().is_some() {
            return Err(
                "method `exact` solves the torque-free rigid body only, and this \
                 spacecraft has effectors or a prescribed motion; use dop853 or auto"
                    .into(),
            );
        }
        let omega0 = Vector3::new(y0[0], y0[1], y0[2]);
        let q0 =
            UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(y0[3], y0[4], y0[5], y0[6]));
        let solution = TorqueFreeSolution::new(&sc.hub.inertia, &omega0, &q0)
            .map_err(|e| format!("the exact solution is not available: {e}"))?;
        let period = solution.polhode_period();
        // Rotation rate bounds how fast anything observable can change.
        let spin = omega0.norm().max(1e-300);
        let mut h = (1.0 / output_rate).min(0.25 / spin);
        if period.is_finite() && period > 0.0 {
            h = h.min(period / 32.0);
        }
        Ok(ExactStepper {
            solution,
            h,
            t: 0.0,
            t_prev: 0.0,
            y: y0.to_vec(),
            stats: Stats::default(),
        })
    }

    /// The state at any time `t` (s) in one evaluation, whatever the horizon: what a
    /// benchmark of the closed form should time (the stepping only serves sampling and
    /// event location).
    pub fn state_at(&self, t: f64) -> Vec<f64> {
        let mut out = self.y.clone();
        self.evaluate(t, &mut out, &self.y);
        out
    }

    fn evaluate(&self, t: f64, out: &mut [f64], reference: &[f64]) {
        let (w, q) = self.solution.state_at(t);
        // Keep the quaternion on the same hemisphere as the reference, for smooth telemetry.
        let s = if q.w * reference[3] + q.i * reference[4] + q.j * reference[5] + q.k * reference[6]
            < 0.0
        {
            -1.0
        } else {
            1.0
        };
        out[..3].copy_from_slice(w.as_slice());
        out[3] = s * q.w;
        out[4] = s * q.i;
        out[5] = s * q.j;
        out[6] = s * q.k;
    }
}

impl Stepper for ExactStepper {
    fn restart<S: OdeSystem + ?Sized>(&mut self, _sys: &S, _y: &[f64]) {
        // Rigid bodies only (no effector, so no breakpoint and no held state).
    }
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
    fn step<S: OdeSystem + ?Sized>(&mut self, _sys: &S, t_end: f64) -> Result<f64, StepError> {
        let t1 = if t_end - self.t <= self.h * (1.0 + 1e-9) {
            t_end
        } else {
            self.t + self.h
        };
        // Evaluate into a stack buffer (the hemisphere reference is the current state).
        let mut y = [0.0; 7];
        self.evaluate(t1, &mut y, &self.y);
        self.y.copy_from_slice(&y);
        self.t_prev = self.t;
        self.t = t1;
        self.stats.steps += 1;
        Ok(t1)
    }
    fn interpolate(&self, t: f64, out: &mut [f64]) {
        self.evaluate(t, out, &self.y);
    }
}
