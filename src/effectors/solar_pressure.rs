//! `solar_pressure`: the torque of solar radiation pressure on one flat plate of the hub.
//!
//! The Sun's direction and distance come from the low-precision solar coordinates of the
//! *Astronomical Almanac* as given by Vallado, *Fundamentals of Astrodynamics and
//! Applications* (4th ed., 2013), Algorithm 29 (about 0.01°, 1950–2050), at the scenario
//! epoch plus `t`. With n̂ the plate's unit normal (body axes), ŝ the unit vector to the Sun
//! (body axes) and cos α = n̂·ŝ, the force on a sunlit plate of area A (Wertz (ed.),
//! *Spacecraft Attitude Determination and Control*, 1978, §17.2; Vallado §8.6.4) is
//!
//! ```text
//! F = −P A cos α [(1 − ρs) ŝ + 2 (ρs cos α + ρd/3) n̂]    (cos α > 0, not in shadow)
//! P = (S / c) (1 AU / d)²,   S = 1361 W/m² (Kopp & Lean 2011)
//! ```
//!
//! and zero otherwise (a one-sided plate; the cylindrical Earth shadow, no penumbra). The
//! torque about the hub's centre of mass is τ = r_cp × F. The torque is external, so the
//! effector carries one bookkeeping state, the work done on the body W = ∫ τ·ω dt (J).

use super::environment::{EnvironmentTorque, names, to_body};
use crate::model::HubState;
use crate::orbit::Orbit;
use nalgebra::Vector3;
use std::sync::Arc;

/// The total solar irradiance at 1 AU (W/m²): Kopp & Lean 2011, *Geophys. Res. Lett.* 38,
/// L01706 (1360.8 ± 0.5 W/m² at solar minimum), rounded as by the IAU 2015 Resolution B3
/// nominal value.
pub const SOLAR_IRRADIANCE: f64 = 1361.0;
/// The speed of light (m/s, exact).
pub const SPEED_OF_LIGHT: f64 = 299_792_458.0;
/// The radiation pressure of the Sun on a perfect absorber at 1 AU (N/m²): S/c = 4.54e-6.
pub const SOLAR_PRESSURE_1AU: f64 = SOLAR_IRRADIANCE / SPEED_OF_LIGHT;
/// The astronomical unit (m, IAU 2012 Resolution B2, exact).
pub const ASTRONOMICAL_UNIT: f64 = 149_597_870_700.0;
/// Unix time (s) of 2000-01-01T12:00:00 UTC, the J2000 origin of the Julian centuries
/// (JD 2451545.0, taken in UT1 ≈ UTC).
pub const J2000_UNIX_S: f64 = 946_728_000.0;
/// TT − UTC (s): 32.184 s + ΔAT, with ΔAT = 37 s (the value since 2017-01-01); earlier epochs
/// had ΔAT = 10 to 36 s, an error of under 27 s (0.0003° of the Sun's longitude).
pub const TT_MINUS_UTC: f64 = 69.184;

/// The Sun's geocentric position by the low-precision formulas (Vallado Algorithm 29):
/// the unit vector from the Earth's centre to the Sun in the mean equator and equinox of
/// date (taken as the ECI axes; precession since J2000 is 0.014° per year), and the
/// distance in AU, at `unix_s` seconds (UTC) since 1970.
pub fn sun_direction(unix_s: f64) -> (Vector3<f64>, f64) {
    let (lambda, eps, d) = sun_ecliptic(unix_s);
    let (sl, cl) = lambda.sin_cos();
    let (se, ce) = eps.sin_cos();
    (Vector3::new(cl, ce * sl, se * sl), d)
}

/// The Sun's ecliptic longitude λ (rad), the obliquity of the ecliptic ε (rad) and the
/// Earth–Sun distance (AU) at `unix_s` seconds (UTC) since 1970 (Vallado Algorithm 29; the
/// Astronomical Almanac's low-precision solar coordinates).
pub fn sun_ecliptic(unix_s: f64) -> (f64, f64, f64) {
    // Julian centuries from J2000 of UT1 (≈ UTC) and of TDB (≈ TT).
    let t_ut1 = (unix_s - J2000_UNIX_S) / (86_400.0 * 36_525.0);
    let t_tdb = (unix_s + TT_MINUS_UTC - J2000_UNIX_S) / (86_400.0 * 36_525.0);
    let mean_longitude = (280.460 + 36_000.771 * t_ut1).rem_euclid(360.0);
    let mean_anomaly = (357.529_109_2 + 35_999.050_34 * t_tdb)
        .rem_euclid(360.0)
        .to_radians();
    let lambda = (mean_longitude
        + 1.914_666_471 * mean_anomaly.sin()
        + 0.019_994_643 * (2.0 * mean_anomaly).sin())
    .to_radians();
    let distance = 1.000_140_612
        - 0.016_708_617 * mean_anomaly.cos()
        - 0.000_139_589 * (2.0 * mean_anomaly).cos();
    let obliquity = (23.439_291 - 0.013_004_2 * t_tdb).to_radians();
    (lambda, obliquity, distance)
}

/// One flat plate in the Sun's radiation.
#[derive(Debug, Clone)]
pub struct SolarPressure {
    /// Name (telemetry topic).
    pub name: String,
    /// The orbit of the spacecraft's centre of mass (for the shadow).
    pub orbit: Arc<Orbit>,
    /// The scenario epoch (Unix ns, UTC) of simulation time 0.
    pub epoch_unix_ns: i64,
    /// Plate area A (m²).
    pub area: f64,
    /// Unit normal n̂ of the plate's sunlit face (body axes).
    pub normal: Vector3<f64>,
    /// Centre of pressure r_cp relative to the hub's centre of mass (m, body axes).
    pub center_of_pressure: Vector3<f64>,
    /// Specular reflectivity ρs.
    pub specular: f64,
    /// Diffuse reflectivity ρd.
    pub diffuse: f64,
}

