//! `wheel_damper`: a viscous wheel (or ring) damper about a body axis (Kasdin & Paley).
//!
//! A rotor of axial inertia I_W spins at Ω relative to the body about the unit axis â; the
//! body's inertia tensor includes the rotor as if locked (Kasdin & Paley's convention). The
//! viscous coupling applies −DΩ to the rotor and +DΩ to the body about â. With H = Iω + I_W Ω â:
//!
//! ```text
//! (I − I_W â âᵀ) ω̇ = −ω × H + D Ω â,     Ω̇ = −D Ω / I_W − â · ω̇.
//! ```
//!
//! States: Ω (rad/s) and the dissipated energy (Ẇ = D Ω²).

use crate::model::{
    Drawing, Effector, EnergyAccount, HubAcceleration, HubCoupling, HubState, Momentum, Validity,
};
use nalgebra::Vector3;

/// A viscous wheel damper.
#[derive(Debug, Clone)]
pub struct WheelDamper {
    /// Name.
    pub name: String,
    /// Rotor axial inertia I_W (kg m²).
    pub inertia: f64,
    /// Unit rotor axis â (body axes).
    pub axis: Vector3<f64>,
    /// Viscous coefficient D (N m s/rad).
    pub damping: f64,
    /// Initial relative rate Ω₀ (rad/s).
    pub initial_rate: f64,
    /// Where to draw it (m, body axes).
    pub position: Vector3<f64>,
    /// Largest relative rotor speed |Ω| the wheel is rated for (rad/s); `None`: unrated.
    pub max_speed: Option<f64>,
}

/// Fraction of the rated speed past which the wheel warns.
pub const SPEED_WARN: f64 = 0.9;

/// Where a rotor's relative rate `rate` (rad/s) stands against its rated `max_speed`
/// ([`Effector::validity`] of `wheel_damper` and `wheel`).
pub fn rotor_speed_validity(max_speed: Option<f64>, rate: f64) -> Option<Validity> {
    max_speed.map(|max| Validity {
        value: rate.abs(),
        warn: SPEED_WARN * max,
        limit: max,
    })
}

/// The rotor's speed in words against its rating, for warnings and diagnoses.
pub fn rotor_speed_report(max_speed: Option<f64>, rate: f64) -> String {
    format!(
        "its rotor turns at {:.6e} rad/s relative to the hub, against its rated {} rad/s \
         (warning at {}%)",
        rate.abs(),
        max_speed.unwrap_or(f64::INFINITY),
        SPEED_WARN * 100.0
    )
}

impl Effector for WheelDamper {
    fn name(&self) -> &str {
        &self.name
    }
    fn kind(&self) -> &'static str {
        "wheel_damper"
    }
    fn num_states(&self) -> usize {
        2
    }
    fn num_dynamic_states(&self) -> usize {
        1
    }
    fn state_names(&self) -> Vec<String> {
        vec!["rate".into(), "dissipated_energy".into()]
    }
    fn initial_state(&self) -> Vec<f64> {
        vec![self.initial_rate, 0.0]
    }
    fn couple(&self, hub: &HubState, x: &[f64], c: &mut HubCoupling, _s: &mut [f64]) {
        let a = self.axis;
        let rotor = self.inertia * x[0] * a;
        let mut block = c.mass.fixed_view_mut::<3, 3>(3, 3);
        block -= self.inertia * a * a.transpose();
        c.add_torque(&(-hub.omega.cross(&rotor) + self.damping * x[0] * a));
    }
    fn derivatives(
        &self,
        _hub: &HubState,
        accel: &HubAcceleration,
        x: &[f64],
        _s: &[f64],
        dx: &mut [f64],
    ) {
        dx[0] = -self.damping * x[0] / self.inertia - self.axis.dot(&accel.angular);
        dx[1] = self.damping * x[0] * x[0];
    }
    fn momentum(&self, hub: &HubState, x: &[f64]) -> Momentum {
        let spin = self.axis.dot(&hub.omega);
        Momentum {
            angular: self.inertia * x[0] * self.axis,
            kinetic_energy: self.inertia * x[0] * (spin + 0.5 * x[0]),
            ..Momentum::default()
        }
    }
    fn energy(&self, _hub: &HubState, x: &[f64]) -> EnergyAccount {
        EnergyAccount {
            elastic: 0.0,
            dissipated: x[1],
            power: self.damping * x[0] * x[0],
            work: 0.0,
        }
    }
    fn telemetry_names(&self) -> Vec<String> {
        ["rate", "dissipated_energy", "dissipation_power"]
            .iter()
            .map(|s| s.to_string())
            .collect()
    }
    fn telemetry(&self, _hub: &HubState, x: &[f64]) -> Vec<f64> {
        vec![x[0], x[1], self.damping * x[0] * x[0]]
    }
    fn validity(&self, x: &[f64]) -> Option<Validity> {
        rotor_speed_validity(self.max_speed, x[0])
    }
    fn validity_report(&self, x: &[f64]) -> (String, String) {
        (
            rotor_speed_report(self.max_speed, x[0]),
            "a rotor with more inertia or less initial rate, or a higher rating if the \
             hardware has it"
                .into(),
        )
    }
    fn drawings(&self, _x: &[f64]) -> Vec<Drawing> {
        let d = (self.inertia.sqrt() * 0.5).clamp(0.05, 0.5);
        vec![Drawing::Disc {
            center: self.position,
            axis: self.axis,
            diameter: d,
            thickness: 0.2 * d,
        }]
    }
}
