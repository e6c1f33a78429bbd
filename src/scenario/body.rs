//! `body:`: the hub's mass properties as written, validated into a [`RigidBody`].

use super::{
    MAX_MAGNITUDE, MIN_MOMENT_RATIO, MIN_POSITIVE, ScenarioError, ShapeSpec, key_location, loc,
    number,
};
use crate::model::RigidBody;
use nalgebra::{Matrix3, Vector3};
use serde::Deserialize;
use serde_saphyr::Spanned;
use std::path::Path;

/// `body:` mass properties and display.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Hub mass (kg), excluding effectors that move mass; needed when there are such. With
    /// `composite: true`, the whole spacecraft's mass.
    #[serde(default)]
    pub mass: Option<Spanned<f64>>,
    /// Full inertia tensor about the centre of mass, body axes (kg m², rows). With
    /// `composite: true`, the whole spacecraft's, effectors at rest, about its centre of mass.
    #[serde(default)]
    pub inertia: Option<Spanned<[[f64; 3]; 3]>>,
    /// Principal moments along body x, y, z (kg m²), instead of `inertia`.
    #[serde(default)]
    pub principal: Option<Spanned<[f64; 3]>>,
    /// Body axis whose angle to H is reported as the nutation angle.
    #[serde(default)]
    pub spin_axis: Option<Spanned<[f64; 3]>>,
    /// Shape drawn in viewers (default: a box with the proportions of the inertia), and
    /// against which effector placement is checked (not checked without it).
    #[serde(default)]
    pub shape: Option<Spanned<ShapeSpec>>,
    /// The mass properties are the whole spacecraft's (hub, appendages and dampers at rest,
    /// about the whole spacecraft's centre of mass), as mass-properties reports give them;
    /// polhode subtracts the effectors at rest to get the hub's own (docs/conventions.md).
    #[serde(default)]
    pub composite: Option<Spanned<bool>>,
}

/// The hub as validated, with where its inertia was written (for later messages).
pub(super) struct ValidHub {
    /// The hub (principal moments and axes).
    pub hub: RigidBody,
    /// The inertia tensor as given (kg m², body axes).
    pub inertia: Matrix3<f64>,
    /// Its line and column.
    pub location: Option<(u32, u32)>,
    /// `body.inertia` or `body.principal`.
    pub field: &'static str,
}

impl BodySpec {
    /// Checks the inertia (given as a tensor or as principal moments) of the file at `path`
    /// whose text is `source`: one of the two, finite, in range, physical, and not so thin
    /// that a rate is undefined.
    pub(super) fn hub(&self, path: &Path, source: &str) -> Result<ValidHub, ScenarioError> {
        let err = |l: Option<(u32, u32)>, field: &str, msg: String| {
            ScenarioError::at(path, l, field, msg)
        };
        let (inertia, inertia_loc, inertia_field) = match (&self.inertia, &self.principal) {
            (Some(_), Some(p)) => {
                return Err(err(
                    loc(p),
                    "body.principal",
                    "give either `inertia` or `principal`, not both".into(),
                ));
            }
            (Some(i), None) => (
                Matrix3::from_row_slice(&i.value.concat()),
                loc(i),
                "body.inertia",
            ),
            (None, Some(p)) => (
                Matrix3::from_diagonal(&Vector3::from(p.value)),
                loc(p),
                "body.principal",
            ),
            (None, None) => {
                return Err(err(
                    key_location(source, "body"),
                    "body",
                    "missing the mass properties: expected `inertia: [[..],[..],[..]]` \
                     (kg m²) or `principal: [I1, I2, I3]`"
                        .into(),
                ));
            }
        };
        let largest = inertia.amax();
        if largest.is_finite() && !(MIN_POSITIVE..=MAX_MAGNITUDE).contains(&largest) {
            return Err(err(
                inertia_loc,
                inertia_field,
                format!(
                    "the largest entry is {largest:e} kg m²; inertia moments must lie from \
                     {MIN_POSITIVE:e} to {MAX_MAGNITUDE:e} kg m² (SI units: is it in g cm² or \
                     another unit?)"
                ),
            ));
        }
        let hub = RigidBody::new(inertia).map_err(|e| {
            err(
                inertia_loc,
                inertia_field,
                format!("not a physical inertia tensor: {e}"),
            )
        })?;
        let moments = hub.principal_moments;
        let (smallest, biggest) = (moments.min(), moments.max());
        if smallest < MIN_MOMENT_RATIO * biggest {
            return Err(err(
                inertia_loc,
                inertia_field,
                format!(
                    "principal moments {} kg m²: the smallest is {:.1e} of the largest, below \
                     the {MIN_MOMENT_RATIO:e} polhode supports (an ideal rod or a body with no \
                     inertia about an axis cannot be integrated: its rate about that axis is \
                     undefined)",
                    [moments[0], moments[1], moments[2]].map(number).join(", "),
                    smallest / biggest
                ),
            ));
        }
        Ok(ValidHub {
            hub,
            inertia,
            location: inertia_loc,
            field: inertia_field,
        })
    }
}
