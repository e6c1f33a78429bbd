//! `magnetic_dipole:` in the scenario file: a constant (residual) dipole moment on the hub
//! in the first-degree IGRF field of the Earth ([`crate::effectors::magnetic_dipole`]);
//! needs `orbit:`, and an epoch within the field model's years.
//!
//! ```yaml
//! - magnetic_dipole:
//!     moment: [0.05, 0.0, 0.0]   # A m², body axes
//! ```

use super::{Check, Context, ScenarioError, geomagnetic_field};
use crate::effectors::MagneticDipole;
use nalgebra::Vector3;
use serde::Deserialize;
use serde_saphyr::Spanned;

/// `magnetic_dipole:` — a constant (residual) dipole moment on the hub in the first-degree
/// IGRF field of the Earth.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MagneticDipoleSpec {
    /// Name (default `magnetic_dipole`).
    #[serde(default)]
    pub name: Option<String>,
    /// The dipole moment (A m², body axes).
    pub moment: Spanned<[f64; 3]>,
}

/// Largest magnitude of a `magnetic_dipole` moment (A m²): far above any spacecraft's
/// magnetorquers (tens to hundreds of A m²).
pub const MAX_DIPOLE_MOMENT: f64 = 1e4;

/// Validates a `magnetic_dipole:` entry and builds it; `orbit` is the scenario's, `item`
/// where the list item starts.
pub(super) fn build(
    ck: &Check,
    cx: &Context,
    spec: &MagneticDipoleSpec,
    name: String,
    orbit: std::sync::Arc<crate::orbit::Orbit>,
    item: Option<(u32, u32)>,
) -> Result<MagneticDipole, ScenarioError> {
    let v = Vector3::from(spec.moment.value);
    if !v.iter().all(|c| c.is_finite()) || v.norm() > MAX_DIPOLE_MOMENT {
        return Err(ck.err(
            &spec.moment,
            "moment",
            format!(
                "expected three finite numbers with magnitude at most {MAX_DIPOLE_MOMENT:e} \
                 (A m², body axes), got [{}, {}, {}]",
                spec.moment.value[0], spec.moment.value[1], spec.moment.value[2]
            ),
        ));
    }
    let field = geomagnetic_field(cx, item)?;
    Ok(MagneticDipole {
        name,
        orbit,
        field,
        moment: v,
    })
}
