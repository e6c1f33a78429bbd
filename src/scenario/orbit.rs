//! `orbit:` in the scenario file: the elements at the epoch, validated into an
//! [`crate::orbit::Orbit`], and `initial.frame: lvlh` (attitude and rates given relative to
//! the orbit frame).

use super::{ScenarioError, loc};
use crate::orbit::{CentralBody, Elements, Orbit};
use nalgebra::{UnitQuaternion, Vector3};
use serde::Deserialize;
use serde_saphyr::Spanned;
use std::path::Path;
use std::sync::Arc;

/// `orbit:` — the orbit of the spacecraft's centre of mass, by its elements at the epoch.
/// Either `semi_major_axis_km` (with `eccentricity`, default 0) or `perigee_altitude_km` and
/// `apogee_altitude_km`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OrbitSpec {
    /// The body orbited (`earth`, the default).
    #[serde(default)]
    pub central_body: Option<Spanned<String>>,
    /// Semi-major axis (km).
    #[serde(default)]
    pub semi_major_axis_km: Option<Spanned<f64>>,
    /// Perigee altitude above the equatorial radius (km).
    #[serde(default)]
    pub perigee_altitude_km: Option<Spanned<f64>>,
    /// Apogee altitude above the equatorial radius (km).
    #[serde(default)]
    pub apogee_altitude_km: Option<Spanned<f64>>,
    /// Eccentricity, 0 ≤ e < 1 (with `semi_major_axis_km`; default 0).
    #[serde(default)]
    pub eccentricity: Option<Spanned<f64>>,
    /// Inclination (degrees, default 0).
    #[serde(default)]
    pub inclination_deg: Option<Spanned<f64>>,
    /// Right ascension of the ascending node (degrees, default 0).
    #[serde(default)]
    pub raan_deg: Option<Spanned<f64>>,
    /// Argument of perigee (degrees, default 0).
    #[serde(default)]
    pub arg_perigee_deg: Option<Spanned<f64>>,
    /// True anomaly at the epoch (degrees, default 0).
    #[serde(default)]
    pub true_anomaly_deg: Option<Spanned<f64>>,
    /// Include the secular J2 drift of the node, the perigee and the mean anomaly (default
    /// false).
    #[serde(default)]
    pub j2_secular: Option<bool>,
    /// The geomagnetic field every magnetic model sees: `igrf` (IGRF-14 to degree 13,
    /// 1900–2030; the default) or `dipole` (its first degree, 1965–2030).
    #[serde(default)]
    pub magnetic_field: Option<Spanned<String>>,
}

/// The main-field model `orbit.magnetic_field` chooses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MagneticModel {
    /// IGRF-14 to degree 13.
    Igrf,
    /// IGRF-14's first degree.
    Dipole,
}

/// `orbit.magnetic_field` (default `igrf`) and where it is written.
pub(super) fn magnetic_model(
    path: &Path,
    spec: Option<&OrbitSpec>,
) -> Result<(MagneticModel, Option<(u32, u32)>), ScenarioError> {
    let Some(given) = spec.and_then(|s| s.magnetic_field.as_ref()) else {
        return Ok((MagneticModel::Igrf, None));
    };
    match given.value.as_str() {
        "igrf" => Ok((MagneticModel::Igrf, loc(given))),
        "dipole" => Ok((MagneticModel::Dipole, loc(given))),
        other => Err(ScenarioError::at(
            path,
            loc(given),
            "orbit.magnetic_field",
            format!(
                "expected `igrf` (IGRF-14 to degree 13, 1900 to 2030) or `dipole` (its first \
                 degree, 1965 to 2030), got `{other}`"
            ),
        )),
    }
}

