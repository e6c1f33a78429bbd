//! `wheel:` in the scenario file: a driven rotor with its motor mode and friction
//! ([`crate::effectors::motor_wheel`]).
//!
//! ```yaml
//! - wheel:
//!     axial_inertia: 0.02          # kg m², part of body.principal/inertia as if locked
//!     transverse_inertia: 0.011    # kg m², optional: checked (I_a ≤ 2 I_t)
//!     axis: [0, 0, 1]
//!     motor: {speed_hold: {rate: 200.0, bandwidth: 5.0}}   # or free, {torque: {…}},
//!                                  # or {rate_damping: {gain: 0.05, sample_rate: 10}}
//!     max_torque: 0.1              # N m
//!     friction: {viscous: 1.0e-6, coulomb: 1.0e-4, smoothing_speed: 0.1}
//!     copies: {count: 4, about: [0, 0, 1]}
//! ```

use super::{Check, CopiesSpec, EffectorSpec, ScenarioError, copy_name};
use crate::effectors::clock::SampleClock;
use crate::effectors::motor::{Friction, MotorMode, RateDamping, SpeedHold, TorqueProfile};
use crate::effectors::motor_wheel::MotorWheel;
use crate::model::{Effector, RigidBody};
use nalgebra::Vector3;
use serde::Deserialize;
use serde_saphyr::Spanned;

/// `wheel:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotorWheelSpec {
    /// Name (default `wheel`).
    #[serde(default)]
    pub name: Option<String>,
    /// Rotor axial inertia (kg m²), included in `body` as if locked.
    pub axial_inertia: Spanned<f64>,
    /// Rotor transverse inertia about its centre (kg m²), optional: checked against the axial.
    #[serde(default)]
    pub transverse_inertia: Option<Spanned<f64>>,
    /// Rotor axis (body axes).
    pub axis: Spanned<[f64; 3]>,
    /// The motor's mode (default `free`).
    #[serde(default)]
    pub motor: Option<Spanned<MotorSpec>>,
    /// Largest motor torque (N m).
    #[serde(default)]
    pub max_torque: Option<Spanned<f64>>,
    /// Bearing friction (default none).
    #[serde(default)]
    pub friction: Option<FrictionSpec>,
    /// Initial rotor rate relative to the body (rad/s).
    #[serde(default)]
    pub initial_rate: Option<Spanned<f64>>,
    /// Where to draw it (m, body axes).
    #[serde(default)]
    pub position: Option<Spanned<[f64; 3]>>,
    /// Drawn diameter (m; default from the axial inertia).
    #[serde(default)]
    pub diameter: Option<Spanned<f64>>,
    /// Largest relative rotor speed the wheel is rated for (rad/s).
    #[serde(default)]
    pub max_speed: Option<Spanned<f64>>,
    /// Identical wheels turned evenly about a body axis (a pyramid).
    #[serde(default)]
    pub copies: Option<CopiesSpec>,
}

/// `motor:` — `free`, `{torque: …}` or `{speed_hold: …}`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "snake_case")]
pub enum MotorSpec {
    /// Coasting.
    Free,
    /// A commanded torque profile.
    Torque(TorqueSpec),
    /// A PI loop holding the relative rate.
    SpeedHold(SpeedHoldSpec),
    /// This wheel's share of a discrete rate-damping law for the hub.
    RateDamping(RateDampingSpec),
}

/// `rate_damping:` — every wheel with it forms one assembly that commands the hub torque −K ω,
/// sampled at `sample_rate` and held (zero-order hold).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RateDampingSpec {
    /// The gain K (N m s): the hub torque per unit body rate.
    pub gain: Spanned<f64>,
    /// How often the controller samples ω (Hz).
    pub sample_rate: Spanned<f64>,
}

