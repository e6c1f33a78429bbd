//! Quantities derived from a state at one instant: what every logged sample knows.

use super::{HubState, Momentum, Spacecraft};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

/// Derived quantities at one instant.
#[derive(Debug, Clone, PartialEq)]
pub struct Observation {
    /// Simulation time (s).
    pub t: f64,
    /// Body rates (rad/s, body frame).
    pub omega: Vector3<f64>,
    /// Attitude, body → inertial, normalised from the integrated quaternion.
    pub attitude: UnitQuaternion<f64>,
    /// `|q| − 1` of the integrated quaternion (a measure of integration error).
    pub q_norm_error: f64,
    /// Total angular momentum about the system centre of mass, body frame (N m s).
    pub h_body: Vector3<f64>,
    /// The same in the inertial frame (N m s); constant for a free system.
    pub h_inertial: Vector3<f64>,
    /// `|H|` (N m s).
    pub h_norm: f64,
    /// Angular momentum the exhaust has carried out since t = 0, about the centre of mass,
    /// inertial frame (N m s; zero without a thruster): `h_inertial` plus this is constant
    /// for a free system.
    pub h_carried_out: Vector3<f64>,
    /// Kinetic energy of the whole spacecraft in its centre-of-mass frame (J).
    pub kinetic_energy: f64,
    /// Elastic energy stored in the effectors' springs (J).
    pub elastic_energy: f64,
    /// Energy dissipated by the effectors since t = 0 (J).
    pub dissipated_energy: f64,
    /// Present total dissipation rate (W).
    pub dissipation_power: f64,
    /// Work done on the spacecraft by external (environmental) torques since t = 0 (J).
    pub external_work: f64,
    /// Angle between the scenario's spin axis and H (rad).
    pub nutation_angle: f64,
    /// Angle between ω and each principal axis of the hub, in principal order (rad, [0, π]).
    pub angles_to_principal: [f64; 3],
    /// Angle (rad) between the first permanent magnet's (`magnetic_dipole`) moment and the
    /// local field; NaN without one.
    pub field_angle: f64,
}

impl Observation {
    /// The conserved quantities it holds (what [`Spacecraft::invariants`] computes alone).
    pub fn invariants(&self) -> Invariants {
        Invariants {
            h_body: self.h_body,
            h_inertial: self.h_inertial,
            h_carried_out: self.h_carried_out,
            kinetic_energy: self.kinetic_energy,
            elastic_energy: self.elastic_energy,
            dissipated_energy: self.dissipated_energy,
            dissipation_power: self.dissipation_power,
            external_work: self.external_work,
            q_norm_error: self.q_norm_error,
        }
    }

    /// Kinetic + elastic + dissipated energy minus the work of external torques (J):
    /// constant for any spacecraft without a prescribed motion (work–energy theorem).
    pub fn energy_balance(&self) -> f64 {
        self.kinetic_energy + self.elastic_energy + self.dissipated_energy - self.external_work
    }
}

/// Angle between two vectors (rad), accurate for small and near-π angles alike.
pub fn angle_between(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    angle_from(a.cross(b).norm(), a.dot(b))
}

/// The angle between two vectors a and b (rad) from |a × b| and a · b, as [`angle_between`]
/// forms it: the arctangent of the lanes ([`crate::lanes::elementary::half_plane_atan2`],
/// within one unit in the last place), so that the lanes' angles are the scalar path's.
pub fn angle_from(cross_norm: f64, dot: f64) -> f64 {
    crate::lanes::elementary::half_plane_atan2(cross_norm, dot)
}

/// The conserved quantities only: what drift tracking needs at every step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Invariants {
    /// Angular momentum, body frame (N m s).
    pub h_body: Vector3<f64>,
    /// Angular momentum, inertial frame (N m s).
    pub h_inertial: Vector3<f64>,
    /// Angular momentum carried out by exhaust since t = 0, inertial frame (N m s).
    pub h_carried_out: Vector3<f64>,
    /// Kinetic energy (J).
    pub kinetic_energy: f64,
    /// Elastic energy (J).
    pub elastic_energy: f64,
    /// Dissipated energy (J).
    pub dissipated_energy: f64,
    /// Present dissipation rate (W).
    pub dissipation_power: f64,
    /// Work of external torques (J).
    pub external_work: f64,
    /// `|q| − 1`.
    pub q_norm_error: f64,
}

