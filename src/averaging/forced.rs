//! Effectors with internal degrees of freedom (spring–mass dampers, hinged rods, modal
//! appendages): their dissipation averaged over the periodic orbits of the coupled spacecraft
//! with its dashpots removed, tabulated in the nutation angle at fixed |H| once per scene
//! (docs/averaging.md).
//!
//! - [`coupled_orbit`]: at given |H| and energy, the periodic orbit in body axes of the
//!   undamped spacecraft (rates and appendage states return after one period), by
//!   Gauss–Newton on the period map with a phase condition, a finite-difference Jacobian and
//!   Broyden updates; the damped model's dissipation power averaged along it.
//! - [`periodic_response`]: the appendages alone driven by the locked spacecraft's
//!   torque-free motion (one-way coupling), the orbit search's first guess. On its own it
//!   dissipates 19 % too much on Explorer 1, whose antenna modes lie near the nutation
//!   frequency.
//! - [`DissipationTable`]: the orbits at Chebyshev nodes in the nutation angle, for an
//!   axisymmetric locked spacecraft.

use crate::exact::TorqueFreeSolution;
use crate::integrate::{Dop853, OdeSystem, Stepper, Tolerances};
use crate::model::{HubState, Secular, SecularMotion, SecularRates, Spacecraft};
use nalgebra::{DMatrix, DVector, Matrix3, UnitQuaternion, Vector3};
use std::cell::RefCell;
use std::sync::Arc;

/// The spacecraft's effectors driven by a prescribed torque-free hub motion.
struct Driven<'a> {
    sc: &'a Spacecraft,
    motion: &'a TorqueFreeSolution,
    inertia: Matrix3<f64>,
    inertia_inv: Matrix3<f64>,
    /// The state with the prescribed rates written in, reused from call to call.
    state: RefCell<Vec<f64>>,
}

impl OdeSystem for Driven<'_> {
    fn dim(&self) -> usize {
        self.sc.dim()
    }
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        let omega = self.motion.omega_at(t);
        let omega_dot = self.inertia_inv * (self.inertia * omega).cross(&omega);
        let mut state = self.state.borrow_mut();
        state.clear();
        state.extend_from_slice(y);
        state[..3].copy_from_slice(omega.as_slice());
        self.sc.rhs_prescribed(t, &state, &omega_dot, true, dydt);
        dydt[..3].copy_from_slice(omega_dot.as_slice());
    }
}

/// The periodic response at one slow state.
#[derive(Debug, Clone)]
pub struct PeriodicResponse {
    /// Polhode period P (s).
    pub period: f64,
    /// Each dissipating effector's energy dissipated over one period, over P (W).
    pub powers: Vec<f64>,
    /// Newton iterations taken.
    pub iterations: usize,
    /// |x(P) − x(0)| at the solution, relative to max(|x|, 1e-6).
    pub residual: f64,
}

/// Which states of the spacecraft the shooting solves for, and where each effector's dissipated
/// energy is.
#[derive(Debug, Clone)]
pub struct Layout {
    /// Indices of the effectors' dynamic states in the state vector.
    pub dynamic: Vec<usize>,
    /// Index of each averaged effector's dissipated energy in the state vector.
    pub dissipated: Vec<usize>,
}

/// Integrates `y` over [0, `period`] under `system`.
/// `what` names the system in an error.
fn flow<S: OdeSystem>(
    system: &S,
    y: &mut [f64],
    period: f64,
    rtol: f64,
    what: &str,
) -> Result<(), String> {
    let tol = Tolerances {
        rtol,
        atol: rtol * 1e-3,
    };
    let mut stepper = Dop853::new(0.0, y, tol, f64::INFINITY, None).with_dense_output(false);
    while stepper.t() < period {
        stepper
            .step(system, period)
            .map_err(|e| format!("{what} could not be integrated: {e}"))?;
    }
    y.copy_from_slice(stepper.y());
    Ok(())
}

