//! `eddy_currents`: the torque of the currents a magnetic field induces in a rotating
//! conducting (non-magnetic) body, by the magnetic-tensor model of Ortiz Gómez & Walker
//! ("Eddy currents applied to de-tumbling of space debris", Acta Astronautica 114, 2015).
//!
//! In body axes the ambient field B changes as Ḃ = −ω × B. At a low magnetic Reynolds
//! number the induced currents follow Ḃ without lag and without changing the field, so the
//! induced magnetic moment is linear in Ḃ, m = −M Ḃ = M (ω × B), with M the body's magnetic
//! tensor (S m⁴, body axes, symmetric positive semi-definite), and the torque is
//!
//! ```text
//! τ = m × B = (M (ω × B)) × B,        τ·ω = −(ω × B)ᵀ M (ω × B) ≤ 0
//! ```
//!
//! For an isotropic M = μ 1 this is τ = −μ |B|² ω⊥, ω⊥ the rate across B: the spin about B
//! induces nothing and is kept.
//!
//! Tensors from geometry and conductivity σ (S/m), derived from the quasi-static induced
//! field E = −½ Ḃ × r (tangential at every sphere about the centre, so no charge builds up):
//! - spherical shell of outer radius R and wall h (solid sphere: h = R), exact at low
//!   Reynolds number for any wall: M = (2π/15) σ (R⁵ − (R − h)⁵) 1, which is
//!   (2π/3) σ h R⁴ 1 for a thin wall (Ortiz Gómez & Walker) and (2π/15) σ R⁵ 1 solid;
//! - open thin-walled cylinder (no end caps) of radius R, length L, wall h, axis â:
//!   M = π σ h R³ [½ L â âᵀ + (L − 2R tanh(L/2R)) (1 − â âᵀ)], the across-axis term from the
//!   stream function of the wall's currents, which close near the open ends.
//!
//! Validity: the model neglects the field of the induced currents, which makes them lag and
//! weakens the torque once the skin depth δ = √(2/(μ₀σ|ω|)) is not large against the
//! conductor. With ℓ² = h R (R for a solid sphere) and ε = ℓ²/δ² = μ₀σ|ω|ℓ²/2, the torque's
//! relative error is about k ε²: k = 4/9 for a thin spherical shell (its currents obey
//! τ_s dBᵢ/dt + Bᵢ = B with τ_s = μ₀σhR/3, so the exact torque carries 1/(1 + (ωτ_s)²)),
//! k = 0.0381 for a solid sphere (the low-frequency expansion of its exact polarisability,
//! Landau & Lifshitz, *Electrodynamics of Continuous Media*, §59), k = 1 for the cylinder
//! (τ = μ₀σhR/2 of the long cylinder, an upper bound). That error estimate is the
//! effector's validity measure.

use super::environment::{EnvironmentTorque, names, to_body};
use crate::averaging::eddy::{AveragedEddy, FieldMoments};
use crate::model::{HubState, Secular, Validity};
use crate::orbit::{GeomagneticField, Orbit};
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::PI;
use std::sync::Arc;

/// The vacuum permeability μ₀ (H/m; CODATA 2018).
pub const MU_0: f64 = 1.256_637_062_12e-6;

/// Estimated relative torque error past which a run is warned (the measure of
/// [`EddyCurrents::validity`]).
pub const ERROR_WARN: f64 = 0.01;

/// Estimated relative torque error past which the model does not hold: refused at load,
/// and a run stops (`checks.on_validity`).
pub const ERROR_LIMIT: f64 = 0.1;

/// A conducting body whose magnetic tensor follows from its geometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Conductor {
    /// A spherical shell of outer radius `radius` (m) and wall `thickness` (m, up to the
    /// radius: a solid sphere).
    SphericalShell {
        /// Outer radius R (m).
        radius: f64,
        /// Wall thickness h (m), 0 < h ≤ R.
        thickness: f64,
    },
    /// An open thin-walled cylinder (no end caps).
    CylindricalShell {
        /// Radius R of the wall (m).
        radius: f64,
        /// Length L (m).
        length: f64,
        /// Wall thickness h (m), h ≪ R.
        thickness: f64,
        /// Unit axis â (body axes).
        axis: Vector3<f64>,
    },
}

impl Conductor {
    /// The magnetic tensor M (S m⁴, body axes) for conductivity `sigma` (S/m).
    pub fn tensor(&self, sigma: f64) -> Matrix3<f64> {
        match *self {
            Conductor::SphericalShell { radius, thickness } => {
                let inner = (radius - thickness).max(0.0);
                Matrix3::identity() * (2.0 * PI / 15.0) * sigma * (radius.powi(5) - inner.powi(5))
            }
            Conductor::CylindricalShell {
                radius,
                length,
                thickness,
                axis,
            } => {
                let k = PI * sigma * thickness * radius.powi(3);
                let along = 0.5 * length;
                let across = length - 2.0 * radius * (length / (2.0 * radius)).tanh();
                let aa = axis * axis.transpose();
                k * (along * aa + across * (Matrix3::identity() - aa))
            }
        }
    }

