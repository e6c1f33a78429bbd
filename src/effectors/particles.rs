//! Effectors made of particles whose body-frame positions are functions of a few coordinates
//! (spring–mass dampers, hinged rods, modal beams), with their equations of motion derived
//! once here, by the principle of virtual work, for all of them.
//!
//! Particle p has mass m_p and position r_p(q) about the hub's centre of mass B (body axes),
//! with Jacobian J_p = ∂r_p/∂q (3 × n) and convective term κ_p = Σ_jk ∂²r_p/∂q_j∂q_k u_j u_k
//! (u = q̇). Its inertial acceleration is
//!
//! ```text
//! a_p = a_B + ω̇ × r_p + J_p u̇ + c_p,   c_p = ω × (ω × r_p) + 2 ω × (J_p u) + κ_p,
//! ```
//!
//! and the coordinates obey Σ_p m_p J_pᵀ a_p = Q(q, u) (springs and dashpots). Writing
//! z = [a_B; ω̇], that is `M u̇ = g − Cᵀ z` with
//!
//! ```text
//! M = Σ m JᵀJ,  Cᵀ = Σ m [Jᵀ, Jᵀ[r×]ᵀ] (n × 6),  g = Q − Σ m Jᵀ c.
//! ```
//!
//! The particles add `D z + C u̇ + e` to the hub's force and moment equations, with
//! D = Σ m [[1, −[r×]], [[r×], |r|²1 − r rᵀ]] and e = Σ m [c; r × c]; substituting u̇ gives
//! the back-substituted terms `mass += D − C M⁻¹ Cᵀ`, `force −= e + C M⁻¹ g`. Because every
//! term comes from the same particle kinematics, the total momentum and energy are conserved
//! exactly by the continuous equations (tested), whatever the kinematics.

use crate::model::{
    Drawing, Effector, EnergyAccount, Grouping, HubAcceleration, HubCoupling, HubState, Momentum,
    TidalCoupling, Validity,
};
use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};
use std::fmt::Debug;

/// Largest number of coordinates a particle effector may have.
pub const MAX_COORDINATES: usize = 24;

/// One particle's kinematics at given coordinates and rates.
#[derive(Debug, Clone)]
pub struct ParticlePoint {
    /// Mass (kg).
    pub mass: f64,
    /// Position about the hub's centre of mass B (m, body axes).
    pub position: Vector3<f64>,
    /// Columns of the Jacobian ∂r/∂q (m per unit coordinate); only the first n are used.
    pub jacobian: [Vector3<f64>; MAX_COORDINATES],
    /// Convective acceleration Σ ∂²r/∂q_j∂q_k u_j u_k (m/s²).
    pub convective: Vector3<f64>,
}

impl Default for ParticlePoint {
    fn default() -> Self {
        ParticlePoint {
            mass: 0.0,
            position: Vector3::zeros(),
            jacobian: [Vector3::zeros(); MAX_COORDINATES],
            convective: Vector3::zeros(),
        }
    }
}

/// A set of particles moved by `n` coordinates, with springs and dashpots on them.
pub trait ParticleModel: Debug + Send + Sync {
    /// What is shared by all particles at given coordinates and rates (computed once).
    type Cache: Default;
    /// The same model with its dashpots removed (for the averaged method's undamped orbits).
    fn undamped(&self) -> Self
    where
        Self: Sized;
    /// Computes the shared part of the kinematics at coordinates `q` and rates `u`.
    fn prepare(&self, _q: &[f64], _u: &[f64]) -> Self::Cache {
        Self::Cache::default()
    }
    /// The YAML kind.
    fn kind(&self) -> &'static str;
    /// Number of coordinates n (≤ [`MAX_COORDINATES`]).
    fn num_coordinates(&self) -> usize;
    /// Names of the coordinates (their units in `docs/effectors.md`).
    fn coordinate_names(&self) -> Vec<String>;
    /// Number of particles.
    fn num_particles(&self) -> usize;
    /// Fills `out` with particle `p`'s kinematics at coordinates `q` and rates `u` (`cache`
    /// from [`ParticleModel::prepare`] at the same `q` and `u`).
    fn particle(
        &self,
        p: usize,
        cache: &Self::Cache,
        q: &[f64],
        u: &[f64],
        out: &mut ParticlePoint,
    );
    /// The particle sums at coordinates `q`, rates `u` and hub rate `omega` in closed form,
    /// written into `out` (zeroed on entry), for a model that has one; returns false, and
    /// `couple` sums [`ParticleModel::particle`] over the particles instead, otherwise. The
    /// closed form must equal the particle sum to rounding (each model tests it).
    fn summed<const N: usize>(
        &self,
        _q: &[f64],
        _u: &[f64],
        _omega: &Vector3<f64>,
        _out: &mut ParticleSums<N>,
    ) -> bool {
        false
    }
    /// [`Effector::couple`] in closed form, for a model whose coordinates can be eliminated
    /// by hand: adds `D − C M⁻¹ Cᵀ` to the lower triangle of `coupling.mass` and subtracts
    /// `e + C M⁻¹ g` from `coupling.force` (the module documentation's terms), and writes
    /// what `derivatives` reads into `kept` (W = M⁻¹ [g | Cᵀ], row-major with stride 7, then
    /// the packed unit L of a diagonal M). Returns false, and `couple` eliminates the
    /// coordinates from the sums instead, otherwise. Never called with tidal forces.
    fn couple_closed_form(
        &self,
        _q: &[f64],
        _u: &[f64],
        _omega: &Vector3<f64>,
        _coupling: &mut HubCoupling,
        _kept: &mut [f64],
    ) -> bool {
        false
    }
    /// [`Effector::couple_alone`] in closed form: as
    /// [`ParticleModel::couple_closed_form`], for the one effector of a scene that moves mass,
    /// with the hub's translation (hub mass `hub_mass`, kg) eliminated too. Adds to the
    /// rotational rows of `coupling` only, and keeps W with zero translational columns.
    /// Returns false, having changed nothing, for a model without one. Never called with
    /// tidal forces.
    fn couple_alone_closed_form(
        &self,
        _q: &[f64],
        _u: &[f64],
        _omega: &Vector3<f64>,
        _hub_mass: f64,
        _coupling: &mut HubCoupling,
        _kept: &mut [f64],
    ) -> bool {
        false
    }
    /// Whether it implements [`ParticleModel::rhs_alone_closed_form`].
    const HAS_RHS_ALONE: bool = false;
    /// [`Effector::rhs_alone`] in closed form: the hub's angular acceleration `omega_dot`
    /// (rad/s², body axes) and the coordinates' accelerations `u_dot`, given the hub's inertia
    /// `hub_inertia` (kg m², about its centre of mass, lower triangle read) and mass
    /// `hub_mass` (kg). Returns false, having written nothing, for a model without one (or
    /// when its solve fails); the spacecraft then couples and solves.
    #[allow(clippy::too_many_arguments)]
    fn rhs_alone_closed_form(
        &self,
        _q: &[f64],
        _u: &[f64],
        _omega: &Vector3<f64>,
        _hub_inertia: &Matrix3<f64>,
        _hub_mass: f64,
        _omega_dot: &mut Vector3<f64>,
        _u_dot: &mut [f64],
    ) -> bool {
        false
    }
    /// The particles' [`Momentum`] (relative to the hub's centre of mass, with the hub at rest
    /// and turning at `omega`) in closed form, for a model that has one; `None`, and the
    /// particles are summed instead, otherwise.
    fn momentum_closed_form(
        &self,
        _q: &[f64],
        _u: &[f64],
        _omega: &Vector3<f64>,
    ) -> Option<Momentum> {
        None
    }
    /// Generalised forces of springs and dashpots, written into `out` (length n).
    fn forces(&self, q: &[f64], u: &[f64], out: &mut [f64]);
    /// Elastic energy (J).
    fn elastic_energy(&self, q: &[f64]) -> f64;
    /// Dissipation rate (W).
    fn dissipation_power(&self, q: &[f64], u: &[f64]) -> f64;
    /// Extra telemetry (names), e.g. a tip deflection.
    fn extra_telemetry_names(&self) -> Vec<String> {
        Vec::new()
    }
    /// Extra telemetry values at `q`.
    fn extra_telemetry(&self, _q: &[f64]) -> Vec<f64> {
        Vec::new()
    }
    /// What the 3D view draws at `q`.
    fn drawings(&self, q: &[f64]) -> Vec<Drawing>;
    /// Where coordinates `q` stand against the model's range ([`Effector::validity`]).
    fn validity(&self, _q: &[f64]) -> Option<Validity> {
        None
    }
    /// The validity measure at `q` in words ([`Effector::validity_report`]).
    fn validity_report(&self, _q: &[f64]) -> (String, String) {
        (String::new(), String::new())
    }
    /// Where it stands at the hub state `hub` and coordinates `q`
    /// ([`Effector::validity_at`]); the default sees `q` only.
    fn validity_at(&self, _hub: &HubState, q: &[f64]) -> Option<Validity> {
        self.validity(q)
    }
    /// [`ParticleModel::validity_at`] in words ([`Effector::validity_report_at`]).
    fn validity_report_at(&self, _hub: &HubState, q: &[f64]) -> (String, String) {
        self.validity_report(q)
    }
    /// The kind of group it couples in with others of its scene ([`Effector::grouping`]).
    fn grouping(&self) -> Option<Grouping> {
        None
    }
}

