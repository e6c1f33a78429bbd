//! The Earth's magnetic field as the first-degree IGRF: a tilted dipole at the Earth's
//! centre. See `docs/environment.md`, section "Magnetic field and residual dipole".
//!
//! The IGRF scalar potential (Alken et al. 2021, *Earth Planets Space* 73:49, eq. 1) kept
//! to degree 1, with Schmidt semi-normalised P₁⁰ = cos θ, P₁¹ = sin θ, is
//!
//! ```text
//! V = a (a/r)² [g₁⁰ cos θ + (g₁¹ cos φ + h₁¹ sin φ) sin θ] = a³ (g·r) / r³,
//! g = (g₁¹, h₁¹, g₁⁰)   (ECEF components; x = r sin θ cos φ, y = r sin θ sin φ, z = r cos θ)
//! ```
//!
//! with `a = 6371.2 km` the IGRF reference radius, and `B = −∇V`:
//!
//! ```text
//! B(r) = (a/r)³ [3 (g·r̂) r̂ − g] = (a/r)³ B₀ [3 (m̂·r̂) r̂ − m̂],   B₀ = |g|, m̂ = g/B₀.
//! ```
//!
//! Since g₁⁰ < 0, m̂ points roughly to geographic south and the field at the equator points
//! north (+z, `−g₁⁰ (a/r)³`, about 29.4 µT on the reference sphere).
//!
//! Coefficients: IGRF-14 (IAGA Working Group V-MOD, released November 2024; the
//! coefficient file `igrf14coeffs.txt` distributed by NOAA NCEI): the definitive
//! (DGRF) dipole coefficients every five years from 1965.0 to 2020.0, the IGRF 2025.0
//! values, and the predicted secular variation for 2025.0–2030.0. Between snapshots the
//! coefficients are linear in time, as the IGRF defines them; after 2025.0 they follow the
//! secular variation. Time is the decimal calendar year of UTC.

use super::Orbit;
use super::earth_rotation_angle;
use super::field_table::{FieldTable, igrf_eci};
use nalgebra::Vector3;
use std::sync::Arc;

/// The IGRF reference radius `a` (m): the mean Earth radius of the IGRF potential (not the
/// WGS-84 equatorial radius).
pub const REFERENCE_RADIUS: f64 = 6_371_200.0;

/// First and last years (decimal, UTC) for which [`Dipole::igrf14`] interpolates the
/// tabulated coefficients or their predicted secular variation.
pub const FIRST_YEAR: f64 = 1965.0;
/// See [`FIRST_YEAR`].
pub const LAST_YEAR: f64 = 2030.0;

/// Year of the first snapshot in the tables below; one every five years.
const TABLE_START: f64 = 1965.0;
/// IGRF-14 g₁⁰ (nT) at 1965.0, 1970.0, …, 2025.0 (DGRF to 2020.0, IGRF 2025.0).
const G10: [f64; 13] = [
    -30334.0, -30220.0, -30100.0, -29992.0, -29873.0, -29775.0, -29692.0, -29619.4, -29554.63,
    -29496.57, -29441.46, -29403.41, -29350.0,
];
/// IGRF-14 g₁¹ (nT), same epochs.
const G11: [f64; 13] = [
    -2119.0, -2068.0, -2013.0, -1956.0, -1905.0, -1848.0, -1784.0, -1728.2, -1669.05, -1586.42,
    -1501.77, -1451.37, -1410.3,
];
/// IGRF-14 h₁¹ (nT), same epochs.
const H11: [f64; 13] = [
    5776.0, 5737.0, 5675.0, 5604.0, 5500.0, 5406.0, 5306.0, 5186.1, 5077.99, 4944.26, 4795.99,
    4653.35, 4545.5,
];
/// IGRF-14 predicted secular variation 2025.0–2030.0 of (g₁⁰, g₁¹, h₁¹), nT/yr.
const SV_2025: [f64; 3] = [12.6, 10.0, -21.5];

