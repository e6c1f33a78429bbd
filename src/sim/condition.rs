//! Conditions on the observed state: what `stop` and `events` watch.

use crate::model::Observation;

/// A quantity events can watch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// Nutation angle (degrees).
    NutationAngleDeg,
    /// Angle between ω and principal axis 1, 2 or 3 (degrees); the index is 0-based.
    AngleToPrincipalDeg(usize),
    /// Body rate component 0, 1 or 2 (rad/s).
    Omega(usize),
    /// Kinetic energy (J).
    KineticEnergy,
    /// The body's rate |ω| (deg/s).
    RateDegS,
    /// Angle between the permanent magnet's moment and the local field (degrees).
    FieldAngleDeg,
}

impl Quantity {
    /// The YAML key naming it.
    pub fn key(&self) -> &'static str {
        match self {
            Quantity::NutationAngleDeg => "nutation_angle_deg",
            Quantity::AngleToPrincipalDeg(0) => "angle_to_principal_1_deg",
            Quantity::AngleToPrincipalDeg(1) => "angle_to_principal_2_deg",
            Quantity::AngleToPrincipalDeg(_) => "angle_to_principal_3_deg",
            Quantity::Omega(0) => "omega_x",
            Quantity::Omega(1) => "omega_y",
            Quantity::Omega(_) => "omega_z",
            Quantity::KineticEnergy => "kinetic_energy",
            Quantity::RateDegS => "rate_deg_s",
            Quantity::FieldAngleDeg => "field_angle_deg",
        }
    }

    /// Its value in an observation.
    pub fn value(&self, o: &Observation) -> f64 {
        match *self {
            Quantity::NutationAngleDeg => o.nutation_angle.to_degrees(),
            Quantity::AngleToPrincipalDeg(i) => o.angles_to_principal[i].to_degrees(),
            Quantity::Omega(i) => o.omega[i],
            Quantity::KineticEnergy => o.kinetic_energy,
            Quantity::RateDegS => o.omega.norm().to_degrees(),
            Quantity::FieldAngleDeg => o.field_angle.to_degrees(),
        }
    }
}

/// A validated condition: holds while `sign · (quantity − threshold) > 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Condition {
    /// What is watched.
    pub quantity: Quantity,
    /// The threshold, in the quantity's unit.
    pub threshold: f64,
    /// `true` for `above`, `false` for `below`.
    pub above: bool,
    /// Only the first occurrence is recorded.
    pub once: bool,
    /// How long the condition must hold before it counts (s); 0 counts at once.
    pub hold: f64,
}

impl Condition {
    /// Signed distance from the threshold: positive while the condition holds.
    pub fn margin(&self, o: &Observation) -> f64 {
        self.margin_of_value(self.quantity.value(o))
    }

    /// [`Condition::margin`] of a value of the quantity (in its unit).
    pub fn margin_of_value(&self, value: f64) -> f64 {
        let d = value - self.threshold;
        if self.above { d } else { -d }
    }

    /// A condition that holds at once, recorded every time it becomes true.
    pub fn crossing(quantity: Quantity, threshold: f64, above: bool) -> Self {
        Condition {
            quantity,
            threshold,
            above,
            once: false,
            hold: 0.0,
        }
    }

    /// Human-readable form, e.g. `nutation_angle_deg above 89`, `nutation_angle_deg below 1
    /// for 60 s`, `omega_z above 2 once`. Also the key of a campaign's event column.
    pub fn describe(&self) -> String {
        let dir = if self.above { "above" } else { "below" };
        let mut text = format!("{} {dir} {}", self.quantity.key(), self.threshold);
        if self.hold > 0.0 {
            text += &format!(" for {} s", self.hold);
        }
        if self.once {
            text += " once";
        }
        text
    }
}
