//! Closed-form solution of torque-free rigid-body motion (the Euler–Poinsot problem): the
//! project's reference solution.
//!
//! Conventions: SI units; the attitude quaternion maps body vectors to inertial vectors
//! (`v_N = R(q) v_B`), Hamilton product, `q̇ = ½ q ⊗ (0, ω_B)`; body rates are in the user's
//! body frame, in which the inertia tensor may be a full symmetric matrix. Internally the
//! solution works in principal axes (I1 ≤ I2 ≤ I3, right-handed) and rotates back.
//!
//! Body rates follow Jacobi's elliptic-function solution; the attitude is a 3-1-3 Euler
//! sequence relative to an inertial frame whose z axis is the angular momentum, with nutation
//! and spin angles algebraic in the rates and the precession angle in closed form through an
//! incomplete elliptic integral of the third kind (Carlson R_J). Derivation, regimes and
//! measured accuracy: `docs/exact-solution.md`.

pub mod elliptic;
#[cfg(test)]
mod tests;

use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::fmt;

use nalgebra::{Matrix3, Quaternion, Rotation3, SymmetricEigen, Unit, UnitQuaternion, Vector3};

use elliptic::{Jacobi, carlson_rj, inverse_sncndn, is_odd};

/// Two principal moments whose difference is at most this fraction of the largest moment are
/// treated as equal (axisymmetric body; all three: spherical). Dimensionless.
pub const SYMMETRY_TOLERANCE: f64 = 1e-13;

/// Largest accepted asymmetry |J_ij − J_ji| of the inertia tensor, relative to its largest
/// entry; the tensor is symmetrised before use. Dimensionless.
pub const ASYMMETRY_TOLERANCE: f64 = 1e-12;

/// Relative slack on the triangle inequality I1 + I2 ≥ I3 of the principal moments.
/// Dimensionless.
pub const TRIANGLE_TOLERANCE: f64 = 1e-12;

/// Qualitative type of the torque-free motion. Axis numbers refer to the sorted principal
/// axes: 1 = minimum, 2 = intermediate, 3 = maximum moment of inertia.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Regime {
    /// ω = 0: the body stays at rest.
    Rest,
    /// All three principal moments equal: ω is constant, the body spins uniformly about it.
    Spherical,
    /// Two moments equal: ω precesses uniformly about the symmetry axis `axis` (1 or 3, the
    /// axis whose moment is unique). Includes spin about or perpendicular to that axis.
    Symmetric {
        /// Symmetry axis (1 = its moment is the minimum, 3 = the maximum).
        axis: u8,
    },
    /// Triaxial body spinning exactly about principal axis `axis` (ω constant; about axis 2 it
    /// is the unstable equilibrium).
    PureSpin {
        /// Spin axis (1, 2 or 3).
        axis: u8,
    },
    /// Triaxial body, polhode circulating about principal axis `axis`: 3 when L² > 2E·I2,
    /// 1 when L² < 2E·I2.
    Circulating {
        /// Axis the polhode encircles (1 or 3).
        axis: u8,
    },
    /// Triaxial body exactly on the separatrix L² = 2E·I2 (hyperbolic solution: ω tends to
    /// the intermediate axis as t → ±∞).
    Separatrix,
}

/// Why a torque-free solution could not be built.
#[derive(Debug, Clone, PartialEq)]
pub enum ExactError {
    /// An input (inertia, rate or quaternion, named here) has a NaN or infinite entry.
    NonFinite(&'static str),
    /// The inertia tensor is not symmetric: largest |J_ij − J_ji| (kg m²) given.
    NotSymmetric {
        /// Largest |J_ij − J_ji| (kg m²).
        asymmetry: f64,
    },
    /// The inertia tensor is not positive definite: its smallest eigenvalue (kg m²) given.
    NotPositiveDefinite {
        /// Smallest eigenvalue (kg m²).
        min_moment: f64,
    },
    /// The principal moments (kg m², sorted) violate I1 + I2 ≥ I3: not a physical body.
    TriangleInequality {
        /// Sorted principal moments (kg m²).
        moments: [f64; 3],
    },
}

impl fmt::Display for ExactError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ExactError::NonFinite(what) => write!(f, "non-finite value in {what}"),
            ExactError::NotSymmetric { asymmetry } => write!(
                f,
                "inertia tensor is not symmetric (largest |J_ij - J_ji| = {asymmetry:e} kg m^2)"
            ),
            ExactError::NotPositiveDefinite { min_moment } => write!(
                f,
                "inertia tensor is not positive definite (smallest eigenvalue {min_moment:e} kg m^2)"
            ),
            ExactError::TriangleInequality { moments } => write!(
                f,
                "principal moments {:?} kg m^2 violate the triangle inequality I1 + I2 >= I3",
                moments
            ),
        }
    }
}

