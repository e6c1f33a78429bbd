//! A thruster or motor that expels the propellant of its tank: thrust along a direction from a
//! nozzle, the mass flow from the thrust and the specific impulse (or given), and the
//! variable-mass terms of the hub's equations (docs/effectors.md, "Thruster").
//!
//! The spacecraft is the control volume: the hub, the propellant left in the tank
//! ([`PropellantTank`]) and every other effector. With the mass flow ṁ ≥ 0 leaving through the
//! nozzle exit at r_e (body axes, about the hub's centre of mass B) with thrust **F** (the
//! exhaust's velocity relative to the body is **u** = −**F**/ṁ), the propellant's mass m,
//! centre r, inertia about B J_B and their body-frame rates, Reynolds' transport theorem gives
//! (Panicucci, Allard & Schaub, J. Astronaut. Sci. 65, 2018; Thomson, *Introduction to Space
//! Dynamics*, 1961, for the jet damping ṁ r_e × (ω × r_e)):
//!
//! ```text
//! translation:  m a_B − m r × ω̇ + … = F − ω × (ω × m r) + ṁ ω × (r − r_e) − 2 m ω × r′ + ṁ r′ − m r″
//! rotation:     J_B ω̇ + m r × a_B + … = r_e × F − ω × J_B ω − J_B′ ω − ṁ r_e × (ω × r_e)
//!                                      + ṁ r × r′ − m r × r″ − m ω × (r × r′)
//! ```
//!
//! the terms this effector adds to the hub's ([`HubCoupling`]). The angular momentum the
//! exhaust carries out about the system's centre of mass C, ṁ (r_e − c) × (v_e − v_C), is
//! integrated in inertial axes as three bookkeeping states, so that H + what the exhaust took
//! is the conserved quantity the run's drift measures.

use super::propellant_tank::{PropellantTank, TankState};
use crate::model::{CentreOfMass, Effector, HubAcceleration, HubCoupling, HubState, Momentum};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

/// Standard gravity g₀ (m/s²), which converts a specific impulse to an exhaust velocity
/// (3rd CGPM, 1901).
pub const STANDARD_GRAVITY: f64 = 9.80665;

/// A quantity given as a function of time: constant, or linear between points and zero
/// outside them.
#[derive(Debug, Clone, PartialEq)]
pub enum Profile {
    /// The same value at every time.
    Constant(f64),
    /// Linear between the points `(t, v)` (times strictly increasing), zero before the first
    /// and after the last; with the integral from the first point to each point.
    Table {
        /// The points (s, value).
        points: Vec<(f64, f64)>,
        /// ∫ from the first point to point k.
        cumulative: Vec<f64>,
    },
}

impl Profile {
    /// A table (times strictly increasing, at least two points).
    pub fn table(points: Vec<(f64, f64)>) -> Profile {
        let mut cumulative = vec![0.0; points.len()];
        for k in 1..points.len() {
            let ((t0, v0), (t1, v1)) = (points[k - 1], points[k]);
            cumulative[k] = cumulative[k - 1] + 0.5 * (v0 + v1) * (t1 - t0);
        }
        Profile::Table { points, cumulative }
    }

    /// The value at time `t` and its slope (per s).
    pub fn at(&self, t: f64) -> (f64, f64) {
        match self {
            Profile::Constant(v) => (*v, 0.0),
            Profile::Table { points, .. } => {
                let k = points.partition_point(|p| p.0 <= t);
                if k == 0 || k == points.len() {
                    return (0.0, 0.0);
                }
                let ((t0, v0), (t1, v1)) = (points[k - 1], points[k]);
                let slope = (v1 - v0) / (t1 - t0);
                (v0 + slope * (t - t0), slope)
            }
        }
    }

    /// ∫ from the first point (or −∞ for a constant: from 0) to `t`.
    fn antiderivative(&self, t: f64) -> f64 {
        match self {
            Profile::Constant(v) => v * t,
            Profile::Table { points, cumulative } => {
                let k = points.partition_point(|p| p.0 <= t);
                if k == 0 {
                    return 0.0;
                }
                if k == points.len() {
                    return cumulative[k - 1];
                }
                let (t0, v0) = points[k - 1];
                let (v, _) = self.at(t);
                cumulative[k - 1] + 0.5 * (v0 + v) * (t - t0)
            }
        }
    }

