//! `aerodynamic`: the torque of atmospheric drag on the hub, for a constant projected area
//! with a fixed centre of pressure ([`Aerodynamic`]), or on the facets of the body's shape
//! ([`ShapeAerodynamic`], with the surface of [`facets`]).
//!
//! With ρ the density at the spacecraft's altitude, v_rel the velocity of the spacecraft's
//! centre of mass relative to the co-rotating atmosphere and r_cp the centre of pressure
//! (body axes, about the hub's centre of mass),
//!
//! ```text
//! v_rel = v − ω_E × r,   F = −½ ρ |v_rel|² C_d A v̂_rel,   τ = r_cp × F
//! ```
//!
//! (Vallado, *Fundamentals of Astrodynamics and Applications*, 4th ed., 2013, §8.6.2, the
//! drag acceleration with the co-rotating atmosphere; Wertz (ed.), *Spacecraft Attitude
//! Determination and Control*, 1978, §17.2, the aerodynamic torque r_cp × F). The density is
//! the exponential atmosphere of Vallado's Table 8-4 ([`density`]). The area A does not
//! change with attitude: the torque depends on the attitude only through the direction of
//! the wind in body axes. The torque is external, so the effector carries one bookkeeping
//! state, the work done on the body `W = ∫ τ·ω dt` (J), which the energy balance subtracts.

pub mod facets;

use super::environment::{EnvironmentTorque, names, to_body};
use crate::model::HubState;
use crate::orbit::Orbit;
use facets::DragSurface;
use nalgebra::Vector3;
use std::sync::Arc;

/// The exponential atmosphere of Vallado (2013), Table 8-4 ("Exponential Atmospheric
/// Model"), typed from the table: base altitude h₀ (km), nominal density ρ₀ (kg/m³) and scale
/// height H (km). Each row holds from its h₀ to the next row's h₀; the last row (1000 km)
/// holds above. Vallado builds it from the U.S. Standard Atmosphere 1976 at 0 km and CIRA-72
/// from 25 to 1000 km (moderate solar activity).
pub const EXPONENTIAL_ATMOSPHERE: [(f64, f64, f64); 28] = [
    (0.0, 1.225, 7.249),
    (25.0, 3.899e-2, 6.349),
    (30.0, 1.774e-2, 6.682),
    (40.0, 3.972e-3, 7.554),
    (50.0, 1.057e-3, 8.382),
    (60.0, 3.206e-4, 7.714),
    (70.0, 8.770e-5, 6.549),
    (80.0, 1.905e-5, 5.799),
    (90.0, 3.396e-6, 5.382),
    (100.0, 5.297e-7, 5.877),
    (110.0, 9.661e-8, 7.263),
    (120.0, 2.438e-8, 9.473),
    (130.0, 8.484e-9, 12.636),
    (140.0, 3.845e-9, 16.149),
    (150.0, 2.070e-9, 22.523),
    (180.0, 5.464e-10, 29.740),
    (200.0, 2.789e-10, 37.105),
    (250.0, 7.248e-11, 45.546),
    (300.0, 2.418e-11, 53.628),
    (350.0, 9.518e-12, 53.298),
    (400.0, 3.725e-12, 58.515),
    (450.0, 1.585e-12, 60.828),
    (500.0, 6.967e-13, 63.822),
    (600.0, 1.454e-13, 71.835),
    (700.0, 3.614e-14, 88.667),
    (800.0, 1.170e-14, 124.64),
    (900.0, 5.245e-15, 181.05),
    (1000.0, 3.019e-15, 268.00),
];

/// The density (kg/m³) at the altitude `h` (m) of the exponential atmosphere
/// [`EXPONENTIAL_ATMOSPHERE`]: ρ = ρ₀ exp(−(h − h₀)/H) in the band with h₀ ≤ h below the
/// next base. Above 1000 km the last band goes on; below 0 km the first band does.
///
/// The band is chosen by the altitude rounded to the millimetre: the fit jumps by 0.14% at
/// 25 km and by under 0.01% at the other band bases, and a circular orbit at a base altitude
/// (400 km, 500 km) has a radius that wanders by an ulp around it, which would otherwise
/// switch bands from one step to the next and make adaptive integrators reject steps.
pub fn density(h: f64) -> f64 {
    let km = h / 1e3;
    let band_km = (h * 1e3).round() / 1e6;
    let row = EXPONENTIAL_ATMOSPHERE
        .iter()
        .rev()
        .find(|r| r.0 <= band_km)
        .unwrap_or(&EXPONENTIAL_ATMOSPHERE[0]);
    let (h0, rho0, scale) = *row;
    rho0 * (-(km - h0) / scale).exp()
}

