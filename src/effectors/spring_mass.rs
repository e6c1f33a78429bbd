//! `spring_mass_damper`: a particle on a line fixed in the body, with a spring and a dashpot.
//!
//! Position r = r₀ + ρ p̂ (body axes, about the hub's centre of mass), spring force −kρ
//! (relaxed at ρ = 0), dashpot −cρ̇. The hub translates as the particle moves (the system
//! centre of mass stays put), so no reduced-mass shortcut is taken: any number of these
//! couple correctly through the hub.

use super::particles::{ParticleModel, ParticlePoint, ParticleSums};
use crate::lanes::{Lane, linalg};
use crate::model::{Drawing, HubCoupling, Momentum, Validity};
use nalgebra::{Matrix3, Vector3};

/// A spring–mass–dashpot damper.
#[derive(Debug, Clone)]
pub struct SpringMass {
    /// Particle mass (kg).
    pub mass: f64,
    /// Point of the line at ρ = 0 (m, body axes, about the hub's centre of mass).
    pub position: Vector3<f64>,
    /// Unit direction of the line (body axes).
    pub direction: Vector3<f64>,
    /// Spring stiffness k (N/m).
    pub stiffness: f64,
    /// Dashpot coefficient c (N s/m).
    pub damping: f64,
    /// Travel |ρ| the damper's stops allow (m); `None` for an unlimited line. Past it the
    /// particle would hit its stop, which the model does not have.
    pub travel: Option<f64>,
}

/// Fraction of the travel past which the damper warns that it nears its stop.
pub const TRAVEL_WARN: f64 = 0.9;

impl SpringMass {
    /// The two-body reduction's terms at coordinate `q`, rate `u` and hub rate `omega`, with
    /// hub mass `hub_mass` (kg), by the lanes' form at one lane; `None` for a direction that
    /// is not a unit vector (the reduction is written for one, as scenarios give it).
    #[inline(always)]
    fn reduction(
        &self,
        q: &[f64],
        u: &[f64],
        omega: &Vector3<f64>,
        hub_mass: f64,
    ) -> Option<ReductionLanes<f64>> {
        if !self.has_unit_direction() {
            return None;
        }
        let lanes = self.lanes();
        Some(lanes.reduction(q[0], u[0], (*omega).into(), lanes.reduced_mass(hub_mass)))
    }
}

// The closed forms below, written once over the lane type: the scalar path calls them at one
// lane (`f64`, through [`SpringMass::lanes`]), the lockstep ensembles (crate::lanes::ensemble)
// at four or eight.

/// A spring–mass damper's parameters in lanes (one damper per lane): what its closed forms
/// read, generic over the lane type so that the scalar path (at `f64`, through
/// [`SpringMass::lanes`]) and the lockstep ensembles (crate::lanes::ensemble) run one code.
#[derive(Debug, Clone, Copy)]
pub struct SpringMassLanes<L> {
    /// Particle mass (kg).
    pub mass: L,
    /// Point of the line at ρ = 0 (m, body axes, about the hub's centre of mass).
    pub position: [L; 3],
    /// Unit direction of the line (body axes).
    pub direction: [L; 3],
    /// Spring stiffness k (N/m).
    pub stiffness: L,
    /// Dashpot coefficient c (N s/m).
    pub damping: L,
}

/// [`Reduction`] per lane.
struct ReductionLanes<L> {
    /// Reduced mass m* = m M/(M + m) (kg).
    reduced_mass: L,
    /// Particle position r (m, body axes).
    r: [L; 3],
    /// t = r × p̂ (m).
    t: [L; 3],
    /// ρ̈ at ω̇ = 0: Q/m* − p̂·c (m/s²).
    free_acceleration: L,
    /// r × (m* (c − p̂ (p̂·c)) + p̂ Q) (N m).
    moment: [L; 3],
}

