//! `wheel`: a driven rotor (momentum or reaction wheel, a dual-spin rotor) on an axis of the
//! hub, with a motor between rotor and hub and bearing friction.
//!
//! The rotor has axial inertia I_a about the unit axis â (body axes); like `wheel_damper`'s,
//! it is part of the body's inertia I as if locked, so H = I ω + I_a Ω â with Ω its rate
//! relative to the hub. The motor torque u (on the rotor, −u on the hub) and the friction
//! f(Ω) ([`Friction`]) are internal, so with g = u − f(Ω) the equations are
//!
//! ```text
//! (I − I_a â âᵀ) ω̇ = −ω × H − g â,      I_a (â·ω̇ + Ω̇) = g
//! ```
//!
//! (Hughes, *Spacecraft Attitude Dynamics*, 1986, on gyrostats; Wittenburg, *Dynamics of
//! Multibody Systems*, 2008, on the gyrostat). H_N is conserved whatever u does. The motor's work
//! W = ∫ u Ω dt enters the energy balance as work done on the spacecraft, and the friction's
//! ∫ f Ω dt ≥ 0 as dissipated energy.
//!
//! States: Ω (rad/s); the PI loop's integral z (rad) in `speed_hold`, or the held torque
//! command (N m) of a step profile or of rate damping; the motor's work (J); the dissipated
//! energy (J).

use super::motor::{Friction, MotorMode, TorqueProfile};
use super::wheel::{rotor_speed_report, rotor_speed_validity};
use crate::model::{
    Drawing, Effector, EnergyAccount, HubAcceleration, HubCoupling, HubState, Momentum, Validity,
};
use nalgebra::Vector3;

/// A driven wheel.
#[derive(Debug, Clone)]
pub struct MotorWheel {
    /// Name.
    pub name: String,
    /// Rotor axial inertia I_a (kg m²), included in the body's inertia as if locked.
    pub axial_inertia: f64,
    /// Unit rotor axis â (body axes).
    pub axis: Vector3<f64>,
    /// The motor's mode.
    pub mode: MotorMode,
    /// Largest motor torque |u| (N m); `None`: unlimited.
    pub max_torque: Option<f64>,
    /// Bearing friction.
    pub friction: Friction,
    /// Initial relative rate Ω₀ (rad/s).
    pub initial_rate: f64,
    /// Where to draw it (m, body axes).
    pub position: Vector3<f64>,
    /// Drawn diameter (m).
    pub diameter: f64,
    /// Largest relative speed |Ω| the wheel is rated for (rad/s); `None`: unrated.
    pub max_speed: Option<f64>,
}

impl MotorWheel {
    fn holds_speed(&self) -> bool {
        matches!(self.mode, MotorMode::SpeedHold(_))
    }

    /// Whether the motor torque is a held (discrete) state: a step profile, or a sampled
    /// controller's command, whose value changes only at its breakpoints, where the run stops
    /// and updates it.
    fn holds_torque(&self) -> bool {
        matches!(
            self.mode,
            MotorMode::Torque(TorqueProfile::Steps(_)) | MotorMode::RateDamping(_)
        )
    }

    /// Index of the motor-work state (after Ω and, in `speed_hold`, z, or for a step
    /// profile the held torque).
    fn work_index(&self) -> usize {
        if self.holds_speed() || self.holds_torque() {
            2
        } else {
            1
        }
    }

    fn limit(&self, u: f64) -> f64 {
        match self.max_torque {
            Some(m) => u.clamp(-m, m),
            None => u,
        }
    }

    /// The motor torque u (N m) and, in `speed_hold`, the unsaturated command v, at time `t`
    /// and states `x`.
    pub fn motor_torque(&self, t: f64, x: &[f64]) -> (f64, f64) {
        match &self.mode {
            MotorMode::Free => (0.0, 0.0),
            MotorMode::Torque(TorqueProfile::Steps(_)) | MotorMode::RateDamping(_) => {
                (self.limit(x[1]), x[1])
            }
            MotorMode::Torque(profile) => {
                let v = profile.at(t);
                (self.limit(v), v)
            }
            MotorMode::SpeedHold(hold) => {
                let v = hold.kp * (hold.rate - x[0]) + hold.ki * x[1];
                (self.limit(v), v)
            }
        }
    }
}

