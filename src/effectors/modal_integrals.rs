//! The modal beam's particle sums from shape integrals: node sums taken once, at
//! construction, so that a right-hand side costs O(N⁴) in the number of modes N whatever the
//! number of mass nodes.
//!
//! Every quantity the particle loop of [`super::particles`] needs of node p is linear in the
//! node's *features*
//!
//! ```text
//! f_p = (1, x_p, φ_1(x_p) … φ_N(x_p), S_ij(x_p) for i ≤ j)      (F = 2 + N + N(N+1)/2 of them)
//! ```
//!
//! with coefficients (body-frame vectors) that depend on the state only. With
//! Q_ij = Σ_d q_di q_dj and t̂_d, â, p₀ as in [`super::modal`]:
//!
//! ```text
//! position  r_p = Σ_f A_r[f] f_p:   A_r[1] = p₀,  A_r[x] = â,  A_r[φ_i] = Σ_d q_di t̂_d,
//!                                   A_r[S_ij] = −γ_ij â,  γ_ii = ½ Q_ii,  γ_ij = Q_ij (i < j);
//! Jacobian  J_p,di = Σ_f A_di[f] f_p:  A_di[φ_i] = t̂_d,  A_di[S_ij] = −q_dj â  (each j);
//! velocity  J_p u:   A_v[φ_i] = Σ_d u_di t̂_d,  A_v[S_ij] = −β_ij â,
//!                    β_ii = Σ_d u_di q_di,  β_ij = Σ_d (u_di q_dj + u_dj q_di);
//! convective κ_p:    A_κ[S_ij] = −μ_ij â,  μ_ii = Σ_d u_di²,  μ_ij = 2 Σ_d u_di u_dj;
//! c_p = ω × (ω × r_p) + 2 ω × J_p u + κ_p:  A_c[f] = ω × (ω × A_r[f]) + 2 ω × A_v[f] + A_κ[f].
//! ```
//!
//! (Without geometric stiffening the S_ij coefficients are zero.) A mass-weighted sum of a
//! product of two such quantities is therefore a contraction with the symmetric F × F matrix
//! of second moments of the features,
//!
//! ```text
//! W[f,g] = Σ_p m_p f_p[f] f_p[g],
//! ```
//!
//! whose entries are the shape integrals (modal inertia invariants) of flexible multibody
//! dynamics: Σm, Σm x, Σm x², Σm φ_i, Σm x φ_i, Σm φ_iφ_j, Σm S_ij, Σm x S_ij, Σm φ_k S_ij,
//! Σm S_ij S_kl (kg times the features' units: m, kg^-½ for φ, kg⁻¹ m⁻¹ for S). See Shabana,
//! *Dynamics of Multibody Systems* (Cambridge University Press), the inertia shape integrals
//! of the floating frame of reference formulation; Wallrapp, "Standardization of flexible
//! body modeling in multibody system codes, part I", Mechanics of Structures and Machines 22
//! (1994), the modal inertia invariants; and, for the second-order foreshortening terms that
//! carry the geometric stiffening, Kane, Ryan & Banerjee, J. Guidance 10 (1987), and Ryu, Kim
//! & Kim, Computers & Structures 62 (1997). With K[g] = Σ_f W_fg A_r[f] and
//! B[g] = Σ_f W_fg A_c[f]:
//!
//! ```text
//! Σ m = W[1,1],  Σ m r = K[1],   Σ m c = B[1],
//! Σ m r rᵀ = Σ_g K[g] A_r[g]ᵀ  (→ Σ m (|r|² 1 − r rᵀ)),   Σ m r × c = Σ_g K[g] × A_c[g],
//! Σ m J_k = Σ_g W[1,g] A_k[g],   Σ m r × J_k = Σ_g K[g] × A_k[g],   Σ m J_k · c = Σ_g B[g] · A_k[g],
//! Σ m J_k · J_l = Σ_fg W_fg A_k[f] · A_l[g]
//! ```
//!
//! (a bracket names a feature: [1] is the constant one). The Jacobian columns have N + 1 non-zero coefficients,
//! so these cost O(F²) for K and B and O(N² F) for M: O(N⁴) in all. The equations are exact
//! (the same sums in another order); the test below compares them with the node loop.

