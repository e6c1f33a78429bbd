//! `initial:`: the body rates and attitude at sim time 0 as written, validated into ω₀ and q₀
//! (before an orbit's LVLH frame, if any, turns them inertial).

use super::{MAX_RATE, ScenarioError, finite3, key_location, loc, loc_of};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use serde::Deserialize;
use serde_saphyr::Spanned;
use std::path::Path;

/// `initial:` state at sim time 0.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialSpec {
    /// Body rates (rad/s).
    #[serde(default)]
    pub omega: Option<Spanned<[f64; 3]>>,
    /// Body rates (rev/min), instead of `omega`.
    #[serde(default)]
    pub omega_rpm: Option<Spanned<[f64; 3]>>,
    /// Attitude, body → inertial (default identity); body → LVLH with `frame: lvlh`.
    #[serde(default)]
    pub attitude: Option<Spanned<QuaternionSpec>>,
    /// `inertial` (default) or `lvlh`: the frame `attitude` and the rates are relative to.
    #[serde(default)]
    pub frame: Option<Spanned<String>>,
}

/// A quaternion by named components (scalar `w`).
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QuaternionSpec {
    /// Scalar part.
    pub w: f64,
    /// Vector part, x.
    pub x: f64,
    /// Vector part, y.
    pub y: f64,
    /// Vector part, z.
    pub z: f64,
}

/// Distance of a given quaternion's norm from 1 up to which it is normalised silently
/// (rounding in digits written out in full).
pub const QUATERNION_NORM_SILENT: f64 = 1e-6;
/// Distance of a given quaternion's norm from 1 past which it is refused: a quaternion typed
/// to four digits, {w: 0.7071, x: 0, y: 0.7071, z: 0}, has norm 0.99999 and is normalised
/// with a warning; one off by more than a thousandth is more likely a mistake.
pub const QUATERNION_NORM_REFUSE: f64 = 1e-3;

/// The body rates ω₀ (rad/s), the attitude q₀, and a warning about the attitude as given.
pub(super) type InitialState = (Vector3<f64>, UnitQuaternion<f64>, Option<ScenarioError>);

impl InitialSpec {
    /// The body rates ω₀ (rad/s) and the attitude q₀ (body → the frame of `frame:`), checked:
    /// one of `omega` and `omega_rpm`, finite, |ω₀| at most [`MAX_RATE`], and a quaternion
    /// whose norm is within [`QUATERNION_NORM_REFUSE`] of 1 (normalised; a located warning
    /// past [`QUATERNION_NORM_SILENT`], returned beside). `source` is the file's text, to
    /// place an error about a missing key.
    pub(super) fn state(&self, path: &Path, source: &str) -> Result<InitialState, ScenarioError> {
        let err = |l: Option<(u32, u32)>, field: &str, msg: String| {
            ScenarioError::at(path, l, field, msg)
        };
        let omega0 = match (&self.omega, &self.omega_rpm) {
            (Some(_), Some(r)) => {
                return Err(err(
                    loc(r),
                    "initial.omega_rpm",
                    "give either `omega` (rad/s) or `omega_rpm`, not both".into(),
                ));
            }
            (Some(w), None) => {
                if !finite3(&w.value) {
                    return Err(err(
                        loc(w),
                        "initial.omega",
                        "expected three finite numbers (rad/s)".into(),
                    ));
                }
                let w = Vector3::from(w.value);
                check_rate(&w).map_err(|m| err(loc_of(&self.omega), "initial.omega", m))?;
                w
            }
            (None, Some(r)) => {
                if !finite3(&r.value) {
                    return Err(err(
                        loc(r),
                        "initial.omega_rpm",
                        "expected three finite numbers (rev/min)".into(),
                    ));
                }
                let w = Vector3::from(r.value) * (2.0 * std::f64::consts::PI / 60.0);
                check_rate(&w).map_err(|m| err(loc_of(&self.omega_rpm), "initial.omega_rpm", m))?;
                w
            }
            (None, None) => {
                return Err(err(
                    key_location(source, "initial"),
                    "initial",
                    "missing the body rates: expected `omega: [wx, wy, wz]` (rad/s) or \
                 `omega_rpm: [..]`"
                        .into(),
                ));
            }
        };
        let mut note = None;
        let attitude0 = match &self.attitude {
            None => UnitQuaternion::identity(),
            Some(a) => {
                let q = Quaternion::new(a.value.w, a.value.x, a.value.y, a.value.z);
                let n = q.norm();
                // Six decimals, trailing zeros dropped: 0.99999, 0.989949, 0.
                let short = format!("{n:.6}");
                let short = short.trim_end_matches('0').trim_end_matches('.');
                if !q.coords.iter().all(|c| c.is_finite())
                    || (n - 1.0).abs() > QUATERNION_NORM_REFUSE
                {
                    return Err(err(
                        loc(a),
                        "initial.attitude",
                        format!(
                            "expected a unit quaternion {{w, x, y, z}} (norm within \
                             {QUATERNION_NORM_REFUSE:e} of 1, then normalised), got norm {short}"
                        ),
                    ));
                }
                if (n - 1.0).abs() > QUATERNION_NORM_SILENT {
                    note = Some(err(
                        loc(a),
                        "initial.attitude",
                        format!(
                            "the quaternion's norm is {short} (hand-typed digits?): normalised to \
                             {{w: {:.9}, x: {:.9}, y: {:.9}, z: {:.9}}}",
                            q.w / n,
                            q.i / n,
                            q.j / n,
                            q.k / n
                        ),
                    ));
                }
                UnitQuaternion::from_quaternion(q)
            }
        };
        Ok((omega0, attitude0, note))
    }
}

/// Refuses initial body rates beyond [`MAX_RATE`].
pub(super) fn check_rate(w: &Vector3<f64>) -> Result<(), String> {
    // Scaled, so that huge components do not overflow the norm.
    let m = w.amax();
    let n = if m > 0.0 { m * (w / m).norm() } else { 0.0 };
    if n > MAX_RATE {
        Err(format!(
            "|ω| = {n:e} rad/s is beyond the {MAX_RATE:e} rad/s polhode supports (is it in \
             deg/s or rev/min? `omega` is rad/s, `omega_rpm` rev/min)"
        ))
    } else {
        Ok(())
    }
}