    /// ℓ² (m²): the conductor's size in the magnetic Reynolds number ε = μ₀σ|ω|ℓ²/2, h R
    /// for a wall, R² for a solid sphere.
    pub fn length_squared(&self) -> f64 {
        match *self {
            Conductor::SphericalShell { radius, thickness } => radius * thickness.min(radius),
            Conductor::CylindricalShell {
                radius, thickness, ..
            } => radius * thickness,
        }
    }

    /// k: the torque's relative error is about k ε² at small ε (see the module's notes).
    pub fn error_coefficient(&self) -> f64 {
        match *self {
            Conductor::SphericalShell { radius, thickness } if thickness >= radius => 0.0381,
            Conductor::SphericalShell { .. } => 4.0 / 9.0,
            Conductor::CylindricalShell { .. } => 1.0,
        }
    }

    /// The conductor in words, for messages.
    pub fn describe(&self) -> String {
        match *self {
            Conductor::SphericalShell { radius, thickness } if thickness >= radius => {
                format!("solid sphere of radius {radius} m")
            }
            Conductor::SphericalShell { radius, thickness } => {
                format!("spherical shell of radius {radius} m and wall {thickness} m")
            }
            Conductor::CylindricalShell {
                radius,
                length,
                thickness,
                ..
            } => format!(
                "cylindrical shell of radius {radius} m, length {length} m and wall {thickness} m"
            ),
        }
    }
}

/// The material and shape behind a tensor, for its validity range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// The body.
    pub conductor: Conductor,
    /// Electrical conductivity σ (S/m).
    pub conductivity: f64,
}

impl Material {
    /// The magnetic Reynolds number ε = ℓ²/δ² = μ₀σ|ω|ℓ²/2 at the rate `rate` (rad/s).
    pub fn reynolds(&self, rate: f64) -> f64 {
        0.5 * MU_0 * self.conductivity * rate * self.conductor.length_squared()
    }

    /// The skin depth δ = √(2/(μ₀σ|ω|)) (m) at the rate `rate` (rad/s).
    pub fn skin_depth(&self, rate: f64) -> f64 {
        (2.0 / (MU_0 * self.conductivity * rate)).sqrt()
    }

    /// The estimated relative error of the torque, k ε², at the rate `rate` (rad/s).
    pub fn torque_error(&self, rate: f64) -> f64 {
        let e = self.reynolds(rate);
        self.conductor.error_coefficient() * e * e
    }

    /// Where the rate `rate` (rad/s) stands, in words: `(where it stands, remedy)`.
    pub fn report(&self, rate: f64) -> (String, String) {
        (
            format!(
                "at |ω| = {rate:.4e} rad/s the skin depth δ = {:.4e} m against ℓ = √(hR) = \
                 {:.4e} m of the {} (σ = {:e} S/m) gives the magnetic Reynolds number \
                 ε = ℓ²/δ² = {:.4} and an estimated torque error k ε² = {:.3} (k = {}; \
                 warning at {ERROR_WARN}, limit {ERROR_LIMIT}): the induced currents' own \
                 field, which the low-Reynolds model leaves out, weakens the torque",
                self.skin_depth(rate),
                self.conductor.length_squared().sqrt(),
                self.conductor.describe(),
                self.conductivity,
                self.reynolds(rate),
                self.torque_error(rate),
                self.conductor.error_coefficient()
            ),
            "a slower spin, or a model with the skin effect (not in polhode)".into(),
        )
    }
}

/// The field the body turns in.
#[derive(Debug, Clone)]
pub enum AmbientField {
    /// The Earth's field (first-degree IGRF) along the orbit.
    Geomagnetic {
        /// The orbit of the spacecraft's centre of mass.
        orbit: Arc<Orbit>,
        /// The field model (carries the scenario epoch).
        field: GeomagneticField,
    },
    /// A field uniform and constant in inertial space (T, inertial axes): for checks
    /// against closed forms, from code only.
    Uniform(Vector3<f64>),
}

impl AmbientField {
    /// The field (T, body axes) at time `t` (s) for the integrated attitude `q` (w, x, y, z;
    /// body → inertial; normalised here).
    #[inline]
    pub fn body(&self, t: f64, q: &[f64]) -> Vector3<f64> {
        match self {
            AmbientField::Geomagnetic { orbit, field } => {
                super::magnetic_dipole::field_body(orbit, field, t, q)
            }
            AmbientField::Uniform(b) => to_body(q, b),
        }
    }
}

/// Eddy-current damping of a conducting body by its magnetic tensor.
#[derive(Debug, Clone)]
pub struct EddyCurrents {
    /// Name (telemetry topic).
    pub name: String,
    /// The field the body turns in.
    pub field: AmbientField,
    /// The magnetic tensor M (S m⁴ = N m s/T², body axes; symmetric, positive semi-definite).
    pub tensor: Matrix3<f64>,
    /// The material and shape M comes from, which bound the rates the model holds at;
    /// `None` for a tensor given directly (no range known).
    pub material: Option<Material>,
}

