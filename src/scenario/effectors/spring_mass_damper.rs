//! `spring_mass_damper:` in the scenario file: a particle on a line fixed in the body, with a
//! spring and a dashpot ([`crate::effectors::spring_mass`]).
//!
//! ```yaml
//! - spring_mass_damper:
//!     mass: 52.744              # kg
//!     position: [1.0, 0.0, 0.0] # m, body axes: the line's point at zero offset
//!     direction: [0, 0, 1]      # the line (here parallel to the spin axis)
//!     stiffness: 52.744         # N/m
//!     damping: 105.49           # N s/m
//!     initial_offset: 0.01      # m, optional
//!     travel: 0.2               # m, optional: what the stops allow
//! ```

use super::{Check, Context, ScenarioError};
use crate::effectors::{ParticleEffector, SpringMass};
use serde::Deserialize;
use serde_saphyr::Spanned;

/// `spring_mass_damper:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpringMassSpec {
    /// Name (default `spring_mass_damper`).
    #[serde(default)]
    pub name: Option<String>,
    /// Particle mass (kg).
    pub mass: Spanned<f64>,
    /// Point of the line at zero offset (m, body axes, about the hub's centre of mass, or the
    /// whole spacecraft's with `body.composite`).
    pub position: Spanned<[f64; 3]>,
    /// Direction of the line (body axes).
    pub direction: Spanned<[f64; 3]>,
    /// Spring stiffness (N/m).
    pub stiffness: Spanned<f64>,
    /// Dashpot coefficient (N s/m).
    pub damping: Spanned<f64>,
    /// Initial offset (m).
    #[serde(default)]
    pub initial_offset: Option<Spanned<f64>>,
    /// Initial rate (m/s).
    #[serde(default)]
    pub initial_rate: Option<Spanned<f64>>,
    /// Travel |offset| the damper's stops allow (m); beyond it the model does not hold.
    #[serde(default)]
    pub travel: Option<Spanned<f64>>,
}

/// Validates a `spring_mass_damper:` entry and builds it.
pub(super) fn build(
    ck: &Check,
    cx: &Context,
    spec: &SpringMassSpec,
    name: String,
) -> Result<ParticleEffector<SpringMass>, ScenarioError> {
    let model = SpringMass {
        mass: ck.positive(&spec.mass, "mass", "kg")?,
        position: ck.on_body(&spec.position, "position", "the line's point", cx)? + cx.shift,
        direction: ck.unit(&spec.direction, "direction")?,
        stiffness: ck.non_negative(&spec.stiffness, "stiffness", "N/m")?,
        damping: ck.non_negative(&spec.damping, "damping", "N s/m")?,
        travel: spec
            .travel
            .as_ref()
            .map(|t| ck.positive(t, "travel", "m"))
            .transpose()?,
    };
    let q0 = ck.finite(&spec.initial_offset, "initial_offset", "m")?;
    let u0 = ck.finite(&spec.initial_rate, "initial_rate", "m/s")?;
    Ok(ParticleEffector::new(name, model, &[q0], &[u0]))
}
