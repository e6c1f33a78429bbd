//! The exponential atmosphere and the `aerodynamic` drag torque, checked against what polhode
//! did not produce: the rows of Vallado's Table 8-4 typed again here, the U.S. Standard
//! Atmosphere 1976 evaluated here from its defining equations, the relative wind and the
//! torque worked out by hand, the work–energy balance of a tumbling CubeSat, and the located
//! errors. For drag on the facets of `body.shape` (`from_shape: true`): one face turned to
//! the wind against a single plate by hand, a cube at symmetric incidence against √2 s² and
//! √3 s², the cylinder's projected area against its closed form, box and cylinder at general
//! attitudes against a silhouette ray-cast here, the composite placement, the work–energy
//! balance, and the located errors.
mod common;

use common::run;

use nalgebra::{UnitQuaternion, Vector3};
use polhode::effectors::Aerodynamic;
use polhode::effectors::aerodynamic::facets::DragSurface;
use polhode::effectors::aerodynamic::{ShapeAerodynamic, density};
use polhode::model::HubState;
use polhode::orbit::{CentralBody, Elements, Orbit};
use polhode::scenario::{Overrides, Scenario, parse};
use polhode::sim::Status;
use std::path::Path;
use std::sync::Arc;

/// WGS-84 GM (m³/s²), equatorial radius (m) and rotation rate (rad/s), NIMA TR8350.2 Table 3.1.
const MU: f64 = 3.986_004_418e14;
const R_E: f64 = 6_378_137.0;
const OMEGA_E: f64 = 7.292_115e-5;

/// Rows of Vallado (2013), Table 8-4, typed again for the test: base altitude (km), nominal
/// density (kg/m³), scale height (km).
const ROWS: [(f64, f64, f64); 8] = [
    (0.0, 1.225, 7.249),
    (25.0, 3.899e-2, 6.349),
    (100.0, 5.297e-7, 5.877),
    (150.0, 2.070e-9, 22.523),
    (400.0, 3.725e-12, 58.515),
    (500.0, 6.967e-13, 63.822),
    (900.0, 5.245e-15, 181.05),
    (1000.0, 3.019e-15, 268.00),
];

#[test]
fn the_density_is_the_tabulated_one_at_the_band_bases_and_exponential_between() {
    for (h0, rho0, _) in ROWS {
        assert_eq!(density(h0 * 1e3), rho0, "at {h0} km");
    }
    // Midpoints, evaluated by hand: 425 km is 25 km into the 400 km band,
    // 3.725e-12 exp(−25/58.515) = 3.725e-12 × 0.652307 = 2.42984e-12; 525 km,
    // 6.967e-13 exp(−25/63.822) = 6.967e-13 × 0.675897 = 4.70897e-13; 1100 km (the last
    // band goes on), 3.019e-15 exp(−100/268) = 3.019e-15 × 0.688576 = 2.07881e-15.
    for (h, expected) in [
        (425e3, 2.42984e-12),
        (525e3, 4.70897e-13),
        (1100e3, 2.07881e-15),
    ] {
        let rho = density(h);
        assert!(
            (rho / expected - 1.0).abs() < 5e-6,
            "{h}: {rho:e} vs {expected:e}"
        );
    }
    // Just below a band base the lower band holds; the fit is continuous to 0.2% there.
    let below = density(400e3 - 1e-3);
    assert!((below / 3.725e-12 - 1.0).abs() < 2e-3, "{below:e}");
    // Monotone decreasing from 0 to 1200 km in 1 km steps.
    let mut last = f64::INFINITY;
    for k in 0..=1200 {
        let rho = density(k as f64 * 1e3);
        assert!(rho < last && rho > 0.0, "{k} km");
        last = rho;
    }
}

/// The U.S. Standard Atmosphere 1976 (NOAA, NASA, USAF, 1976), below 86 km, from its
/// defining equations: geopotential altitude H = r₀ z/(r₀ + z), r₀ = 6356.766 km; linear
/// molecular-temperature layers with bases 0, 11, 20, 32, 47, 51, 71 km′ and gradients −6.5,
/// 0, 1, 2.8, 0, −2.8, −2 K/km′; the hydrostatic pressure in each layer; ρ = P M₀/(R* T),
/// g₀ = 9.80665 m/s², M₀ = 28.9644 kg/kmol, R* = 8314.32 J/(kmol K).
fn ussa76(z: f64) -> f64 {
    const LAYERS: [(f64, f64); 8] = [
        (0.0, -6.5e-3),
        (11_000.0, 0.0),
        (20_000.0, 1.0e-3),
        (32_000.0, 2.8e-3),
        (47_000.0, 0.0),
        (51_000.0, -2.8e-3),
        (71_000.0, -2.0e-3),
        (84_852.0, 0.0),
    ];
    let (g0, m0, r_star, r0) = (9.80665, 28.9644, 8314.32, 6_356_766.0);
    let gmr = g0 * m0 / r_star;
    let h = r0 * z / (r0 + z);
    let (mut t, mut p) = (288.15, 101_325.0);
    for w in LAYERS.windows(2) {
        let ((hb, l), (ht, _)) = (w[0], w[1]);
        let top = h.min(ht);
        if l == 0.0 {
            p *= (-gmr * (top - hb) / t).exp();
        } else {
            let tn = t + l * (top - hb);
            p *= (tn / t).powf(-gmr / l);
            t = tn;
        }
        if h <= ht {
            break;
        }
    }
    p * m0 / (r_star * t)
}

