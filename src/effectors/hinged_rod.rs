//! `hinged_rod`: a thin rigid rod on a hinge with one or two rotational degrees of freedom
//! (a universal joint), with torsional springs and dampers on the joint angles.
//!
//! At the hinge point h (body axes), with rest direction ê₀, hinge axis n̂ (⊥ ê₀) and
//! b̂ = n̂ × ê₀, the rod's direction is
//!
//! ```text
//! ê(θ_f, θ_l) = cos θ_f (cos θ_l ê₀ + sin θ_l b̂) + sin θ_f n̂:
//! ```
//!
//! lag θ_l rotates the rod about the body-fixed n̂, then flap θ_f tips it toward n̂. Springs and
//! dampers act on the joint angles: Q = −k θ − c θ̇ (generalised forces). A thin uniform rod
//! (no inertia about its own axis) is exactly two particles of half its mass at the 2-point
//! Gauss–Legendre stations s = L/2 (1 ∓ 1/√3): every term of its equations of motion, its
//! momentum and its energy is a quadratic polynomial in s, which that rule integrates exactly.

use super::particles::{ParticleModel, ParticlePoint, ParticleSums, add_mass_and_first_moment};
use crate::model::{Drawing, Grouping, HubCoupling, Momentum, Validity};
use crate::sincos::sin_cos;
use nalgebra::{Matrix3, Matrix6, Vector3};

/// Which joint angles are free.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HingeFreedom {
    /// Flap only (rotation toward the hinge axis).
    Flap,
    /// Lag only (rotation about the hinge axis).
    Lag,
    /// Both: a universal joint.
    FlapLag,
}

/// A hinged thin rod.
#[derive(Debug, Clone)]
pub struct HingedRod {
    /// Rod mass (kg).
    pub mass: f64,
    /// Rod length (m).
    pub length: f64,
    /// Hinge point (m, body axes, about the hub's centre of mass).
    pub hinge: Vector3<f64>,
    /// Unit rest direction ê₀.
    pub direction: Vector3<f64>,
    /// Unit hinge axis n̂ (⊥ ê₀): lag turns about it, flap tips toward it.
    pub axis: Vector3<f64>,
    /// Free joint angles.
    pub freedom: HingeFreedom,
    /// Torsional stiffness on flap and lag (N m/rad).
    pub stiffness: [f64; 2],
    /// Torsional damping on flap and lag (N m s/rad).
    pub damping: [f64; 2],
}

impl HingedRod {
    /// (θ_f, θ_l, θ̇_f, θ̇_l) from the coordinates and rates.
    fn angles(&self, q: &[f64], u: &[f64]) -> [f64; 4] {
        match self.freedom {
            HingeFreedom::FlapLag => [q[0], q[1], u[0], u[1]],
            HingeFreedom::Flap => [q[0], 0.0, u[0], 0.0],
            HingeFreedom::Lag => [0.0, q[0], 0.0, u[0]],
        }
    }

    /// Rod direction ê and its partial derivatives, and the convective term Σ ∂²ê u u.
    fn direction_at(&self, a: [f64; 4]) -> [Vector3<f64>; 4] {
        let [f, l, df, dl] = a;
        let b = self.axis.cross(&self.direction);
        let (sf, cf) = sin_cos(f);
        let (sl, cl) = sin_cos(l);
        let c = cl * self.direction + sl * b;
        let c_prime = -sl * self.direction + cl * b;
        let e = cf * c + sf * self.axis;
        let e_f = -sf * c + cf * self.axis;
        let e_l = cf * c_prime;
        let kappa = -cf * dl * dl * c - 2.0 * sf * df * dl * c_prime - df * df * e;
        [e, e_f, e_l, kappa]
    }

    /// The rod's first and second moments of mass about the hinge, m₁ = ∫ s dm = m L/2
    /// (kg m) and m₂ = ∫ s² dm = m L²/3 (kg m²).
    pub(crate) fn moments(&self) -> (f64, f64) {
        let m = self.mass;
        (0.5 * m * self.length, m * self.length * self.length / 3.0)
    }

    /// Tip position (m, body axes) at coordinates `q`.
    pub fn tip(&self, q: &[f64]) -> Vector3<f64> {
        let zeros = [0.0; 2];
        let [e, ..] = self.direction_at(self.angles(q, &zeros[..q.len()]));
        self.hinge + self.length * e
    }
}

