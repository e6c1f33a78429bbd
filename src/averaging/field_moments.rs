//! The orbit-averaged second moment of the geomagnetic field, S = ⟨B Bᵀ⟩ (docs/averaging.md,
//! "Eddy currents"): what the averaged method needs of the field for torques quadratic in B.
//!
//! **Circular orbits: the exact double mean.** With the Earth rotation angle θ(t) and the
//! node Ω(t), the field in inertial axes along the orbit is
//! B_N = R₃(Ω) R₃(−λ) B_E(R₃(λ) r_Ω(u)), where λ = Ω − θ is the node's Earth-fixed longitude,
//! u the argument of latitude and r_Ω(u) = a (cos u, cos i sin u, sin i sin u) the position in
//! the node's axes. Both u and λ advance uniformly, at incommensurate rates away from a
//! resonance (a repeating ground track), so the time mean of B Bᵀ is the mean over the torus
//! (u, λ) of the node-axis field's second moment, S_Ω, turned by the node: S = R₃(Ω) S_Ω R₃(Ω)ᵀ.
//! The field to degree n has Cartesian components that are exterior solid harmonics of degree
//! n + 1, so along a great circle they are trigonometric polynomials of degree n + 1 in u and
//! of degree n in λ; their products have degree 2n + 2 and 2n, and the trapezoid rule on
//! 2n + 3 equally spaced points in each angle integrates them exactly. The Gauss coefficients
//! are linear in the decimal year within each calendar year (IGRF-14 is linear between its
//! five-yearly models and along its predicted secular variation), so S_Ω is quadratic in time
//! there and is interpolated exactly from the year's start, middle and end.
//!
//! **Eccentric orbits: windows.** The radius changes along the orbit and the perigee turns
//! (J2), so S is the mean of B Bᵀ along the orbit itself, weighted by a box of one orbit
//! period convolved with a box of one sidereal day, computed at windows two days apart and
//! interpolated.

use crate::model::Forcing;
use crate::orbit::igrf::Coefficients;
use crate::orbit::magnetic::{Dipole, FieldModel};
use crate::orbit::{GeomagneticField, Orbit};
use nalgebra::{Matrix3, Rotation3, Vector3};
use std::collections::HashMap;
use std::f64::consts::TAU;
use std::sync::{Arc, Mutex};

/// The sidereal day (s): the period of the Earth's rotation against the stars.
pub const SIDEREAL_DAY: f64 = 86_164.090_5;

/// Spacing of the windows at which S is computed on an eccentric orbit (s): two days.
pub const WINDOW_SPACING: f64 = 2.0 * 86_400.0;

/// Field samples per orbit in a window's quadrature (eccentric orbits).
pub const SAMPLES_PER_ORBIT: usize = 16;

/// The orbit-averaged second moment S(t) = ⟨B Bᵀ⟩ (T², inertial axes) of the field the body
/// turns in.
#[derive(Debug)]
pub enum FieldMoments {
    /// A field constant in inertial axes: S = B Bᵀ.
    Uniform(Matrix3<f64>),
    /// The geomagnetic field along a circular orbit: the exact mean over the argument of
    /// latitude and the node's Earth-fixed longitude, turned by the node.
    CircularOrbit {
        /// The orbit.
        orbit: Arc<Orbit>,
        /// The field model.
        field: GeomagneticField,
        /// S_Ω (T², node axes) at the start, middle and end of each calendar year computed so
        /// far, by year.
        cache: Mutex<HashMap<i64, [Matrix3<f64>; 3]>>,
    },
    /// The geomagnetic field along an eccentric orbit, windowed and interpolated.
    Orbit {
        /// The orbit.
        orbit: Arc<Orbit>,
        /// The field model.
        field: GeomagneticField,
        /// Windows computed so far, by index (window k is centred at k·[`WINDOW_SPACING`]).
        cache: Mutex<HashMap<i64, Matrix3<f64>>>,
        /// The first and last window inside the field model's years: beyond them S is held
        /// (a slow stepper's trial stage may look past the end of the run).
        windows: (i64, i64),
    },
}