impl<L: Lane> ReductionLanes<L> {
    /// The entries (row, column, value) of m* (|r|² 1 − r rᵀ − t tᵀ) on and below the
    /// diagonal (kg m²).
    #[inline(always)]
    fn added_inertia(&self) -> [(usize, usize, L); 6] {
        let (r, t, r2) = (self.r, self.t, linalg::dot(self.r, self.r));
        let entry = |i: usize, j: usize| {
            let diagonal = if i == j { r2 } else { L::splat(0.0) };
            (
                i,
                j,
                self.reduced_mass * (diagonal - r[i] * r[j] - t[i] * t[j]),
            )
        };
        [
            entry(0, 0),
            entry(1, 0),
            entry(2, 0),
            entry(1, 1),
            entry(2, 1),
            entry(2, 2),
        ]
    }
}

/// The lone damper's closed-form accelerations ([`SpringMassLanes::lone_accelerations`]).
#[derive(Debug, Clone, Copy)]
pub struct LoneAccelerations<L: Lane> {
    /// The hub's angular acceleration ω̇ (rad/s², body axes).
    pub omega_dot: [L; 3],
    /// The offset's acceleration ρ̈ (m/s²).
    pub u_dot: L,
    /// Lanes whose 3 × 3 system was positive definite (elsewhere the values are meaningless).
    pub solved: L::Mask,
}

impl<L: Lane> SpringMassLanes<L> {
    /// The generalised force of spring and dashpot, −kρ − cρ̇ (N), at offset `q` (m) and rate
    /// `u` (m/s).
    #[inline(always)]
    pub fn force(&self, q: L, u: L) -> L {
        -self.stiffness * q - self.damping * u
    }

    /// The power the dashpot dissipates, c ρ̇² (W), at rate `u` (m/s).
    #[inline(always)]
    pub fn dissipation_power(&self, u: L) -> L {
        self.damping * u * u
    }

    /// The reduced mass m* = m M / (M + m) (kg) of the particle and a hub of mass `hub_mass`
    /// (M, kg): a run's constant, formed once.
    #[inline(always)]
    pub fn reduced_mass(&self, hub_mass: L) -> L {
        self.mass * hub_mass / (hub_mass + self.mass)
    }

    /// The two-body reduction's terms at offset `q`, rate `u` and hub rate `omega`, with the
    /// reduced mass `m_star` ([`SpringMassLanes::reduced_mass`]), for a unit direction.
    #[inline(always)]
    fn reduction(&self, q: L, u: L, omega: [L; 3], m_star: L) -> ReductionLanes<L> {
        use linalg::{add, cross, dot, scale, sub};
        let (p, rho_dot) = (self.direction, u);
        let r = add(self.position, scale(q, p));
        let c = add(
            cross(omega, cross(omega, r)),
            scale(L::splat(2.0) * rho_dot, cross(omega, p)),
        );
        let generalised = self.force(q, u);
        let pc = dot(p, c);
        let pull = add(scale(m_star, sub(c, scale(pc, p))), scale(generalised, p));
        ReductionLanes {
            reduced_mass: m_star,
            r,
            t: cross(r, p),
            free_acceleration: generalised / m_star - pc,
            moment: cross(r, pull),
        }
    }