/// What the plate sees at one instant.
#[derive(Debug, Clone, Copy)]
pub struct SolarState {
    /// Unit vector to the Sun in body axes.
    pub sun_body: Vector3<f64>,
    /// False in the Earth's shadow.
    pub illuminated: bool,
    /// Force on the plate (N, body axes).
    pub force: Vector3<f64>,
    /// Torque about the hub's centre of mass (N m, body axes).
    pub torque: Vector3<f64>,
}

impl SolarPressure {
    /// The Sun's unit vector (ECI) and distance (AU) at `t` s after the epoch.
    #[inline]
    pub fn sun_eci(&self, t: f64) -> (Vector3<f64>, f64) {
        sun_direction(self.epoch_unix_ns as f64 * 1e-9 + t)
    }

    /// True when the spacecraft is outside the Earth's cylindrical shadow at `t`: in shadow
    /// when r·ŝ < 0 and |r − (r·ŝ)ŝ| < R.
    #[inline]
    pub fn illuminated(&self, t: f64, s_eci: &Vector3<f64>) -> bool {
        let (r_hat, radius) = self.orbit.direction(t);
        let along = r_hat.dot(s_eci);
        if along >= 0.0 {
            return true;
        }
        (r_hat - along * s_eci).norm() * radius >= self.orbit.body().radius
    }

    /// The force of the radiation (N, body axes) for the unit Sun vector `s` (body axes) at
    /// the pressure `p` (N/m²), zero when the back of the plate faces the Sun.
    #[inline]
    pub fn plate_force(&self, s: &Vector3<f64>, p: f64) -> Vector3<f64> {
        let cos_a = self.normal.dot(s);
        if cos_a <= 0.0 {
            return Vector3::zeros();
        }
        -p * self.area
            * cos_a
            * ((1.0 - self.specular) * s
                + 2.0 * (self.specular * cos_a + self.diffuse / 3.0) * self.normal)
    }

    /// The Sun vector, shadow, force and torque at `t` for attitude `q` (w, x, y, z; body →
    /// inertial; normalised here).
    pub fn state_at(&self, t: f64, q: &[f64]) -> SolarState {
        let (s_n, d_au) = self.sun_eci(t);
        let s = to_body(q, &s_n);
        let illuminated = self.illuminated(t, &s_n);
        let force = if illuminated {
            self.plate_force(&s, SOLAR_PRESSURE_1AU / (d_au * d_au))
        } else {
            Vector3::zeros()
        };
        SolarState {
            sun_body: s,
            illuminated,
            force,
            torque: self.center_of_pressure.cross(&force),
        }
    }
}

impl EnvironmentTorque for SolarPressure {
    fn name(&self) -> &str {
        &self.name
    }
    fn kind(&self) -> &'static str {
        "solar_pressure"
    }
    fn environment_torque(&self, hub: &HubState) -> Vector3<f64> {
        self.state_at(hub.t, hub.attitude).torque
    }
    fn telemetry_names(&self) -> Vec<String> {
        names(&[
            "torque_x",
            "torque_y",
            "torque_z",
            "sun_x",
            "sun_y",
            "sun_z",
            "illuminated",
            "work",
        ])
    }
    fn telemetry(&self, hub: &HubState, work: f64) -> Vec<f64> {
        let st = self.state_at(hub.t, hub.attitude);
        vec![
            st.torque[0],
            st.torque[1],
            st.torque[2],
            st.sun_body[0],
            st.sun_body[1],
            st.sun_body[2],
            if st.illuminated { 1.0 } else { 0.0 },
            work,
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::orbit::{CentralBody, Elements};
    use nalgebra::UnitQuaternion;

    /// The square-root-free rotation of the Sun vector against nalgebra's, for a quaternion
    /// off unit norm by 1e-3.
    #[test]
    fn the_body_sun_vector_equals_the_rotated_one() {
        let orbit = Orbit::new(
            CentralBody::EARTH,
            Elements::new(6.9e6, 0.01, 0.9, 0.4, 1.1, 0.2),
            false,
        )
        .unwrap();
        let sp = SolarPressure {
            name: "s".into(),
            orbit: Arc::new(orbit),
            epoch_unix_ns: 1_700_000_000_000_000_000,
            area: 1.0,
            normal: Vector3::new(0.6, 0.0, 0.8),
            center_of_pressure: Vector3::new(0.1, 0.2, -0.3),
            specular: 0.3,
            diffuse: 0.2,
        };
        let q = UnitQuaternion::from_euler_angles(0.3, -1.2, 2.5);
        let raw = [q.w * 1.001, q.i * 1.001, q.j * 1.001, q.k * 1.001];
        for t in [0.0, 1234.5, 9876.0] {
            let expected = q.inverse_transform_vector(&sp.sun_eci(t).0);
            let got = sp.state_at(t, &raw).sun_body;
            assert!(
                (got - expected).norm() <= 1e-14,
                "t = {t}: {got:?} vs {expected:?}"
            );
        }
    }

    /// 1361 W/m² over c is 4.54e-6 N/m² (4.56e-6 would be the older 1367 W/m²).
    #[test]
    fn the_pressure_at_one_au() {
        assert!((SOLAR_PRESSURE_1AU - 4.5398e-6).abs() < 1e-10);
    }
}