impl FieldMoments {
    /// The geomagnetic field along `orbit`: the exact double mean for a circular orbit,
    /// windows for an eccentric one.
    pub fn orbit(orbit: Arc<Orbit>, field: GeomagneticField) -> FieldMoments {
        if orbit.elements().eccentricity == 0.0 {
            return FieldMoments::CircularOrbit {
                orbit,
                field,
                cache: Mutex::new(HashMap::new()),
            };
        }
        let (first, last) = field.years();
        let year = 365.25 * 86_400.0;
        let half = 0.5 * (SIDEREAL_DAY + orbit.period()) + WINDOW_SPACING;
        let lo = (first - field.year(0.0)) * year + half;
        let hi = (last - field.year(0.0)) * year - half;
        let windows = (
            (lo / WINDOW_SPACING).ceil() as i64,
            (hi / WINDOW_SPACING).floor() as i64,
        );
        FieldMoments::Orbit {
            orbit,
            field,
            cache: Mutex::new(HashMap::new()),
            windows,
        }
    }

    /// The forcing periods, for a field that depends on the orbit.
    pub fn forcing(&self) -> Option<Forcing> {
        match self {
            FieldMoments::Uniform(_) => None,
            FieldMoments::CircularOrbit { orbit, .. } | FieldMoments::Orbit { orbit, .. } => {
                Some(Forcing {
                    period: orbit.period(),
                    window: SIDEREAL_DAY + orbit.period(),
                })
            }
        }
    }

    /// S at `t` (s).
    pub fn at(&self, t: f64) -> Matrix3<f64> {
        match self {
            FieldMoments::Uniform(s) => *s,
            FieldMoments::CircularOrbit {
                orbit,
                field,
                cache,
            } => {
                let (first, last) = field.years();
                let year = field.year(t).clamp(first, last);
                let whole = (year.floor() as i64).min(last as i64 - 1);
                let f = year - whole as f64;
                let mut cache = cache.lock().unwrap_or_else(|e| e.into_inner());
                let [s0, s1, s2] = *cache.entry(whole).or_insert_with(|| {
                    [0.0, 0.5, 1.0].map(|x| node_axes_mean(orbit, field, whole as f64 + x))
                });
                // Lagrange through f = 0, 1/2, 1: exact for S_Ω quadratic in the year.
                let s_node = s0 * (2.0 * (f - 0.5) * (f - 1.0)) - s1 * (4.0 * f * (f - 1.0))
                    + s2 * (2.0 * f * (f - 0.5));
                let turn = Rotation3::from_axis_angle(&Vector3::z_axis(), orbit.raan(t));
                turn * s_node * turn.transpose()
            }
            FieldMoments::Orbit {
                orbit,
                field,
                cache,
                windows,
            } => {
                let x = t / WINDOW_SPACING;
                let k = x.floor();
                let u = x - k;
                let k = k as i64;
                let mut cache = cache.lock().unwrap_or_else(|e| e.into_inner());
                let mut get = |j: i64| {
                    let j = j.clamp(windows.0, windows.1.max(windows.0));
                    *cache
                        .entry(j)
                        .or_insert_with(|| window_mean(orbit, field, j as f64 * WINDOW_SPACING))
                };
                let (p0, p1, p2, p3) = (get(k - 1), get(k), get(k + 1), get(k + 2));
                let (u2, u3) = (u * u, u * u * u);
                (p1 * 2.0
                    + (p2 - p0) * u
                    + (p0 * 2.0 - p1 * 5.0 + p2 * 4.0 - p3) * u2
                    + (p1 * 3.0 - p0 - p2 * 3.0 + p3) * u3)
                    * 0.5
            }
        }
    }
}

/// The main field's model at one decimal year, in Earth-fixed axes.
enum EarthFixedField {
    Dipole(Dipole),
    Harmonics(Box<Coefficients>),
}

impl EarthFixedField {
    /// `field`'s model at `year` (held at the ends of its years).
    fn at_year(field: &GeomagneticField, year: f64) -> EarthFixedField {
        let (first, last) = field.years();
        let year = year.clamp(first, last);
        match field.model {
            FieldModel::Dipole => EarthFixedField::Dipole(Dipole::igrf14(year)),
            FieldModel::Igrf { .. } => match Coefficients::igrf14(year) {
                Ok(c) => EarthFixedField::Harmonics(Box::new(c)),
                // Unreachable with the year clamped into the model's years; the dipole of
                // that year keeps S finite if it ever were.
                Err(_) => EarthFixedField::Dipole(Dipole::igrf14(year)),
            },
        }
    }