    /// The whole right-hand side of a hub (inertia `hub_inertia`, kg m² about its centre of
    /// mass, as columns; `reduced_mass` [`SpringMassLanes::reduced_mass`] of its mass, kg)
    /// carrying this damper alone, in closed form
    /// ([`ParticleModel::rhs_alone_closed_form`]): ω̇ and ρ̈ at offset `q` (m), rate `u`
    /// (m/s) and hub rate `omega` (rad/s). The direction must be a unit vector.
    #[inline(always)]
    pub fn lone_accelerations(
        &self,
        q: L,
        u: L,
        omega: [L; 3],
        hub_inertia: &[[L; 3]; 3],
        reduced_mass: L,
    ) -> LoneAccelerations<L> {
        let terms = self.reduction(q, u, omega, reduced_mass);
        // Column j, row i: m[j][i].
        let mut m = *hub_inertia;
        for (i, j, added) in terms.added_inertia() {
            m[j][i] += added;
        }
        let gyroscopic = linalg::cross(omega, linalg::mat_vec(hub_inertia, omega));
        let force = linalg::sub(
            [-gyroscopic[0], -gyroscopic[1], -gyroscopic[2]],
            terms.moment,
        );
        let (inverse, solved) =
            linalg::spd_inverse3(m[0][0], m[0][1], m[0][2], m[1][1], m[1][2], m[2][2]);
        let w = linalg::mat_vec(&inverse, force);
        let t = terms.t;
        LoneAccelerations {
            omega_dot: w,
            u_dot: terms.free_acceleration - t[0] * w[0] - t[1] * w[1] - t[2] * w[2],
            solved,
        }
    }
}

impl SpringMass {
    /// Its parameters as one lane.
    pub fn lanes(&self) -> SpringMassLanes<f64> {
        SpringMassLanes {
            mass: self.mass,
            position: self.position.into(),
            direction: self.direction.into(),
            stiffness: self.stiffness,
            damping: self.damping,
        }
    }

    /// Whether its direction is a unit vector, as the closed forms are written for (scenarios
    /// give one); they decline otherwise.
    pub fn has_unit_direction(&self) -> bool {
        (self.direction.norm_squared() - 1.0).abs() <= 1e-12
    }
}

