//! `magnetorquer:` in the scenario file: three coils along the body axes under B-dot control
//! ([`crate::effectors::magnetorquer`]).
//!
//! ```yaml
//! - magnetorquer:
//!     max_dipole: [0.2, 0.2, 0.2]                 # A m² per body axis (or one number)
//!     bdot: {gain: auto, sample_rate: 1.0}        # gain in N m s, or `auto`; Hz
//! ```
//!
//! `gain: auto` is Avanzini & Giulietti's (JGCD 35(4), 2012) k = 2 n (1 + sin ξ_m) J_min, with
//! n the orbit's mean motion, J_min the smallest principal moment of `body` and ξ_m taken as
//! the orbit's inclination (docs/actuators.md says why and what it neglects).

use super::{Check, Context, ScenarioError};
use crate::effectors::Magnetorquer;
use crate::effectors::clock::SampleClock;
use crate::effectors::magnetorquer::optimal_gain;
use nalgebra::Vector3;
use serde::Deserialize;
use serde_saphyr::Spanned;

/// `magnetorquer:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MagnetorquerSpec {
    /// Name (default `magnetorquer`).
    #[serde(default)]
    pub name: Option<String>,
    /// Largest dipole per body axis (A m²): one number for all three, or three.
    pub max_dipole: Spanned<PerAxis>,
    /// The B-dot detumbling law.
    pub bdot: BdotSpec,
}

/// One value for every body axis, or one each.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub enum PerAxis {
    /// The same for x, y and z.
    All(f64),
    /// `[x, y, z]`.
    Each([f64; 3]),
}

/// `bdot:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BdotSpec {
    /// The gain k (N m s), or `auto`.
    pub gain: Spanned<Gain>,
    /// How often the controller samples the field (Hz).
    pub sample_rate: Spanned<f64>,
}

/// A gain given as a number or as `auto`.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub enum Gain {
    /// The gain itself.
    Value(f64),
    /// A word: only `auto` is accepted.
    Word(String),
}

/// Largest dipole per axis (A m²): far above any spacecraft's coils (CubeSats carry 0.1–1,
/// large satellites hundreds).
pub const MAX_COIL_DIPOLE: f64 = 1e4;

/// Builds the magnetorquer of one `magnetorquer:` entry; `orbit` is the scenario's.
pub(super) fn build(
    ck: &Check,
    cx: &Context,
    spec: &MagnetorquerSpec,
    name: String,
    orbit: std::sync::Arc<crate::orbit::Orbit>,
    field: crate::orbit::GeomagneticField,
) -> Result<Magnetorquer, ScenarioError> {
    let max_dipole = match spec.max_dipole.value {
        PerAxis::All(v) => Vector3::repeat(v),
        PerAxis::Each(v) => Vector3::from(v),
    };
    if !max_dipole
        .iter()
        .all(|v| v.is_finite() && *v > 0.0 && *v <= MAX_COIL_DIPOLE)
    {
        return Err(ck.err(
            &spec.max_dipole,
            "max_dipole",
            format!(
                "expected positive dipoles up to {MAX_COIL_DIPOLE:e} A m² (one number, or one \
                 per body axis), got [{}, {}, {}]",
                max_dipole.x, max_dipole.y, max_dipole.z
            ),
        ));
    }
    let rate = ck.positive(&spec.bdot.sample_rate, "bdot.sample_rate", "Hz")?;
    let ticks = cx.duration * rate;
    if ticks > crate::scenario::MAX_SAMPLES {
        return Err(ck.err(
            &spec.bdot.sample_rate,
            "bdot.sample_rate",
            format!(
                "{ticks:.3e} controller samples ({:e} s at {rate:e} Hz) exceed the limit of {:e} \
                 that output samples have too; lower the rate or the duration",
                cx.duration,
                crate::scenario::MAX_SAMPLES
            ),
        ));
    }
    let gain = match &spec.bdot.gain.value {
        Gain::Value(k) => ck.positive(
            &Spanned {
                value: *k,
                referenced: spec.bdot.gain.referenced,
                defined: spec.bdot.gain.defined,
            },
            "bdot.gain",
            "N m s",
        )?,
        Gain::Word(w) if w == "auto" => optimal_gain(&orbit, &cx.hub.inertia),
        Gain::Word(w) => {
            return Err(ck.err(
                &spec.bdot.gain,
                "bdot.gain",
                format!("expected a gain (N m s) or `auto`, got `{w}`"),
            ));
        }
    };
    Ok(Magnetorquer {
        name,
        orbit,
        field,
        max_dipole,
        gain,
        clock: SampleClock::from_rate(rate),
    })
}