impl std::error::Error for ExactError {}

/// Exact torque-free motion of a rigid body from given initial rates and attitude.
///
/// Build once with [`TorqueFreeSolution::new`], then evaluate at any time (negative and large
/// times included) with [`TorqueFreeSolution::state_at`]; everything that does not depend on
/// t is precomputed. A `state_at` call costs about 0.6 µs (elliptic case).
#[derive(Debug, Clone)]
pub struct TorqueFreeSolution {
    regime: Regime,
    m: f64,
    m1: f64,
    lambda: f64,
    period: f64,
    delta: f64,
    /// `delta` before reduction to [0, 2π) (rad).
    delta_total: f64,
    moments: Vector3<f64>,
    axes: Matrix3<f64>,
    h_inertial: Vector3<f64>,
    energy: f64,
    motion: Motion,
}

#[derive(Debug, Clone)]
enum Motion {
    /// ω constant; q(t) = q0 ⊗ exp(½ ω t).
    Steady {
        omega: Vector3<f64>,
        q0: UnitQuaternion<f64>,
    },
    Symmetric(SymmetricMotion),
    Elliptic(Box<EllipticMotion>),
}

/// Axisymmetric body, in the user's body frame: ω(t) = Rot(a, k t) ω0 and
/// q(t) = Rot_N(Ĥ, h t / I_t) ⊗ q0 ⊗ Rot_B(a, −k t).
#[derive(Debug, Clone)]
struct SymmetricMotion {
    axis: Unit<Vector3<f64>>,
    omega_par: Vector3<f64>,
    omega_perp: Vector3<f64>,
    omega_cross: Vector3<f64>,
    rate_k: f64,
    precession_rate: f64,
    h_hat_n: Unit<Vector3<f64>>,
    q0: UnitQuaternion<f64>,
}

/// Triaxial body (elliptic or separatrix motion), expressed in the "Euler frame" E: the
/// principal axes ordered so that E3 is the axis the polhode circulates about (identity order
/// for circulation about axis 3 and on the separatrix, cyclic (2, 3, 1) for circulation about
/// axis 1).
#[derive(Debug, Clone)]
struct EllipticMotion {
    separatrix: bool,
    jac: Jacobi,
    m: f64,
    lambda: f64,
    /// Phase c: τ(t) = λ t + c.
    phase: f64,
    /// Signed amplitudes (rad/s) of ω_E: ω_E = amp ∘ (cn, sn, dn) or amp ∘ (sn, cn, dn).
    amp: [f64; 3],
    /// true: ω_E = amp ∘ (sn, cn, dn) (circulation about axis 1).
    sn_first: bool,
    /// Principal moments in E order (kg m²).
    inertia_e: [f64; 3],
    /// |H| / I_c (rad/s), I_c = moment of the circulation axis.
    spin_rate: f64,
    /// |H| (1/I_o − 1/I_c) / λ (dimensionless): φ = spin_rate·t + kappa·(Π̃(τ) − Π̃(c)).
    kappa: f64,
    /// ν > 0 in φ̇ = |H|/I_c + |H|(1/I_o − 1/I_c) / (1 + ν sn²).
    nu: f64,
    big_nu: bool,
    /// √((1 + ν)(1 + m/ν)), used when ν > 1.
    x_big: f64,
    /// Π̃(K) (0 on the separatrix, where it is not used).
    pi_k: f64,
    /// Π̃(c).
    pi_c: f64,
    /// |coefficients| of sin β and cos β in (H_E1, H_E2) and their signs, for unwrapping ψ.
    sin_coef: f64,
    cos_coef: f64,
    sign_a: f64,
    sign_b: f64,
    /// E-frame axes as columns in the user body frame.
    pe: Matrix3<f64>,
    q_left: UnitQuaternion<f64>,
    q_right: UnitQuaternion<f64>,
}

