//! Uniform cantilever beam (clamped at x = 0, free at x = L) with an optional
//! tip point mass, reduced to its first N bending modes by Rayleigh–Ritz.
//!
//! The beam is represented for a multibody simulator by a set of mass nodes
//! (Gauss–Legendre quadrature points plus a tip node).  The node set *is* the
//! mass model: each node is a particle at position `x` along the undeformed
//! beam with transverse deflection `w(x) = Σ_i q_i φ_i(x)` and axial
//! foreshortening `s(x) = ½ Σ_ij q_i q_j S_ij(x)`, where
//! `S_ij(x) = ∫_0^x φ_i'(ξ) φ_j'(ξ) dξ`.
//!
//! All quantities are SI: metres, kilograms, seconds, newtons.

use nalgebra::{DMatrix, DVector, SymmetricEigen};
use std::f64::consts::PI;

/// Largest number of modes [`beam_modes`] accepts.
const MAX_MODES: usize = 10;
/// Number of extra clamped-free eigenfunctions in the Ritz basis beyond `n_modes`.
const EXTRA_BASIS: usize = 6;

/// Physical properties of a uniform cantilever beam.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeamProperties {
    /// Beam length L from the clamped root to the free tip, in metres (m).
    pub length: f64,
    /// Bending stiffness EI, in newton square metres (N m²).
    pub bending_stiffness: f64,
    /// Mass per unit length ρA, in kilograms per metre (kg/m).
    pub mass_per_length: f64,
    /// Point mass attached at the free tip (x = L), in kilograms (kg); must be >= 0.
    pub tip_mass: f64,
}

/// One mass node (particle) of the beam's mass model.
#[derive(Debug, Clone, PartialEq)]
pub struct BeamNode {
    /// Position along the undeformed beam, measured from the root, in metres (m).
    pub x: f64,
    /// Mass lumped at this node, in kilograms (kg).
    pub mass: f64,
    /// Mode-shape values φ_i(x) for the N modes (length N), in m per unit modal
    /// coordinate (modes are mass-normalised, so modal coordinates have units
    /// of m·kg^½ and φ has units of kg^-½).
    pub phi: Vec<f64>,
    /// Mode-shape slopes φ_i'(x) (length N), in kg^-½ m^-1 (derivative of `phi`
    /// with respect to x).
    pub dphi: Vec<f64>,
    /// Foreshortening integrals S_ij(x) = ∫_0^x φ_i' φ_j' dξ, row-major N×N,
    /// symmetric, in kg^-1 m^-1 (so that ½ Σ q_i q_j S_ij is in metres).
    pub shortening: Vec<f64>,
}

/// Modal reduction of a cantilever beam: frequencies and the node mass model.
#[derive(Debug, Clone, PartialEq)]
pub struct BeamModes {
    /// Non-rotating natural frequencies of the N modes, in rad/s, ascending.
    pub frequencies: Vec<f64>,
    /// Mass nodes (Gauss–Legendre points on [0, L], then the tip node).
    pub nodes: Vec<BeamNode>,
    /// Index into `nodes` of the node at x = L (carries the tip mass, in kg,
    /// which may be zero); always present.
    pub tip: usize,
}

/// Computes the first `n_modes` (1..=10) bending modes of a uniform cantilever
/// with a tip mass by Rayleigh–Ritz, and the node mass model built from them.
///
/// Frequencies are in rad/s; node positions in m; node masses in kg. Modes are
/// mass-normalised with respect to the node model (Σ_g m_g φ_i φ_j = δ_ij) and
/// signed so that φ_i(L) > 0.
pub fn beam_modes(props: &BeamProperties, n_modes: usize) -> Result<BeamModes, String> {
    let ritz = ritz_solve(props, n_modes)?;
    let n = n_modes;
    let length = props.length;
    let n_gauss = ritz.n_gauss;
    let (unit_t, unit_w) = gauss_legendre_unit(n_gauss);

    let mut node_positions: Vec<(f64, f64)> = unit_t
        .iter()
        .zip(&unit_w)
        .map(|(&t, &w)| {
            (
                0.5 * length * (t + 1.0),
                props.mass_per_length * 0.5 * length * w,
            )
        })
        .collect();
    node_positions.push((length, props.tip_mass));

    let mut nodes = Vec::with_capacity(node_positions.len());
    for &(x, mass) in &node_positions {
        let (phi, dphi) = ritz.mode_values(x);
        // S_ij(x) by a Gauss rule on [0, x] with the same number of points.
        let mut shortening = vec![0.0; n * n];
        for (&t, &w) in unit_t.iter().zip(&unit_w) {
            let xi = 0.5 * x * (t + 1.0);
            let wi = 0.5 * x * w;
            let (_, d) = ritz.mode_values(xi);
            for i in 0..n {
                for j in i..n {
                    shortening[i * n + j] += wi * d[i] * d[j];
                }
            }
        }
        for i in 0..n {
            for j in 0..i {
                shortening[i * n + j] = shortening[j * n + i];
            }
        }
        nodes.push(BeamNode {
            x,
            mass,
            phi,
            dphi,
            shortening,
        });
    }
    let tip = nodes.len() - 1;
    Ok(BeamModes {
        frequencies: ritz.frequencies,
        nodes,
        tip,
    })
}