/// The density (kg/m³) at the altitude of `orbit` at `t` (s), and the velocity relative to
/// the co-rotating atmosphere v − ω_E × r (m/s, ECI).
#[inline]
pub fn density_and_wind_eci(orbit: &Orbit, t: f64) -> (f64, Vector3<f64>) {
    let (r, v) = orbit.state(t);
    let body = orbit.body();
    let rho = density(r.norm() - body.radius);
    // ω_E × r with ω_E = ω_E ẑ.
    let w = body.rotation_rate;
    let wind = v - Vector3::new(-w * r.y, w * r.x, 0.0);
    (rho, wind)
}

/// Drag on the hub with a constant projected area and a fixed centre of pressure.
#[derive(Debug, Clone)]
pub struct Aerodynamic {
    /// Name (telemetry topic).
    pub name: String,
    /// The orbit of the spacecraft's centre of mass.
    pub orbit: Arc<Orbit>,
    /// Drag coefficient C_d (dimensionless).
    pub drag_coefficient: f64,
    /// Projected area A (m²), the same for every attitude.
    pub area: f64,
    /// Centre of pressure r_cp (m, body axes, about the hub's centre of mass).
    pub center_of_pressure: Vector3<f64>,
}

impl Aerodynamic {
    /// The density (kg/m³) at the orbit's altitude at `t`, and the velocity relative to the
    /// co-rotating atmosphere v − ω_E × r (m/s, ECI).
    #[inline]
    pub fn density_and_wind_eci(&self, t: f64) -> (f64, Vector3<f64>) {
        density_and_wind_eci(&self.orbit, t)
    }

    /// The density (kg/m³) and the relative velocity v_rel (m/s, body axes) at `t` for the
    /// attitude `q` (w, x, y, z; body → inertial; normalised here).
    #[inline]
    pub fn density_and_wind(&self, t: f64, q: &[f64]) -> (f64, Vector3<f64>) {
        let (rho, v) = self.density_and_wind_eci(t);
        (rho, to_body(q, &v))
    }

    /// The drag force −½ ρ |v_rel|² C_d A v̂_rel (N, in the axes of `wind`).
    #[inline]
    pub fn force(&self, rho: f64, wind: &Vector3<f64>) -> Vector3<f64> {
        -0.5 * rho * self.drag_coefficient * self.area * wind.norm() * wind
    }

    /// The torque r_cp × F (N m, body axes) at `t` for attitude `q`.
    #[inline]
    pub fn torque_at(&self, t: f64, q: &[f64]) -> Vector3<f64> {
        let (rho, wind) = self.density_and_wind(t, q);
        self.center_of_pressure.cross(&self.force(rho, &wind))
    }
}

/// The telemetry of both drag models (units in `log::units`).
const TELEMETRY: [&str; 8] = [
    "torque_x", "torque_y", "torque_z", "density", "wind_x", "wind_y", "wind_z", "work",
];

/// One telemetry sample in the order of [`TELEMETRY`]: the torque (N m), the density
/// (kg/m³), the relative wind in body axes (m/s) and the work done so far (J).
fn telemetry_row(tau: &Vector3<f64>, rho: f64, wind: &Vector3<f64>, work: f64) -> Vec<f64> {
    vec![tau[0], tau[1], tau[2], rho, wind[0], wind[1], wind[2], work]
}

impl EnvironmentTorque for Aerodynamic {
    fn name(&self) -> &str {
        &self.name
    }
    fn kind(&self) -> &'static str {
        "aerodynamic"
    }
    fn environment_torque(&self, hub: &HubState) -> Vector3<f64> {
        self.torque_at(hub.t, hub.attitude)
    }
    fn telemetry_names(&self) -> Vec<String> {
        names(&TELEMETRY)
    }
    fn telemetry(&self, hub: &HubState, work: f64) -> Vec<f64> {
        let (rho, wind) = self.density_and_wind(hub.t, hub.attitude);
        let tau = self.center_of_pressure.cross(&self.force(rho, &wind));
        telemetry_row(&tau, rho, &wind, work)
    }
}

/// Drag on the facets of the body's shape: the projected area and the centre of pressure
/// follow the attitude. With w = v_rel in body axes and ŵ = w/|w|,
///
/// ```text
/// F = −½ ρ |w|² C_d A_p(ŵ) ŵ,   τ = Σ c_i × F_i = −½ ρ |w|² C_d M(ŵ) × ŵ
/// ```
///
/// with A_p and M the projected area and its first moment of [`DragSurface::projection`].
#[derive(Debug, Clone)]
pub struct ShapeAerodynamic {
    /// Name (telemetry topic).
    pub name: String,
    /// The orbit of the spacecraft's centre of mass.
    pub orbit: Arc<Orbit>,
    /// Drag coefficient C_d of every facet (dimensionless).
    pub drag_coefficient: f64,
    /// The surface (body axes, about the hub's centre of mass).
    pub surface: DragSurface,
}

