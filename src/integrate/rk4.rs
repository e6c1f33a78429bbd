//! Classic fourth-order Runge–Kutta with a fixed step and a third-order continuous extension.

use super::grid::FixedGrid;
use super::{OdeSystem, Stats, StepError, Stepper};

/// Classic RK4, fixed step `dt` (the last step is shortened to land on `t_end`).
///
/// It never fails by itself: a non-finite state is diagnosed by the caller (the run loop
/// checks every step), which keeps this inner loop free of per-step scans.
///
/// Dense output uses the third-order continuous extension of RK4 (Hairer, Nørsett & Wanner,
/// *Solving ODEs I*, §II.6), which needs no extra right-hand-side evaluation.
#[derive(Debug, Clone)]
pub struct Rk4 {
    /// Step n ends at `t0 + n·dt` (see [`FixedGrid`]).
    grid: FixedGrid,
    t: f64,
    t_prev: f64,
    y: Vec<f64>,
    y_prev: Vec<f64>,
    k: [Vec<f64>; 4],
    scratch: Vec<f64>,
    stats: Stats,
}

impl Rk4 {
    /// Starts at `(t0, y0)` with step `dt` (s, > 0).
    pub fn new(t0: f64, y0: &[f64], dt: f64) -> Self {
        let n = y0.len();
        Rk4 {
            grid: FixedGrid::new(t0, dt),
            t: t0,
            t_prev: t0,
            y: y0.to_vec(),
            y_prev: y0.to_vec(),
            k: [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]],
            scratch: vec![0.0; n],
            stats: Stats::default(),
        }
    }

    /// The nominal step (s).
    pub fn dt(&self) -> f64 {
        self.grid.dt()
    }
}

impl Rk4 {
    /// One step of size `h` for a state of any length, stages in the heap buffers.
    fn advance_general<S: OdeSystem + ?Sized>(&mut self, sys: &S, t: f64, h: f64) {
        let n = self.y.len();
        let [k1, k2, k3, k4] = &mut self.k;
        let y = &self.y[..n];
        let s = &mut self.scratch[..n];
        sys.rhs(t, y, k1);
        for i in 0..n {
            s[i] = y[i] + 0.5 * h * k1[i];
        }
        sys.rhs(t + 0.5 * h, s, k2);
        for i in 0..n {
            s[i] = y[i] + 0.5 * h * k2[i];
        }
        sys.rhs(t + 0.5 * h, s, k3);
        for i in 0..n {
            s[i] = y[i] + h * k3[i];
        }
        sys.rhs(t + h, s, k4);
        std::mem::swap(&mut self.y_prev, &mut self.y);
        let h6 = h / 6.0;
        let (y_new, y_old) = (&mut self.y[..n], &self.y_prev[..n]);
        let (k1, k2, k3, k4) = (&k1[..n], &k2[..n], &k3[..n], &k4[..n]);
        for i in 0..n {
            y_new[i] = y_old[i] + h6 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
        }
    }

    /// The same step for a state of length `N`, with the stages in stack arrays; the stages
    /// kept for dense output are copied back afterwards. Bit-for-bit the same arithmetic.
    #[inline(always)]
    fn advance_fixed<const N: usize, S: OdeSystem + ?Sized>(&mut self, sys: &S, t: f64, h: f64) {
        let mut y = [0.0; N];
        y.copy_from_slice(&self.y);
        let (mut k1, mut k2, mut k3, mut k4) = ([0.0; N], [0.0; N], [0.0; N], [0.0; N]);
        sys.rhs(t, &y, &mut k1);
        let s: [f64; N] = std::array::from_fn(|i| y[i] + 0.5 * h * k1[i]);
        sys.rhs(t + 0.5 * h, &s, &mut k2);
        let s: [f64; N] = std::array::from_fn(|i| y[i] + 0.5 * h * k2[i]);
        sys.rhs(t + 0.5 * h, &s, &mut k3);
        let s: [f64; N] = std::array::from_fn(|i| y[i] + h * k3[i]);
        sys.rhs(t + h, &s, &mut k4);
        let h6 = h / 6.0;
        let y_new: [f64; N] =
            std::array::from_fn(|i| y[i] + h6 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]));
        self.y_prev.copy_from_slice(&y);
        self.y.copy_from_slice(&y_new);
        self.k[0].copy_from_slice(&k1);
        self.k[1].copy_from_slice(&k2);
        self.k[2].copy_from_slice(&k3);
        self.k[3].copy_from_slice(&k4);
    }
}

