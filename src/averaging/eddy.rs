//! Eddy-current damping averaged over the torque-free motion and the orbit
//! (docs/averaging.md, "Eddy currents").
//!
//! The torque τ = (M (ω × B)) × B = \[B\]× M \[B\]× ω is linear in ω and quadratic in B. When the
//! body turns many times per orbit and the orbit-driven field is independent of the fast
//! phases (no resonance), the mean over both is the mean over the body's motion of a torque
//! in which B Bᵀ is replaced by its orbit average S = ⟨B Bᵀ⟩ (inertial axes):
//!
//! ```text
//! ⟨[B]× M [B]×⟩ = G(S, M) = tr S · M + tr M · S − S M − M S − (tr S tr M − tr(S M)) 1
//! ```
//!
//! for symmetric S and M. S is the field's second moment averaged over a window of one orbit
//! convolved with one sidereal day ([`FieldMoments`]), sampled every two days and
//! interpolated.

pub use super::field_moments::FieldMoments;
use crate::model::{Forcing, Secular, SecularMotion, SecularRates};
use nalgebra::{Matrix3, Vector3};

/// Relative tolerance within which the body is taken as axisymmetric and M as axisymmetric
/// about its symmetry axis, or isotropic.
const SHAPE_TOLERANCE: f64 = 1e-9;

/// Points over the precession angle in the cone average: the averaged quantities are
/// trigonometric polynomials of degree at most 4 in it, which 8 equally spaced points
/// integrate exactly.
const CONE_POINTS: usize = 8;

/// G(S, M) = ⟨\[B\]× M \[B\]×⟩ for ⟨B Bᵀ⟩ = S, both symmetric.
pub fn field_tensor(s: &Matrix3<f64>, m: &Matrix3<f64>) -> Matrix3<f64> {
    let (ts, tm) = (s.trace(), m.trace());
    let sm = s * m;
    m * ts + s * tm - sm - sm.transpose() - Matrix3::identity() * (ts * tm - sm.trace())
}

/// How the torque is averaged over the body's motion.
#[derive(Debug, Clone, Copy)]
enum Shape {
    /// Not prepared yet.
    Unprepared,
    /// M = μ 1 on any non-spherical body: closed form from ⟨ω ωᵀ⟩.
    Isotropic(f64),
    /// An axisymmetric body with M axisymmetric about the same axis (or isotropic): the
    /// regular precession's cone, in closed form by quadrature over the precession angle.
    Coaxial {
        /// Moment about the symmetry axis and across it (kg m²).
        i_s: f64,
        i_t: f64,
        /// M across the axis and its excess along it (S m⁴).
        m_t: f64,
        m_excess: f64,
    },
}

/// Eddy currents as the averaged method sees them.
#[derive(Debug)]
pub struct AveragedEddy {
    /// The magnetic tensor M (S m⁴, body axes).
    pub tensor: Matrix3<f64>,
    /// The field's orbit-averaged second moment.
    pub field: FieldMoments,
    shape: Shape,
}

impl AveragedEddy {
    /// Eddy currents of tensor `tensor` in the field `field`.
    pub fn new(tensor: Matrix3<f64>, field: FieldMoments) -> AveragedEddy {
        AveragedEddy {
            tensor,
            field,
            shape: Shape::Unprepared,
        }
    }
}

impl Secular for AveragedEddy {
    fn prepare(&mut self, inertia: &Matrix3<f64>) -> Result<(), String> {
        let m = self.tensor;
        let scale = m.amax();
        let mu = m.trace() / 3.0;
        if (m - Matrix3::identity() * mu).amax() <= SHAPE_TOLERANCE * scale {
            self.shape = Shape::Isotropic(mu);
            return Ok(());
        }
        let body = crate::model::RigidBody::new(*inertia).map_err(|e| e.to_string())?;
        let [i1, i2, i3] = [
            body.principal_moments.x,
            body.principal_moments.y,
            body.principal_moments.z,
        ];
        let tol = SHAPE_TOLERANCE * i3;
        let (axis, i_s, i_t) = if i3 - i2 <= tol && i2 - i1 > tol {
            (0, i1, 0.5 * (i2 + i3))
        } else if i2 - i1 <= tol && i3 - i2 > tol {
            (2, i3, 0.5 * (i1 + i2))
        } else {
            return Err(format!(
                "its magnetic tensor is not isotropic and the body is not axisymmetric \
                 (principal moments {i1:.6e}, {i2:.6e}, {i3:.6e} kg m²): the mean torque \
                 then depends on the joint average of the attitude and the rates over the \
                 polhode, which is not implemented (an isotropic tensor, such as a spherical \
                 shell's, or an axisymmetric body with the tensor's axis on its symmetry axis \
                 can be averaged)"
            ));
        };
        let a = body.principal_axes.column(axis).into_owned();
        let m_a = (a.transpose() * m * a)[0];
        let m_t = 0.5 * (m.trace() - m_a);
        let aa = a * a.transpose();
        let coaxial = Matrix3::identity() * m_t + aa * (m_a - m_t);
        if (m - coaxial).amax() > SHAPE_TOLERANCE * scale {
            return Err(
                "its magnetic tensor is not axisymmetric about the body's symmetry axis: the \
                 mean torque then depends on the body's spin about that axis, which is not \
                 implemented (give the cylinder the body's symmetry axis)"
                    .into(),
            );
        }
        self.shape = Shape::Coaxial {
            i_s,
            i_t,
            m_t,
            m_excess: m_a - m_t,
        };
        Ok(())
    }

