//! `rayleigh`: a Rayleigh dissipation function R = ½ ωᵀ Γ ω (Γ symmetric positive
//! semi-definite) and its torque τ = −∂R/∂ω = −Γ ω.
//!
//! Then dT/dt = ωᵀ τ = −2R exactly. The torque acts like external friction: it drains |H| as well
//! as energy (Rayleigh's dissipation function: Goldstein, *Classical Mechanics*, §1.5). One
//! bookkeeping state, the dissipated energy (Ẇ = 2R), closes the energy balance T + W = T₀.

use crate::model::{
    Effector, EnergyAccount, HubAcceleration, HubCoupling, HubState, Secular, SecularMotion,
    SecularRates,
};
use nalgebra::{Matrix3, Vector3};

/// Rayleigh dissipation torque.
#[derive(Debug, Clone)]
pub struct Rayleigh {
    /// Name.
    pub name: String,
    /// Γ (N m s/rad), symmetric positive semi-definite, body axes.
    pub gamma: Matrix3<f64>,
}

impl Rayleigh {
    /// The dissipation function R = ½ ωᵀ Γ ω (W/2) at body rates `omega`.
    pub fn dissipation_function(&self, omega: &nalgebra::Vector3<f64>) -> f64 {
        0.5 * omega.dot(&(self.gamma * omega))
    }
}

impl Effector for Rayleigh {
    fn name(&self) -> &str {
        &self.name
    }
    fn kind(&self) -> &'static str {
        "rayleigh"
    }
    fn num_states(&self) -> usize {
        1
    }
    fn num_dynamic_states(&self) -> usize {
        0
    }
    fn state_names(&self) -> Vec<String> {
        vec!["dissipated_energy".into()]
    }
    fn initial_state(&self) -> Vec<f64> {
        vec![0.0]
    }
    fn is_external(&self) -> bool {
        true
    }
    fn torque_only(&self) -> bool {
        true
    }
    fn torque(&self, hub: &HubState, _x: &[f64]) -> Vector3<f64> {
        -(self.gamma * hub.omega)
    }
    fn couple(&self, hub: &HubState, _x: &[f64], c: &mut HubCoupling, _s: &mut [f64]) {
        c.add_torque(&(-(self.gamma * hub.omega)));
    }
    fn derivatives(
        &self,
        hub: &HubState,
        _a: &HubAcceleration,
        _x: &[f64],
        _s: &[f64],
        dx: &mut [f64],
    ) {
        dx[0] = 2.0 * self.dissipation_function(&hub.omega);
    }
    fn secular(&self) -> Option<Box<dyn Secular>> {
        Some(Box::new(self.clone()))
    }
    fn energy(&self, hub: &HubState, x: &[f64]) -> EnergyAccount {
        EnergyAccount {
            elastic: 0.0,
            dissipated: x[0],
            power: 2.0 * self.dissipation_function(&hub.omega),
            work: 0.0,
        }
    }
    fn telemetry_names(&self) -> Vec<String> {
        vec!["dissipated_energy".into(), "dissipation_power".into()]
    }
    fn telemetry(&self, hub: &HubState, x: &[f64]) -> Vec<f64> {
        vec![x[0], 2.0 * self.dissipation_function(&hub.omega)]
    }
}

impl Secular for Rayleigh {
    fn rates(&self, motion: &SecularMotion) -> SecularRates {
        // ⟨ωᵀ A ω⟩ = tr(A ⟨ω ωᵀ⟩): dT/dt = −ωᵀΓω and d|H|/dt = Ĥ·τ = −(Jω)ᵀΓω / |H|.
        let power = (self.gamma * motion.omega_omega).trace();
        let h_rate = if motion.h > 0.0 {
            -(motion.inertia * self.gamma * motion.omega_omega).trace() / motion.h
        } else {
            0.0
        };
        SecularRates {
            energy_rate: -power,
            h_rate,
            dissipation_rate: power,
            ..SecularRates::default()
        }
    }
}