    /// ∫ from 0 to `t` (exact: the pieces are linear).
    pub fn integral(&self, t: f64) -> f64 {
        self.antiderivative(t) - self.antiderivative(0.0)
    }

    /// The first time after `t` (s) where the profile is not smooth.
    pub fn next_breakpoint(&self, t: f64) -> Option<f64> {
        match self {
            Profile::Constant(_) => None,
            Profile::Table { points, .. } => {
                let k = points.partition_point(|p| p.0 <= t);
                points.get(k).map(|p| p.0)
            }
        }
    }
}

/// Where the mass flow comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum MassFlow {
    /// ṁ = F / (g₀ I_sp), with I_sp the specific impulse (s).
    SpecificImpulse(f64),
    /// ṁ given as a profile (kg/s).
    Given(Profile),
}

/// A thruster drawing on one tank.
#[derive(Debug, Clone)]
pub struct Thruster {
    name: String,
    /// Centre of the nozzle exit (m, body axes, about B).
    pub nozzle: Vector3<f64>,
    /// Unit thrust direction (body axes); the exhaust leaves along its opposite.
    pub direction: Vector3<f64>,
    /// Radius of the nozzle exit (m): the exhaust leaves uniformly over the disc, which adds
    /// ṁ (a²/4)(1 + d dᵀ) to the jet damping (0: a point).
    pub exit_radius: f64,
    /// Thrust magnitude (N) against time.
    pub thrust: Profile,
    /// The mass flow.
    pub flow: MassFlow,
    /// The tank it draws on; `None` when another effector carries the propellant and the
    /// flow inside the spacecraft to this nozzle (a [`super::DrainingSlosh`] tank): this one
    /// then adds the thrust and the exhaust's momentum flux alone.
    pub tank: Option<PropellantTank>,
    /// Propellant in the tank at t = 0 (kg); 0 without a tank.
    pub initial_propellant: f64,
}

impl Thruster {
    /// A thruster named `name` drawing on `tank`, which holds `initial_propellant` (kg) at
    /// t = 0; `direction` is normalised here.
    pub fn new(
        name: impl Into<String>,
        nozzle: Vector3<f64>,
        direction: Vector3<f64>,
        thrust: Profile,
        flow: MassFlow,
        tank: PropellantTank,
        initial_propellant: f64,
    ) -> Thruster {
        Thruster {
            tank: Some(tank),
            initial_propellant,
            ..Thruster::fed(name, nozzle, direction, thrust, flow)
        }
    }

    /// A thruster whose propellant, and the flow inside the spacecraft to its nozzle, another
    /// effector carries (a [`super::DrainingSlosh`] tank); `direction` is normalised here.
    pub fn fed(
        name: impl Into<String>,
        nozzle: Vector3<f64>,
        direction: Vector3<f64>,
        thrust: Profile,
        flow: MassFlow,
    ) -> Thruster {
        Thruster {
            name: name.into(),
            nozzle,
            direction: direction.normalize(),
            exit_radius: 0.0,
            thrust,
            flow,
            tank: None,
            initial_propellant: 0.0,
        }
    }

    /// The same with a nozzle exit of radius `radius` (m).
    pub fn with_exit_radius(mut self, radius: f64) -> Thruster {
        self.exit_radius = radius;
        self
    }

    /// ⟨ρ × (ω × ρ)⟩ over the exit disc, per unit mass flow (m²/s): (a²/4)(ω + d (d·ω)).
    fn exit_spread(&self, omega: &Vector3<f64>) -> Vector3<f64> {
        let d = &self.direction;
        0.25 * self.exit_radius * self.exit_radius * (omega + d * d.dot(omega))
    }

    /// The largest thrust of its profile (N).
    pub fn peak_thrust(&self) -> f64 {
        match &self.thrust {
            Profile::Constant(v) => *v,
            Profile::Table { points, .. } => points.iter().map(|p| p.1).fold(0.0, f64::max),
        }
    }