impl BeamModes {
    /// Number of modes N.
    fn n_modes(&self) -> usize {
        self.frequencies.len()
    }

    /// Modal mass matrix from the nodes: Σ_g m_g φ_i φ_j (should be identity);
    /// dimensionless for mass-normalised modes (kg · kg^-1).
    pub fn mass_matrix(&self) -> DMatrix<f64> {
        let n = self.n_modes();
        let mut m = DMatrix::zeros(n, n);
        for node in &self.nodes {
            for i in 0..n {
                for j in 0..n {
                    m[(i, j)] += node.mass * node.phi[i] * node.phi[j];
                }
            }
        }
        m
    }

    /// Stiffness: diag(ω_i²) (mass-normalised modes), in rad²/s² (i.e. N m⁻¹ per
    /// unit modal mass).
    pub fn stiffness_matrix(&self) -> DMatrix<f64> {
        let omega2: Vec<f64> = self.frequencies.iter().map(|w| w * w).collect();
        DMatrix::from_diagonal(&DVector::from_vec(omega2))
    }

    /// Geometric stiffness per unit Ω² (Ω in rad/s) for spin about an axis
    /// perpendicular to the beam through a point `hub_radius` metres behind the
    /// root: K_G,ij = Σ_g m_g (hub_radius + x_g) S_ij(x_g), dimensionless for
    /// mass-normalised modes (multiply by Ω² in rad²/s² to get a stiffness in
    /// the units of [`BeamModes::stiffness_matrix`]).
    ///
    /// For hub_radius = 0 this equals ∫ ρA (L² − x²)/2 φ_i'φ_j' dx +
    /// m_tip L ∫_0^L φ_i'φ_j' dx.
    pub fn geometric_stiffness(&self, hub_radius: f64) -> DMatrix<f64> {
        let n = self.n_modes();
        let mut kg = DMatrix::zeros(n, n);
        for node in &self.nodes {
            let f = node.mass * (hub_radius + node.x);
            for i in 0..n {
                for j in 0..n {
                    kg[(i, j)] += f * node.shortening[i * n + j];
                }
            }
        }
        kg
    }
}

/// Gauss–Legendre rule with `n` points on [-1, 1], nodes ascending.
/// Nodes by Newton iteration on P_n; weights 2 / ((1 − t²) P_n'(t)²).
fn gauss_legendre_unit(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut nodes = vec![0.0; n];
    let mut weights = vec![0.0; n];
    let nf = n as f64;
    for i in 0..n.div_ceil(2) {
        // Initial guess for the i-th largest root.
        let mut t = (PI * (i as f64 + 0.75) / (nf + 0.5)).cos();
        for _ in 0..100 {
            let (p, dp) = legendre(n, t);
            let dt = p / dp;
            t -= dt;
            if dt.abs() <= 1e-15 {
                break;
            }
        }
        let (_, dp) = legendre(n, t);
        let w = 2.0 / ((1.0 - t * t) * dp * dp);
        nodes[i] = -t;
        nodes[n - 1 - i] = t;
        weights[i] = w;
        weights[n - 1 - i] = w;
    }
    if n % 2 == 1 {
        nodes[n / 2] = 0.0;
    }
    (nodes, weights)
}

/// Legendre polynomial P_n(t) and its derivative P_n'(t) (for |t| < 1).
fn legendre(n: usize, t: f64) -> (f64, f64) {
    let mut p_prev = 1.0;
    let mut p = t;
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 1..n {
        let kf = k as f64;
        let p_next = ((2.0 * kf + 1.0) * t * p - kf * p_prev) / (kf + 1.0);
        p_prev = p;
        p = p_next;
    }
    let dp = n as f64 * (t * p - p_prev) / (t * t - 1.0);
    (p, dp)
}