/// The periodic response of the effectors of `sc` (state layout `layout`, starting guess
/// `guess` for the dynamic states, the rest of the state from `y0`) to the torque-free motion
/// of the locked body `inertia` with rates `omega_ref` at t = 0.
pub fn periodic_response(
    sc: &Spacecraft,
    y0: &[f64],
    layout: &Layout,
    inertia: &Matrix3<f64>,
    omega_ref: &Vector3<f64>,
    guess: &[f64],
    rtol: f64,
) -> Result<(PeriodicResponse, Vec<f64>), String> {
    let motion = TorqueFreeSolution::new(inertia, omega_ref, &UnitQuaternion::identity())
        .map_err(|e| format!("the locked spacecraft's motion: {e}"))?;
    let period = motion.polhode_period();
    if !(period.is_finite() && period > 0.0) {
        return Err("the locked spacecraft's motion has no finite period here".into());
    }
    let system = Driven {
        sc,
        motion: &motion,
        inertia: *inertia,
        inertia_inv: inertia
            .try_inverse()
            .ok_or("the locked inertia is singular")?,
        state: RefCell::new(Vec::with_capacity(sc.dim())),
    };
    let n = layout.dynamic.len();
    let start = |x: &[f64]| -> Vec<f64> {
        let mut y = y0.to_vec();
        y[..3].copy_from_slice(omega_ref.as_slice());
        for (&i, &v) in layout.dynamic.iter().zip(x) {
            y[i] = v;
        }
        for &i in &layout.dissipated {
            y[i] = 0.0;
        }
        y
    };
    let map = |x: &[f64]| -> Result<Vec<f64>, String> {
        let mut y = start(x);
        flow(&system, &mut y, period, rtol, "the driven effectors")?;
        Ok(y)
    };
    let mut x = guess.to_vec();
    let mut iterations = 0;
    let mut residual = f64::INFINITY;
    let mut end = map(&x)?;
    for _ in 0..8 {
        let g = DVector::from_iterator(n, layout.dynamic.iter().zip(&x).map(|(&i, v)| end[i] - v));
        let scale = x.iter().fold(1e-6_f64, |m, v| m.max(v.abs()));
        residual = g.amax() / scale;
        if residual < 1e-9 {
            break;
        }
        iterations += 1;
        // Jacobian of the period map minus the identity, by forward differences.
        let mut jac = DMatrix::zeros(n, n);
        for c in 0..n {
            let step = 1e-7 * scale.max(x[c].abs());
            let mut xp = x.clone();
            xp[c] += step;
            let yp = map(&xp)?;
            for (r, &i) in layout.dynamic.iter().enumerate() {
                jac[(r, c)] = (yp[i] - end[i]) / step - if r == c { 1.0 } else { 0.0 };
            }
        }
        let dx = jac
            .lu()
            .solve(&(-g))
            .ok_or("the period map's Jacobian is singular (an undamped resonance?)")?;
        for (v, d) in x.iter_mut().zip(dx.iter()) {
            *v += d;
        }
        end = map(&x)?;
    }
    if residual.is_nan() || residual >= 1e-6 {
        return Err(format!(
            "the effectors' periodic response did not converge (residual {residual:.1e})"
        ));
    }
    let powers = layout.dissipated.iter().map(|&i| end[i] / period).collect();
    Ok((
        PeriodicResponse {
            period,
            powers,
            iterations,
            residual,
        },
        x,
    ))
}

/// The spacecraft with every effector's dissipation removed.
pub fn undamped(sc: &Spacecraft) -> Result<Spacecraft, String> {
    let mut out = Spacecraft::new(sc.hub.clone(), sc.spin_axis);
    out.hub_mass = sc.hub_mass;
    for e in sc.effectors() {
        let free = e.without_dissipation().ok_or_else(|| {
            format!(
                "effector `{}` ({}) cannot be made conservative",
                e.name(),
                e.kind()
            )
        })?;
        out.add_effector(free).map_err(|e| e.to_string())?;
    }
    Ok(out)
}