    /// The mass flow ṁ ≥ 0 (kg/s) at `t` and its rate (kg/s²).
    pub fn mass_flow(&self, t: f64) -> (f64, f64) {
        match &self.flow {
            MassFlow::SpecificImpulse(isp) => {
                let (f, df) = self.thrust.at(t);
                let c = 1.0 / (STANDARD_GRAVITY * isp);
                (f * c, df * c)
            }
            MassFlow::Given(p) => p.at(t),
        }
    }

    /// Propellant expelled from 0 to `t` (kg).
    pub fn expelled(&self, t: f64) -> f64 {
        match &self.flow {
            MassFlow::SpecificImpulse(isp) => self.thrust.integral(t) / (STANDARD_GRAVITY * isp),
            MassFlow::Given(p) => p.integral(t),
        }
    }

    /// The propellant's mass properties at `t`; `None` without a tank of its own.
    pub fn tank_state(&self, t: f64) -> Option<TankState> {
        let (flow, flow_rate) = self.mass_flow(t);
        let mass = self.initial_propellant - self.expelled(t);
        self.tank
            .as_ref()
            .map(|tank| tank.state(mass, -flow, -flow_rate))
    }

    /// The first time after `t` where the thrust or the flow is not smooth.
    pub fn next_kink(&self, t: f64) -> Option<f64> {
        let flow = match &self.flow {
            MassFlow::Given(p) => p.next_breakpoint(t),
            MassFlow::SpecificImpulse(_) => None,
        };
        match (self.thrust.next_breakpoint(t), flow) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }
}