use super::beam::BeamModes;
use super::particles::ParticleSums;
use crate::model::Momentum;
use nalgebra::{Matrix3, Vector3};

/// Most modes the closed form takes (the beam's own limit is 10).
const MAX_MODES: usize = 10;
/// Most features: 2 + N + N(N+1)/2 for N = [`MAX_MODES`].
const MAX_FEATURES: usize = 2 + MAX_MODES + MAX_MODES * (MAX_MODES + 1) / 2;
/// Most coordinates: N in each of two directions.
const MAX_BEAM_COORDINATES: usize = 2 * MAX_MODES;

/// The second moments W of the node features of a beam's mass model.
#[derive(Debug, Clone)]
pub(crate) struct ShapeIntegrals {
    /// Number of modes N.
    modes: usize,
    /// Number of features F.
    features: usize,
    /// W, F × F row-major, symmetric.
    moments: Vec<f64>,
}

/// The beam's geometry in body axes, as [`super::modal::ModalBeam`] holds it.
pub(crate) struct Geometry {
    /// Root point p₀ (m).
    pub attachment: Vector3<f64>,
    /// Unit beam axis â.
    pub axis: Vector3<f64>,
    /// Bending directions t̂_d: the first [`Geometry::count`] (one or two).
    pub directions: [Vector3<f64>; 2],
    /// Number of bending directions.
    pub count: usize,
    /// Whether the foreshortening is modelled.
    pub stiffening: bool,
}

/// Feature index of S_ij (= S_ji) among the F features of N modes: they follow the N mode
/// shapes, row by row of the upper triangle i ≤ j.
#[inline(always)]
fn pair_feature(modes: usize, i: usize, j: usize) -> usize {
    let (i, j) = if i <= j { (i, j) } else { (j, i) };
    2 + modes + i * modes - i * i.saturating_sub(1) / 2 - i + j
}

impl ShapeIntegrals {
    /// The integrals of `modes`' mass nodes; `None` past [`MAX_MODES`] modes.
    pub(crate) fn new(modes: &BeamModes) -> Option<Self> {
        let n = modes.frequencies.len();
        if n == 0 || n > MAX_MODES {
            return None;
        }
        let features = 2 + n + n * (n + 1) / 2;
        let mut moments = vec![0.0; features * features];
        let mut f = vec![0.0; features];
        for node in modes.nodes.iter().filter(|node| node.mass > 0.0) {
            f[0] = 1.0;
            f[1] = node.x;
            f[2..2 + n].copy_from_slice(&node.phi[..n]);
            for i in 0..n {
                for j in i..n {
                    f[pair_feature(n, i, j)] = node.shortening[i * n + j];
                }
            }
            for a in 0..features {
                let mf = node.mass * f[a];
                for b in 0..features {
                    moments[a * features + b] += mf * f[b];
                }
            }
        }
        Some(ShapeIntegrals {
            modes: n,
            features,
            moments,
        })
    }

    /// The particle sums at coordinates `q`, rates `u` (each `[flap modes…, lag modes…]` as
    /// the beam orders them) and hub rate `omega`, into `out`.
    pub(crate) fn sums<const N: usize>(
        &self,
        geometry: &Geometry,
        q: &[f64],
        u: &[f64],
        omega: &Vector3<f64>,
        out: &mut ParticleSums<N>,
    ) {
        // Compiled for one to four modes in two directions (fixed loop bounds), and for any
        // number of modes up to ten in one or two.
        let two = geometry.count == 2;
        match self.modes {
            1 if two => self.sums_sized::<1, 4, 2, 2, N>(geometry, q, u, omega, out),
            2 if two => self.sums_sized::<2, 7, 4, 2, N>(geometry, q, u, omega, out),
            3 if two => self.sums_sized::<3, 11, 6, 2, N>(geometry, q, u, omega, out),
            4 if two => self.sums_sized::<4, 16, 8, 2, N>(geometry, q, u, omega, out),
            _ => self.sums_sized::<MAX_MODES, MAX_FEATURES, MAX_BEAM_COORDINATES, 0, N>(
                geometry, q, u, omega, out,
            ),
        }
    }

    /// The number of bending directions: `ND` when it is not zero (a constant), the
    /// geometry's own otherwise.
    #[inline(always)]
    fn directions<const ND: usize>(geometry: &Geometry) -> &[Vector3<f64>] {
        if ND > 0 {
            debug_assert_eq!(geometry.count, ND);
            &geometry.directions[..ND]
        } else {
            &geometry.directions[..geometry.count]
        }
    }