impl Invariants {
    /// Kinetic + elastic + dissipated energy minus the work of external torques (J).
    pub fn energy_balance(&self) -> f64 {
        self.kinetic_energy + self.elastic_energy + self.dissipated_energy - self.external_work
    }
}

pub(super) fn invariants(sc: &Spacecraft, t: f64, y: &[f64]) -> (Invariants, UnitQuaternion<f64>) {
    let omega = Vector3::new(y[0], y[1], y[2]);
    let q_raw = Quaternion::new(y[3], y[4], y[5], y[6]);
    let q_norm = q_raw.norm();
    let attitude = UnitQuaternion::new_unchecked(q_raw / q_norm);
    let mut h_body = sc.hub.inertia * omega;
    let mut kinetic_energy = 0.5 * omega.dot(&(sc.hub.inertia * omega));
    let (mut elastic_energy, mut dissipated_energy, mut dissipation_power) = (0.0, 0.0, 0.0);
    let mut external_work = 0.0;
    let mut h_carried_out = Vector3::zeros();
    if !sc.effectors().is_empty() {
        let hub = HubState {
            t,
            omega,
            attitude: &y[3..7],
        };
        let start = Momentum {
            mass: sc.hub_mass.unwrap_or(0.0),
            angular: h_body,
            kinetic_energy,
            ..Momentum::default()
        };
        let sum = sc.summed_momentum(&hub, y, start);
        h_body = sum.angular;
        kinetic_energy = sum.kinetic_energy;
        let (total_mass, first_moment, linear) = (sum.mass, sum.first_moment, sum.linear);
        for (i, e) in sc.effectors().iter().enumerate() {
            let x = sc.effector_states(i, y);
            let a = e.energy(&hub, x);
            elastic_energy += a.elastic;
            dissipated_energy += a.dissipated;
            dissipation_power += a.power;
            external_work += a.work;
        }
        if sc.expels_mass() {
            for (i, e) in sc.effectors().iter().enumerate() {
                h_carried_out += e.momentum_carried_out(sc.effector_states(i, y));
            }
        }
        // The system's linear momentum is zero, so the hub moves at v_B = −P_rel / M; that
        // adds S × v_B to H and −½ |P_rel|² / M to T (values about the system centre of mass).
        if total_mass > 0.0 && linear != Vector3::zeros() {
            let v_hub = -linear / total_mass;
            h_body += first_moment.cross(&v_hub);
            kinetic_energy -= 0.5 * linear.norm_squared() / total_mass;
        }
    }
    let h_inertial = attitude * h_body;
    let inv = Invariants {
        h_body,
        h_inertial,
        h_carried_out,
        kinetic_energy,
        elastic_energy,
        dissipated_energy,
        dissipation_power,
        external_work,
        q_norm_error: q_norm - 1.0,
    };
    (inv, attitude)
}

/// The angle between `omega` and each principal axis of the hub, in principal order (rad).
pub(super) fn angles_to_principal(sc: &Spacecraft, omega: &Vector3<f64>) -> [f64; 3] {
    let axes = &sc.hub.principal_axes;
    let angle = |c: usize| angle_between(omega, &axes.column(c).into());
    [angle(0), angle(1), angle(2)]
}

/// The observation at state `y`; its angles to the principal axes are NaN unless `angles`.
pub(super) fn observe(sc: &Spacecraft, t: f64, y: &[f64], angles: bool) -> Observation {
    let (inv, attitude) = invariants(sc, t, y);
    let h_norm = inv.h_body.norm();
    let nutation_angle = angle_between(&sc.spin_axis, &inv.h_body);
    Observation::from_invariants(sc, t, y, &inv, attitude, angles, h_norm, nutation_angle)
}

