//! `energy_sink:` in the scenario file: the quasi-rigid model of internal dissipation
//! ([`crate::effectors::energy_sink`]).
//!
//! ```yaml
//! - energy_sink:
//!     time_constant: 2117.2   # s, target nutation time constant about the initial spin
//!     # or coefficient: 0.05  # N m s/rad, the coefficient c itself
//! ```
//!
//! It keeps |H| only alone among effectors that carry momentum: the cross-kind check in
//! `effectors.rs` refuses the combination.

use super::{Check, Context, ScenarioError};
use crate::effectors::EnergySink;
use serde::Deserialize;
use serde_saphyr::Spanned;

/// `energy_sink:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnergySinkSpec {
    /// Name (default `energy_sink`).
    #[serde(default)]
    pub name: Option<String>,
    /// Coefficient c (N m s/rad).
    #[serde(default)]
    pub coefficient: Option<Spanned<f64>>,
    /// Target nutation time constant (s), instead of `coefficient`: c is solved so that the
    /// linearised nutation mode about the initial spin grows or decays as e^{±t/τ}.
    #[serde(default)]
    pub time_constant: Option<Spanned<f64>>,
}

/// Validates an `energy_sink:` entry and builds it; `item` is where the list item starts.
pub(super) fn build(
    ck: &Check,
    cx: &Context,
    spec: &EnergySinkSpec,
    name: String,
    item: Option<(u32, u32)>,
) -> Result<EnergySink, ScenarioError> {
    let coefficient = match (&spec.coefficient, &spec.time_constant) {
        (Some(c), None) => ck.positive(c, "coefficient", "N m s/rad")?,
        (None, Some(t)) => {
            let tau = ck.positive(t, "time_constant", "s")?;
            crate::linearize::energy_sink_coefficient(
                cx.hub,
                cx.spin_axis,
                cx.omega0.dot(&cx.spin_axis),
                tau,
            )
            .map_err(|m| ck.err(t, "time_constant", m))?
        }
        _ => {
            return Err(ScenarioError::at(
                cx.path,
                item,
                ck.prefix.clone(),
                "expected exactly one of `coefficient` (N m s/rad) or `time_constant` (s)",
            ));
        }
    };
    Ok(EnergySink {
        name,
        coefficient,
        inertia: cx.hub.inertia,
    })
}