/// What `couple` needs from the particles' kinematics, summed over them, for at most `N`
/// coordinates (only the leading n are used): the module documentation's M, Cᵀ, the
/// inertial part of g, and the terms of D and e.
#[derive(Debug, Clone)]
pub struct ParticleSums<const N: usize> {
    /// Coordinate mass matrix M = Σ m JᵀJ, lower triangle (kg × coordinate units²).
    pub mass: [[f64; N]; N],
    /// Cᵀ = Σ m [Jᵀ, (r × J)ᵀ], one row of 6 per coordinate.
    pub coupling: [[f64; 6]; N],
    /// Inertial generalised forces −Σ m Jᵀ c, one per coordinate.
    pub inertial: [f64; N],
    /// Σ m (kg).
    pub total_mass: f64,
    /// Σ m r (kg m).
    pub first_moment: Vector3<f64>,
    /// Σ m (|r|² 1 − r rᵀ) (kg m²).
    pub inertia: Matrix3<f64>,
    /// Σ m c (N).
    pub force: Vector3<f64>,
    /// Σ m r × c (N m).
    pub moment: Vector3<f64>,
}

impl<const N: usize> Default for ParticleSums<N> {
    fn default() -> Self {
        ParticleSums {
            mass: [[0.0; N]; N],
            coupling: [[0.0; 6]; N],
            inertial: [0.0; N],
            total_mass: 0.0,
            first_moment: Vector3::zeros(),
            inertia: Matrix3::zeros(),
            force: Vector3::zeros(),
            moment: Vector3::zeros(),
        }
    }
}

/// A [`ParticleModel`] as an effector: states `[q (n), u (n), dissipated energy]`.
#[derive(Debug)]
pub struct ParticleEffector<P: ParticleModel> {
    name: String,
    model: P,
    initial: Vec<f64>,
}

impl<P: ParticleModel> ParticleEffector<P> {
    /// Wraps `model` with initial coordinates `q0` and rates `u0` (each length n).
    pub fn new(name: impl Into<String>, model: P, q0: &[f64], u0: &[f64]) -> Self {
        let n = model.num_coordinates();
        assert!(n <= MAX_COORDINATES && q0.len() == n && u0.len() == n);
        let mut initial = Vec::with_capacity(2 * n + 1);
        initial.extend_from_slice(q0);
        initial.extend_from_slice(u0);
        initial.push(0.0);
        ParticleEffector {
            name: name.into(),
            model,
            initial,
        }
    }

    /// The particle model.
    pub fn model(&self) -> &P {
        &self.model
    }
}

/// In-place factors M = L D Lᵀ (L unit lower triangular, D diagonal) of the leading n × n
/// block of `a`, lower triangle read and written: L below the diagonal, the reciprocals of D
/// on it; returns false if not positive definite. Cholesky's factor is L D^½, but this needs
/// no square roots: one division per pivot, on the factorisation's critical path. (Indexed
/// loops, as the algorithm is written.)
#[allow(clippy::needless_range_loop)]
fn ldl<const N: usize>(a: &mut [[f64; N]; N], n: usize) -> bool {
    let mut diagonal = [0.0; N];
    for j in 0..n {
        // Row j of L D: l_jk d_k (k < j).
        let mut ld = [0.0; N];
        let mut d = a[j][j];
        for k in 0..j {
            ld[k] = a[j][k] * diagonal[k];
            d -= ld[k] * a[j][k];
        }
        if d.is_nan() || d <= 0.0 {
            return false;
        }
        diagonal[j] = d;
        let r = 1.0 / d;
        a[j][j] = r;
        for i in j + 1..n {
            let mut s = a[i][j];
            for k in 0..j {
                s -= a[i][k] * ld[k];
            }
            a[i][j] = s * r;
        }
    }
    true
}