impl EddyCurrents {
    /// The torque (M (ω × B)) × B (N m, body axes) for the body rates `omega` (rad/s) and the
    /// field `b` (T), both in body axes.
    #[inline]
    pub fn torque_in(&self, omega: &Vector3<f64>, b: &Vector3<f64>) -> Vector3<f64> {
        (self.tensor * omega.cross(b)).cross(b)
    }
}

impl EnvironmentTorque for EddyCurrents {
    fn name(&self) -> &str {
        &self.name
    }
    fn kind(&self) -> &'static str {
        "eddy_currents"
    }
    fn environment_torque(&self, hub: &HubState) -> Vector3<f64> {
        let b = self.field.body(hub.t, hub.attitude);
        self.torque_in(&hub.omega, &b)
    }
    fn telemetry_names(&self) -> Vec<String> {
        names(&[
            "torque_x", "torque_y", "torque_z", "b_x", "b_y", "b_z", "power", "reynolds", "work",
        ])
    }
    fn telemetry(&self, hub: &HubState, work: f64) -> Vec<f64> {
        let b = self.field.body(hub.t, hub.attitude);
        let tau = self.torque_in(&hub.omega, &b);
        let reynolds = self
            .material
            .map_or(f64::NAN, |m| m.reynolds(hub.omega.norm()));
        vec![
            tau[0],
            tau[1],
            tau[2],
            b[0],
            b[1],
            b[2],
            -tau.dot(&hub.omega),
            reynolds,
            work,
        ]
    }
    fn validity(&self, hub: &HubState) -> Option<Validity> {
        self.material.map(|m| Validity {
            value: m.torque_error(hub.omega.norm()),
            warn: ERROR_WARN,
            limit: ERROR_LIMIT,
        })
    }
    fn validity_report(&self, hub: &HubState) -> (String, String) {
        self.material
            .map(|m| m.report(hub.omega.norm()))
            .unwrap_or_default()
    }
    fn secular(&self) -> Option<Box<dyn Secular>> {
        let field = match &self.field {
            AmbientField::Geomagnetic { orbit, field } => {
                FieldMoments::orbit(orbit.clone(), field.clone())
            }
            AmbientField::Uniform(b) => FieldMoments::Uniform(b * b.transpose()),
        };
        Some(Box::new(AveragedEddy::new(self.tensor, field)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The thick-shell formula reaches the thin-shell and solid-sphere limits, and the
    /// cylinder's tensor is axisymmetric with the long-cylinder limits.
    #[test]
    fn tensors_reach_their_limits() {
        let sigma = 3.0e7;
        let thin = Conductor::SphericalShell {
            radius: 1.0,
            thickness: 1e-6,
        }
        .tensor(sigma);
        let expected = 2.0 * PI / 3.0 * sigma * 1e-6;
        assert!((thin[(0, 0)] / expected - 1.0).abs() < 3e-6);
        let solid = Conductor::SphericalShell {
            radius: 0.5,
            thickness: 0.5,
        }
        .tensor(sigma);
        assert!((solid[(1, 1)] / (2.0 * PI / 15.0 * sigma * 0.5f64.powi(5)) - 1.0).abs() < 1e-15);
        let axis = Vector3::new(0.0, 0.6, 0.8);
        let long = Conductor::CylindricalShell {
            radius: 0.1,
            length: 1000.0,
            thickness: 1e-3,
            axis,
        }
        .tensor(sigma);
        let k = PI * sigma * 1e-3 * 1e-3 * 1000.0;
        assert!(((axis.transpose() * long * axis)[0] / (0.5 * k) - 1.0).abs() < 1e-12);
        let across = Vector3::new(1.0, 0.0, 0.0);
        let m = (across.transpose() * long * across)[0];
        assert!((m / k - (1.0 - 2e-4)).abs() < 1e-12, "{m} vs {k}");
    }

    /// The torque removes energy for an anisotropic tensor, and leaves the spin about B for
    /// an isotropic one.
    #[test]
    fn the_torque_dissipates_and_spares_the_spin_about_the_field() {
        let e = EddyCurrents {
            name: "e".into(),
            field: AmbientField::Uniform(Vector3::new(0.0, 0.0, 3e-5)),
            tensor: Matrix3::new(2.0, 0.3, 0.1, 0.3, 1.0, -0.2, 0.1, -0.2, 0.5),
            material: None,
        };
        let b = Vector3::new(1e-5, -2e-5, 3e-5);
        for omega in [
            Vector3::new(1.0, 2.0, -0.5),
            Vector3::new(-3.0, 0.1, 0.2),
            b * 1e5,
        ] {
            assert!(e.torque_in(&omega, &b).dot(&omega) <= 0.0);
        }
        let iso = EddyCurrents {
            tensor: Matrix3::identity() * 4.0,
            ..e
        };
        let along = b * 2e4;
        let scale = 4.0 * b.norm_squared() * along.norm();
        assert!(iso.torque_in(&along, &b).norm() <= 1e-15 * scale);
        let across = Vector3::new(2.0, 1.0, 0.0);
        let expected = -4.0 * b.norm_squared() * across;
        assert!((iso.torque_in(&across, &b) - expected).norm() <= 1e-15 * expected.norm());
    }
}