/// The table's rows from 0 to 80 km against the 1976 standard: sea level exactly, the
/// CIRA-72 rows above it within 6% (Vallado takes 25–1000 km from CIRA-72, a different
/// model). The standard evaluated here reproduces its published table values.
#[test]
fn the_lower_rows_agree_with_the_us_standard_atmosphere_1976() {
    // Published USSA76 densities (kg/m³) at 25, 50 and 80 km.
    for (z, published) in [(25e3, 4.0084e-2), (50e3, 1.0269e-3), (80e3, 1.8458e-5)] {
        let got = ussa76(z);
        assert!(
            (got / published - 1.0).abs() < 1e-4,
            "{z}: {got:e} vs {published:e}"
        );
    }
    for (km, worst) in [
        (0.0, 1e-5),
        (25.0, 0.03),
        (30.0, 0.04),
        (40.0, 0.01),
        (50.0, 0.03),
        (60.0, 0.04),
        (70.0, 0.06),
        (80.0, 0.035),
    ] {
        let (ours, standard) = (density(km * 1e3), ussa76(km * 1e3));
        let diff = (ours / standard - 1.0).abs();
        eprintln!("{km} km: table {ours:e}, USSA76 {standard:e}, {diff:.4}");
        assert!(diff < worst, "{km} km: {ours:e} vs {standard:e}");
    }
}

fn equatorial(altitude: f64) -> Arc<Orbit> {
    Arc::new(
        Orbit::new(
            CentralBody::EARTH,
            Elements::new(R_E + altitude, 0.0, 0.0, 0.0, 0.0, 0.0),
            false,
        )
        .unwrap(),
    )
}

fn aero(orbit: Arc<Orbit>, cp: Vector3<f64>) -> Aerodynamic {
    Aerodynamic {
        name: "a".into(),
        orbit,
        drag_coefficient: 2.2,
        area: 1.5,
        center_of_pressure: cp,
    }
}

/// Equatorial, prograde, circular at 400 km: the air co-rotates at ω_E a along-track, so
/// the relative velocity is (√(μ/a) − ω_E a) along-track = 7668.56 − 494.27 = 7174.29 m/s.
#[test]
fn the_relative_wind_of_an_equatorial_orbit_is_the_orbital_speed_less_the_air_speed() {
    let a = R_E + 400e3;
    let speed = (MU / a).sqrt() - OMEGA_E * a;
    assert!((speed - 7174.29).abs() < 0.01, "{speed}");
    let orbit = equatorial(400e3);
    let n = orbit.mean_motion();
    let md = aero(orbit, Vector3::new(0.1, -0.2, 0.3));
    let identity = [1.0, 0.0, 0.0, 0.0];
    for t in [0.0f64, 1000.0, 3000.0] {
        // Along-track: (−sin nt, cos nt, 0) in ECI; body = ECI for the identity attitude.
        let expected = speed * Vector3::new(-(n * t).sin(), (n * t).cos(), 0.0);
        let (rho, wind) = md.density_and_wind(t, &identity);
        assert!(
            (wind - expected).norm() <= 1e-9 * speed,
            "t = {t}: {wind:?} vs {expected:?}"
        );
        // The radius is a to an ulp, so the altitude may fall just below the 400 km base,
        // where the 350 km band gives 9.518e-12 exp(−50/53.298) = 3.72487e-12.
        assert!((rho / 3.725e-12 - 1.0).abs() < 1e-4, "{rho:e}");
    }
    // Turned 90° about z (body x along inertial y): at t = 0 the wind is along body +x.
    let q = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f64::consts::FRAC_PI_2);
    let (_, wind) = md.density_and_wind(0.0, &[q.w, q.i, q.j, q.k]);
    assert!(
        (wind - Vector3::new(speed, 0.0, 0.0)).norm() <= 1e-9 * speed,
        "{wind:?}"
    );
}