impl Observation {
    /// The observation of `sc` at state `y` (time `t`, s) whose invariants and attitude are
    /// already known (as [`Spacecraft::invariants`] gives them, or the same computed
    /// elsewhere bit for bit), with |H| (`h_body`'s norm) and the nutation angle
    /// ([`angle_between`] the spin axis and `h_body`), which the lanes compute themselves:
    /// the rest is derived here. Its angles to the principal axes are NaN unless `angles`.
    #[inline]
    #[allow(clippy::too_many_arguments)] // the parts of one observation
    pub(crate) fn from_invariants(
        sc: &Spacecraft,
        t: f64,
        y: &[f64],
        inv: &Invariants,
        attitude: UnitQuaternion<f64>,
        angles: bool,
        h_norm: f64,
        nutation_angle: f64,
    ) -> Observation {
        // The calls first and ω last, read straight into the observation: ω held across
        // the calls went through the stack in pieces and was read back whole, a load that
        // waited on store forwarding (6 % of a lane campaign's time).
        let field_angle = field_angle(sc, t, y);
        let angles_to_principal = if angles {
            angles_to_principal(sc, &Vector3::new(y[0], y[1], y[2]))
        } else {
            [f64::NAN; 3]
        };
        Observation {
            t,
            omega: Vector3::new(y[0], y[1], y[2]),
            attitude,
            q_norm_error: inv.q_norm_error,
            h_body: inv.h_body,
            h_inertial: inv.h_inertial,
            h_norm,
            h_carried_out: inv.h_carried_out,
            kinetic_energy: inv.kinetic_energy,
            elastic_energy: inv.elastic_energy,
            dissipated_energy: inv.dissipated_energy,
            dissipation_power: inv.dissipation_power,
            external_work: inv.external_work,
            nutation_angle,
            angles_to_principal,
            field_angle,
        }
    }
}

/// The first effector's [`crate::model::Effector::field_angle`] at state `y` (rad), NaN if none
/// has one.
fn field_angle(sc: &Spacecraft, t: f64, y: &[f64]) -> f64 {
    if !sc.has_magnet {
        return f64::NAN;
    }
    let hub = sc.hub_state(t, y);
    sc.effectors()
        .iter()
        .find_map(|e| e.field_angle(&hub))
        .unwrap_or(f64::NAN)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::RigidBody;
    use approx::assert_relative_eq;

    #[test]
    fn momentum_energy_and_angles_of_a_known_state() {
        let sc = Spacecraft::new(
            RigidBody::from_principal([1.0, 2.0, 3.0]).unwrap(),
            Vector3::z(),
        );
        // Rotated by 90° about z: body x is inertial y.
        let q = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f64::consts::FRAC_PI_2);
        let y = sc.initial_state(&Vector3::new(1.0, 0.0, 1.0), &q);
        let o = sc.observe(0.0, &y);
        assert_relative_eq!(o.h_body, Vector3::new(1.0, 0.0, 3.0), epsilon = 1e-15);
        assert_relative_eq!(o.h_inertial, Vector3::new(0.0, 1.0, 3.0), epsilon = 1e-15);
        assert_relative_eq!(o.kinetic_energy, 0.5 * (1.0 + 3.0), epsilon = 1e-15);
        assert_relative_eq!(o.nutation_angle, (1.0f64 / 3.0).atan(), epsilon = 1e-15);
        let quarter = std::f64::consts::FRAC_PI_4;
        assert_relative_eq!(o.angles_to_principal[0], quarter, epsilon = 1e-15);
        assert_relative_eq!(o.angles_to_principal[1], 2.0 * quarter, epsilon = 1e-15);
        assert_relative_eq!(o.angles_to_principal[2], quarter, epsilon = 1e-15);
    }

    #[test]
    fn small_angles_keep_their_digits() {
        let a = Vector3::new(1.0, 0.0, 0.0);
        let b = Vector3::new(1.0, 1e-12, 0.0);
        assert_relative_eq!(angle_between(&a, &b), 1e-12, max_relative = 1e-12);
    }
}
