//! `effectors:` and `hub_motion:` in the scenario file: specs, validation, and construction.
//!
//! Each list item is a one-key mapping naming the kind, e.g. `- hinged_rod: {mass: 0.139, …}`.
//! Every physical parameter keeps its span, so an unphysical value is reported at its line.
//!
//! Each kind has its own file in `effectors/` (`rayleigh.rs`, `hinged_rod.rs`, …, and
//! `hub_motion.rs`): its spec, a short YAML example, and the `build` that validates and
//! constructs it. This file keeps the `EffectorSpec` list item, the shared checks (`Check`,
//! placement on `body.shape`, `copies:`), the `Context`, and `build`, which dispatches each
//! item to its kind and then checks the kinds against each other.

use super::{MAX_MAGNITUDE, MIN_POSITIVE, ScenarioError, Shape, loc};
use crate::model::{Effector, RigidBody};
use nalgebra::{UnitQuaternion, Vector3};
use serde::Deserialize;
use serde_saphyr::Spanned;
use std::path::Path;

mod aerodynamic;
mod eddy_currents;
mod energy_sink;
mod gravity_gradient;
mod hinged_rod;
mod hub_motion;
mod hysteresis_rod;
mod magnetic_dipole;
mod magnetorquer;
mod modal_appendage;
mod rayleigh;
mod slosh_pendulum;
mod slosh_tank;
mod solar_pressure;
mod spring_mass_damper;
mod thruster;
mod wheel;
mod wheel_damper;

use aerodynamic::AerodynamicSpec;
use eddy_currents::EddyCurrentsSpec;
use energy_sink::EnergySinkSpec;
use gravity_gradient::GravityGradientSpec;
use hinged_rod::HingedRodSpec;
use hysteresis_rod::HysteresisRodSpec;
use magnetic_dipole::MagneticDipoleSpec;
use magnetorquer::MagnetorquerSpec;
use modal_appendage::ModalSpec;
use rayleigh::RayleighSpec;
use slosh_pendulum::SloshPendulumSpec;
use solar_pressure::SolarPressureSpec;
use spring_mass_damper::SpringMassSpec;
use thruster::ThrusterSpec;
use wheel::MotorWheelSpec;
use wheel_damper::WheelSpec;

pub use hub_motion::HubMotionSpec;
pub(super) use hub_motion::build as motion;

/// One entry of `effectors:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "snake_case")]
pub enum EffectorSpec {
    /// Rayleigh dissipation torque −Γω.
    Rayleigh(RayleighSpec),
    /// Quasi-rigid energy-sink torque.
    EnergySink(EnergySinkSpec),
    /// Particle on a line with spring and dashpot.
    SpringMassDamper(SpringMassSpec),
    /// Viscous wheel damper.
    WheelDamper(WheelSpec),
    /// A driven rotor: motor (free, torque profile or speed hold) and bearing friction.
    Wheel(Box<MotorWheelSpec>),
    /// Rigid rod on a hinge.
    HingedRod(HingedRodSpec),
    /// Damped spherical pendulum (the slosh analog).
    SloshPendulum(SloshPendulumSpec),
    /// Modal cantilever beam.
    ModalAppendage(ModalSpec),
    /// A thruster or motor expelling its tank's propellant.
    Thruster(Box<ThrusterSpec>),
    /// Gravity-gradient torque of the central body (needs `orbit:`).
    GravityGradient(GravityGradientSpec),
    /// A constant magnetic dipole moment in the Earth's field (needs `orbit:`).
    MagneticDipole(MagneticDipoleSpec),
    /// Eddy-current damping of a conducting body in the Earth's field (needs `orbit:`).
    EddyCurrents(EddyCurrentsSpec),
    /// A hysteresis rod in the Earth's field (needs `orbit:`).
    HysteresisRod(HysteresisRodSpec),
    /// Magnetorquer coils under B-dot control (needs `orbit:`).
    Magnetorquer(Box<MagnetorquerSpec>),
    /// Solar radiation pressure on a flat plate (needs `orbit:`).
    SolarPressure(SolarPressureSpec),
    /// Drag on a constant projected area with a fixed centre of pressure, or on the facets of
    /// `body.shape` (needs `orbit:`).
    Aerodynamic(AerodynamicSpec),
}