/// Validates `orbit:` into an orbit; `block` is where the `orbit:` key is written.
pub(super) fn orbit(
    path: &Path,
    spec: &OrbitSpec,
    block: Option<(u32, u32)>,
) -> Result<Arc<Orbit>, ScenarioError> {
    let at = |s: Option<(u32, u32)>, key: &str, m: String| {
        ScenarioError::at(path, s.or(block), format!("orbit.{key}"), m)
    };
    let body = match &spec.central_body {
        None => CentralBody::EARTH,
        Some(name) => {
            CentralBody::by_name(&name.value).map_err(|m| at(loc(name), "central_body", m))?
        }
    };
    // Every number finite, first, so that the messages below can do arithmetic.
    let numbers = [
        (&spec.semi_major_axis_km, "semi_major_axis_km"),
        (&spec.perigee_altitude_km, "perigee_altitude_km"),
        (&spec.apogee_altitude_km, "apogee_altitude_km"),
        (&spec.eccentricity, "eccentricity"),
        (&spec.inclination_deg, "inclination_deg"),
        (&spec.raan_deg, "raan_deg"),
        (&spec.arg_perigee_deg, "arg_perigee_deg"),
        (&spec.true_anomaly_deg, "true_anomaly_deg"),
    ];
    for (v, key) in numbers {
        if let Some(v) = v
            && !v.value.is_finite()
        {
            return Err(at(
                loc(v),
                key,
                format!("expected a finite number, got {}", v.value),
            ));
        }
    }
    // The inclination is checked here, where its own location is known (Elements::validate
    // only has the number).
    if let Some(inc) = &spec.inclination_deg
        && !(0.0..=180.0).contains(&inc.value)
    {
        return Err(at(
            loc(inc),
            "inclination_deg",
            format!(
                "expected an inclination from 0 to 180 degrees, got {}",
                crate::timefmt::number(inc.value)
            ),
        ));
    }
    let angle = |v: &Option<Spanned<f64>>| v.as_ref().map_or(0.0, |a| a.value.to_radians());
    let (i, raan, argp, nu) = (
        angle(&spec.inclination_deg),
        angle(&spec.raan_deg),
        angle(&spec.arg_perigee_deg),
        angle(&spec.true_anomaly_deg),
    );
    let elements = match (
        &spec.semi_major_axis_km,
        &spec.perigee_altitude_km,
        &spec.apogee_altitude_km,
    ) {
        (Some(a), None, None) => {
            let e = spec.eccentricity.as_ref().map_or(0.0, |e| e.value);
            let el = Elements::new(a.value * 1e3, e, i, raan, argp, nu);
            el.validate(&body).map_err(|m| {
                let (where_, key) = match &spec.eccentricity {
                    Some(e) if !(0.0..1.0).contains(&e.value) => (loc(e), "eccentricity"),
                    _ => (loc(a), "semi_major_axis_km"),
                };
                at(where_, key, m)
            })?;
            el
        }
        (None, Some(p), Some(q)) => {
            if let Some(e) = &spec.eccentricity {
                return Err(at(
                    loc(e),
                    "eccentricity",
                    "the perigee and apogee altitudes already fix the eccentricity: give \
                     either them or `semi_major_axis_km` with `eccentricity`"
                        .into(),
                ));
            }
            Elements::from_altitudes(&body, p.value * 1e3, q.value * 1e3, i, raan, argp, nu)
                .map_err(|m| at(loc(p), "perigee_altitude_km", m))?
        }
        _ => {
            return Err(at(
                None,
                "semi_major_axis_km",
                "expected the orbit's size as `semi_major_axis_km` (with `eccentricity`, \
                 default 0), or as `perigee_altitude_km` and `apogee_altitude_km`, not both"
                    .into(),
            ));
        }
    };
    let located = spec
        .inclination_deg
        .as_ref()
        .and_then(loc)
        .or(spec.semi_major_axis_km.as_ref().and_then(loc));
    Orbit::new(body, elements, spec.j2_secular.unwrap_or(false))
        .map(Arc::new)
        .map_err(|m| at(located, "inclination_deg", m))
}

/// The frame `initial.attitude` and `initial.omega` are given in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InitialFrame {
    /// Attitude body → inertial; rates relative to inertial space (the default).
    Inertial,
    /// Attitude body → LVLH; rates relative to the LVLH frame (body axes).
    Lvlh,
}

/// Parses `initial.frame`; `lvlh` needs an orbit.
pub(super) fn initial_frame(
    path: &Path,
    frame: &Option<Spanned<String>>,
    has_orbit: bool,
) -> Result<InitialFrame, ScenarioError> {
    let Some(f) = frame else {
        return Ok(InitialFrame::Inertial);
    };
    match f.value.as_str() {
        "inertial" => Ok(InitialFrame::Inertial),
        "lvlh" if has_orbit => Ok(InitialFrame::Lvlh),
        "lvlh" => Err(ScenarioError::at(
            path,
            loc(f),
            "initial.frame",
            "`lvlh` is the orbit frame, so it needs an `orbit:` block (semi_major_axis_km or \
             perigee/apogee altitudes, inclination_deg, …)",
        )),
        other => Err(ScenarioError::at(
            path,
            loc(f),
            "initial.frame",
            format!("expected `inertial` or `lvlh`, got `{other}`"),
        )),
    }
}

/// The inertial initial state from one given relative to LVLH at t = 0: the attitude
/// body → inertial `q_NB = q_NO ⊗ q_OB`, and the body rates relative to inertial space
/// `ω_BN = ω_BO + C_BN ω_ON` (body axes), with `q_NO` the LVLH attitude and `ω_ON` its
/// angular velocity (Hughes 1986, §8.1; Wertz 1978, §2.3).
pub fn from_lvlh(
    orbit: &Orbit,
    attitude_lvlh: &UnitQuaternion<f64>,
    omega_lvlh: &Vector3<f64>,
) -> (UnitQuaternion<f64>, Vector3<f64>) {
    let frame = orbit.lvlh(0.0);
    let q_no = frame.lvlh_to_eci();
    let q_nb = q_no * attitude_lvlh;
    let omega_bn = omega_lvlh + q_nb.inverse_transform_vector(&frame.omega);
    (q_nb, omega_bn)
}
