//! The Earth's dipole field and the `magnetic_dipole` torque, checked against what polhode
//! did not produce: −∇V by finite differences of the IGRF potential written out here, the
//! pure dipole's pole and equator strengths, the Earth rotation angle evaluated here from
//! its IERS definition, the geometry of m × B, the work–energy balance of a tumbling CubeSat,
//! and the located errors.
mod common;

use common::run;

use nalgebra::{UnitQuaternion, Vector3};
use polhode::effectors::MagneticDipole;
use polhode::orbit::magnetic::{Dipole, REFERENCE_RADIUS};
use polhode::orbit::{CentralBody, Elements, GeomagneticField, Orbit};
use polhode::scenario::{Overrides, Scenario, parse};
use polhode::sim::Status;
use std::path::Path;
use std::sync::Arc;

/// IGRF-14 DGRF 2020.0 first-degree coefficients (nT), typed from the IAGA coefficient file.
const G10: f64 = -29403.41;
const G11: f64 = -1451.37;
const H11: f64 = 4653.35;
/// IGRF reference radius (m).
const A: f64 = 6_371_200.0;

/// The degree-1 IGRF potential (T m) at the ECEF point `p` (m), from the spherical form
/// V = a (a/r)² [g₁⁰ P₁⁰(cos θ) + (g₁¹ cos φ + h₁¹ sin φ) P₁¹(cos θ)], P₁⁰ = cos θ,
/// P₁¹ = sin θ (Schmidt semi-normalised).
fn potential(p: &Vector3<f64>) -> f64 {
    let r = p.norm();
    let theta = (p.x.hypot(p.y)).atan2(p.z);
    let phi = p.y.atan2(p.x);
    1e-9 * A
        * (A / r).powi(2)
        * (G10 * theta.cos() + (G11 * phi.cos() + H11 * phi.sin()) * theta.sin())
}

/// −∇V by fourth-order central differences with a 1 km step.
fn minus_gradient(p: &Vector3<f64>) -> Vector3<f64> {
    let h = 1000.0;
    let mut b = Vector3::zeros();
    for k in 0..3 {
        let e = Vector3::ith(k, h);
        let d = -potential(&(p + 2.0 * e)) + 8.0 * potential(&(p + e)) - 8.0 * potential(&(p - e))
            + potential(&(p - 2.0 * e));
        b[k] = -d / (12.0 * h);
    }
    b
}

#[test]
fn the_field_is_minus_the_gradient_of_the_igrf_potential() {
    let dipole = Dipole::igrf14(2020.0);
    assert_eq!((dipole.g10, dipole.g11, dipole.h11), (G10, G11, H11));
    assert_eq!(REFERENCE_RADIUS, A);
    // The equator at Greenwich, on the reference sphere, then other points and heights.
    let greenwich = Vector3::new(A, 0.0, 0.0);
    let b = dipole.field_ecef(&greenwich);
    let expected = minus_gradient(&greenwich);
    assert!(
        (b - expected).norm() <= 1e-9 * expected.norm(),
        "{b:?} vs {expected:?}"
    );
    // The field there points north (+z ECEF), −g₁⁰ = 29.4 µT.
    assert!((b.z - 29_403.41e-9).abs() < 1e-15, "{b:?}");
    assert!(b.z > 0.0 && b.z.abs() > 5.0 * b.x.abs().max(b.y.abs()));
    for (lat, lon, height) in [
        (0.7f64, -1.3f64, 0.0),
        (-0.4, 2.9, 500e3),
        (1.2, 0.3, 2000e3),
        (-1.4, -2.2, 35786e3),
    ] {
        let r =
            (A + height) * Vector3::new(lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin());
        let b = dipole.field_ecef(&r);
        let expected = minus_gradient(&r);
        assert!(
            (b - expected).norm() <= 1e-9 * expected.norm(),
            "{lat} {lon} {height}: {b:?} vs {expected:?}"
        );
    }
}

