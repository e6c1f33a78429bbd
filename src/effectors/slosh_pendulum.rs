//! `slosh_pendulum`: a point mass on a massless rod from a fixed pivot, free to swing in two
//! angles (a spherical pendulum), with a dashpot on the mass's motion relative to the body.
//! It is the pendulum analog of a tank's first lateral slosh mode (docs/effectors.md).
//!
//! With the pendulum frame p̂₁ (the rest direction), p̂₂, p̂₃ fixed in the body, the mass sits at
//!
//! ```text
//! r = d + l ê,   ê(φ, θ) = cos φ cos θ p̂₁ + sin φ cos θ p̂₂ − sin θ p̂₃,
//! ```
//!
//! the angle convention of Allard, Schaub & Piggott (2016) and of Basilisk's
//! `sphericalPendulum`. The dashpot's force on the mass is −c ṙ' (ṙ' its velocity relative to
//! the body), so its generalised forces are Q = −c Jᵀ J u = −c l² (cos² θ φ̇, θ̇). Nothing else
//! restores the pendulum: in free flight the restoring field is the centrifugal one of the
//! spin, which the equations of motion carry.
//!
//! The angles are singular where the rod lies along ±p̂₃ (θ = ±90°): φ is then undefined and
//! the coordinate mass m l² cos² θ vanishes. The run stops there with a diagnosis.

use super::particles::{ParticleModel, ParticlePoint};
use crate::model::{Drawing, Validity};
use crate::sincos::sin_cos;
use nalgebra::Vector3;

/// A damped spherical pendulum.
#[derive(Debug, Clone)]
pub struct SloshPendulum {
    /// Mass of the pendulum's bob (kg).
    pub mass: f64,
    /// Rod length l, pivot to mass (m).
    pub length: f64,
    /// Pivot point d (m, body axes, about the hub's centre of mass).
    pub pivot: Vector3<f64>,
    /// The pendulum frame [p̂₁, p̂₂, p̂₃] (body axes, orthonormal, right-handed); p̂₁ is the rest
    /// direction.
    pub frame: [Vector3<f64>; 3],
    /// Dashpot coefficient c on the mass's velocity relative to the body (N s/m).
    pub damping: f64,
}

/// |cos θ| below which the pendulum is at its coordinate singularity: θ within 2.9° of ±90°,
/// where the rod lies along ±p̂₃ and φ is undefined.
pub const SINGULAR_COS_THETA: f64 = 0.05;
/// |θ| (degrees, folded into [0°, 90°]) past which the pendulum warns that it nears the
/// singularity: the φ inertia m l² cos² θ has fallen to cos² 75° = 7 % of its value at rest.
pub const THETA_WARN_DEG: f64 = 75.0;

/// θ folded into [0, π/2] (rad): its distance to the nearest multiple of π.
fn folded(theta: f64) -> f64 {
    let a = theta.abs();
    if a <= std::f64::consts::FRAC_PI_2 {
        return a;
    }
    let m = a % std::f64::consts::PI;
    m.min(std::f64::consts::PI - m)
}

/// The pendulum frame of a rest direction `p1` (unit, body axes): p̂₃ = p̂₁ × ê_k / |…|, with ê_k
/// the body axis least aligned with p̂₁ (the first on ties), and p̂₂ = p̂₃ × p̂₁. A rest direction
/// along body x gives the body axes themselves.
pub fn pendulum_frame(p1: Vector3<f64>) -> [Vector3<f64>; 3] {
    let mut k = 0;
    for i in 1..3 {
        if p1[i].abs() < p1[k].abs() {
            k = i;
        }
    }
    let mut axis = Vector3::zeros();
    axis[k] = 1.0;
    let p3 = p1.cross(&axis).normalize();
    let p2 = p3.cross(&p1);
    [p1, p2, p3]
}