/// Solves L X = B in place (forward substitution) for the 7 columns of the first n rows of
/// `b`, with the unit lower triangular L from [`ldl`]. (Indexed loops, as the algorithm is
/// written.)
#[allow(clippy::needless_range_loop)]
fn forward7<const N: usize>(l: &[[f64; N]; N], n: usize, b: &mut [[f64; 7]; N]) {
    for i in 0..n {
        for k in 0..i {
            let lik = l[i][k];
            for c in 0..7 {
                b[i][c] -= lik * b[k][c];
            }
        }
    }
}

/// Adds a mass `m` with first moment `s` about B (kg, kg m) to the lower triangle of the
/// hub's 6 × 6 mass: `m` on the translational diagonal and `[s×]` in the rotation–translation
/// block.
pub(crate) fn add_mass_and_first_moment(hub: &mut Matrix6<f64>, m: f64, s: &Vector3<f64>) {
    for i in 0..3 {
        hub[(i, i)] += m;
    }
    hub[(4, 0)] += s.z;
    hub[(5, 0)] -= s.y;
    hub[(3, 1)] -= s.z;
    hub[(5, 1)] += s.x;
    hub[(3, 2)] += s.y;
    hub[(4, 2)] -= s.x;
}

/// Index of L's entry (i, j), i ≥ j, packed row by row.
fn packed(i: usize, j: usize) -> usize {
    i * (i + 1) / 2 + j
}

impl<P: ParticleModel> ParticleEffector<P> {
    /// The number of coordinates in a copy compiled for `N`: `N` itself, a constant the
    /// compiler folds into the loops, below [`MAX_COORDINATES`]; the model's, at run time,
    /// for the general copy.
    fn sized<const N: usize>(&self) -> usize {
        if N < MAX_COORDINATES {
            N
        } else {
            self.model.num_coordinates()
        }
    }

    /// [`Effector::couple`] for `N` coordinates when `N` is below [`MAX_COORDINATES`] (the
    /// loops then have fixed bounds, and the compiler unrolls them and keeps the small
    /// matrices in registers), or for any number up to `N` = [`MAX_COORDINATES`], taken at
    /// run time. The arithmetic, and so every bit of the result, is the same either way.
    fn couple_sized<const N: usize>(
        &self,
        hub: &HubState,
        x: &[f64],
        coupling: &mut HubCoupling,
        scratch: &mut [f64],
    ) {
        let n = self.sized::<N>();
        let (q, u) = (&x[..n], &x[n..2 * n]);
        let w = hub.omega;
        if coupling.tidal.is_none() && self.model.couple_closed_form(q, u, &w, coupling, scratch) {
            coupling.translation = true;
            return;
        }
        self.couple_from_sums::<N>(&w, q, u, coupling, scratch);
    }

    /// [`Effector::couple`] from the particle sums (closed-form or summed particle by
    /// particle), with the coordinates eliminated numerically: the reference for
    /// [`ParticleModel::couple_closed_form`], and the path of every model without one.
    fn couple_from_sums<const N: usize>(
        &self,
        w: &Vector3<f64>,
        q: &[f64],
        u: &[f64],
        coupling: &mut HubCoupling,
        scratch: &mut [f64],
    ) {
        let n = self.sized::<N>();
        let mut sums = ParticleSums::<N>::default();
        if coupling.tidal.is_some() || !self.model.summed(q, u, w, &mut sums) {
            self.sum_particles(q, u, w, &mut coupling.tidal, &mut coupling.force, &mut sums);
        }
        let mut forces = [0.0; N];
        self.model.forces(q, u, &mut forces[..n]);
        let mut g = sums.inertial;
        for k in 0..n {
            g[k] += forces[k];
        }
        // D and e, D's lower triangle only (the spacecraft completes the upper one):
        // [[m 1, ·], [[s×], Σ m (|r|² 1 − r rᵀ)]] with s = Σ m r.
        let (m_sum, s_sum, d_rr) = (sums.total_mass, sums.first_moment, &sums.inertia);
        let hub = &mut coupling.mass;
        add_mass_and_first_moment(hub, m_sum, &s_sum);
        for i in 0..3 {
            for j in 0..=i {
                hub[(3 + i, 3 + j)] += d_rr[(i, j)];
            }
        }
        for i in 0..3 {
            coupling.force[i] -= sums.force[i];
            coupling.force[3 + i] -= sums.moment[i];
        }
        coupling.translation = true;
        let mass = &mut sums.mass;
        let ct = &sums.coupling;
        let kept = &mut scratch[..7 * n + n * (n + 1) / 2];
        let (kept_w, kept_l) = kept.split_at_mut(7 * n);
        // The coordinates' elimination, with M = L D Lᵀ (L unit lower triangular) and
        // W = D⁻¹ L⁻¹ [g | Cᵀ]: C M⁻¹ Cᵀ = Σ_k left_kᵀ right_k (the last 6 of the 7) and
        // C M⁻¹ g = Σ_k left_kᵀ right_k0, with right_k = W_k and left_k = (L⁻¹ Cᵀ)_k; and
        // `derivatives` finishes u̇ = L⁻ᵀ (W_g − W_C z) from W (row-major, stride 7) and L
        // (packed, unit diagonal) kept in the scratch.
        let mut left = [[0.0; 6]; N];
        let mut right = [[0.0; 7]; N];
        let diagonal = (1..n).all(|k| mass[k][..k].iter().all(|&v| v == 0.0));
        let definite = if diagonal {
            // M diagonal (one coordinate, or kinematics with orthogonal Jacobian columns):
            // L = 1, D = M: W = M⁻¹ [g | Cᵀ], and left = Cᵀ.
            kept_l.fill(0.0);
            let mut definite = true;
            for k in 0..n {
                let d = mass[k][k];
                definite &= d > 0.0;
                let r = 1.0 / d;
                right[k][0] = g[k] * r;
                for a in 0..6 {
                    right[k][1 + a] = ct[k][a] * r;
                }
                left[k] = ct[k];
                kept_l[packed(k, k)] = 1.0;
            }
            definite
        } else if ldl(mass, n) {
            // L⁻¹ [g | Cᵀ] (n × 7) by one forward substitution with 7 columns; its last six
            // columns are left, and D⁻¹ times it is W.
            for k in 0..n {
                right[k][0] = g[k];
                right[k][1..].copy_from_slice(&ct[k]);
            }
            forward7(mass, n, &mut right);
            for k in 0..n {
                left[k].copy_from_slice(&right[k][1..]);
                let r = mass[k][k];
                for v in right[k].iter_mut() {
                    *v *= r;
                }
                kept_l[packed(k, 0)..packed(k, k)].copy_from_slice(&mass[k][..k]);
                kept_l[packed(k, k)] = 1.0;
            }
            true
        } else {
            false
        };
        if !definite {
            // A degenerate configuration: poison the hub solve, so the run stops with a
            // diagnosis rather than continuing with nonsense.
            coupling.force[0] = f64::NAN;
            kept.fill(f64::NAN);
            return;
        }
        for k in 0..n {
            kept_w[k * 7..k * 7 + 7].copy_from_slice(&right[k]);
        }
        // mass −= C M⁻¹ Cᵀ (lower triangle); force −= C M⁻¹ g.
        // (On the matrices' arrays, column by column, with fixed bounds: no index checks.)
        let mass_columns = &mut coupling.mass.data.0;
        for (lk, rk) in left[..n].iter().zip(&right[..n]) {
            for a in 0..6 {
                let lka = lk[a];
                coupling.force[a] -= lka * rk[0];
                for b in 0..6 {
                    if b <= a {
                        mass_columns[b][a] -= lka * rk[1 + b];
                    }
                }
            }
        }
    }