/// `copies: {count: 4, about: [0, 0, 1]}`: identical copies turned evenly about a body axis
/// through the hub's centre of mass (e.g. turnstile antennas).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CopiesSpec {
    /// Number of copies (≥ 1), the first as written.
    pub count: Spanned<u32>,
    /// Axis they are turned about (body axes).
    pub about: Spanned<[f64; 3]>,
}

/// Builds located errors for one effector entry.
struct Check<'a> {
    path: &'a Path,
    prefix: String,
}

impl Check<'_> {
    fn err<T>(&self, s: &Spanned<T>, key: &str, msg: impl Into<String>) -> ScenarioError {
        ScenarioError::at(self.path, loc(s), format!("{}.{key}", self.prefix), msg)
    }
    fn positive(&self, s: &Spanned<f64>, key: &str, unit: &str) -> Result<f64, ScenarioError> {
        let v = s.value;
        if super::in_positive_range(v) {
            Ok(v)
        } else {
            Err(self.err(
                s,
                key,
                format!(
                    "expected a positive value from {MIN_POSITIVE:e} to {MAX_MAGNITUDE:e} \
                     ({unit}), got {}",
                    super::number(v)
                ),
            ))
        }
    }
    fn non_negative(&self, s: &Spanned<f64>, key: &str, unit: &str) -> Result<f64, ScenarioError> {
        let v = s.value;
        if (0.0..=MAX_MAGNITUDE).contains(&v) {
            Ok(v)
        } else {
            Err(self.err(
                s,
                key,
                format!(
                    "expected a value from 0 to {MAX_MAGNITUDE:e} ({unit}), got {}",
                    super::number(v)
                ),
            ))
        }
    }
    fn finite(
        &self,
        s: &Option<Spanned<f64>>,
        key: &str,
        unit: &str,
    ) -> Result<f64, ScenarioError> {
        match s {
            None => Ok(0.0),
            Some(x) if x.value.abs() <= MAX_MAGNITUDE => Ok(x.value),
            Some(x) => Err(self.err(
                x,
                key,
                format!(
                    "expected a value from -{MAX_MAGNITUDE:e} to {MAX_MAGNITUDE:e} ({unit}), got {}",
                    x.value
                ),
            )),
        }
    }
    fn point(&self, s: &Spanned<[f64; 3]>, key: &str) -> Result<Vector3<f64>, ScenarioError> {
        if s.value.iter().all(|x| x.abs() <= MAX_MAGNITUDE) {
            Ok(Vector3::from(s.value))
        } else {
            Err(self.err(
                s,
                key,
                format!("expected three numbers within ±{MAX_MAGNITUDE:e} (m, body axes)"),
            ))
        }
    }
    fn unit(&self, s: &Spanned<[f64; 3]>, key: &str) -> Result<Vector3<f64>, ScenarioError> {
        // Scaled first, so that huge or tiny components neither overflow nor underflow.
        super::unit_vector(&Vector3::from(s.value))
            .ok_or_else(|| self.err(s, key, "expected a non-zero vector of three finite numbers"))
    }
    fn perpendicular(
        &self,
        s: &Spanned<[f64; 3]>,
        key: &str,
        to: &Vector3<f64>,
        to_key: &str,
    ) -> Result<Vector3<f64>, ScenarioError> {
        let v = self.unit(s, key)?;
        let c = v.dot(to);
        if c.abs() > 1e-6 {
            return Err(self.err(
                s,
                key,
                format!(
                    "expected a direction perpendicular to `{to_key}`; the angle between them \
                     is {:.4}°",
                    c.clamp(-1.0, 1.0).acos().to_degrees()
                ),
            ));
        }
        // Remove the rounding-level component, so the frame is orthonormal to 1e-16.
        Ok((v - c * to).normalize())
    }
    /// A point that must be on or inside the hub, as written (before any composite shift).
    /// Checked against `body.shape`; without one, nothing is invented: the point is taken as
    /// given and a located warning says what to add to have it checked.
    fn on_body(
        &self,
        s: &Spanned<[f64; 3]>,
        key: &str,
        what: &str,
        cx: &Context,
    ) -> Result<Vector3<f64>, ScenarioError> {
        let p = self.point(s, key)?;
        let Some(shape) = cx.shape else {
            cx.notes.borrow_mut().push(self.err(
                s,
                key,
                format!(
                    "placement not checked: give `body.shape` (a box or a cylinder, in body \
                     axes) to check that {what} is on or inside the body"
                ),
            ));
            return Ok(p);
        };
        if let Some(excess) = outside(shape, &p) {
            return Err(self.err(
                s,
                key,
                format!(
                    "the point [{}, {}, {}] m is outside the body by {excess:.4} m: it must be \
                     on or inside the hub's shape (`body.shape`)",
                    p[0], p[1], p[2]
                ),
            ));
        }
        Ok(p)
    }
    fn copies(&self, c: &Option<CopiesSpec>) -> Result<Vec<UnitQuaternion<f64>>, ScenarioError> {
        let Some(c) = c else {
            return Ok(vec![UnitQuaternion::identity()]);
        };
        let n = c.count.value;
        if !(1..=64).contains(&n) {
            return Err(self.err(&c.count, "copies.count", "expected a count from 1 to 64"));
        }
        let axis = self.unit(&c.about, "copies.about")?;
        let axis = nalgebra::Unit::new_normalize(axis);
        Ok((0..n)
            .map(|k| {
                UnitQuaternion::from_axis_angle(
                    &axis,
                    2.0 * std::f64::consts::PI * k as f64 / n as f64,
                )
            })
            .collect())
    }
}

