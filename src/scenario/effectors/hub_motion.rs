//! `hub_motion:` in the scenario file: a prescribed rotation of the hub, driven by a motor
//! about an axis fixed in inertial space ([`crate::effectors::motion`]).
//!
//! ```yaml
//! hub_motion:
//!   spin_up: {axis: [0, 0, 1], rate: 6.0, ramp_time: 15.0}   # rad/s, s
//! ```
//!
//! `initial.omega` must then be the motion's rates at t = 0 (checked in `scenario`).

use super::{Check, ScenarioError};
use crate::effectors::SpinUp;
use serde::Deserialize;
use serde_saphyr::Spanned;
use std::path::Path;

/// `hub_motion:`: a prescribed hub rotation.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "snake_case")]
pub enum HubMotionSpec {
    /// The smooth spin-up of Kane, Ryan & Banerjee (1987).
    SpinUp {
        /// Spin axis (body axes).
        axis: Spanned<[f64; 3]>,
        /// Final rate (rad/s).
        rate: Spanned<f64>,
        /// Ramp duration (s).
        ramp_time: Spanned<f64>,
    },
}

/// Validates `hub_motion:` and builds the motion.
pub(in crate::scenario) fn build(
    path: &Path,
    spec: &HubMotionSpec,
) -> Result<SpinUp, ScenarioError> {
    let ck = Check {
        path,
        prefix: "hub_motion.spin_up".into(),
    };
    match spec {
        HubMotionSpec::SpinUp {
            axis,
            rate,
            ramp_time,
        } => Ok(SpinUp {
            axis: ck.unit(axis, "axis")?,
            rate: ck.finite(&Some(rate.clone()), "rate", "rad/s")?,
            ramp_time: ck.positive(ramp_time, "ramp_time", "s")?,
        }),
    }
}