/// First-degree Gauss coefficients (nT).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dipole {
    /// g₁⁰ (nT).
    pub g10: f64,
    /// g₁¹ (nT).
    pub g11: f64,
    /// h₁¹ (nT).
    pub h11: f64,
}

impl Dipole {
    /// The IGRF-14 dipole at the decimal year `year`: linear between the five-yearly
    /// snapshots, and along the predicted secular variation after 2025.0. Outside
    /// [`FIRST_YEAR`]..=[`LAST_YEAR`] it extrapolates linearly (the first interval's rate
    /// before 1965.0); the scenario refuses epochs there.
    pub fn igrf14(year: f64) -> Dipole {
        let last = G10.len() - 1;
        let x = (year - TABLE_START) / 5.0;
        if x >= last as f64 {
            let dt = year - (TABLE_START + 5.0 * last as f64);
            return Dipole {
                g10: G10[last] + SV_2025[0] * dt,
                g11: G11[last] + SV_2025[1] * dt,
                h11: H11[last] + SV_2025[2] * dt,
            };
        }
        let k = (x.floor().max(0.0) as usize).min(last - 1);
        let f = x - k as f64;
        let lerp = |c: &[f64; 13]| c[k] + f * (c[k + 1] - c[k]);
        Dipole {
            g10: lerp(&G10),
            g11: lerp(&G11),
            h11: lerp(&H11),
        }
    }

    /// The vector `g = (g₁¹, h₁¹, g₁⁰)` in ECEF components (T): `B₀ m̂`.
    pub fn gauss_vector(&self) -> Vector3<f64> {
        1e-9 * Vector3::new(self.g11, self.h11, self.g10)
    }

    /// B₀ = |g| (T): the field strength on the reference sphere at the magnetic equator.
    pub fn strength(&self) -> f64 {
        self.gauss_vector().norm()
    }

    /// The field (T) at `r` (m, ECEF).
    pub fn field_ecef(&self, r: &Vector3<f64>) -> Vector3<f64> {
        let radius = r.norm();
        dipole_field(&self.gauss_vector(), &(r / radius), radius)
    }
}

/// `(a/r)³ [3 (g·r̂) r̂ − g]` (T) for the Gauss vector `g` (T) and the unit position `r_hat`
/// at distance `radius` (m), both in the same frame.
#[inline]
pub fn dipole_field(g: &Vector3<f64>, r_hat: &Vector3<f64>, radius: f64) -> Vector3<f64> {
    let s = REFERENCE_RADIUS / radius;
    s * s * s * (3.0 * g.dot(r_hat) * r_hat - g)
}

/// Days from 1970-01-01 to 1 January of `year` (proleptic Gregorian).
fn days_to_new_year(year: i64) -> i64 {
    let y = year - 1;
    365 * (year - 1970) + (y.div_euclid(4) - y.div_euclid(100) + y.div_euclid(400))
        - (1969 / 4 - 1969 / 100 + 1969 / 400)
}

/// The decimal calendar year of the Unix time `unix_s` (s, UTC): the year plus the elapsed
/// fraction of it (365 or 366 days), as the IGRF's own synthesis programs count time.
pub fn decimal_year(unix_s: f64) -> f64 {
    let days = (unix_s / 86_400.0).floor() as i64;
    let mut year = 1970 + days.div_euclid(366);
    while days_to_new_year(year) > days {
        year -= 1;
    }
    while days_to_new_year(year + 1) <= days {
        year += 1;
    }
    let start = days_to_new_year(year) as f64 * 86_400.0;
    let length = (days_to_new_year(year + 1) - days_to_new_year(year)) as f64 * 86_400.0;
    year as f64 + (unix_s - start) / length
}