/// How far `p` lies outside `shape` (m), or `None` if on or inside (with a 1e-9 relative
/// allowance for points given on the surface).
fn outside(shape: &Shape, p: &Vector3<f64>) -> Option<f64> {
    let (local, excess) = match shape {
        Shape::Box { size, orientation } => {
            let l = orientation.inverse() * p;
            let e = (0..3)
                .map(|i| l[i].abs() - 0.5 * size[i])
                .fold(f64::NEG_INFINITY, f64::max);
            (size.max(), e)
        }
        Shape::Cylinder {
            radius,
            length,
            orientation,
        } => {
            let l = orientation.inverse() * p;
            let radial = (l.x * l.x + l.y * l.y).sqrt() - radius;
            let axial = l.z.abs() - 0.5 * length;
            (length.max(2.0 * radius), radial.max(axial))
        }
    };
    (excess > 1e-9 * local).then_some(excess)
}

/// Everything needed to build effectors: the file, the hub, and the initial spin.
pub(super) struct Context<'a> {
    pub path: &'a Path,
    pub hub: &'a RigidBody,
    /// `body.shape`, if given: placement is checked against it, and only then.
    pub shape: Option<&'a Shape>,
    pub spin_axis: Vector3<f64>,
    pub omega0: Vector3<f64>,
    /// Added to every position after its placement check (and after `copies` turn it): zero,
    /// or with `body.composite` minus the hub's centre of mass, moving positions written about
    /// the whole spacecraft's centre of mass to the hub's.
    pub shift: Vector3<f64>,
    /// Located warnings (placements that could not be checked).
    pub notes: std::cell::RefCell<Vec<ScenarioError>>,
    /// The orbit (`orbit:`), which environmental effectors need.
    pub orbit: Option<std::sync::Arc<crate::orbit::Orbit>>,
    /// The scenario epoch (Unix ns, UTC) of simulation time 0, and where `epoch:` is written
    /// (None for the default).
    pub epoch_unix_ns: i64,
    pub epoch_loc: Option<(u32, u32)>,
    /// The run's duration (s), which bounds the ticks a discrete controller may take.
    pub duration: f64,
    /// The hub's mass (`body.mass`, kg), if given.
    pub hub_mass: Option<f64>,
    /// `orbit.magnetic_field` and where it is written (None for the default).
    pub magnetic_model: (super::orbit::MagneticModel, Option<(u32, u32)>),
    /// The field the first magnetic effector built, shared by the others.
    pub field: std::cell::RefCell<Option<crate::orbit::GeomagneticField>>,
}