impl SloshPendulum {
    /// The rod's direction ê, the unit vectors â = ∂ê/∂φ / cos θ and ∂ê/∂θ, and the
    /// convective Σ ∂²ê/∂q_j∂q_k u_j u_k at angles (φ, θ) and rates (φ̇, θ̇).
    fn directions(&self, q: &[f64], u: &[f64]) -> [Vector3<f64>; 4] {
        let [p1, p2, p3] = self.frame;
        let (sp, cp) = sin_cos(q[0]);
        let (st, ct) = sin_cos(q[1]);
        let c = cp * p1 + sp * p2;
        let a = -sp * p1 + cp * p2;
        let e = ct * c - st * p3;
        let e_theta = -st * c - ct * p3;
        let (dp, dt) = (u[0], u[1]);
        // ∂²ê/∂φ² = −cos θ c, ∂²ê/∂φ∂θ = −sin θ â, ∂²ê/∂θ² = −ê.
        let kappa = -(ct * dp * dp) * c - (2.0 * st * dp * dt) * a - (dt * dt) * e;
        [e, ct * a, e_theta, kappa]
    }

    /// The bob's position (m, body axes) at angles `q`.
    pub fn bob(&self, q: &[f64]) -> Vector3<f64> {
        let [e, ..] = self.directions(q, &[0.0, 0.0]);
        self.pivot + self.length * e
    }

    /// The angle between the rod and its rest direction (rad) at angles `q`.
    pub fn swing(&self, q: &[f64]) -> f64 {
        let (_, cp) = sin_cos(q[0]);
        let (_, ct) = sin_cos(q[1]);
        (cp * ct).clamp(-1.0, 1.0).acos()
    }
}