/// `torque:` — exactly one of `constant`, `linear`, `steps`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TorqueSpec {
    /// The same torque at every time (N m).
    #[serde(default)]
    pub constant: Option<Spanned<f64>>,
    /// `[[t, u], …]`: linear between the points (s, N m).
    #[serde(default)]
    pub linear: Option<Spanned<Vec<[f64; 2]>>>,
    /// `[[t, u], …]`: u from t until the next time (s, N m), zero before the first.
    #[serde(default)]
    pub steps: Option<Spanned<Vec<[f64; 2]>>>,
}

/// `speed_hold:` — the commanded rate and either a bandwidth or both gains.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpeedHoldSpec {
    /// Commanded rate relative to the hub (rad/s).
    pub rate: Spanned<f64>,
    /// Closed-loop bandwidth ω_c (rad/s): K_p = 2 I_a ω_c, K_i = I_a ω_c².
    #[serde(default)]
    pub bandwidth: Option<Spanned<f64>>,
    /// Proportional gain (N m s/rad).
    #[serde(default)]
    pub kp: Option<Spanned<f64>>,
    /// Integral gain (N m/rad).
    #[serde(default)]
    pub ki: Option<Spanned<f64>>,
}

/// `friction:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrictionSpec {
    /// Viscous coefficient (N m s/rad).
    #[serde(default)]
    pub viscous: Option<Spanned<f64>>,
    /// Coulomb torque (N m).
    #[serde(default)]
    pub coulomb: Option<Spanned<f64>>,
    /// Speed below which the Coulomb torque is smoothed (rad/s; default 0.01).
    #[serde(default)]
    pub smoothing_speed: Option<Spanned<f64>>,
}

/// Default smoothing speed of the Coulomb friction (rad/s).
pub const DEFAULT_SMOOTHING_SPEED: f64 = 0.01;

fn profile(
    ck: &Check,
    t: &TorqueSpec,
    at: &Spanned<MotorSpec>,
) -> Result<TorqueProfile, ScenarioError> {
    let table = |s: &Spanned<Vec<[f64; 2]>>, key: &str| super::time_table(ck, s, key);
    match (&t.constant, &t.linear, &t.steps) {
        (Some(c), None, None) if c.value.is_finite() => Ok(TorqueProfile::Constant(c.value)),
        (Some(c), None, None) => {
            Err(ck.err(c, "motor.torque.constant", "expected a finite torque (N m)"))
        }
        (None, Some(l), None) => Ok(TorqueProfile::Linear(table(l, "motor.torque.linear")?)),
        (None, None, Some(s)) => Ok(TorqueProfile::Steps(table(s, "motor.torque.steps")?)),
        _ => Err(ck.err(
            at,
            "motor.torque",
            "expected exactly one of `constant` (N m), `linear` or `steps` ([[t, u], …] in s \
             and N m)",
        )),
    }
}

