//! `slosh_pendulum:` in the scenario file: a damped spherical pendulum, the mechanical analog
//! of a tank's first lateral slosh mode ([`crate::effectors::slosh_pendulum`]), given either
//! as a pendulum or as a tank, from which the analog follows
//! ([`crate::effectors::slosh_analog`], docs/slosh-analogs.md).
//!
//! ```yaml
//! - slosh_pendulum:               # the pendulum itself
//!     mass: 20.0                  # kg, the sloshing mass
//!     length: 0.3                 # m, pivot to mass
//!     pivot: [0.0, 0.0, 0.5]      # m, body axes, about the hub's centre of mass
//!     rest_direction: [1, 0, 0]   # the rod's direction at φ = θ = 0
//!     damping: 2.0                # N s/m, on the mass's velocity relative to the body
//!     initial_angles: [0.1, 0.0]  # rad, [φ, θ]
//!     initial_rates: [0.0, 0.0]   # rad/s
//! - slosh_pendulum:               # or a tank in the spin's centrifugal field
//!     tank:
//!       shape: {sphere: {radius: 0.25}}   # or {cylinder: {radius: r, height: h}}
//!       center: [0.5, 0.0, 0.2]           # m, body axes
//!       fill: 0.5                         # by volume
//!       liquid: {density: 1004.0, kinematic_viscosity: 9.0e-7, surface_tension: 0.066}
//!       damping_factor: 1.0               # optional: × the smooth-wall damping (baffles)
//!       drained_by: main_engine           # optional: a thruster without a `tank:` of its
//!                                         # own draws this liquid, and the analog follows
//!                                         # the fill as it falls
//! ```

use super::slosh_tank::{TankSpec, refuse_keys_beside_tank, tank_analog};
use super::{Check, Context, ScenarioError};
use crate::effectors::draining_slosh::{DrainingSlosh, FillCurves};
use crate::effectors::slosh_analog::{Liquid, Tank};
use crate::effectors::slosh_pendulum::{
    SINGULAR_COS_THETA, SloshPendulum, THETA_WARN_DEG, pendulum_frame, pendulum_frame_with_pole,
};
use crate::effectors::{ParticleEffector, Thruster};
use crate::model::Effector;
use nalgebra::Vector3;
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
    #[serde(default)]
    pub mass: Option<Spanned<f64>>,
    /// Rod length, pivot to mass (m).
    #[serde(default)]
    pub length: Option<Spanned<f64>>,
    /// Pivot (m, body axes, about the hub's centre of mass, or the whole spacecraft's with
    /// `body.composite`); checked to be on or in `body.shape` when one is given.
    #[serde(default)]
    pub pivot: Option<Spanned<[f64; 3]>>,
    /// The rod's direction at zero angles (body axes; normalised).
    #[serde(default)]
    pub rest_direction: Option<Spanned<[f64; 3]>>,
    /// Dashpot on the mass's velocity relative to the body (N s/m).
    #[serde(default)]
    pub damping: Option<Spanned<f64>>,
    /// A tank, instead of the five keys above.
    #[serde(default)]
    pub tank: Option<Spanned<TankSpec>>,
    /// p̂₃, the direction along which the angles are singular (body axes, ⊥ the rest
    /// direction): choose one the rod will not reach. Default: from the rest direction alone
    /// (docs/effectors.md), or for a tank the direction tangential to the spin.
    #[serde(default)]
    pub pole: Option<Spanned<[f64; 3]>>,
    /// Initial `[φ, θ]` (rad).
    #[serde(default)]
    pub initial_angles: Option<Spanned<[f64; 2]>>,
    /// Initial `[φ̇, θ̇]` (rad/s).
    #[serde(default)]
    pub initial_rates: Option<Spanned<[f64; 2]>>,
}

/// Validates a `slosh_pendulum:` entry and builds it; `feed` is the thruster its tank's
/// `drained_by` names, built without a tank of its own.
pub(super) fn build(
    ck: &Check,
    cx: &Context,
    spec: &SloshPendulumSpec,
    name: String,
    feed: Option<Thruster>,
) -> Result<Box<dyn Effector>, ScenarioError> {
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
    let (model, setting) = match &spec.tank {
        Some(tank) => {
            let (model, setting) = from_tank(ck, cx, spec, tank)?;
            (model, Some(setting))
        }
        None => {
            let missing = |key: &str, what: &str| {
                ScenarioError::at(
                    cx.path,
                    None,
                    ck.prefix.clone(),
                    format!(
                        "missing field `{key}` ({what}): give the pendulum's `mass`, `length`, \
                         `pivot`, `rest_direction` and `damping`, or a `tank:` to derive them \
                         from"
                    ),
                )
            };
            let mass = spec.mass.as_ref().ok_or_else(|| missing("mass", "kg"))?;
            let length = spec.length.as_ref().ok_or_else(|| missing("length", "m"))?;
            let pivot = spec
                .pivot
                .as_ref()
                .ok_or_else(|| missing("pivot", "m, body axes"))?;
            let rest = spec
                .rest_direction
                .as_ref()
                .ok_or_else(|| missing("rest_direction", "body axes"))?;
            let damping = spec
                .damping
                .as_ref()
                .ok_or_else(|| missing("damping", "N s/m"))?;
            let p1 = ck.unit(rest, "rest_direction")?;
            let frame = match &spec.pole {
                Some(pole) => pendulum_frame_with_pole(
                    p1,
                    ck.perpendicular(pole, "pole", &p1, "rest_direction")?,
                ),
                None => pendulum_frame(p1),
            };
            let model = SloshPendulum {
                mass: ck.positive(mass, "mass", "kg")?,
                length: ck.positive(length, "length", "m")?,
                pivot: ck.on_body(pivot, "pivot", "the pendulum's pivot", cx)? + cx.shift,
                frame,
                damping: ck.non_negative(damping, "damping", "N s/m")?,
                fixed_mass: 0.0,
                fixed_position: Vector3::zeros(),
                amplitude_warning: None,
            };
            (model, None)
        }
    };
    let q0 = pair(&spec.initial_angles, "initial_angles", "rad")?;
    let u0 = pair(&spec.initial_rates, "initial_rates", "rad/s")?;
    let folded = crate::effectors::hinged_rod::folded_angle(q0[1]).to_degrees();
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
    match (feed, setting, &spec.tank) {
        (Some(feed), Some(setting), Some(tank)) => Ok(Box::new(draining(
            ck, cx, tank, name, feed, model, setting, q0, u0,
        )?)),
        _ => Ok(Box::new(ParticleEffector::new(name, model, &q0, &u0))),
    }
}