/// Gauss–Legendre rule with `n` points on [a, b]: (nodes, weights).
#[cfg(test)]
fn gauss_legendre(n: usize, a: f64, b: f64) -> (Vec<f64>, Vec<f64>) {
    let (t, w) = gauss_legendre_unit(n);
    let h = 0.5 * (b - a);
    (
        t.iter().map(|&t| a + h * (t + 1.0)).collect(),
        w.iter().map(|&w| h * w).collect(),
    )
}

/// k-th (k >= 1) root βL of the clamped-free frequency equation
/// 1 + cos βL cosh βL = 0, by safeguarded Newton on g(β) = 1/cosh β + cos β,
/// which has the same roots and exactly one in ((k−1)π, kπ).
fn clamped_free_root(k: usize) -> f64 {
    let g = |b: f64| 1.0 / b.cosh() + b.cos();
    let dg = |b: f64| -b.tanh() / b.cosh() - b.sin();
    let mut lo = (k - 1) as f64 * PI;
    let mut hi = k as f64 * PI;
    let lo_positive = g(lo) > 0.0;
    let mut b = (2 * k - 1) as f64 * PI / 2.0;
    for _ in 0..200 {
        let gb = g(b);
        if gb == 0.0 {
            return b;
        }
        if (gb > 0.0) == lo_positive {
            lo = b;
        } else {
            hi = b;
        }
        let mut next = b - gb / dg(b);
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if (next - b).abs() <= 4.0 * f64::EPSILON * b {
            return next;
        }
        b = next;
    }
    b
}

/// One clamped-free uniform-beam eigenfunction
/// ψ(x) = cosh βx − cos βx − σ (sinh βx − sin βx), evaluated in the stable form
/// ψ = a₊ e^{β(x−L)} + a₋ e^{−βx} − cos βx + σ sin βx,
/// with a₊ = (1 − σ) e^{βL} / 2 and a₋ = (1 + σ) / 2.
#[derive(Debug, Clone, Copy)]
struct ClampedFreeFunction {
    /// Wavenumber β, 1/m.
    beta: f64,
    /// Beam length, m.
    length: f64,
    sigma: f64,
    a_plus: f64,
    a_minus: f64,
}

impl ClampedFreeFunction {
    fn new(k: usize, length: f64) -> Self {
        let bl = clamped_free_root(k);
        let e = (-bl).exp();
        let (s, c) = bl.sin_cos();
        // (1 − σ) e^{βL} / 2 written without cancellation:
        // 1 − σ = (e^{−βL} + cos βL + sin βL) / (cosh βL + cos βL).
        let a_plus = (e + c + s) / (1.0 + e * e + 2.0 * e * c);
        let one_minus_sigma = 2.0 * a_plus * e;
        Self {
            beta: bl / length,
            length,
            sigma: 1.0 - one_minus_sigma,
            a_plus,
            a_minus: 1.0 - 0.5 * one_minus_sigma,
        }
    }

    /// (ψ, ψ' [1/m], ψ'' [1/m²]) at x (m).
    fn eval(&self, x: f64) -> (f64, f64, f64) {
        let z = self.beta * x;
        let t1 = self.a_plus * (self.beta * (x - self.length)).exp();
        let t2 = self.a_minus * (-z).exp();
        let (s, c) = z.sin_cos();
        let psi = t1 + t2 - c + self.sigma * s;
        let dpsi = self.beta * (t1 - t2 + s + self.sigma * c);
        let ddpsi = self.beta * self.beta * (t1 + t2 + c - self.sigma * s);
        (psi, dpsi, ddpsi)
    }
}

/// Result of the Ritz solve: basis, coefficients and frequencies.
struct RitzSolution {
    basis: Vec<ClampedFreeFunction>,
    /// B×N: φ_i = Σ_k coeffs[(k, i)] ψ_k.
    coeffs: DMatrix<f64>,
    /// rad/s, ascending.
    frequencies: Vec<f64>,
    /// Number of Gauss points of the mass-node rule.
    n_gauss: usize,
}