/// φ reduced to [−2π, 2π] (the quaternion of a rotation by φ has period 4π), in two parts
/// so that the reduction adds no error beyond that of φ itself.
fn reduce_4pi(phi: f64) -> f64 {
    const FOUR_PI_HI: f64 = 4.0 * PI;
    const FOUR_PI_LO: f64 = 4.898_587_196_589_413e-16;
    let n = (phi / FOUR_PI_HI).round();
    if n == 0.0 {
        return phi;
    }
    (-n).mul_add(FOUR_PI_LO, (-n).mul_add(FOUR_PI_HI, phi))
}

/// Quaternion of the 3-1-3 rotation Rz(φ)·Rx(θ)·Rz(ψ).
fn euler313(phi: f64, theta: f64, psi: f64) -> UnitQuaternion<f64> {
    let (st, ct) = (0.5 * theta).sin_cos();
    let (sp, cp) = (0.5 * (phi + psi)).sin_cos();
    let (sm, cm) = (0.5 * (phi - psi)).sin_cos();
    UnitQuaternion::new_unchecked(Quaternion::new(ct * cp, st * cm, st * sm, ct * sp))
}

impl EllipticMotion {
    /// Π̃(r) = ∫₀^r du / (1 + ν sn²u) for r in [−K, K] (any r on the separatrix), given
    /// (sn, cn, dn)(r).
    fn pi_tilde_reduced(&self, r: f64, s: f64, c: f64, d: f64) -> f64 {
        let nu = self.nu;
        if self.separatrix {
            // m = 1: ∫ du / (1 + ν tanh²u) = (u + √ν atan(√ν tanh u)) / (1 + ν).
            let sq = nu.sqrt();
            return (r + sq * (sq * s).atan()) / (1.0 + nu);
        }
        if s == 0.0 {
            return 0.0;
        }
        let s3 = s * s * s;
        let (c2, d2) = (c * c, d * d);
        if self.big_nu {
            // Π(n) = F − Π(m/n) + R_C term (DLMF 19.7.9) with n = −ν: no cancellation for ν > 1.
            let m = self.m;
            m / (3.0 * nu) * s3 * carlson_rj(c2, d2, 1.0, 1.0 + m * s * s / nu)
                + (s * self.x_big).atan2(c * d) / self.x_big
        } else {
            // Π(n; φ|m) = F + (n/3) sin³φ R_J(cos²φ, dn², 1, 1 − n sin²φ) (DLMF 19.25.14).
            r - nu / 3.0 * s3 * carlson_rj(c2, d2, 1.0, 1.0 + nu * s * s)
        }
    }

    fn pi_tilde(&self, tau: f64) -> f64 {
        let (j, r) = self.jac.reduce(tau);
        let (s, c, d) = self.jac.eval_reduced(r);
        self.pi_tilde_total(j, r, s, c, d)
    }

    fn pi_tilde_total(&self, j: f64, r: f64, s: f64, c: f64, d: f64) -> f64 {
        let base = self.pi_tilde_reduced(r, s, c, d);
        if j == 0.0 {
            base
        } else {
            (2.0 * j).mul_add(self.pi_k, base)
        }
    }

    /// ω in the E frame from the reduced values.
    fn omega_e(&self, j: f64, s: f64, c: f64, d: f64) -> Vector3<f64> {
        let (s, c) = if is_odd(j) { (-s, -c) } else { (s, c) };
        if self.sn_first {
            Vector3::new(self.amp[0] * s, self.amp[1] * c, self.amp[2] * d)
        } else {
            Vector3::new(self.amp[0] * c, self.amp[1] * s, self.amp[2] * d)
        }
    }

    fn omega(&self, t: f64) -> Vector3<f64> {
        let tau = self.lambda.mul_add(t, self.phase);
        let (j, r) = self.jac.reduce(tau);
        let (s, c, d) = self.jac.eval_reduced(r);
        self.pe * self.omega_e(j, s, c, d)
    }

