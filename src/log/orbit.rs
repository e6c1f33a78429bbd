//! `polhode.Orbit`: the spacecraft's orbit and its attitude relative to the LVLH frame, one
//! flat protobuf message of doubles per sample (as `polhode.Telemetry`), written only for
//! scenarios with an `orbit:`.
//!
//! Units and descriptions are those of [`units::ORBIT`] in [`units::field_unit`]. The
//! attitude relative to LVLH is `q_OB = q_NO⁻¹ ⊗ q_NB` (body → LVLH, scalar first, sign with
//! `w ≥ 0`), and its 3-2-1 Euler angles are the aerospace sequence (Wertz 1978, §12.1 and
//! appendix E; Sidi 1997): yaw ψ about `o3`, then pitch θ about the new 2 axis, then
//! roll φ about the new 1 axis, `R(q_OB) = R_z(ψ) R_y(θ) R_x(φ)`; φ, ψ in (−180°, 180°],
//! θ in [−90°, 90°]. The body's rate relative to LVLH is `ω_BO = ω_BN − C_BN ω_ON` in body
//! components (`ω_ON` the LVLH frame's rate, [`crate::orbit::Lvlh::omega`]).
//!
//! The attitude relative to LVLH, [`ATTITUDE_FIELDS`] (the last ten of [`FIELDS`]), is also a
//! set of columns of the sample tables and the Python `Result` ([`super::samples`]), computed by
//! the same [`attitude_values`].

use super::{telemetry, units};
use crate::orbit::Orbit;
use nalgebra::{UnitQuaternion, Vector3};

/// Fully qualified schema name.
pub const SCHEMA_NAME: &str = "polhode.Orbit";

/// Field names in field-number order (field `i` has number `i + 1`).
pub const FIELDS: [&str; 19] = [
    "sim_time",
    "r_eci_x",
    "r_eci_y",
    "r_eci_z",
    "v_eci_x",
    "v_eci_y",
    "v_eci_z",
    "altitude",
    "argument_of_latitude_deg",
    "q_lvlh_w",
    "q_lvlh_x",
    "q_lvlh_y",
    "q_lvlh_z",
    "roll_deg",
    "pitch_deg",
    "yaw_deg",
    "omega_lvlh_x",
    "omega_lvlh_y",
    "omega_lvlh_z",
];

/// Index in [`FIELDS`] of the first of [`ATTITUDE_FIELDS`].
pub const ATTITUDE_START: usize = 9;

/// The attitude relative to LVLH: `q_OB`, its 3-2-1 angles (deg) and `ω_BO` (rad/s, body
/// axes); the columns the sample tables add for a scenario with an orbit.
pub const ATTITUDE_FIELDS: [&str; 10] = [
    "q_lvlh_w",
    "q_lvlh_x",
    "q_lvlh_y",
    "q_lvlh_z",
    "roll_deg",
    "pitch_deg",
    "yaw_deg",
    "omega_lvlh_x",
    "omega_lvlh_y",
    "omega_lvlh_z",
];

/// The serialized `FileDescriptorSet` of [`FIELDS`] as proto3 doubles.
pub fn schema_bytes() -> Vec<u8> {
    telemetry::schema_for("polhode", "Orbit", units::ORBIT, &FIELDS)
}

/// The body attitude relative to LVLH, `q_OB = q_NO⁻¹ ⊗ q_NB` (it maps body components to
/// LVLH components), with the sign chosen so that `w ≥ 0`.
pub fn body_in_lvlh(
    lvlh_to_eci: &UnitQuaternion<f64>,
    attitude: &UnitQuaternion<f64>,
) -> UnitQuaternion<f64> {
    let q = lvlh_to_eci.inverse() * attitude;
    if q.w < 0.0 {
        UnitQuaternion::new_unchecked(-q.into_inner())
    } else {
        q
    }
}