/// What the analog of a tank was derived from.
struct TankSetting {
    shape: Tank,
    /// The tank's centre (m, body axes, about B).
    center: Vector3<f64>,
    /// × the smooth-wall damping.
    damping_factor: f64,
    liquid: Liquid,
    /// The restoring acceleration (m/s²).
    field: f64,
}

/// A tank drained by `feed`: the analog followed from the initial fill down to the fill the
/// run ends at.
#[allow(clippy::too_many_arguments)]
fn draining(
    ck: &Check,
    cx: &Context,
    tank: &Spanned<TankSpec>,
    name: String,
    feed: Thruster,
    model: SloshPendulum,
    setting: TankSetting,
    q0: [f64; 2],
    u0: [f64; 2],
) -> Result<DrainingSlosh, ScenarioError> {
    let t = &tank.value;
    let drained_by = t
        .drained_by
        .as_ref()
        .expect("a drained tank names its thruster");
    let full_mass = setting.liquid.density * setting.shape.volume();
    let fill = t.fill.value;
    let initial_mass = fill * full_mass;
    let expelled = feed.expelled(cx.duration);
    if expelled >= initial_mass {
        return Err(ck.err(
            drained_by,
            "tank.drained_by",
            format!(
                "thruster `{}` expels {expelled:.6} kg by the end of the run (t = {} s), and \
                 the tank holds {initial_mass:.6} kg: shorten the burn or the run (burnout is \
                 not modelled)",
                feed.name(),
                cx.duration
            ),
        ));
    }
    let end = (initial_mass - expelled) / full_mass;
    // A run that drains (almost) nothing still follows the analog over a sliver of fill.
    let lo = end.min(fill - 1e-6);
    let (curves, _) = FillCurves::fit(&setting.shape, &setting.liquid, setting.field, lo, fill)
        .map_err(|e| {
            ck.err(
                drained_by,
                "tank.drained_by",
                format!(
                    "thruster `{}` drains the tank from fill {fill} to {end:.6} by the end of \
                     the run (t = {} s), and the slosh analog cannot follow it there: {e}",
                    feed.name(),
                    cx.duration
                ),
            )
        })?;
    Ok(DrainingSlosh::new(
        name,
        feed,
        setting.shape,
        setting.center,
        fill,
        setting.liquid,
        setting.field,
        model.frame,
        curves,
        q0,
        u0,
    )
    .with_damping_factor(setting.damping_factor))
}

/// The pendulum of a tank's first lateral slosh mode in the centrifugal field of the initial
/// spin ([`tank_analog`]): it hangs radially outward from the spin axis.
fn from_tank(
    ck: &Check,
    cx: &Context,
    spec: &SloshPendulumSpec,
    tank: &Spanned<TankSpec>,
) -> Result<(SloshPendulum, TankSetting), ScenarioError> {
    refuse_keys_beside_tank(
        ck,
        tank,
        &[
            (spec.mass.is_some(), "mass"),
            (spec.length.is_some(), "length"),
            (spec.pivot.is_some(), "pivot"),
            (spec.rest_direction.is_some(), "rest_direction"),
            (spec.damping.is_some(), "damping"),
        ],
        "the pendulum's mass, length, pivot, rest direction and damping",
    )?;
    let derived = tank_analog(ck, cx, tank, "pendulum")?;
    let (analog, center, down) = (&derived.analog, derived.center, derived.down);
    let radius = derived.shape.radius();
    // Heights are along "up", against the field. The pole is tangential to the spin unless
    // given: a spin that moves toward another body axis (a flat spin) swings the rod in the
    // plane of the spin axis and the tank, away from it.
    let up = -down;
    let frame = match &spec.pole {
        Some(pole) => pendulum_frame_with_pole(
            down,
            ck.perpendicular(pole, "pole", &down, "the tank's field direction")?,
        ),
        None => pendulum_frame_with_pole(down, derived.tangential()),
    };
    let damping_factor = derived.damping_factor;
    let model = SloshPendulum {
        mass: analog.slosh_mass,
        length: analog.pendulum_length,
        pivot: center + analog.pivot_height * up,
        frame,
        damping: damping_factor * analog.dashpot,
        fixed_mass: analog.fixed_mass,
        fixed_position: center + analog.fixed_mass_height * up,
        amplitude_warning: Some(
            analog.max_pendulum_angle(crate::effectors::draining_slosh::WAVE_RATIO, radius),
        ),
    };
    let setting = TankSetting {
        shape: derived.shape,
        center,
        damping_factor,
        liquid: derived.liquid,
        field: derived.field,
    };
    Ok((model, setting))
}
