//! `tank:` in the scenario file, shared by the slosh analogs that a tank can stand for
//! (`slosh_pendulum`, `spring_mass_damper`): the tank's shape, place, fill and liquid, and the
//! first lateral mode's analog derived from them in the centrifugal field of the initial spin
//! ([`crate::effectors::slosh_analog`], docs/slosh-analogs.md).
//!
//! ```yaml
//! tank:
//!   shape: {sphere: {radius: 0.25}}   # or {cylinder: {radius: r, height: h}},
//!                                     # or {capsule: {radius: r, barrel: b}}
//!   center: [0.5, 0.0, 0.2]           # m, body axes
//!   fill: 0.5                         # by volume
//!   liquid: {density: 1004.0, kinematic_viscosity: 9.0e-7, surface_tension: 0.066}
//!   damping_factor: 1.0               # optional: × the smooth-wall damping (baffles)
//!   drained_by: main_engine           # optional, the pendulum form only
//! ```

use super::{Check, Context, ScenarioError};
use crate::effectors::slosh_analog::{
    Liquid, SPIN_NONUNIFORMITY_MAX, SloshAnalog, SloshError, SloshWarning, Tank, slosh_analog,
    spin_field,
};
use nalgebra::Vector3;
use serde::Deserialize;
use serde_saphyr::Spanned;

/// `tank:` — a tank whose first lateral slosh mode an analog stands for.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TankSpec {
    /// `{sphere: {radius}}`, `{cylinder: {radius, height}}` or `{capsule: {radius, barrel}}`
    /// (m); a cylinder or capsule stands with its axis along the field, radially outward from
    /// the spin axis.
    pub shape: Spanned<TankShapeSpec>,
    /// The tank's geometric centre (m, body axes).
    pub center: Spanned<[f64; 3]>,
    /// Fill fraction by volume.
    pub fill: Spanned<f64>,
    /// The propellant.
    pub liquid: Spanned<LiquidSpec>,
    /// The thruster that drains the tank (by name; it has no `tank:` of its own). The
    /// pendulum form only.
    #[serde(default)]
    pub drained_by: Option<Spanned<String>>,
    /// Multiplies the smooth-wall damping of the analog (default 1; baffles raise it).
    #[serde(default)]
    pub damping_factor: Option<Spanned<f64>>,
}

/// The tank's shape.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "snake_case")]
pub enum TankShapeSpec {
    /// A sphere.
    Sphere {
        /// Inner radius (m).
        radius: f64,
    },
    /// An upright cylinder with flat ends.
    Cylinder {
        /// Inner radius (m).
        radius: f64,
        /// Inner height between the ends (m).
        height: f64,
    },
    /// A cylinder with hemispherical ends, standing along the field.
    Capsule {
        /// Inner radius of the barrel and the domes (m).
        radius: f64,
        /// Length of the straight barrel between the domes (m).
        barrel: f64,
    },
}

/// `liquid:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LiquidSpec {
    /// Density (kg/m³).
    pub density: f64,
    /// Kinematic viscosity (m²/s).
    pub kinematic_viscosity: f64,
    /// Surface tension against the ullage gas (N/m).
    pub surface_tension: f64,
}

/// Field non-uniformity across a tank (Ω² R/|g| = R/r_T in a pure spin) past which a tank is
/// refused: the field then varies by half its value between the centre and the wall, and a
/// uniform-field analog says nothing reliable (docs/slosh-analogs.md). Between
/// [`SPIN_NONUNIFORMITY_MAX`] and this, the run is warned.
const NONUNIFORMITY_REFUSE: f64 = 0.5;

/// A tank's first lateral slosh mode in the centrifugal field of the initial spin, with what
/// it was derived from.
pub(super) struct TankAnalog {
    /// The analog (heights along "up", from the tank's centre).
    pub analog: SloshAnalog,
    pub shape: Tank,
    /// The tank's centre (m, body axes, about B).
    pub center: Vector3<f64>,
    pub liquid: Liquid,
    /// The restoring acceleration at the tank's centre, Ω² r_T (m/s²).
    pub field: f64,
    /// × the smooth-wall damping.
    pub damping_factor: f64,
    /// The field's direction (unit, body axes): radially outward from the spin axis.
    pub down: Vector3<f64>,
    /// The spin axis (unit, body axes).
    pub axis: Vector3<f64>,
    /// The initial spin rate Ω about `axis` (rad/s).
    pub spin: f64,
}

impl TankAnalog {
    /// The direction tangential to the spin at the tank (unit, body axes): axis × outward.
    pub fn tangential(&self) -> Vector3<f64> {
        self.axis.cross(&self.down).normalize()
    }
}

/// Refuses an entry that gives both `tank` and one of the keys a tank derives (`given`: which
/// keys are present; `derived`: the list in words).
pub(super) fn refuse_keys_beside_tank(
    ck: &Check,
    tank: &Spanned<TankSpec>,
    given: &[(bool, &str)],
    derived: &str,
) -> Result<(), ScenarioError> {
    match given.iter().find(|(is, _)| *is) {
        Some((_, key)) => Err(ck.err(
            tank,
            "tank",
            format!(
                "`{key}` and `tank` are both given: with a tank, {derived} follow from it; \
                 remove `{key}`, or the tank"
            ),
        )),
        None => Ok(()),
    }
}