    /// ω_E(t) and the E → N' rotation Rz(φ)Rx(θ)Rz(ψ).
    fn euler_state(&self, t: f64) -> (Vector3<f64>, UnitQuaternion<f64>) {
        let tau = self.lambda.mul_add(t, self.phase);
        let (j, r) = self.jac.reduce(tau);
        let (s, c, d) = self.jac.eval_reduced(r);
        let w = self.omega_e(j, s, c, d);
        let pit = self.pi_tilde_total(j, r, s, c, d);
        let phi = reduce_4pi(self.spin_rate.mul_add(t, self.kappa * (pit - self.pi_c)));
        let hx = self.inertia_e[0] * w.x;
        let hy = self.inertia_e[1] * w.y;
        let hz = self.inertia_e[2] * w.z;
        let theta = hx.hypot(hy).atan2(hz);
        let psi_p = hx.atan2(hy);
        // Continuous branch of ψ: χ = continuous angle of (cos_coef·cos β, sin_coef·sin β),
        // β = am τ = jπ + am r; only j mod 4 matters for the quaternion.
        let chi = j
            .rem_euclid(4.0)
            .mul_add(PI, (self.sin_coef * s).atan2(self.cos_coef * c));
        let psi_c = if self.sn_first {
            self.sign_a * (FRAC_PI_2 - self.sign_b * (FRAC_PI_2 - chi))
        } else {
            self.sign_a * (FRAC_PI_2 - self.sign_b * chi)
        };
        let psi = psi_p + TAU * ((psi_c - psi_p) / TAU).round();
        (w, euler313(phi, theta, psi))
    }

    fn state(&self, t: f64) -> (Vector3<f64>, UnitQuaternion<f64>) {
        let (w, qe) = self.euler_state(t);
        (self.pe * w, self.q_left * qe * self.q_right)
    }
}

/// Principal moments (ascending) and axes (columns, right-handed) of a symmetric matrix.
/// A diagonal matrix is handled exactly (signed permutation of the body axes).
fn principal_decomposition(j: &Matrix3<f64>) -> ([f64; 3], Matrix3<f64>) {
    let diagonal = j[(0, 1)] == 0.0 && j[(0, 2)] == 0.0 && j[(1, 2)] == 0.0;
    let (vals, vecs) = if diagonal {
        ([j[(0, 0)], j[(1, 1)], j[(2, 2)]], Matrix3::identity())
    } else {
        let e = SymmetricEigen::new(*j);
        (
            [e.eigenvalues[0], e.eigenvalues[1], e.eigenvalues[2]],
            e.eigenvectors,
        )
    };
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&a, &b| vals[a].total_cmp(&vals[b]));
    // Canonical signs: axes 1 and 2 point into the positive half of the body axis they are
    // closest to (largest component positive); axis 3 = axis 1 × axis 2 (right-handed).
    let mut cols = [
        vecs.column(idx[0]).into_owned(),
        vecs.column(idx[1]).into_owned(),
    ];
    for c in &mut cols {
        let imax = c.iamax();
        if c[imax] < 0.0 {
            *c = -*c;
        }
    }
    // Re-orthonormalise (Gram–Schmidt) so that P is a rotation to rounding level.
    cols[0] = cols[0].normalize();
    cols[1] = (cols[1] - cols[0] * cols[0].dot(&cols[1])).normalize();
    let p = Matrix3::from_columns(&[cols[0], cols[1], cols[0].cross(&cols[1])]);
    ([vals[idx[0]], vals[idx[1]], vals[idx[2]]], p)
}

/// A power of two close to x > 0 (exact scaling factor).
fn pow2_near(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return 1.0;
    }
    let e = (x.log2().floor() as i32).clamp(-1000, 1000);
    2f64.powi(e)
}

fn quat_of(m: &Matrix3<f64>) -> UnitQuaternion<f64> {
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*m))
}

/// Rotation by `angle` (rad) about `axis`.
fn axis_angle(axis: &Unit<Vector3<f64>>, angle: f64) -> UnitQuaternion<f64> {
    let (s, c) = (0.5 * angle).sin_cos();
    UnitQuaternion::new_unchecked(Quaternion::from_parts(c, axis.into_inner() * s))
}

/// Data shared by all triaxial elliptic cases before the Euler frame is fixed.
struct Triaxial {
    separatrix: bool,
    m: f64,
    m1: f64,
    lambda_n: f64,
    amp_n: [f64; 3],
    sn_first: bool,
    order: [usize; 3],
    /// (sn, cn, dn) at t = 0, or for the separatrix the phase directly.
    initial: Initial,
    i_c: f64,
    i_o: f64,
    nu: f64,
}

