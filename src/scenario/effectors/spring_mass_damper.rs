//! `spring_mass_damper:` in the scenario file: a particle on a line fixed in the body, with a
//! spring and a dashpot ([`crate::effectors::spring_mass`]), given either as the damper itself
//! or as a tank, whose first lateral slosh mode it then stands for (docs/slosh-analogs.md).
//!
//! ```yaml
//! - spring_mass_damper:
//!     mass: 52.744              # kg
//!     position: [1.0, 0.0, 0.0] # m, body axes: the line's point at zero offset
//!     direction: [0, 0, 1]      # the line (here parallel to the spin axis)
//!     stiffness: 52.744         # N/m
//!     damping: 105.49           # N s/m
//!     initial_offset: 0.01      # m, optional
//!     travel: 0.2               # m, optional: what the stops allow
//! - spring_mass_damper:         # or a tank in the spin's centrifugal field
//!     tank:                     # as slosh_pendulum's, without drained_by
//!       shape: {sphere: {radius: 0.25}}
//!       center: [0.5, 0.0, 0.2]
//!       fill: 0.5
//!       liquid: {density: 1004.0, kinematic_viscosity: 9.0e-7, surface_tension: 0.066}
//!     directions: [tangential, axial]  # optional (default both): the lines the mass moves on
//!     initial_offset: [0.01, 0.0]      # m, one per direction, optional
//! ```

use super::slosh_tank::{TankSpec, refuse_keys_beside_tank, tank_analog};
use super::{Check, Context, ScenarioError};
use crate::effectors::draining_slosh::WAVE_RATIO;
use crate::effectors::slosh_spring::SecondLine;
use crate::effectors::{ParticleEffector, SloshSpring, SpringMass};
use crate::model::Effector;
use serde::Deserialize;
use serde_saphyr::Spanned;

/// `spring_mass_damper:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpringMassSpec {
    /// Name (default `spring_mass_damper`).
    #[serde(default)]
    pub name: Option<String>,
    /// Particle mass (kg).
    #[serde(default)]
    pub mass: Option<Spanned<f64>>,
    /// Point of the line at zero offset (m, body axes, about the hub's centre of mass, or the
    /// whole spacecraft's with `body.composite`).
    #[serde(default)]
    pub position: Option<Spanned<[f64; 3]>>,
    /// Direction of the line (body axes).
    #[serde(default)]
    pub direction: Option<Spanned<[f64; 3]>>,
    /// Spring stiffness (N/m).
    #[serde(default)]
    pub stiffness: Option<Spanned<f64>>,
    /// Dashpot coefficient (N s/m).
    #[serde(default)]
    pub damping: Option<Spanned<f64>>,
    /// A tank, instead of the five keys above (and `travel`).
    #[serde(default)]
    pub tank: Option<Spanned<TankSpec>>,
    /// With a tank: the lines its sloshing mass moves on (default both).
    #[serde(default)]
    pub directions: Option<Spanned<Vec<SloshDirection>>>,
    /// Initial offset (m): one number, or with a tank one per direction.
    #[serde(default)]
    pub initial_offset: Option<Spanned<Numbers>>,
    /// Initial rate (m/s): as `initial_offset`.
    #[serde(default)]
    pub initial_rate: Option<Spanned<Numbers>>,
    /// Travel |offset| the damper's stops allow (m); beyond it the model does not hold.
    #[serde(default)]
    pub travel: Option<Spanned<f64>>,
}

/// A lateral slosh direction of a tank on a spinning body (both ⊥ the field, which is radial).
#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum SloshDirection {
    /// Along the spin's velocity at the tank: spin axis × radial.
    Tangential,
    /// Parallel to the spin axis.
    Axial,
}

/// One number, or a list of them.
#[derive(Debug)]
pub enum Numbers {
    /// A number.
    One(f64),
    /// A list.
    Many(Vec<f64>),
}

