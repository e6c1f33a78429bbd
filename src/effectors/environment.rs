//! What the environmental torques (gravity gradient, magnetic dipole, aerodynamic, solar
//! pressure) share: one [`Effector`] implementation over an [`EnvironmentTorque`] model, and
//! the rotation of an inertial vector into body axes by the integrated quaternion.
//!
//! Each such torque is external and torque-only, and carries one bookkeeping state: the work
//! it has done on the hub, W = ∫ τ·ω dt (J), which the energy balance subtracts. A model
//! states only its name, kind, torque and telemetry, as functions of the hub state (time,
//! attitude and rates: most use the first two, eddy currents the rates too), and, when its
//! model holds only in a range of that state, where it stands.

use crate::model::{
    Effector, EnergyAccount, HubAcceleration, HubCoupling, HubState, Secular, Validity,
};
use nalgebra::{Matrix3, Vector3};
use std::fmt::Debug;

/// An environmental torque on the hub, a function of the hub state (time `hub.t`, the
/// integrated attitude `hub.attitude` (w, x, y, z; body → inertial; not quite unit) and the
/// body rates `hub.omega`).
pub trait EnvironmentTorque: Debug + Send + Sync {
    /// Unique name (telemetry topic).
    fn name(&self) -> &str;
    /// The kind as written in YAML.
    fn kind(&self) -> &'static str;
    /// The torque (N m, body axes) at the hub state `hub`.
    fn environment_torque(&self, hub: &HubState) -> Vector3<f64>;
    /// Names of its telemetry fields (`work` among them; units in `log::units`).
    fn telemetry_names(&self) -> Vec<String>;
    /// Telemetry values at `hub`, with the work done so far `work` (J), in the order of
    /// [`EnvironmentTorque::telemetry_names`].
    fn telemetry(&self, hub: &HubState, work: f64) -> Vec<f64>;
    /// The gradient of its field (1/s², body axes) at `hub`, when the field also acts on
    /// the masses other effectors move ([`Effector::tidal_gradient`]); `None` otherwise.
    fn tidal_gradient(&self, _hub: &HubState) -> Option<Matrix3<f64>> {
        None
    }
    /// Where the hub state stands against the range its model holds in
    /// ([`Effector::validity_at`]); `None` (the default) for a model without one.
    fn validity(&self, _hub: &HubState) -> Option<Validity> {
        None
    }
    /// [`EnvironmentTorque::validity`] in words: `(where it stands, remedy)`.
    fn validity_report(&self, _hub: &HubState) -> (String, String) {
        (String::new(), String::new())
    }
    /// [`Effector::field_angle`] (rad); `None` by default.
    fn field_angle(&self, _hub: &HubState) -> Option<f64> {
        None
    }
    /// Whether [`EnvironmentTorque::tidal_gradient`] gives a field.
    fn acts_on_moving_masses(&self) -> bool {
        false
    }
    /// Its effect averaged over the torque-free motion and the orbit, for `method: averaged`
    /// ([`Effector::secular`]); `None` (the default) when it cannot be averaged. Its one
    /// state, the work, grows at the averaged power.
    fn secular(&self) -> Option<Box<dyn Secular>> {
        None
    }
}

/// C(q)ᵀ v: the inertial vector `v` in body axes, for the integrated, not quite unit,
/// quaternion `q` (w, x, y, z). For such a q, (w² − |u|²) v + 2 (u·v) u − 2 w (u × v) is |q|²
/// times the rotated vector; dividing by |q|² normalises exactly, without a square root.
#[inline(always)]
pub fn to_body(q: &[f64], v: &Vector3<f64>) -> Vector3<f64> {
    let (w, u) = (q[0], Vector3::new(q[1], q[2], q[3]));
    let u2 = u.norm_squared();
    ((w * w - u2) * v + 2.0 * u.dot(v) * u - 2.0 * w * u.cross(v)) / (w * w + u2)
}

impl<T: EnvironmentTorque + 'static> Effector for T {
    fn name(&self) -> &str {
        EnvironmentTorque::name(self)
    }
    fn kind(&self) -> &'static str {
        EnvironmentTorque::kind(self)
    }
    fn num_states(&self) -> usize {
        1
    }
    fn num_dynamic_states(&self) -> usize {
        0
    }
    fn state_names(&self) -> Vec<String> {
        vec!["work".into()]
    }
    fn initial_state(&self) -> Vec<f64> {
        vec![0.0]
    }
    fn is_external(&self) -> bool {
        true
    }
    fn acts_on_moving_masses(&self) -> bool {
        EnvironmentTorque::acts_on_moving_masses(self)
    }
    fn tidal_gradient(&self, hub: &HubState) -> Option<Matrix3<f64>> {
        EnvironmentTorque::tidal_gradient(self, hub)
    }
    fn scratch_len(&self) -> usize {
        3
    }
    fn torque_only(&self) -> bool {
        true
    }
    fn torque(&self, hub: &HubState, _x: &[f64]) -> Vector3<f64> {
        self.environment_torque(hub)
    }
    fn couple(&self, hub: &HubState, _x: &[f64], coupling: &mut HubCoupling, scratch: &mut [f64]) {
        let tau = self.environment_torque(hub);
        coupling.add_torque(&tau);
        scratch[..3].copy_from_slice(tau.as_slice());
    }
    fn derivatives(
        &self,
        hub: &HubState,
        accel: &HubAcceleration,
        _x: &[f64],
        scratch: &[f64],
        dx: &mut [f64],
    ) {
        // Power of the torque on the hub: τ·ω (the torque is the scratch), plus that of the
        // field on the moving masses when it acts on them.
        dx[0] = scratch[0] * hub.omega[0] + scratch[1] * hub.omega[1] + scratch[2] * hub.omega[2];
        if EnvironmentTorque::acts_on_moving_masses(self) {
            dx[0] += accel.tidal_power;
        }
    }
    fn energy(&self, _hub: &HubState, x: &[f64]) -> EnergyAccount {
        EnergyAccount {
            work: x[0],
            ..EnergyAccount::default()
        }
    }
    fn telemetry_names(&self) -> Vec<String> {
        EnvironmentTorque::telemetry_names(self)
    }
    fn telemetry(&self, hub: &HubState, x: &[f64]) -> Vec<f64> {
        EnvironmentTorque::telemetry(self, hub, x[0])
    }
    fn field_angle(&self, hub: &HubState) -> Option<f64> {
        EnvironmentTorque::field_angle(self, hub)
    }
    fn validity_at(&self, hub: &HubState, _x: &[f64]) -> Option<Validity> {
        EnvironmentTorque::validity(self, hub)
    }
    fn validity_report_at(&self, hub: &HubState, _x: &[f64]) -> (String, String) {
        EnvironmentTorque::validity_report(self, hub)
    }
    fn secular(&self) -> Option<Box<dyn Secular>> {
        EnvironmentTorque::secular(self)
    }
}

/// Field names from string literals.
pub fn names(fields: &[&str]) -> Vec<String> {
    fields.iter().map(|s| s.to_string()).collect()
}
