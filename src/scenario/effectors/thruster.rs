//! `thruster:` in the scenario file: a thruster or motor expelling the propellant of its tank
//! ([`crate::effectors::thruster`], [`crate::effectors::propellant_tank`]).
//!
//! ```yaml
//! - thruster:
//!     nozzle: [0.004, 0.0, -1.0]      # m, centre of the nozzle exit, body axes
//!     direction: [0, 0, 1]            # thrust direction; the exhaust leaves along −direction
//!     exit_radius: 0.3                # m, the nozzle exit's (default 0, a point)
//!     thrust: {constant: 9000.0}      # N; or {table: [[t, F], …]}: linear between, 0 outside
//!     isp: 280.0                      # s; or mass_flow: {constant: kg/s} / {table: …}
//!     tank:
//!       model: centrifugal_burn       # point | constant_volume | constant_density |
//!                                     # emptying | uniform_burn | centrifugal_burn
//!       center: [0.0, 0.0, -0.3]      # m, body axes
//!       axis: [0, 0, 1]               # a cylinder's axis; emptying: outlet → opposite pole
//!       radius: 0.5                   # m
//!       length: 0.8                   # m, cylinders
//!       propellant: 400.0             # kg at t = 0
//! ```
//!
//! Without `tank:`, a `slosh_pendulum` whose `tank:` says `drained_by: <this thruster's name>`
//! holds the propellant, and its slosh analog follows the fill as it falls
//! ([`crate::effectors::draining_slosh`]).

use super::{Check, Context, ScenarioError};
use crate::effectors::propellant_tank::{PropellantTank, TankModel};
use crate::effectors::thruster::{MassFlow, Profile, STANDARD_GRAVITY, Thruster};
use serde::Deserialize;
use serde_saphyr::Spanned;
use std::f64::consts::PI;

/// `thruster:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThrusterSpec {
    /// Name (default `thruster`).
    #[serde(default)]
    pub name: Option<String>,
    /// Centre of the nozzle exit (m, body axes, about the hub's centre of mass, or the whole
    /// spacecraft's with `body.composite`).
    pub nozzle: Spanned<[f64; 3]>,
    /// Thrust direction (body axes; normalised).
    pub direction: Spanned<[f64; 3]>,
    /// Radius of the nozzle exit (m; default 0, a point).
    #[serde(default)]
    pub exit_radius: Option<Spanned<f64>>,
    /// Thrust magnitude (N).
    pub thrust: Spanned<ProfileSpec>,
    /// Specific impulse (s): ṁ = F / (g₀ I_sp).
    #[serde(default)]
    pub isp: Option<Spanned<f64>>,
    /// The mass flow (kg/s), instead of `isp`.
    #[serde(default)]
    pub mass_flow: Option<Spanned<ProfileSpec>>,
    /// The tank it draws on; absent when a `slosh_pendulum`'s tank names this thruster in
    /// `drained_by` (that tank's liquid is then the propellant).
    #[serde(default)]
    pub tank: Option<Spanned<PropellantTankSpec>>,
}

/// A value against time: `{constant: v}` or `{table: [[t, v], …]}` (linear between the
/// points, zero before the first and after the last).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProfileSpec {
    /// The same value at every time.
    #[serde(default)]
    pub constant: Option<Spanned<f64>>,
    /// `[[t, v], …]` (s, value).
    #[serde(default)]
    pub table: Option<Spanned<Vec<[f64; 2]>>>,
}

/// `tank:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PropellantTankSpec {
    /// The depletion model.
    pub model: Spanned<String>,
    /// The tank's geometric centre (m, body axes).
    pub center: Spanned<[f64; 3]>,
    /// A cylinder's axis, or the emptying sphere's outlet-to-pole direction (body axes).
    #[serde(default)]
    pub axis: Option<Spanned<[f64; 3]>>,
    /// Radius (m): the sphere's or the cylinder's (outer).
    #[serde(default)]
    pub radius: Option<Spanned<f64>>,
    /// A cylinder's length (m).
    #[serde(default)]
    pub length: Option<Spanned<f64>>,
    /// Density (kg/m³) of the emptying tank's liquid or the burning grain; default: the
    /// propellant fills the tank at t = 0.
    #[serde(default)]
    pub density: Option<Spanned<f64>>,
    /// Propellant mass at t = 0 (kg).
    pub propellant: Spanned<f64>,
}