impl RitzSolution {
    /// (φ_i(x), φ_i'(x)) for all modes at x (m).
    fn mode_values(&self, x: f64) -> (Vec<f64>, Vec<f64>) {
        let n = self.coeffs.ncols();
        let mut phi = vec![0.0; n];
        let mut dphi = vec![0.0; n];
        for (k, f) in self.basis.iter().enumerate() {
            let (p, d, _) = f.eval(x);
            for i in 0..n {
                let c = self.coeffs[(k, i)];
                phi[i] += c * p;
                dphi[i] += c * d;
            }
        }
        (phi, dphi)
    }
}

fn validate(props: &BeamProperties, n_modes: usize) -> Result<(), String> {
    let positive = |name: &str, unit: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(format!(
                "{name} must be finite and positive (in {unit}), got {v}"
            ))
        }
    };
    positive("length", "m", props.length)?;
    positive("bending_stiffness", "N m^2", props.bending_stiffness)?;
    positive("mass_per_length", "kg/m", props.mass_per_length)?;
    if !(props.tip_mass.is_finite() && props.tip_mass >= 0.0) {
        return Err(format!(
            "tip_mass must be finite and non-negative (in kg), got {}",
            props.tip_mass
        ));
    }
    if n_modes == 0 || n_modes > MAX_MODES {
        return Err(format!(
            "n_modes must be between 1 and {MAX_MODES}, got {n_modes}"
        ));
    }
    Ok(())
}

