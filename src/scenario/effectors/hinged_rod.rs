//! `hinged_rod:` in the scenario file: a rigid rod on a hinge with torsional springs and
//! dampers, free to flap, lag or both ([`crate::effectors::hinged_rod`]).
//!
//! ```yaml
//! - hinged_rod:
//!     mass: 0.139                # kg
//!     length: 0.56               # m
//!     hinge: [0.0, 0.076, 0.1]   # m, body axes: on or in `body.shape` when one is given
//!     direction: [0, 1, 0]       # the rod at rest
//!     axis: [0, 0, 1]            # ⊥ direction: lag turns about it, flap tips toward it
//!     freedom: flap_lag          # or flap, or lag
//!     stiffness: 0.565           # N m/rad, one value or [flap, lag]
//!     damping: 6.0e-4            # N m s/rad, one value or [flap, lag]
//!     initial_angles: [0.1, 0.0] # rad, [flap, lag], optional
//!     copies: {count: 4, about: [0, 0, 1]}
//! ```

use super::{
    Check, Context, CopiesSpec, MAX_MAGNITUDE, ScenarioError, check_copies_on_body, copy_name,
};
use crate::effectors::{HingeFreedom, HingedRod, ParticleEffector};
use crate::model::Effector;
use serde::Deserialize;
use serde_saphyr::Spanned;

/// A scalar applied to both hinge angles, or `[flap, lag]`.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(untagged)]
pub enum PerAngle {
    /// The same value for flap and lag.
    Both(f64),
    /// `[flap, lag]`.
    Each([f64; 2]),
}

impl PerAngle {
    fn pair(self) -> [f64; 2] {
        match self {
            PerAngle::Both(x) => [x, x],
            PerAngle::Each(p) => p,
        }
    }
}

/// `hinged_rod:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HingedRodSpec {
    /// Name (default `hinged_rod`).
    #[serde(default)]
    pub name: Option<String>,
    /// Rod mass (kg).
    pub mass: Spanned<f64>,
    /// Rod length (m).
    pub length: Spanned<f64>,
    /// Hinge point (m, body axes, about the hub's centre of mass, or the whole spacecraft's
    /// with `body.composite`); checked to be on or in `body.shape` when one is given.
    pub hinge: Spanned<[f64; 3]>,
    /// Rest direction of the rod (body axes).
    pub direction: Spanned<[f64; 3]>,
    /// Hinge axis (⊥ direction): lag turns about it, flap tips toward it.
    pub axis: Spanned<[f64; 3]>,
    /// `flap_lag` (default), `flap` or `lag`.
    #[serde(default)]
    pub freedom: Option<Spanned<String>>,
    /// Torsional stiffness (N m/rad), one value or `[flap, lag]`.
    pub stiffness: Spanned<PerAngle>,
    /// Torsional damping (N m s/rad), one value or `[flap, lag]`.
    pub damping: Spanned<PerAngle>,
    /// Initial `[flap, lag]` angles (rad).
    #[serde(default)]
    pub initial_angles: Option<Spanned<[f64; 2]>>,
    /// Initial `[flap, lag]` rates (rad/s).
    #[serde(default)]
    pub initial_rates: Option<Spanned<[f64; 2]>>,
    /// Copies turned about an axis.
    #[serde(default)]
    pub copies: Option<CopiesSpec>,
}

/// Validates a `hinged_rod:` entry and builds its rods (one per copy) into `out`; `name` is
/// the base name the copies are numbered from.
pub(super) fn build(
    ck: &Check,
    cx: &Context,
    spec: &HingedRodSpec,
    name: String,
    out: &mut Vec<Box<dyn Effector>>,
) -> Result<(), ScenarioError> {
    let freedom = match spec.freedom.as_ref().map(|f| f.value.as_str()) {
        None | Some("flap_lag") => HingeFreedom::FlapLag,
        Some("flap") => HingeFreedom::Flap,
        Some("lag") => HingeFreedom::Lag,
        Some(other) => {
            let f = spec.freedom.as_ref().expect("present");
            return Err(ck.err(
                f,
                "freedom",
                format!("unknown freedom `{other}`, expected flap_lag, flap or lag"),
            ));
        }
    };
    let mass = ck.positive(&spec.mass, "mass", "kg")?;
    let length = ck.positive(&spec.length, "length", "m")?;
    let direction = ck.unit(&spec.direction, "direction")?;
    let axis = ck.perpendicular(&spec.axis, "axis", &direction, "direction")?;
    let hinge = ck.on_body(&spec.hinge, "hinge", "the hinge", cx)?;
    let pair = |s: &Spanned<PerAngle>, key: &str, unit: &str| {
        let p = s.value.pair();
        if p.iter().all(|x| (0.0..=MAX_MAGNITUDE).contains(x)) {
            Ok(p)
        } else {
            Err(ck.err(
                s,
                key,
                format!(
                    "expected a value from 0 to {MAX_MAGNITUDE:e}, or [flap, lag] values from 0 \
                     to {MAX_MAGNITUDE:e} ({unit}), got {}",
                    p.map(crate::scenario::number).join(", ")
                ),
            ))
        }
    };
    let stiffness = pair(&spec.stiffness, "stiffness", "N m/rad")?;
    let damping = pair(&spec.damping, "damping", "N m s/rad")?;
    let finite2 = |s: &Option<Spanned<[f64; 2]>>, key: &str| match s {
        None => Ok([0.0; 2]),
        Some(v) if v.value.iter().all(|x| x.abs() <= MAX_MAGNITUDE) => Ok(v.value),
        Some(v) => Err(ck.err(v, key, "expected [flap, lag], two finite numbers")),
    };
    let a0 = finite2(&spec.initial_angles, "initial_angles")?;
    let r0 = finite2(&spec.initial_rates, "initial_rates")?;
    let (q0, u0): (Vec<f64>, Vec<f64>) = match freedom {
        HingeFreedom::FlapLag => (a0.to_vec(), r0.to_vec()),
        HingeFreedom::Flap => (vec![a0[0]], vec![r0[0]]),
        HingeFreedom::Lag => (vec![a0[1]], vec![r0[1]]),
    };
    let rotations = ck.copies(&spec.copies)?;
    check_copies_on_body(ck, &spec.copies, &rotations, &hinge, cx.shape)?;
    let count = rotations.len();
    for (k, rot) in rotations.into_iter().enumerate() {
        let rod = HingedRod {
            mass,
            length,
            hinge: rot * hinge + cx.shift,
            direction: rot * direction,
            axis: rot * axis,
            freedom,
            stiffness,
            damping,
        };
        out.push(Box::new(ParticleEffector::new(
            copy_name(&name, k, count),
            rod,
            &q0,
            &u0,
        )));
    }
    Ok(())
}
