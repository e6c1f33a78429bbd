//! `hysteresis_rod:` in the scenario file: a soft-magnetic rod along a body axis whose flux
//! density follows the field along it through a hysteresis loop
//! ([`crate::effectors::hysteresis_rod`]); needs `orbit:`, and an epoch within the field
//! model's years.
//!
//! ```yaml
//! - hysteresis_rod:
//!     axis: [1, 0, 0]          # body axes
//!     length: 0.095            # m  (or volume: m^3 instead of length and diameter)
//!     diameter: 0.001          # m
//!     coercivity: 12           # A/m, apparent (the rod's, shape demagnetisation included)
//!     remanence: 0.35          # T, apparent
//!     saturation: 0.74         # T, apparent
//!     # properties: material   # the three above are the material's instead; needs length
//!                              # and diameter (the rod's demagnetising factor converts them)
//!     # conductivity: 1.72e6   # S/m, for the eddy-current validity check (HyMu-80's)
//!     # minor_loops: {q0: 0, p: 2}   # Flatley & Henretty's shape constants
//! ```

use super::{Check, Context, ScenarioError, geomagnetic_field};
use crate::effectors::HysteresisRod;
use crate::effectors::eddy_currents::AmbientField;
use crate::effectors::hysteresis_rod::{
    DEFAULT_P, DEFAULT_Q0, HYMU80_CONDUCTIVITY, HysteresisLoop, RodConductor, demagnetising_factor,
};
use serde::Deserialize;
use serde_saphyr::Spanned;
use std::f64::consts::PI;

/// `hysteresis_rod:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HysteresisRodSpec {
    /// Name (default `hysteresis_rod`).
    #[serde(default)]
    pub name: Option<String>,
    /// The rod's axis (body axes; normalised).
    pub axis: Spanned<[f64; 3]>,
    /// Volume (m³), instead of `length` and `diameter`.
    #[serde(default)]
    pub volume: Option<Spanned<f64>>,
    /// Length (m), with `diameter`.
    #[serde(default)]
    pub length: Option<Spanned<f64>>,
    /// Diameter (m), with `length`.
    #[serde(default)]
    pub diameter: Option<Spanned<f64>>,
    /// Coercivity H_c (A/m), apparent unless `properties: material`.
    pub coercivity: Spanned<f64>,
    /// Remanence B_r (T), below `saturation`; apparent unless `properties: material`.
    pub remanence: Spanned<f64>,
    /// Saturation flux density B_s (T); apparent unless `properties: material`.
    pub saturation: Spanned<f64>,
    /// Whether the loop is the rod's (`apparent`, the default) or its material's (`material`,
    /// converted with the rod's demagnetising factor from `length` and `diameter`).
    #[serde(default)]
    pub properties: Option<Spanned<String>>,
    /// Electrical conductivity (S/m) for the eddy-current validity check (default HyMu-80's,
    /// 1.72e6 S/m); needs `diameter`.
    #[serde(default)]
    pub conductivity: Option<Spanned<f64>>,
    /// Flatley & Henretty's minor-loop constants (default q0 = 0, p = 2).
    #[serde(default)]
    pub minor_loops: Option<MinorLoopsSpec>,
}

/// `minor_loops:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MinorLoopsSpec {
    /// Recoil slope q₀, from 0 to 1.
    pub q0: Spanned<f64>,
    /// Exponent p, positive.
    pub p: Spanned<f64>,
}

/// Largest saturation flux density accepted (T): above any soft-magnetic alloy's (permendur
/// saturates near 2.4 T).
pub const MAX_SATURATION: f64 = 3.0;

/// Validates a `hysteresis_rod:` entry and builds it; `orbit` is the scenario's, `item`
/// where the list item starts.
pub(super) fn build(
    ck: &Check,
    cx: &Context,
    spec: &HysteresisRodSpec,
    name: String,
    orbit: std::sync::Arc<crate::orbit::Orbit>,
    item: Option<(u32, u32)>,
) -> Result<HysteresisRod, ScenarioError> {
    let axis = ck.unit(&spec.axis, "axis")?;
    let material = match &spec.properties {
        None => false,
        Some(p) => match p.value.as_str() {
            "apparent" => false,
            "material" => true,
            other => {
                return Err(ck.err(
                    p,
                    "properties",
                    format!("expected `apparent` or `material`, got `{other}`"),
                ));
            }
        },
    };
    let mut aspect = None;
    let mut radius = None;
    let volume = match (&spec.volume, &spec.length, &spec.diameter) {
        (Some(v), None, None) => ck.positive(v, "volume", "m^3")?,
        (None, Some(l), Some(d)) => {
            let l = ck.positive(l, "length", "m")?;
            let d = ck.positive(d, "diameter", "m")?;
            aspect = Some(l / d);
            radius = Some(0.5 * d);
            0.25 * PI * d * d * l
        }
        _ => {
            return Err(ScenarioError::at(
                cx.path,
                item,
                ck.prefix.clone(),
                "expected either `volume` (m^3) or `length` and `diameter` (m)",
            ));
        }
    };
    let coercivity = ck.positive(&spec.coercivity, "coercivity", "A/m")?;
    let remanence = ck.positive(&spec.remanence, "remanence", "T")?;
    let saturation = ck.positive(&spec.saturation, "saturation", "T")?;
    if saturation > MAX_SATURATION {
        return Err(ck.err(
            &spec.saturation,
            "saturation",
            format!(
                "expected at most {MAX_SATURATION} T (soft-magnetic alloys saturate below \
                 2.4 T), got {saturation}"
            ),
        ));
    }
    if remanence >= saturation {
        return Err(ck.err(
            &spec.remanence,
            "remanence",
            format!(
                "expected a remanence below the saturation {saturation} T (the loop's \
                 k = tan(π B_r/(2 B_s))/H_c needs B_r < B_s), got {remanence} T"
            ),
        ));
    }
    let mut hysteresis = HysteresisLoop::new(coercivity, remanence, saturation);
    // The material loop becomes the rod's through its demagnetising factor.
    let demagnetising = match (material, aspect) {
        (false, _) => None,
        (true, Some(m)) => Some(demagnetising_factor(m)),
        (true, None) => {
            return Err(ck.err(
                spec.properties
                    .as_ref()
                    .expect("material is set by `properties`"),
                "properties",
                "expected `length` and `diameter` with `properties: material` (the \
                 demagnetising factor needs the rod's length-to-diameter ratio), got `volume`",
            ));
        }
    };
    if let Some(m) = &spec.minor_loops {
        let q0 = m.q0.value;
        if !(0.0..=1.0).contains(&q0) {
            return Err(ck.err(
                &m.q0,
                "minor_loops.q0",
                format!(
                    "expected a recoil slope from 0 to 1, got {}",
                    super::super::number(q0)
                ),
            ));
        }
        hysteresis.q0 = q0;
        hysteresis.p = ck.positive(&m.p, "minor_loops.p", "1")?;
    } else {
        hysteresis.q0 = DEFAULT_Q0;
        hysteresis.p = DEFAULT_P;
    }
    if let Some(n) = demagnetising {
        hysteresis = hysteresis.apparent(n);
    }
    let conductivity = match &spec.conductivity {
        Some(c) => ck.positive(c, "conductivity", "S/m")?,
        None => HYMU80_CONDUCTIVITY,
    };
    let conductor = radius.map(|radius| RodConductor {
        radius,
        conductivity,
    });
    let field = geomagnetic_field(cx, item)?;
    Ok(HysteresisRod {
        name,
        field: AmbientField::Geomagnetic { orbit, field },
        axis,
        volume,
        hysteresis,
        conductor,
    })
}