    /// Highest degree of the harmonics.
    fn degree(&self) -> usize {
        match self {
            EarthFixedField::Dipole(_) => 1,
            EarthFixedField::Harmonics(c) => c.degree(),
        }
    }

    /// The field (T, ECEF) at `r` (m, ECEF).
    fn at(&self, r: &Vector3<f64>) -> Vector3<f64> {
        match self {
            EarthFixedField::Dipole(d) => d.field_ecef(r),
            EarthFixedField::Harmonics(c) => c.field_ecef(r),
        }
    }
}

/// Points in each angle of the exact double mean of a field to degree `degree`: 2n + 3.
pub fn double_mean_points(degree: usize) -> usize {
    2 * degree + 3
}

/// S_Ω (T², node axes: x toward the ascending node, z along the Earth's axis) at the decimal
/// `year` for the circular `orbit`: the mean of B Bᵀ over the argument of latitude and the
/// node's Earth-fixed longitude, exact for the model's degree.
pub fn node_axes_mean(orbit: &Orbit, field: &GeomagneticField, year: f64) -> Matrix3<f64> {
    let model = EarthFixedField::at_year(field, year);
    node_axes_mean_with(orbit, &model, double_mean_points(model.degree()))
}

/// S_Ω by the trapezoid rule on `points` × `points` angles.
fn node_axes_mean_with(orbit: &Orbit, model: &EarthFixedField, points: usize) -> Matrix3<f64> {
    let elements = orbit.elements();
    let a = elements.semi_major_axis;
    let (sin_i, cos_i) = elements.inclination.sin_cos();
    let mut sum = Matrix3::zeros();
    for j in 0..points {
        let (sin_u, cos_u) = (TAU * j as f64 / points as f64).sin_cos();
        let r_node = Vector3::new(a * cos_u, a * cos_i * sin_u, a * sin_i * sin_u);
        for k in 0..points {
            let (sin_l, cos_l) = (TAU * k as f64 / points as f64).sin_cos();
            // R₃(λ) r_Ω in Earth-fixed axes, and the field turned back by R₃(−λ).
            let r_earth = Vector3::new(
                cos_l * r_node.x - sin_l * r_node.y,
                sin_l * r_node.x + cos_l * r_node.y,
                r_node.z,
            );
            let b_earth = model.at(&r_earth);
            let b = Vector3::new(
                cos_l * b_earth.x + sin_l * b_earth.y,
                -sin_l * b_earth.x + cos_l * b_earth.y,
                b_earth.z,
            );
            sum += b * b.transpose();
        }
    }
    sum / (points * points) as f64
}

/// The mean of B Bᵀ (T², inertial axes) about `centre` (s), weighted by a box of one orbit
/// period P convolved with a box of one sidereal day D (a trapezoid of base P + D): it removes
/// the harmonics of the orbit (to first order in the Earth's rotation over one orbit) and of
/// the day. Both boxes are rounded to whole samples, P/[`SAMPLES_PER_ORBIT`] apart, so the
/// weight's corners fall on samples and the composite trapezoid rule is exact for it.
pub fn window_mean(orbit: &Orbit, field: &GeomagneticField, centre: f64) -> Matrix3<f64> {
    let p = orbit.period();
    let step = p / SAMPLES_PER_ORBIT as f64;
    let np = SAMPLES_PER_ORBIT as i64;
    let nd = (SIDEREAL_DAY / step).round() as i64;
    let half = (np + nd) / 2;
    let mut sum = Matrix3::zeros();
    let mut weights = 0.0;
    for i in -half..=half {
        // The trapezoid: 1 on the plateau, falling linearly to 0 at ±(P + D)/2.
        let w = ((half - i.abs()) as f64 / np as f64).clamp(0.0, 1.0);
        if w == 0.0 {
            continue;
        }
        let b = field.field_on_orbit(orbit, centre + i as f64 * step);
        sum += b * b.transpose() * w;
        weights += w;
    }
    sum / weights
}

#[cfg(test)]
mod tests;