    /// The number of modes and features: `NM` and `F` when `NM` is below [`MAX_MODES`] (the
    /// loops then have fixed bounds), the beam's own otherwise.
    fn sizes<const NM: usize, const F: usize>(&self) -> (usize, usize) {
        if NM < MAX_MODES {
            debug_assert!(NM == self.modes && F == self.features);
            (NM, F)
        } else {
            (self.modes, self.features)
        }
    }

    /// [`ShapeIntegrals::sums`] for `NM` modes and `F` features (see
    /// [`ShapeIntegrals::sizes`]), `C` ≥ 2 `NM` coordinates and `ND` directions (see
    /// [`ShapeIntegrals::directions`]), written into `out` (zero on entry). (Indexed loops,
    /// as the formulas are written.)
    #[allow(clippy::needless_range_loop)]
    fn sums_sized<
        const NM: usize,
        const F: usize,
        const C: usize,
        const ND: usize,
        const N: usize,
    >(
        &self,
        geometry: &Geometry,
        q: &[f64],
        u: &[f64],
        omega: &Vector3<f64>,
        out: &mut ParticleSums<N>,
    ) {
        let (nm, nf) = self.sizes::<NM, F>();
        let dirs = Self::directions::<ND>(geometry);
        let axis = geometry.axis;
        let w = omega;
        let stiff = geometry.stiffening;
        let wm = &self.moments[..nf * nf];
        // Coefficients of position, relative velocity, κ and c (without stiffening the S_ij
        // ones are zero, and so are their products below).
        let (a_r, a_v, a_k) = self.coefficients::<NM, F, ND>(geometry, q, u);
        let mut a_c = [Vector3::zeros(); F];
        // ω × (ω × a) = ω (ω·a) − a ω².
        let w2 = w.norm_squared();
        for f in 0..nf {
            a_c[f] = w * w.dot(&a_r[f]) - w2 * a_r[f] + 2.0 * w.cross(&a_v[f]) + a_k[f];
        }
        // K[g] = Σ_f W_fg A_r[f],  B[g] = Σ_f W_fg A_c[f].
        let mut k = [Vector3::zeros(); F];
        let mut b = [Vector3::zeros(); F];
        for g in 0..nf {
            let row = &wm[g * nf..(g + 1) * nf];
            let (mut kg, mut bg) = (Vector3::zeros(), Vector3::zeros());
            for f in 0..nf {
                kg += row[f] * a_r[f];
                bg += row[f] * a_c[f];
            }
            k[g] = kg;
            b[g] = bg;
        }
        out.total_mass = wm[0];
        out.first_moment = k[0];
        out.force = b[0];
        let mut rr = Matrix3::zeros();
        let mut e_r = Vector3::zeros();
        for f in 0..nf {
            rr += k[f] * a_r[f].transpose();
            e_r += k[f].cross(&a_c[f]);
        }
        let rr = 0.5 * (rr + rr.transpose());
        out.inertia = Matrix3::from_diagonal_element(rr.trace()) - rr;
        out.moment = e_r;
        // Coordinate k = (d, i): A_k = t̂_d at φ_i, −q_dj â at S_ij. P_k[g] = Σ_j −q_dj W[S_ij, g]
        // (the â part of A_k contracted with W), for g over the φ and S features.
        let mut p = [[0.0; F]; C];
        let aa = axis.norm_squared();
        // S_ij's feature index (constants once the loops over NM modes are unrolled).
        let pair = |i: usize, j: usize| pair_feature(nm, i, j);
        for (d, t) in dirs.iter().enumerate() {
            let ta = t.dot(&axis);
            for i in 0..nm {
                let kk = d * nm + i;
                let phi = 2 + i;
                let (mut w0, mut ks, mut bs) = (0.0, Vector3::zeros(), Vector3::zeros());
                if stiff {
                    let pk = &mut p[kk];
                    for j in 0..nm {
                        let c = -q[d * nm + j];
                        let s = pair(i, j);
                        let row = &wm[s * nf..(s + 1) * nf];
                        for g in 2..nf {
                            pk[g] += c * row[g];
                        }
                        w0 += c * row[0];
                        ks += c * k[s];
                        bs += c * b[s];
                    }
                }
                let trans = wm[phi] * t + w0 * axis;
                let rot = k[phi].cross(t) + ks.cross(&axis);
                out.coupling[kk][..3].copy_from_slice(trans.as_slice());
                out.coupling[kk][3..].copy_from_slice(rot.as_slice());
                out.inertial[kk] = -(b[phi].dot(t) + bs.dot(&axis));
                // M_kl = t̂_d·t̂_e W[φ_i, φ_j] + t̂_d·â P_l[φ_i] + â·t̂_e P_k[φ_j]
                //        + â·â Σ_j' −q_ej' P_k[S_jj'],   for l = (e, j) ≤ k.
                for e in 0..=d {
                    let te = &dirs[e];
                    let tt = t.dot(te);
                    let ea = te.dot(&axis);
                    let last = if e == d { i + 1 } else { nm };
                    for j in 0..last {
                        let l = e * nm + j;
                        let mut m = tt * wm[phi * nf + 2 + j];
                        if stiff {
                            let mut ss = 0.0;
                            for jj in 0..nm {
                                ss += -q[e * nm + jj] * p[kk][pair(j, jj)];
                            }
                            m += ta * p[l][phi] + ea * p[kk][2 + j] + aa * ss;
                        }
                        out.mass[kk][l] = m;
                    }
                }
            }
        }
    }