impl Effector for Thruster {
    fn name(&self) -> &str {
        &self.name
    }
    fn kind(&self) -> &'static str {
        "thruster"
    }
    fn num_states(&self) -> usize {
        3
    }
    fn num_dynamic_states(&self) -> usize {
        0
    }
    fn state_names(&self) -> Vec<String> {
        ["x", "y", "z"]
            .iter()
            .map(|c| format!("exhaust_momentum_{c}"))
            .collect()
    }
    fn initial_state(&self) -> Vec<f64> {
        vec![0.0; 3]
    }
    fn moves_mass(&self) -> bool {
        true
    }
    fn expels_mass(&self) -> bool {
        true
    }
    fn next_breakpoint(&self, t: f64) -> Option<f64> {
        self.next_kink(t)
    }
    fn couple(&self, hub: &HubState, _x: &[f64], c: &mut HubCoupling, _scratch: &mut [f64]) {
        let w = hub.omega;
        let (flow, flow_rate) = self.mass_flow(hub.t);
        let re = self.nozzle;
        let thrust = self.thrust.at(hub.t).0 * self.direction;
        // The exhaust leaving at r_e: the thrust and the momentum flux ṁ (ω × r_e) relative
        // to B's velocity (B's own cancels against the content's mass loss).
        let mut force = thrust - flow * w.cross(&re);
        let mut moment =
            re.cross(&thrust) - flow * re.cross(&w.cross(&re)) - flow * self.exit_spread(&w);
        if let Some(s) = self.tank_state(hub.t) {
            let (m, r, v, a) = (s.mass, s.center, s.center_rate, s.center_accel);
            let j = s.inertia_about_b();
            let dj = s.inertia_about_b_rate();
            super::particles::add_mass_and_first_moment(&mut c.mass, m, &(m * r));
            for i in 0..3 {
                for k in 0..=i {
                    c.mass[(3 + i, 3 + k)] += j[(i, k)];
                }
            }
            // The flow inside, from the propellant's centre to the nozzle: its momentum and
            // angular momentum about B and their body-frame rates.
            let flow_path = re - r;
            let (p_flow, h_flow) = (flow * flow_path, flow * r.cross(&re));
            let dp_flow = flow_rate * flow_path - flow * v;
            let dh_flow = flow_rate * r.cross(&re) + flow * v.cross(&re);
            force += flow * w.cross(&r) - w.cross(&w.cross(&(m * r))) - 2.0 * m * w.cross(&v)
                + flow * v
                - m * a
                - dp_flow
                - w.cross(&p_flow);
            let rv = r.cross(&v);
            moment += -w.cross(&(j * w)) - dj * w + flow * rv
                - m * r.cross(&a)
                - m * w.cross(&rv)
                - dh_flow
                - w.cross(&h_flow);
        }
        for i in 0..3 {
            c.force[i] += force[i];
            c.force[3 + i] += moment[i];
        }
        c.translation = true;
    }
    fn derivatives(
        &self,
        _hub: &HubState,
        _accel: &HubAcceleration,
        _x: &[f64],
        _scratch: &[f64],
        dx: &mut [f64],
    ) {
        // The exhaust's bookkeeping needs the system's centre of mass: `exhaust_rates`.
        dx[..3].fill(0.0);
    }
    fn exhaust_rates(&self, hub: &HubState, centre: &CentreOfMass, _x: &[f64], dx: &mut [f64]) {
        let (flow, _) = self.mass_flow(hub.t);
        let thrust = self.thrust.at(hub.t).0 * self.direction;
        // The exhaust's velocity relative to C: ω × r_e + u − (v_C − v_B), with ṁ u = −F.
        let arm = self.nozzle - centre.offset;
        let momentum = flow * (hub.omega.cross(&self.nozzle) - centre.velocity) - thrust;
        let flux = arm.cross(&momentum) + flow * self.exit_spread(&hub.omega);
        let q = hub.attitude;
        let attitude = UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]));
        let inertial = attitude * flux;
        dx[..3].copy_from_slice(inertial.as_slice());
    }
    fn momentum(&self, hub: &HubState, _x: &[f64]) -> Momentum {
        let Some(s) = self.tank_state(hub.t) else {
            return Momentum::default();
        };
        let w = hub.omega;
        let velocity = w.cross(&s.center) + s.center_rate;
        let (flow, _) = self.mass_flow(hub.t);
        Momentum {
            mass: s.mass,
            first_moment: s.mass * s.center,
            linear: s.mass * velocity + flow * (self.nozzle - s.center),
            angular: s.inertia_about_b() * w
                + s.mass * s.center.cross(&s.center_rate)
                + flow * s.center.cross(&self.nozzle),
            kinetic_energy: 0.5 * w.dot(&(s.inertia * w)) + 0.5 * s.mass * velocity.norm_squared(),
        }
    }
    fn mass_rate(&self, t: f64) -> (f64, Vector3<f64>) {
        let (flow, _) = self.mass_flow(t);
        (-flow, -flow * self.nozzle)
    }
    fn momentum_carried_out(&self, x: &[f64]) -> Vector3<f64> {
        Vector3::new(x[0], x[1], x[2])
    }
    fn telemetry_names(&self) -> Vec<String> {
        let mut names = vec!["thrust".to_string(), "mass_flow".to_string()];
        if self.tank.is_some() {
            names.insert(0, "propellant_mass".into());
        }
        names
    }
    fn telemetry(&self, hub: &HubState, _x: &[f64]) -> Vec<f64> {
        let mut values = vec![self.thrust.at(hub.t).0, self.mass_flow(hub.t).0];
        if let Some(s) = self.tank_state(hub.t) {
            values.insert(0, s.mass);
        }
        values
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn a_table_integrates_exactly_and_is_zero_outside() {
        let p = Profile::table(vec![(1.0, 0.0), (2.0, 10.0), (4.0, 10.0), (5.0, 0.0)]);
        assert_eq!(p.at(0.5), (0.0, 0.0));
        assert_eq!(p.at(1.5), (5.0, 10.0));
        assert_eq!(p.at(6.0), (0.0, 0.0));
        assert_relative_eq!(p.integral(1.5), 1.25, epsilon = 1e-15);
        assert_relative_eq!(p.integral(10.0), 5.0 + 20.0 + 5.0, epsilon = 1e-14);
        assert_eq!(p.next_breakpoint(0.0), Some(1.0));
        assert_eq!(p.next_breakpoint(4.0), Some(5.0));
        assert_eq!(p.next_breakpoint(5.0), None);
        assert_relative_eq!(Profile::Constant(3.0).integral(2.0), 6.0);
    }
}