/// A periodic orbit, in body axes, of the undamped spacecraft at given |H| and energy.
#[derive(Debug, Clone)]
pub struct CoupledOrbit {
    /// Its period (s).
    pub period: f64,
    /// Body rates at its start (rad/s).
    pub omega0: Vector3<f64>,
    /// The effectors' dynamic states at its start.
    pub x0: Vec<f64>,
    /// Each effector's dissipation power (in the damped spacecraft) averaged along it (W).
    pub powers: Vec<f64>,
    /// Gauss–Newton iterations taken.
    pub iterations: usize,
    /// The largest scaled residual at the solution.
    pub residual: f64,
}

/// The periodic orbit (in body axes) of `free` (the undamped spacecraft) with |H| = `h` and
/// kinetic plus elastic energy `energy`, whose rates at t = 0 are normal to `phase_axis`,
/// from `guess` = (ω₀, dynamic states, period); and the dissipation power of `damped` (the
/// same spacecraft with its dashpots) averaged along it.
#[allow(clippy::too_many_arguments)]
pub fn coupled_orbit(
    damped: &Spacecraft,
    free: &Spacecraft,
    y0: &[f64],
    layout: &Layout,
    h: f64,
    energy: f64,
    phase_axis: &Vector3<f64>,
    guess: (Vector3<f64>, &[f64], f64),
    rtol: f64,
) -> Result<CoupledOrbit, String> {
    let n = layout.dynamic.len();
    let unknowns = 3 + n + 1;
    let rows = 3 + n + 3;
    let mut v = Vec::with_capacity(unknowns);
    v.extend_from_slice(guess.0.as_slice());
    v.extend_from_slice(guess.1);
    v.push(guess.2);
    let spin = guess.0.norm();
    let start = |v: &[f64]| -> Vec<f64> {
        let mut y = y0.to_vec();
        y[..3].copy_from_slice(&v[..3]);
        for (&i, &x) in layout.dynamic.iter().zip(&v[3..3 + n]) {
            y[i] = x;
        }
        for &i in &layout.dissipated {
            y[i] = 0.0;
        }
        y
    };
    let tol = Tolerances {
        rtol,
        atol: rtol * 1e-3,
    };
    let residuals = |v: &[f64]| -> Result<Vec<f64>, String> {
        let y_start = start(v);
        let mut y = y_start.clone();
        flow(free, &mut y, v[3 + n], rtol, "the undamped spacecraft")?;
        let inv = free.invariants(0.0, &y_start);
        let mut r = Vec::with_capacity(rows);
        for c in 0..3 {
            r.push((y[c] - y_start[c]) / spin);
        }
        for &i in &layout.dynamic {
            r.push(y[i] - y_start[i]);
        }
        r.push(inv.h_body.norm() / h - 1.0);
        r.push((inv.kinetic_energy + inv.elastic_energy) / energy - 1.0);
        r.push(Vector3::new(v[0], v[1], v[2]).dot(phase_axis) / spin);
        Ok(r)
    };
    let mut r = residuals(&v)?;
    let mut iterations = 0;
    let norm = |r: &[f64]| r.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    // Gauss–Newton with a finite-difference Jacobian at the start and Broyden's rank-1 updates
    // after each step (one integration per iteration instead of one per unknown).
    let mut jac = DMatrix::zeros(rows, unknowns);
    let mut fresh = false;
    while norm(&r) > 1e-10 && iterations < 16 {
        iterations += 1;
        if !fresh {
            for c in 0..unknowns {
                let step = 1e-7
                    * v[c].abs().max(if c < 3 {
                        spin
                    } else if c < 3 + n {
                        1e-3
                    } else {
                        v[c]
                    });
                let mut vp = v.clone();
                vp[c] += step;
                let rp = residuals(&vp)?;
                for k in 0..rows {
                    jac[(k, c)] = (rp[k] - r[k]) / step;
                }
            }
            fresh = true;
        }
        let dv = jac
            .clone()
            .svd(true, true)
            .solve(&(-DVector::from_vec(r.clone())), 1e-12)
            .map_err(|e| format!("the orbit's Gauss–Newton step failed: {e}"))?;
        // Halve the step until the residual falls (and the period stays within a factor of 2
        // of the guess), at most 6 times.
        let mut scale = 1.0;
        let mut accepted = None;
        for _ in 0..6 {
            let trial: Vec<f64> = v
                .iter()
                .zip(dv.iter())
                .map(|(x, d)| x + scale * d)
                .collect();
            let p = trial[3 + n];
            if p > 0.5 * guess.2 && p < 2.0 * guess.2 {
                let rt = residuals(&trial)?;
                if norm(&rt) < norm(&r) {
                    accepted = Some((trial, rt, scale));
                    break;
                }
            }
            scale *= 0.5;
        }
        match accepted {
            Some((trial, rt, scale)) => {
                // Broyden: J += (Δr − J Δv) Δvᵀ / |Δv|².
                let step = &dv * scale;
                let dr = DVector::from_iterator(rows, rt.iter().zip(&r).map(|(a, b)| a - b));
                let denom = step.norm_squared();
                if denom > 0.0 {
                    let update = (dr - &jac * &step) * step.transpose() / denom;
                    jac += update;
                }
                v = trial;
                r = rt;
            }
            // No descent with a Broyden Jacobian: recompute it; with a fresh one, give up.
            None if fresh && iterations > 1 => fresh = false,
            None => break,
        }
    }
    let residual = norm(&r);
    if residual.is_nan() || residual >= 1e-7 {
        return Err(format!(
            "the undamped spacecraft's periodic orbit did not converge (residual {residual:.1e})"
        ));
    }
    // The damped model's dissipation power, averaged along the orbit (periodic trapezoid).
    let period = v[3 + n];
    let samples = 256;
    let mut y = start(&v);
    let mut stepper = Dop853::new(0.0, &y, tol, f64::INFINITY, None).with_dense_output(false);
    let mut powers = vec![0.0; damped.effectors().len()];
    let mut add = |t: f64, y: &[f64]| {
        let hub = HubState {
            t,
            omega: Vector3::new(y[0], y[1], y[2]),
            attitude: &y[3..7],
        };
        for (k, e) in damped.effectors().iter().enumerate() {
            powers[k] += e.energy(&hub, damped.effector_states(k, y)).power / samples as f64;
        }
    };
    add(0.0, &y);
    for k in 1..samples {
        let t = period * k as f64 / samples as f64;
        while stepper.t() < t {
            stepper
                .step(free, t)
                .map_err(|e| format!("the undamped spacecraft could not be integrated: {e}"))?;
        }
        y.copy_from_slice(stepper.y());
        add(t, &y);
    }
    Ok(CoupledOrbit {
        period,
        omega0: Vector3::new(v[0], v[1], v[2]),
        x0: v[3..3 + n].to_vec(),
        powers,
        iterations,
        residual,
    })
}