    /// The coefficients A_r, A_v and A_κ at `q` and `u` (`NM` and `F` as in
    /// [`ShapeIntegrals::sizes`]).
    #[allow(clippy::type_complexity)]
    #[inline(always)]
    fn coefficients<const NM: usize, const F: usize, const ND: usize>(
        &self,
        geometry: &Geometry,
        q: &[f64],
        u: &[f64],
    ) -> ([Vector3<f64>; F], [Vector3<f64>; F], [Vector3<f64>; F]) {
        let (nm, _) = self.sizes::<NM, F>();
        let dirs = Self::directions::<ND>(geometry);
        let axis = geometry.axis;
        let mut a_r = [Vector3::zeros(); F];
        let mut a_v = [Vector3::zeros(); F];
        let mut a_k = [Vector3::zeros(); F];
        a_r[0] = geometry.attachment;
        a_r[1] = axis;
        for i in 0..nm {
            for (d, t) in dirs.iter().enumerate() {
                a_r[2 + i] += q[d * nm + i] * t;
                a_v[2 + i] += u[d * nm + i] * t;
            }
        }
        if geometry.stiffening {
            for i in 0..nm {
                for j in i..nm {
                    let (mut gq, mut gv, mut gk) = (0.0, 0.0, 0.0);
                    for d in 0..dirs.len() {
                        let (qi, qj) = (q[d * nm + i], q[d * nm + j]);
                        let (ui, uj) = (u[d * nm + i], u[d * nm + j]);
                        gq += qi * qj;
                        gv += ui * qj + uj * qi;
                        gk += ui * uj;
                    }
                    if i == j {
                        gq *= 0.5;
                        gv *= 0.5;
                    } else {
                        gk *= 2.0;
                    }
                    let s = pair_feature(nm, i, j);
                    a_r[s] = -gq * axis;
                    a_v[s] = -gv * axis;
                    a_k[s] = -gk * axis;
                }
            }
        }
        (a_r, a_v, a_k)
    }

    /// The particles' momentum about B relative to B's velocity ([`Momentum`]) at `q`, `u`
    /// and hub rate `omega`: with the velocity coefficients A_w[f] = ω × A_r[f] + A_v[f],
    /// Σ m v = Σ_g W[1,g] A_w[g], Σ m r × v = Σ_g K[g] × A_w[g] and
    /// ½ Σ m |v|² = ½ Σ_fg W_fg A_w[f] · A_w[g].
    pub(crate) fn momentum(
        &self,
        geometry: &Geometry,
        q: &[f64],
        u: &[f64],
        omega: &Vector3<f64>,
    ) -> Momentum {
        match self.modes {
            1 => self.momentum_sized::<1, 4>(geometry, q, u, omega),
            2 => self.momentum_sized::<2, 7>(geometry, q, u, omega),
            3 => self.momentum_sized::<3, 11>(geometry, q, u, omega),
            4 => self.momentum_sized::<4, 16>(geometry, q, u, omega),
            _ => self.momentum_sized::<MAX_MODES, MAX_FEATURES>(geometry, q, u, omega),
        }
    }