/// Read directly (not as an untagged enum, which buffers the value first).
impl<'de> Deserialize<'de> for Numbers {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visit;
        impl<'de> serde::de::Visitor<'de> for Visit {
            type Value = Numbers;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number or a list of numbers")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Numbers, E> {
                Ok(Numbers::One(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Numbers, E> {
                Ok(Numbers::One(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Numbers, E> {
                Ok(Numbers::One(v as f64))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut a: A,
            ) -> Result<Numbers, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = a.next_element::<f64>()? {
                    v.push(x);
                }
                Ok(Numbers::Many(v))
            }
        }
        d.deserialize_any(Visit)
    }
}

/// Validates a `spring_mass_damper:` entry and builds it.
pub(super) fn build(
    ck: &Check,
    cx: &Context,
    spec: &SpringMassSpec,
    name: String,
) -> Result<Box<dyn Effector>, ScenarioError> {
    Ok(match &spec.tank {
        Some(tank) => {
            let model = from_tank(ck, cx, spec, tank)?;
            let n = if model.second.is_some() { 2 } else { 1 };
            let q0 = numbers(ck, &spec.initial_offset, n, "initial_offset", "m")?;
            let u0 = numbers(ck, &spec.initial_rate, n, "initial_rate", "m/s")?;
            Box::new(ParticleEffector::new(name, model, &q0, &u0))
        }
        None => {
            let model = explicit(ck, cx, spec)?;
            let q0 = numbers(ck, &spec.initial_offset, 1, "initial_offset", "m")?;
            let u0 = numbers(ck, &spec.initial_rate, 1, "initial_rate", "m/s")?;
            Box::new(ParticleEffector::new(name, model, &q0, &u0))
        }
    })
}

/// The damper as given.
fn explicit(ck: &Check, cx: &Context, spec: &SpringMassSpec) -> Result<SpringMass, ScenarioError> {
    let missing = |key: &str, what: &str| {
        ScenarioError::at(
            cx.path,
            None,
            ck.prefix.clone(),
            format!(
                "missing field `{key}` ({what}): give the damper's `mass`, `position`, \
                 `direction`, `stiffness` and `damping`, or a `tank:` to derive them from"
            ),
        )
    };
    if let Some(d) = &spec.directions {
        return Err(ck.err(
            d,
            "directions",
            "`directions` chooses a tank's slosh directions: give a `tank:`, or `direction` \
             for the damper's line",
        ));
    }
    let mass = spec.mass.as_ref().ok_or_else(|| missing("mass", "kg"))?;
    let position = spec
        .position
        .as_ref()
        .ok_or_else(|| missing("position", "m, body axes"))?;
    let direction = spec
        .direction
        .as_ref()
        .ok_or_else(|| missing("direction", "body axes"))?;
    let stiffness = spec
        .stiffness
        .as_ref()
        .ok_or_else(|| missing("stiffness", "N/m"))?;
    let damping = spec
        .damping
        .as_ref()
        .ok_or_else(|| missing("damping", "N s/m"))?;
    Ok(SpringMass {
        mass: ck.positive(mass, "mass", "kg")?,
        position: ck.on_body(position, "position", "the line's point", cx)? + cx.shift,
        direction: ck.unit(direction, "direction")?,
        stiffness: ck.non_negative(stiffness, "stiffness", "N/m")?,
        damping: ck.non_negative(damping, "damping", "N s/m")?,
        travel: spec
            .travel
            .as_ref()
            .map(|t| ck.positive(t, "travel", "m"))
            .transpose()?,
    })
}

/// `n` numbers from `s` (zeros when absent): one number when `n` is 1, a list of `n`
/// otherwise (or of one, when `n` is 1).
fn numbers(
    ck: &Check,
    s: &Option<Spanned<Numbers>>,
    n: usize,
    key: &str,
    unit: &str,
) -> Result<Vec<f64>, ScenarioError> {
    let Some(s) = s else {
        return Ok(vec![0.0; n]);
    };
    let values = match &s.value {
        Numbers::One(x) if n == 1 => vec![*x],
        Numbers::Many(v) if v.len() == n => v.clone(),
        _ => {
            return Err(ck.err(
                s,
                key,
                format!(
                    "expected {} ({unit}), one per direction the mass moves on",
                    if n == 1 {
                        "one number".to_string()
                    } else {
                        format!("a list of {n} numbers")
                    }
                ),
            ));
        }
    };
    if let Some(x) = values
        .iter()
        .find(|x| x.abs() > super::MAX_MAGNITUDE || x.is_nan())
    {
        return Err(ck.err(
            s,
            key,
            format!(
                "expected {} from -{:e} to {:e} ({unit}), got {x}",
                if values.len() == 1 {
                    "a value"
                } else {
                    "values"
                },
                super::MAX_MAGNITUDE,
                super::MAX_MAGNITUDE
            ),
        ));
    }
    Ok(values)
}

/// The spring–mass analog of a tank's first lateral slosh mode in the centrifugal field of
/// the initial spin ([`tank_analog`]): the sloshing mass m_s at the analog's rest height, free
/// to move on the lines `directions` chooses (⊥ the radial field), the fixed liquid m₀ fixed
/// in the body at its height, and the analog's dashpot c = 2 ζ m_s ω₁.
///
/// The stiffness makes each line's small-oscillation frequency in the spinning body the
/// analog's ω₁. A particle on a line p̂ through r₀, in a body turning steadily at Ω about ê,
/// feels the centrifugal force m Ω² (r − ê (ê·r)), whose component along p̂ at r = r₀ + ρ p̂
/// is m Ω² (p̂·r₀ − (ê·p̂)(ê·r₀) + ρ (1 − (ê·p̂)²)); the Coriolis force 2 m Ω ê × ṙ is ⊥ p̂. With
/// r₀ in the plane of ê and the radial direction (so p̂·r₀ = 0 for the tangential line), the
/// rest point is an equilibrium and
///
/// ```text
/// tangential (ê·p̂ = 0):  m ρ̈ + c ρ̇ + (k − m Ω²) ρ = 0   →  k = m_s (ω₁² + Ω²),
/// axial      (ê·p̂ = 1):  m ρ̈ + c ρ̇ + k ρ = 0            →  k = m_s ω₁².
/// ```
fn from_tank(
    ck: &Check,
    cx: &Context,
    spec: &SpringMassSpec,
    tank: &Spanned<TankSpec>,
) -> Result<SloshSpring, ScenarioError> {
    refuse_keys_beside_tank(
        ck,
        tank,
        &[
            (spec.mass.is_some(), "mass"),
            (spec.position.is_some(), "position"),
            (spec.direction.is_some(), "direction"),
            (spec.stiffness.is_some(), "stiffness"),
            (spec.damping.is_some(), "damping"),
            (spec.travel.is_some(), "travel"),
        ],
        "the spring's mass, position, directions, stiffness, damping and travel",
    )?;
    if let Some(by) = &tank.value.drained_by {
        return Err(ck.err(
            by,
            "tank.drained_by",
            "the spring–mass analog is for a tank at a fixed fill; a tank that drains is \
             supported by the pendulum form: `slosh_pendulum: {tank: {…, drained_by}}` \
             (docs/slosh-analogs.md)",
        ));
    }
    let directions = match &spec.directions {
        None => vec![SloshDirection::Tangential, SloshDirection::Axial],
        Some(d) => {
            let v = &d.value;
            if v.is_empty() || v.len() > 2 || (v.len() == 2 && v[0] == v[1]) {
                return Err(ck.err(
                    d,
                    "directions",
                    "expected one or both of `tangential` and `axial`, each once",
                ));
            }
            v.clone()
        }
    };
    let derived = tank_analog(ck, cx, tank, "spring–mass")?;
    let a = &derived.analog;
    let (m, w1, spin) = (a.slosh_mass, a.frequency, derived.spin);
    let line = |d: SloshDirection| match d {
        SloshDirection::Tangential => (derived.tangential(), m * (w1 * w1 + spin * spin)),
        SloshDirection::Axial => (derived.axis, m * w1 * w1),
    };
    let (direction, stiffness) = line(directions[0]);
    let second = directions.get(1).map(|&d| {
        let (direction, stiffness) = line(d);
        SecondLine {
            direction,
            stiffness,
        }
    });
    let (up, radius) = (-derived.down, derived.shape.radius());
    Ok(SloshSpring {
        spring: SpringMass {
            mass: m,
            position: derived.center + a.slosh_mass_height * up,
            direction,
            stiffness,
            damping: derived.damping_factor * a.dashpot,
            // The mass a tank's radius from rest stands for no liquid motion: the run stops.
            travel: Some(radius),
        },
        second,
        fixed_mass: a.fixed_mass,
        fixed_position: derived.center + a.fixed_mass_height * up,
        // The pendulum's swing θ moves its mass L θ across: the same wall wave.
        amplitude_warning: a.pendulum_length * a.max_pendulum_angle(WAVE_RATIO, radius),
        design_spin: Some((cx.spin_axis, spin)),
    })
}