/// The effectors' averaged dissipation over the coupled periodic orbits of a spacecraft whose
/// locked inertia is axisymmetric, tabulated in the nutation angle θ (between H and the
/// symmetry axis) at fixed |H|: T = ½|H|² (cos²θ/I_s + sin²θ/I_t) maps θ to the energy.
/// The power vanishes like sin²θ cos²θ at both ends, so the table holds the smooth
/// f(θ) = P(θ) / (sin²θ cos²θ), interpolated by Chebyshev's barycentric formula.
#[derive(Debug)]
pub struct DissipationTable {
    /// Moment about the symmetry axis and the transverse moment (kg m²).
    i_s: f64,
    i_t: f64,
    /// Chebyshev nodes in θ (rad) on [a, b], and their barycentric weights.
    nodes: Vec<f64>,
    weights: Vec<f64>,
    /// f at each node, per effector (W).
    f: Vec<Vec<f64>>,
    a: f64,
    b: f64,
}

/// Nutation nodes per table.
const NODES: usize = 10;
/// The table stops this far (rad) from the flat spin (or the pure spin): nearer, the orbits'
/// period grows without bound and the appendages' response turns strongly nonlinear. Beyond
/// it f is held at its end value.
const END_MARGIN: f64 = 8.0 * std::f64::consts::PI / 180.0;

