//! `wheel_damper:` in the scenario file: a viscous wheel (or ring) damper about a body axis,
//! after Kasdin & Paley ([`crate::effectors::wheel`]).
//!
//! ```yaml
//! - wheel_damper:
//!     inertia: 6.0              # kg m² about its axis, part of `body` as if locked
//!     axis: [0, 0, 1]
//!     damping: 50.0             # N m s/rad
//!     initial_rate: 0.0         # rad/s relative to the body, optional
//!     position: [0.0, 0.0, 0.6] # m, where it is drawn, optional
//!     max_speed: 100.0          # rad/s, optional: what the wheel is rated for
//! ```

use super::{Check, Context, ScenarioError};
use crate::effectors::WheelDamper;
use serde::Deserialize;
use serde_saphyr::Spanned;

/// `wheel_damper:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WheelSpec {
    /// Name (default `wheel_damper`).
    #[serde(default)]
    pub name: Option<String>,
    /// Rotor axial inertia (kg m²), included in `body` as if locked.
    pub inertia: Spanned<f64>,
    /// Rotor axis (body axes).
    pub axis: Spanned<[f64; 3]>,
    /// Viscous coefficient (N m s/rad).
    pub damping: Spanned<f64>,
    /// Initial rotor rate relative to the body (rad/s).
    #[serde(default)]
    pub initial_rate: Option<Spanned<f64>>,
    /// Where to draw it (m, body axes).
    #[serde(default)]
    pub position: Option<Spanned<[f64; 3]>>,
    /// Largest relative rotor speed the wheel is rated for (rad/s).
    #[serde(default)]
    pub max_speed: Option<Spanned<f64>>,
}

/// Validates a `wheel_damper:` entry and builds it.
pub(super) fn build(
    ck: &Check,
    cx: &Context,
    spec: &WheelSpec,
    name: String,
) -> Result<WheelDamper, ScenarioError> {
    let damper = WheelDamper {
        name,
        inertia: ck.positive(&spec.inertia, "inertia", "kg m²")?,
        axis: ck.unit(&spec.axis, "axis")?,
        damping: ck.non_negative(&spec.damping, "damping", "N m s/rad")?,
        initial_rate: ck.finite(&spec.initial_rate, "initial_rate", "rad/s")?,
        position: match &spec.position {
            Some(p) => ck.point(p, "position")? + cx.shift,
            None => cx.shift,
        },
        max_speed: spec
            .max_speed
            .as_ref()
            .map(|v| ck.positive(v, "max_speed", "rad/s"))
            .transpose()?,
    };
    // The rotor is part of the body's inertia: I − I_W â âᵀ must stay positive definite,
    // i.e. I_W âᵀ I⁻¹ â < 1 (stricter than I_W < âᵀ I â off the principal axes).
    let a = ck.unit(&spec.axis, "axis")?;
    let limit = 1.0 / a.dot(&(cx.hub.inertia_inv * a));
    if spec.inertia.value >= limit {
        return Err(ck.err(
            &spec.inertia,
            "inertia",
            format!(
                "the rotor's inertia must be less than 1 / (âᵀ I⁻¹ â) = {limit} kg m² for this \
                 axis: the body's inertia includes the rotor, and the rest of the body must \
                 keep a positive-definite inertia"
            ),
        ));
    }
    Ok(damper)
}
