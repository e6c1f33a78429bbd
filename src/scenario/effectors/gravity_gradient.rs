//! `gravity_gradient:` in the scenario file: the central body's gravity-gradient torque on
//! the hub ([`crate::effectors::gravity_gradient`]); needs `orbit:`.
//!
//! ```yaml
//! - gravity_gradient: {}     # only an optional `name`: the hub's inertia and the orbit
//!                            # give the torque
//! ```

use super::Context;
use crate::effectors::GravityGradient;
use serde::Deserialize;

/// `gravity_gradient:` — no parameters beyond a name: the hub's inertia and the orbit give
/// the torque.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GravityGradientSpec {
    /// Name (default `gravity_gradient`).
    #[serde(default)]
    pub name: Option<String>,
}

/// Builds the torque of one `gravity_gradient:` entry; `orbit` is the scenario's.
pub(super) fn build(
    cx: &Context,
    name: String,
    orbit: std::sync::Arc<crate::orbit::Orbit>,
) -> GravityGradient {
    GravityGradient {
        name,
        orbit,
        inertia: cx.hub.inertia,
    }
}