/// The models `tank.model` takes.
const MODELS: &str = "point, constant_volume, constant_density, emptying, uniform_burn or \
                      centrifugal_burn";

fn profile(
    ck: &Check,
    s: &Spanned<ProfileSpec>,
    key: &str,
    unit: &str,
) -> Result<Profile, ScenarioError> {
    match (&s.value.constant, &s.value.table) {
        (Some(c), None) => Ok(Profile::Constant(ck.non_negative(
            c,
            &format!("{key}.constant"),
            unit,
        )?)),
        (None, Some(t)) => {
            let key = format!("{key}.table");
            let points = super::time_table(ck, t, &key)?;
            if points.len() < 2 {
                return Err(ck.err(t, &key, "expected at least two [t, value] points"));
            }
            if let Some(p) = points.iter().find(|p| {
                !(p.0.abs() <= super::MAX_MAGNITUDE && (0.0..=super::MAX_MAGNITUDE).contains(&p.1))
            }) {
                return Err(ck.err(
                    t,
                    &key,
                    format!(
                        "expected times within ±{:e} s and values from 0 to {:e} ({unit}), got [{}, {}]",
                        super::MAX_MAGNITUDE,
                        super::MAX_MAGNITUDE,
                        p.0,
                        p.1
                    ),
                ));
            }
            Ok(Profile::table(points))
        }
        _ => Err(ck.err(
            s,
            key,
            format!(
                "expected exactly one of `constant` ({unit}) or `table` ([[t, value], …] in s \
                 and {unit}, linear between the points and zero outside them)"
            ),
        )),
    }
}

fn tank(
    ck: &Check,
    cx: &Context,
    s: &Spanned<PropellantTankSpec>,
) -> Result<(PropellantTank, f64), ScenarioError> {
    let spec = &s.value;
    let propellant = ck.positive(&spec.propellant, "tank.propellant", "kg")?;
    let required = |v: &Option<Spanned<f64>>, key: &str, unit: &str| match v {
        Some(x) => ck.positive(x, &format!("tank.{key}"), unit),
        None => Err(ck.err(
            &spec.model,
            &format!("tank.{key}"),
            format!("a `{}` tank needs `{key}` ({unit})", spec.model.value),
        )),
    };
    let unused = |v: bool, key: &str| {
        if v {
            Err(ck.err(
                &spec.model,
                &format!("tank.{key}"),
                format!("a `{}` tank takes no `{key}`", spec.model.value),
            ))
        } else {
            Ok(())
        }
    };
    let model = match spec.model.value.as_str() {
        "point" => {
            unused(spec.radius.is_some(), "radius")?;
            unused(spec.length.is_some(), "length")?;
            unused(spec.density.is_some(), "density")?;
            TankModel::Point
        }
        "constant_volume" | "constant_density" => {
            unused(spec.length.is_some(), "length")?;
            unused(spec.density.is_some(), "density")?;
            let radius = required(&spec.radius, "radius", "m")?;
            if spec.model.value == "constant_volume" {
                TankModel::ConstantVolume { radius }
            } else {
                TankModel::ConstantDensity {
                    radius,
                    initial_mass: propellant,
                }
            }
        }
        "emptying" => {
            unused(spec.length.is_some(), "length")?;
            let radius = required(&spec.radius, "radius", "m")?;
            let density = match &spec.density {
                Some(d) => ck.positive(d, "tank.density", "kg/m³")?,
                None => propellant / (4.0 / 3.0 * PI * radius.powi(3)),
            };
            TankModel::Emptying { radius, density }
        }
        "uniform_burn" | "centrifugal_burn" => {
            let radius = required(&spec.radius, "radius", "m")?;
            let length = required(&spec.length, "length", "m")?;
            if spec.model.value == "uniform_burn" {
                unused(spec.density.is_some(), "density")?;
                TankModel::UniformBurn { radius, length }
            } else {
                let density = match &spec.density {
                    Some(d) => ck.positive(d, "tank.density", "kg/m³")?,
                    None => propellant / (PI * radius * radius * length),
                };
                TankModel::CentrifugalBurn {
                    radius,
                    length,
                    density,
                }
            }
        }
        other => {
            return Err(ck.err(
                &spec.model,
                "tank.model",
                format!("expected {MODELS}, got `{other}`"),
            ));
        }
    };
    let capacity = model.capacity();
    if propellant > capacity * (1.0 + 1e-12) {
        return Err(ck.err(
            &spec.propellant,
            "tank.propellant",
            format!(
                "the tank holds at most {capacity:.6} kg at the density given, and \
                 `propellant` is {propellant} kg"
            ),
        ));
    }
    let axis = match (&spec.axis, model) {
        (
            Some(a),
            TankModel::Point | TankModel::ConstantVolume { .. } | TankModel::ConstantDensity { .. },
        ) => {
            return Err(ck.err(
                a,
                "tank.axis",
                format!(
                    "a `{}` tank is symmetric and takes no `axis`",
                    spec.model.value
                ),
            ));
        }
        (Some(a), _) => ck.unit(a, "tank.axis")?,
        (
            None,
            TankModel::Point | TankModel::ConstantVolume { .. } | TankModel::ConstantDensity { .. },
        ) => nalgebra::Vector3::z(),
        (None, _) => {
            return Err(ck.err(
                &spec.model,
                "tank.axis",
                format!(
                    "a `{}` tank needs `axis` (body axes: {})",
                    spec.model.value,
                    if let TankModel::Emptying { .. } = model {
                        "from the outlet to the opposite pole; the liquid is settled towards the \
                         outlet"
                    } else {
                        "the cylinder's axis"
                    }
                ),
            ));
        }
    };
    let center = ck.point(&spec.center, "tank.center")? + cx.shift;
    Ok((
        PropellantTank {
            model,
            center,
            axis,
        },
        propellant,
    ))
}