    /// [`ShapeIntegrals::momentum`] for `NM` modes and `F` features.
    #[allow(clippy::needless_range_loop)]
    fn momentum_sized<const NM: usize, const F: usize>(
        &self,
        geometry: &Geometry,
        q: &[f64],
        u: &[f64],
        omega: &Vector3<f64>,
    ) -> Momentum {
        let (_, nf) = self.sizes::<NM, F>();
        let wm = &self.moments[..nf * nf];
        let (a_r, a_v, _) = self.coefficients::<NM, F, 0>(geometry, q, u);
        let mut a_w = [Vector3::zeros(); F];
        for f in 0..nf {
            a_w[f] = omega.cross(&a_r[f]) + a_v[f];
        }
        let mut out = Momentum {
            mass: wm[0],
            ..Momentum::default()
        };
        let mut energy = 0.0;
        for g in 0..nf {
            let row = &wm[g * nf..(g + 1) * nf];
            let (mut kg, mut vg) = (Vector3::zeros(), Vector3::zeros());
            for f in 0..nf {
                kg += row[f] * a_r[f];
                vg += row[f] * a_w[f];
            }
            if g == 0 {
                out.first_moment = kg;
                out.linear = vg;
            }
            out.angular += kg.cross(&a_w[g]);
            energy += vg.dot(&a_w[g]);
        }
        out.kinetic_energy = 0.5 * energy;
        out
    }
}

#[cfg(test)]
mod tests {
    use super::super::beam::{BeamProperties, beam_modes};
    use super::super::modal::ModalBeam;
    use super::super::particles::{MAX_COORDINATES, ParticleEffector, ParticleModel, ParticleSums};
    use super::*;
    use crate::model::{Effector, HubState};

    /// The sums by the particle effector's own loop, node by node (the reference).
    fn node_sums(
        beam: &ModalBeam,
        q: &[f64],
        u: &[f64],
        w: &Vector3<f64>,
    ) -> ParticleSums<MAX_COORDINATES> {
        let effector = ParticleEffector::new("beam", beam.clone(), q, u);
        let mut sums = ParticleSums::default();
        let mut hub_force = nalgebra::Vector6::zeros();
        effector.sum_particles(q, u, w, &mut None, &mut hub_force, &mut sums);
        sums
    }

    /// The momentum by the particle effector's own loop, node by node (the reference).
    fn node_momentum(beam: &ModalBeam, q: &[f64], u: &[f64], w: &Vector3<f64>) -> Momentum {
        let effector = ParticleEffector::new("beam", beam.clone(), q, u);
        let hub = HubState {
            t: 0.0,
            omega: *w,
            attitude: &[1.0, 0.0, 0.0, 0.0],
        };
        effector.momentum_of_particles(&hub, &effector.initial_state())
    }