impl Effector for MotorWheel {
    fn name(&self) -> &str {
        &self.name
    }
    fn kind(&self) -> &'static str {
        "wheel"
    }
    fn num_states(&self) -> usize {
        self.work_index() + 2
    }
    fn num_dynamic_states(&self) -> usize {
        self.work_index()
    }
    fn state_names(&self) -> Vec<String> {
        let mut names = vec!["rate".to_string()];
        if self.holds_speed() {
            names.push("rate_error_integral".into());
        }
        if self.holds_torque() {
            names.push("held_torque".into());
        }
        names.extend(["motor_work".into(), "dissipated_energy".into()]);
        names
    }
    fn initial_state(&self) -> Vec<f64> {
        let mut x = vec![0.0; self.num_states()];
        x[0] = self.initial_rate;
        if let MotorMode::Torque(profile @ TorqueProfile::Steps(_)) = &self.mode {
            x[1] = profile.at(0.0);
        }
        x
    }
    fn scratch_len(&self) -> usize {
        // u, v, f.
        3
    }
    fn couple(&self, hub: &HubState, x: &[f64], c: &mut HubCoupling, scratch: &mut [f64]) {
        let a = self.axis;
        let (u, v) = self.motor_torque(hub.t, x);
        let f = self.friction.torque(x[0]);
        scratch[0] = u;
        scratch[1] = v;
        scratch[2] = f;
        let mut block = c.mass.fixed_view_mut::<3, 3>(3, 3);
        block -= self.axial_inertia * a * a.transpose();
        let rotor = self.axial_inertia * x[0] * a;
        c.add_torque(&(-hub.omega.cross(&rotor) - (u - f) * a));
    }
    fn derivatives(
        &self,
        _hub: &HubState,
        accel: &HubAcceleration,
        x: &[f64],
        scratch: &[f64],
        dx: &mut [f64],
    ) {
        let (u, v, f) = (scratch[0], scratch[1], scratch[2]);
        dx[0] = (u - f) / self.axial_inertia - self.axis.dot(&accel.angular);
        if let MotorMode::SpeedHold(hold) = &self.mode {
            // Back-calculation anti-windup with the tracking time K_p/K_i.
            dx[1] = (hold.rate - x[0]) + (u - v) / hold.kp;
        }
        if self.holds_torque() {
            dx[1] = 0.0;
        }
        let w = self.work_index();
        dx[w] = u * x[0];
        dx[w + 1] = f * x[0];
    }
    fn momentum(&self, hub: &HubState, x: &[f64]) -> Momentum {
        let spin = self.axis.dot(&hub.omega);
        Momentum {
            angular: self.axial_inertia * x[0] * self.axis,
            kinetic_energy: self.axial_inertia * x[0] * (spin + 0.5 * x[0]),
            ..Momentum::default()
        }
    }
    fn energy(&self, _hub: &HubState, x: &[f64]) -> EnergyAccount {
        let w = self.work_index();
        EnergyAccount {
            elastic: 0.0,
            dissipated: x[w + 1],
            power: self.friction.torque(x[0]) * x[0],
            work: x[w],
        }
    }
    fn telemetry_names(&self) -> Vec<String> {
        [
            "rate",
            "momentum",
            "motor_torque",
            "friction_torque",
            "motor_work",
            "dissipated_energy",
            "dissipation_power",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    }
    fn telemetry(&self, hub: &HubState, x: &[f64]) -> Vec<f64> {
        let (u, _) = self.motor_torque(hub.t, x);
        let f = self.friction.torque(x[0]);
        let w = self.work_index();
        vec![
            x[0],
            self.axial_inertia * x[0],
            u,
            f,
            x[w],
            x[w + 1],
            f * x[0],
        ]
    }
    fn next_breakpoint(&self, t: f64) -> Option<f64> {
        match &self.mode {
            MotorMode::Torque(profile) => profile.next_breakpoint(t),
            MotorMode::RateDamping(law) => Some(law.clock.next_tick(t)),
            _ => None,
        }
    }
    fn at_breakpoint(&self, hub: &HubState, x: &mut [f64]) {
        // The step profile's new value, held until the next breakpoint.
        match &self.mode {
            MotorMode::Torque(profile @ TorqueProfile::Steps(_)) => x[1] = profile.at(hub.t),
            // The controller's tick: sample ω, hold the command until the next.
            MotorMode::RateDamping(law) => x[1] = law.gains.dot(&hub.omega),
            _ => {}
        }
    }
    fn sampled_rate_loop(&self) -> Option<(nalgebra::Matrix3<f64>, f64)> {
        match &self.mode {
            // The reaction on the hub of the command u = gains·ω along the axis.
            MotorMode::RateDamping(law) => {
                Some((self.axis * law.gains.transpose(), law.clock.period))
            }
            _ => None,
        }
    }
    fn held_rotor_states(&self) -> Option<Vec<(usize, f64)>> {
        // At the held rate the motor supplies the friction: K_i z = f(Ω_cmd) (with K_i = 0
        // a proportional loop settles off its command, so no state holds the rate exactly).
        match &self.mode {
            MotorMode::SpeedHold(hold) if hold.ki > 0.0 => Some(vec![
                (0, hold.rate),
                (1, self.friction.torque(hold.rate) / hold.ki),
            ]),
            _ => None,
        }
    }
    fn validity(&self, x: &[f64]) -> Option<Validity> {
        rotor_speed_validity(self.max_speed, x[0])
    }
    fn validity_report(&self, x: &[f64]) -> (String, String) {
        (
            rotor_speed_report(self.max_speed, x[0]),
            "a lower commanded rate or torque, a wheel with more inertia, or momentum \
             unloading"
                .into(),
        )
    }
    fn drawings(&self, _x: &[f64]) -> Vec<Drawing> {
        vec![Drawing::Disc {
            center: self.position,
            axis: self.axis,
            diameter: self.diameter,
            thickness: 0.25 * self.diameter,
        }]
    }
}