#[test]
fn the_dipole_is_twice_as_strong_at_its_poles_as_on_its_equator() {
    let dipole = Dipole::igrf14(2020.0);
    let b0 = (G10 * G10 + G11 * G11 + H11 * H11).sqrt() * 1e-9;
    assert!((dipole.strength() - b0).abs() < 1e-15 * b0 * 1e3);
    let m_hat = Vector3::new(G11, H11, G10).normalize();
    for pole in [m_hat, -m_hat] {
        let b = dipole.field_ecef(&(A * pole)).norm();
        assert!((b - 2.0 * b0).abs() <= 1e-12 * b0, "{b} vs {}", 2.0 * b0);
    }
    // Points on the magnetic equator: perpendicular to m̂.
    let u = m_hat.cross(&Vector3::z()).normalize();
    let v = m_hat.cross(&u);
    for angle in [0.0f64, 1.0, 2.5, 4.0] {
        let r = A * (angle.cos() * u + angle.sin() * v);
        let b = dipole.field_ecef(&r).norm();
        assert!((b - b0).abs() <= 1e-12 * b0, "{b} vs {b0}");
        // Twice as far out, an eighth of it.
        let b2 = dipole.field_ecef(&(2.0 * r)).norm();
        assert!((b2 - b0 / 8.0).abs() <= 1e-12 * b0);
    }
}

/// The ECI field is the ECEF field turned by the Earth rotation angle θ, evaluated here from
/// its definition θ = 2π (0.7790572732640 + 1.00273781191135448 D_U) (IERS Conventions
/// 2010, eq. 5.15): at 2020-01-01T00:00Z, D_U = 7304.5 d.
#[test]
fn the_inertial_field_turns_with_the_earth() {
    let epoch_ns = 1_577_836_800_000_000_000i64;
    let field = GeomagneticField::new(epoch_ns);
    let dipole = Dipole::igrf14(2020.0);
    for t in [0.0f64, 3600.0] {
        let d_u = 7304.5 + t / 86_400.0;
        let theta =
            std::f64::consts::TAU * (0.779_057_273_264_0 + 1.002_737_811_911_354_6 * d_u).fract();
        let rz = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), theta);
        for r_ecef in [Vector3::new(7.0e6, 0.0, 0.0), Vector3::new(1e6, -5e6, 4e6)] {
            let r_eci = rz * r_ecef;
            let got = field.field_eci(t, &r_eci.normalize(), r_eci.norm());
            // The coefficients drift by < 0.01 nT in an hour: compare at the model's own
            // coefficients for the instant, turned here.
            let at_t = Dipole::igrf14(field.year(t));
            let expected = rz * at_t.field_ecef(&r_ecef);
            assert!(
                (got - expected).norm() <= 1e-9 * expected.norm(),
                "t = {t}: {got:?} vs {expected:?}"
            );
            assert!((at_t.g10 - dipole.g10).abs() < 0.01);
        }
    }
}

#[test]
fn the_torque_is_perpendicular_to_the_moment_and_the_field() {
    let orbit = Orbit::new(
        CentralBody::EARTH,
        Elements::new(6_878_137.0, 0.0, 51.6f64.to_radians(), 0.3, 0.0, 0.0),
        false,
    )
    .unwrap();
    let md = MagneticDipole {
        name: "m".into(),
        orbit: Arc::new(orbit),
        field: GeomagneticField::new(1_748_736_000_000_000_000),
        moment: Vector3::new(0.03, -0.01, 0.04),
    };
    let q = UnitQuaternion::from_euler_angles(0.7, 0.2, -1.9);
    let raw = [q.w, q.i, q.j, q.k];
    for t in [0.0, 900.0, 2500.0, 5000.0] {
        let b = md.field_body(t, &raw);
        let tau = md.torque_at(t, &raw);
        // LEO: 20–60 µT.
        assert!(b.norm() > 15e-6 && b.norm() < 65e-6, "{b:?}");
        assert!(tau.dot(&md.moment).abs() <= 1e-14 * tau.norm() * md.moment.norm());
        assert!(tau.dot(&b).abs() <= 1e-14 * tau.norm() * b.norm());
        let sin = md.moment.cross(&b).norm() / (md.moment.norm() * b.norm());
        assert!((tau.norm() - md.moment.norm() * b.norm() * sin).abs() <= 1e-14 * tau.norm());
    }
}