/// Which model of the main field a run uses.
#[derive(Debug, Clone)]
pub enum FieldModel {
    /// The first-degree IGRF-14 (a tilted dipole), 1965–2030.
    Dipole,
    /// IGRF-14 to degree 13, 1900–2030: along the run's orbit from `table` where it has one
    /// (tabulated once, [`FieldTable`]), from the harmonics otherwise.
    Igrf {
        /// The field along the run's orbit.
        table: Option<Arc<FieldTable>>,
    },
}

/// The geomagnetic field along a run: IGRF-14 at the scenario epoch plus `t`, rotated from
/// ECEF to ECI by the Earth rotation angle, as a dipole or to degree 13.
#[derive(Debug, Clone)]
pub struct GeomagneticField {
    /// The scenario epoch (Unix ns, UTC) of simulation time 0.
    pub epoch_unix_ns: i64,
    /// The model.
    pub model: FieldModel,
}

impl GeomagneticField {
    /// The dipole field for a run starting at `epoch_unix_ns`.
    pub fn new(epoch_unix_ns: i64) -> GeomagneticField {
        GeomagneticField {
            epoch_unix_ns,
            model: FieldModel::Dipole,
        }
    }

    /// The degree-13 field for a run starting at `epoch_unix_ns`, along the run's orbit from
    /// `table` where given.
    pub fn igrf(epoch_unix_ns: i64, table: Option<Arc<FieldTable>>) -> GeomagneticField {
        GeomagneticField {
            epoch_unix_ns,
            model: FieldModel::Igrf { table },
        }
    }

    /// The decimal year at `t` s after the epoch.
    pub fn year(&self, t: f64) -> f64 {
        decimal_year(self.epoch_unix_ns as f64 * 1e-9 + t)
    }

    /// The first and last years its model covers.
    pub fn years(&self) -> (f64, f64) {
        match self.model {
            FieldModel::Dipole => (FIRST_YEAR, LAST_YEAR),
            FieldModel::Igrf { .. } => (super::igrf::FIRST_YEAR, super::igrf::LAST_YEAR),
        }
    }

    /// The dipole's Gauss vector `g` (T) in ECI components at `t`: `R3(−θ) g_ECEF`, θ the
    /// Earth rotation angle ([`earth_rotation_angle`]).
    pub fn gauss_vector_eci(&self, t: f64) -> Vector3<f64> {
        let g = Dipole::igrf14(self.year(t)).gauss_vector();
        let (s, c) = earth_rotation_angle(self.epoch_unix_ns, t).sin_cos();
        Vector3::new(c * g.x - s * g.y, s * g.x + c * g.y, g.z)
    }

    /// The field (T, ECI) at `t` at the unit position `r_hat` (ECI) and distance `radius` (m),
    /// from the model itself (the harmonics for IGRF; NaN outside its years).
    #[inline]
    pub fn field_eci(&self, t: f64, r_hat: &Vector3<f64>, radius: f64) -> Vector3<f64> {
        match self.model {
            FieldModel::Dipole => dipole_field(&self.gauss_vector_eci(t), r_hat, radius),
            FieldModel::Igrf { .. } => igrf_eci(self.epoch_unix_ns, t, &(radius * r_hat))
                .unwrap_or(Vector3::repeat(f64::NAN)),
        }
    }

    /// The field (T, ECI) at `t` at the position of `orbit` (the run's: the table, where
    /// there is one, was built for it).
    #[inline]
    pub fn field_on_orbit(&self, orbit: &Orbit, t: f64) -> Vector3<f64> {
        if let FieldModel::Igrf { table: Some(table) } = &self.model
            && let Some(b) = table.field_eci(t)
        {
            return b;
        }
        // Kind 2: the dipole, 3: the harmonics, each at this epoch along this orbit.
        let kind = match self.model {
            FieldModel::Dipole => 2,
            FieldModel::Igrf { .. } => 3,
        };
        let key = [kind, orbit.id(), self.epoch_unix_ns as u64, t.to_bits()];
        super::recent::kept(key, || {
            let (r_hat, radius) = orbit.direction(t);
            self.field_eci(t, &r_hat, radius)
        })
    }