/// The analog of `tank` in the spin's centrifugal field: the field at the tank's centre is
/// Ω² r_T, radially outward from the spin axis (through the hub's centre of mass), and the
/// analog's axis is that direction. `model` names the analog in messages ("pendulum").
/// Refuses what the analog cannot stand for (a tank on or near the spin axis, a fill or Bond
/// number outside its range) and notes what it stands for with reservations.
pub(super) fn tank_analog(
    ck: &Check,
    cx: &Context,
    tank: &Spanned<TankSpec>,
    model: &str,
) -> Result<TankAnalog, ScenarioError> {
    let t = &tank.value;
    let shape = match t.shape.value {
        TankShapeSpec::Sphere { radius } => Tank::Sphere { radius },
        TankShapeSpec::Cylinder { radius, height } => Tank::Cylinder { radius, height },
        TankShapeSpec::Capsule { radius, barrel } => Tank::Capsule { radius, barrel },
    };
    let liquid = Liquid {
        density: t.liquid.value.density,
        kinematic_viscosity: t.liquid.value.kinematic_viscosity,
        surface_tension: t.liquid.value.surface_tension,
    };
    let center = ck.on_body(&t.center, "tank.center", "the tank's centre", cx)? + cx.shift;
    let axis = cx.spin_axis;
    let spin = cx.omega0.dot(&axis);
    let outward = center - center.dot(&axis) * axis;
    let distance = outward.norm();
    let radius = shape.radius();
    let field = spin_field(spin, distance, 0.0, radius).map_err(|e| {
        ck.err(
            &t.center,
            "tank.center",
            format!(
                "{e}: the tank's centre is {distance:.4} m from the spin axis and the initial \
                 spin is {spin:.6} rad/s; the analog needs the centrifugal field of a spin \
                 about an axis the tank is off"
            ),
        )
    })?;
    if field.nonuniformity > NONUNIFORMITY_REFUSE {
        return Err(ck.err(
            &t.center,
            "tank.center",
            format!(
                "the centrifugal field changes by {:.0}% across the tank (radius {radius} m at \
                 {distance:.4} m from the spin axis); the {model} analog assumes a uniform \
                 field, and past {:.0}% it no longer describes the liquid \
                 (docs/slosh-analogs.md): a tank on or near the spin axis needs another model",
                100.0 * field.nonuniformity,
                100.0 * NONUNIFORMITY_REFUSE
            ),
        ));
    }
    if field.nonuniformity > SPIN_NONUNIFORMITY_MAX {
        cx.notes.borrow_mut().push(ck.err(
            &t.center,
            "tank.center",
            format!(
                "slosh analog: the centrifugal field changes by {:.0}% across the tank (R/r_T); \
                 the uniform-field analog is accurate to a few percent up to {:.0}% \
                 (docs/slosh-analogs.md), so expect its frequency and damping to be off by \
                 more here",
                100.0 * field.nonuniformity,
                100.0 * SPIN_NONUNIFORMITY_MAX
            ),
        ));
    }
    let analog = slosh_analog(&shape, t.fill.value, &liquid, field.acceleration).map_err(|e| {
        let (at, key) = match e {
            SloshError::FillOutOfRange { .. } => (super::loc(&t.fill), "tank.fill"),
            _ => (super::loc(tank), "tank"),
        };
        ScenarioError::at(cx.path, at, format!("{}.{key}", ck.prefix), e.to_string())
    })?;
    for w in &analog.warnings {
        let text = match w {
            SloshWarning::BondMarginal { bond } => format!(
                "Bond number {bond:.1}: surface tension raises the slosh frequency by a few \
                 percent, which the gravity analog leaves out"
            ),
            SloshWarning::ShallowLiquid { depth_ratio } => format!(
                "shallow liquid (h/R = {depth_ratio:.3}): the analog's damping correlation is \
                 least certain here"
            ),
        };
        cx.notes
            .borrow_mut()
            .push(ck.err(tank, "tank", format!("slosh analog: {text}")));
    }
    let coriolis = analog.coriolis_ratio(spin);
    if coriolis > 1.0 {
        cx.notes.borrow_mut().push(ck.err(
            tank,
            "tank",
            format!(
                "slosh analog: the Coriolis acceleration on the liquid is {coriolis:.2} times \
                 its restoring one (2Ω/ω₁); the uniform-field {model} leaves the liquid's own \
                 Coriolis coupling out"
            ),
        ));
    }
    let damping_factor = match &t.damping_factor {
        Some(f) => ck.non_negative(f, "tank.damping_factor", "× the smooth-wall damping")?,
        None => 1.0,
    };
    Ok(TankAnalog {
        analog,
        shape,
        center,
        liquid,
        field: field.acceleration,
        damping_factor,
        down: outward / distance,
        axis,
        spin,
    })
}