/// Validates `effectors:` and builds them, in order.
pub(super) fn build(
    cx: &Context,
    specs: &[Spanned<EffectorSpec>],
) -> Result<Vec<Box<dyn Effector>>, ScenarioError> {
    let mut out: Vec<Box<dyn Effector>> = Vec::new();
    let rate_damping =
        std::cell::RefCell::new(wheel::rate_damping_laws(cx.path, specs, cx.duration)?);
    for (i, spanned) in specs.iter().enumerate() {
        let spec = &spanned.value;
        // Where the list item starts, for errors about the item as a whole.
        let item = loc(spanned);
        let kind = match spec {
            EffectorSpec::Rayleigh(_) => "rayleigh",
            EffectorSpec::EnergySink(_) => "energy_sink",
            EffectorSpec::SpringMassDamper(_) => "spring_mass_damper",
            EffectorSpec::WheelDamper(_) => "wheel_damper",
            EffectorSpec::Wheel(_) => "wheel",
            EffectorSpec::HingedRod(_) => "hinged_rod",
            EffectorSpec::SloshPendulum(_) => "slosh_pendulum",
            EffectorSpec::ModalAppendage(_) => "modal_appendage",
            EffectorSpec::Thruster(_) => "thruster",
            EffectorSpec::GravityGradient(_) => "gravity_gradient",
            EffectorSpec::MagneticDipole(_) => "magnetic_dipole",
            EffectorSpec::EddyCurrents(_) => "eddy_currents",
            EffectorSpec::HysteresisRod(_) => "hysteresis_rod",
            EffectorSpec::Magnetorquer(_) => "magnetorquer",
            EffectorSpec::SolarPressure(_) => "solar_pressure",
            EffectorSpec::Aerodynamic(_) => "aerodynamic",
        };
        let ck = Check {
            path: cx.path,
            prefix: format!("effectors[{i}].{kind}"),
        };
        let name_of = |n: &Option<String>| {
            n.clone()
                .filter(|s| !s.trim().is_empty())
                .unwrap_or_else(|| {
                    if specs.len() > 1 {
                        format!("{kind}_{}", i + 1)
                    } else {
                        kind.to_string()
                    }
                })
        };
        // Environmental torques need the orbit.
        let needs_orbit = || {
            cx.orbit.clone().ok_or_else(|| {
                ScenarioError::at(
                    cx.path,
                    item,
                    ck.prefix.clone(),
                    format!(
                        "{} needs the spacecraft's orbit: add an `orbit:` block \
                         (semi_major_axis_km or perigee/apogee altitudes, inclination_deg, …)",
                        if kind == "magnetorquer" {
                            "a magnetorquer acts in the Earth's magnetic field, so it"
                        } else {
                            "an environmental torque"
                        }
                    ),
                )
            })
        };
        match spec {
            EffectorSpec::GravityGradient(g) => {
                let orbit = needs_orbit()?;
                out.push(Box::new(gravity_gradient::build(
                    cx,
                    name_of(&g.name),
                    orbit,
                )));
            }
            EffectorSpec::MagneticDipole(m) => {
                let orbit = needs_orbit()?;
                out.push(Box::new(magnetic_dipole::build(
                    &ck,
                    cx,
                    m,
                    name_of(&m.name),
                    orbit,
                    item,
                )?));
            }
            EffectorSpec::EddyCurrents(e) => {
                let orbit = needs_orbit()?;
                out.push(Box::new(eddy_currents::build(
                    &ck,
                    cx,
                    e,
                    name_of(&e.name),
                    orbit,
                    item,
                )?));
            }
            EffectorSpec::HysteresisRod(r) => {
                let orbit = needs_orbit()?;
                out.push(Box::new(hysteresis_rod::build(
                    &ck,
                    cx,
                    r,
                    name_of(&r.name),
                    orbit,
                    item,
                )?));
            }
            EffectorSpec::Magnetorquer(m) => {
                let orbit = needs_orbit()?;
                let field = geomagnetic_field(cx, item)?;
                out.push(Box::new(magnetorquer::build(
                    &ck,
                    cx,
                    m,
                    name_of(&m.name),
                    orbit,
                    field,
                )?));
            }
            EffectorSpec::SolarPressure(sp) => {
                let orbit = needs_orbit()?;
                out.push(Box::new(solar_pressure::build(
                    &ck,
                    cx,
                    sp,
                    name_of(&sp.name),
                    orbit,
                    item,
                )?));
            }
            EffectorSpec::Aerodynamic(a) => {
                let orbit = needs_orbit()?;
                out.push(aerodynamic::build(
                    &ck,
                    cx,
                    a,
                    name_of(&a.name),
                    orbit,
                    item,
                )?);
            }
            EffectorSpec::Rayleigh(r) => {
                out.push(Box::new(rayleigh::build(
                    &ck,
                    cx,
                    r,
                    name_of(&r.name),
                    item,
                )?));
            }
            EffectorSpec::EnergySink(e) => {
                out.push(Box::new(energy_sink::build(
                    &ck,
                    cx,
                    e,
                    name_of(&e.name),
                    item,
                )?));
            }
            EffectorSpec::SpringMassDamper(s) => {
                out.push(spring_mass_damper::build(&ck, cx, s, name_of(&s.name))?);
            }
            EffectorSpec::SloshPendulum(s) => {
                let feed = match s.tank.as_ref().and_then(|t| t.value.drained_by.as_ref()) {
                    Some(by) => Some(feeding_thruster(cx, specs, by, &ck)?),
                    None => None,
                };
                out.push(slosh_pendulum::build(&ck, cx, s, name_of(&s.name), feed)?);
            }
            EffectorSpec::Wheel(w) => {
                wheel::build(
                    &ck,
                    w,
                    name_of(&w.name),
                    cx.shift,
                    cx.hub,
                    &rate_damping,
                    &mut out,
                )?;
            }
            EffectorSpec::WheelDamper(w) => {
                out.push(Box::new(wheel_damper::build(&ck, cx, w, name_of(&w.name))?));
            }
            EffectorSpec::HingedRod(h) => {
                hinged_rod::build(&ck, cx, h, name_of(&h.name), &mut out)?;
            }
            EffectorSpec::ModalAppendage(m) => {
                modal_appendage::build(&ck, cx, m, name_of(&m.name), &mut out)?;
            }
            EffectorSpec::Thruster(t) => {
                let name = name_of(&t.name);
                if t.tank.is_none() {
                    fed_by_one_tank(cx, specs, &name, &ck, item)?;
                }
                out.push(Box::new(thruster::build(&ck, cx, t, name)?));
            }
        }
    }
    // The energy sink is the quasi-rigid model: its Ĥ is the hub's Iω, so it keeps |H| only
    // when no other effector carries momentum (every effector that is not torque-only does;
    // `Spacecraft::add_effector` refuses the same, for spacecraft built in code).
    let sink = specs
        .iter()
        .position(|s| matches!(s.value, EffectorSpec::EnergySink(_)));
    if let Some(i) = sink
        && out
            .iter()
            .any(|e| !e.needs_rigid_spacecraft() && !e.torque_only())
    {
        return Err(ScenarioError::at(
            cx.path,
            loc(&specs[i]),
            format!("effectors[{i}].energy_sink"),
            "an energy sink models the internal dissipation of a quasi-rigid body and cannot \
             be combined with effectors that carry momentum of their own (dampers, rods, \
             beams, wheels): model the dissipation with those instead",
        ));
    }
    thrust_beside_slosh_analogs(cx, specs, &out);
    Ok(out)
}

