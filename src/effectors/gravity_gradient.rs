//! `gravity_gradient`: the torque of a central body's gravity on the extended hub.
//!
//! With r̂ the unit vector from the central body to the spacecraft's centre of mass, in body
//! axes, and I the hub's inertia about its centre of mass (body axes), the first-order
//! torque is
//!
//! ```text
//! τ = (3μ / r³) r̂ × (I r̂)
//! ```
//!
//! (Hughes, *Spacecraft Attitude Dynamics*, 1986, §8.1; Wertz (ed.), *Spacecraft Attitude
//! Determination and Control*, 1978, §17.2). The neglected terms are of relative order
//! (body size / r). The orbit is a model-level input: `r(t)` comes from
//! [`crate::orbit::Orbit::state`] at the right-hand side's time. The torque is external, so
//! the effector carries one bookkeeping state, the work done on the body `W = ∫ τ·ω dt`
//! (J), which the energy balance subtracts.

use super::environment::{EnvironmentTorque, names, to_body};
use crate::model::HubState;
use crate::orbit::Orbit;
use nalgebra::{Matrix3, Vector3};
use std::sync::Arc;

/// Gravity-gradient torque on a rigid hub in orbit.
#[derive(Debug, Clone)]
pub struct GravityGradient {
    /// Name (telemetry topic).
    pub name: String,
    /// The orbit of the spacecraft's centre of mass.
    pub orbit: Arc<Orbit>,
    /// The hub's inertia about its centre of mass, body axes (kg m²).
    pub inertia: Matrix3<f64>,
}

impl GravityGradient {
    /// The torque (N m, body axes) at time `t` (s) for the attitude `q` (w, x, y, z; body →
    /// inertial; normalised here).
    #[inline(always)]
    pub fn torque(&self, t: f64, q: &[f64]) -> Vector3<f64> {
        let (r_hat_n, mu_over_r3) = self.orbit.tidal_direction(t);
        let r_hat = to_body(q, &r_hat_n);
        (3.0 * mu_over_r3) * r_hat.cross(&(self.inertia * r_hat))
    }

    /// The gradient of the central body's field at the orbit position, in body axes (1/s²):
    /// G = (μ/r³)(3 r̂ r̂ᵀ − 1), so that a mass m displaced by ρ from the centre of mass
    /// feels the tidal force m G ρ to first order in ρ/r (Hughes 1986, §8.1). Its moment
    /// summed over a rigid body, ∫ ρ × G ρ dm, is [`GravityGradient::torque`].
    pub fn gradient(&self, t: f64, q: &[f64]) -> Matrix3<f64> {
        let (r_hat_n, radius) = self.orbit.direction(t);
        let r_hat = to_body(q, &r_hat_n);
        let mu_r3 = self.orbit.body().mu / (radius * radius * radius);
        mu_r3 * (3.0 * r_hat * r_hat.transpose() - Matrix3::identity())
    }

    /// The attitude-dependent part of the hub's gravitational potential energy (J) at `t`
    /// for attitude `q`, from MacCullagh's formula U = −μm/r − (μ/2r³)(tr I − 3 r̂ᵀ I r̂):
    /// V = (μ / 2r³)(3 r̂ᵀ I r̂ − tr I) (Hughes 1986, §8.1). The torque is −∂V/∂(attitude)
    /// for a fixed orbit position (lowest with the minimum-inertia axis along r̂). It is not
    /// conserved along an orbit (r̂ turns), so it is not part of the energy balance (the work
    /// `W` is).
    pub fn potential(&self, t: f64, q: &[f64]) -> f64 {
        let (r_hat_n, radius) = self.orbit.direction(t);
        let r_hat = to_body(q, &r_hat_n);
        let mu_r3 = self.orbit.body().mu / (radius * radius * radius);
        0.5 * mu_r3 * (3.0 * r_hat.dot(&(self.inertia * r_hat)) - self.inertia.trace())
    }
}

impl EnvironmentTorque for GravityGradient {
    fn name(&self) -> &str {
        &self.name
    }
    fn kind(&self) -> &'static str {
        "gravity_gradient"
    }
    fn environment_torque(&self, hub: &HubState) -> Vector3<f64> {
        self.torque(hub.t, hub.attitude)
    }
    fn acts_on_moving_masses(&self) -> bool {
        true
    }
    fn tidal_gradient(&self, hub: &HubState) -> Option<Matrix3<f64>> {
        Some(self.gradient(hub.t, hub.attitude))
    }
    fn telemetry_names(&self) -> Vec<String> {
        names(&[
            "torque_x",
            "torque_y",
            "torque_z",
            "work",
            "potential_energy",
        ])
    }
    fn telemetry(&self, hub: &HubState, work: f64) -> Vec<f64> {
        let (t, q) = (hub.t, hub.attitude);
        let tau = self.torque(t, q);
        vec![tau[0], tau[1], tau[2], work, self.potential(t, q)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::orbit::{CentralBody, Elements};
    use nalgebra::UnitQuaternion;

    /// The square-root-free torque against the textbook evaluation with a normalised
    /// quaternion and the orbit's position, for a quaternion off unit norm by 1e-3, in a
    /// circular and an eccentric orbit.
    #[test]
    fn the_fast_torque_equals_the_textbook_formula() {
        let inertia = Matrix3::new(3.0, 0.2, -0.1, 0.2, 5.0, 0.3, -0.1, 0.3, 7.0);
        for e in [0.0, 0.3] {
            let orbit = Orbit::new(
                CentralBody::EARTH,
                Elements::new(1.2e7, e, 0.9, 0.4, 1.1, 0.2),
                true,
            )
            .unwrap();
            let gg = GravityGradient {
                name: "gg".into(),
                orbit: Arc::new(orbit),
                inertia,
            };
            let q = UnitQuaternion::from_euler_angles(0.3, -1.2, 2.5);
            let raw = [q.w * 1.001, q.i * 1.001, q.j * 1.001, q.k * 1.001];
            for t in [0.0, 1234.5, 9876.0] {
                let (r, _) = gg.orbit.state(t);
                let r_b = q.inverse_transform_vector(&r.normalize());
                let mu = gg.orbit.body().mu;
                let expected = 3.0 * mu / r.norm().powi(3) * r_b.cross(&(inertia * r_b));
                let got = gg.torque(t, &raw);
                assert!(
                    (got - expected).norm() <= 1e-14 * expected.norm(),
                    "e = {e}, t = {t}: {got:?} vs {expected:?}"
                );
            }
        }
    }
}