    /// A deterministic uniform number in [−1, 1) (xorshift64*).
    fn uniform(state: &mut u64) -> f64 {
        *state ^= *state >> 12;
        *state ^= *state << 25;
        *state ^= *state >> 27;
        let x = state.wrapping_mul(0x2545_F491_4F6C_DD1D);
        (x >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    /// Largest |a − b| over a group of sums, over the group's largest |b|.
    fn relative(a: &[f64], b: &[f64]) -> f64 {
        let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let diff = a
            .iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(scale > 0.0);
        diff / scale
    }

    #[test]
    fn each_mode_pair_has_its_own_feature_after_the_mode_shapes() {
        for n in 1..=MAX_MODES {
            let features = 2 + n + n * (n + 1) / 2;
            let mut next = 2 + n;
            for i in 0..n {
                for j in i..n {
                    assert_eq!(pair_feature(n, i, j), next, "N = {n}, S_{i}{j}");
                    assert_eq!(pair_feature(n, j, i), next, "N = {n}, S_{j}{i}");
                    next += 1;
                }
            }
            assert_eq!(next, features);
        }
    }

    #[test]
    fn shape_integrals_give_the_node_sums() {
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut worst = 0.0f64;
        for modes in [1, 2, 3, 4, 6] {
            let props = BeamProperties {
                length: 2.5,
                bending_stiffness: 30.0,
                mass_per_length: 0.7,
                tip_mass: 0.4,
            };
            let shapes = beam_modes(&props, modes).unwrap();
            let tip_phi = shapes.nodes[shapes.tip].phi.clone();
            // A beam off the centre of mass, along a skew axis.
            let axis = Vector3::new(0.6, 0.64, 0.48);
            let flap = Vector3::new(0.8, -0.48, -0.36);
            let lag = axis.cross(&flap);
            for bending in [
                vec![("flap", flap)],
                vec![("lag", lag)],
                vec![("flap", flap), ("lag", lag)],
            ] {
                for stiffening in [true, false] {
                    let bending: Vec<(String, Vector3<f64>)> =
                        bending.iter().map(|(s, t)| (s.to_string(), *t)).collect();
                    let beam = ModalBeam::new(
                        shapes.clone(),
                        Vector3::new(0.3, -0.2, 0.5),
                        axis,
                        bending.clone(),
                        0.01,
                        stiffening,
                    );
                    let n = beam.num_coordinates();
                    for _ in 0..5 {
                        // Tip deflections up to ~0.3 L in each mode, rates of a few per second.
                        let q: Vec<f64> = (0..n)
                            .map(|k| uniform(&mut state) * 0.3 * props.length / tip_phi[k % modes])
                            .collect();
                        let u: Vec<f64> =
                            (0..n).map(|k| 3.0 * q[k] * uniform(&mut state)).collect();
                        let w = Vector3::new(
                            uniform(&mut state),
                            uniform(&mut state),
                            5.0 * uniform(&mut state),
                        );
                        let reference = node_sums(&beam, &q, &u, &w);
                        let mut closed = ParticleSums::<MAX_COORDINATES>::default();
                        assert!(beam.summed(&q, &u, &w, &mut closed));
                        let lower = |s: &ParticleSums<MAX_COORDINATES>| {
                            (0..n)
                                .flat_map(|k| (0..=k).map(move |l| s.mass[k][l]))
                                .collect::<Vec<_>>()
                        };
                        let ct = |s: &ParticleSums<MAX_COORDINATES>| {
                            s.coupling[..n]
                                .iter()
                                .flatten()
                                .copied()
                                .collect::<Vec<_>>()
                        };
                        let groups = [
                            ("M", relative(&lower(&closed), &lower(&reference))),
                            ("Cᵀ", relative(&ct(&closed), &ct(&reference))),
                            (
                                "g",
                                relative(&closed.inertial[..n], &reference.inertial[..n]),
                            ),
                            ("m", relative(&[closed.total_mass], &[reference.total_mass])),
                            (
                                "Σ m r",
                                relative(
                                    closed.first_moment.as_slice(),
                                    reference.first_moment.as_slice(),
                                ),
                            ),
                            (
                                "D_rr",
                                relative(closed.inertia.as_slice(), reference.inertia.as_slice()),
                            ),
                            (
                                "e_t",
                                relative(closed.force.as_slice(), reference.force.as_slice()),
                            ),
                            (
                                "e_r",
                                relative(closed.moment.as_slice(), reference.moment.as_slice()),
                            ),
                        ];
                        let (mc, mr) = (
                            beam.momentum_closed_form(&q, &u, &w).unwrap(),
                            node_momentum(&beam, &q, &u, &w),
                        );
                        let vectors = |m: &Momentum| {
                            let mut v = vec![m.mass];
                            v.extend(m.first_moment.iter().chain(&m.linear).chain(&m.angular));
                            v
                        };
                        let momentum = [
                            (
                                "mass, Σ m r, Σ m v, Σ m r × v",
                                relative(&vectors(&mc), &vectors(&mr)),
                            ),
                            (
                                "½ Σ m |v|²",
                                relative(&[mc.kinetic_energy], &[mr.kinetic_energy]),
                            ),
                        ];
                        for (name, rel) in groups.into_iter().chain(momentum) {
                            assert!(
                                rel < 1e-12,
                                "{name}: {rel:e} ({modes} modes, {} directions, stiffening \
                                 {stiffening})",
                                bending.len()
                            );
                            worst = worst.max(rel);
                        }
                    }
                }
            }
        }
        println!("largest relative difference {worst:e}");
    }
}
