//! `modal_appendage:` in the scenario file: a cantilever beam in its first bending modes
//! (Rayleigh–Ritz), with tip mass, modal damping and geometric stiffening
//! ([`crate::effectors::modal`], [`crate::effectors::beam`]).
//!
//! ```yaml
//! - modal_appendage:
//!     length: 6.0                         # m
//!     bending_stiffness: 40.0             # N m², EI
//!     mass_per_length: 0.4                # kg/m, ρA
//!     tip_mass: 1.5                       # kg, optional
//!     attachment: [0.7, 0.0, 0.0]         # m, body axes: on or in `body.shape` when given
//!     direction: [1, 0, 0]
//!     flap_direction: [0, 0, 1]           # ⊥ direction; lag is direction × flap
//!     bending: both                       # or flap, or lag
//!     modes: 3                            # per bending direction, 1 to 10
//!     damping_ratio: 0.05                 # default 0.005
//!     initial_tip_deflection: [0.0, 0.05] # m, [flap, lag], in the first mode's shape
//! ```

use super::{Check, Context, CopiesSpec, ScenarioError, check_copies_on_body, copy_name, loc};
use crate::effectors::beam::{BeamProperties, beam_modes};
use crate::effectors::{ModalBeam, ParticleEffector};
use crate::model::Effector;
use serde::Deserialize;
use serde_saphyr::Spanned;

/// `modal_appendage:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModalSpec {
    /// Name (default `modal_appendage`).
    #[serde(default)]
    pub name: Option<String>,
    /// Beam length (m).
    pub length: Spanned<f64>,
    /// Bending stiffness EI (N m²).
    pub bending_stiffness: Spanned<f64>,
    /// Mass per unit length ρA (kg/m).
    pub mass_per_length: Spanned<f64>,
    /// Tip mass (kg).
    #[serde(default)]
    pub tip_mass: Option<Spanned<f64>>,
    /// Root point (m, body axes, about the hub's centre of mass, or the whole spacecraft's
    /// with `body.composite`); checked to be on or in `body.shape` when one is given.
    pub attachment: Spanned<[f64; 3]>,
    /// Beam direction (body axes).
    pub direction: Spanned<[f64; 3]>,
    /// First bending direction `flap` (⊥ direction); `lag` is direction × flap.
    pub flap_direction: Spanned<[f64; 3]>,
    /// `both` (default), `flap` or `lag`.
    #[serde(default)]
    pub bending: Option<Spanned<String>>,
    /// Number of modes per bending direction (1–10, default 3).
    #[serde(default)]
    pub modes: Option<Spanned<u32>>,
    /// Modal damping ratio ζ (default 0.005).
    #[serde(default)]
    pub damping_ratio: Option<Spanned<f64>>,
    /// Model the foreshortening that stiffens a spun beam (default true).
    #[serde(default)]
    pub geometric_stiffening: Option<bool>,
    /// Initial tip deflection along flap and lag (m), in the first mode's shape.
    #[serde(default)]
    pub initial_tip_deflection: Option<Spanned<[f64; 2]>>,
    /// Copies turned about an axis.
    #[serde(default)]
    pub copies: Option<CopiesSpec>,
}

/// Validates a `modal_appendage:` entry and builds its beams (one per copy) into `out`;
/// `name` is the base name the copies are numbered from.
pub(super) fn build(
    ck: &Check,
    cx: &Context,
    spec: &ModalSpec,
    name: String,
    out: &mut Vec<Box<dyn Effector>>,
) -> Result<(), ScenarioError> {
    let props = BeamProperties {
        length: ck.positive(&spec.length, "length", "m")?,
        bending_stiffness: ck.positive(&spec.bending_stiffness, "bending_stiffness", "N m²")?,
        mass_per_length: ck.positive(&spec.mass_per_length, "mass_per_length", "kg/m")?,
        tip_mass: match &spec.tip_mass {
            Some(t) => ck.non_negative(t, "tip_mass", "kg")?,
            None => 0.0,
        },
    };
    let n_modes = match &spec.modes {
        None => 3,
        Some(n) if (1..=10).contains(&n.value) => n.value as usize,
        Some(n) => return Err(ck.err(n, "modes", "expected 1 to 10 modes")),
    };
    let zeta = match &spec.damping_ratio {
        None => 0.005,
        Some(z) => ck.non_negative(z, "damping_ratio", "–")?,
    };
    let direction = ck.unit(&spec.direction, "direction")?;
    let flap = ck.perpendicular(
        &spec.flap_direction,
        "flap_direction",
        &direction,
        "direction",
    )?;
    let lag = direction.cross(&flap);
    let attachment = ck.on_body(&spec.attachment, "attachment", "the root", cx)?;
    let which = match spec.bending.as_ref().map(|b| b.value.as_str()) {
        None | Some("both") => vec![true, true],
        Some("flap") => vec![true, false],
        Some("lag") => vec![false, true],
        Some(other) => {
            let b = spec.bending.as_ref().expect("present");
            return Err(ck.err(
                b,
                "bending",
                format!("unknown bending `{other}`, expected both, flap or lag"),
            ));
        }
    };
    let modes = beam_modes(&props, n_modes)
        .map_err(|e| ScenarioError::at(cx.path, loc(&spec.length), ck.prefix.clone(), e))?;
    let tip0 = match &spec.initial_tip_deflection {
        None => [0.0; 2],
        Some(v) if v.value.iter().all(|x| x.is_finite()) => v.value,
        Some(v) => {
            return Err(ck.err(
                v,
                "initial_tip_deflection",
                "expected [flap, lag], two finite numbers (m)",
            ));
        }
    };
    let tip_phi = modes.nodes[modes.tip].phi[0];
    let rotations = ck.copies(&spec.copies)?;
    check_copies_on_body(ck, &spec.copies, &rotations, &attachment, cx.shape)?;
    let count = rotations.len();
    for (k, rot) in rotations.into_iter().enumerate() {
        let mut bending = Vec::new();
        let mut q0 = Vec::new();
        for (d, (label, t)) in [("flap", flap), ("lag", lag)].into_iter().enumerate() {
            if which[d] {
                bending.push((label.to_string(), rot * t));
                let mut q = vec![0.0; n_modes];
                q[0] = tip0[d] / tip_phi;
                q0.extend(q);
            }
        }
        let n = q0.len();
        let beam = ModalBeam::new(
            modes.clone(),
            rot * attachment + cx.shift,
            rot * direction,
            bending,
            zeta,
            spec.geometric_stiffening.unwrap_or(true),
        );
        out.push(Box::new(ParticleEffector::new(
            copy_name(&name, k, count),
            beam,
            &q0,
            &vec![0.0; n],
        )));
    }
    Ok(())
}
