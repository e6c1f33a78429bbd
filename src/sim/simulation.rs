//! What a run integrates: the typed description every front end (the YAML loader, the Python
//! package, code) builds, and the run loop reads.

use super::{Condition, DriftLimits, Method};
use crate::model::Spacecraft;
use nalgebra::{UnitQuaternion, Vector3};

/// A spacecraft, its initial state, and how to integrate and watch it.
///
/// Build one in code, or get one from a scenario file ([`crate::scenario::load`]; a
/// [`crate::scenario::Scenario`] derefs to its `Simulation`), then hand it to
/// [`crate::sim::run`] with a [`crate::sim::Sink`].
#[derive(Debug)]
pub struct Simulation {
    /// The spacecraft (hub and effectors).
    pub spacecraft: Spacecraft,
    /// Initial body rates (rad/s, body frame).
    pub omega0: Vector3<f64>,
    /// Initial attitude, body → inertial.
    pub attitude0: UnitQuaternion<f64>,
    /// Simulated time span (s).
    pub duration: f64,
    /// Integration method and its settings.
    pub method: Method,
    /// Output samples per second of sim time (Hz); the last instant is always sampled.
    pub output_rate: f64,
    /// Conditions that end the run, located in time.
    pub stop: Vec<Condition>,
    /// Conditions recorded every time they become true (or once).
    pub events: Vec<Condition>,
    /// Drift bounds checked at every step, and what a breach or a model out of its validity
    /// range does.
    pub drift_limits: DriftLimits,
}

impl Simulation {
    /// A run of `spacecraft` from rates `omega0` (rad/s) and attitude `attitude0` for
    /// `duration` (s) with `method`, sampled at 10 Hz, with no conditions and unchecked drift
    /// (a model leaving its validity range stops the run).
    pub fn new(
        spacecraft: Spacecraft,
        omega0: Vector3<f64>,
        attitude0: UnitQuaternion<f64>,
        duration: f64,
        method: Method,
    ) -> Self {
        Simulation {
            spacecraft,
            omega0,
            attitude0,
            duration,
            method,
            output_rate: 10.0,
            stop: Vec::new(),
            events: Vec::new(),
            drift_limits: DriftLimits::default(),
        }
    }
}