/// The rate-damping law of every wheel with `motor: {rate_damping: …}`, in the order the
/// wheels are built (copies included): one assembly, one gain and one sample rate, each wheel
/// commanding its row of K A⁺ (A: the wheels' axes as columns). Checks the gain and the rate
/// (the controller's ticks over `duration` count against the same limit as output samples).
pub(super) fn rate_damping_laws(
    path: &std::path::Path,
    specs: &[Spanned<EffectorSpec>],
    duration: f64,
) -> Result<std::collections::VecDeque<RateDamping>, ScenarioError> {
    let mut axes: Vec<Vector3<f64>> = Vec::new();
    let mut law: Option<(f64, f64)> = None;
    for (i, spanned) in specs.iter().enumerate() {
        let EffectorSpec::Wheel(w) = &spanned.value else {
            continue;
        };
        let Some(Spanned {
            value: MotorSpec::RateDamping(r),
            ..
        }) = &w.motor
        else {
            continue;
        };
        let ck = Check {
            path,
            prefix: format!("effectors[{i}].wheel"),
        };
        let gain = ck.positive(&r.gain, "motor.rate_damping.gain", "N m s")?;
        let rate = ck.positive(&r.sample_rate, "motor.rate_damping.sample_rate", "Hz")?;
        let ticks = duration * rate;
        if ticks > crate::scenario::MAX_SAMPLES {
            return Err(ck.err(
                &r.sample_rate,
                "motor.rate_damping.sample_rate",
                format!(
                    "{ticks:.3e} controller samples ({duration:e} s at {rate:e} Hz) exceed the                      limit of {:e} that output samples have too; lower the rate or the duration",
                    crate::scenario::MAX_SAMPLES
                ),
            ));
        }
        match law {
            None => law = Some((gain, rate)),
            Some((g, f)) if g == gain && f == rate => {}
            Some((g, f)) => {
                return Err(ck.err(
                    &r.gain,
                    "motor.rate_damping",
                    format!(
                        "the wheels under rate damping form one assembly with one law: expected                          gain {g} N m s and sample_rate {f} Hz as on the first such wheel, got                          {gain} N m s and {rate} Hz"
                    ),
                ));
            }
        }
        let axis = ck.unit(&w.axis, "axis")?;
        for rot in ck.copies(&w.copies)? {
            axes.push(rot * axis);
        }
    }
    let Some((gain, rate)) = law else {
        return Ok(Default::default());
    };
    let a = nalgebra::DMatrix::from_fn(3, axes.len(), |r, c| axes[c][r]);
    // A⁺ by the SVD: for axes spanning fewer than three dimensions the hub is damped in
    // their span only.
    let pinv = a
        .pseudo_inverse(1e-12)
        .expect("the SVD of a finite 3 × n matrix exists");
    let clock = SampleClock::from_rate(rate);
    Ok((0..axes.len())
        .map(|j| RateDamping {
            gains: gain * Vector3::new(pinv[(j, 0)], pinv[(j, 1)], pinv[(j, 2)]),
            clock,
        })
        .collect())
}

