//! `eddy_currents:` in the scenario file: the damping torque of the currents the Earth's
//! field induces in a rotating conducting body, by its magnetic tensor
//! ([`crate::effectors::eddy_currents`]); needs `orbit:`, and an epoch within the field
//! model's years.
//!
//! ```yaml
//! - eddy_currents:
//!     conductivity: 3.5e7                               # S/m
//!     shape: {spherical_shell: {radius: 0.3, thickness: 0.002}}   # m
//!     # or {solid_sphere: {radius: 0.12}}
//!     # or {cylindrical_shell: {radius: 1.5, length: 10, thickness: 0.004, axis: [0, 0, 1]}}
//!     # or, instead of conductivity and shape: tensor: [[..], [..], [..]]  # S m^4
//! ```
//!
//! From a shape and conductivity the loader checks the model's range at the initial rate:
//! past [`ERROR_LIMIT`] it refuses, past [`ERROR_WARN`] it warns; the run keeps checking.

use super::{Check, Context, ScenarioError, geomagnetic_field};
use crate::effectors::EddyCurrents;
use crate::effectors::eddy_currents::{AmbientField, Conductor, ERROR_LIMIT, ERROR_WARN, Material};
use nalgebra::Matrix3;
use serde::Deserialize;
use serde_saphyr::Spanned;

/// `eddy_currents:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EddyCurrentsSpec {
    /// Name (default `eddy_currents`).
    #[serde(default)]
    pub name: Option<String>,
    /// Electrical conductivity σ of the body's conductor (S/m), with `shape`.
    #[serde(default)]
    pub conductivity: Option<Spanned<f64>>,
    /// The conductor's shape (m), with `conductivity`.
    #[serde(default)]
    pub shape: Option<Spanned<ConductorSpec>>,
    /// The magnetic tensor M (S m⁴, body axes, rows; symmetric, positive semi-definite),
    /// instead of `conductivity` and `shape`.
    #[serde(default)]
    pub tensor: Option<Spanned<[[f64; 3]; 3]>>,
}

/// `shape:` — one of the conductors whose tensor polhode knows.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "snake_case")]
pub enum ConductorSpec {
    /// A spherical shell: outer radius and wall thickness (m; thickness up to the radius).
    SphericalShell {
        /// Outer radius (m).
        radius: Spanned<f64>,
        /// Wall thickness (m).
        thickness: Spanned<f64>,
    },
    /// A solid sphere (m).
    SolidSphere {
        /// Radius (m).
        radius: Spanned<f64>,
    },
    /// An open thin-walled cylinder (no end caps).
    CylindricalShell {
        /// Radius of the wall (m).
        radius: Spanned<f64>,
        /// Length (m).
        length: Spanned<f64>,
        /// Wall thickness (m), at most a tenth of the radius.
        thickness: Spanned<f64>,
        /// Axis (body axes).
        axis: Spanned<[f64; 3]>,
    },
}

/// Largest conductivity accepted (S/m): above silver's 6.3e7 at room temperature.
pub const MAX_CONDUCTIVITY: f64 = 1e8;

/// Largest wall of a cylindrical shell, as a fraction of its radius: its tensor is the
/// thin-wall one.
pub const MAX_CYLINDER_WALL: f64 = 0.1;