impl DissipationTable {
    /// Tabulates the dissipation of `sc`'s effectors from the initial state `y0` toward the
    /// end state (the spin about the axis of most inertia), with shooting tolerance `rtol`.
    pub fn new(sc: &Spacecraft, y0: &[f64], layout: &Layout, rtol: f64) -> Result<Self, String> {
        let inertia = sc.system_inertia(y0);
        let body = crate::model::RigidBody::new(inertia)
            .map_err(|e| format!("the locked spacecraft's inertia: {e}"))?;
        let [i1, i2, i3] = [
            body.principal_moments.x,
            body.principal_moments.y,
            body.principal_moments.z,
        ];
        let tol = 1e-9 * i3;
        let (axis, i_s, i_t) = if i3 - i2 <= tol && i2 - i1 > tol {
            (0, i1, 0.5 * (i2 + i3))
        } else if i2 - i1 <= tol && i3 - i2 > tol {
            (2, i3, 0.5 * (i1 + i2))
        } else {
            return Err(format!(
                "the spacecraft locked in its initial configuration is not axisymmetric \
                 (principal moments {i1:.6e}, {i2:.6e}, {i3:.6e} kg m²); averaging effectors \
                 with internal degrees of freedom is implemented for axisymmetric spacecraft \
                 only"
            ));
        };
        let sym = body.principal_axes.column(axis).into_owned();
        let omega0 = Vector3::new(y0[0], y0[1], y0[2]);
        let h_vec = inertia * omega0;
        let h = h_vec.norm();
        let theta0 = (h_vec.dot(&sym).abs() / h).clamp(-1.0, 1.0).acos();
        // Dissipation drives θ toward 90° for a minor-axis spinner, toward 0 otherwise.
        let (a, b) = if i_s < i_t {
            (theta0, std::f64::consts::FRAC_PI_2 - END_MARGIN)
        } else {
            (END_MARGIN, theta0)
        };
        if b <= a || b.is_nan() || a.is_nan() {
            return Err("the initial nutation is already at the end state".into());
        }
        let nodes: Vec<f64> = (0..NODES)
            .map(|k| {
                let x = (std::f64::consts::PI * (k as f64 + 0.5) / NODES as f64).cos();
                0.5 * (a + b) + 0.5 * (b - a) * x
            })
            .collect();
        let free = undamped(sc)?;
        // The transverse axis normal to the reference rates fixes the orbit's phase.
        let transverse = body
            .principal_axes
            .column(if axis == 0 { 2 } else { 0 })
            .into_owned();
        let phase_axis = sym.cross(&transverse);
        let mut f = Vec::with_capacity(NODES);
        // Continue from the node nearest the initial state.
        let order: Vec<usize> = if i_s < i_t {
            (0..NODES).rev().collect()
        } else {
            (0..NODES).collect()
        };
        let mut guess: Option<(Vec<f64>, f64, f64)> = None;
        let mut values = vec![Vec::new(); NODES];
        for &k in &order {
            let th = nodes[k];
            let (s, c) = th.sin_cos();
            // The locked body's motion at this θ: rates with H at θ from the axis, normal to
            // the phase axis.
            let omega = (sym * (h * c / i_s)) + transverse * (h * s / i_t);
            // The guess: at the first node, the appendages' response to the locked body's
            // motion; then the previous orbit's appendage states, and its period scaled by the
            // locked body's nutation rate λ = |H cos θ (I_t − I_s)/(I_s I_t)|.
            let rate = |th: f64| (h * th.cos() * (i_t - i_s) / (i_s * i_t)).abs();
            let (x, p) = match guess.take() {
                Some((x_prev, p_prev, th_prev)) => (x_prev, p_prev * rate(th_prev) / rate(th)),
                None => {
                    let start = vec![0.0; layout.dynamic.len()];
                    let (r, x) = periodic_response(sc, y0, layout, &inertia, &omega, &start, rtol)
                        .map_err(|e| format!("at a nutation of {:.2}°: {e}", th.to_degrees()))?;
                    (x, r.period)
                }
            };
            let w = omega;
            // The orbit's kinetic plus elastic energy is the locked body's T at this θ: the
            // slow variable the table is read with.
            let total = 0.5 * h * h * (c * c / i_s + s * s / i_t);
            let orbit = coupled_orbit(
                sc,
                &free,
                y0,
                layout,
                h,
                total,
                &phase_axis,
                (w, &x, p),
                rtol,
            )
            .map_err(|e| format!("at a nutation of {:.2}°: {e}", th.to_degrees()))?;
            let shape = (s * c).powi(2);
            values[k] = orbit.powers.iter().map(|p| p / shape).collect();
            guess = Some((orbit.x0, orbit.period, th));
        }
        f.extend(values);
        // Barycentric weights of Chebyshev points of the first kind.
        let weights = (0..NODES)
            .map(|j| {
                (if j % 2 == 0 { 1.0 } else { -1.0 })
                    * (std::f64::consts::PI * (j as f64 + 0.5) / NODES as f64).sin()
            })
            .collect();
        Ok(DissipationTable {
            i_s,
            i_t,
            nodes,
            weights,
            f,
            a,
            b,
        })
    }