enum Initial {
    Functions { s: f64, c: f64, d: f64 },
    Phase(f64),
}

impl TorqueFreeSolution {
    /// Builds the exact solution. `inertia`: body-frame inertia tensor (kg m², symmetric
    /// positive definite, any orientation), `omega0`: body rates at t = 0 (rad/s, body frame),
    /// `q0`: attitude at t = 0 (body → inertial).
    pub fn new(
        inertia: &Matrix3<f64>,
        omega0: &Vector3<f64>,
        q0: &UnitQuaternion<f64>,
    ) -> Result<Self, ExactError> {
        if !inertia.iter().all(|x| x.is_finite()) {
            return Err(ExactError::NonFinite("inertia"));
        }
        if !omega0.iter().all(|x| x.is_finite()) {
            return Err(ExactError::NonFinite("omega0"));
        }
        if !q0.coords.iter().all(|x| x.is_finite()) {
            return Err(ExactError::NonFinite("q0"));
        }
        let scale = inertia.amax();
        let asymmetry = (inertia - inertia.transpose()).amax();
        if asymmetry > ASYMMETRY_TOLERANCE * scale {
            return Err(ExactError::NotSymmetric { asymmetry });
        }
        let j = (inertia + inertia.transpose()) * 0.5;
        let (moments, p) = principal_decomposition(&j);
        let [i1, i2, i3] = moments;
        if i1 <= 0.0 {
            return Err(ExactError::NotPositiveDefinite { min_moment: i1 });
        }
        if i1 + i2 < i3 * (1.0 - TRIANGLE_TOLERANCE) {
            return Err(ExactError::TriangleInequality { moments });
        }
        let h_body = j * omega0;
        let h_inertial = q0 * h_body;
        let energy = 0.5 * omega0.dot(&h_body);
        let mut sol = TorqueFreeSolution {
            regime: Regime::Rest,
            m: 0.0,
            m1: 1.0,
            lambda: 0.0,
            period: f64::INFINITY,
            delta: f64::NAN,
            delta_total: f64::NAN,
            moments: Vector3::new(i1, i2, i3),
            axes: p,
            h_inertial,
            energy,
            motion: Motion::Steady {
                omega: *omega0,
                q0: *q0,
            },
        };
        if *omega0 == Vector3::zeros() {
            return Ok(sol);
        }
        let tol = SYMMETRY_TOLERANCE * i3;
        let eq12 = i2 - i1 <= tol;
        let eq23 = i3 - i2 <= tol;
        if eq12 && eq23 {
            sol.regime = Regime::Spherical;
            return Ok(sol);
        }
        if eq12 || eq23 {
            sol.build_symmetric(eq12, omega0, q0);
            return Ok(sol);
        }
        // Triaxial: principal components, scaled by an exact power of two.
        let w = p.transpose() * omega0;
        let sc = pow2_near(w.amax());
        let wn = w / sc;
        let (w1, w2, w3) = (wn.x, wn.y, wn.z);
        let (d21, d31, d32) = (i2 - i1, i3 - i1, i3 - i2);
        let i123 = i1 * i2 * i3;
        let (q1, q2, q3) = (w1 * w1, w2 * w2, w3 * w3);
        // Δ1 = L² − 2E·I1, Δ3 = 2E·I3 − L² as sums of non-negative terms.
        let delta1 = i2 * q2 * d21 + i3 * q3 * d31;
        let delta3 = i1 * q1 * d31 + i2 * q2 * d32;
        // L² − 2E·I2 = I3 ω3² (I3 − I2) − I1 ω1² (I2 − I1).
        let d2 = i3 * q3 * d32 - i1 * q1 * d21;
        let lam_a = (d32 * delta1 / i123).sqrt();
        let lam_c = (d21 * delta3 / i123).sqrt();
        if w1 == 0.0 && w2 == 0.0 {
            sol.set_pure_spin(3, 0.0, 1.0, sc * lam_a, omega0);
            return Ok(sol);
        }
        if w2 == 0.0 && w3 == 0.0 {
            sol.set_pure_spin(1, 0.0, 1.0, sc * lam_c, omega0);
            return Ok(sol);
        }
        if w1 == 0.0 && w3 == 0.0 {
            sol.set_pure_spin(2, 1.0, 0.0, sc * lam_a, omega0);
            return Ok(sol);
        }
        let amp_a = (delta3 / (i1 * d31)).sqrt();
        let tri = if d2 > 0.0 {
            // Circulation about axis 3: ω = (A cn, s B sn, s C dn), s = sign ω3.
            let b = (delta3 / (i2 * d32)).sqrt();
            let c = (delta1 / (i3 * d31)).sqrt();
            let s3 = w3.signum();
            Triaxial {
                separatrix: false,
                m: d21 * delta3 / (d32 * delta1),
                m1: d31 * d2 / (d32 * delta1),
                lambda_n: lam_a,
                amp_n: [amp_a, s3 * b, s3 * c],
                sn_first: false,
                order: [0, 1, 2],
                initial: Initial::Functions {
                    s: w2 / (s3 * b),
                    c: w1 / amp_a,
                    d: w3.abs() / c,
                },
                i_c: i3,
                i_o: i1,
                nu: i3 * d21 / (i1 * d32),
            }
        } else if d2 < 0.0 {
            // Circulation about axis 1: ω = (s A dn, s B sn, C cn), s = sign ω1.
            // Euler frame E = (axis 2, axis 3, axis 1).
            let b = (delta1 / (i2 * d21)).sqrt();
            let c = (delta1 / (i3 * d31)).sqrt();
            let s1 = w1.signum();
            Triaxial {
                separatrix: false,
                m: d32 * delta1 / (d21 * delta3),
                m1: d31 * (-d2) / (d21 * delta3),
                lambda_n: lam_c,
                amp_n: [s1 * b, c, s1 * amp_a],
                sn_first: true,
                order: [1, 2, 0],
                initial: Initial::Functions {
                    s: w2 / (s1 * b),
                    c: w3 / c,
                    d: w1.abs() / amp_a,
                },
                i_c: i1,
                i_o: i3,
                nu: i1 * d32 / (i3 * d21),
            }
        } else {
            // Separatrix: ω = (s1 A sech, s1 s3 B tanh, s3 C sech).
            let b = (delta3 / (i2 * d32)).sqrt();
            let c = (delta1 / (i3 * d31)).sqrt();
            let (s1, s3) = (w1.signum(), w3.signum());
            let sech = ((w1.abs() / amp_a) * (w3.abs() / c)).sqrt();
            let tanh = w2 / (s1 * s3 * b);
            Triaxial {
                separatrix: true,
                m: 1.0,
                m1: 0.0,
                lambda_n: lam_a,
                amp_n: [s1 * amp_a, s1 * s3 * b, s3 * c],
                sn_first: false,
                order: [0, 1, 2],
                initial: Initial::Phase((tanh / sech).asinh()),
                i_c: i3,
                i_o: i1,
                nu: i3 * d21 / (i1 * d32),
            }
        };
        let h_n = Vector3::new(i1 * w1, i2 * w2, i3 * w3).norm();
        sol.build_elliptic(tri, sc, h_n, &moments, q0);
        Ok(sol)
    }

