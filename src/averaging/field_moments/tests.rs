use super::*;
use crate::orbit::{CentralBody, Elements};

/// 2020-06-01T00:00Z (Unix ns).
const EPOCH_2020_06: i64 = 1_590_969_600_000_000_000;

fn circular(altitude_km: f64, inclination_deg: f64, j2: bool) -> Arc<Orbit> {
    let earth = CentralBody::by_name("earth").unwrap();
    let a = earth.radius + altitude_km * 1e3;
    let elements = Elements::new(a, 0.0, inclination_deg.to_radians(), 0.7, 0.0, 0.3);
    Arc::new(Orbit::new(earth, elements, j2).unwrap())
}

fn relative(a: &Matrix3<f64>, b: &Matrix3<f64>) -> f64 {
    (a - b).amax() / b.amax()
}

/// The span of the time means (s): 60 days.
const SPAN: f64 = 60.0 * 86_400.0;

/// The mean of B Bᵀ along the orbit itself over [0, span] (s), sampled 40 times an orbit and
/// weighted by sin⁴ (a window whose spectrum falls as f⁻⁵), for the instant span/2.
fn smooth_time_mean(orbit: &Orbit, field: &GeomagneticField, span: f64) -> Matrix3<f64> {
    let samples = (span / (orbit.period() / 40.0)) as usize;
    let mut sum = Matrix3::zeros();
    let mut weights = 0.0;
    for i in 0..=samples {
        let s = i as f64 / samples as f64;
        let w = (std::f64::consts::PI * s).sin().powi(4);
        let b = field.field_on_orbit(orbit, s * span);
        sum += b * b.transpose() * w;
        weights += w;
    }
    sum / weights
}

/// 2n + 3 points per angle give the double mean to rounding: the same as twice as many.
#[test]
fn the_double_mean_is_exact_on_2n_plus_3_points() {
    let orbit = circular(700.0, 71.0, false);
    for field in [
        GeomagneticField::new(EPOCH_2020_06),
        GeomagneticField::igrf(EPOCH_2020_06, None),
    ] {
        let model = EarthFixedField::at_year(&field, 2020.4);
        let n = model.degree();
        let exact = node_axes_mean_with(&orbit, &model, double_mean_points(n));
        let finer = node_axes_mean_with(&orbit, &model, 2 * double_mean_points(n) + 1);
        assert!(
            relative(&exact, &finer) < 1e-13,
            "{n}: {}",
            relative(&exact, &finer)
        );
        // Too few points alias (the count matters, so the check above can fail).
        let fewer = node_axes_mean_with(&orbit, &model, n + 1);
        println!(
            "degree {n}: exact {:.1e}, on n + 1 points {:.1e}",
            relative(&exact, &finer),
            relative(&fewer, &finer)
        );
        assert!(
            relative(&fewer, &finer) > 1e-9,
            "{n}: {}",
            relative(&fewer, &finer)
        );
    }
}

/// Within a calendar year S_Ω is quadratic in time: the interpolant equals the direct mean.
#[test]
fn the_yearly_interpolant_is_exact() {
    let orbit = circular(700.0, 71.0, false);
    let field = GeomagneticField::igrf(EPOCH_2020_06, None);
    let moments = FieldMoments::orbit(orbit.clone(), field.clone());
    for days in [10.0, 123.4, 300.0, 500.0] {
        let t = days * 86_400.0;
        let direct = node_axes_mean(&orbit, &field, field.year(t));
        let turn = Rotation3::from_axis_angle(&Vector3::z_axis(), orbit.raan(t));
        let direct = turn * direct * turn.transpose();
        let s = moments.at(t);
        assert!(
            relative(&s, &direct) < 1e-13,
            "{days} d: {}",
            relative(&s, &direct)
        );
    }
}

/// Against the time mean of B Bᵀ along the orbit itself (the field at the orbit's position,
/// as a run sees it), with a smooth window of 60 days about the instant: the two routes share
/// only the field model.
#[test]
fn the_double_mean_is_the_time_mean_along_the_orbit() {
    // 830 km: 14.1 orbits a sidereal day, away from a repeating ground track of low order.
    let orbit = circular(830.0, 71.0, false);
    for field in [
        GeomagneticField::new(EPOCH_2020_06),
        GeomagneticField::igrf(EPOCH_2020_06, None),
    ] {
        let time_mean = smooth_time_mean(&orbit, &field, SPAN);
        let moments = FieldMoments::orbit(orbit.clone(), field.clone());
        let s = moments.at(0.5 * SPAN);
        let off = relative(&s, &time_mean);
        println!("{}: {off:.2e}", field.describe());
        assert!(off < 1e-8, "{}: {off:.2e}", field.describe());
    }
}

/// An eccentric orbit takes the windows: against the same smooth time mean, to the windows'
/// sideband leak.
#[test]
fn the_windows_follow_the_time_mean_on_an_eccentric_orbit() {
    let earth = CentralBody::by_name("earth").unwrap();
    let a = earth.radius + 1_000e3;
    let elements = Elements::new(a, 0.05, 71f64.to_radians(), 0.7, 0.4, 0.3);
    let orbit = Arc::new(Orbit::new(earth, elements, false).unwrap());
    let field = GeomagneticField::new(EPOCH_2020_06);
    let moments = FieldMoments::orbit(orbit.clone(), field.clone());
    assert!(matches!(moments, FieldMoments::Orbit { .. }));
    let time_mean = smooth_time_mean(&orbit, &field, SPAN);
    let off = relative(&moments.at(0.5 * SPAN), &time_mean);
    println!("eccentric windows: {off:.2e}");
    assert!(off < 1e-3, "{off:.2e}");
}