    /// θ (rad) at kinetic energy `energy` (J) and |H| = `h`.
    fn theta(&self, h: f64, energy: f64) -> f64 {
        // 2T/h² = cos²θ/I_s + sin²θ/I_t.
        let x = 2.0 * energy / (h * h);
        let s2 = ((x - 1.0 / self.i_s) / (1.0 / self.i_t - 1.0 / self.i_s)).clamp(0.0, 1.0);
        s2.sqrt().asin()
    }

    /// Effector `k`'s averaged dissipation power (W) at `energy` (J).
    pub fn power(&self, k: usize, h: f64, energy: f64) -> f64 {
        let theta = self.theta(h, energy);
        let th = theta.clamp(self.a, self.b);
        let shape = {
            let (s, c) = theta.sin_cos();
            (s * c).powi(2)
        };
        // Barycentric interpolation at Chebyshev points of the first kind.
        let mut num = 0.0;
        let mut den = 0.0;
        for (j, &xj) in self.nodes.iter().enumerate() {
            let d = th - xj;
            if d == 0.0 {
                return self.f[j][k] * shape;
            }
            let w = self.weights[j];
            num += w / d * self.f[j][k];
            den += w / d;
        }
        num / den * shape
    }
}

/// One effector's share of a [`DissipationTable`], as the averaged method asks for it.
#[derive(Debug)]
pub struct Tabulated {
    /// The shared table.
    pub table: Arc<DissipationTable>,
    /// Which effector.
    pub index: usize,
}

impl Secular for Tabulated {
    fn rates(&self, motion: &SecularMotion) -> SecularRates {
        let p = self.table.power(self.index, motion.h, motion.energy);
        SecularRates {
            energy_rate: -p,
            h_rate: 0.0,
            dissipation_rate: p,
            ..SecularRates::default()
        }
    }
}