/// The name entry `j` of `specs` goes by: its `name`, or its kind (numbered when the list has
/// more than one entry).
fn thruster_name(specs: &[Spanned<EffectorSpec>], j: usize, given: &Option<String>) -> String {
    given
        .clone()
        .filter(|s| !s.trim().is_empty())
        .unwrap_or_else(|| {
            if specs.len() > 1 {
                format!("thruster_{}", j + 1)
            } else {
                "thruster".to_string()
            }
        })
}

/// The slosh tanks whose `drained_by` names thruster `name`: (entry index, the key).
fn tanks_drained_by<'a>(
    specs: &'a [Spanned<EffectorSpec>],
    name: &str,
) -> impl Iterator<Item = (usize, &'a Spanned<String>)> {
    specs
        .iter()
        .enumerate()
        .filter_map(move |(i, s)| match &s.value {
            EffectorSpec::SloshPendulum(p) => p
                .tank
                .as_ref()
                .and_then(|t| t.value.drained_by.as_ref())
                .filter(|by| by.value == name)
                .map(|by| (i, by)),
            _ => None,
        })
}

/// A thruster without a `tank:` draws on exactly one slosh tank that names it.
fn fed_by_one_tank(
    cx: &Context,
    specs: &[Spanned<EffectorSpec>],
    name: &str,
    ck: &Check,
    item: Option<(u32, u32)>,
) -> Result<(), ScenarioError> {
    let mut tanks = tanks_drained_by(specs, name);
    if tanks.next().is_none() {
        return Err(ScenarioError::at(
            cx.path,
            item,
            format!("{}.tank", ck.prefix),
            format!(
                "missing field `tank`: thruster `{name}` needs a `tank:` (its depletion model \
                 and propellant), or a `slosh_pendulum` whose `tank:` says \
                 `drained_by: {name}`"
            ),
        ));
    }
    if let Some((i, by)) = tanks.next() {
        return Err(ScenarioError::at(
            cx.path,
            loc(by),
            format!("effectors[{i}].slosh_pendulum.tank.drained_by"),
            format!(
                "thruster `{name}` is already drained by an earlier tank: a thruster draws on \
                 one tank (give each tank its own thruster entry, at the same nozzle if they \
                 feed one engine)"
            ),
        ));
    }
    Ok(())
}