/// Rayleigh–Ritz solve with B = n_modes + 6 clamped-free eigenfunctions.
fn ritz_solve(props: &BeamProperties, n_modes: usize) -> Result<RitzSolution, String> {
    validate(props, n_modes)?;
    let length = props.length;
    let nb = n_modes + EXTRA_BASIS;
    let n_gauss = 4 * nb + 8;
    let basis: Vec<ClampedFreeFunction> = (1..=nb)
        .map(|k| ClampedFreeFunction::new(k, length))
        .collect();

    // Basis mass matrix, exactly consistent with the node model.
    let mut mass = DMatrix::<f64>::zeros(nb, nb);
    let mut add_mass = |x: f64, m: f64| {
        let psi: Vec<f64> = basis.iter().map(|f| f.eval(x).0).collect();
        for k in 0..nb {
            for l in 0..nb {
                mass[(k, l)] += m * psi[k] * psi[l];
            }
        }
    };
    let (unit_t, unit_w) = gauss_legendre_unit(n_gauss);
    for (&t, &w) in unit_t.iter().zip(&unit_w) {
        add_mass(
            0.5 * length * (t + 1.0),
            props.mass_per_length * 0.5 * length * w,
        );
    }
    add_mass(length, props.tip_mass);

    // Basis stiffness by a finer Gauss rule.
    let mut stiff = DMatrix::<f64>::zeros(nb, nb);
    let (kt, kw) = gauss_legendre_unit(2 * n_gauss);
    for (&t, &w) in kt.iter().zip(&kw) {
        let x = 0.5 * length * (t + 1.0);
        let wk = props.bending_stiffness * 0.5 * length * w;
        let dd: Vec<f64> = basis.iter().map(|f| f.eval(x).2).collect();
        for k in 0..nb {
            for l in 0..nb {
                stiff[(k, l)] += wk * dd[k] * dd[l];
            }
        }
    }

    // K v = ω² M v via M = L Lᵀ, A = L⁻¹ K L⁻ᵀ.
    let chol = mass
        .clone()
        .cholesky()
        .ok_or_else(|| "basis mass matrix is not positive definite".to_string())?;
    let l = chol.l();
    let solve_err = || "triangular solve failed in the Ritz eigenproblem".to_string();
    let linv_k = l.solve_lower_triangular(&stiff).ok_or_else(solve_err)?;
    let a = l
        .solve_lower_triangular(&linv_k.transpose())
        .ok_or_else(solve_err)?;
    let a = (&a + a.transpose()) * 0.5;
    let eig = SymmetricEigen::new(a);
    let mut order: Vec<usize> = (0..nb).collect();
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));

    let lt = l.transpose();
    let mut coeffs = DMatrix::<f64>::zeros(nb, n_modes);
    let mut frequencies = Vec::with_capacity(n_modes);
    let psi_tip: Vec<f64> = basis.iter().map(|f| f.eval(length).0).collect();
    for (col, &idx) in order.iter().take(n_modes).enumerate() {
        let lambda = eig.eigenvalues[idx];
        if !(lambda.is_finite() && lambda > 0.0) {
            return Err(format!("non-positive Ritz eigenvalue {lambda}"));
        }
        let y = eig.eigenvectors.column(idx).into_owned();
        let mut v = lt.solve_upper_triangular(&y).ok_or_else(solve_err)?;
        let norm = (v.transpose() * &mass * &v)[(0, 0)].sqrt();
        v /= norm;
        let tip: f64 = v.iter().zip(&psi_tip).map(|(c, p)| c * p).sum();
        if tip < 0.0 {
            v = -v;
        }
        coeffs.set_column(col, &v);
        frequencies.push(lambda.sqrt());
    }
    Ok(RitzSolution {
        basis,
        coeffs,
        frequencies,
        n_gauss,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// Span 10 m, EI = 1.4e4 N m², ρA = 1.2 kg/m.
    fn props_big(tip_mass: f64) -> BeamProperties {
        BeamProperties {
            length: 10.0,
            bending_stiffness: 1.4e4,
            mass_per_length: 1.2,
            tip_mass,
        }
    }

    /// Unit beam: L = 1, EI = 1, ρA = 1.
    fn props_unit(tip_mass: f64) -> BeamProperties {
        BeamProperties {
            length: 1.0,
            bending_stiffness: 1.0,
            mass_per_length: 1.0,
            tip_mass,
        }
    }

    /// sqrt(ρA L⁴ / EI), s: multiplies ω to give the non-dimensional ω̄.
    fn time_scale(p: &BeamProperties) -> f64 {
        (p.mass_per_length * p.length.powi(4) / p.bending_stiffness).sqrt()
    }

    /// Lowest eigenvalues (ascending) of a symmetric matrix.
    fn sorted_eigenvalues(m: DMatrix<f64>) -> Vec<f64> {
        let mut ev: Vec<f64> = SymmetricEigen::new(m).eigenvalues.iter().copied().collect();
        ev.sort_by(f64::total_cmp);
        ev
    }

    fn max_abs(m: &DMatrix<f64>) -> f64 {
        m.iter().fold(0.0, |a: f64, &b| a.max(b.abs()))
    }

    #[test]
    fn gauss_legendre_exact_for_degree_2g_minus_1() {
        for &len in &[1.0, 10.0] {
            for &g in &[1usize, 2, 5, 13, 36, 72, 144] {
                let (x, w) = gauss_legendre(g, 0.0, len);
                let wsum: f64 = w.iter().sum();
                assert_relative_eq!(wsum, len, max_relative = 1e-14);
                let p = (2 * g - 1) as i32;
                let approx: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(p)).sum();
                let exact = len.powi(p + 1) / (p + 1) as f64;
                assert_relative_eq!(approx, exact, max_relative = 1e-13);
                assert!(x.windows(2).all(|s| s[0] < s[1]));
            }
        }
    }

    #[test]
    fn clamped_free_roots_match_reference() {
        let reference = [1.875104068711961, 4.694091132974175, 7.854757438237613];
        for (k, r) in reference.iter().enumerate() {
            assert!((clamped_free_root(k + 1) - r).abs() < 1e-12);
        }
        // Higher roots approach (2k−1)π/2 and stay in their brackets.
        for k in 4..=16 {
            let b = clamped_free_root(k);
            assert!((b - (2 * k - 1) as f64 * PI / 2.0).abs() < 1e-3);
            // Residual limited by rounding of the argument of cos (~β·ε).
            assert!((1.0 / b.cosh() + b.cos()).abs() < 1e-13);
        }
    }

    #[test]
    fn basis_functions_stable_form_and_orthogonality() {
        let len = 10.0;
        let nb = 16;
        let basis: Vec<_> = (1..=nb).map(|k| ClampedFreeFunction::new(k, len)).collect();
        // Agree with the textbook form where it is still well-conditioned.
        for f in basis.iter().take(3) {
            let bl = f.beta * len;
            let sigma = (bl.sinh() - bl.sin()) / (bl.cosh() + bl.cos());
            for i in 0..=20 {
                let x = len * i as f64 / 20.0;
                let z = f.beta * x;
                let naive = z.cosh() - z.cos() - sigma * (z.sinh() - z.sin());
                assert!((f.eval(x).0 - naive).abs() < 1e-11);
            }
        }
        // Boundary conditions: ψ(0) = ψ'(0) = 0, ψ''(L) = 0, |ψ(L)| = 2.
        for f in &basis {
            let (p0, d0, _) = f.eval(0.0);
            let (pl, _, ddl) = f.eval(len);
            assert!(p0.abs() < 1e-14);
            assert!(d0.abs() < 1e-14 * f.beta);
            assert!(ddl.abs() < 1e-12 * f.beta * f.beta);
            assert_relative_eq!(pl.abs(), 2.0, max_relative = 1e-12);
        }
        // ∫ψ_kψ_l = L δ_kl and ∫ψ_k''ψ_l'' = β_k⁴ L δ_kl (closed forms).
        let (x, w) = gauss_legendre(200, 0.0, len);
        let mut worst_m: f64 = 0.0;
        let mut worst_k: f64 = 0.0;
        for k in 0..nb {
            for l in 0..nb {
                let (mut m, mut s) = (0.0, 0.0);
                for (&x, &w) in x.iter().zip(&w) {
                    let a = basis[k].eval(x);
                    let b = basis[l].eval(x);
                    m += w * a.0 * b.0;
                    s += w * a.2 * b.2;
                }
                let em = if k == l { len } else { 0.0 };
                let b4 = (basis[k].beta * basis[l].beta).powi(2);
                let es = if k == l { b4 * len } else { 0.0 };
                worst_m = worst_m.max((m - em).abs() / len);
                worst_k = worst_k.max((s - es).abs() / (b4 * len));
            }
        }
        assert!(worst_m < 1e-12, "mass orthogonality error {worst_m}");
        assert!(worst_k < 1e-12, "stiffness orthogonality error {worst_k}");
    }

    #[test]
    fn non_rotating_frequencies_without_tip_mass() {
        // ω̄ = (βL)² with the reference roots.
        let reference = [
            1.875104068711961f64.powi(2),
            4.694091132974175f64.powi(2),
            7.854757438237613f64.powi(2),
        ];
        for props in [props_big(0.0), props_unit(0.0)] {
            for n in [3, 5, 10] {
                let modes = beam_modes(&props, n).unwrap();
                assert_eq!(modes.frequencies.len(), n);
                assert!(modes.frequencies.windows(2).all(|w| w[0] < w[1]));
                let ts = time_scale(&props);
                for (w, r) in modes.frequencies.iter().zip(&reference) {
                    assert_relative_eq!(w * ts, r, max_relative = 1e-10);
                }
            }
        }
        let modes = beam_modes(&props_unit(0.0), 5).unwrap();
        assert_relative_eq!(modes.frequencies[0], 3.5160, max_relative = 1e-5);
        assert_relative_eq!(modes.frequencies[1], 22.0345, max_relative = 1e-5);
    }

    #[test]
    fn node_model_mass_normalised_and_clamped() {
        for props in [props_big(0.0), props_big(3.0), props_unit(1.0)] {
            let n = 5;
            let modes = beam_modes(&props, n).unwrap();
            let err = max_abs(&(modes.mass_matrix() - DMatrix::identity(n, n)));
            assert!(err < 1e-12, "mass matrix error {err}");
            // Total node mass = ρA L + m_tip.
            let total: f64 = modes.nodes.iter().map(|g| g.mass).sum();
            let expect = props.mass_per_length * props.length + props.tip_mass;
            assert_relative_eq!(total, expect, max_relative = 1e-13);
            // Tip node.
            let tip = &modes.nodes[modes.tip];
            assert_eq!(tip.x, props.length);
            assert_eq!(tip.mass, props.tip_mass);
            assert!(tip.phi.iter().all(|&p| p > 0.0));
            // Stiffness = diag(ω²).
            let k = modes.stiffness_matrix();
            for i in 0..n {
                assert_eq!(k[(i, i)], modes.frequencies[i].powi(2));
            }
            // Clamped root: φ(0) = φ'(0) = 0 (evaluated from the basis).
            let ritz = ritz_solve(&props, n).unwrap();
            let (p0, d0) = ritz.mode_values(0.0);
            let (pl, dl) = ritz.mode_values(props.length);
            let scale_p = pl.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            let scale_d = dl.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            assert!(p0.iter().all(|v| v.abs() < 1e-13 * scale_p));
            assert!(d0.iter().all(|v| v.abs() < 1e-13 * scale_d));
            // Shortening is symmetric, and positive semi-definite on the diagonal.
            for g in &modes.nodes {
                for i in 0..n {
                    assert!(g.shortening[i * n + i] >= 0.0);
                    for j in 0..n {
                        assert_eq!(g.shortening[i * n + j], g.shortening[j * n + i]);
                    }
                }
            }
        }
    }

    /// Non-dimensional frequency ω̄ = λ² of the k-th root of the cantilever
    /// tip-mass frequency equation
    /// 1 + cos λ cosh λ + μλ(cos λ sinh λ − sin λ cosh λ) = 0
    /// (divided by cosh λ), by scanning and bisection.
    fn tip_mass_reference(mu: f64, k: usize) -> f64 {
        let f = |l: f64| 1.0 / l.cosh() + l.cos() + mu * l * (l.cos() * l.tanh() - l.sin());
        let mut found = 0;
        let step = 1e-3;
        let mut a = step;
        loop {
            let b = a + step;
            if f(a) * f(b) <= 0.0 {
                found += 1;
                if found == k {
                    let (mut lo, mut hi) = (a, b);
                    for _ in 0..200 {
                        let mid = 0.5 * (lo + hi);
                        if f(lo) * f(mid) <= 0.0 {
                            hi = mid;
                        } else {
                            lo = mid;
                        }
                    }
                    let l = 0.5 * (lo + hi);
                    return l * l;
                }
            }
            a = b;
        }
    }

    #[test]
    fn tip_mass_frequencies_match_frequency_equation() {
        // The clamped-free basis does not satisfy the tip shear condition
        // EI w'''(L) = −m_tip ω² w(L), so Ritz converges algebraically
        // (measured with μ = 1: n_modes = 5 → 1.00e-5 / 1.22e-4,
        // n_modes = 10 → 3.3e-6 / 4.0e-5 relative for modes 1 / 2).
        let mu = 1.0;
        let r1 = tip_mass_reference(mu, 1);
        let r2 = tip_mass_reference(mu, 2);
        for base in [props_big(0.0), props_unit(0.0)] {
            let props = BeamProperties {
                tip_mass: mu * base.mass_per_length * base.length,
                ..base
            };
            for (n, tol1, tol2) in [(10, 1e-5, 1e-4), (5, 1.5e-5, 1.5e-4)] {
                let modes = beam_modes(&props, n).unwrap();
                let ts = time_scale(&props);
                let e1 = modes.frequencies[0] * ts / r1 - 1.0;
                let e2 = modes.frequencies[1] * ts / r2 - 1.0;
                // Rayleigh–Ritz bounds from above.
                assert!(e1 > -1e-12 && e2 > -1e-12);
                assert!(e1 < tol1, "n = {n}: mode 1 relative error {e1}");
                assert!(e2 < tol2, "n = {n}: mode 2 relative error {e2}");
            }
        }
    }

    #[test]
    fn rotating_cantilever_flap_frequencies() {
        // Published first-flap ω̄ for a uniform rotating cantilever, zero hub
        // radius, γ = Ω sqrt(ρA L⁴/EI). Non-rotating modes represent the
        // tension-loaded root poorly, so the reduced model converges like
        // ~n⁻⁵ (measured, n_modes = 5: 0, 4.8e-5, 4.1e-4; n_modes = 10:
        // 0, 1.4e-5, 1.9e-5 relative to the 5-digit published values).
        let cases = [(0.0, 3.5160), (6.0, 7.3604), (12.0, 13.1702)];
        for props in [props_unit(0.0), props_big(0.0)] {
            let ts = time_scale(&props);
            let mut previous: Option<Vec<f64>> = None;
            for (n, tol) in [(5, 1e-3), (10, 3e-5)] {
                let modes = beam_modes(&props, n).unwrap();
                let k = modes.stiffness_matrix();
                let kg = modes.geometric_stiffness(0.0);
                let mut current = Vec::new();
                for &(gamma, reference) in &cases {
                    let omega = gamma / ts;
                    let ev = sorted_eigenvalues(&k + &kg * (omega * omega));
                    let wbar = ev[0].sqrt() * ts;
                    let err = (wbar / reference - 1.0).abs();
                    assert!(err < tol, "n = {n}, γ = {gamma}: ω̄ = {wbar}, error {err}");
                    current.push(wbar);
                }
                // More modes can only lower the Ritz estimate.
                if let Some(prev) = &previous {
                    for (c, p) in current.iter().zip(prev) {
                        assert!(*c <= p * (1.0 + 1e-12));
                    }
                }
                previous = Some(current);
            }
        }
    }

    /// Composite Simpson over [0, L] of f(x) φ_i'(x) φ_j'(x), with φ' from
    /// the basis functions directly.
    fn simpson_dphi_products(
        ritz: &RitzSolution,
        len: f64,
        intervals: usize,
        f: impl Fn(f64) -> f64,
    ) -> DMatrix<f64> {
        let n = ritz.coeffs.ncols();
        let h = len / intervals as f64;
        let mut out = DMatrix::zeros(n, n);
        for s in 0..=intervals {
            let x = h * s as f64;
            let c = if s == 0 || s == intervals {
                1.0
            } else if s % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let wgt = c * h / 3.0 * f(x);
            let (_, d) = ritz.mode_values(x);
            for i in 0..n {
                for j in 0..n {
                    out[(i, j)] += wgt * d[i] * d[j];
                }
            }
        }
        out
    }

    #[test]
    fn geometric_stiffness_matches_closed_form() {
        for props in [props_big(0.0), props_big(4.0), props_unit(0.5)] {
            let n = 5;
            let modes = beam_modes(&props, n).unwrap();
            let ritz = ritz_solve(&props, n).unwrap();
            let len = props.length;
            let rho = props.mass_per_length;
            let m_tip = props.tip_mass;
            let intervals = 40_000;
            let centrifugal =
                simpson_dphi_products(&ritz, len, intervals, |x| rho * 0.5 * (len * len - x * x));
            let full = simpson_dphi_products(&ritz, len, intervals, |_| 1.0);
            let lever = simpson_dphi_products(&ritz, len, intervals, |x| rho * (len - x));
            let expect0 = &centrifugal + &full * (m_tip * len);
            let got0 = modes.geometric_stiffness(0.0);
            let err0 = max_abs(&(&got0 - &expect0)) / max_abs(&expect0);
            assert!(err0 < 1e-9, "K_G(0) relative error {err0}");
            // Hub offset r adds r (∫ρA (L − x) φ_i'φ_j' dx + m_tip S(L)).
            let r = 0.3 * len;
            let expect_r = &expect0 + (&lever + &full * m_tip) * r;
            let got_r = modes.geometric_stiffness(r);
            let err_r = max_abs(&(&got_r - &expect_r)) / max_abs(&expect_r);
            assert!(err_r < 1e-9, "K_G(r) relative error {err_r}");
            // Tip shortening S(L) = ∫_0^L φ_i'φ_j'.
            let s_tip = DMatrix::from_row_slice(n, n, &modes.nodes[modes.tip].shortening);
            let err_s = max_abs(&(&s_tip - &full)) / max_abs(&full);
            assert!(err_s < 1e-9, "S(L) relative error {err_s}");
        }
    }

    #[test]
    fn rejects_bad_properties() {
        let good = props_big(1.0);
        assert!(beam_modes(&good, 1).is_ok());
        let cases: [(BeamProperties, &str); 9] = [
            (
                BeamProperties {
                    length: 0.0,
                    ..good
                },
                "length",
            ),
            (
                BeamProperties {
                    length: f64::NAN,
                    ..good
                },
                "length",
            ),
            (
                BeamProperties {
                    length: f64::INFINITY,
                    ..good
                },
                "length",
            ),
            (
                BeamProperties {
                    bending_stiffness: -1.0,
                    ..good
                },
                "bending_stiffness",
            ),
            (
                BeamProperties {
                    bending_stiffness: f64::NAN,
                    ..good
                },
                "bending_stiffness",
            ),
            (
                BeamProperties {
                    mass_per_length: 0.0,
                    ..good
                },
                "mass_per_length",
            ),
            (
                BeamProperties {
                    mass_per_length: f64::INFINITY,
                    ..good
                },
                "mass_per_length",
            ),
            (
                BeamProperties {
                    tip_mass: -0.1,
                    ..good
                },
                "tip_mass",
            ),
            (
                BeamProperties {
                    tip_mass: f64::NAN,
                    ..good
                },
                "tip_mass",
            ),
        ];
        for (p, name) in cases {
            let err = beam_modes(&p, 3).unwrap_err();
            assert!(err.contains(name), "{err}");
        }
        for n in [0, 11] {
            let err = beam_modes(&good, n).unwrap_err();
            assert!(err.contains("n_modes"), "{err}");
        }
    }
}
