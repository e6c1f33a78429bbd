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

use super::hinged_rod::folded_angle;
use super::particles::{ParticleModel, ParticlePoint, ParticleSums, add_mass_and_first_moment};
use crate::model::{Drawing, HubCoupling, Momentum, Validity, spd_inverse3};
use crate::sincos::sin_cos;
use nalgebra::{Matrix3, Vector3};

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
    /// The tank's non-sloshing liquid (kg), a point mass fixed in the body at
    /// `fixed_position`; zero for a bare pendulum.
    pub fixed_mass: f64,
    /// Where the non-sloshing liquid sits (m, body axes, about the hub's centre of mass).
    pub fixed_position: Vector3<f64>,
    /// The swing (rad) past which a tank's analog leaves its small-amplitude range (warned);
    /// `None` for a bare pendulum, whose only range is its angles'.
    pub amplitude_warning: Option<f64>,
}

/// |cos θ| below which the pendulum is at its coordinate singularity: θ within 2.9° of ±90°,
/// where the rod lies along ±p̂₃ and φ is undefined.
pub const SINGULAR_COS_THETA: f64 = 0.05;
/// |θ| (degrees, folded into [0°, 90°]) past which the pendulum warns that it nears the
/// singularity: the φ inertia m l² cos² θ has fallen to cos² 75° = 7 % of its value at rest.
pub const THETA_WARN_DEG: f64 = 75.0;

