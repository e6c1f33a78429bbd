//! `slosh_pendulum:` in the scenario file: a damped spherical pendulum, the mechanical analog
//! of a tank's first lateral slosh mode ([`crate::effectors::slosh_pendulum`]).
//!
//! ```yaml
//! - slosh_pendulum:
//!     mass: 20.0                 # kg, the sloshing mass
//!     length: 0.3                # m, pivot to mass
//!     pivot: [0.0, 0.0, 0.5]     # m, body axes, about the hub's centre of mass
//!     rest_direction: [1, 0, 0]  # the rod's direction at φ = θ = 0
//!     damping: 2.0               # N s/m, on the mass's velocity relative to the body
//!     initial_angles: [0.1, 0.0] # rad, [φ, θ]
//!     initial_rates: [0.0, 0.0]  # rad/s
//! ```

use super::{Check, Context, ScenarioError};
use crate::effectors::ParticleEffector;
use crate::effectors::slosh_pendulum::{
    SINGULAR_COS_THETA, SloshPendulum, THETA_WARN_DEG, pendulum_frame,
};
use serde::Deserialize;
use serde_saphyr::Spanned;

/// `slosh_pendulum:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SloshPendulumSpec {
    /// Name (default `slosh_pendulum`).
    #[serde(default)]
    pub name: Option<String>,
    /// The sloshing mass (kg).
    pub mass: Spanned<f64>,
    /// Rod length, pivot to mass (m).
    pub length: Spanned<f64>,
    /// Pivot (m, body axes, about the hub's centre of mass, or the whole spacecraft's with
    /// `body.composite`); checked to be on or in `body.shape` when one is given.
    pub pivot: Spanned<[f64; 3]>,
    /// The rod's direction at zero angles (body axes; normalised).
    pub rest_direction: Spanned<[f64; 3]>,
    /// Dashpot on the mass's velocity relative to the body (N s/m).
    pub damping: Spanned<f64>,
    /// Initial `[φ, θ]` (rad).
    #[serde(default)]
    pub initial_angles: Option<Spanned<[f64; 2]>>,
    /// Initial `[φ̇, θ̇]` (rad/s).
    #[serde(default)]
    pub initial_rates: Option<Spanned<[f64; 2]>>,
}

/// Validates a `slosh_pendulum:` entry and builds it.
pub(super) fn build(
    ck: &Check,
    cx: &Context,
    spec: &SloshPendulumSpec,
    name: String,
) -> Result<ParticleEffector<SloshPendulum>, ScenarioError> {
    let pair = |s: &Option<Spanned<[f64; 2]>>, key: &str, unit: &str| match s {
        None => Ok([0.0; 2]),
        Some(v) if v.value.iter().all(|x| x.abs() <= super::MAX_MAGNITUDE) => Ok(v.value),
        Some(v) => Err(ck.err(
            v,
            key,
            format!(
                "expected two numbers within ±{:e} ({unit})",
                super::MAX_MAGNITUDE
            ),
        )),
    };
    let model = SloshPendulum {
        mass: ck.positive(&spec.mass, "mass", "kg")?,
        length: ck.positive(&spec.length, "length", "m")?,
        pivot: ck.on_body(&spec.pivot, "pivot", "the pendulum's pivot", cx)? + cx.shift,
        frame: pendulum_frame(ck.unit(&spec.rest_direction, "rest_direction")?),
        damping: ck.non_negative(&spec.damping, "damping", "N s/m")?,
    };
    let q0 = pair(&spec.initial_angles, "initial_angles", "rad")?;
    let u0 = pair(&spec.initial_rates, "initial_rates", "rad/s")?;
    let theta = q0[1].abs() % std::f64::consts::PI;
    let folded = theta.min(std::f64::consts::PI - theta).to_degrees();
    if folded > THETA_WARN_DEG
        && let Some(s) = &spec.initial_angles
    {
        return Err(ck.err(
            s,
            "initial_angles",
            format!(
                "θ = {} rad is {folded:.2}° from 0 or 180°, near the angles' singularity at \
                 θ = ±90° (a run stops at {:.2}°): start within {THETA_WARN_DEG}° of θ = 0 or \
                 180°, turning `rest_direction` toward the initial rod",
                q0[1],
                SINGULAR_COS_THETA.acos().to_degrees()
            ),
        ));
    }
    Ok(ParticleEffector::new(name, model, &q0, &u0))
}