/// The 3-2-1 Euler angles `(roll φ, pitch θ, yaw ψ)` (rad) of a rotation `q` with
/// `R(q) = R_z(ψ) R_y(θ) R_x(φ)`: φ, ψ in (−π, π], θ in [−π/2, π/2].
pub fn euler_321(q: &UnitQuaternion<f64>) -> (f64, f64, f64) {
    let (w, x, y, z) = (q.w, q.i, q.j, q.k);
    let roll = (2.0 * (w * x + y * z)).atan2(1.0 - 2.0 * (x * x + y * y));
    let pitch = (2.0 * (w * y - z * x)).clamp(-1.0, 1.0).asin();
    let yaw = (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z));
    (roll, pitch, yaw)
}

/// The values of [`ATTITUDE_FIELDS`] at sim time `t` (s) for the body attitude `attitude`
/// (`q_NB`) and body rate `omega` (`ω_BN`, rad/s, body axes): `q_OB`, roll, pitch, yaw (deg),
/// `ω_BO` (rad/s, body axes).
pub fn attitude_values(
    orbit: &Orbit,
    t: f64,
    attitude: &UnitQuaternion<f64>,
    omega: &Vector3<f64>,
) -> [f64; 10] {
    let lvlh = orbit.lvlh(t);
    let q = body_in_lvlh(&lvlh.lvlh_to_eci(), attitude);
    let (roll, pitch, yaw) = euler_321(&q);
    let omega_rel = omega - attitude.inverse_transform_vector(&lvlh.omega);
    [
        q.w,
        q.i,
        q.j,
        q.k,
        roll.to_degrees(),
        pitch.to_degrees(),
        yaw.to_degrees(),
        omega_rel.x,
        omega_rel.y,
        omega_rel.z,
    ]
}

/// The values of [`FIELDS`] at sim time `t` (s) for the body attitude `attitude` (`q_NB`)
/// and body rate `omega` (`ω_BN`, rad/s, body axes).
pub fn values(
    orbit: &Orbit,
    t: f64,
    attitude: &UnitQuaternion<f64>,
    omega: &Vector3<f64>,
) -> [f64; 19] {
    let (r, v) = orbit.state(t);
    let mut out = [0.0; 19];
    out[..ATTITUDE_START].copy_from_slice(&[
        t,
        r[0] / 1e3,
        r[1] / 1e3,
        r[2] / 1e3,
        v[0] / 1e3,
        v[1] / 1e3,
        v[2] / 1e3,
        orbit.altitude(t) / 1e3,
        orbit.argument_of_latitude(t).to_degrees(),
    ]);
    out[ATTITUDE_START..].copy_from_slice(&attitude_values(orbit, t, attitude, omega));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn euler_angles_follow_the_3_2_1_sequence() {
        let (roll, pitch, yaw) = (0.3_f64, -0.7_f64, 2.5_f64);
        let q = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw)
            * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), pitch)
            * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), roll);
        let (r, p, y) = euler_321(&q);
        assert!((r - roll).abs() < 1e-12 && (p - pitch).abs() < 1e-12 && (y - yaw).abs() < 1e-12);
        // Independent of the quaternion's sign.
        let (r2, p2, y2) = euler_321(&UnitQuaternion::new_unchecked(-q.into_inner()));
        assert!((r2 - r).abs() < 1e-12 && (p2 - p).abs() < 1e-12 && (y2 - y).abs() < 1e-12);
    }

    #[test]
    fn body_in_lvlh_undoes_the_lvlh_attitude() {
        let q_no = UnitQuaternion::from_euler_angles(0.4, -1.1, 2.9);
        let q_ob = UnitQuaternion::from_euler_angles(-0.2, 0.1, -3.0);
        let q = body_in_lvlh(&q_no, &(q_no * q_ob));
        assert!(q.w >= 0.0);
        assert!(q.angle_to(&q_ob) < 1e-12);
    }

    #[test]
    fn the_attitude_fields_are_the_tail_of_the_fields() {
        assert_eq!(FIELDS[ATTITUDE_START..], ATTITUDE_FIELDS);
    }

    #[test]
    fn every_field_has_a_unit() {
        for f in FIELDS {
            let (d, u) = units::field_unit(units::ORBIT, f).unwrap_or_else(|| panic!("{f}"));
            assert!(!d.is_empty() && !u.is_empty(), "{f}");
        }
    }
}