/// A tank analog's non-sloshing liquid `mass` (kg) at `position` (m, body axes), drawn as a
/// sphere growing with the cube root of the mass; nothing without one.
pub(crate) fn fixed_liquid_drawing(mass: f64, position: Vector3<f64>) -> Option<Drawing> {
    (mass > 0.0).then(|| Drawing::Sphere {
        center: position,
        diameter: (mass.cbrt() * 0.05).clamp(0.02, 0.3),
    })
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

/// The pendulum frame of a rest direction `p1` and a pole `p3` (unit, perpendicular, body
/// axes): [p̂₁, p̂₃ × p̂₁, p̂₃]. The angles are singular where the rod lies along ±p̂₃.
pub fn pendulum_frame_with_pole(p1: Vector3<f64>, p3: Vector3<f64>) -> [Vector3<f64>; 3] {
    [p1, p3.cross(&p1), p3]
}

impl SloshPendulum {
    /// The rod's direction ê, the unit vectors â = ∂ê/∂φ / cos θ and ∂ê/∂θ, and the
    /// convective Σ ∂²ê/∂q_j∂q_k u_j u_k at angles (φ, θ) and rates (φ̇, θ̇).
    pub(crate) fn directions(&self, q: &[f64], u: &[f64]) -> [Vector3<f64>; 4] {
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

/// The bob's kinematics at one state, for the closed forms.
struct Terms {
    /// Rod direction ê.
    e: Vector3<f64>,
    /// Jacobian columns j_φ = l cos θ â and j_θ = l ∂ê/∂θ (m/rad).
    columns: [Vector3<f64>; 2],
    /// |j_φ|² and |j_θ|² (m²/rad²).
    lengths: [f64; 2],
    /// Bob position r = d + l ê (m, body axes).
    r: Vector3<f64>,
    /// Its acceleration at ω̇ = 0 and u̇ = 0 relative to the hub's centre:
    /// c = ω × (ω × r) + 2 ω × J u + l κ (m/s²).
    free: Vector3<f64>,
    /// The dashpot's force on the bob, −c J u (N).
    dashpot: Vector3<f64>,
}

impl SloshPendulum {
    /// [`Terms`] at angles `q`, rates `u` and hub rate `omega`; `None` at the angles'
    /// singularity (cos θ = 0), where the general path stops the run.
    #[inline(always)]
    fn terms(&self, q: &[f64], u: &[f64], omega: &Vector3<f64>) -> Option<Terms> {
        let [e, e_phi, e_theta, kappa] = self.directions(q, u);
        let l = self.length;
        let columns = [l * e_phi, l * e_theta];
        let lengths = [columns[0].norm_squared(), l * l];
        if lengths[0].is_nan() || lengths[0] <= 0.0 {
            return None;
        }
        let r = self.pivot + l * e;
        let velocity = columns[0] * u[0] + columns[1] * u[1];
        let free = omega.cross(&omega.cross(&r)) + 2.0 * omega.cross(&velocity) + l * kappa;
        Some(Terms {
            e,
            columns,
            lengths,
            r,
            free,
            dashpot: -self.damping * velocity,
        })
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
        if self.fixed_mass > 0.0 { 2 } else { 1 }
    }
    fn particle(
        &self,
        p: usize,
        cache: &Self::Cache,
        _q: &[f64],
        _u: &[f64],
        out: &mut ParticlePoint,
    ) {
        if p == 1 {
            // The non-sloshing liquid: fixed in the body.
            out.mass = self.fixed_mass;
            out.position = self.fixed_position;
            out.jacobian[0] = Vector3::zeros();
            out.jacobian[1] = Vector3::zeros();
            out.convective = Vector3::zeros();
            return;
        }
        let [e, e_phi, e_theta, kappa] = *cache;
        let l = self.length;
        out.mass = self.mass;
        out.position = self.pivot + l * e;
        out.jacobian[0] = l * e_phi;
        out.jacobian[1] = l * e_theta;
        out.convective = l * kappa;
    }
    /// One particle with orthogonal Jacobian columns: the sums written out.
    fn summed<const N: usize>(
        &self,
        q: &[f64],
        u: &[f64],
        omega: &Vector3<f64>,
        out: &mut ParticleSums<N>,
    ) -> bool {
        let Some(t) = self.terms(q, u, omega) else {
            return false;
        };
        let m = self.mass;
        for k in 0..2 {
            let mj = m * t.columns[k];
            let moment = t.r.cross(&mj);
            out.mass[k][k] = m * t.lengths[k];
            out.coupling[k] = [mj.x, mj.y, mj.z, moment.x, moment.y, moment.z];
            out.inertial[k] = -mj.dot(&t.free);
        }
        let (r, m0, r0) = (t.r, self.fixed_mass, self.fixed_position);
        let point =
            |r: &Vector3<f64>| Matrix3::from_diagonal_element(r.norm_squared()) - r * r.transpose();
        let force0 = m0 * omega.cross(&omega.cross(&r0));
        out.total_mass = m + m0;
        out.first_moment = m * r + m0 * r0;
        out.inertia = m * point(&r) + m0 * point(&r0);
        let force = m * t.free;
        out.force = force + force0;
        out.moment = r.cross(&force) + r0.cross(&force0);
        true
    }
    /// The rod transmits force to the bob only along ê, and the angles move it freely ⊥ ê
    /// (the Jacobian columns span that plane), so with Φ z = a_B + ω̇ × r the elimination is
    ///
    /// ```text
    /// D − C M⁻¹ Cᵀ = m v vᵀ,  v = [ê; r × ê],   e + C M⁻¹ g = [f; r × f],  f = m ê (ê·c) + F,
    /// ```
    ///
    /// with F the dashpot's force (⊥ ê): a point mass constrained along the rod only.
    fn couple_closed_form(
        &self,
        q: &[f64],
        u: &[f64],
        omega: &Vector3<f64>,
        coupling: &mut HubCoupling,
        kept: &mut [f64],
    ) -> bool {
        let Some(t) = self.terms(q, u, omega) else {
            return false;
        };
        let m = self.mass;
        let pull = (m * t.e.dot(&t.free)) * t.e + t.dashpot;
        let moment = t.r.cross(&pull);
        for i in 0..3 {
            coupling.force[i] -= pull[i];
            coupling.force[3 + i] -= moment[i];
        }
        let hub = &mut coupling.mass;
        if self.fixed_mass > 0.0 {
            // The non-sloshing liquid moves with the hub: its D and e as a point mass.
            let (m0, r0) = (self.fixed_mass, self.fixed_position);
            add_mass_and_first_moment(hub, m0, &(m0 * r0));
            let r2 = r0.norm_squared();
            for i in 0..3 {
                for j in 0..=i {
                    let diagonal = if i == j { r2 } else { 0.0 };
                    hub[(3 + i, 3 + j)] += m0 * (diagonal - r0[i] * r0[j]);
                }
            }
            let force0 = m0 * omega.cross(&omega.cross(&r0));
            let moment0 = r0.cross(&force0);
            for i in 0..3 {
                coupling.force[i] -= force0[i];
                coupling.force[3 + i] -= moment0[i];
            }
        }
        let re = t.r.cross(&t.e);
        let v = [t.e.x, t.e.y, t.e.z, re.x, re.y, re.z];
        for i in 0..6 {
            let m_vi = m * v[i];
            for j in 0..=i {
                hub[(i, j)] += m_vi * v[j];
            }
        }
        // W_k = [g_k, Cᵀ_k] / M_kk with M_kk = m |j_k|², g_k = j_k·F − m j_k·c and
        // Cᵀ_k = m [j_k; r × j_k]; L = 1.
        for k in 0..2 {
            let (j, inv) = (t.columns[k], 1.0 / t.lengths[k]);
            let rj = t.r.cross(&j);
            let row = &mut kept[7 * k..7 * k + 7];
            row[0] = (j.dot(&t.dashpot) / m - j.dot(&t.free)) * inv;
            for a in 0..3 {
                row[1 + a] = j[a] * inv;
                row[4 + a] = rj[a] * inv;
            }
        }
        kept[14..17].copy_from_slice(&[1.0, 0.0, 1.0]);
        true
    }
    const HAS_RHS_ALONE: bool = true;
    /// The pendulum alone on the hub: with the system's centre of mass fixed, the bob moves as
    /// one of reduced mass m* = m M/(M + m) about a fixed hub centre (as the spring–mass
    /// damper's two-body reduction), and the elimination above leaves a rank-one update of
    /// the hub's inertia (t = r × ê):
    ///
    /// ```text
    /// (I + m* t tᵀ) ω̇ = −ω × Iω − r × (m* ê (ê·c) + F),
    /// q̈_k = (j_k·F/m* − j_k·(ω̇ × r + c)) / |j_k|².
    /// ```
    fn rhs_alone_closed_form(
        &self,
        q: &[f64],
        u: &[f64],
        omega: &Vector3<f64>,
        hub_inertia: &Matrix3<f64>,
        hub_mass: f64,
        omega_dot: &mut Vector3<f64>,
        u_dot: &mut [f64],
    ) -> bool {
        // With the tank's fixed liquid, three masses share the centre of mass: the general
        // path then.
        if self.fixed_mass > 0.0 {
            return false;
        }
        let Some(t) = self.terms(q, u, omega) else {
            return false;
        };
        let m_star = self.mass * hub_mass / (hub_mass + self.mass);
        let pull = (m_star * t.e.dot(&t.free)) * t.e + t.dashpot;
        let force = -omega.cross(&(hub_inertia * omega)) - t.r.cross(&pull);
        let arm = t.r.cross(&t.e);
        let i = hub_inertia;
        let diagonal = i[(1, 0)] == 0.0 && i[(2, 0)] == 0.0 && i[(2, 1)] == 0.0;
        let w = if diagonal && i[(0, 0)] > 0.0 && i[(1, 1)] > 0.0 && i[(2, 2)] > 0.0 {
            // Principal body axes: Sherman–Morrison on the diagonal,
            // (I + m* t tᵀ)⁻¹ b = I⁻¹ b − m* I⁻¹t (tᵀ I⁻¹ b) / (1 + m* tᵀ I⁻¹ t).
            let inv = Vector3::new(1.0 / i[(0, 0)], 1.0 / i[(1, 1)], 1.0 / i[(2, 2)]);
            let ib = inv.component_mul(&force);
            let it = inv.component_mul(&arm);
            ib - (m_star * arm.dot(&ib) / (1.0 + m_star * arm.dot(&it))) * it
        } else {
            let entry = |r: usize, c: usize| i[(r, c)] + m_star * arm[r] * arm[c];
            let Some(inverse) = spd_inverse3(
                entry(0, 0),
                entry(1, 0),
                entry(2, 0),
                entry(1, 1),
                entry(2, 1),
                entry(2, 2),
            ) else {
                return false;
            };
            inverse * force
        };
        let a = w.cross(&t.r) + t.free;
        for ((out, j), length) in u_dot.iter_mut().zip(&t.columns).zip(&t.lengths) {
            *out = (j.dot(&t.dashpot) / m_star - j.dot(&a)) / length;
        }
        *omega_dot = w;
        true
    }
    fn momentum_closed_form(&self, q: &[f64], u: &[f64], omega: &Vector3<f64>) -> Option<Momentum> {
        let [e, e_phi, e_theta, _] = self.directions(q, u);
        let (m, l) = (self.mass, self.length);
        let r = self.pivot + l * e;
        let v = omega.cross(&r) + l * (u[0] * e_phi + u[1] * e_theta);
        let (m0, r0) = (self.fixed_mass, self.fixed_position);
        let v0 = omega.cross(&r0);
        Some(Momentum {
            mass: m + m0,
            first_moment: m * r + m0 * r0,
            linear: m * v + m0 * v0,
            angular: m * r.cross(&v) + m0 * r0.cross(&v0),
            kinetic_energy: 0.5 * (m * v.norm_squared() + m0 * v0.norm_squared()),
        })
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
        let limit = SINGULAR_COS_THETA.acos().to_degrees();
        Some(match self.amplitude_warning {
            // The swing bounds |θ| (the rod is at least |θ| from p̂₁), so its limit keeps the
            // angles clear of their singularity too.
            Some(amplitude) => Validity {
                value: self.swing(q).to_degrees(),
                warn: amplitude.to_degrees(),
                limit,
            },
            None => Validity {
                value: folded_angle(q[1]).to_degrees(),
                warn: THETA_WARN_DEG,
                limit,
            },
        })
    }
    fn validity_report(&self, q: &[f64]) -> (String, String) {
        if let Some(amplitude) = self.amplitude_warning {
            return (
                format!(
                    "its rod has swung {:.2}° from rest: past {:.2}° the tank's free-surface \
                     wave at the wall exceeds 0.1 of the tank radius, beyond the small \
                     amplitudes the linear slosh analog is derived for (the run stops at \
                     {:.2}°, where the pendulum's angles are singular)",
                    self.swing(q).to_degrees(),
                    amplitude.to_degrees(),
                    SINGULAR_COS_THETA.acos().to_degrees()
                ),
                "more damping (baffles) or a smaller disturbance; large liquid motion needs a \
                 nonlinear slosh model, which polhode does not have"
                    .into(),
            );
        }
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
        let mut drawings = vec![
            Drawing::Line {
                points: vec![self.pivot, bob],
                thickness: 0.1 * size,
            },
            Drawing::Sphere {
                center: bob,
                diameter: size,
            },
        ];
        drawings.extend(fixed_liquid_drawing(self.fixed_mass, self.fixed_position));
        drawings
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
            fixed_mass: 0.0,
            fixed_position: Vector3::zeros(),
            amplitude_warning: None,
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