/// Validates a `thruster:` entry and builds it.
pub(super) fn build(
    ck: &Check,
    cx: &Context,
    spec: &ThrusterSpec,
    name: String,
) -> Result<Thruster, ScenarioError> {
    let nozzle = ck.point(&spec.nozzle, "nozzle")? + cx.shift;
    let direction = ck.unit(&spec.direction, "direction")?;
    let thrust = profile(ck, &spec.thrust, "thrust", "N")?;
    let flow = match (&spec.isp, &spec.mass_flow) {
        (Some(isp), None) => MassFlow::SpecificImpulse(ck.positive(isp, "isp", "s")?),
        (None, Some(f)) => MassFlow::Given(profile(ck, f, "mass_flow", "kg/s")?),
        _ => {
            return Err(ck.err(
                &spec.thrust,
                "isp",
                format!(
                    "expected exactly one of `isp` (s; the mass flow is then F / (g₀ I_sp) with \
                     g₀ = {STANDARD_GRAVITY} m/s²) or `mass_flow` (kg/s)"
                ),
            ));
        }
    };
    let exit_radius = match &spec.exit_radius {
        Some(r) => ck.non_negative(r, "exit_radius", "m")?,
        None => 0.0,
    };
    let Some(tank_spec) = &spec.tank else {
        // A slosh tank drained by this thruster holds the propellant, and checks the burn.
        return Ok(
            Thruster::fed(name, nozzle, direction, thrust, flow).with_exit_radius(exit_radius)
        );
    };
    let (tank, propellant) = tank(ck, cx, tank_spec)?;
    let thruster = Thruster::new(name, nozzle, direction, thrust, flow, tank, propellant)
        .with_exit_radius(exit_radius);
    // Burnout is not modelled: the tank must hold what the run expels.
    let expelled = thruster.expelled(cx.duration);
    if expelled >= propellant {
        return Err(ck.err(
            &tank_spec.value.propellant,
            "tank.propellant",
            format!(
                "the thrust profile expels {expelled:.6} kg by the end of the run \
                 (t = {} s), and the tank holds {propellant} kg: shorten the burn or the run \
                 (burnout is not modelled)",
                cx.duration
            ),
        ));
    }
    // The emptying sphere's level speeds up without bound as the last liquid drains (the
    // free surface's area vanishes at the outlet): keep 1 % of the sphere.
    if let TankModel::Emptying { .. } = tank.model {
        let floor = EMPTYING_FLOOR * tank.model.capacity();
        if propellant - expelled < floor {
            return Err(ck.err(
                &tank_spec.value.propellant,
                "tank.propellant",
                format!(
                    "the run leaves {:.6} kg in the emptying tank, under 1 % of the sphere \
                     ({floor:.6} kg), where the model's free surface shrinks to the outlet \
                     and its level's rate has no bound: shorten the burn or the run",
                    propellant - expelled
                ),
            ));
        }
    }
    Ok(thruster)
}

/// The least fraction of an emptying sphere the run may leave in it.
const EMPTYING_FLOOR: f64 = 0.01;