    /// [`Effector::derivatives`] for `N` coordinates, or any number up to `N` =
    /// [`MAX_COORDINATES`] taken at run time (as [`ParticleEffector::couple_sized`]):
    /// u̇ = L⁻ᵀ (W_g − W_C z), with W and L kept by `couple`.
    fn derivatives_sized<const N: usize>(
        &self,
        accel: &HubAcceleration,
        x: &[f64],
        scratch: &[f64],
        dx: &mut [f64],
    ) {
        let n = self.sized::<N>();
        let (q, u) = (&x[..n], &x[n..2 * n]);
        let z = accel.as_vector6();
        let (w, l) = scratch[..7 * n + n * (n + 1) / 2].split_at(7 * n);
        let mut u_dot = [0.0; N];
        for (k, t) in u_dot[..n].iter_mut().enumerate() {
            let wk = &w[k * 7..k * 7 + 7];
            let mut s = wk[0];
            for a in 0..6 {
                s -= wk[1 + a] * z[a];
            }
            *t = s;
        }
        for i in (0..n).rev() {
            let mut s = u_dot[i];
            for k in i + 1..n {
                s -= l[packed(k, i)] * u_dot[k];
            }
            u_dot[i] = s * l[packed(i, i)];
        }
        self.write_derivatives(q, u, &u_dot[..n], dx);
    }

    /// Writes its states' derivatives into `dx`: the coordinates' rates `u`, their
    /// accelerations `u_dot`, then the dissipated energy's rate, at coordinates `q`.
    #[inline(always)]
    fn write_derivatives(&self, q: &[f64], u: &[f64], u_dot: &[f64], dx: &mut [f64]) {
        let n = u.len();
        let (rates, rest) = dx.split_at_mut(n);
        rates.copy_from_slice(u);
        rest[..n].copy_from_slice(u_dot);
        rest[n] = self.model.dissipation_power(q, u);
    }

    /// The particle sums by summing [`ParticleModel::particle`] over the particles (the
    /// reference form), with the gravity gradient's tidal forces when `tidal` is given (added
    /// to the inertial generalised forces and to the hub's `force`).
    pub(crate) fn sum_particles<const N: usize>(
        &self,
        q: &[f64],
        u: &[f64],
        w: &Vector3<f64>,
        tidal: &mut Option<TidalCoupling>,
        hub_force: &mut Vector6<f64>,
        sums: &mut ParticleSums<N>,
    ) {
        let n = q.len();
        let ParticleSums {
            mass,
            coupling: ct,
            inertial: g,
            total_mass: m_sum,
            first_moment: s_sum,
            inertia: d_rr,
            force: e_t,
            moment: e_r,
        } = sums;
        let mut pt = ParticlePoint::default();
        let cache = self.model.prepare(q, u);
        for p in 0..self.model.num_particles() {
            self.model.particle(p, &cache, q, u, &mut pt);
            let m = pt.mass;
            let r = pt.position;
            let jac = &pt.jacobian[..n];
            let mut v_rel = Vector3::zeros();
            for (k, j) in jac.iter().enumerate() {
                v_rel += j * u[k];
            }
            if let Some(field) = tidal {
                // The gravity gradient's tidal force on this particle: an external force on
                // the coordinates (Jᵀ f) and on the system (f, r × f).
                let f = m * (field.gradient * r);
                for k in 0..n {
                    g[k] += jac[k].dot(&f);
                }
                let moment = r.cross(&f);
                for i in 0..3 {
                    hub_force[i] += f[i];
                    hub_force[3 + i] += moment[i];
                }
                let v = w.cross(&r) + v_rel;
                field.relative_power += f.dot(&v);
                field.first_moment += m * r;
                field.relative_momentum += m * v;
                field.moving_mass += m;
            }
            let c = w.cross(&w.cross(&r)) + 2.0 * w.cross(&v_rel) + pt.convective;
            for k in 0..n {
                let jk = jac[k];
                for l in 0..=k {
                    mass[k][l] += m * jk.dot(&jac[l]);
                }
                let rj = r.cross(&jk);
                let row = &mut ct[k];
                row[0] += m * jk.x;
                row[1] += m * jk.y;
                row[2] += m * jk.z;
                row[3] += m * rj.x;
                row[4] += m * rj.y;
                row[5] += m * rj.z;
                g[k] -= m * jk.dot(&c);
            }
            *m_sum += m;
            *s_sum += m * r;
            *d_rr += m * (Matrix3::from_diagonal_element(r.norm_squared()) - r * r.transpose());
            *e_t += m * c;
            *e_r += m * r.cross(&c);
        }
    }

    /// [`Effector::momentum`] summed over the particles (the reference form).
    pub(crate) fn momentum_of_particles(&self, hub: &HubState, x: &[f64]) -> Momentum {
        let n = self.model.num_coordinates();
        let (q, u) = (&x[..n], &x[n..2 * n]);
        let mut out = Momentum::default();
        let mut pt = ParticlePoint::default();
        let cache = self.model.prepare(q, u);
        for p in 0..self.model.num_particles() {
            self.model.particle(p, &cache, q, u, &mut pt);
            let m = pt.mass;
            let r = pt.position;
            let mut v = hub.omega.cross(&r);
            for (k, j) in pt.jacobian[..n].iter().enumerate() {
                v += j * u[k];
            }
            out.mass += m;
            out.first_moment += m * r;
            out.linear += m * v;
            out.angular += m * r.cross(&v);
            out.kinetic_energy += 0.5 * m * v.norm_squared();
        }
        out
    }
}