impl ParticleModel for SpringMass {
    type Cache = ();
    const HAS_RHS_ALONE: bool = true;
    fn kind(&self) -> &'static str {
        "spring_mass_damper"
    }
    fn undamped(&self) -> Self {
        SpringMass {
            damping: 0.0,
            ..self.clone()
        }
    }
    fn num_coordinates(&self) -> usize {
        1
    }
    fn coordinate_names(&self) -> Vec<String> {
        vec!["offset".into()]
    }
    fn num_particles(&self) -> usize {
        1
    }
    fn particle(&self, _p: usize, _c: &(), q: &[f64], _u: &[f64], out: &mut ParticlePoint) {
        out.mass = self.mass;
        out.position = self.position + q[0] * self.direction;
        out.jacobian[0] = self.direction;
        out.convective = Vector3::zeros();
    }
    /// One particle, J = p̂ and no convective term: the sums written out, without the
    /// general routine's particle record.
    fn summed<const N: usize>(
        &self,
        q: &[f64],
        u: &[f64],
        omega: &Vector3<f64>,
        out: &mut ParticleSums<N>,
    ) -> bool {
        let (m, p) = (self.mass, self.direction);
        let r = self.position + q[0] * p;
        let c = omega.cross(&omega.cross(&r)) + 2.0 * u[0] * omega.cross(&p);
        let mp = m * p;
        let moment = r.cross(&mp);
        out.mass[0][0] = m * p.norm_squared();
        out.coupling[0] = [mp.x, mp.y, mp.z, moment.x, moment.y, moment.z];
        out.inertial[0] = -mp.dot(&c);
        out.total_mass = m;
        out.first_moment = m * r;
        out.inertia = m * (Matrix3::from_diagonal_element(r.norm_squared()) - r * r.transpose());
        out.force = m * c;
        out.moment = r.cross(&out.force);
        true
    }
    /// The two-body reduction: with the hub (mass M) and the particle sharing a fixed centre
    /// of mass, a_B = −(m/(M + m)) (ω̇ × r + p̂ ρ̈ + c), and the particle moves as one of
    /// reduced mass m* = m M/(M + m) about a fixed hub centre. Eliminating ρ̈ from
    /// m* p̂·(ω̇ × r + p̂ ρ̈ + c) = Q then leaves (|p̂| = 1, t = r × p̂)
    ///
    /// ```text
    /// (I + m* (|r|² 1 − r rᵀ − t tᵀ)) ω̇ = −ω × Iω − r × (m* (c − p̂ (p̂·c)) + p̂ Q),
    /// ρ̈ = Q/m* − p̂·c − t·ω̇.
    /// ```
    ///
    /// A direction that is not a unit vector takes the general path.
    fn couple_alone_closed_form(
        &self,
        q: &[f64],
        u: &[f64],
        omega: &Vector3<f64>,
        hub_mass: f64,
        coupling: &mut HubCoupling,
        kept: &mut [f64],
    ) -> bool {
        let Some(terms) = self.reduction(q, u, omega, hub_mass) else {
            return false;
        };
        for (i, j, added) in terms.added_inertia() {
            coupling.mass[(3 + i, 3 + j)] += added;
        }
        for i in 0..3 {
            coupling.force[3 + i] -= terms.moment[i];
        }
        // W = [ρ̈ at ω̇ = 0 | 0 0 0 | t], and L = 1.
        let t = terms.t;
        kept[..8].copy_from_slice(&[
            terms.free_acceleration,
            0.0,
            0.0,
            0.0,
            t[0],
            t[1],
            t[2],
            1.0,
        ]);
        true
    }
    /// The same reduction, solved: one symmetric 3 × 3 system by cofactors.
    #[inline(always)]
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
        if !self.has_unit_direction() {
            return false;
        }
        let lanes = self.lanes();
        // Columns: hub_inertia[c][r] is I(r, c).
        let columns = [0, 1, 2].map(|c| [0, 1, 2].map(|r| hub_inertia[(r, c)]));
        let a = lanes.lone_accelerations(
            q[0],
            u[0],
            (*omega).into(),
            &columns,
            lanes.reduced_mass(hub_mass),
        );
        if !a.solved {
            return false;
        }
        *omega_dot = a.omega_dot.into();
        u_dot[0] = a.u_dot;
        true
    }
    fn momentum_closed_form(&self, q: &[f64], u: &[f64], omega: &Vector3<f64>) -> Option<Momentum> {
        let m = self.mass;
        let r = self.position + q[0] * self.direction;
        let v = omega.cross(&r) + u[0] * self.direction;
        Some(Momentum {
            mass: m,
            first_moment: m * r,
            linear: m * v,
            angular: m * r.cross(&v),
            kinetic_energy: 0.5 * m * v.norm_squared(),
        })
    }
    fn forces(&self, q: &[f64], u: &[f64], out: &mut [f64]) {
        out[0] = -self.stiffness * q[0] - self.damping * u[0];
    }
    fn elastic_energy(&self, q: &[f64]) -> f64 {
        0.5 * self.stiffness * q[0] * q[0]
    }
    fn dissipation_power(&self, _q: &[f64], u: &[f64]) -> f64 {
        self.damping * u[0] * u[0]
    }
    fn validity(&self, q: &[f64]) -> Option<Validity> {
        self.travel.map(|travel| Validity {
            value: q[0].abs(),
            warn: TRAVEL_WARN * travel,
            limit: travel,
        })
    }
    fn validity_report(&self, q: &[f64]) -> (String, String) {
        (
            format!(
                "its mass is {:.4} m from its rest point, against a travel of {} m (warning at \
                 {}%); the model has no end stops, so past the travel it is no longer the \
                 damper built",
                q[0].abs(),
                self.travel.unwrap_or(f64::INFINITY),
                TRAVEL_WARN * 100.0
            ),
            "a stiffer spring, more travel, or a smaller disturbance".into(),
        )
    }
    fn drawings(&self, q: &[f64]) -> Vec<Drawing> {
        let size = (self.mass.cbrt() * 0.05).clamp(0.02, 0.3);
        vec![
            Drawing::Line {
                points: vec![
                    self.position - 4.0 * size * self.direction,
                    self.position + 4.0 * size * self.direction,
                ],
                thickness: 0.1 * size,
            },
            Drawing::Sphere {
                center: self.position + q[0] * self.direction,
                diameter: size,
            },
        ]
    }
}