/// |cos θ_f| below which a flap–lag rod is at its coordinate singularity: flap within 2.9° of
/// ±90°, where the rod lies along its lag axis, lag is undefined, and the lag spring and damper
/// act on a vanishing inertia (the equations become infinitely stiff).
pub const SINGULAR_COS_FLAP: f64 = 0.05;
/// Flap angle (degrees from 0, folded into [0°, 90°]) past which a flap–lag rod warns that it
/// nears the singularity: the lag inertia has fallen to cos² 75° = 7 % of its value at rest.
pub const FLAP_WARN_DEG: f64 = 75.0;

/// The flap angle folded into [0, π/2] (rad): arccos |cos θ_f|, the distance from θ_f to the
/// nearest multiple of π, computed without a cosine (this is checked at every step).
pub(crate) fn folded_angle(angle: f64) -> f64 {
    let a = angle.abs();
    if a <= std::f64::consts::FRAC_PI_2 {
        return a;
    }
    let m = a % std::f64::consts::PI;
    m.min(std::f64::consts::PI - m)
}

/// Adds the hinge point's constant share of a flap–lag rod's D − C M⁻¹ Cᵀ to the lower
/// triangle of the hub's mass: `rest` (m − μ, kg) at the hinge `h` (m, body axes),
/// `rest` [[1, −[h×]], [[h×], |h|² 1 − h hᵀ]].
pub(crate) fn add_hinge_mass(hub: &mut Matrix6<f64>, rest: f64, h: &Vector3<f64>) {
    let s = rest * h;
    add_mass_and_first_moment(hub, rest, &s);
    let h2 = h.norm_squared();
    for i in 0..3 {
        hub[(3 + i, 3 + i)] += rest * h2;
        for j in 0..=i {
            hub[(3 + i, 3 + j)] -= s[i] * h[j];
        }
    }
}

/// Stations and weights of the 2-point Gauss rule on [0, 1].
const STATIONS: [f64; 2] = [
    0.5 - 0.288_675_134_594_812_9, // ½ (1 − 1/√3)
    0.5 + 0.288_675_134_594_812_9,
];

