//! `solar_pressure:` in the scenario file: solar radiation pressure on one flat plate,
//! one-sided, in the Earth's cylindrical shadow ([`crate::effectors::solar_pressure`]);
//! needs `orbit:`, and an epoch from 1950 to 2050 (the span of the solar coordinates).
//!
//! ```yaml
//! - solar_pressure:
//!     area: 2.0                          # m²
//!     normal: [1, 0, 0]                  # the sunlit face's normal, body axes
//!     center_of_pressure: [0.1, 0.0, 0.3] # m, body axes, about the hub's centre of mass
//!     specular: 0.3                      # ρs, 0 to 1
//!     diffuse: 0.2                       # ρd, 0 to 1, ρs + ρd ≤ 1
//! ```

use super::{Check, Context, ScenarioError};
use crate::effectors::SolarPressure;
use nalgebra::Vector3;
use serde::Deserialize;
use serde_saphyr::Spanned;

/// `solar_pressure:` — one flat plate in the Sun's radiation, one-sided, in the Earth's
/// cylindrical shadow.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolarPressureSpec {
    /// Name (default `solar_pressure`).
    #[serde(default)]
    pub name: Option<String>,
    /// Plate area (m²).
    pub area: Spanned<f64>,
    /// Normal of the plate's sunlit face (body axes; normalised).
    pub normal: Spanned<[f64; 3]>,
    /// Centre of pressure relative to the hub's centre of mass (m, body axes).
    pub center_of_pressure: Spanned<[f64; 3]>,
    /// Specular reflectivity ρs (0 to 1).
    pub specular: Spanned<f64>,
    /// Diffuse reflectivity ρd (0 to 1, ρs + ρd ≤ 1).
    pub diffuse: Spanned<f64>,
}

/// Largest distance of a `solar_pressure` centre of pressure from the hub's centre of mass
/// (m).
pub const MAX_PRESSURE_ARM: f64 = 1e3;
/// Unix time (s) of 2050-01-01T00:00Z, the end of the span of the low-precision solar
/// coordinates (1950–2050).
pub const SOLAR_EPHEMERIS_END_UNIX_S: f64 = 2_524_608_000.0;
/// 1950-01-01T00:00:00Z as Unix seconds: the start of the same span.
pub const SOLAR_EPHEMERIS_START_UNIX_S: f64 = -631_152_000.0;

/// Validates a `solar_pressure:` entry and builds it; `orbit` is the scenario's, `item`
/// where the list item starts.
pub(super) fn build(
    ck: &Check,
    cx: &Context,
    spec: &SolarPressureSpec,
    name: String,
    orbit: std::sync::Arc<crate::orbit::Orbit>,
    item: Option<(u32, u32)>,
) -> Result<SolarPressure, ScenarioError> {
    let area = ck.positive(&spec.area, "area", "m²")?;
    let Some(n) = crate::scenario::unit_vector(&Vector3::from(spec.normal.value)) else {
        let num = crate::timefmt::number;
        return Err(ck.err(
            &spec.normal,
            "normal",
            format!(
                "expected a non-zero vector of three finite numbers (body axes), got [{}, {}, {}]",
                num(spec.normal.value[0]),
                num(spec.normal.value[1]),
                num(spec.normal.value[2])
            ),
        ));
    };
    let r_cp = Vector3::from(spec.center_of_pressure.value);
    if !r_cp.iter().all(|c| c.is_finite()) || r_cp.norm() > MAX_PRESSURE_ARM {
        return Err(ck.err(
            &spec.center_of_pressure,
            "center_of_pressure",
            format!(
                "expected three finite numbers within {MAX_PRESSURE_ARM:e} m of the centre of \
                 mass (m, body axes), got [{}, {}, {}]",
                spec.center_of_pressure.value[0],
                spec.center_of_pressure.value[1],
                spec.center_of_pressure.value[2]
            ),
        ));
    }
    let mut rho = [0.0; 2];
    for (k, (v, key)) in [(&spec.specular, "specular"), (&spec.diffuse, "diffuse")]
        .into_iter()
        .enumerate()
    {
        if !(0.0..=1.0).contains(&v.value) {
            return Err(ck.err(
                v,
                key,
                format!(
                    "expected a reflectivity from 0 to 1, got {}",
                    crate::scenario::number(v.value)
                ),
            ));
        }
        rho[k] = v.value;
    }
    if rho[0] + rho[1] > 1.0 {
        return Err(ck.err(
            &spec.diffuse,
            "diffuse",
            format!(
                "expected specular + diffuse at most 1 (the rest is absorbed), got {} + {} = {}",
                rho[0],
                rho[1],
                rho[0] + rho[1]
            ),
        ));
    }
    let epoch_s = cx.epoch_unix_ns as f64 * 1e-9;
    if !(SOLAR_EPHEMERIS_START_UNIX_S..SOLAR_EPHEMERIS_END_UNIX_S).contains(&epoch_s) {
        return Err(ScenarioError::at(
            cx.path,
            cx.epoch_loc.or(item),
            "epoch",
            "the low-precision solar coordinates (Vallado Algorithm 29) hold from 1950 to 2050: \
             choose an epoch from 1950-01-01 to before 2050-01-01",
        ));
    }
    Ok(SolarPressure {
        name,
        orbit,
        epoch_unix_ns: cx.epoch_unix_ns,
        area,
        normal: n,
        center_of_pressure: r_cp + cx.shift,
        specular: rho[0],
        diffuse: rho[1],
    })
}