fn load(yaml: &str) -> Scenario {
    parse(
        Path::new("mag.yaml"),
        yaml.to_string(),
        &Overrides::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"))
}

/// A 3U CubeSat tumbling at 500 km, 51.6°, with a 0.05 A m² residual dipole, for two
/// orbits: T − W stays put to 1e-9 of T while T itself changes.
#[test]
fn the_energy_balance_holds_while_the_torque_works() {
    let yaml = "name: mag
epoch: 2025-06-01T00:00:00Z
body: {principal: [0.035, 0.035, 0.008]}
orbit: {semi_major_axis_km: 6878.137, inclination_deg: 51.6, raan_deg: 40.0}
initial: {omega: [0.02, -0.01, 0.03]}
duration: 11340
integrator: {method: dop853, rtol: 1.0e-13, atol: 1.0e-16}
output: {rate: 0.05}
effectors:
  - magnetic_dipole: {moment: [0.03, 0.0, 0.04]}
";
    let s = load(yaml);
    let (out, rec) = run(&s);
    assert_eq!(out.status, Status::Complete);
    let (worst, spread) = common::balance_drift_and_spread(&rec.samples);
    eprintln!("T - W drift {worst:e} of T0, T spread {:e} of T0", spread);
    assert!(worst < 1e-9, "energy balance drift {worst:e} (relative)");
    assert!(spread > 1e-3, "T spread {:e}", spread);
}

#[test]
fn bad_magnetic_input_is_refused_with_located_errors() {
    let base =
        "name: x\nbody: {principal: [1, 2, 3]}\ninitial: {omega: [0, 0, 0.1]}\nduration: 1\n";
    let orbit = "orbit: {semi_major_axis_km: 7000}\n";
    let cases = [
        (
            format!("{base}effectors:\n  - magnetic_dipole: {{moment: [0.1, 0, 0]}}\n"),
            "mag.yaml:6:5: field `effectors[0].magnetic_dipole`: an environmental torque needs the spacecraft's orbit",
        ),
        (
            format!("{base}{orbit}effectors:\n  - magnetic_dipole: {{moment: [.nan, 0, 0]}}\n"),
            "mag.yaml:7:31: field `effectors[0].magnetic_dipole.moment`: expected three finite numbers",
        ),
        (
            format!(
                "{base}{orbit}effectors:\n  - magnetic_dipole: {{moment: [1.0e4, 1.0e3, 0]}}\n"
            ),
            "field `effectors[0].magnetic_dipole.moment`: expected three finite numbers with magnitude at most 1e4",
        ),
        (
            format!("{base}{orbit}effectors:\n  - magnetic_dipole: {{}}\n"),
            "missing field `moment`",
        ),
        (
            format!(
                "epoch: 1950-01-01T00:00:00Z\n{base}orbit: {{semi_major_axis_km: 7000, magnetic_field: dipole}}\neffectors:\n  - magnetic_dipole: {{moment: [0.1, 0, 0]}}\n"
            ),
            "mag.yaml:1:8: field `epoch`: the magnetic field model, IGRF-14 dipole (`magnetic_field: dipole`), covers 1965 to 2030, and the run spans 1950.00 to 1950.00: choose an epoch and duration in that range, or `magnetic_field: igrf` (1900 to 2030)",
        ),
        (
            format!(
                "epoch: 1899-06-01T00:00:00Z\n{base}{orbit}effectors:\n  - magnetic_dipole: {{moment: [0.1, 0, 0]}}\n"
            ),
            "mag.yaml:1:8: field `epoch`: `1899-06-01T00:00:00Z` is before 1900-01-01",
        ),
        (
            format!(
                "epoch: 2031-01-01T00:00:00Z\n{base}{orbit}effectors:\n  - magnetic_dipole: {{moment: [0.1, 0, 0]}}\n"
            ),
            "field `epoch`: the magnetic field model, IGRF-14 (`magnetic_field: igrf`, the default), covers 1900 to 2030, and the run spans 2031.00 to 2031.00",
        ),
        (
            format!(
                "{base}orbit: {{semi_major_axis_km: 7000, magnetic_field: wmm}}\neffectors:\n  - magnetic_dipole: {{moment: [0.1, 0, 0]}}\n"
            ),
            "field `orbit.magnetic_field`: expected `igrf` (IGRF-14 to degree 13, 1900 to 2030) or `dipole` (its first degree, 1965 to 2030), got `wmm`",
        ),
    ];
    for (yaml, expect) in cases {
        let e = parse(Path::new("mag.yaml"), yaml.clone(), &Overrides::default())
            .expect_err(&yaml)
            .to_string();
        assert!(e.contains(expect), "expected {expect:?} in {e}\n{yaml}");
    }
    // The default epoch (J2000) is inside the model's span.
    load(&format!(
        "{base}{orbit}effectors:\n  - magnetic_dipole: {{moment: [0.1, 0, 0]}}\n"
    ));
}