    fn set_pure_spin(&mut self, axis: u8, m: f64, m1: f64, lambda: f64, omega0: &Vector3<f64>) {
        self.regime = Regime::PureSpin { axis };
        self.m = m;
        self.m1 = m1;
        self.lambda = lambda;
        if axis != 2 {
            self.period = TAU / lambda;
            self.delta_total = omega0.norm() * self.period;
            self.delta = self.delta_total.rem_euclid(TAU);
        }
    }

    fn build_symmetric(&mut self, eq12: bool, omega0: &Vector3<f64>, q0: &UnitQuaternion<f64>) {
        let [i1, i2, i3] = [self.moments.x, self.moments.y, self.moments.z];
        let (col, i_s, i_t, axis) = if eq12 {
            (2, i3, 0.5 * (i1 + i2), 3)
        } else {
            (0, i1, 0.5 * (i2 + i3), 1)
        };
        let a = Unit::new_normalize(self.axes.column(col).into_owned());
        let wa = a.dot(omega0);
        let omega_par = a.into_inner() * wa;
        let omega_perp = omega0 - omega_par;
        let rate_k = (i_s - i_t) * wa / i_t;
        let h_b = omega0 * i_t + a.into_inner() * ((i_s - i_t) * wa);
        let h = h_b.norm();
        let h_hat_n = Unit::new_normalize(q0 * h_b);
        self.regime = Regime::Symmetric { axis };
        self.lambda = rate_k.abs();
        if rate_k != 0.0 {
            self.period = TAU / rate_k.abs();
            self.delta_total = h / i_t * self.period;
            self.delta = self.delta_total.rem_euclid(TAU);
        }
        self.motion = Motion::Symmetric(SymmetricMotion {
            axis: a,
            omega_par,
            omega_perp,
            omega_cross: a.cross(&omega_perp),
            rate_k,
            precession_rate: h / i_t,
            h_hat_n,
            q0: *q0,
        });
    }

