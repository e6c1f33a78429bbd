//! `magnetic_dipole`: the torque of the Earth's magnetic field on a residual (or fixed)
//! magnetic dipole moment carried by the hub.
//!
//! With m the dipole moment (A m², body axes) and B the geomagnetic field at the
//! spacecraft's centre of mass in body axes,
//!
//! ```text
//! τ = m × B,   B_body = C(q)ᵀ B_ECI
//! ```
//!
//! (Wertz (ed.), *Spacecraft Attitude Determination and Control*, 1978, §17.2). B_ECI is the
//! first-degree IGRF ([`crate::orbit::magnetic`]) at the orbit position `r(t)`, rotated from
//! ECEF by the Earth rotation angle at the scenario epoch plus `t`. The torque is external,
//! so the effector carries one bookkeeping state, the work done on the body
//! `W = ∫ τ·ω dt` (J), which the energy balance subtracts. (The potential −m·B is not
//! conserved: B turns in inertial space as the spacecraft moves and the Earth rotates.)

use super::environment::{EnvironmentTorque, names, to_body};
use crate::model::HubState;
use crate::orbit::{GeomagneticField, Orbit};
use nalgebra::Vector3;
use std::sync::Arc;

/// The geomagnetic field (T, body axes) at the position of `orbit` at time `t` (s), for the
/// integrated attitude `q` (w, x, y, z; body → inertial; normalised here).
#[inline]
pub fn field_body(orbit: &Orbit, field: &GeomagneticField, t: f64, q: &[f64]) -> Vector3<f64> {
    to_body(q, &field.field_on_orbit(orbit, t))
}

/// A constant magnetic dipole moment on the hub in the Earth's field.
#[derive(Debug, Clone)]
pub struct MagneticDipole {
    /// Name (telemetry topic).
    pub name: String,
    /// The orbit of the spacecraft's centre of mass.
    pub orbit: Arc<Orbit>,
    /// The geomagnetic field along the run (carries the scenario epoch).
    pub field: GeomagneticField,
    /// The dipole moment m (A m², body axes).
    pub moment: Vector3<f64>,
}

impl MagneticDipole {
    /// The geomagnetic field (T, body axes) at time `t` (s) for the attitude `q` (w, x, y, z;
    /// body → inertial; normalised here).
    #[inline]
    pub fn field_body(&self, t: f64, q: &[f64]) -> Vector3<f64> {
        field_body(&self.orbit, &self.field, t, q)
    }

    /// The torque m × B (N m, body axes) at `t` for attitude `q`.
    #[inline]
    pub fn torque_at(&self, t: f64, q: &[f64]) -> Vector3<f64> {
        self.moment.cross(&self.field_body(t, q))
    }
}

impl EnvironmentTorque for MagneticDipole {
    fn name(&self) -> &str {
        &self.name
    }
    fn kind(&self) -> &'static str {
        "magnetic_dipole"
    }
    fn environment_torque(&self, hub: &HubState) -> Vector3<f64> {
        self.torque_at(hub.t, hub.attitude)
    }
    fn field_angle(&self, hub: &HubState) -> Option<f64> {
        let b = self.field_body(hub.t, hub.attitude);
        // atan2(|m × b|, m·b) keeps its digits near 0 and π.
        Some(self.moment.cross(&b).norm().atan2(self.moment.dot(&b)))
    }
    fn telemetry_names(&self) -> Vec<String> {
        names(&[
            "torque_x", "torque_y", "torque_z", "b_x", "b_y", "b_z", "work",
        ])
    }
    fn telemetry(&self, hub: &HubState, work: f64) -> Vec<f64> {
        let b = self.field_body(hub.t, hub.attitude);
        let tau = self.moment.cross(&b);
        vec![tau[0], tau[1], tau[2], b[0], b[1], b[2], work]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::orbit::{CentralBody, Elements};
    use nalgebra::UnitQuaternion;

    /// A dipole on a slightly eccentric, inclined low orbit, in the field of late 2023.
    fn dipole_on_orbit() -> MagneticDipole {
        let orbit = Orbit::new(
            CentralBody::EARTH,
            Elements::new(6.9e6, 0.01, 0.9, 0.4, 1.1, 0.2),
            false,
        )
        .unwrap();
        MagneticDipole {
            name: "m".into(),
            orbit: Arc::new(orbit),
            field: GeomagneticField::new(1_700_000_000_000_000_000),
            moment: Vector3::new(0.1, -0.2, 0.3),
        }
    }

    /// The square-root-free rotation against nalgebra's, for a quaternion off unit norm by
    /// 1e-3.
    #[test]
    fn the_fast_body_field_equals_the_rotated_field() {
        let md = dipole_on_orbit();
        let q = UnitQuaternion::from_euler_angles(0.3, -1.2, 2.5);
        let raw = [q.w * 1.001, q.i * 1.001, q.j * 1.001, q.k * 1.001];
        for t in [0.0, 1234.5, 9876.0] {
            let (r_hat, radius) = md.orbit.direction(t);
            let expected = q.inverse_transform_vector(&md.field.field_eci(t, &r_hat, radius));
            let got = md.field_body(t, &raw);
            assert!(
                (got - expected).norm() <= 1e-14 * expected.norm(),
                "t = {t}: {got:?} vs {expected:?}"
            );
        }
    }

    /// The angle to the field against acos of the normalised dot product of the moment and
    /// the field rotated by nalgebra, away from 0 and π where acos loses digits.
    #[test]
    fn the_field_angle_is_the_angle_between_moment_and_field() {
        let md = dipole_on_orbit();
        let q = UnitQuaternion::from_euler_angles(0.3, -1.2, 2.5);
        let raw = [q.w, q.i, q.j, q.k];
        for t in [0.0, 1234.5, 9876.0] {
            let (r_hat, radius) = md.orbit.direction(t);
            let b = q.inverse_transform_vector(&md.field.field_eci(t, &r_hat, radius));
            let expected = (md.moment.dot(&b) / (md.moment.norm() * b.norm())).acos();
            let hub = HubState {
                t,
                attitude: &raw,
                omega: Vector3::zeros(),
            };
            let got = EnvironmentTorque::field_angle(&md, &hub).unwrap();
            assert!(
                (got - expected).abs() < 1e-12,
                "t = {t}: {got} vs {expected}"
            );
        }
    }
}