impl ParticleModel for HingedRod {
    /// ê, ∂ê/∂θ_f, ∂ê/∂θ_l and the convective Σ ∂²ê u u at the current angles and rates.
    type Cache = [Vector3<f64>; 4];
    fn prepare(&self, q: &[f64], u: &[f64]) -> Self::Cache {
        self.direction_at(self.angles(q, u))
    }
    fn kind(&self) -> &'static str {
        "hinged_rod"
    }
    /// A scene's flap–lag rods couple [`super::rod_lanes::LANES`] at a time, one per lane.
    fn grouping(&self) -> Option<Grouping> {
        (self.freedom == HingeFreedom::FlapLag).then_some(Grouping {
            kind: "flap_lag_rods",
            form: super::rod_lanes::RodLanes::form_groups,
        })
    }
    fn undamped(&self) -> Self {
        HingedRod {
            damping: [0.0; 2],
            ..self.clone()
        }
    }
    fn num_coordinates(&self) -> usize {
        match self.freedom {
            HingeFreedom::FlapLag => 2,
            _ => 1,
        }
    }
    fn coordinate_names(&self) -> Vec<String> {
        match self.freedom {
            HingeFreedom::FlapLag => vec!["flap".into(), "lag".into()],
            HingeFreedom::Flap => vec!["flap".into()],
            HingeFreedom::Lag => vec!["lag".into()],
        }
    }
    fn num_particles(&self) -> usize {
        2
    }
    fn validity(&self, q: &[f64]) -> Option<Validity> {
        (self.freedom == HingeFreedom::FlapLag).then(|| Validity {
            value: folded_angle(q[0]).to_degrees(),
            warn: FLAP_WARN_DEG,
            limit: SINGULAR_COS_FLAP.acos().to_degrees(),
        })
    }
    fn validity_report(&self, q: &[f64]) -> (String, String) {
        (
            format!(
                "it has swung to flap = {:.2}°: at ±90° it lies along its lag axis, where the \
                 flap–lag angles are singular (lag is undefined) and the lag spring and damper \
                 act on no inertia (warning past {FLAP_WARN_DEG}° of flap, limit {:.2}°)",
                q[0].to_degrees(),
                SINGULAR_COS_FLAP.acos().to_degrees()
            ),
            "keep the rod away from 90° flap (a stiffer flap spring, a smaller initial flap \
             rate), or give it one freedom (`freedom: flap` or `lag`)"
                .into(),
        )
    }
    fn particle(
        &self,
        p: usize,
        cache: &Self::Cache,
        _q: &[f64],
        _u: &[f64],
        out: &mut ParticlePoint,
    ) {
        let s = STATIONS[p] * self.length;
        let [e, e_f, e_l, kappa] = *cache;
        out.mass = 0.5 * self.mass;
        out.position = self.hinge + s * e;
        match self.freedom {
            HingeFreedom::FlapLag => {
                out.jacobian[0] = s * e_f;
                out.jacobian[1] = s * e_l;
            }
            HingeFreedom::Flap => out.jacobian[0] = s * e_f,
            HingeFreedom::Lag => out.jacobian[0] = s * e_l,
        }
        out.convective = s * kappa;
    }
    /// The rod's sums in closed form: with r = h + s ê and the rod's moments about the hinge
    /// m₁ = ∫ s dm = m L/2 and m₂ = ∫ s² dm = m L²/3 (which the two Gauss particles reproduce
    /// exactly), the point at s accelerates (relative to the hub) by c(s) = a_h + s a_ê, and
    /// every sum is a combination of h, ê and its derivatives (docs/effectors.md).
    fn summed<const N: usize>(
        &self,
        q: &[f64],
        u: &[f64],
        omega: &Vector3<f64>,
        out: &mut ParticleSums<N>,
    ) -> bool {
        let angles = self.angles(q, u);
        let [e, e_f, e_l, kappa] = self.direction_at(angles);
        let columns = match self.freedom {
            HingeFreedom::FlapLag => [e_f, e_l],
            HingeFreedom::Flap => [e_f, Vector3::zeros()],
            HingeFreedom::Lag => [e_l, Vector3::zeros()],
        };
        let (m, h) = (self.mass, self.hinge);
        let (m1, m2) = self.moments();
        // Σ m r = m h + m₁ ê and Σ m s r = m₁ h + m₂ ê.
        let p1 = m * h + m1 * e;
        let p2 = m1 * h + m2 * e;
        // a_h = ω × (ω × h), a_ê = ω × (ω × ê) + 2 ω × ê̇ + κ, and ω × (ω × v) = ω (ω·v) − v ω²,
        // so Σ m c = m a_h + m₁ a_ê and Σ m s c = m₁ a_h + m₂ a_ê are:
        let w2 = omega.norm_squared();
        let e_rate = angles[2] * e_f + angles[3] * e_l;
        let relative = 2.0 * omega.cross(&e_rate) + kappa;
        let force = omega * omega.dot(&p1) - w2 * p1 + m1 * relative;
        let force_s = omega * omega.dot(&p2) - w2 * p2 + m2 * relative;
        for (k, jk) in columns[..q.len()].iter().enumerate() {
            // ∂ê/∂θ_f ⊥ ∂ê/∂θ_l (c ⊥ c′ and n̂ ⊥ c′): M is diagonal, its off-diagonal
            // entry exactly zero, which `couple` then eliminates without a factorisation.
            out.mass[k][k] = m2 * jk.norm_squared();
            let moment = p2.cross(jk);
            out.coupling[k] = [
                m1 * jk.x,
                m1 * jk.y,
                m1 * jk.z,
                moment.x,
                moment.y,
                moment.z,
            ];
            out.inertial[k] = -jk.dot(&force_s);
        }
        out.total_mass = m;
        out.first_moment = p1;
        // Σ m (|r|² 1 − r rᵀ) with Σ m r rᵀ = m g gᵀ + (m₂ − m₁²/m) ê êᵀ, g = p1/m (the rod's
        // centre of mass).
        // Entry by entry (symmetric): m g gᵀ = p₁ p₁ᵀ/m.
        let inv_m = 1.0 / m;
        let spread = m2 - m1 * m1 * inv_m;
        let trace = p1.norm_squared() * inv_m + spread;
        let entry = |i: usize, j: usize| -(p1[i] * p1[j] * inv_m + spread * e[i] * e[j]);
        let (xy, xz, yz) = (entry(0, 1), entry(0, 2), entry(1, 2));
        out.inertia = Matrix3::new(
            trace + entry(0, 0),
            xy,
            xz,
            xy,
            trace + entry(1, 1),
            yz,
            xz,
            yz,
            trace + entry(2, 2),
        );
        out.force = force;
        out.moment = h.cross(&force) + e.cross(&force_s);
        true
    }

    /// The flap–lag rod's coordinates eliminated by hand (docs/effectors.md, closed forms): the
    /// Jacobian columns ∂ê/∂θ_f and ∂ê/∂θ_l are orthogonal and both ⊥ ê, so the joint leaves
    /// the rod free to turn about the hinge and `D − C M⁻¹ Cᵀ` is the hinge point carrying
    /// the mass tensor (m − μ) 1 + μ ê êᵀ, μ = m₁²/m₂: a constant part plus μ v vᵀ,
    /// v = [ê; h × ê]. With one freedom the columns do not span ⊥ ê, and the sums are used.
    fn couple_closed_form(
        &self,
        q: &[f64],
        u: &[f64],
        omega: &Vector3<f64>,
        coupling: &mut HubCoupling,
        kept: &mut [f64],
    ) -> bool {
        if self.freedom != HingeFreedom::FlapLag {
            return false;
        }
        let angles = self.angles(q, u);
        let [e, e_f, e_l, kappa] = self.direction_at(angles);
        let [_, _, flap_rate, lag_rate] = angles;
        let cos2 = e_l.norm_squared(); // |∂ê/∂θ_l|² = cos² θ_f; |∂ê/∂θ_f| = 1
        if cos2.is_nan() || cos2 <= 0.0 {
            // Lag has no inertia: poison the hub solve, so the run stops with a diagnosis.
            coupling.force[0] = f64::NAN;
            kept.fill(f64::NAN);
            return true;
        }
        let (m, h) = (self.mass, self.hinge);
        let (m1, m2) = self.moments();
        let mu = m1 * m1 / m2;
        let rest = m - mu;
        let mut joint_forces = [0.0; 2];
        self.forces(q, u, &mut joint_forces);
        let [q_flap, q_lag] = joint_forces;
        // The joint's generalised forces as a vector ⊥ ê: G = Σ_k Q_k ∂ê/∂θ_k / |∂ê/∂θ_k|².
        let joint = q_flap * e_f + (q_lag / cos2) * e_l;
        // The rod's acceleration terms free of the unknowns: a_h = ω × (ω × h) at the hinge,
        // and along the rod λ = ê · (ω × (ω × ê) + 2 ω × ê̇ + κ).
        let w2 = omega.norm_squared();
        let e_rate = flap_rate * e_f + lag_rate * e_l;
        let relative = 2.0 * omega.cross(&e_rate) + kappa;
        let omega_e = omega.dot(&e);
        let lambda = omega_e * omega_e - w2 + e.dot(&relative);
        let a_h = omega * omega.dot(&h) - w2 * h;
        // e + C M⁻¹ g: the force [(m − μ) 1 + μ ê êᵀ] a_h + m₁ λ ê + (m₁/m₂) G at the hinge,
        // and the joint's torque ê × G.
        let force = rest * a_h + (mu * e.dot(&a_h) + m1 * lambda) * e + (m1 / m2) * joint;
        let moment = h.cross(&force) + e.cross(&joint);
        for i in 0..3 {
            coupling.force[i] -= force[i];
            coupling.force[3 + i] -= moment[i];
        }
        // D − C M⁻¹ Cᵀ (lower triangle): (m − μ) [[1, −[h×]], [[h×], |h|² 1 − h hᵀ]] + μ v vᵀ.
        let hub = &mut coupling.mass;
        add_hinge_mass(hub, rest, &h);
        let he = h.cross(&e);
        let v = [e.x, e.y, e.z, he.x, he.y, he.z];
        for i in 0..6 {
            let mu_vi = mu * v[i];
            for j in 0..=i {
                hub[(i, j)] += mu_vi * v[j];
            }
        }
        // What `derivatives` reads: W_k = [g_k, Cᵀ_k] / M_kk with Cᵀ_k = [m₁ j_k, p₂ × j_k],
        // g_k = Q_k − j_k · Σ m s c, and L = 1.
        let p2 = m1 * h + m2 * e;
        let force_s = omega * omega.dot(&p2) - w2 * p2 + m2 * relative;
        for (k, (j, mass_k, q_k)) in [(e_f, m2, q_flap), (e_l, m2 * cos2, q_lag)]
            .into_iter()
            .enumerate()
        {
            let r = 1.0 / mass_k;
            let moment = p2.cross(&j);
            let row = &mut kept[7 * k..7 * k + 7];
            row[0] = (q_k - j.dot(&force_s)) * r;
            for a in 0..3 {
                row[1 + a] = m1 * j[a] * r;
                row[4 + a] = moment[a] * r;
            }
        }
        kept[14..17].copy_from_slice(&[1.0, 0.0, 1.0]);
        true
    }

    /// The rod's momentum in closed form: the point at s moves at v(s) = v_h + s v_ê with
    /// v_h = ω × h and v_ê = ω × ê + ê̇, so every sum is one of m, m₁ and m₂.
    fn momentum_closed_form(&self, q: &[f64], u: &[f64], omega: &Vector3<f64>) -> Option<Momentum> {
        let angles = self.angles(q, u);
        let [e, e_f, e_l, _] = self.direction_at(angles);
        let (m, h) = (self.mass, self.hinge);
        let (m1, m2) = self.moments();
        let v_h = omega.cross(&h);
        let v_e = omega.cross(&e) + angles[2] * e_f + angles[3] * e_l;
        Some(Momentum {
            mass: m,
            first_moment: m * h + m1 * e,
            linear: m * v_h + m1 * v_e,
            angular: m * h.cross(&v_h) + m1 * (h.cross(&v_e) + e.cross(&v_h)) + m2 * e.cross(&v_e),
            kinetic_energy: 0.5 * (m * v_h.norm_squared() + 2.0 * m1 * v_h.dot(&v_e))
                + 0.5 * m2 * v_e.norm_squared(),
        })
    }
    fn forces(&self, q: &[f64], u: &[f64], out: &mut [f64]) {
        let [f, l, df, dl] = self.angles(q, u);
        let qf = -self.stiffness[0] * f - self.damping[0] * df;
        let ql = -self.stiffness[1] * l - self.damping[1] * dl;
        match self.freedom {
            HingeFreedom::FlapLag => {
                out[0] = qf;
                out[1] = ql;
            }
            HingeFreedom::Flap => out[0] = qf,
            HingeFreedom::Lag => out[0] = ql,
        }
    }
    fn elastic_energy(&self, q: &[f64]) -> f64 {
        let zeros = [0.0; 2];
        let [f, l, ..] = self.angles(q, &zeros[..q.len()]);
        0.5 * (self.stiffness[0] * f * f + self.stiffness[1] * l * l)
    }
    fn dissipation_power(&self, q: &[f64], u: &[f64]) -> f64 {
        let [_, _, df, dl] = self.angles(q, u);
        self.damping[0] * df * df + self.damping[1] * dl * dl
    }
    fn extra_telemetry_names(&self) -> Vec<String> {
        vec!["tip_x".into(), "tip_y".into(), "tip_z".into()]
    }
    fn extra_telemetry(&self, q: &[f64]) -> Vec<f64> {
        self.tip(q).as_slice().to_vec()
    }
    fn drawings(&self, q: &[f64]) -> Vec<Drawing> {
        let tip = self.tip(q);
        vec![
            Drawing::Line {
                points: vec![self.hinge, tip],
                thickness: (0.02 * self.length).max(0.005),
            },
            Drawing::Sphere {
                center: tip,
                diameter: (0.05 * self.length).max(0.01),
            },
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fold equals arccos |cos θ| (the angle from the nearest multiple of π) over several
    /// turns of either sign, to the cosine's rounding.
    #[test]
    fn folded_flap_is_the_distance_to_the_nearest_multiple_of_pi() {
        for k in -4000..=4000 {
            let flap = k as f64 * 0.003_7;
            let reference = flap.cos().abs().min(1.0).acos();
            // arccos near 0 amplifies the cosine's rounding: 1e-8 rad there, 1e-15 elsewhere.
            let tolerance = if reference < 1e-3 { 1e-7 } else { 1e-12 };
            assert!(
                (folded_angle(flap) - reference).abs() <= tolerance,
                "{flap}: {} against {reference}",
                folded_angle(flap)
            );
        }
        assert_eq!(folded_angle(-0.25), 0.25);
        assert!(folded_angle(f64::NAN).is_nan());
    }
}