    fn build_elliptic(
        &mut self,
        tri: Triaxial,
        sc: f64,
        h_n: f64,
        moments: &[f64; 3],
        q0: &UnitQuaternion<f64>,
    ) {
        let m = tri.m.clamp(0.0, 1.0);
        let m1 = tri.m1.clamp(0.0, 1.0);
        // 1 − m can underflow to 0 only within ~1e-308 of the separatrix: treat as on it.
        let separatrix = tri.separatrix || m1 == 0.0;
        let jac = Jacobi::new(m, m1);
        let k = jac.quarter_period();
        let phase = match tri.initial {
            Initial::Functions { s, c, d } => inverse_sncndn(s, c, d, k),
            Initial::Phase(u) => u,
        };
        let lambda = sc * tri.lambda_n;
        let h = sc * h_n;
        let inertia_e = [
            moments[tri.order[0]],
            moments[tri.order[1]],
            moments[tri.order[2]],
        ];
        let amp = [sc * tri.amp_n[0], sc * tri.amp_n[1], sc * tri.amp_n[2]];
        // (H_E1, H_E2) = (a·f1, b·f2); (f1, f2) = (sin β, cos β) or (cos β, sin β).
        let a = inertia_e[0] * amp[0];
        let b = inertia_e[1] * amp[1];
        let (sin_coef, cos_coef) = if tri.sn_first {
            (a.abs(), b.abs())
        } else {
            (b.abs(), a.abs())
        };
        let nu = tri.nu;
        let p = &self.axes;
        let pe = Matrix3::from_columns(&[
            p.column(tri.order[0]),
            p.column(tri.order[1]),
            p.column(tri.order[2]),
        ]);
        let mut em = EllipticMotion {
            separatrix,
            jac,
            m,
            lambda,
            phase,
            amp,
            sn_first: tri.sn_first,
            inertia_e,
            spin_rate: h / tri.i_c,
            kappa: h_n / tri.lambda_n * ((tri.i_c - tri.i_o) / (tri.i_o * tri.i_c)),
            nu,
            big_nu: nu > 1.0,
            x_big: ((1.0 + nu) * (1.0 + m / nu)).sqrt(),
            pi_k: 0.0,
            pi_c: 0.0,
            sin_coef,
            cos_coef,
            sign_a: if a < 0.0 { -1.0 } else { 1.0 },
            sign_b: if b < 0.0 { -1.0 } else { 1.0 },
            pe,
            q_left: UnitQuaternion::identity(),
            q_right: UnitQuaternion::identity(),
        };
        if !separatrix {
            em.pi_k = em.pi_tilde_reduced(k, 1.0, 0.0, m1.sqrt());
        }
        em.pi_c = em.pi_tilde(phase);
        let q_pe = quat_of(&pe);
        let (_, q_e0) = em.euler_state(0.0);
        em.q_left = q0 * q_pe * q_e0.inverse();
        em.q_right = q_pe.inverse();

        self.m = m;
        self.m1 = m1;
        self.lambda = lambda;
        if separatrix {
            self.regime = Regime::Separatrix;
        } else {
            self.regime = Regime::Circulating {
                axis: if tri.sn_first { 1 } else { 3 },
            };
            self.period = 4.0 * k / lambda;
            let phi_t = em.spin_rate.mul_add(self.period, 4.0 * em.kappa * em.pi_k);
            self.delta_total = phi_t;
            self.delta = phi_t.rem_euclid(TAU);
        }
        self.motion = Motion::Elliptic(Box::new(em));
    }