/// τ = r_cp × F worked out by components at t = 0, 400 km: the wind is w ŷ (identity
/// attitude), F = (0, −f, 0) with f = ½ ρ w² C_d A = ½ × 3.725e-12 × 7174.29² × 2.2 × 1.5
/// = 3.16350e-4 N, and (0.1, −0.2, 0.3) × (0, −f, 0) = (0.3 f, 0, −0.1 f).
#[test]
fn the_torque_is_the_centre_of_pressure_cross_the_drag_force() {
    let a = R_E + 400e3;
    let w = (MU / a).sqrt() - OMEGA_E * a;
    let f = 0.5 * 3.725e-12 * w * w * 2.2 * 1.5;
    assert!((f / 3.16350e-4 - 1.0).abs() < 1e-5, "{f:e}");
    let md = aero(equatorial(400e3), Vector3::new(0.1, -0.2, 0.3));
    let tau = md.torque_at(0.0, &[1.0, 0.0, 0.0, 0.0]);
    let expected = Vector3::new(0.3 * f, 0.0, -0.1 * f);
    assert!(
        (tau - expected).norm() <= 1e-9 * expected.norm(),
        "{tau:?} vs {expected:?}"
    );
    // Turned 90° about z, the wind is w x̂ in body axes: F = (−f, 0, 0) and
    // (0.1, −0.2, 0.3) × (−f, 0, 0) = (0, −0.3 f, −0.2 f).
    let q = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f64::consts::FRAC_PI_2);
    let tau = md.torque_at(0.0, &[q.w, q.i, q.j, q.k]);
    let expected = Vector3::new(0.0, -0.3 * f, -0.2 * f);
    assert!(
        (tau - expected).norm() <= 1e-9 * expected.norm(),
        "{tau:?} vs {expected:?}"
    );
}

#[test]
fn the_torque_is_zero_with_the_centre_of_pressure_at_the_centre_of_mass() {
    let orbit = Arc::new(
        Orbit::new(
            CentralBody::EARTH,
            Elements::new(R_E + 300e3, 0.01, 0.9, 0.4, 1.1, 0.2),
            false,
        )
        .unwrap(),
    );
    let md = aero(orbit, Vector3::zeros());
    let q = UnitQuaternion::from_euler_angles(0.3, -1.2, 2.5);
    for t in [0.0, 1234.5, 4000.0] {
        assert_eq!(
            md.torque_at(t, &[q.w, q.i, q.j, q.k]),
            Vector3::zeros(),
            "t = {t}"
        );
    }
}