impl<P: ParticleModel + 'static> Effector for ParticleEffector<P> {
    fn without_dissipation(&self) -> Option<Box<dyn Effector>> {
        Some(Box::new(ParticleEffector {
            name: self.name.clone(),
            model: self.model.undamped(),
            initial: self.initial.clone(),
        }))
    }
    fn name(&self) -> &str {
        &self.name
    }
    fn kind(&self) -> &'static str {
        self.model.kind()
    }
    fn num_states(&self) -> usize {
        2 * self.model.num_coordinates() + 1
    }
    fn num_dynamic_states(&self) -> usize {
        2 * self.model.num_coordinates()
    }
    fn state_names(&self) -> Vec<String> {
        let q = self.model.coordinate_names();
        let mut names = q.clone();
        names.extend(q.iter().map(|c| format!("{c}_rate")));
        names.push("dissipated_energy".into());
        names
    }
    fn initial_state(&self) -> Vec<f64> {
        self.initial.clone()
    }
    fn moves_mass(&self) -> bool {
        true
    }
    fn scratch_len(&self) -> usize {
        // W = L⁻¹ [g | Cᵀ] (7n) and L (packed, n(n + 1)/2), kept from `couple` for
        // `derivatives`.
        let n = self.model.num_coordinates();
        7 * n + n * (n + 1) / 2
    }

    fn couple(&self, hub: &HubState, x: &[f64], coupling: &mut HubCoupling, scratch: &mut [f64]) {
        match self.model.num_coordinates() {
            1 => self.couple_sized::<1>(hub, x, coupling, scratch),
            2 => self.couple_sized::<2>(hub, x, coupling, scratch),
            4 => self.couple_sized::<4>(hub, x, coupling, scratch),
            6 => self.couple_sized::<6>(hub, x, coupling, scratch),
            _ => self.couple_sized::<MAX_COORDINATES>(hub, x, coupling, scratch),
        }
    }

    fn couple_alone(
        &self,
        hub: &HubState,
        hub_mass: f64,
        x: &[f64],
        coupling: &mut HubCoupling,
        scratch: &mut [f64],
    ) -> bool {
        let n = self.model.num_coordinates();
        let (q, u) = (&x[..n], &x[n..2 * n]);
        coupling.tidal.is_none()
            && self
                .model
                .couple_alone_closed_form(q, u, &hub.omega, hub_mass, coupling, scratch)
    }

    fn has_rhs_alone(&self) -> bool {
        P::HAS_RHS_ALONE
    }

    fn rhs_alone(
        &self,
        hub: &HubState,
        hub_inertia: &Matrix3<f64>,
        hub_mass: f64,
        x: &[f64],
        omega_dot: &mut Vector3<f64>,
        dx: &mut [f64],
    ) -> bool {
        let n = self.model.num_coordinates();
        let (q, u) = (&x[..n], &x[n..2 * n]);
        let mut u_dot = [0.0; MAX_COORDINATES];
        if !self.model.rhs_alone_closed_form(
            q,
            u,
            &hub.omega,
            hub_inertia,
            hub_mass,
            omega_dot,
            &mut u_dot[..n],
        ) {
            return false;
        }
        self.write_derivatives(q, u, &u_dot[..n], dx);
        true
    }

    fn derivatives(
        &self,
        _hub: &HubState,
        accel: &HubAcceleration,
        x: &[f64],
        scratch: &[f64],
        dx: &mut [f64],
    ) {
        match self.model.num_coordinates() {
            1 => self.derivatives_sized::<1>(accel, x, scratch, dx),
            2 => self.derivatives_sized::<2>(accel, x, scratch, dx),
            4 => self.derivatives_sized::<4>(accel, x, scratch, dx),
            6 => self.derivatives_sized::<6>(accel, x, scratch, dx),
            _ => self.derivatives_sized::<MAX_COORDINATES>(accel, x, scratch, dx),
        }
    }

    fn momentum(&self, hub: &HubState, x: &[f64]) -> Momentum {
        let n = self.model.num_coordinates();
        let (q, u) = (&x[..n], &x[n..2 * n]);
        self.model
            .momentum_closed_form(q, u, &hub.omega)
            .unwrap_or_else(|| self.momentum_of_particles(hub, x))
    }

    fn energy(&self, _hub: &HubState, x: &[f64]) -> EnergyAccount {
        let n = self.model.num_coordinates();
        let (q, u) = (&x[..n], &x[n..2 * n]);
        EnergyAccount {
            elastic: self.model.elastic_energy(q),
            dissipated: x[2 * n],
            power: self.model.dissipation_power(q, u),
            work: 0.0,
        }
    }

    fn telemetry_names(&self) -> Vec<String> {
        let mut names = self.state_names();
        names.pop();
        names.extend(
            ["elastic_energy", "dissipated_energy", "dissipation_power"]
                .iter()
                .map(|s| s.to_string()),
        );
        names.extend(self.model.extra_telemetry_names());
        names
    }

    fn telemetry(&self, hub: &HubState, x: &[f64]) -> Vec<f64> {
        let n = self.model.num_coordinates();
        let a = self.energy(hub, x);
        let mut v = x[..2 * n].to_vec();
        v.extend([a.elastic, a.dissipated, a.power]);
        v.extend(self.model.extra_telemetry(&x[..n]));
        v
    }

    fn drawings(&self, x: &[f64]) -> Vec<Drawing> {
        self.model.drawings(&x[..self.model.num_coordinates()])
    }

    fn validity(&self, x: &[f64]) -> Option<Validity> {
        self.model.validity(&x[..self.model.num_coordinates()])
    }

    fn validity_report(&self, x: &[f64]) -> (String, String) {
        self.model
            .validity_report(&x[..self.model.num_coordinates()])
    }

    fn validity_at(&self, hub: &HubState, x: &[f64]) -> Option<Validity> {
        self.model
            .validity_at(hub, &x[..self.model.num_coordinates()])
    }

    fn validity_report_at(&self, hub: &HubState, x: &[f64]) -> (String, String) {
        self.model
            .validity_report_at(hub, &x[..self.model.num_coordinates()])
    }

    fn grouping(&self) -> Option<Grouping> {
        self.model.grouping()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[allow(clippy::needless_range_loop)] // the matrix identities, index by index
    fn ldl_and_its_substitutions_solve_a_small_system() {
        let m = [[4.0, 2.0, 0.6], [2.0, 5.0, 1.0], [0.6, 1.0, 3.0]];
        // In a larger array: only the leading 3 × 3 block is used.
        let mut a = [[0.0; 4]; 4];
        for (i, row) in m.iter().enumerate() {
            a[i][..3].copy_from_slice(row);
        }
        assert!(ldl(&mut a, 3));
        // L D Lᵀ = M, with L's unit diagonal implied and D's stored as reciprocals.
        let entry = |i: usize, j: usize| if i == j { 1.0 } else { a[i][j] };
        for i in 0..3 {
            for j in 0..=i {
                let ldlt: f64 = (0..=j).map(|k| entry(i, k) * entry(j, k) / a[k][k]).sum();
                assert!((ldlt - m[i][j]).abs() < 1e-14, "({i}, {j}): {ldlt}");
            }
        }
        // L W = B column by column.
        let rhs: [[f64; 7]; 3] =
            std::array::from_fn(|i| std::array::from_fn(|c| (i * 7 + c) as f64 - 9.5));
        let mut w = [[0.0; 7]; 4];
        w[..3].copy_from_slice(&rhs);
        forward7(&a, 3, &mut w);
        for c in 0..7 {
            for i in 0..3 {
                let r: f64 = (0..=i).map(|k| entry(i, k) * w[k][c]).sum();
                assert!((r - rhs[i][c]).abs() < 1e-13, "{r} {}", rhs[i][c]);
            }
        }
        let mut singular = [[0.0; 2]; 2];
        assert!(!ldl(&mut singular, 2));
    }

    /// A model's closed-form sums and momentum equal the particle sums to rounding, at states
    /// spread over the coordinates' range.
    fn closed_form_equals_particle_sums<P: ParticleModel>(e: &ParticleEffector<P>, x: &[f64]) {
        let n = e.model.num_coordinates();
        let (q, u) = (&x[..n], &x[n..2 * n]);
        let w = Vector3::new(0.4, -1.3, 7.9);
        let mut closed = ParticleSums::<MAX_COORDINATES>::default();
        assert!(
            e.model.summed(q, u, &w, &mut closed),
            "{} has a closed form",
            e.model.kind()
        );
        let mut summed = ParticleSums::<MAX_COORDINATES>::default();
        let mut hub_force = Vector6::zeros();
        e.sum_particles(q, u, &w, &mut None, &mut hub_force, &mut summed);
        assert_eq!(hub_force, Vector6::zeros());
        let close = |a: &[f64], b: &[f64], what: &str| {
            let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (x, y) in a.iter().zip(b) {
                // The sums cancel (the centripetal terms against each other), so rounding
                // differences reach a few tens of ulps of the largest entry.
                assert!(
                    (x - y).abs() <= 1e-13 * scale,
                    "{what}: closed form {x:e}, particles {y:e} (scale {scale:e}) at {q:?} {u:?}"
                );
            }
        };
        for k in 0..n {
            close(&closed.mass[k][..=k], &summed.mass[k][..=k], "M");
            close(&closed.coupling[k], &summed.coupling[k], "Cᵀ");
        }
        close(&closed.inertial[..n], &summed.inertial[..n], "−Σ m Jᵀ c");
        close(&[closed.total_mass], &[summed.total_mass], "Σ m");
        close(
            closed.first_moment.as_slice(),
            summed.first_moment.as_slice(),
            "Σ m r",
        );
        close(
            closed.inertia.as_slice(),
            summed.inertia.as_slice(),
            "Σ m (|r|² − r rᵀ)",
        );
        close(closed.force.as_slice(), summed.force.as_slice(), "Σ m c");
        close(
            closed.moment.as_slice(),
            summed.moment.as_slice(),
            "Σ m r × c",
        );
        let hub = HubState {
            t: 0.0,
            omega: w,
            attitude: &[1.0, 0.0, 0.0, 0.0],
        };
        let closed = e
            .model
            .momentum_closed_form(q, u, &w)
            .expect("a closed form");
        let summed = e.momentum_of_particles(&hub, x);
        close(&[closed.mass], &[summed.mass], "momentum: mass");
        let (a, b) = (closed.first_moment, summed.first_moment);
        close(a.as_slice(), b.as_slice(), "momentum: first moment");
        close(
            closed.linear.as_slice(),
            summed.linear.as_slice(),
            "linear momentum",
        );
        close(
            closed.angular.as_slice(),
            summed.angular.as_slice(),
            "angular momentum",
        );
        let (a, b) = (closed.kinetic_energy, summed.kinetic_energy);
        close(&[a], &[b], "kinetic energy");
    }

    /// The `k`-th of the rod states the tests sample: flap and lag over ±1.4 rad, their rates
    /// over ±30 rad/s.
    fn flap_lag_state(k: usize) -> [f64; 4] {
        let a = k as f64;
        [
            1.4 * (0.7 * a).sin(),
            -1.4 * (1.3 * a + 0.2).cos(),
            30.0 * (0.9 * a + 1.0).sin(),
            -20.0 * (0.4 * a).cos(),
        ]
    }

    #[test]
    fn hinged_rod_closed_form_sums_equal_its_particle_sums() {
        use super::super::hinged_rod::{HingeFreedom, HingedRod};
        for freedom in [HingeFreedom::FlapLag, HingeFreedom::Flap, HingeFreedom::Lag] {
            let rod = HingedRod {
                mass: 0.139,
                length: 0.56,
                hinge: Vector3::new(0.03, 0.076, 0.1),
                direction: Vector3::new(0.0, 0.6, 0.8),
                axis: Vector3::new(1.0, 0.0, 0.0),
                freedom,
                stiffness: [0.565, 0.3],
                damping: [6e-4, 1e-3],
            };
            let n = rod.num_coordinates();
            let e = ParticleEffector::new("rod", rod, &vec![0.0; n], &vec![0.0; n]);
            for k in 0..25 {
                let x = flap_lag_state(k);
                let state: Vec<f64> = if n == 2 { x.to_vec() } else { vec![x[0], x[2]] };
                closed_form_equals_particle_sums(&e, &state);
            }
        }
    }

    /// The flap–lag rod's coordinates eliminated by hand give the hub terms and the kept
    /// W of the numerical elimination from its sums, to rounding; a non-finite state poisons
    /// the hub's force, so the run stops with a diagnosis.
    #[test]
    #[allow(clippy::needless_range_loop)] // the lower triangle, index by index
    fn hinged_rod_closed_form_coupling_equals_the_elimination_from_its_sums() {
        use super::super::hinged_rod::{HingeFreedom, HingedRod};
        use nalgebra::{Matrix6, Vector6};
        // Two geometries: hinge, rest direction and hinge axis (⊥ the direction).
        let (s2, s3) = (0.5f64.sqrt(), (1.0f64 / 3.0).sqrt());
        let geometries = [
            (
                Vector3::new(0.03, 0.076, 0.1),
                Vector3::new(0.0, 0.6, 0.8),
                Vector3::new(1.0, 0.0, 0.0),
            ),
            (
                Vector3::new(-0.4, 0.2, -1.1),
                Vector3::new(s2, s2, 0.0),
                Vector3::new(-s3, s3, s3),
            ),
        ];
        let start = HubCoupling {
            mass: Matrix6::zeros(),
            force: Vector6::zeros(),
            translation: false,
            tidal: None,
        };
        let mut worst = 0.0f64;
        let rod = |(hinge, direction, axis): (Vector3<f64>, Vector3<f64>, Vector3<f64>)| {
            let rod = HingedRod {
                mass: 0.139,
                length: 0.56,
                hinge,
                direction,
                axis,
                freedom: HingeFreedom::FlapLag,
                stiffness: [0.565, 0.3],
                damping: [6e-4, 1e-3],
            };
            ParticleEffector::new("rod", rod, &[0.0; 2], &[0.0; 2])
        };
        for (geometry, k) in geometries
            .iter()
            .flat_map(|g| (0..25).map(move |k| (*g, k)))
        {
            let e = rod(geometry);
            let a = k as f64;
            let [flap, lag, flap_rate, lag_rate] = flap_lag_state(k);
            let x = [flap, lag, flap_rate, lag_rate, 0.0];
            // The hub's rate up to 80 rad/s.
            let omega = Vector3::new(0.4 * a.cos(), -1.3, 3.2 * a);
            worst = worst.max(coupling_by_hand_equals_the_sums(&e, &x, omega, 1e-13));
        }
        eprintln!("largest difference, relative to each quantity's scale: {worst:e}");
        let e = rod(geometries[0]);
        // A non-finite angle makes lag's inertia (cos² θ_f) NaN, which poisons the hub solve.
        let mut poisoned = start.clone();
        let mut kept = [0.0; 17];
        let hub = HubState {
            t: 0.0,
            omega: Vector3::new(0.0, 0.0, 1.0),
            attitude: &[1.0, 0.0, 0.0, 0.0],
        };
        e.couple_sized::<2>(
            &hub,
            &[f64::NAN, 0.0, 0.0, 0.0, 0.0],
            &mut poisoned,
            &mut kept,
        );
        assert!(poisoned.force[0].is_nan() && kept.iter().all(|v| v.is_nan()));
    }

    /// A two-coordinate model's coupling by hand (`couple_sized`, which takes its closed form)
    /// against the elimination from its sums (`couple_from_sums`) at state `x` and hub
    /// rate `omega`: hub mass and force, both rows of W and L, each within `tolerance` of its
    /// largest entry. Returns the largest relative difference.
    #[allow(clippy::needless_range_loop)] // the lower triangle, index by index
    fn coupling_by_hand_equals_the_sums<P: ParticleModel + 'static>(
        e: &ParticleEffector<P>,
        x: &[f64; 5],
        omega: Vector3<f64>,
        tolerance: f64,
    ) -> f64 {
        use nalgebra::{Matrix6, Vector6};
        let start = HubCoupling {
            mass: Matrix6::zeros(),
            force: Vector6::zeros(),
            translation: false,
            tidal: None,
        };
        let hub = HubState {
            t: 0.0,
            omega,
            attitude: &[1.0, 0.0, 0.0, 0.0],
        };
        let (mut closed, mut reference) = (start.clone(), start);
        let (mut kept_closed, mut kept_reference) = ([0.0; 17], [0.0; 17]);
        e.couple_sized::<2>(&hub, x, &mut closed, &mut kept_closed);
        e.couple_from_sums::<2>(
            &omega,
            &x[..2],
            &x[2..4],
            &mut reference,
            &mut kept_reference,
        );
        let mut worst = 0.0f64;
        let mut close = |by_hand: &[f64], from_sums: &[f64], what: &str| {
            let scale = from_sums.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (a, b) in by_hand.iter().zip(from_sums) {
                let error = (a - b).abs() / scale;
                worst = worst.max(error);
                assert!(
                    error <= tolerance,
                    "{what}: by hand {a:e}, from the sums {b:e} (scale {scale:e}) at {x:?}"
                );
            }
        };
        let lower = |m: &Matrix6<f64>| {
            let mut v = Vec::new();
            for i in 0..6 {
                for j in 0..=i {
                    v.push(m[(i, j)]);
                }
            }
            v
        };
        close(&lower(&closed.mass), &lower(&reference.mass), "mass");
        close(closed.force.as_slice(), reference.force.as_slice(), "force");
        close(&kept_closed[..7], &kept_reference[..7], "W, first row");
        close(&kept_closed[7..14], &kept_reference[7..14], "W, second row");
        assert_eq!(kept_closed[14..], kept_reference[14..], "L");
        assert!(closed.translation);
        worst
    }

    /// The slosh pendulum's coupling by hand (a point mass constrained along its rod only)
    /// against the elimination from its particle sums, at random geometries and states.
    #[test]
    fn slosh_pendulum_closed_form_coupling_equals_the_elimination_from_its_sums() {
        use super::super::slosh_pendulum::{SloshPendulum, pendulum_frame};
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut uniform = |lo: f64, hi: f64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            lo + (hi - lo) * (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..50 {
            let rest = Vector3::new(uniform(-1.0, 1.0), uniform(-1.0, 1.0), uniform(-1.0, 1.0));
            let pendulum = SloshPendulum {
                mass: uniform(0.5, 40.0),
                length: uniform(0.05, 1.0),
                pivot: Vector3::new(uniform(-1.0, 1.0), uniform(-1.0, 1.0), uniform(-1.0, 1.0)),
                frame: pendulum_frame(rest.normalize()),
                damping: uniform(0.0, 50.0),
                fixed_mass: if uniform(0.0, 1.0) < 0.5 {
                    0.0
                } else {
                    uniform(0.5, 40.0)
                },
                fixed_position: Vector3::new(
                    uniform(-1.0, 1.0),
                    uniform(-1.0, 1.0),
                    uniform(-1.0, 1.0),
                ),
                amplitude_warning: None,
            };
            let e = ParticleEffector::new("p", pendulum, &[0.0; 2], &[0.0; 2]);
            let x = [
                uniform(-3.0, 3.0),
                uniform(-1.4, 1.4),
                uniform(-5.0, 5.0),
                uniform(-5.0, 5.0),
                0.0,
            ];
            let omega = Vector3::new(uniform(-6.0, 6.0), uniform(-6.0, 6.0), uniform(-6.0, 6.0));
            coupling_by_hand_equals_the_sums(&e, &x, omega, 1e-12);
            closed_form_equals_particle_sums(&e, &x);
        }
    }

    #[test]
    fn spring_mass_closed_form_sums_equal_its_particle_sums() {
        use super::super::spring_mass::SpringMass;
        let damper = SpringMass {
            mass: 52.7,
            position: Vector3::new(1.0, -0.3, 0.2),
            direction: Vector3::new(0.6, 0.0, 0.8),
            stiffness: 52.7,
            damping: 105.5,
            travel: None,
        };
        let e = ParticleEffector::new("damper", damper, &[0.0], &[0.0]);
        for k in 0..25 {
            let a = k as f64;
            let x = [0.4 * (0.7 * a).sin(), 3.0 * (1.3 * a + 0.2).cos()];
            closed_form_equals_particle_sums(&e, &x);
        }
    }

    /// The fixed-size coupling and derivatives (one, two, four or six coordinates) and the
    /// general ones give the same bits: the same arithmetic, in the same order.
    #[test]
    fn fixed_size_coupling_equals_the_general_one_bit_for_bit() {
        use super::super::hinged_rod::{HingeFreedom, HingedRod};
        use super::super::spring_mass::SpringMass;
        use nalgebra::{Matrix6, Vector6};
        fn both<P: ParticleModel + 'static>(e: &ParticleEffector<P>, x: &[f64]) {
            let hub = HubState {
                t: 0.3,
                omega: Vector3::new(0.3, -0.2, 7.5),
                attitude: &[1.0, 0.0, 0.0, 0.0],
            };
            let start = HubCoupling {
                mass: Matrix6::identity() * 3.0,
                force: Vector6::new(0.0, 0.0, 0.0, 0.1, -0.2, 0.3),
                translation: false,
                tidal: None,
            };
            let n = e.model.num_coordinates();
            let (mut fixed, mut general) = (start.clone(), start);
            let (mut s1, mut s2) = (vec![0.0; e.scratch_len()], vec![0.0; e.scratch_len()]);
            match n {
                1 => e.couple_sized::<1>(&hub, x, &mut fixed, &mut s1),
                2 => e.couple_sized::<2>(&hub, x, &mut fixed, &mut s1),
                4 => e.couple_sized::<4>(&hub, x, &mut fixed, &mut s1),
                _ => e.couple_sized::<6>(&hub, x, &mut fixed, &mut s1),
            }
            e.couple_sized::<MAX_COORDINATES>(&hub, x, &mut general, &mut s2);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(fixed.mass.as_slice()), bits(general.mass.as_slice()));
            assert_eq!(bits(fixed.force.as_slice()), bits(general.force.as_slice()));
            assert_eq!(bits(&s1), bits(&s2));
            assert!(
                fixed.mass != Matrix6::identity() * 3.0,
                "the coupling added something"
            );
            // And the coordinates' accelerations from what the coupling kept.
            let accel = HubAcceleration {
                linear: Vector3::new(0.01, -0.02, 0.005),
                angular: Vector3::new(0.3, 0.1, -0.2),
                tidal_power: 0.0,
            };
            let (mut d1, mut d2) = (vec![0.0; x.len()], vec![0.0; x.len()]);
            match n {
                1 => e.derivatives_sized::<1>(&accel, x, &s1, &mut d1),
                2 => e.derivatives_sized::<2>(&accel, x, &s1, &mut d1),
                4 => e.derivatives_sized::<4>(&accel, x, &s1, &mut d1),
                _ => e.derivatives_sized::<6>(&accel, x, &s1, &mut d1),
            }
            e.derivatives_sized::<MAX_COORDINATES>(&accel, x, &s2, &mut d2);
            assert_eq!(bits(&d1), bits(&d2));
            assert!(d1[n..2 * n].iter().all(|v| *v != 0.0), "{d1:?}");
        }
        let rod = |freedom| HingedRod {
            mass: 0.3,
            length: 1.2,
            hinge: Vector3::new(0.1, 0.0, 0.4),
            direction: Vector3::x(),
            axis: Vector3::z(),
            freedom,
            stiffness: [2.0, 3.0],
            damping: [0.1, 0.2],
        };
        let e = ParticleEffector::new("rod", rod(HingeFreedom::FlapLag), &[0.2, -0.4], &[1.1, 0.7]);
        both(&e, &[0.2, -0.4, 1.1, 0.7, 0.0]);
        let e = ParticleEffector::new("rod", rod(HingeFreedom::Lag), &[0.3], &[-0.5]);
        both(&e, &[0.3, -0.5, 0.0]);
        let damper = SpringMass {
            mass: 0.5,
            position: Vector3::new(0.0, 0.7, 0.2),
            direction: Vector3::new(0.6, 0.0, 0.8),
            stiffness: 40.0,
            damping: 0.8,
            travel: None,
        };
        let e = ParticleEffector::new("damper", damper, &[0.01], &[0.3]);
        both(&e, &[0.01, 0.3, 0.0]);
        // Modal beams of two and three modes in two directions, by their shape integrals.
        use super::super::beam::{BeamProperties, beam_modes};
        use super::super::modal::ModalBeam;
        for modes in [2, 3] {
            let shapes = beam_modes(
                &BeamProperties {
                    length: 1.5,
                    bending_stiffness: 4.0,
                    mass_per_length: 0.3,
                    tip_mass: 0.1,
                },
                modes,
            )
            .unwrap();
            let beam = ModalBeam::new(
                shapes,
                Vector3::new(0.2, 0.0, 0.1),
                Vector3::x(),
                vec![("flap".into(), Vector3::z()), ("lag".into(), -Vector3::y())],
                0.01,
                true,
            );
            let n = 2 * modes;
            let x: Vec<f64> = (0..=2 * n).map(|k| 0.01 * (k as f64 - 3.3)).collect();
            let e = ParticleEffector::new("beam", beam, &x[..n], &x[n..2 * n]);
            both(&e, &x);
        }
    }
}