/// Validates an `eddy_currents:` entry and builds it; `orbit` is the scenario's, `item`
/// where the list item starts.
pub(super) fn build(
    ck: &Check,
    cx: &Context,
    spec: &EddyCurrentsSpec,
    name: String,
    orbit: std::sync::Arc<crate::orbit::Orbit>,
    item: Option<(u32, u32)>,
) -> Result<EddyCurrents, ScenarioError> {
    let (tensor, material) = match (&spec.conductivity, &spec.shape, &spec.tensor) {
        (Some(sigma), Some(shape), None) => {
            let conductivity = ck.positive(sigma, "conductivity", "S/m")?;
            if conductivity > MAX_CONDUCTIVITY {
                return Err(ck.err(
                    sigma,
                    "conductivity",
                    format!(
                        "expected at most {MAX_CONDUCTIVITY:e} S/m (silver conducts 6.3e7 S/m), \
                         got {conductivity:e}"
                    ),
                ));
            }
            let conductor = conductor(ck, shape)?;
            let material = Material {
                conductor,
                conductivity,
            };
            // The model's range at the initial rate.
            let rate = cx.omega0.norm();
            let error = material.torque_error(rate);
            if error > ERROR_LIMIT {
                let (state, remedy) = material.report(rate);
                return Err(ck.err(
                    sigma,
                    "conductivity",
                    format!(
                        "the eddy-current model does not hold at the initial rate: {state}; \
                         suggested remedy: {remedy}"
                    ),
                ));
            }
            if error > ERROR_WARN {
                let (state, _) = material.report(rate);
                cx.notes.borrow_mut().push(ck.err(
                    sigma,
                    "conductivity",
                    format!("the eddy-current model nears the edge of its range: {state}"),
                ));
            }
            (conductor.tensor(conductivity), Some(material))
        }
        (None, None, Some(t)) => (tensor(ck, t)?, None),
        _ => {
            return Err(ScenarioError::at(
                cx.path,
                item,
                ck.prefix.clone(),
                "expected either `conductivity` (S/m) with `shape` ({spherical_shell: \
                 {radius, thickness}}, {solid_sphere: {radius}} or {cylindrical_shell: \
                 {radius, length, thickness, axis}}), or `tensor: [[..], [..], [..]]` \
                 (S m^4) alone",
            ));
        }
    };
    let field = geomagnetic_field(cx, item)?;
    Ok(EddyCurrents {
        name,
        field: AmbientField::Geomagnetic { orbit, field },
        tensor,
        material,
    })
}

/// The conductor of `shape:`, its dimensions checked.
fn conductor(ck: &Check, shape: &Spanned<ConductorSpec>) -> Result<Conductor, ScenarioError> {
    Ok(match &shape.value {
        ConductorSpec::SphericalShell { radius, thickness } => {
            let r = ck.positive(radius, "shape.spherical_shell.radius", "m")?;
            let h = ck.positive(thickness, "shape.spherical_shell.thickness", "m")?;
            if h > r {
                return Err(ck.err(
                    thickness,
                    "shape.spherical_shell.thickness",
                    format!(
                        "expected a wall no thicker than the radius {r} m (a solid sphere), \
                         got {h} m"
                    ),
                ));
            }
            Conductor::SphericalShell {
                radius: r,
                thickness: h,
            }
        }
        ConductorSpec::SolidSphere { radius } => {
            let r = ck.positive(radius, "shape.solid_sphere.radius", "m")?;
            Conductor::SphericalShell {
                radius: r,
                thickness: r,
            }
        }
        ConductorSpec::CylindricalShell {
            radius,
            length,
            thickness,
            axis,
        } => {
            let r = ck.positive(radius, "shape.cylindrical_shell.radius", "m")?;
            let l = ck.positive(length, "shape.cylindrical_shell.length", "m")?;
            let h = ck.positive(thickness, "shape.cylindrical_shell.thickness", "m")?;
            if h > MAX_CYLINDER_WALL * r {
                return Err(ck.err(
                    thickness,
                    "shape.cylindrical_shell.thickness",
                    format!(
                        "expected a thin wall, at most {MAX_CYLINDER_WALL} of the radius \
                         ({} m): the open cylinder's tensor is the thin-wall one; got {h} m",
                        MAX_CYLINDER_WALL * r
                    ),
                ));
            }
            Conductor::CylindricalShell {
                radius: r,
                length: l,
                thickness: h,
                axis: ck.unit(axis, "shape.cylindrical_shell.axis")?,
            }
        }
    })
}

/// `tensor:` checked: finite, symmetric and positive semi-definite (a negative eigenvalue
/// would feed energy into the spin).
fn tensor(ck: &Check, t: &Spanned<[[f64; 3]; 3]>) -> Result<Matrix3<f64>, ScenarioError> {
    let m = Matrix3::from_row_slice(&t.value.concat());
    if !m
        .iter()
        .all(|x| x.is_finite() && x.abs() <= super::MAX_MAGNITUDE)
    {
        return Err(ck.err(
            t,
            "tensor",
            format!(
                "expected finite numbers within ±{:e} (S m^4)",
                super::MAX_MAGNITUDE
            ),
        ));
    }
    let scale = m.amax().max(f64::MIN_POSITIVE);
    if (m - m.transpose()).amax() > 1e-12 * scale {
        return Err(ck.err(t, "tensor", "expected a symmetric matrix"));
    }
    let low = m.symmetric_eigenvalues().min();
    if low < -1e-12 * scale {
        return Err(ck.err(
            t,
            "tensor",
            format!(
                "expected a positive semi-definite matrix (eddy currents only remove energy); \
                 its smallest eigenvalue is {low:e}"
            ),
        ));
    }
    Ok(m)
}