    /// Body rates (rad/s, user body frame) and attitude (body → inertial) at time `t` (s);
    /// any finite t, negative or large (e.g. 1e6 s).
    pub fn state_at(&self, t: f64) -> (Vector3<f64>, UnitQuaternion<f64>) {
        match &self.motion {
            Motion::Steady { omega, q0 } => {
                let rate = omega.norm();
                if rate == 0.0 {
                    return (*omega, *q0);
                }
                let axis = Unit::new_unchecked(omega / rate);
                (*omega, q0 * axis_angle(&axis, rate * t))
            }
            Motion::Symmetric(sm) => {
                let (s, c) = (sm.rate_k * t).sin_cos();
                let omega = sm.omega_par + sm.omega_perp * c + sm.omega_cross * s;
                let q = axis_angle(&sm.h_hat_n, sm.precession_rate * t)
                    * sm.q0
                    * axis_angle(&sm.axis, -sm.rate_k * t);
                (omega, q)
            }
            Motion::Elliptic(em) => em.state(t),
        }
    }

    /// Body rates (rad/s, user body frame) at time `t` (s); cheaper than [`Self::state_at`].
    pub fn omega_at(&self, t: f64) -> Vector3<f64> {
        match &self.motion {
            Motion::Steady { omega, .. } => *omega,
            Motion::Symmetric(sm) => {
                let (s, c) = (sm.rate_k * t).sin_cos();
                sm.omega_par + sm.omega_perp * c + sm.omega_cross * s
            }
            Motion::Elliptic(em) => em.omega(t),
        }
    }

    /// Elliptic parameter m = k² (dimensionless): 0 for rest, spherical, symmetric bodies and
    /// pure spin about axes 1 and 3; 1 on the separatrix and for pure spin about axis 2.
    pub fn modulus(&self) -> f64 {
        self.m
    }

    /// Complementary parameter 1 − m (dimensionless), computed without cancellation.
    pub fn complementary_modulus(&self) -> f64 {
        self.m1
    }

    /// Time scale λ (1/s) of the elliptic solution, τ = λ t + c (Landau & Lifshitz §37). Symmetric
    /// body: |k| = |ω_s (I_s − I_t)/I_t|, the polhode rate; pure spin: the limit for vanishing
    /// nutation (axes 1, 3: small-oscillation frequency; axis 2: instability growth rate); rest and
    /// spherical: 0.
    pub fn lambda(&self) -> f64 {
        self.lambda
    }

    /// Polhode period 4K(m)/λ (s), the period of ω(t). Symmetric body: 2π/|k|; pure spin about
    /// axes 1 or 3: 2π/λ (limit of vanishing nutation). `f64::INFINITY` on the separatrix,
    /// for pure spin about axis 2, rest, spherical bodies and symmetric bodies with k = 0.
    pub fn polhode_period(&self) -> f64 {
        self.period
    }

    /// Net rotation angle (rad, in [0, 2π)) about the angular momentum Ĥ_N that the body has
    /// turned after one polhode period: q(t + T) = Rot(Ĥ_N, Δ) ⊗ q(t) as rotations. NaN when
    /// the period is infinite.
    pub fn precession_per_period(&self) -> f64 {
        self.delta
    }

    /// The precession angle (rad) of one polhode period before its reduction to [0, 2π): the
    /// Euler angle φ about Ĥ_N gained over the period (3-1-3 about the circulation axis;
    /// the symmetry axis for a symmetric body). Over the period it is the mean precession rate
    /// times the period. NaN when the period is infinite.
    pub fn precession_angle_per_period(&self) -> f64 {
        self.delta_total
    }

    /// Motion regime (see [`Regime`]).
    pub fn regime(&self) -> Regime {
        self.regime
    }

    /// Principal moments I1 ≤ I2 ≤ I3 (kg m²).
    pub fn principal_moments(&self) -> Vector3<f64> {
        self.moments
    }

    /// Principal axes as columns (user body frame, right-handed), in the order of
    /// [`Self::principal_moments`]; axes 1 and 2 point into the positive half of the body axis
    /// they are closest to, axis 3 = axis 1 × axis 2. Dimensionless.
    pub fn principal_axes(&self) -> Matrix3<f64> {
        self.axes
    }

    /// Angular momentum in the inertial frame, H_N = R(q0) J ω0 (N m s); constant.
    pub fn angular_momentum_inertial(&self) -> Vector3<f64> {
        self.h_inertial
    }

    /// Rotational kinetic energy ½ ω0ᵀ J ω0 (J); constant.
    pub fn kinetic_energy(&self) -> f64 {
        self.energy
    }
}
