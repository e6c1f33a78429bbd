//! `effectors:` and `hub_motion:` in the scenario file: specs, validation, and construction.
//!
//! Each list item is a one-key mapping naming the kind, e.g. `- hinged_rod: {mass: 0.139, …}`.
//! Every physical parameter keeps its span, so an unphysical value is reported at its line.

use super::{MAX_MAGNITUDE, MIN_POSITIVE, ScenarioError, Shape, loc};
use crate::effectors::SpinUp;
use crate::model::{Effector, RigidBody};
use nalgebra::{UnitQuaternion, Vector3};
use serde::Deserialize;
use serde_saphyr::Spanned;
use std::path::Path;

mod energy_sink;
mod gravity_gradient;
mod hinged_rod;
mod magnetic_dipole;
mod magnetorquer;
mod modal_appendage;
mod rayleigh;
mod slosh_pendulum;
mod spring_mass_damper;
mod wheel;
mod wheel_damper;

use energy_sink::EnergySinkSpec;
use gravity_gradient::GravityGradientSpec;
use hinged_rod::HingedRodSpec;
use magnetic_dipole::MagneticDipoleSpec;
use magnetorquer::MagnetorquerSpec;
use modal_appendage::ModalSpec;
use rayleigh::RayleighSpec;
use slosh_pendulum::SloshPendulumSpec;
use spring_mass_damper::SpringMassSpec;
use wheel::MotorWheelSpec;
use wheel_damper::WheelSpec;

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
    /// Gravity-gradient torque of the central body (needs `orbit:`).
    GravityGradient(GravityGradientSpec),
    /// A constant magnetic dipole moment in the Earth's field (needs `orbit:`).
    MagneticDipole(MagneticDipoleSpec),
    /// Magnetorquer coils under B-dot control (needs `orbit:`).
    Magnetorquer(Box<MagnetorquerSpec>),
    /// Solar radiation pressure on a flat plate (needs `orbit:`).
    SolarPressure(SolarPressureSpec),
    /// Drag on a constant projected area with a fixed centre of pressure, or on the facets of
    /// `body.shape` (needs `orbit:`).
    Aerodynamic(AerodynamicSpec),
}

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

/// `solar_pressure:` — one flat plate in the Sun's radiation, one-sided, in the Earth's
/// cylindrical shadow.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolarPressureSpec {
    /// Name (default `solar_pressure`).
    #[serde(default)]
    pub name: Option<String>,
    /// Plate area (m²).
    pub area: Spanned<f64>,
    /// Normal of the plate's sunlit face (body axes; normalised).
    pub normal: Spanned<[f64; 3]>,
    /// Centre of pressure relative to the hub's centre of mass (m, body axes).
    pub center_of_pressure: Spanned<[f64; 3]>,
    /// Specular reflectivity ρs (0 to 1).
    pub specular: Spanned<f64>,
    /// Diffuse reflectivity ρd (0 to 1, ρs + ρd ≤ 1).
    pub diffuse: Spanned<f64>,
}

/// Largest distance of a `solar_pressure` centre of pressure from the hub's centre of mass
/// (m).
pub const MAX_PRESSURE_ARM: f64 = 1e3;
/// Unix time (s) of 2050-01-01T00:00Z, the end of the span of the low-precision solar
/// coordinates (1950–2050).
pub const SOLAR_EPHEMERIS_END_UNIX_S: f64 = 2_524_608_000.0;
/// 1950-01-01T00:00:00Z as Unix seconds: the start of the same span.
pub const SOLAR_EPHEMERIS_START_UNIX_S: f64 = -631_152_000.0;

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

