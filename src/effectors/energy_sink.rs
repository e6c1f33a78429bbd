//! `energy_sink`: the quasi-rigid model of internal energy dissipation (Thomson & Reiter
//! 1960; Likins 1967; Hughes 1986, ch. 5).
//!
//! τ = −c (ω − (ω·Ĥ) Ĥ) with Ĥ = Iω/|Iω| (the hub's momentum direction, body axes). Then
//! H·τ = 0, so |H| is kept (the direction of H_N is not: the torque is not a true internal
//! force), and dT/dt = −c |ω⊥|² ≤ 0, ω⊥ = ω − (ω·Ĥ)Ĥ. The body drifts to rotation about its
//! maximum-inertia axis with T = |H|²/(2 I_max). One bookkeeping state, the dissipated energy.
//! The coefficient can be given directly or solved from a target nutation time constant.

use crate::model::{
    Effector, EnergyAccount, HubAcceleration, HubCoupling, HubState, Secular, SecularMotion,
    SecularRates,
};
use nalgebra::{Matrix3, Vector3};

/// Energy-sink torque.
#[derive(Debug, Clone)]
pub struct EnergySink {
    /// Name.
    pub name: String,
    /// Coefficient c (N m s/rad).
    pub coefficient: f64,
    /// The hub's inertia (kg m²), for Ĥ.
    pub inertia: Matrix3<f64>,
}

impl EnergySink {
    /// ω⊥ = ω − (ω·Ĥ) Ĥ (rad/s).
    pub fn transverse_rate(&self, omega: &Vector3<f64>) -> Vector3<f64> {
        let h = self.inertia * omega;
        let n2 = h.norm_squared();
        if n2 == 0.0 {
            return Vector3::zeros();
        }
        omega - h * (omega.dot(&h) / n2)
    }
}

impl Effector for EnergySink {
    fn name(&self) -> &str {
        &self.name
    }
    fn kind(&self) -> &'static str {
        "energy_sink"
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
        // Keeps |H| but turns H_N.
        true
    }
    fn torque_only(&self) -> bool {
        true
    }
    fn needs_rigid_spacecraft(&self) -> bool {
        true
    }
    fn keeps_momentum_norm(&self) -> bool {
        // H·τ = 0.
        true
    }
    fn torque(&self, hub: &HubState, _x: &[f64]) -> Vector3<f64> {
        -self.coefficient * self.transverse_rate(&hub.omega)
    }
    fn couple(&self, hub: &HubState, _x: &[f64], c: &mut HubCoupling, _s: &mut [f64]) {
        c.add_torque(&(-self.coefficient * self.transverse_rate(&hub.omega)));
    }
    fn derivatives(
        &self,
        hub: &HubState,
        _a: &HubAcceleration,
        _x: &[f64],
        _s: &[f64],
        dx: &mut [f64],
    ) {
        // ω·τ = −c ω·ω⊥ = −c |ω⊥|² (ω⊥ ⊥ Ĥ, so ω·ω⊥ = ω⊥·ω⊥).
        dx[0] = self.coefficient * self.transverse_rate(&hub.omega).norm_squared();
    }
    fn secular(&self) -> Option<Box<dyn Secular>> {
        Some(Box::new(self.clone()))
    }
    fn energy(&self, hub: &HubState, x: &[f64]) -> EnergyAccount {
        EnergyAccount {
            elastic: 0.0,
            dissipated: x[0],
            power: self.coefficient * self.transverse_rate(&hub.omega).norm_squared(),
            work: 0.0,
        }
    }
    fn telemetry_names(&self) -> Vec<String> {
        vec!["dissipated_energy".into(), "dissipation_power".into()]
    }
    fn telemetry(&self, hub: &HubState, x: &[f64]) -> Vec<f64> {
        vec![
            x[0],
            self.coefficient * self.transverse_rate(&hub.omega).norm_squared(),
        ]
    }
}

impl Secular for EnergySink {
    fn rates(&self, motion: &SecularMotion) -> SecularRates {
        // ω·Ĥ = 2T/|H| is constant along the motion, so ⟨|ω⊥|²⟩ = ⟨|ω|²⟩ − (2T/|H|)².
        if motion.h == 0.0 {
            return SecularRates::default();
        }
        let along = 2.0 * motion.energy / motion.h;
        let transverse = (motion.omega_omega.trace() - along * along).max(0.0);
        let power = self.coefficient * transverse;
        SecularRates {
            energy_rate: -power,
            h_rate: 0.0,
            dissipation_rate: power,
            ..SecularRates::default()
        }
    }
}
