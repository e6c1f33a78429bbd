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
    Drawing, Effector, EnergyAccount, HubAcceleration, HubCoupling, HubState, Momentum, Validity,
};
use nalgebra::{Matrix3, Vector3};
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

/// The sums of the particle loop of the coupling, for a model that has them in closed form
/// ([`ParticleModel::summed`]): everything the loop accumulates, before the springs, the
/// dashpots and the back-substitution are added. Only the leading n entries (n × n for
/// `mass`) are read.
#[derive(Debug, Clone)]
pub struct ParticleSums<const N: usize> {
    /// M = Σ m JᵀJ: row k holds columns 0..=k (the lower triangle; kg per unit coordinate²).
    pub mass: [[f64; N]; N],
    /// Cᵀ = Σ m [Jᵀ, (r × J)ᵀ]: row k is [Σ m J_k, Σ m r × J_k].
    pub ct: [[f64; 6]; N],
    /// −Σ m Jᵀ c (the generalised inertial forces, without the springs and dashpots).
    pub g: [f64; N],
    /// Σ m (kg).
    pub m_sum: f64,
    /// Σ m r (kg m).
    pub s_sum: Vector3<f64>,
    /// Σ m (|r|² 1 − r rᵀ) (kg m²).
    pub d_rr: Matrix3<f64>,
    /// Σ m c (N).
    pub e_t: Vector3<f64>,
    /// Σ m r × c (N m).
    pub e_r: Vector3<f64>,
}