fn load(yaml: &str) -> Scenario {
    parse(
        Path::new("aero.yaml"),
        yaml.to_string(),
        &Overrides::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"))
}

/// A 3U CubeSat tumbling at 350 km, 51.6°, with its centre of pressure 2 cm off the centre
/// of mass, for one orbit: T − W stays put to 1e-9 of T while T itself changes.
#[test]
fn the_energy_balance_holds_while_the_drag_torque_works() {
    let yaml = "name: aero
body: {principal: [0.035, 0.035, 0.008]}
orbit: {semi_major_axis_km: 6728.137, inclination_deg: 51.6, raan_deg: 40.0}
initial: {omega: [0.02, -0.01, 0.03]}
duration: 5500
integrator: {method: dop853, rtol: 1.0e-13, atol: 1.0e-16}
output: {rate: 0.05}
effectors:
  - aerodynamic: {drag_coefficient: 2.2, area: 0.03, center_of_pressure: [0.0, 0.02, 0.01]}
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
fn bad_aerodynamic_input_is_refused_with_located_errors() {
    let base =
        "name: x\nbody: {principal: [1, 2, 3]}\ninitial: {omega: [0, 0, 0.1]}\nduration: 1\n";
    let orbit = "orbit: {semi_major_axis_km: 6800}\n";
    let item = |cd: &str, area: &str, cp: &str| {
        format!(
            "effectors:\n  - aerodynamic: {{drag_coefficient: {cd}, area: {area}, center_of_pressure: {cp}}}\n"
        )
    };
    let cases = [
        (
            format!("{base}{}", item("2.2", "1", "[0.1, 0, 0]")),
            "aero.yaml:6:5: field `effectors[0].aerodynamic`: an environmental torque needs the spacecraft's orbit",
        ),
        (
            format!("{base}{orbit}{}", item("0", "1", "[0.1, 0, 0]")),
            "aero.yaml:7:37: field `effectors[0].aerodynamic.drag_coefficient`: expected a value in (0, 10]",
        ),
        (
            format!("{base}{orbit}{}", item("10.5", "1", "[0.1, 0, 0]")),
            "field `effectors[0].aerodynamic.drag_coefficient`: expected a value in (0, 10]",
        ),
        (
            format!("{base}{orbit}{}", item(".nan", "1", "[0.1, 0, 0]")),
            "field `effectors[0].aerodynamic.drag_coefficient`",
        ),
        (
            format!("{base}{orbit}{}", item("2.2", "0", "[0.1, 0, 0]")),
            "field `effectors[0].aerodynamic.area`: expected a positive value",
        ),
        (
            format!("{base}{orbit}{}", item("2.2", "1", "[1.0e3, 1, 0]")),
            "field `effectors[0].aerodynamic.center_of_pressure`: expected three finite numbers within 1e3 m",
        ),
        (
            format!("{base}{orbit}{}", item("2.2", "1", "[.inf, 0, 0]")),
            "field `effectors[0].aerodynamic.center_of_pressure`",
        ),
        (
            format!(
                "{base}{orbit}effectors:\n  - aerodynamic: {{drag_coefficient: 2.2, area: 1}}\n"
            ),
            "missing field `center_of_pressure`",
        ),
    ];
    for (yaml, expect) in cases {
        let e = parse(Path::new("aero.yaml"), yaml.clone(), &Overrides::default())
            .expect_err(&yaml)
            .to_string();
        assert!(e.contains(expect), "expected {expect:?} in {e}\n{yaml}");
    }
    // The edges are accepted, and the default name is the kind.
    let s = load(&format!(
        "{base}{orbit}{}",
        item("10", "1", "[1.0e3, 0, 0]")
    ));
    assert_eq!(s.spacecraft.effectors()[0].name(), "aerodynamic");
}

// ---------------------------------------------------------------------------------------
// Drag on the facets of `body.shape`.

/// The wind speed (m/s) and ½ ρ w² C_d (N/m²) at t = 0 on the equatorial circular orbit at
/// 400 km, by hand: w = √(μ/a) − ω_E a, ρ = 3.725e-12 kg/m³ (the 400 km row), C_d = 2.2.
fn dynamic_pressure_400km() -> (f64, f64) {
    let a = R_E + 400e3;
    let w = (MU / a).sqrt() - OMEGA_E * a;
    (w, 0.5 * 3.725e-12 * w * w * 2.2)
}

fn shape_aero(surface: DragSurface) -> ShapeAerodynamic {
    ShapeAerodynamic {
        name: "a".into(),
        orbit: equatorial(400e3),
        drag_coefficient: 2.2,
        surface,
    }
}

fn close(got: Vector3<f64>, want: Vector3<f64>, tol: f64, what: &str) {
    assert!(
        (got - want).norm() <= tol * want.norm(),
        "{what}: {got:?} vs {want:?}"
    );
}

/// The torque of the first effector of `s` at t = 0 for the attitude `q`.
fn torque_of(s: &Scenario, q: &UnitQuaternion<f64>) -> Vector3<f64> {
    let attitude = [q.w, q.i, q.j, q.k];
    let hub = HubState {
        t: 0.0,
        omega: Vector3::zeros(),
        attitude: &attitude,
    };
    s.spacecraft.effectors()[0].torque(&hub, &[0.0])
}

/// A box of 0.2 × 0.3 × 0.5 m centred at c = (0.1, −0.2, 0.3) m from the centre of mass,
/// with the wind along a face normal: only that face takes the flow, so the drag is one
/// plate of that face's area at its centre. Identity attitude, t = 0: the wind is w ŷ, the
/// +y face (0.2 × 0.5 = 0.1 m²) at c + 0.15 ŷ takes F = (0, −f, 0), f = q 0.1 m², and
/// τ = (c + 0.15 ŷ) × F = c × F = (0.3 f, 0, −0.1 f). Turned 90° about z the wind is w x̂:
/// the +x face (0.3 × 0.5 = 0.15 m²) takes F = (−f′, 0, 0), f′ = q 0.15 m², and
/// τ = c × F = (0, −0.3 f′, −0.2 f′). Both through the structure and through the YAML.
#[test]
fn a_box_face_on_to_the_wind_is_one_plate_at_that_face() {
    let (_, q) = dynamic_pressure_400km();
    let c = Vector3::new(0.1, -0.2, 0.3);
    let md = shape_aero(DragSurface::cuboid(
        Vector3::new(0.2, 0.3, 0.5),
        &UnitQuaternion::identity(),
        c,
    ));
    let s = load(
        "name: a
body: {principal: [1, 2, 3], shape: {box: {size: [0.2, 0.3, 0.5]}}}
orbit: {semi_major_axis_km: 6778.137}
initial: {omega: [0, 0, 0.1]}
duration: 1
effectors:
  - aerodynamic: {drag_coefficient: 2.2, from_shape: true, shape_center: [0.1, -0.2, 0.3]}
",
    );
    let identity = UnitQuaternion::identity();
    let f = q * 0.1;
    let want = Vector3::new(0.3 * f, 0.0, -0.1 * f);
    close(
        md.torque_at(0.0, &[1.0, 0.0, 0.0, 0.0]),
        want,
        1e-9,
        "face +y",
    );
    close(torque_of(&s, &identity), want, 1e-9, "face +y, YAML");
    let (rho, wind) = md.density_and_wind(0.0, &[1.0, 0.0, 0.0, 0.0]);
    let (force, _) = md.force_and_torque(rho, &wind);
    close(force, Vector3::new(0.0, -f, 0.0), 1e-9, "force, face +y");

    let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f64::consts::FRAC_PI_2);
    let f = q * 0.15;
    let want = Vector3::new(0.0, -0.3 * f, -0.2 * f);
    close(
        md.torque_at(0.0, &[turn.w, turn.i, turn.j, turn.k]),
        want,
        1e-9,
        "face +x",
    );
    close(torque_of(&s, &turn), want, 1e-9, "face +x, YAML");
}

/// A cube of side s = 0.4 m: with the wind along a face diagonal two faces take it at
/// cos 45°, A_p = 2 s²/√2 = √2 s²; along a body diagonal three faces at 1/√3,
/// A_p = 3 s²/√3 = √3 s². Centred on the centre of mass the torque vanishes by symmetry;
/// centred at c it is c × F (the three faces' centres at c + (s/2) ê_k average, weighted
/// equally, to c + (s/6)(1, 1, 1), which is along the wind).
#[test]
fn a_cube_at_symmetric_incidence_shows_root_two_and_root_three_faces() {
    let side: f64 = 0.4;
    let (rho, speed) = (3.725e-12, 7000.0);
    let q = 0.5 * rho * speed * speed * 2.2;
    for (dir, area) in [
        (Vector3::new(1.0, 1.0, 0.0), 2f64.sqrt() * side * side),
        (Vector3::new(1.0, 1.0, 1.0), 3f64.sqrt() * side * side),
        (Vector3::new(-1.0, 0.0, 1.0), 2f64.sqrt() * side * side),
        (Vector3::new(1.0, -1.0, -1.0), 3f64.sqrt() * side * side),
    ] {
        let wind = speed * dir.normalize();
        let want_force = -q * area * dir.normalize();
        let centred = shape_aero(DragSurface::cuboid(
            Vector3::repeat(side),
            &UnitQuaternion::identity(),
            Vector3::zeros(),
        ));
        let (force, torque) = centred.force_and_torque(rho, &wind);
        close(force, want_force, 1e-14, "force");
        assert!(
            torque.norm() <= 1e-15 * force.norm() * side,
            "{dir:?}: {torque:?}"
        );
        let c = Vector3::new(0.03, -0.05, 0.02);
        let offset = shape_aero(DragSurface::cuboid(
            Vector3::repeat(side),
            &UnitQuaternion::identity(),
            c,
        ));
        let (force, torque) = offset.force_and_torque(rho, &wind);
        close(force, want_force, 1e-14, "force, offset");
        close(torque, c.cross(&want_force), 1e-13, "torque, offset");
    }
}

/// A cylinder of radius r and length L seen at α from its axis shows its end cap
/// (π r² cos α) and its side (a 2r × L sin α rectangle): A_p = π r² |cos α| + 2 r L sin α.
/// By hand for r = 0.3 m, L = 1.2 m: 0.282743 m² end-on, 0.72 m² side-on, and at 45°
/// (0.282743 + 0.72)/√2 = 0.709047 m²; at 30° and 60° against the formula.
#[test]
fn the_cylinder_shows_its_closed_form_projected_area() {
    let (r, l): (f64, f64) = (0.3, 1.2);
    let axis = Vector3::new(1.0, 2.0, -2.0) / 3.0;
    let orientation = UnitQuaternion::rotation_between(&Vector3::z(), &axis).unwrap();
    let cylinder = DragSurface::cylinder(r, l, &orientation, Vector3::zeros());
    // A direction perpendicular to the axis.
    let across = Vector3::new(2.0, -1.0, 0.0).normalize();
    let closed =
        |alpha: f64| std::f64::consts::PI * r * r * alpha.cos().abs() + 2.0 * r * l * alpha.sin();
    for (deg, by_hand) in [
        (0.0, Some(0.282_743)),
        (90.0, Some(0.72)),
        (45.0, Some(0.709_047)),
        (30.0, None),
        (60.0, None),
        (135.0, Some(0.709_047)),
        (180.0, Some(0.282_743)),
    ] {
        let alpha = f64::to_radians(deg);
        let w_hat = alpha.cos() * axis + alpha.sin() * across;
        let (area, _) = cylinder.projection(&w_hat);
        let want = closed(alpha);
        assert!(
            (area - want).abs() <= 1e-14 * want,
            "{deg}°: {area} vs {want}"
        );
        if let Some(h) = by_hand {
            assert!((area - h).abs() < 1e-6, "{deg}°: {area} vs {h}");
        }
    }
}

/// An orthonormal pair perpendicular to the unit vector `d`.
fn plane_basis(d: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let helper = if d.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let e1 = d.cross(&helper).normalize();
    (e1, d.cross(&e1))
}

/// The line p + t d meets the convex body `inside`, given as the parameter interval of each
/// of its slabs (min, max), intersected: the line hits when the intervals overlap.
fn overlap(intervals: &[(f64, f64)]) -> bool {
    let lo = intervals
        .iter()
        .map(|i| i.0)
        .fold(f64::NEG_INFINITY, f64::max);
    let hi = intervals.iter().map(|i| i.1).fold(f64::INFINITY, f64::min);
    lo <= hi
}

/// The interval of t where a + b t lies in [−h, h] (all t if b = 0 and |a| ≤ h).
fn slab(a: f64, b: f64, h: f64) -> (f64, f64) {
    if b == 0.0 {
        return if a.abs() <= h {
            (f64::NEG_INFINITY, f64::INFINITY)
        } else {
            (1.0, -1.0)
        };
    }
    let (t1, t2) = ((-h - a) / b, (h - a) / b);
    (t1.min(t2), t1.max(t2))
}

/// Ray-casts the silhouette of a convex body seen along `d` (unit) on an n × n grid of
/// cell midpoints spanning ±`half` about `center`: its area and its centroid.
fn silhouette(
    d: &Vector3<f64>,
    center: &Vector3<f64>,
    half: f64,
    n: usize,
    hit: impl Fn(&Vector3<f64>) -> bool,
) -> (f64, Vector3<f64>) {
    let (e1, e2) = plane_basis(d);
    let h = 2.0 * half / n as f64;
    let (mut count, mut sum) = (0usize, Vector3::zeros());
    for i in 0..n {
        for j in 0..n {
            let (u, v) = (-half + (i as f64 + 0.5) * h, -half + (j as f64 + 0.5) * h);
            let p = center + u * e1 + v * e2;
            if hit(&p) {
                count += 1;
                sum += p;
            }
        }
    }
    (count as f64 * h * h, sum / count as f64)
}

/// Box and cylinder at general attitudes, off the centre of mass, against their silhouettes
/// ray-cast here (a line meets the box when its three slab intervals overlap, and the
/// cylinder when its radial interval, from a quadratic, overlaps its axial slab): for convex
/// bodies the projected area is the silhouette's area, and the torque −q A_p (s̄ × ŵ) with s̄
/// the silhouette's centroid, since each silhouette point stands for one lit element.
#[test]
fn box_and_cylinder_agree_with_a_ray_cast_silhouette() {
    let (rho, speed) = (3.725e-12, 7000.0);
    let q = 0.5 * rho * speed * speed * 2.2;
    let n = 1500;
    let c = Vector3::new(0.04, -0.03, 0.05);
    let size = Vector3::new(0.3, 0.5, 0.8);
    let turn = UnitQuaternion::from_euler_angles(0.3, -0.5, 0.9);
    let cuboid = DragSurface::cuboid(size, &turn, c);
    let (r, l) = (0.25, 0.9);
    let axis = Vector3::new(0.2, -0.4, 0.9).normalize();
    let cylinder = DragSurface::cylinder(
        r,
        l,
        &UnitQuaternion::rotation_between(&Vector3::z(), &axis).unwrap(),
        c,
    );
    let mut worst: (f64, f64) = (0.0, 0.0);
    for dir in [
        Vector3::new(1.0, 0.2, -0.3),
        Vector3::new(-0.4, 0.9, 0.6),
        Vector3::new(0.1, -0.3, -1.0),
        axis + Vector3::new(0.05, 0.0, 0.0),
    ] {
        let d = dir.normalize();
        let wind = speed * d;
        let in_box = |p: &Vector3<f64>| {
            let (a, b) = (turn.inverse() * (p - c), turn.inverse() * d);
            overlap(&[
                slab(a.x, b.x, 0.5 * size.x),
                slab(a.y, b.y, 0.5 * size.y),
                slab(a.z, b.z, 0.5 * size.z),
            ])
        };
        let in_cylinder = |p: &Vector3<f64>| {
            let a = p - c;
            let (a_ax, d_ax) = (a.dot(&axis), d.dot(&axis));
            let (a_perp, d_perp) = (a - a_ax * axis, d - d_ax * axis);
            // |a⊥ + t d⊥|² ≤ r²: qa t² + qb t + qc ≤ 0.
            let (qa, qb, qc) = (
                d_perp.norm_squared(),
                2.0 * a_perp.dot(&d_perp),
                a_perp.norm_squared() - r * r,
            );
            let radial = if qa < 1e-300 {
                if qc <= 0.0 {
                    (f64::NEG_INFINITY, f64::INFINITY)
                } else {
                    (1.0, -1.0)
                }
            } else {
                let disc = qb * qb - 4.0 * qa * qc;
                if disc < 0.0 {
                    (1.0, -1.0)
                } else {
                    let s = disc.sqrt();
                    ((-qb - s) / (2.0 * qa), (-qb + s) / (2.0 * qa))
                }
            };
            overlap(&[radial, slab(a_ax, d_ax, 0.5 * l)])
        };
        for (what, surface, half, hit) in [
            (
                "box",
                &cuboid,
                0.5 * size.norm(),
                &in_box as &dyn Fn(&Vector3<f64>) -> bool,
            ),
            (
                "cylinder",
                &cylinder,
                (r * r + 0.25 * l * l).sqrt(),
                &in_cylinder as &dyn Fn(&Vector3<f64>) -> bool,
            ),
        ] {
            let (area, centroid) = silhouette(&d, &c, half, n, hit);
            let md = shape_aero(surface.clone());
            let (force, torque) = md.force_and_torque(rho, &wind);
            let want_force = -q * area * d;
            let want_torque = centroid.cross(&want_force);
            let ea = (force.norm() / want_force.norm() - 1.0).abs();
            // The torque's error against the force times the body's size.
            let et = (torque - want_torque).norm() / (want_force.norm() * half);
            eprintln!("{what} {d:?}: area error {ea:.2e}, torque error {et:.2e}");
            worst = (worst.0.max(ea), worst.1.max(et));
            assert!(
                ea < 5e-4 && et < 5e-5,
                "{what} {d:?}: {force:?} {torque:?} vs {want_force:?} {want_torque:?}"
            );
        }
    }
    eprintln!("worst: area {:.2e}, torque {:.2e}", worst.0, worst.1);
}

/// With `body.composite` the shape is written about the whole spacecraft's centre of mass O
/// (docs/conventions.md), and drag acts on it there. A 2 kg particle at (0.4, 0, 0) m from O
/// of a 10 kg spacecraft puts the hub's centre of mass at (−0.1, 0, 0) m from O, so the unit
/// cube's centre is at (0.1, 0, 0) from the hub's. The wind w ŷ (identity attitude, t = 0)
/// takes the +y face (1 m²) at (0.1, 0.5, 0): F = (0, −f, 0), f = q 1 m², and
/// τ = (0.1, 0.5, 0) × F = (0, 0, −0.1 f). A constant-area centre of pressure written about O
/// moves with it.
#[test]
fn with_a_composite_body_the_shape_stays_where_it_was_written() {
    let (_, q) = dynamic_pressure_400km();
    let s = load(
        "name: a
body: {composite: true, mass: 10.0, principal: [5.0, 6.0, 7.0], shape: {box: {size: [1, 1, 1]}}}
orbit: {semi_major_axis_km: 6778.137}
initial: {omega: [0, 0, 0.1]}
duration: 1
effectors:
  - aerodynamic: {drag_coefficient: 2.2, from_shape: true}
  - spring_mass_damper: {mass: 2.0, position: [0.4, 0, 0], direction: [0, 0, 1], stiffness: 10.0, damping: 0.1}
",
    );
    let want = Vector3::new(0.0, 0.0, -0.1 * q);
    close(
        torque_of(&s, &UnitQuaternion::identity()),
        want,
        1e-9,
        "composite",
    );
    // A constant area of 1 m² with its centre of pressure written at O is moved the same
    // way, to (0.1, 0, 0): τ = (0.1, 0, 0) × (0, −f, 0) = (0, 0, −0.1 f).
    let s = load(
        "name: a
body: {composite: true, mass: 10.0, principal: [5.0, 6.0, 7.0]}
orbit: {semi_major_axis_km: 6778.137}
initial: {omega: [0, 0, 0.1]}
duration: 1
effectors:
  - aerodynamic: {drag_coefficient: 2.2, area: 1, center_of_pressure: [0, 0, 0]}
  - spring_mass_damper: {mass: 2.0, position: [0.4, 0, 0], direction: [0, 0, 1], stiffness: 10.0, damping: 0.1}
",
    );
    close(
        torque_of(&s, &UnitQuaternion::identity()),
        want,
        1e-9,
        "composite, constant area",
    );
}

/// The 3U CubeSat of the constant-area test with its shape (0.1 × 0.1 × 0.34 m box, and then
/// a cylinder) centred 2.2 cm off its centre of mass: T − W stays put to 1e-9 of T over one
/// orbit while T itself changes.
#[test]
fn the_energy_balance_holds_with_drag_on_the_shape() {
    for shape in [
        "{box: {size: [0.1, 0.1, 0.34]}}",
        "{cylinder: {radius: 0.06, length: 0.34, axis: [0, 0, 1]}}",
    ] {
        let yaml = format!(
            "name: aero
body: {{principal: [0.035, 0.035, 0.008], shape: {shape}}}
orbit: {{semi_major_axis_km: 6728.137, inclination_deg: 51.6, raan_deg: 40.0}}
initial: {{omega: [0.02, -0.01, 0.03]}}
duration: 5500
integrator: {{method: dop853, rtol: 1.0e-13, atol: 1.0e-16}}
output: {{rate: 0.05}}
effectors:
  - aerodynamic: {{drag_coefficient: 2.2, from_shape: true, shape_center: [0.0, 0.02, 0.01]}}
"
        );
        let s = load(&yaml);
        let (out, rec) = run(&s);
        assert_eq!(out.status, Status::Complete);
        let (worst, spread) = common::balance_drift_and_spread(&rec.samples);
        eprintln!(
            "{shape}: T - W drift {worst:e} of T0, T spread {:e} of T0",
            spread
        );
        assert!(worst < 1e-9, "{shape}: energy balance drift {worst:e}");
        assert!(spread > 1e-3, "{shape}: T spread {:e}", spread);
    }
}

#[test]
fn bad_shape_drag_input_is_refused_with_located_errors() {
    let base = "name: x\nbody: {principal: [1, 2, 3]}\ninitial: {omega: [0, 0, 0.1]}\n\
                duration: 1\norbit: {semi_major_axis_km: 6800}\n";
    let shaped = base.replace(
        "principal: [1, 2, 3]}",
        "principal: [1, 2, 3], shape: {box: {size: [1, 1, 1]}}}",
    );
    let item =
        |rest: &str| format!("effectors:\n  - aerodynamic: {{drag_coefficient: 2.2{rest}}}\n");
    let cases = [
        (
            format!("{base}{}", item(", from_shape: true")),
            "aero.yaml:7:54: field `effectors[0].aerodynamic.from_shape`: drag on the body's facets needs `body.shape`",
        ),
        (
            format!("{base}{}", item("")),
            "aero.yaml:7:5: field `effectors[0].aerodynamic`: expected `area` (m²) and `center_of_pressure` (m, body axes) for a constant projected area, or `from_shape: true`",
        ),
        (
            format!("{shaped}{}", item(", from_shape: false")),
            "field `effectors[0].aerodynamic`: expected `area` (m²) and `center_of_pressure`",
        ),
        (
            format!("{base}{}", item(", area: 1")),
            "aero.yaml:7:5: field `effectors[0].aerodynamic`: missing field `center_of_pressure`",
        ),
        (
            format!("{shaped}{}", item(", from_shape: true, area: 1")),
            "aero.yaml:7:66: field `effectors[0].aerodynamic.area`: with `from_shape: true` the projected area follows from `body.shape`",
        ),
        (
            format!(
                "{shaped}{}",
                item(", from_shape: true, center_of_pressure: [0, 0, 0]")
            ),
            "field `effectors[0].aerodynamic.center_of_pressure`: with `from_shape: true` the centre of pressure follows",
        ),
        (
            format!(
                "{shaped}{}",
                item(", area: 1, center_of_pressure: [0, 0, 0], shape_center: [0, 0, 0]")
            ),
            "field `effectors[0].aerodynamic.shape_center`: `shape_center` places `body.shape` for `from_shape: true`",
        ),
        (
            format!(
                "{shaped}{}",
                item(", from_shape: true, shape_center: [.nan, 0, 0]")
            ),
            "field `effectors[0].aerodynamic.shape_center`: expected three finite numbers within 1e3 m",
        ),
        (
            format!(
                "{shaped}{}",
                item(", from_shape: true, shape_center: [0, 1.0e3, 1]")
            ),
            "field `effectors[0].aerodynamic.shape_center`: expected three finite numbers within 1e3 m",
        ),
        (
            format!("{shaped}{}", item(", from_shape: yes please")),
            "effectors[0].aerodynamic.from_shape",
        ),
    ];
    for (yaml, expect) in cases {
        let e = parse(Path::new("aero.yaml"), yaml.clone(), &Overrides::default())
            .expect_err(&yaml)
            .to_string();
        assert!(e.contains(expect), "expected {expect:?} in {e}\n{yaml}");
    }
    // The shape model is accepted with and without `shape_center`, for both shapes.
    for yaml in [
        format!("{shaped}{}", item(", from_shape: true")),
        format!(
            "{shaped}{}",
            item(", from_shape: true, shape_center: [0.01, 0, 0]")
        ),
        format!(
            "{}{}",
            base.replace(
                "principal: [1, 2, 3]}",
                "principal: [1, 2, 3], shape: {cylinder: {radius: 0.5, length: 2}}}"
            ),
            item(", from_shape: true")
        ),
    ] {
        let s = load(&yaml);
        assert_eq!(s.spacecraft.effectors()[0].kind(), "aerodynamic");
    }
}