/// The thruster that a slosh tank's `drained_by` names, built without a tank of its own (the
/// tank's liquid is its propellant).
fn feeding_thruster(
    cx: &Context,
    specs: &[Spanned<EffectorSpec>],
    by: &Spanned<String>,
    ck: &Check,
) -> Result<crate::effectors::Thruster, ScenarioError> {
    let mut names = Vec::new();
    for (j, s) in specs.iter().enumerate() {
        let EffectorSpec::Thruster(t) = &s.value else {
            continue;
        };
        let name = thruster_name(specs, j, &t.name);
        if name != by.value {
            names.push(name);
            continue;
        }
        if let Some(tank) = &t.tank {
            return Err(ck.err(
                by,
                "tank.drained_by",
                format!(
                    "thruster `{name}` draws on its own `tank:` (effectors[{j}], line {}): \
                     remove it there, so that this tank's liquid is its propellant",
                    tank.referenced.line()
                ),
            ));
        }
        let thruster_check = Check {
            path: cx.path,
            prefix: format!("effectors[{j}].thruster"),
        };
        return thruster::build(&thruster_check, cx, t, name);
    }
    Err(ck.err(
        by,
        "tank.drained_by",
        format!(
            "no thruster is named `{}`{}",
            by.value,
            if names.is_empty() {
                " (the scene has no thruster)".to_string()
            } else {
                format!(" (thrusters: {})", names.join(", "))
            }
        ),
    ))
}