impl<const N: usize> ParticleSums<N> {
    /// All sums zero.
    pub fn zero() -> Self {
        ParticleSums {
            mass: [[0.0; N]; N],
            ct: [[0.0; 6]; N],
            g: [0.0; N],
            m_sum: 0.0,
            s_sum: Vector3::zeros(),
            d_rr: Matrix3::zeros(),
            e_t: Vector3::zeros(),
            e_r: Vector3::zeros(),
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
    /// The particle loop's sums at coordinates `q`, rates `u` and hub rate `omega`, in closed
    /// form, written into `out` (zeroed, with N ≥ n); returns false, leaving the sums to the
    /// loop over [`ParticleModel::particle`], if the model has no closed form (the default).
    /// The effector uses it when no gravity gradient acts on the particles.
    fn summed<const N: usize>(
        &self,
        _q: &[f64],
        _u: &[f64],
        _omega: &Vector3<f64>,
        _out: &mut ParticleSums<N>,
    ) -> bool {
        false
    }
    /// The particles' momentum ([`Effector::momentum`]) at coordinates `q`, rates `u` and hub
    /// rate `omega`, in closed form; `None` (the default) sums it particle by particle.
    fn summed_momentum(&self, _q: &[f64], _u: &[f64], _omega: &Vector3<f64>) -> Option<Momentum> {
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

fn cross_matrix(r: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -r.z, r.y, r.z, 0.0, -r.x, -r.y, r.x, 0.0)
}

/// In-place Cholesky of the leading n × n block of `a` (lower triangle read and written);
/// returns false if not positive definite. (Indexed loops, as the algorithm is written.)
#[allow(clippy::needless_range_loop)]
fn cholesky<const N: usize>(a: &mut [[f64; N]; N], n: usize) -> bool {
    for j in 0..n {
        let mut d = a[j][j];
        for k in 0..j {
            d -= a[j][k] * a[j][k];
        }
        if d.is_nan() || d <= 0.0 {
            return false;
        }
        let d = d.sqrt();
        a[j][j] = d;
        for i in j + 1..n {
            let mut s = a[i][j];
            for k in 0..j {
                s -= a[i][k] * a[j][k];
            }
            a[i][j] = s / d;
        }
    }
    true
}

/// Solves L Lᵀ X = B in place for the 7 right-hand sides of the first n rows of `b` (`l`
/// from [`cholesky`]). (Indexed loops, as the algorithm is written.)
#[allow(clippy::needless_range_loop)]
fn cholesky_solve7<const N: usize>(l: &[[f64; N]; N], n: usize, b: &mut [[f64; 7]; N]) {
    for i in 0..n {
        for k in 0..i {
            let lik = l[i][k];
            for c in 0..7 {
                b[i][c] -= lik * b[k][c];
            }
        }
        let d = l[i][i];
        for c in 0..7 {
            b[i][c] /= d;
        }
    }
    for i in (0..n).rev() {
        for k in i + 1..n {
            let lki = l[k][i];
            for c in 0..7 {
                b[i][c] -= lki * b[k][c];
            }
        }
        let d = l[i][i];
        for c in 0..7 {
            b[i][c] /= d;
        }
    }
}

impl<P: ParticleModel> ParticleEffector<P> {
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
        let n = if N < MAX_COORDINATES {
            N
        } else {
            self.model.num_coordinates()
        };
        let (q, u) = (&x[..n], &x[n..2 * n]);
        let w = hub.omega;
        // M (lower triangle), Cᵀ (n × 6) and g (n).
        let mut mass = [[0.0; N]; N];
        let mut ct = [[0.0; 6]; N];
        let mut g = [0.0; N];
        let mut d_rr = Matrix3::zeros();
        let (mut m_sum, mut s_sum) = (0.0, Vector3::zeros());
        let (mut e_t, mut e_r) = (Vector3::zeros(), Vector3::zeros());
        let mut pt = ParticlePoint::default();
        let cache = self.model.prepare(q, u);
        let mut tidal = coupling.tidal;
        // A model with its sums in closed form skips the loop (unless tidal forces act).
        let mut sums = ParticleSums::<N>::zero();
        let summed = tidal.is_none() && self.model.summed(q, u, &w, &mut sums);
        if summed {
            ParticleSums {
                mass,
                ct,
                g,
                m_sum,
                s_sum,
                d_rr,
                e_t,
                e_r,
            } = sums;
        }
        let particles = if summed {
            0
        } else {
            self.model.num_particles()
        };
        for p in 0..particles {
            self.model.particle(p, &cache, q, u, &mut pt);
            let m = pt.mass;
            let r = pt.position;
            let jac = &pt.jacobian[..n];
            let mut v_rel = Vector3::zeros();
            for (k, j) in jac.iter().enumerate() {
                v_rel += j * u[k];
            }
            if let Some(field) = &mut tidal {
                // The gravity gradient's tidal force on this particle: an external force on
                // the coordinates (Jᵀ f) and on the system (f, r × f).
                let f = m * (field.gradient * r);
                for k in 0..n {
                    g[k] += jac[k].dot(&f);
                }
                let moment = r.cross(&f);
                for i in 0..3 {
                    coupling.force[i] += f[i];
                    coupling.force[3 + i] += moment[i];
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
            m_sum += m;
            s_sum += m * r;
            d_rr += m * (Matrix3::from_diagonal_element(r.norm_squared()) - r * r.transpose());
            e_t += m * c;
            e_r += m * r.cross(&c);
        }
        coupling.tidal = tidal;
        let mut forces = [0.0; MAX_COORDINATES];
        self.model.forces(q, u, &mut forces[..n]);
        for k in 0..n {
            g[k] += forces[k];
        }
        // D and e.
        let sx = cross_matrix(&s_sum);
        for i in 0..3 {
            coupling.mass[(i, i)] += m_sum;
        }
        let mut block = coupling.mass.fixed_view_mut::<3, 3>(0, 3);
        block -= sx;
        let mut block = coupling.mass.fixed_view_mut::<3, 3>(3, 0);
        block += sx;
        let mut block = coupling.mass.fixed_view_mut::<3, 3>(3, 3);
        block += d_rr;
        for i in 0..3 {
            coupling.force[i] -= e_t[i];
            coupling.force[3 + i] -= e_r[i];
        }
        coupling.translation = true;
        let kept = &mut scratch[..7 * n];
        if !cholesky(&mut mass, n) {
            // A degenerate configuration: poison the hub solve, so the run stops with a
            // diagnosis rather than continuing with nonsense.
            coupling.force[0] = f64::NAN;
            kept.fill(f64::NAN);
            return;
        }
        // Y = M⁻¹ Cᵀ (n × 6) and y_g = M⁻¹ g, kept for `derivatives`: one solve with 7
        // right-hand sides [g | Cᵀ], written to the scratch row-major with stride 7.
        let mut rhs = [[0.0; 7]; N];
        for k in 0..n {
            rhs[k][0] = g[k];
            rhs[k][1..].copy_from_slice(&ct[k]);
        }
        cholesky_solve7(&mass, n, &mut rhs);
        for k in 0..n {
            kept[k * 7..k * 7 + 7].copy_from_slice(&rhs[k]);
        }
        // mass −= C Y ; force −= C y_g, with C = (Cᵀ)ᵀ.
        for k in 0..n {
            let ck = &ct[k];
            let yk = &rhs[k];
            for (a, &cka) in ck.iter().enumerate() {
                coupling.force[a] -= cka * yk[0];
                for b in 0..6 {
                    coupling.mass[(a, b)] -= cka * yk[1 + b];
                }
            }
        }
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
        // y_g (n) and Y (6n), kept from `couple` for `derivatives`.
        7 * self.model.num_coordinates()
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

    fn derivatives(
        &self,
        hub: &HubState,
        accel: &HubAcceleration,
        x: &[f64],
        scratch: &[f64],
        dx: &mut [f64],
    ) {
        let n = self.model.num_coordinates();
        let (q, u) = (&x[..n], &x[n..2 * n]);
        let z = accel.as_vector6();
        dx[..n].copy_from_slice(u);
        for k in 0..n {
            let yk = &scratch[k * 7..k * 7 + 7];
            let mut s = yk[0];
            for a in 0..6 {
                s -= yk[1 + a] * z[a];
            }
            dx[n + k] = s;
        }
        dx[2 * n] = self.model.dissipation_power(q, u);
        let _ = hub;
    }

    fn momentum(&self, hub: &HubState, x: &[f64]) -> Momentum {
        let n = self.model.num_coordinates();
        let (q, u) = (&x[..n], &x[n..2 * n]);
        if let Some(summed) = self.model.summed_momentum(q, u, &hub.omega) {
            return summed;
        }
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
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cholesky_solves_a_small_system_with_several_right_hand_sides() {
        let m = [[4.0, 2.0, 0.6], [2.0, 5.0, 1.0], [0.6, 1.0, 3.0]];
        // In a larger array: only the leading 3 × 3 block is used.
        let mut a = [[0.0; 4]; 4];
        for (i, row) in m.iter().enumerate() {
            a[i][..3].copy_from_slice(row);
        }
        assert!(cholesky(&mut a, 3));
        let rhs: [[f64; 7]; 3] =
            std::array::from_fn(|i| std::array::from_fn(|c| (i * 7 + c) as f64 - 9.5));
        let mut b = [[0.0; 7]; 4];
        b[..3].copy_from_slice(&rhs);
        cholesky_solve7(&a, 3, &mut b);
        for c in 0..7 {
            for (i, row) in m.iter().enumerate() {
                let r: f64 = (0..3).map(|k| row[k] * b[k][c]).sum();
                assert!((r - rhs[i][c]).abs() < 1e-13, "{r} {}", rhs[i][c]);
            }
        }
        let mut singular = [[0.0; 2]; 2];
        assert!(!cholesky(&mut singular, 2));
    }

    /// The fixed-size coupling (one, two, four or six coordinates) and the general one give the same
    /// bits: the same arithmetic, in the same order.
    #[test]
    fn fixed_size_coupling_equals_the_general_one_bit_for_bit() {
        use super::super::hinged_rod::{HingeFreedom, HingedRod};
        use super::super::spring_mass::SpringMass;
        use nalgebra::{Matrix6, Vector6};
        fn both<P: ParticleModel>(e: &ParticleEffector<P>, x: &[f64]) {
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
            let (mut s1, mut s2) = (vec![0.0; 7 * n], vec![0.0; 7 * n]);
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