/// `hub_motion:`: a prescribed hub rotation.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "snake_case")]
pub enum HubMotionSpec {
    /// The smooth spin-up of Kane, Ryan & Banerjee (1987).
    SpinUp {
        /// Spin axis (body axes).
        axis: Spanned<[f64; 3]>,
        /// Final rate (rad/s).
        rate: Spanned<f64>,
        /// Ramp duration (s).
        ramp_time: Spanned<f64>,
    },
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
            EffectorSpec::GravityGradient(_) => "gravity_gradient",
            EffectorSpec::MagneticDipole(_) => "magnetic_dipole",
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
                let orbit = &needs_orbit()?;
                let area = ck.positive(&sp.area, "area", "m²")?;
                let Some(n) = super::unit_vector(&Vector3::from(sp.normal.value)) else {
                    let num = crate::timefmt::number;
                    return Err(ck.err(
                        &sp.normal,
                        "normal",
                        format!(
                            "expected a non-zero vector of three finite numbers (body axes), \
                             got [{}, {}, {}]",
                            num(sp.normal.value[0]),
                            num(sp.normal.value[1]),
                            num(sp.normal.value[2])
                        ),
                    ));
                };
                let r_cp = Vector3::from(sp.center_of_pressure.value);
                if !r_cp.iter().all(|c| c.is_finite()) || r_cp.norm() > MAX_PRESSURE_ARM {
                    return Err(ck.err(
                        &sp.center_of_pressure,
                        "center_of_pressure",
                        format!(
                            "expected three finite numbers within {MAX_PRESSURE_ARM:e} m of \
                             the centre of mass (m, body axes), got [{}, {}, {}]",
                            sp.center_of_pressure.value[0],
                            sp.center_of_pressure.value[1],
                            sp.center_of_pressure.value[2]
                        ),
                    ));
                }
                let mut rho = [0.0; 2];
                for (k, (v, key)) in [(&sp.specular, "specular"), (&sp.diffuse, "diffuse")]
                    .into_iter()
                    .enumerate()
                {
                    if !(0.0..=1.0).contains(&v.value) {
                        return Err(ck.err(
                            v,
                            key,
                            format!(
                                "expected a reflectivity from 0 to 1, got {}",
                                super::number(v.value)
                            ),
                        ));
                    }
                    rho[k] = v.value;
                }
                if rho[0] + rho[1] > 1.0 {
                    return Err(ck.err(
                        &sp.diffuse,
                        "diffuse",
                        format!(
                            "expected specular + diffuse at most 1 (the rest is absorbed), got \
                             {} + {} = {}",
                            rho[0],
                            rho[1],
                            rho[0] + rho[1]
                        ),
                    ));
                }
                let epoch_s = cx.epoch_unix_ns as f64 * 1e-9;
                if !(SOLAR_EPHEMERIS_START_UNIX_S..SOLAR_EPHEMERIS_END_UNIX_S).contains(&epoch_s) {
                    return Err(ScenarioError::at(
                        cx.path,
                        cx.epoch_loc.or(item),
                        "epoch",
                        "the low-precision solar coordinates (Vallado Algorithm 29) hold from \
                         1950 to 2050: choose an epoch from 1950-01-01 to before 2050-01-01",
                    ));
                }
                out.push(Box::new(crate::effectors::SolarPressure {
                    name: name_of(&sp.name),
                    orbit: orbit.clone(),
                    epoch_unix_ns: cx.epoch_unix_ns,
                    area,
                    normal: n,
                    center_of_pressure: r_cp + cx.shift,
                    specular: rho[0],
                    diffuse: rho[1],
                }));
            }
            EffectorSpec::Aerodynamic(a) => {
                let orbit = &needs_orbit()?;
                let cd = a.drag_coefficient.value;
                if !(cd > 0.0 && cd <= MAX_DRAG_COEFFICIENT) {
                    return Err(ck.err(
                        &a.drag_coefficient,
                        "drag_coefficient",
                        format!(
                            "expected a value in (0, {MAX_DRAG_COEFFICIENT}] (dimensionless; \
                             2.2 is customary in LEO), got {}",
                            super::number(cd)
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
                                "expected three finite numbers within \
                                 {MAX_CENTER_OF_PRESSURE:e} m of the centre of mass (m, body \
                                 axes), got [{}, {}, {}]",
                                s.value[0], s.value[1], s.value[2]
                            ),
                        ))
                    }
                };
                let name = name_of(&a.name);
                match (&a.from_shape, &a.area, &a.center_of_pressure) {
                    (Some(f), area, cp) if f.value => {
                        if let Some(s) = area {
                            return Err(ck.err(
                                s,
                                "area",
                                "with `from_shape: true` the projected area follows from \
                                 `body.shape` and the attitude: remove `area`, or \
                                 `from_shape` for a constant area",
                            ));
                        }
                        if let Some(s) = cp {
                            return Err(ck.err(
                                s,
                                "center_of_pressure",
                                "with `from_shape: true` the centre of pressure follows from \
                                 `body.shape` and the attitude: remove `center_of_pressure` \
                                 (`shape_center` places the shape relative to the centre of \
                                 mass)",
                            ));
                        }
                        let Some(shape) = cx.shape else {
                            return Err(ck.err(
                                f,
                                "from_shape",
                                "drag on the body's facets needs `body.shape`: a box \
                                 `{box: {size: [x, y, z]}}` or a cylinder `{cylinder: \
                                 {radius: r, length: l, axis: [0, 0, 1]}}` (m, body axes)",
                            ));
                        };
                        let center = match &a.shape_center {
                            Some(s) => arm(s, "shape_center")?,
                            None => Vector3::zeros(),
                        } + cx.shift;
                        use crate::effectors::aerodynamic::facets::DragSurface;
                        let surface = match shape {
                            Shape::Box { size, orientation } => {
                                DragSurface::cuboid(*size, orientation, center)
                            }
                            Shape::Cylinder {
                                radius,
                                length,
                                orientation,
                            } => DragSurface::cylinder(*radius, *length, orientation, center),
                        };
                        out.push(Box::new(crate::effectors::aerodynamic::ShapeAerodynamic {
                            name,
                            orbit: orbit.clone(),
                            drag_coefficient: cd,
                            surface,
                        }));
                    }
                    (_, Some(area), Some(cp)) => {
                        if let Some(s) = &a.shape_center {
                            return Err(ck.err(
                                s,
                                "shape_center",
                                "`shape_center` places `body.shape` for `from_shape: true`; \
                                 with a constant `area` the drag acts at `center_of_pressure`",
                            ));
                        }
                        let area = ck.positive(area, "area", "m²")?;
                        let cp = arm(cp, "center_of_pressure")?;
                        out.push(Box::new(crate::effectors::Aerodynamic {
                            name,
                            orbit: orbit.clone(),
                            drag_coefficient: cd,
                            area,
                            center_of_pressure: cp + cx.shift,
                        }));
                    }
                    (_, Some(_), None) => {
                        return Err(ScenarioError::at(
                            cx.path,
                            item,
                            ck.prefix.clone(),
                            "missing field `center_of_pressure`: a constant `area` acts at a \
                             fixed centre of pressure (m, body axes, about the centre of mass)",
                        ));
                    }
                    (_, None, _) => {
                        return Err(ScenarioError::at(
                            cx.path,
                            item,
                            ck.prefix.clone(),
                            "expected `area` (m²) and `center_of_pressure` (m, body axes) for a \
                             constant projected area, or `from_shape: true` for drag on the \
                             facets of `body.shape`",
                        ));
                    }
                }
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
                out.push(Box::new(spring_mass_damper::build(
                    &ck,
                    cx,
                    s,
                    name_of(&s.name),
                )?));
            }
            EffectorSpec::SloshPendulum(s) => {
                out.push(Box::new(slosh_pendulum::build(
                    &ck,
                    cx,
                    s,
                    name_of(&s.name),
                )?));
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
    Ok(out)
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
    let field = crate::orbit::GeomagneticField::new(cx.epoch_unix_ns);
    let year = field.year(0.0);
    use crate::orbit::magnetic::{FIRST_YEAR, LAST_YEAR};
    if !(FIRST_YEAR..=LAST_YEAR).contains(&year) {
        return Err(ScenarioError::at(
            cx.path,
            cx.epoch_loc.or(item),
            "epoch",
            format!(
                "the magnetic field model (IGRF-14 dipole) covers {FIRST_YEAR} to {LAST_YEAR}, \
                 and the epoch is {year:.2}{}: choose an epoch in that range",
                if cx.epoch_loc.is_none() {
                    " (the default)"
                } else {
                    ""
                }
            ),
        ));
    }
    Ok(field)
}

fn copy_name(base: &str, k: usize, count: usize) -> String {
    if count > 1 {
        format!("{base}_{}", k + 1)
    } else {
        base.to_string()
    }
}

/// Validates `hub_motion:`.
pub(super) fn motion(path: &Path, spec: &HubMotionSpec) -> Result<SpinUp, ScenarioError> {
    let ck = Check {
        path,
        prefix: "hub_motion.spin_up".into(),
    };
    match spec {
        HubMotionSpec::SpinUp {
            axis,
            rate,
            ramp_time,
        } => Ok(SpinUp {
            axis: ck.unit(axis, "axis")?,
            rate: ck.finite(&Some(rate.clone()), "rate", "rad/s")?,
            ramp_time: ck.positive(ramp_time, "ramp_time", "s")?,
        }),
    }
}
