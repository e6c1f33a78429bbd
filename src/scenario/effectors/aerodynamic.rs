//! `aerodynamic:` in the scenario file: drag in the exponential atmosphere of Vallado's
//! Table 8-4 ([`crate::effectors::aerodynamic`]), on a constant projected area at a fixed
//! centre of pressure, or on the facets of `body.shape`; needs `orbit:`.
//!
//! ```yaml
//! - aerodynamic:
//!     drag_coefficient: 2.2              # dimensionless
//!     area: 1.0                          # m², the same for every attitude
//!     center_of_pressure: [0.1, 0.0, 0.0] # m, body axes, about the hub's centre of mass
//! - aerodynamic:                         # or: on the facets of `body.shape`
//!     drag_coefficient: 2.2
//!     from_shape: true
//!     shape_center: [0.0, 0.0, 0.1]      # m, where the shape's centre is; optional
//! ```

use super::{Check, Context, ScenarioError, Shape};
use crate::effectors::Aerodynamic;
use crate::effectors::aerodynamic::ShapeAerodynamic;
use crate::effectors::aerodynamic::facets::DragSurface;
use crate::model::Effector;
use nalgebra::Vector3;
use serde::Deserialize;
use serde_saphyr::Spanned;

/// `aerodynamic:` — drag in the exponential atmosphere of Vallado's Table 8-4, either on a
/// constant projected area at a fixed centre of pressure (`area`, `center_of_pressure`), or
/// on the facets of `body.shape` (`from_shape: true`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AerodynamicSpec {
    /// Name (default `aerodynamic`).
    #[serde(default)]
    pub name: Option<String>,
    /// Drag coefficient C_d (dimensionless; 2.2 is customary in LEO).
    pub drag_coefficient: Spanned<f64>,
    /// Projected area A (m²), the same for every attitude.
    #[serde(default)]
    pub area: Option<Spanned<f64>>,
    /// Centre of pressure (m, body axes, about the hub's centre of mass).
    #[serde(default)]
    pub center_of_pressure: Option<Spanned<[f64; 3]>>,
    /// `true`: drag on the facets of `body.shape`, whose projected area and centre of
    /// pressure follow the attitude, instead of `area` and `center_of_pressure`.
    #[serde(default)]
    pub from_shape: Option<Spanned<bool>>,
    /// With `from_shape`, where the centre of `body.shape` is (m, body axes, about the centre
    /// of mass; default the centre of mass).
    #[serde(default)]
    pub shape_center: Option<Spanned<[f64; 3]>>,
}

/// Largest `aerodynamic` drag coefficient: free-molecular flat plates and spheres are 2 to 3.
pub const MAX_DRAG_COEFFICIENT: f64 = 10.0;

/// Largest distance (m) of an `aerodynamic` centre of pressure from the centre of mass.
pub const MAX_CENTER_OF_PRESSURE: f64 = 1e3;

/// Validates an `aerodynamic:` entry and builds it (on a constant area, or on the facets of
/// `body.shape`); `orbit` is the scenario's, `item` where the list item starts.
pub(super) fn build(
    ck: &Check,
    cx: &Context,
    spec: &AerodynamicSpec,
    name: String,
    orbit: std::sync::Arc<crate::orbit::Orbit>,
    item: Option<(u32, u32)>,
) -> Result<Box<dyn Effector>, ScenarioError> {
    let cd = spec.drag_coefficient.value;
    if !(cd > 0.0 && cd <= MAX_DRAG_COEFFICIENT) {
        return Err(ck.err(
            &spec.drag_coefficient,
            "drag_coefficient",
            format!(
                "expected a value in (0, {MAX_DRAG_COEFFICIENT}] (dimensionless; 2.2 is \
                 customary in LEO), got {}",
                crate::scenario::number(cd)
            ),
        ));
    }
    let arm = |s: &Spanned<[f64; 3]>, key: &str| {
        let p = Vector3::from(s.value);
        if p.iter().all(|c| c.is_finite()) && p.norm() <= MAX_CENTER_OF_PRESSURE {
            Ok(p)
        } else {
            Err(ck.err(
                s,
                key,
                format!(
                    "expected three finite numbers within {MAX_CENTER_OF_PRESSURE:e} m of the \
                     centre of mass (m, body axes), got [{}, {}, {}]",
                    s.value[0], s.value[1], s.value[2]
                ),
            ))
        }
    };
    match (&spec.from_shape, &spec.area, &spec.center_of_pressure) {
        (Some(f), area, cp) if f.value => {
            if let Some(s) = area {
                return Err(ck.err(
                    s,
                    "area",
                    "with `from_shape: true` the projected area follows from `body.shape` and \
                     the attitude: remove `area`, or `from_shape` for a constant area",
                ));
            }
            if let Some(s) = cp {
                return Err(ck.err(
                    s,
                    "center_of_pressure",
                    "with `from_shape: true` the centre of pressure follows from `body.shape` \
                     and the attitude: remove `center_of_pressure` (`shape_center` places the \
                     shape relative to the centre of mass)",
                ));
            }
            let Some(shape) = cx.shape else {
                return Err(ck.err(
                    f,
                    "from_shape",
                    "drag on the body's facets needs `body.shape`: a box \
                     `{box: {size: [x, y, z]}}` or a cylinder \
                     `{cylinder: {radius: r, length: l, axis: [0, 0, 1]}}` (m, body axes)",
                ));
            };
            let center = match &spec.shape_center {
                Some(s) => arm(s, "shape_center")?,
                None => Vector3::zeros(),
            } + cx.shift;
            let surface = match shape {
                Shape::Box { size, orientation } => DragSurface::cuboid(*size, orientation, center),
                Shape::Cylinder {
                    radius,
                    length,
                    orientation,
                } => DragSurface::cylinder(*radius, *length, orientation, center),
            };
            Ok(Box::new(ShapeAerodynamic {
                name,
                orbit,
                drag_coefficient: cd,
                surface,
            }))
        }
        (_, Some(area), Some(cp)) => {
            if let Some(s) = &spec.shape_center {
                return Err(ck.err(
                    s,
                    "shape_center",
                    "`shape_center` places `body.shape` for `from_shape: true`; with a constant \
                     `area` the drag acts at `center_of_pressure`",
                ));
            }
            let area = ck.positive(area, "area", "m²")?;
            let cp = arm(cp, "center_of_pressure")?;
            Ok(Box::new(Aerodynamic {
                name,
                orbit,
                drag_coefficient: cd,
                area,
                center_of_pressure: cp + cx.shift,
            }))
        }
        (_, Some(_), None) => Err(ScenarioError::at(
            cx.path,
            item,
            ck.prefix.clone(),
            "missing field `center_of_pressure`: a constant `area` acts at a fixed centre of \
             pressure (m, body axes, about the centre of mass)",
        )),
        (_, None, _) => Err(ScenarioError::at(
            cx.path,
            item,
            ck.prefix.clone(),
            "expected `area` (m²) and `center_of_pressure` (m, body axes) for a constant \
             projected area, or `from_shape: true` for drag on the facets of `body.shape`",
        )),
    }
}