impl ParticleModel for SloshPendulum {
    type Cache = [Vector3<f64>; 4];
    fn prepare(&self, q: &[f64], u: &[f64]) -> Self::Cache {
        self.directions(q, u)
    }
    fn kind(&self) -> &'static str {
        "slosh_pendulum"
    }
    fn undamped(&self) -> Self {
        SloshPendulum {
            damping: 0.0,
            ..self.clone()
        }
    }
    fn num_coordinates(&self) -> usize {
        2
    }
    fn coordinate_names(&self) -> Vec<String> {
        vec!["phi".into(), "theta".into()]
    }
    fn num_particles(&self) -> usize {
        1
    }
    fn particle(
        &self,
        _p: usize,
        cache: &Self::Cache,
        _q: &[f64],
        _u: &[f64],
        out: &mut ParticlePoint,
    ) {
        let [e, e_phi, e_theta, kappa] = *cache;
        let l = self.length;
        out.mass = self.mass;
        out.position = self.pivot + l * e;
        out.jacobian[0] = l * e_phi;
        out.jacobian[1] = l * e_theta;
        out.convective = l * kappa;
    }
    fn forces(&self, q: &[f64], u: &[f64], out: &mut [f64]) {
        // J's columns are orthogonal, of lengths l cos θ and l.
        let (_, ct) = sin_cos(q[1]);
        let cl2 = self.damping * self.length * self.length;
        out[0] = -cl2 * ct * ct * u[0];
        out[1] = -cl2 * u[1];
    }
    fn elastic_energy(&self, _q: &[f64]) -> f64 {
        0.0
    }
    fn dissipation_power(&self, q: &[f64], u: &[f64]) -> f64 {
        let (_, ct) = sin_cos(q[1]);
        let l2 = self.length * self.length;
        self.damping * l2 * (ct * ct * u[0] * u[0] + u[1] * u[1])
    }
    fn extra_telemetry_names(&self) -> Vec<String> {
        vec!["swing_deg".into()]
    }
    fn extra_telemetry(&self, q: &[f64]) -> Vec<f64> {
        vec![self.swing(q).to_degrees()]
    }
    fn validity(&self, q: &[f64]) -> Option<Validity> {
        Some(Validity {
            value: folded(q[1]).to_degrees(),
            warn: THETA_WARN_DEG,
            limit: SINGULAR_COS_THETA.acos().to_degrees(),
        })
    }
    fn validity_report(&self, q: &[f64]) -> (String, String) {
        (
            format!(
                "its rod has swung to θ = {:.2}°: at ±90° it lies along p̂₃, where the angles \
                 (φ, θ) are singular and φ has no inertia (warning past {THETA_WARN_DEG}°, limit \
                 {:.2}°); a slosh analog is far outside its small-amplitude range well before",
                q[1].to_degrees(),
                SINGULAR_COS_THETA.acos().to_degrees()
            ),
            "a smaller disturbance or more damping; for large liquid motion a pendulum analog \
             does not hold"
                .into(),
        )
    }
    fn drawings(&self, q: &[f64]) -> Vec<Drawing> {
        let bob = self.bob(q);
        let size = (self.mass.cbrt() * 0.05).clamp(0.02, 0.3);
        vec![
            Drawing::Line {
                points: vec![self.pivot, bob],
                thickness: 0.1 * size,
            },
            Drawing::Sphere {
                center: bob,
                diameter: size,
            },
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pendulum(p1: Vector3<f64>) -> SloshPendulum {
        SloshPendulum {
            mass: 3.0,
            length: 0.4,
            pivot: Vector3::new(0.2, -0.1, 0.5),
            frame: pendulum_frame(p1.normalize()),
            damping: 1.5,
        }
    }

    #[test]
    fn the_frame_is_orthonormal_and_right_handed_and_body_x_gives_the_body_axes() {
        for p1 in [
            Vector3::x(),
            Vector3::y(),
            Vector3::z(),
            Vector3::new(1.0, 2.0, -3.0).normalize(),
            Vector3::new(-0.3, 0.3, 0.9).normalize(),
        ] {
            let [a, b, c] = pendulum_frame(p1);
            assert_eq!(a, p1);
            for (u, v) in [(a, b), (b, c), (a, c)] {
                assert!(u.dot(&v).abs() < 1e-15);
            }
            for u in [a, b, c] {
                assert!((u.norm() - 1.0).abs() < 1e-15);
            }
            assert!((a.cross(&b) - c).norm() < 1e-15);
        }
        assert_eq!(
            pendulum_frame(Vector3::x()),
            [Vector3::x(), Vector3::y(), Vector3::z()]
        );
    }

    /// The Jacobian and the convective term against central differences of the position.
    #[test]
    fn jacobian_and_convective_term_match_finite_differences() {
        let p = pendulum(Vector3::new(1.0, 2.0, -3.0));
        let q = [0.3, -0.4];
        let u = [0.7, -1.1];
        let mut point = ParticlePoint::default();
        p.particle(0, &p.prepare(&q, &u), &q, &u, &mut point);
        let h = 1e-5;
        let r = |q: [f64; 2]| p.bob(&q);
        for k in 0..2 {
            let mut plus = q;
            let mut minus = q;
            plus[k] += h;
            minus[k] -= h;
            let numeric = (r(plus) - r(minus)) / (2.0 * h);
            assert!((numeric - point.jacobian[k]).norm() < 1e-9, "column {k}");
        }
        // d²r/dt² along q(t) = q + u t at t = 0 is the convective term.
        let along = |t: f64| r([q[0] + u[0] * t, q[1] + u[1] * t]);
        let numeric = (along(h) - 2.0 * along(0.0) + along(-h)) / (h * h);
        assert!((numeric - point.convective).norm() < 1e-4);
        // The rod keeps its length, and the mass sits where the angles say.
        assert!(((point.position - p.pivot).norm() - p.length).abs() < 1e-15);
    }

    /// The dashpot's generalised forces are those of the force −c ṙ' on the mass, and its
    /// power is c |ṙ'|².
    #[test]
    fn dashpot_forces_are_those_of_the_relative_velocity() {
        let p = pendulum(Vector3::new(0.0, 1.0, 1.0));
        let q = [-0.8, 0.6];
        let u = [0.4, 0.9];
        let mut point = ParticlePoint::default();
        p.particle(0, &p.prepare(&q, &u), &q, &u, &mut point);
        let v = point.jacobian[0] * u[0] + point.jacobian[1] * u[1];
        let mut forces = [0.0; 2];
        p.forces(&q, &u, &mut forces);
        for (force, column) in forces.iter().zip(&point.jacobian) {
            let expected = -p.damping * column.dot(&v);
            assert!((force - expected).abs() < 1e-14);
        }
        let power = p.dissipation_power(&q, &u);
        assert!((power - p.damping * v.norm_squared()).abs() < 1e-14);
    }

    #[test]
    fn validity_folds_theta_onto_the_distance_from_the_singularity() {
        let p = pendulum(Vector3::x());
        assert!((p.validity(&[0.0, 0.2]).unwrap().value - 0.2f64.to_degrees()).abs() < 1e-12);
        let v = p.validity(&[0.0, std::f64::consts::PI - 0.1]).unwrap();
        assert!((v.value - 0.1f64.to_degrees()).abs() < 1e-9);
        let v = p.validity(&[0.0, 1.55]).unwrap();
        assert!(v.past_limit());
    }
}