    fn forcing(&self) -> Option<Forcing> {
        // A uniform field still turns H, so the direction is carried for it too.
        Some(self.field.forcing().unwrap_or(Forcing {
            period: 0.0,
            window: 0.0,
        }))
    }

    fn phase_free(&self) -> bool {
        // Isotropic M needs ⟨|ω|²⟩ only, constant on an axisymmetric body; a coaxial M sees
        // the symmetry axis and ω, which move with the precession alone.
        !matches!(self.shape, Shape::Unprepared)
    }

    fn rates(&self, motion: &SecularMotion) -> SecularRates {
        let h = motion.h;
        if h == 0.0 {
            return SecularRates::default();
        }
        let s = self.field.at(motion.t);
        let hh = motion.h_hat;
        let along = 2.0 * motion.energy / h;
        let (energy_rate, torque) = match self.shape {
            Shape::Unprepared => (f64::NAN, Vector3::repeat(f64::NAN)),
            Shape::Isotropic(mu) => {
                // Inertial ⟨ω ωᵀ⟩ = a Ĥ Ĥᵀ + b (1 − Ĥ Ĥᵀ): ω·Ĥ = 2T/|H| is constant, and the
                // part across H turns with the precession.
                let a = along * along;
                let b = 0.5 * (motion.omega_omega.trace() - a).max(0.0);
                let (ts, sh) = (s.trace(), (hh.transpose() * s * hh)[0]);
                let power = mu * (a * (ts - sh) + b * (ts + sh));
                // ⟨τ⟩ = μ G(S, 1) ⟨ω⟩ = −μ (tr S − S) Ĥ 2T/|H|.
                (-power, (s * hh - hh * ts) * (mu * along))
            }
            Shape::Coaxial {
                i_s,
                i_t,
                m_t,
                m_excess,
            } => {
                // Regular precession: the symmetry axis ẑ on a cone of half-angle θ about Ĥ,
                // ω = Ĥ |H|/I_t + ẑ ω_s (I_t − I_s)/I_t with ω_s = |H| cos θ / I_s.
                let x = 2.0 * motion.energy / (h * h);
                let c2 = ((x - 1.0 / i_t) / (1.0 / i_s - 1.0 / i_t)).clamp(0.0, 1.0);
                let (c, sn) = (c2.sqrt(), (1.0 - c2).sqrt());
                let spin = h * c / i_s * (i_t - i_s) / i_t;
                let e1 = crate::averaging::stepper::perpendicular(&hh);
                let e2 = hh.cross(&e1);
                let g_t = field_tensor(&s, &Matrix3::identity()) * m_t;
                let (mut power, mut torque) = (0.0, Vector3::zeros());
                for k in 0..CONE_POINTS {
                    let phi = std::f64::consts::TAU * k as f64 / CONE_POINTS as f64;
                    let (sp, cp) = phi.sin_cos();
                    let z = hh * c + (e1 * cp + e2 * sp) * sn;
                    let omega = hh * (h / i_t) + z * spin;
                    let g = g_t + field_tensor(&s, &(z * z.transpose())) * m_excess;
                    let tau = g * omega;
                    power += tau.dot(&omega);
                    torque += tau;
                }
                let n = CONE_POINTS as f64;
                (power / n, torque / n)
            }
        };
        let h_rate = torque.dot(&hh);
        SecularRates {
            energy_rate,
            h_rate,
            dissipation_rate: energy_rate,
            torque_across: torque - hh * h_rate,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// G(S, M) against the direct sum Σ λ_k [e_k]× M [e_k]× over S's eigenvectors.
    #[test]
    fn the_field_tensor_is_the_mean_of_the_cross_products() {
        let m = Matrix3::new(2.0, 0.3, 0.1, 0.3, 1.0, -0.2, 0.1, -0.2, 0.5);
        let s = Matrix3::new(1.5, -0.4, 0.2, -0.4, 0.9, 0.3, 0.2, 0.3, 0.7);
        let eig = s.symmetric_eigen();
        let mut direct = Matrix3::zeros();
        for k in 0..3 {
            let e = eig.eigenvectors.column(k).into_owned();
            direct += e.cross_matrix() * m * e.cross_matrix() * eig.eigenvalues[k];
        }
        assert!((field_tensor(&s, &m) - direct).amax() < 1e-14);
    }
}