    /// The model in words, for summaries and logs.
    pub fn describe(&self) -> String {
        match &self.model {
            FieldModel::Dipole => "IGRF-14 dipole (degree 1)".into(),
            FieldModel::Igrf { table: Some(t) } => format!(
                "IGRF-14 to degree 13, tabulated along the orbit ({} segments, within {:.1e} nT \
                 of the harmonics)",
                t.len(),
                t.max_error() * 1e9
            ),
            FieldModel::Igrf { table: None } => {
                "IGRF-14 to degree 13, from the harmonics at every evaluation".into()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimal_years_follow_the_calendar() {
        // 2020-01-01T00:00Z, 2020-07-02T00:00Z (day 183 of the leap year 2020), 2025-01-01.
        assert_eq!(decimal_year(1_577_836_800.0), 2020.0);
        assert!((decimal_year(1_593_648_000.0) - (2020.0 + 183.0 / 366.0)).abs() < 1e-12);
        assert_eq!(decimal_year(1_735_689_600.0), 2025.0);
        assert_eq!(decimal_year(0.0), 1970.0);
        assert_eq!(decimal_year(-157_766_400.0), 1965.0);
    }

    #[test]
    fn the_coefficients_hit_the_table_and_the_secular_variation() {
        assert_eq!(Dipole::igrf14(2020.0).g10, -29403.41);
        assert_eq!(Dipole::igrf14(1965.0).h11, 5776.0);
        let d = Dipole::igrf14(2027.5);
        assert!((d.g10 - (-29350.0 + 2.5 * 12.6)).abs() < 1e-9);
        assert!((d.h11 - (4545.5 - 2.5 * 21.5)).abs() < 1e-9);
        let mid = Dipole::igrf14(2022.5);
        assert!((mid.g11 - 0.5 * (-1451.37 - 1410.3)).abs() < 1e-9);
    }

    /// The values kept per thread answer each orbit and each model with its own field, bit
    /// for bit: two orbits built from the same elements and a third, the dipole and the
    /// harmonics, asked in turn at the same instants, each asked again after more instants
    /// than are kept; equal orbits built apart are equal, with different identities.
    #[test]
    fn kept_values_answer_each_orbit_and_model_with_its_own_field() {
        use crate::orbit::{CentralBody, Elements};
        let orbit = |anomaly: f64| {
            let elements = Elements::new(6878.137e3, 0.01, 1.7, 0.7, 0.2, anomaly);
            Orbit::new(CentralBody::EARTH, elements, true).unwrap()
        };
        let (a, twin, b) = (orbit(0.3), orbit(0.3), orbit(2.0));
        assert!(a == twin && a.id() != twin.id() && a != b);
        let epoch = 1_803_945_600_000_000_000_i64;
        let fields = [
            GeomagneticField::new(epoch),
            GeomagneticField::igrf(epoch, None),
        ];
        let direct = |field: &GeomagneticField, orbit: &Orbit, t: f64| {
            let (r_hat, radius) = orbit.direction(t);
            field.field_eci(t, &r_hat, radius).map(f64::to_bits)
        };
        for k in 0..3 * crate::orbit::recent::KEPT {
            for t in [
                0.5 + 61.7 * k as f64,
                0.5 + 61.7 * k.saturating_sub(2) as f64,
            ] {
                for field in &fields {
                    for orbit in [&a, &b, &twin, &a] {
                        let value = field.field_on_orbit(orbit, t).map(f64::to_bits);
                        assert_eq!(value, direct(field, orbit, t), "t = {t}");
                    }
                    assert_ne!(direct(field, &a, t), direct(field, &b, t));
                }
                assert_ne!(direct(&fields[0], &a, t), direct(&fields[1], &a, t));
            }
        }
    }
}