/// Builds the wheel(s) of one `wheel:` entry into `out`; a wheel under rate damping takes its
/// law from the front of `rate_damping` ([`rate_damping_laws`]).
pub(super) fn build(
    ck: &Check,
    w: &MotorWheelSpec,
    name: String,
    shift: Vector3<f64>,
    hub: &RigidBody,
    rate_damping: &std::cell::RefCell<std::collections::VecDeque<RateDamping>>,
    out: &mut Vec<Box<dyn Effector>>,
) -> Result<(), ScenarioError> {
    let axial = ck.positive(&w.axial_inertia, "axial_inertia", "kg m²")?;
    if let Some(t) = &w.transverse_inertia {
        let transverse = ck.positive(t, "transverse_inertia", "kg m²")?;
        // An axisymmetric body's moments obey I_a ≤ 2 I_t (the triangle inequality
        // I_x + I_y ≥ I_z of every rigid body, equality for a flat disc).
        if axial > 2.0 * transverse {
            return Err(ck.err(
                t,
                "transverse_inertia",
                format!(
                    "a rotor's axial inertia cannot exceed twice its transverse inertia (a flat \
                     disc has exactly twice): axial {axial} kg m² against transverse \
                     {transverse} kg m²"
                ),
            ));
        }
    }
    let axis = ck.unit(&w.axis, "axis")?;
    // The rotor is part of the body's inertia: I − I_a â âᵀ must stay positive definite,
    // i.e. I_a âᵀ I⁻¹ â < 1.
    let limit = 1.0 / axis.dot(&(hub.inertia_inv * axis));
    if axial >= limit {
        return Err(ck.err(
            &w.axial_inertia,
            "axial_inertia",
            format!(
                "the rotor's axial inertia must be less than 1 / (âᵀ I⁻¹ â) = {limit} kg m² for \
                 this axis: the body's inertia includes the rotor, and the rest of the body must \
                 keep a positive-definite inertia"
            ),
        ));
    }
    let max_torque = w
        .max_torque
        .as_ref()
        .map(|m| ck.positive(m, "max_torque", "N m"))
        .transpose()?;
    let mode = match &w.motor {
        None => MotorMode::Free,
        Some(m) => match &m.value {
            MotorSpec::Free => MotorMode::Free,
            MotorSpec::Torque(t) => MotorMode::Torque(profile(ck, t, m)?),
            // Its gains come from the whole assembly ([`rate_damping_laws`]), below.
            MotorSpec::RateDamping(_) => MotorMode::RateDamping(RateDamping {
                gains: Vector3::zeros(),
                clock: SampleClock { period: 1.0 },
            }),
            MotorSpec::SpeedHold(h) => {
                let rate = ck.finite(&Some(h.rate.clone()), "motor.speed_hold.rate", "rad/s")?;
                match (&h.bandwidth, &h.kp, &h.ki) {
                    (Some(b), None, None) => MotorMode::SpeedHold(SpeedHold::from_bandwidth(
                        rate,
                        axial,
                        ck.positive(b, "motor.speed_hold.bandwidth", "rad/s")?,
                    )),
                    (None, Some(kp), Some(ki)) => MotorMode::SpeedHold(SpeedHold {
                        rate,
                        kp: ck.positive(kp, "motor.speed_hold.kp", "N m s/rad")?,
                        ki: ck.non_negative(ki, "motor.speed_hold.ki", "N m/rad")?,
                    }),
                    _ => {
                        return Err(ck.err(
                            m,
                            "motor.speed_hold",
                            "expected either `bandwidth` (rad/s) or both gains `kp` (N m s/rad) \
                             and `ki` (N m/rad)",
                        ));
                    }
                }
            }
        },
    };
    let friction = match &w.friction {
        None => Friction::default(),
        Some(f) => Friction {
            viscous: match &f.viscous {
                Some(v) => ck.non_negative(v, "friction.viscous", "N m s/rad")?,
                None => 0.0,
            },
            coulomb: match &f.coulomb {
                Some(v) => ck.non_negative(v, "friction.coulomb", "N m")?,
                None => 0.0,
            },
            smoothing_speed: match &f.smoothing_speed {
                Some(v) => ck.positive(v, "friction.smoothing_speed", "rad/s")?,
                None => DEFAULT_SMOOTHING_SPEED,
            },
        },
    };
    let initial_rate = ck.finite(&w.initial_rate, "initial_rate", "rad/s")?;
    let position = match &w.position {
        Some(p) => ck.point(p, "position")?,
        None => Vector3::zeros(),
    };
    let diameter = match &w.diameter {
        Some(d) => ck.positive(d, "diameter", "m")?,
        None => (axial.sqrt() * 0.5).clamp(0.05, 0.5),
    };
    let max_speed = w
        .max_speed
        .as_ref()
        .map(|v| ck.positive(v, "max_speed", "rad/s"))
        .transpose()?;
    let rotations = ck.copies(&w.copies)?;
    // With copies, the rest of the body is I − Σ I_a â_k â_kᵀ: it must stay positive definite.
    let rest = rotations.iter().fold(hub.inertia, |m, rot| {
        let a = rot * axis;
        m - axial * a * a.transpose()
    });
    let smallest = rest.symmetric_eigenvalues().min();
    if smallest.is_nan() || smallest <= 0.0 {
        return Err(ck.err(
            &w.axial_inertia,
            "axial_inertia",
            format!(
                "the {} rotors' axial inertias leave the rest of the body without a positive                  inertia (smallest moment {smallest:e} kg m²): the body's inertia includes the                  rotors as if locked",
                rotations.len()
            ),
        ));
    }
    let count = rotations.len();
    for (k, rot) in rotations.into_iter().enumerate() {
        let mode = match mode {
            MotorMode::RateDamping(_) => MotorMode::RateDamping(
                rate_damping
                    .borrow_mut()
                    .pop_front()
                    .ok_or_else(|| ck.err(&w.axis, "motor", "rate-damping wheels miscounted"))?,
            ),
            ref other => other.clone(),
        };
        out.push(Box::new(MotorWheel {
            name: copy_name(&name, k, count),
            axial_inertia: axial,
            axis: rot * axis,
            mode,
            max_torque,
            friction,
            initial_rate,
            position: rot * position + shift,
            diameter,
            max_speed,
        }));
    }
    Ok(())
}
