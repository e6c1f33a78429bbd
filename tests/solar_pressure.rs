//! Solar radiation pressure on a flat plate, checked against what polhode did not produce:
//! the Sun's declination, right ascension and distance at the 2024 equinoxes, solstices,
//! perihelion and aphelion published by the U.S. Naval Observatory; the Earth's cylindrical
//! shadow on the anti-Sun and Sun sides of an orbit written out here; the plate force
//! derived by hand for a plate facing the Sun and tilted 60° from it; zero torque with the
//! centre of pressure at the centre of mass; the work–energy balance of a tumbling
//! spacecraft through eclipses; and the located errors.
mod common;

use common::run;

use nalgebra::{UnitQuaternion, Vector3};
use polhode::effectors::SolarPressure;
use polhode::effectors::solar_pressure::sun_direction;
use polhode::orbit::{CentralBody, Elements, Orbit};
use polhode::scenario::{Overrides, Scenario, parse};
use polhode::sim::Status;
use std::path::Path;
use std::sync::Arc;

/// Unix seconds of a UTC calendar instant (proleptic Gregorian; days from civil, written out
/// here).
fn unix(y: i64, m: i64, d: i64, hh: i64, mm: i64) -> f64 {
    let (y, m) = if m <= 2 { (y - 1, m + 9) } else { (y, m - 3) };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let doy = (153 * m + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    let days = era * 146_097 + doe - 719_468;
    (days * 86_400 + hh * 3600 + mm * 60) as f64
}

/// Right ascension (deg, 0 to 360) and declination (deg) of a unit vector.
fn ra_dec(s: &Vector3<f64>) -> (f64, f64) {
    (
        s.y.atan2(s.x).to_degrees().rem_euclid(360.0),
        s.z.asin().to_degrees(),
    )
}

/// Angular difference (deg) folded into −180..180.
fn diff_deg(a: f64, b: f64) -> f64 {
    (a - b + 180.0).rem_euclid(360.0) - 180.0
}

/// The 2024 equinoxes and solstices (USNO, "Earth's Seasons: Equinoxes, Solstices,
/// Perihelion, and Aphelion", to the minute, UTC): the apparent Sun is at right ascension
/// 0°, 90°, 180°, 270° and declination 0, +ε, 0, −ε (ε = 23.44°), to the 0.01° of the
/// low-precision formulas (checked to 0.05°; the Sun's declination moves 0.017° an hour at
/// the equinoxes, its right ascension 0.04° an hour).
#[test]
fn the_sun_is_where_the_seasons_put_it() {
    let eps = 23.436;
    let cases = [
        ("March equinox", unix(2024, 3, 20, 3, 6), 0.0, 0.0),
        ("June solstice", unix(2024, 6, 20, 20, 51), 90.0, eps),
        ("September equinox", unix(2024, 9, 22, 12, 44), 180.0, 0.0),
        ("December solstice", unix(2024, 12, 21, 9, 21), 270.0, -eps),
    ];
    for (what, t, ra, dec) in cases {
        let (s, _) = sun_direction(t);
        assert!((s.norm() - 1.0).abs() < 1e-15);
        let (got_ra, got_dec) = ra_dec(&s);
        eprintln!("{what}: RA {got_ra:.4}° (expected {ra}°), dec {got_dec:.4}° (expected {dec}°)");
        assert!(diff_deg(got_ra, ra).abs() < 0.05, "{what}: RA {got_ra}");
        assert!((got_dec - dec).abs() < 0.05, "{what}: dec {got_dec}");
    }
    // The 1 January 1970 date arithmetic of this test: J2000 is 946 728 000 s.
    assert_eq!(unix(2000, 1, 1, 12, 0), 946_728_000.0);
}

/// 2024 perihelion (3 January 00:39 UTC, 147 100 632 km) and aphelion (5 July 05:06 UTC,
/// 152 100 527 km), USNO: the distance to 2e-4 AU (the formulas track the Earth–Moon
/// barycentre's ellipse; the Earth swings ±4 700 km = 3e-5 AU about it).
#[test]
fn the_sun_is_nearest_in_january_and_farthest_in_july() {
    let au = 149_597_870.7;
    for (what, t, km) in [
        ("perihelion", unix(2024, 1, 3, 0, 39), 147_100_632.0),
        ("aphelion", unix(2024, 7, 5, 5, 6), 152_100_527.0),
    ] {
        let (_, d) = sun_direction(t);
        eprintln!("{what}: {d:.6} AU (expected {:.6})", km / au);
        assert!((d - km / au).abs() < 2e-4, "{what}: {d} AU");
        // And it is the extreme: a day either side is farther (perihelion) / nearer.
        let (_, before) = sun_direction(t - 86_400.0 * 3.0);
        let (_, after) = sun_direction(t + 86_400.0 * 3.0);
        if what == "perihelion" {
            assert!(before > d && after > d);
        } else {
            assert!(before < d && after < d);
        }
    }
}

const EPOCH_JUNE_SOLSTICE_NS: i64 = 1_718_916_660_000_000_000; // 2024-06-20T20:51Z

fn plate(orbit: Orbit, normal: Vector3<f64>, r_cp: Vector3<f64>) -> SolarPressure {
    SolarPressure {
        name: "p".into(),
        orbit: Arc::new(orbit),
        epoch_unix_ns: EPOCH_JUNE_SOLSTICE_NS,
        area: 2.0,
        normal,
        center_of_pressure: r_cp,
        specular: 0.3,
        diffuse: 0.5,
    }
}

/// An equatorial orbit at the June solstice, when the Sun is at RA 90°, dec 23.44°
/// (ŝ = (0, cos ε, sin ε)): at argument of latitude 270° the spacecraft is on the anti-Sun
/// side, |r − (r·ŝ)ŝ| = a sin ε = 2 736 km < R at 500 km, in shadow; at 90° it faces the Sun;
/// at 0° (r ⟂ ŝ, the terminator) it is lit; in GEO at 270°, a sin ε = 16 774 km > R: lit
/// (geostationary eclipses happen only near the equinoxes).
#[test]
fn the_earth_shadows_the_anti_sun_side_of_a_low_orbit() {
    assert_eq!(
        EPOCH_JUNE_SOLSTICE_NS as f64 * 1e-9,
        unix(2024, 6, 20, 20, 51)
    );
    let eps = 23.44f64.to_radians();
    let s_expected = Vector3::new(0.0, eps.cos(), eps.sin());
    let (s, _) = sun_direction(unix(2024, 6, 20, 20, 51));
    assert!((s - s_expected).norm() < 1e-3, "{s:?}");
    let earth = CentralBody::EARTH;
    for (a, u_deg, lit) in [
        (6_878_137.0, 270.0, false),
        (6_878_137.0, 250.0, false),
        (6_878_137.0, 90.0, true),
        (6_878_137.0, 0.0, true),
        (6_878_137.0, 180.0, true),
        (42_164_000.0, 270.0, true),
    ] {
        let orbit = Orbit::new(
            earth,
            Elements::new(a, 0.0, 0.0, 0.0, 0.0, f64::to_radians(u_deg)),
            false,
        )
        .unwrap();
        let sp = plate(orbit, Vector3::x(), Vector3::zeros());
        // The test's own geometry, with the test's own ŝ.
        let r = a * Vector3::new(
            f64::to_radians(u_deg).cos(),
            f64::to_radians(u_deg).sin(),
            0.0,
        );
        let along = r.dot(&s_expected);
        let shadow_here = along < 0.0 && (r - along * s_expected).norm() < earth.radius;
        assert_eq!(shadow_here, !lit, "a = {a}, u = {u_deg}");
        assert_eq!(sp.illuminated(0.0, &s), lit, "a = {a}, u = {u_deg}");
        // In shadow, nothing; in sunlight with the plate facing the Sun, a force.
        let q = UnitQuaternion::identity();
        let sp = SolarPressure { normal: s, ..sp };
        let st = sp.state_at(0.0, &[q.w, q.i, q.j, q.k]);
        assert_eq!(st.illuminated, lit);
        assert_eq!(st.force.norm() > 0.0, lit);
    }
}

/// The plate force by hand. Facing the Sun (n̂ = ŝ, cos α = 1):
/// F = −P A [(1 − ρs) + 2ρs + 2ρd/3] ŝ = −P A (1 + ρs + 2ρd/3) ŝ; for ρs = 0.3, ρd = 0.5,
/// A = 2 m²: −2 P (1.3 + 1/3) ŝ = −(9.8/3) P ŝ. Tilted 60° (cos α = ½):
/// F = −P A ½ [(1 − ρs) ŝ + 2 (ρs/2 + ρd/3) n̂] = −P [0.7 ŝ + (0.3 + 1/3) n̂]. Seen from
/// behind (cos α < 0): zero.
#[test]
fn the_plate_force_matches_the_hand_derivation() {
    let p: f64 = 1361.0 / 299_792_458.0;
    assert!((p - 4.5398e-6).abs() < 1e-10);
    let orbit = Orbit::new(
        CentralBody::EARTH,
        Elements::new(6_878_137.0, 0.0, 0.5, 0.0, 0.0, 0.0),
        false,
    )
    .unwrap();
    let s = Vector3::new(1.0, 2.0, -2.0) / 3.0;
    let sp = plate(orbit.clone(), s, Vector3::zeros());
    let f = sp.plate_force(&s, p);
    let expected = -(9.8 / 3.0) * p * s;
    assert!((f - expected).norm() <= 1e-15 * expected.norm(), "{f:?}");
    // 60°: n̂ turned from ŝ about an axis perpendicular to it.
    let axis = nalgebra::Unit::new_normalize(s.cross(&Vector3::z()));
    let n = nalgebra::Rotation3::from_axis_angle(&axis, 60f64.to_radians()) * s;
    assert!((n.dot(&s) - 0.5).abs() < 1e-15);
    let sp = plate(orbit.clone(), n, Vector3::zeros());
    let f = sp.plate_force(&s, p);
    let expected = -p * (0.7 * s + (0.3 + 1.0 / 3.0) * n);
    assert!((f - expected).norm() <= 1e-14 * expected.norm(), "{f:?}");
    // The back of the plate, and edge-on.
    let sp = plate(orbit.clone(), -s, Vector3::zeros());
    assert_eq!(sp.plate_force(&s, p), Vector3::zeros());
    let sp = plate(orbit, axis.into_inner(), Vector3::zeros());
    assert!(sp.plate_force(&s, p).norm() < 1e-25);
}

/// Along a sunlit orbit position with the plate facing the Sun: the pressure is 1361/c
/// scaled by (1 AU/d)², the force is along −ŝ, the torque is r_cp × F, and zero for
/// r_cp = 0.
#[test]
fn the_torque_is_the_arm_cross_the_force() {
    let orbit = Orbit::new(
        CentralBody::EARTH,
        Elements::new(6_878_137.0, 0.0, 0.0, 0.0, 0.0, 90f64.to_radians()),
        false,
    )
    .unwrap();
    let (s_n, d) = sun_direction(EPOCH_JUNE_SOLSTICE_NS as f64 * 1e-9);
    // 20 June: 1.0162 AU.
    assert!((d - 1.0162).abs() < 2e-4, "{d}");
    let q = UnitQuaternion::from_euler_angles(0.4, -0.7, 1.3);
    let raw = [q.w, q.i, q.j, q.k];
    let s_b = q.inverse_transform_vector(&s_n);
    let r_cp = Vector3::new(0.1, -0.4, 0.25);
    let sp = plate(orbit.clone(), s_b, r_cp);
    let st = sp.state_at(0.0, &raw);
    assert!(st.illuminated);
    assert!((st.sun_body - s_b).norm() < 1e-14);
    let p = 1361.0 / 299_792_458.0 / (d * d);
    let expected = -2.0 * p * (1.0 + 0.3 + 2.0 * 0.5 / 3.0) * s_b;
    assert!((st.force - expected).norm() <= 1e-13 * expected.norm());
    let tau = r_cp.cross(&expected);
    assert!((st.torque - tau).norm() <= 1e-13 * tau.norm());
    eprintln!(
        "|F| = {:e} N, |τ| = {:e} N m",
        st.force.norm(),
        st.torque.norm()
    );
    let sp = plate(orbit, s_b, Vector3::zeros());
    assert_eq!(sp.state_at(0.0, &raw).torque, Vector3::zeros());
}

fn load(yaml: &str) -> Scenario {
    parse(
        Path::new("srp.yaml"),
        yaml.to_string(),
        &Overrides::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"))
}

/// With the centre of pressure at the centre of mass, nothing turns the body: ω stays put.
#[test]
fn a_plate_at_the_centre_of_mass_exerts_no_torque() {
    let yaml = "name: srp0
epoch: 2024-06-20T20:51:00Z
body: {principal: [0.035, 0.035, 0.008]}
orbit: {semi_major_axis_km: 6878.137, inclination_deg: 97.4}
initial: {omega: [0.0, 0.0, 0.05]}
duration: 3000
integrator: {method: dop853, rtol: 1.0e-12, atol: 1.0e-15}
output: {rate: 0.1}
effectors:
  - solar_pressure: {area: 0.3, normal: [1, 0, 0], center_of_pressure: [0, 0, 0], specular: 0.2, diffuse: 0.3}
";
    let (out, rec) = run(&load(yaml));
    assert_eq!(out.status, Status::Complete);
    let first = &rec.samples[0];
    for o in &rec.samples {
        assert_eq!(o.kinetic_energy, first.kinetic_energy, "t = {}", o.t);
        assert_eq!(o.external_work, first.external_work, "work at t = {}", o.t);
    }
}

/// A 3U CubeSat with a 0.3 m² deployed panel 0.2 m off its centre of mass, tumbling in a
/// 500 km, 51.6° orbit through two orbits with eclipses: T − W stays put to 1e-9 of T while
/// T itself changes.
#[test]
fn the_energy_balance_holds_while_the_pressure_works() {
    let yaml = "name: srp
epoch: 2024-03-20T03:06:00Z
body: {principal: [0.035, 0.035, 0.008]}
orbit: {semi_major_axis_km: 6878.137, inclination_deg: 51.6, raan_deg: 40.0}
initial: {omega: [0.002, -0.001, 0.003]}
duration: 11340
integrator: {method: dop853, rtol: 1.0e-13, atol: 1.0e-16}
output: {rate: 0.05}
effectors:
  - solar_pressure: {area: 0.3, normal: [0.6, 0, 0.8], center_of_pressure: [0.0, 0.2, 0.1], specular: 0.1, diffuse: 0.2}
";
    let s = load(yaml);
    let (out, rec) = run(&s);
    assert_eq!(out.status, Status::Complete);
    let (worst, spread) = common::balance_drift_and_spread(&rec.samples);
    eprintln!("T - W drift {worst:e} of T0, T spread {:e} of T0", spread);
    assert!(worst < 1e-9, "energy balance drift {worst:e} (relative)");
    assert!(spread > 1e-3, "T spread {:e}", spread);
    // The run crosses the Earth's shadow: on this orbit, at this epoch, both states occur.
    let orbit = Orbit::new(
        CentralBody::EARTH,
        Elements::new(
            6_878_137.0,
            0.0,
            51.6f64.to_radians(),
            40f64.to_radians(),
            0.0,
            0.0,
        ),
        false,
    )
    .unwrap();
    let mut sp = plate(orbit, Vector3::x(), Vector3::zeros());
    sp.epoch_unix_ns = 1_710_903_960_000_000_000; // 2024-03-20T03:06Z
    assert_eq!(sp.epoch_unix_ns as f64 * 1e-9, unix(2024, 3, 20, 3, 6));
    let lit = (0..1134)
        .filter(|k| {
            let t = *k as f64 * 10.0;
            sp.illuminated(t, &sp.sun_eci(t).0)
        })
        .count();
    eprintln!("sunlit {lit} of 1134 samples");
    assert!(lit > 600 && lit < 1000, "{lit}");
}

#[test]
fn bad_solar_pressure_input_is_refused_with_located_errors() {
    let base =
        "name: x\nbody: {principal: [1, 2, 3]}\ninitial: {omega: [0, 0, 0.1]}\nduration: 1\n";
    let orbit = "orbit: {semi_major_axis_km: 7000}\n";
    let good =
        "area: 1, normal: [1, 0, 0], center_of_pressure: [0, 0, 0.1], specular: 0.2, diffuse: 0.3";
    let with = |body: &str| format!("{base}{orbit}effectors:\n  - solar_pressure: {{{body}}}\n");
    let cases = [
        (
            format!("{base}effectors:\n  - solar_pressure: {{{good}}}\n"),
            "srp.yaml:6:5: field `effectors[0].solar_pressure`: an environmental torque needs the spacecraft's orbit".to_string(),
        ),
        (
            with(&good.replace("area: 1", "area: 0")),
            "srp.yaml:7:28: field `effectors[0].solar_pressure.area`: expected a positive value".to_string(),
        ),
        (
            with(&good.replace("normal: [1, 0, 0]", "normal: [0, 0, 0]")),
            "field `effectors[0].solar_pressure.normal`: expected a non-zero vector".to_string(),
        ),
        (
            with(&good.replace("normal: [1, 0, 0]", "normal: [.nan, 0, 1]")),
            "field `effectors[0].solar_pressure.normal`: expected a non-zero vector".to_string(),
        ),
        (
            with(&good.replace("[0, 0, 0.1]", "[0, 2000, 0]")),
            "field `effectors[0].solar_pressure.center_of_pressure`: expected three finite numbers within 1e3 m".to_string(),
        ),
        (
            with(&good.replace("specular: 0.2", "specular: -0.1")),
            "field `effectors[0].solar_pressure.specular`: expected a reflectivity from 0 to 1, got -0.1".to_string(),
        ),
        (
            with(&good.replace("diffuse: 0.3", "diffuse: 1.5")),
            "field `effectors[0].solar_pressure.diffuse`: expected a reflectivity from 0 to 1".to_string(),
        ),
        (
            with(&good.replace("diffuse: 0.3", "diffuse: 0.9")),
            "field `effectors[0].solar_pressure.diffuse`: expected specular + diffuse at most 1 (the rest is absorbed), got 0.2 + 0.9".to_string(),
        ),
        (
            with("area: 1, normal: [1, 0, 0], specular: 0.2, diffuse: 0.3"),
            "missing field `center_of_pressure`".to_string(),
        ),
        (
            format!("epoch: 2051-01-01T00:00:00Z\n{}", with(good)),
            "srp.yaml:1:8: field `epoch`: the low-precision solar coordinates".to_string(),
        ),
    ];
    for (yaml, expect) in cases {
        let e = parse(Path::new("srp.yaml"), yaml.clone(), &Overrides::default())
            .expect_err(&yaml)
            .to_string();
        assert!(e.contains(&expect), "expected {expect:?} in {e}\n{yaml}");
    }
    // The default epoch (J2000) is fine, and a plate that only reflects.
    load(&with(good));
    load(&with(&good.replace("diffuse: 0.3", "diffuse: 0.8")));
}