/// A slosh analog derived from a tank is designed in the spin's centrifugal field at t = 0; a
/// thruster's acceleration is another restoring field, which the dynamics apply to the analog
/// (pendulum or spring) but the analog's frequency and damping do not follow. Warns, at the
/// tank, where the thrusters' peak acceleration exceeds a tenth of that field.
fn thrust_beside_slosh_analogs(
    cx: &Context,
    specs: &[Spanned<EffectorSpec>],
    out: &[Box<dyn Effector>],
) {
    use crate::effectors::Thruster;
    let thrusters = out
        .iter()
        .filter_map(|e| (e.as_ref() as &dyn std::any::Any).downcast_ref::<Thruster>());
    let (peak, names): (f64, Vec<&str>) = thrusters.fold((0.0, Vec::new()), |(f, mut n), t| {
        n.push(t.name());
        (f + t.peak_thrust(), n)
    });
    if peak <= 0.0 {
        return;
    }
    let hub = crate::model::HubState {
        t: 0.0,
        omega: cx.omega0,
        attitude: &[1.0, 0.0, 0.0, 0.0],
    };
    let mass = cx.hub_mass.unwrap_or(0.0)
        + out
            .iter()
            .map(|e| e.momentum(&hub, &e.initial_state()).mass)
            .sum::<f64>();
    let acceleration = peak / mass;
    for (i, spanned) in specs.iter().enumerate() {
        let (tank, kind, analog) = match &spanned.value {
            EffectorSpec::SloshPendulum(s) => {
                (&s.tank, "slosh_pendulum", "pendulum, but its length")
            }
            EffectorSpec::SpringMassDamper(s) => {
                (&s.tank, "spring_mass_damper", "spring, but its stiffness")
            }
            _ => continue,
        };
        let Some(tank) = tank else { continue };
        let center = Vector3::from(tank.value.center.value) + cx.shift;
        let axis = cx.spin_axis;
        let spin = cx.omega0.dot(&axis);
        let field = spin * spin * (center - center.dot(&axis) * axis).norm();
        if acceleration > 0.1 * field {
            cx.notes.borrow_mut().push(ScenarioError::at(
                cx.path,
                loc(&tank.value.center),
                format!("effectors[{i}].{kind}.tank"),
                format!(
                    "the slosh analog is derived in the spin's centrifugal field at the tank, \
                     {field:.4} m/s², and {} {} the spacecraft by up to {acceleration:.4} m/s² \
                     ({:.2} times that): the dynamics apply that field to the {analog} and \
                     damping stay the analog's for the spin alone (docs/slosh-analogs.md)",
                    names
                        .iter()
                        .map(|n| format!("`{n}`"))
                        .collect::<Vec<_>>()
                        .join(", "),
                    if names.len() == 1 {
                        "accelerates"
                    } else {
                        "accelerate"
                    },
                    acceleration / field
                ),
            ));
        }
    }
}

/// A `[[t, v], …]` table (s, value): at least one point, finite numbers, times strictly
/// increasing.
fn time_table(
    ck: &Check,
    s: &Spanned<Vec<[f64; 2]>>,
    key: &str,
) -> Result<Vec<(f64, f64)>, ScenarioError> {
    let points: Vec<(f64, f64)> = s.value.iter().map(|p| (p[0], p[1])).collect();
    if points.is_empty() {
        return Err(ck.err(s, key, "expected at least one [t, u] point"));
    }
    if let Some(p) = points
        .iter()
        .find(|p| !(p.0.is_finite() && p.1.is_finite()))
    {
        return Err(ck.err(
            s,
            key,
            format!("expected finite numbers, got [{}, {}]", p.0, p.1),
        ));
    }
    if let Some(w) = points.windows(2).find(|w| w[1].0 <= w[0].0) {
        return Err(ck.err(
            s,
            key,
            format!(
                "the times must increase strictly (s): {} is followed by {}",
                w[0].0, w[1].0
            ),
        ));
    }
    Ok(points)
}