impl ShapeAerodynamic {
    /// The density (kg/m³) and the relative velocity v_rel (m/s, body axes) at `t` for the
    /// attitude `q` (w, x, y, z; body → inertial; normalised here).
    #[inline]
    pub fn density_and_wind(&self, t: f64, q: &[f64]) -> (f64, Vector3<f64>) {
        let (rho, v) = density_and_wind_eci(&self.orbit, t);
        (rho, to_body(q, &v))
    }

    /// The drag force F (N) and torque τ (N m) for the density `rho` (kg/m³) and the
    /// relative velocity `wind` (m/s), both in body axes; zero in still air.
    #[inline]
    pub fn force_and_torque(&self, rho: f64, wind: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        let speed = wind.norm();
        if speed == 0.0 {
            return (Vector3::zeros(), Vector3::zeros());
        }
        let w_hat = wind / speed;
        let (area, moment) = self.surface.projection(&w_hat);
        // −½ ρ |w|² C_d ŵ = −½ ρ |w| C_d w.
        let k = -0.5 * rho * self.drag_coefficient * speed;
        (k * area * wind, k * moment.cross(wind))
    }

    /// The torque Σ c_i × F_i (N m, body axes) at `t` for attitude `q`.
    #[inline]
    pub fn torque_at(&self, t: f64, q: &[f64]) -> Vector3<f64> {
        let (rho, wind) = self.density_and_wind(t, q);
        self.force_and_torque(rho, &wind).1
    }
}

impl EnvironmentTorque for ShapeAerodynamic {
    fn name(&self) -> &str {
        &self.name
    }
    fn kind(&self) -> &'static str {
        "aerodynamic"
    }
    fn environment_torque(&self, hub: &HubState) -> Vector3<f64> {
        self.torque_at(hub.t, hub.attitude)
    }
    fn telemetry_names(&self) -> Vec<String> {
        names(&TELEMETRY)
    }
    fn telemetry(&self, hub: &HubState, work: f64) -> Vec<f64> {
        let (rho, wind) = self.density_and_wind(hub.t, hub.attitude);
        let tau = self.force_and_torque(rho, &wind).1;
        telemetry_row(&tau, rho, &wind, work)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::orbit::{CentralBody, Elements};
    use nalgebra::UnitQuaternion;

    /// The bands are in increasing order and continuous to within the table's rounding
    /// (Vallado's fit jumps by 0.14% at 25 km and by under 0.01% at the other bases).
    #[test]
    fn the_table_is_ordered_and_nearly_continuous() {
        for w in EXPONENTIAL_ATMOSPHERE.windows(2) {
            let (h0, rho0, scale) = w[0];
            let (h1, rho1, _) = w[1];
            assert!(h1 > h0 && rho1 < rho0 && scale > 0.0);
            let end = rho0 * (-(h1 - h0) / scale).exp();
            assert!(
                (end / rho1 - 1.0).abs() < 0.1,
                "{h0}..{h1}: {end:e} vs {rho1:e}"
            );
        }
    }

    /// The square-root-free rotation against nalgebra's, for a quaternion off unit norm.
    #[test]
    fn the_body_wind_equals_the_rotated_wind() {
        let orbit = Orbit::new(
            CentralBody::EARTH,
            Elements::new(6.778e6, 0.001, 0.9, 0.4, 1.1, 0.2),
            false,
        )
        .unwrap();
        let aero = Aerodynamic {
            name: "a".into(),
            orbit: Arc::new(orbit),
            drag_coefficient: 2.2,
            area: 0.03,
            center_of_pressure: Vector3::new(0.01, 0.0, 0.05),
        };
        let q = UnitQuaternion::from_euler_angles(0.3, -1.2, 2.5);
        let raw = [q.w * 1.001, q.i * 1.001, q.j * 1.001, q.k * 1.001];
        for t in [0.0, 1234.5, 9876.0] {
            let (_, v) = aero.density_and_wind_eci(t);
            let expected = q.inverse_transform_vector(&v);
            let (_, got) = aero.density_and_wind(t, &raw);
            assert!(
                (got - expected).norm() <= 1e-14 * expected.norm(),
                "t = {t}: {got:?} vs {expected:?}"
            );
        }
    }
}