impl Stepper for Rk4 {
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
        // The step's end from the grid; the step size is the difference of the two times, so
        // the increments add up to the times exactly (accumulating `t += dt` would make the
        // integrated time lag the label by ~n·ulp).
        let (t_next, on_grid) = self.grid.next(t_end);
        let t = self.t;
        let h = t_next - t;
        match self.y.len() {
            // The rigid body's size: stages in stack arrays the compiler keeps in registers.
            7 => self.advance_fixed::<7, S>(sys, t, h),
            _ => self.advance_general(sys, t, h),
        }
        self.stats.rhs_evaluations += 4;
        self.t_prev = t;
        self.t = t_next;
        self.grid.advance(on_grid);
        self.stats.steps += 1;
        Ok(self.t)
    }

    fn restart<S: OdeSystem + ?Sized>(&mut self, _sys: &S, y: &[f64]) {
        self.y.copy_from_slice(y);
        // Each step evaluates its own stages: nothing carried over.
    }

    fn interpolate(&self, t: f64, out: &mut [f64]) {
        let h = self.t - self.t_prev;
        // The step's ends are returned as stored (also when the stages overflowed).
        if h == 0.0 || t == self.t {
            out.copy_from_slice(&self.y);
            return;
        }
        if t == self.t_prev {
            out.copy_from_slice(&self.y_prev);
            return;
        }
        let th = (t - self.t_prev) / h;
        let th2 = th * th;
        let th3 = th2 * th;
        let b1 = th - 1.5 * th2 + 2.0 / 3.0 * th3;
        let b23 = th2 - 2.0 / 3.0 * th3;
        let b4 = -0.5 * th2 + 2.0 / 3.0 * th3;
        let [k1, k2, k3, k4] = &self.k;
        for i in 0..out.len() {
            out[i] = self.y_prev[i] + h * (b1 * k1[i] + b23 * (k2[i] + k3[i]) + b4 * k4[i]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::test_systems::{Clock, Exponential};

    /// A 7-state system (the fixed-size path) and the same system with an 8th, inert state
    /// (the general path): the first seven components must agree bit for bit.
    struct Rotor {
        pad: bool,
    }
    impl OdeSystem for Rotor {
        fn dim(&self) -> usize {
            if self.pad { 8 } else { 7 }
        }
        fn rhs(&self, t: f64, y: &[f64], d: &mut [f64]) {
            for i in 0..7 {
                d[i] = -y[(i + 1) % 7] * (1.0 + 0.1 * i as f64) + (0.3 * t).sin();
            }
            if self.pad {
                d[7] = 0.0;
            }
        }
    }

    #[test]
    fn fixed_size_and_general_paths_agree_bit_for_bit() {
        let y0 = [0.1, -0.2, 0.3, 1.0, 0.5, -0.7, 0.2];
        let mut padded = y0.to_vec();
        padded.push(4.0);
        let mut a = Rk4::new(0.0, &y0, 0.01);
        let mut b = Rk4::new(0.0, &padded, 0.01);
        for _ in 0..1000 {
            a.step(&Rotor { pad: false }, 100.0).unwrap();
            b.step(&Rotor { pad: true }, 100.0).unwrap();
        }
        assert_eq!(a.y(), &b.y()[..7]);
        let (mut da, mut db) = ([0.0; 7], [0.0; 8]);
        a.interpolate(9.995, &mut da);
        b.interpolate(9.995, &mut db);
        assert_eq!(da, db[..7]);
    }

    /// y' = 1 from a large t0: the integrated time y must equal the time label at the end.
    /// Accumulating `t += dt` at t ≈ 1e6 (ulp 1.2e-10) drifts the label by ~1e-6 s over 1e5
    /// steps, and the shortened last step then hides the drift in the state instead.
    #[test]
    fn integrated_time_matches_the_time_label() {
        let (t0, t_end) = (1.0e6, 1.0e6 + 1.0e4);
        let mut s = Rk4::new(t0, &[0.0], 0.1);
        while s.t() < t_end {
            s.step(&Clock, t_end).unwrap();
        }
        assert_eq!(s.stats().steps, 100_000);
        assert!((s.y()[0] - 1.0e4).abs() < 1e-9, "y = {}", s.y()[0]);
    }

    #[test]
    fn convergence_order_is_four() {
        // y' = −y on [0, 2]: error against e^{−2} at two steps.
        let err = |dt: f64| {
            let mut s = Rk4::new(0.0, &[1.0], dt);
            while s.t() < 2.0 {
                s.step(&Exponential(-1.0), 2.0).unwrap();
            }
            (s.y()[0] - (-2.0f64).exp()).abs()
        };
        let order = (err(0.1) / err(0.05)).log2();
        assert!((order - 4.0).abs() < 0.1, "order {order}");
    }
}