/// Every copy's point must be on or in the body too.
fn check_copies_on_body(
    ck: &Check,
    spec: &Option<CopiesSpec>,
    rotations: &[UnitQuaternion<f64>],
    point: &Vector3<f64>,
    shape: Option<&Shape>,
) -> Result<(), ScenarioError> {
    // Without `body.shape` the first point's warning already says what is missing.
    let (Some(c), Some(shape)) = (spec, shape) else {
        return Ok(());
    };
    for (k, rot) in rotations.iter().enumerate() {
        let p = rot * point;
        if let Some(excess) = outside(shape, &p) {
            return Err(ck.err(
                &c.about,
                "copies",
                format!(
                    "copy {} lands at [{:.4}, {:.4}, {:.4}] m, outside the body by {excess:.4} m; \
                     every copy must be on or inside the hub's shape",
                    k + 1,
                    p[0],
                    p[1],
                    p[2]
                ),
            ));
        }
    }
    Ok(())
}

/// The geomagnetic field from the scenario epoch, which must lie in the field model's years.
fn geomagnetic_field(
    cx: &Context,
    item: Option<(u32, u32)>,
) -> Result<crate::orbit::GeomagneticField, ScenarioError> {
    use super::orbit::MagneticModel;
    use crate::orbit::GeomagneticField;
    if let Some(field) = cx.field.borrow().as_ref() {
        return Ok(field.clone());
    }
    let (model, model_loc) = cx.magnetic_model;
    let probe = match model {
        MagneticModel::Dipole => GeomagneticField::new(cx.epoch_unix_ns),
        MagneticModel::Igrf => GeomagneticField::igrf(cx.epoch_unix_ns, None),
    };
    let (first, last) = probe.years();
    let (start, end) = (probe.year(0.0), probe.year(cx.duration));
    if !(first..=last).contains(&start) || !(first..=last).contains(&end) {
        let name = match model {
            MagneticModel::Dipole => "IGRF-14 dipole (`magnetic_field: dipole`)",
            MagneticModel::Igrf => "IGRF-14 (`magnetic_field: igrf`, the default)",
        };
        return Err(ScenarioError::at(
            cx.path,
            cx.epoch_loc.or(model_loc).or(item),
            "epoch",
            format!(
                "the magnetic field model, {name}, covers {first} to {last}, and the run spans \
                 {start:.2} to {end:.2}{}: choose an epoch and duration in that range{}",
                if cx.epoch_loc.is_none() {
                    " (the default epoch)"
                } else {
                    ""
                },
                if model == MagneticModel::Dipole && start >= 1900.0 && end <= 2030.0 {
                    ", or `magnetic_field: igrf` (1900 to 2030)"
                } else {
                    ""
                }
            ),
        ));
    }
    let field = match (model, &cx.orbit) {
        (MagneticModel::Igrf, Some(orbit)) => {
            let table =
                crate::orbit::field_table::FieldTable::build(orbit, cx.epoch_unix_ns, cx.duration)
                    .map_err(|e| ScenarioError::at(cx.path, cx.epoch_loc.or(item), "epoch", e))?;
            GeomagneticField::igrf(cx.epoch_unix_ns, table.map(std::sync::Arc::new))
        }
        _ => probe,
    };
    *cx.field.borrow_mut() = Some(field.clone());
    Ok(field)
}

fn copy_name(base: &str, k: usize, count: usize) -> String {
    if count > 1 {
        format!("{base}_{}", k + 1)
    } else {
        base.to_string()
    }
}
