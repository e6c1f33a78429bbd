//! `polhode linearize` about the LVLH equilibrium of a gravity-gradient spacecraft in a
//! circular orbit, against what it did not produce:
//!
//! - the closed forms of the linearised equations (Hughes, *Spacecraft Attitude Dynamics*,
//!   1986, ch. 9; derived again in docs/cli.md), evaluated here from the moments: pitch
//!   λ² = −3n²k2, roll–yaw s⁴ + n²(1 + 3k1 + k1k3) s² + 4n⁴k1k3 = 0, with
//!   k1 = (I_p − I_y)/I_r, k2 = (I_r − I_y)/I_p, k3 = (I_p − I_r)/I_y (r, p, y: the moments
//!   about roll o1, pitch o2 and yaw o3), over inertia sets in the Lagrange region, the
//!   DeBra–Delp region, and three unstable arrangements;
//! - the roll–yaw frequencies measured in nonlinear runs started in one pure mode (the
//!   mode shape from the closed form, written here);
//! - the direction energy dissipation pushes each region (stabilises the Lagrange
//!   equilibrium, destabilises the DeBra–Delp one);
//! - located refusals of what has no fixed equilibrium.

mod common;

use common::{run, scenario};
use nalgebra::{Complex, UnitQuaternion, Vector3};
use polhode::linearize::lvlh::{LvlhLinearization, linearize_lvlh};
use polhode::model::Observation;
use polhode::sim::Status;
use std::process::Command;

type C64 = Complex<f64>;

/// Earth's μ (m³/s², WGS-84).
const MU: f64 = 3.986_004_418e14;

fn mean_motion(a_km: f64) -> f64 {
    (MU / (a_km * 1e3).powi(3)).sqrt()
}

/// A rigid body with principal moments `i` (body axes) with the gravity gradient in a
/// circular orbit of radius `a_km`, inclined and turned (`orbit_extra` adds keys), started at
/// `attitude` (w, x, y, z) and `omega` relative to LVLH; `effectors` adds list items.
fn scene(
    i: [f64; 3],
    a_km: f64,
    orbit_extra: &str,
    attitude: [f64; 4],
    omega: [f64; 3],
    duration: f64,
    effectors: &str,
) -> String {
    format!(
        "name: gg\nbody: {{principal: [{}, {}, {}]}}\n\
         orbit: {{semi_major_axis_km: {a_km}{orbit_extra}}}\n\
         initial:\n  frame: lvlh\n  omega: [{:e}, {:e}, {:e}]\n  \
         attitude: {{w: {:e}, x: {:e}, y: {:e}, z: {:e}}}\n\
         duration: {duration}\n\
         integrator: {{method: dop853, rtol: 1.0e-12, atol: 1.0e-16}}\n\
         output: {{rate: 0.2}}\n\
         effectors:\n  - gravity_gradient: {{}}\n{effectors}",
        i[0],
        i[1],
        i[2],
        omega[0],
        omega[1],
        omega[2],
        attitude[0],
        attitude[1],
        attitude[2],
        attitude[3],
    )
}

/// An inclined, turned orbit so that the LVLH axes are nowhere near the ECI axes.
const TURNED: &str = ", inclination_deg: 63.4, raan_deg: 40.0, true_anomaly_deg: 25.0";

/// The LVLH linearisation of a loaded scenario (its spacecraft, orbit and initial attitude).
fn linearize_scenario(s: &polhode::scenario::Scenario) -> Result<LvlhLinearization, String> {
    let orbit = s.orbit.as_deref().ok_or("no orbit")?;
    linearize_lvlh(&s.spacecraft, orbit, &s.attitude0)
}

fn linearize_yaml(yaml: &str) -> Result<LvlhLinearization, String> {
    linearize_scenario(&scenario(yaml))
}

/// The six eigenvalues of the closed forms for moments (I_roll, I_pitch, I_yaw) at rate n:
/// (eigenvalue, role).
fn closed_form_eigenvalues(m: [f64; 3], n: f64) -> Vec<(C64, &'static str)> {
    let [ir, ip, iy] = m;
    let (k1, k2, k3) = ((ip - iy) / ir, (ir - iy) / ip, (ip - ir) / iy);
    let mut out = Vec::new();
    let pitch = C64::new(-3.0 * n * n * k2, 0.0).sqrt();
    out.push((pitch, "pitch"));
    out.push((-pitch, "pitch"));
    // x = s²: x² + b n² x + 4 n⁴ k1 k3 = 0.
    let b = n * n * (1.0 + 3.0 * k1 + k1 * k3);
    let c = 4.0 * n.powi(4) * k1 * k3;
    let root = C64::new(b * b - 4.0 * c, 0.0).sqrt();
    for x in [(-b + root) / 2.0, (-b - root) / 2.0] {
        let s = x.sqrt();
        out.push((s, "roll_yaw"));
        out.push((-s, "roll_yaw"));
    }
    out
}

/// Every closed-form eigenvalue has a computed one of the same role within `tol` · n, and the
/// computed ones are matched one to one.
fn assert_matches_closed_form(lin: &LvlhLinearization, moments: [f64; 3], tol: f64, case: &str) {
    let n = lin.orbit_rate;
    let mut unused: Vec<usize> = (0..lin.modes.len()).collect();
    for (want, role) in closed_form_eigenvalues(moments, n) {
        let (pos, err) = unused
            .iter()
            .enumerate()
            .filter(|(_, k)| lin.modes[**k].role == role)
            .map(|(p, &k)| {
                (
                    p,
                    (C64::new(lin.modes[k].re, lin.modes[k].im) - want).norm(),
                )
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or_else(|| panic!("{case}: no {role} mode left for {want}: {lin:#?}"));
        eprintln!("{case}: {role} {want:.6e}: |Δλ|/n = {:.2e}", err / n);
        assert!(
            err < tol * n,
            "{case}: {role} eigenvalue {want} off by {:.3e} n: {lin:#?}",
            err / n
        );
        unused.remove(pos);
    }
    assert!(unused.is_empty(), "{case}: extra modes {unused:?}");
}

/// Pitch and roll–yaw eigenvalues against the closed forms, with the verdict and the region,
/// over the inertia plane: two Lagrange bodies, a DeBra–Delp body, one with the DeBra–Delp
/// ordering outside its region, one with k1k3 < 0, and one whose pitch diverges.
#[test]
fn eigenvalues_match_the_closed_forms_over_the_inertia_plane() {
    let a_km = 7000.0;
    let n = mean_motion(a_km);
    // (I_x, I_y, I_z) with x on roll, y on pitch, z on yaw; expected verdict; region text.
    let cases: [([f64; 3], &str, &str); 6] = [
        // The shipped smallsat: k1 = 0.9895, k3 = 0.875.
        (
            [9.5, 10.2, 0.8],
            "marginally stable (oscillatory)",
            "Lagrange region",
        ),
        (
            [6.0, 8.0, 3.0],
            "marginally stable (oscillatory)",
            "Lagrange region",
        ),
        // k1 = −0.05, k3 = −0.909: 1 + 3k1 + k1k3 = 0.895 > 4√(k1k3) = 0.853.
        (
            [20.0, 10.0, 11.0],
            "marginally stable (oscillatory)",
            "DeBra–Delp region",
        ),
        // k1 = −0.4, k3 = −0.75: 0.1 < 4√0.3 = 2.19, complex s².
        (
            [10.0, 4.0, 8.0],
            "unstable",
            "outside the DeBra–Delp region",
        ),
        // k1 = 0.5, k3 = −1/3.
        ([8.0, 7.0, 3.0], "unstable", "k1k3 = -0.166667 ≤ 0"),
        // I_roll < I_yaw: pitch diverges; roll–yaw alone would be stable (k1, k3 > 0).
        ([6.0, 8.0, 7.0], "unstable", "pitch diverges"),
    ];
    for (moments, verdict, region) in cases {
        let yaml = scene(
            moments,
            a_km,
            TURNED,
            [1.0, 0.0, 0.0, 0.0],
            [0.0; 3],
            1.0,
            "",
        );
        let lin = linearize_yaml(&yaml).unwrap();
        let case = format!("I = {moments:?}");
        assert!((lin.orbit_rate - n).abs() < 1e-15 * n, "{case}");
        assert_eq!(lin.moments, moments, "{case}");
        assert_eq!(lin.verdict, verdict, "{case}: {lin:#?}");
        assert!(
            lin.closed_form.region.contains(region),
            "{case}: {}",
            lin.closed_form.region
        );
        assert!(lin.equilibrium_residual < 1e-12, "{case}");
        assert_matches_closed_form(&lin, moments, 1e-9, &case);
        // The stable cases are purely oscillatory: no real part above rounding.
        if verdict.starts_with("marginally") {
            for m in &lin.modes {
                assert!(m.re.abs() < 1e-9 * n, "{case}: {m:?}");
                assert_eq!(m.kind, "oscillating");
            }
        }
    }
}

/// The equilibrium follows the initial attitude: a body turned 93° about pitch is linearised
/// about the attitude turned 90°, with body z on roll and body x on yaw, so the moments
/// about roll, pitch, yaw are (I_z, I_y, I_x) and the verdict is theirs (here I_roll < I_yaw:
/// pitch diverges).
#[test]
fn the_nearest_equilibrium_to_the_initial_attitude_is_taken() {
    let moments = [6.0, 8.0, 3.0];
    let half = 93f64.to_radians() / 2.0;
    let yaml = scene(
        moments,
        7000.0,
        TURNED,
        [half.cos(), 0.0, half.sin(), 0.0],
        [0.0; 3],
        1.0,
        "",
    );
    let lin = linearize_yaml(&yaml).unwrap();
    assert!((lin.initial_offset_deg - 3.0).abs() < 1e-9, "{lin:#?}");
    let permuted = [3.0, 8.0, 6.0];
    for (got, want) in lin.moments.iter().zip(permuted) {
        assert!((got - want).abs() < 1e-12, "{lin:#?}");
    }
    // A +90° turn about y takes body z to +x (roll) and body x to −z (yaw).
    let axes = lin.body_axes_on_lvlh;
    let close = |a: [f64; 3], b: [f64; 3]| (0..3).all(|k| (a[k] - b[k]).abs() < 1e-12);
    assert!(close(axes[0], [0.0, 0.0, 1.0]), "{axes:?}");
    assert!(close(axes[1], [0.0, 1.0, 0.0]), "{axes:?}");
    assert!(close(axes[2], [-1.0, 0.0, 0.0]), "{axes:?}");
    assert_eq!(lin.verdict, "unstable");
    assert!(lin.closed_form.region.contains("pitch diverges"));
    assert_matches_closed_form(&lin, permuted, 1e-9, "turned 93° about pitch");
}

/// A full inertia tensor whose principal axes are turned 0.3 rad about (1, 2, 3) from the body
/// axes, I = R diag(6, 8, 3) Rᵀ, started with the body axes on LVLH: the equilibrium has the
/// principal axes R e_k on roll, pitch, yaw (0.3 rad = 17.19° away), moments (6, 8, 3), and
/// the closed-form eigenvalues of those moments.
#[test]
fn a_full_inertia_tensor_is_linearised_about_its_principal_axes() {
    let axis = nalgebra::Unit::new_normalize(Vector3::new(1.0, 2.0, 3.0));
    let r = nalgebra::Rotation3::from_axis_angle(&axis, 0.3);
    let inertia = r.matrix()
        * nalgebra::Matrix3::from_diagonal(&Vector3::new(6.0, 8.0, 3.0))
        * r.matrix().transpose();
    let rows: Vec<String> = (0..3)
        .map(|i| {
            format!(
                "[{:e}, {:e}, {:e}]",
                inertia[(i, 0)],
                inertia[(i, 1)],
                inertia[(i, 2)]
            )
        })
        .collect();
    let yaml = scene(
        [1.0, 1.0, 1.0],
        7000.0,
        TURNED,
        [1.0, 0.0, 0.0, 0.0],
        [0.0; 3],
        1.0,
        "",
    )
    .replace(
        "body: {principal: [1, 1, 1]}",
        &format!("body: {{inertia: [{}]}}", rows.join(", ")),
    );
    assert!(yaml.contains("inertia:"), "{yaml}");
    let lin = linearize_yaml(&yaml).unwrap();
    assert!(
        (lin.initial_offset_deg - 0.3f64.to_degrees()).abs() < 1e-9,
        "{lin:#?}"
    );
    for (k, want) in [6.0, 8.0, 3.0].into_iter().enumerate() {
        assert!((lin.moments[k] - want).abs() < 1e-12, "{lin:#?}");
        let principal = r * Vector3::ith(k, 1.0);
        let got = Vector3::from(lin.body_axes_on_lvlh[k]);
        assert!(
            (got.dot(&principal).abs() - 1.0).abs() < 1e-12,
            "axis {k}: {got:?} vs {principal:?}"
        );
    }
    assert_matches_closed_form(&lin, [6.0, 8.0, 3.0], 1e-9, "full tensor");
}

/// The LVLH frame of a circular equatorial orbit at t, built here from its definition: the
/// orbit starts on ECI x and moves toward +y, so r̂ = (cos nt, sin nt, 0), o3 = −r̂,
/// o2 = −ẑ, o1 = o2 × o3.
fn lvlh_to_eci(n: f64, t: f64) -> UnitQuaternion<f64> {
    let nt = n * t;
    let o3 = -Vector3::new(nt.cos(), nt.sin(), 0.0);
    let o2 = -Vector3::z();
    let o1 = o2.cross(&o3);
    let m = nalgebra::Matrix3::from_columns(&[o1, o2, o3]);
    UnitQuaternion::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(m))
}

/// Times of the upward zero crossings of a sampled signal, by linear interpolation.
fn upward_crossings(series: &[(f64, f64)]) -> Vec<f64> {
    series
        .windows(2)
        .filter(|w| w[0].1 < 0.0 && w[1].1 >= 0.0)
        .map(|w| w[0].0 + (w[1].0 - w[0].0) * (-w[0].1) / (w[1].1 - w[0].1))
        .collect()
}

/// Small roll–yaw librations started in one pure mode oscillate at its frequency. With
/// φ = A cos ωt, the yaw equation's partner is ψ = c A sin ωt, c = (4n²k1 − ω²)/(ω n (1 − k1))
/// (from φ̈ + 4n²k1 φ − n(1 − k1) ψ̇ = 0), so the run starts at φ = A, ψ = 0, ψ̇ = c A ω. The
/// frequency is measured from the zero crossings of the larger of φ and ψ (relative attitude
/// against the LVLH frame built in the test) and compared with the closed form and with
/// `linearize` on the same scenario.
#[test]
fn nonlinear_runs_in_one_roll_yaw_mode_oscillate_at_its_frequency() {
    let moments: [f64; 3] = [6.0, 8.0, 3.0];
    let a_km = 6978.137;
    let n = mean_motion(a_km);
    let [ir, ip, iy] = moments;
    let (k1, k3) = ((ip - iy) / ir, (ip - ir) / iy);
    let b = 1.0 + 3.0 * k1 + k1 * k3;
    let root = (b * b - 16.0 * k1 * k3).sqrt();
    for x in [(b + root) / 2.0, (b - root) / 2.0] {
        let omega = n * x.sqrt();
        let c = (4.0 * n * n * k1 - omega * omega) / (omega * n * (1.0 - k1));
        // The larger of φ and ψ at 1e-3 rad.
        let amp = 1e-3 / c.abs().max(1.0);
        let period = std::f64::consts::TAU / omega;
        let yaml = scene(
            moments,
            a_km,
            ", inclination_deg: 0.0",
            [(amp / 2.0).cos(), (amp / 2.0).sin(), 0.0, 0.0],
            [0.0, 0.0, c * amp * omega],
            3.2 * period,
            "",
        );
        let s = scenario(&yaml);
        let lin = linearize_scenario(&s).unwrap();
        let predicted = lin
            .modes
            .iter()
            .filter(|m| m.role == "roll_yaw" && m.im > 0.0)
            .map(|m| m.im)
            .min_by(|a, b| (a - omega).abs().total_cmp(&(b - omega).abs()))
            .unwrap();
        assert!((predicted - omega).abs() < 1e-8 * omega);
        let (out, rec) = run(&s);
        assert_eq!(out.status, Status::Complete);
        let relative = |o: &Observation| lvlh_to_eci(n, o.t).inverse() * o.attitude;
        let yaw_dominant = c.abs() > 1.0;
        let series: Vec<(f64, f64)> = rec
            .samples
            .iter()
            .map(|o| {
                let q = relative(o);
                let sign = q.w.signum();
                let v = if yaw_dominant { q.k } else { q.i };
                (o.t, 2.0 * sign * v)
            })
            .collect();
        let crossings = upward_crossings(&series);
        assert!(crossings.len() >= 3, "{crossings:?}");
        let measured = std::f64::consts::TAU * (crossings.len() - 1) as f64
            / (crossings[crossings.len() - 1] - crossings[0]);
        // Amplitude 1e-3 rad shifts the frequency by ~1e-6 relative (measured: 1.5e-7 and
        // 2.0e-7); the pure mode keeps the other one out (a 1% admixture of the other mode
        // would move the crossings by ~1e-3 of a period).
        let rel = (measured - omega).abs() / omega;
        eprintln!(
            "roll–yaw mode ω = {:.6} n ({} dominant, {} crossings): measured {measured:.9e}, \
             closed form {omega:.9e}, linearize {predicted:.9e} rad/s (rel {rel:.2e})",
            omega / n,
            if yaw_dominant { "yaw" } else { "roll" },
            crossings.len()
        );
        assert!(
            rel < 2e-6,
            "ω = {:.6} n: measured {measured:.9e}, closed form {omega:.9e}, linearize \
             {predicted:.9e} (rel {rel:.2e})",
            omega / n
        );
        // The mode is pure: the other angle stays at its c-ratio, pitch stays put.
        let pitch = rec
            .samples
            .iter()
            .map(|o| relative(o).j.abs())
            .fold(0.0, f64::max);
        assert!(pitch < 1e-6, "pitch reached {pitch}");
    }
}

/// Energy dissipation (an energy sink draining the body's rates across its momentum) damps
/// roll–yaw in the Lagrange region, where the equilibrium is a minimum of the Jacobi integral,
/// and destabilises it in the DeBra–Delp region, where it is not (Hughes 1986, ch. 9). Pitch
/// moves the rate along the momentum, so the sink leaves it undamped.
#[test]
fn dissipation_damps_lagrange_and_destabilises_debra_delp() {
    let sink = "  - energy_sink: {coefficient: 0.002}\n";
    for (moments, lagrange) in [([6.0, 8.0, 3.0], true), ([20.0, 10.0, 11.0], false)] {
        let yaml = scene(
            moments,
            7000.0,
            TURNED,
            [1.0, 0.0, 0.0, 0.0],
            [0.0; 3],
            1.0,
            sink,
        );
        let lin = linearize_yaml(&yaml).unwrap();
        let case = format!("I = {moments:?}: {lin:#?}");
        let roll_yaw: Vec<_> = lin.modes.iter().filter(|m| m.role == "roll_yaw").collect();
        assert_eq!(roll_yaw.len(), 4, "{case}");
        if lagrange {
            assert!(roll_yaw.iter().all(|m| m.kind == "decaying"), "{case}");
            assert_eq!(lin.verdict, "marginally stable (oscillatory)", "{case}");
        } else {
            assert!(roll_yaw.iter().any(|m| m.kind == "growing"), "{case}");
            assert_eq!(lin.verdict, "unstable", "{case}");
        }
        for m in lin.modes.iter().filter(|m| m.role == "pitch") {
            assert!(m.re.abs() < 1e-9 * lin.orbit_rate, "{case}");
        }
    }
}

/// A pitch libration damper: a spring–mass–dashpot (m = 0.1 kg on a 13 kg hub, reduced mass
/// μ = mM/(m + M)) at d = 1 m along yaw (nadir), sliding along roll, with the gravity gradient
/// on its mass too. Derived by hand from the two-body Lagrangian in the rotating frame
/// (kinetic ½I_h2 w² + ½μ[(ẋ + wd)² + w²x²], w = θ̇ − n; hub potential (3n²/2) r̂ᵀI_h r̂;
/// tidal −½μ n²(3(r̂·p)² − |p|²) for p = (x, 0, d), r̂ = (sin θ, 0, −cos θ); spring ½kx²,
/// dashpot c), with I_1, I_2, I_3 the composite moments (I_h + μd² about roll and pitch):
///
/// ```text
/// I_2 θ̈ + μ d ẍ + 3n²(I_1 − I_3) θ + 3μn² d x = 0
/// μ ẍ + μ d θ̈ + c ẋ + k x + 3μn² d θ = 0      (centrifugal and tidal μn²x cancel)
/// ```
///
/// Roll–yaw does not move the mass along roll to first order, so it keeps the rigid closed
/// form with the composite moments.
#[test]
fn a_pitch_damper_matches_the_hand_derived_equations() {
    let (hub, m_hub, m, d, k, c) = ([9.5, 10.2, 0.8], 13.0, 0.1, 1.0, 3e-7, 5e-5);
    let mu = m * m_hub / (m + m_hub);
    let damper = format!(
        "  - spring_mass_damper: {{name: d, mass: {m}, position: [0.0, 0.0, {d}], direction: \
         [1, 0, 0], stiffness: {k:e}, damping: {c:e}}}\n"
    );
    let yaml = scene(
        hub,
        7000.0,
        TURNED,
        [1.0, 0.0, 0.0, 0.0],
        [0.0; 3],
        1.0,
        &damper,
    )
    .replace(
        "body: {principal:",
        &format!("body: {{mass: {m_hub}, principal:"),
    );
    let lin = linearize_yaml(&yaml).unwrap();
    let n = lin.orbit_rate;
    let composite = [hub[0] + mu * d * d, hub[1] + mu * d * d, hub[2]];
    for (got, want) in lin.moments.iter().zip(composite) {
        assert!((got - want).abs() < 1e-12 * want, "{lin:#?}");
    }
    assert!(lin.equilibrium_residual < 1e-12, "{lin:#?}");
    // Roll–yaw: the rigid closed form of the composite moments.
    let rigid: Vec<C64> = closed_form_eigenvalues(composite, n)
        .into_iter()
        .filter(|(_, role)| *role == "roll_yaw")
        .map(|(z, _)| z)
        .collect();
    // Pitch and damper: M s² + C s + K, as a first-order 4×4 in (θ, x, θ̇, ẋ).
    let (i1, i2, i3) = (composite[0], composite[1], composite[2]);
    let mass = nalgebra::Matrix2::new(i2, mu * d, mu * d, mu);
    let stiff = nalgebra::Matrix2::new(
        3.0 * n * n * (i1 - i3),
        3.0 * mu * n * n * d,
        3.0 * mu * n * n * d,
        k,
    );
    let damp = nalgebra::Matrix2::new(0.0, 0.0, 0.0, c);
    let inv = mass.try_inverse().unwrap();
    let mut a = nalgebra::Matrix4::<f64>::zeros();
    a.fixed_view_mut::<2, 2>(0, 2)
        .copy_from(&nalgebra::Matrix2::identity());
    a.fixed_view_mut::<2, 2>(2, 0).copy_from(&(-inv * stiff));
    a.fixed_view_mut::<2, 2>(2, 2).copy_from(&(-inv * damp));
    let coupled: Vec<C64> = a.complex_eigenvalues().iter().copied().collect();
    let mut unused: Vec<usize> = (0..lin.modes.len()).collect();
    for (want, roles) in rigid
        .iter()
        .map(|z| (*z, &["roll_yaw"][..]))
        .chain(coupled.iter().map(|z| (*z, &["pitch", "effector"][..])))
    {
        let (pos, err) = unused
            .iter()
            .enumerate()
            .filter(|(_, k)| roles.contains(&lin.modes[**k].role.as_str()))
            .map(|(p, &k)| {
                (
                    p,
                    (C64::new(lin.modes[k].re, lin.modes[k].im) - want).norm(),
                )
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap();
        eprintln!(
            "pitch damper: {roles:?} {want:.6e}: |Δλ|/n = {:.2e}",
            err / n
        );
        assert!(err < 1e-8 * n, "{want}: off by {:.3e} n: {lin:#?}", err / n);
        unused.remove(pos);
    }
    assert!(unused.is_empty());
    // The damper drains the pitch libration: every pitch/damper mode decays.
    assert!(coupled.iter().all(|z| z.re < -1e-6 * n), "{coupled:?}");
    assert_eq!(lin.verdict, "marginally stable (oscillatory)");
}

/// What has no fixed LVLH equilibrium, or is not linearised here, is refused with the reason.
#[test]
fn refusals_name_the_reason() {
    let i = [6.0, 8.0, 3.0];
    let id = [1.0, 0.0, 0.0, 0.0];
    for (orbit_extra, effectors, expect) in [
        (", eccentricity: 0.01", "", "eccentricity is 0.01"),
        (", eccentricity: 0.01", "", "Floquet"),
        (", j2_secular: true", "", "j2_secular"),
        (
            "",
            "  - magnetic_dipole: {moment: [0.1, 0.0, 0.0]}\n",
            "varies around the orbit",
        ),
        (
            "",
            "  - rayleigh: {gamma_diagonal: [0.01, 0.01, 0.01]}\n",
            "not an equilibrium with it",
        ),
        (
            "",
            "  - wheel_damper: {name: w, inertia: 0.1, axis: [0, 1, 0], damping: 0.0, \
             initial_rate: 5.0}\n",
            "starts away from rest",
        ),
    ] {
        let yaml = scene(i, 7000.0, orbit_extra, id, [0.0; 3], 1.0, effectors);
        let e = linearize_yaml(&yaml).unwrap_err();
        assert!(e.contains(expect), "{expect}: {e}");
    }
}

/// A frictionless wheel at rest on the pitch axis: its conserved absolute momentum is one zero
/// eigenvalue (`rotor`), not a degeneracy; pitch then librates with the wheel turning with
/// the hub in inertial space removed: I_p ← I_p − I_W in the pitch closed form.
#[test]
fn a_free_pitch_wheel_is_a_rotor_mode() {
    let (i, iw) = ([6.0, 8.0, 3.0], 0.5);
    let wheel =
        format!("  - wheel_damper: {{name: w, inertia: {iw}, axis: [0, 1, 0], damping: 0.0}}\n");
    let yaml = scene(
        i,
        7000.0,
        TURNED,
        [1.0, 0.0, 0.0, 0.0],
        [0.0; 3],
        1.0,
        &wheel,
    );
    let lin = linearize_yaml(&yaml).unwrap();
    let n = lin.orbit_rate;
    assert_eq!(lin.verdict, "marginally stable (oscillatory)", "{lin:#?}");
    assert_eq!(lin.modes.iter().filter(|m| m.kind == "rotor").count(), 1);
    // The wheel keeps its inertial rate: the hub alone (I_p − I_W) carries the pitch
    // restoring torque 3n²(I_r − I_y) θ, which acts on the whole body's inertia difference.
    let want = n * (3.0 * (i[0] - i[2]) / (i[1] - iw)).sqrt();
    let pitch = lin
        .modes
        .iter()
        .filter(|m| m.role == "pitch" && m.im > 0.0)
        .map(|m| m.im)
        .next()
        .unwrap();
    assert!(
        (pitch - want).abs() < 1e-8 * want,
        "{pitch} vs {want}: {lin:#?}"
    );
}

fn polhode() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_polhode"));
    c.current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}

/// The command line on the shipped smallsat: the modes with their ω/n and periods, the closed
/// forms and the region; the JSON carries the same; an eccentric orbit exits 2.
#[test]
fn cli_reports_the_smallsat_modes() {
    let out = polhode()
        .args(["linearize", "scenarios/gravity-gradient-smallsat.yaml"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for want in [
        "LVLH equilibrium in a circular orbit",
        "I_roll 9.500000, I_pitch 10.200000, I_yaw 0.800000 kg m²",
        "pitch     oscillating   1.599632",
        "roll_yaw  oscillating   1.989870",
        "roll_yaw  oscillating   0.935215",
        "verdict: marginally stable (oscillatory)",
        "Lagrange region",
    ] {
        assert!(text.contains(want), "{want}:\n{text}");
    }
    let out = polhode()
        .args([
            "linearize",
            "scenarios/gravity-gradient-smallsat.yaml",
            "--json",
            "-",
        ])
        .output()
        .unwrap();
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["modes"].as_array().unwrap().len(), 6);
    assert_eq!(json["closed_form"]["pitch_stable"], true);
    assert_eq!(json["closed_form"]["roll_yaw_stable"], true);
    assert_eq!(json["state_names"][1], "pitch");

    let dir = common::Scratch::new("polhode-lvlh", "eccentric");
    let path = dir.join("eccentric.yaml");
    std::fs::write(
        &path,
        scene(
            [6.0, 8.0, 3.0],
            7000.0,
            ", eccentricity: 0.05",
            [1.0, 0.0, 0.0, 0.0],
            [0.0; 3],
            1.0,
            "",
        ),
    )
    .unwrap();
    let out = polhode()
        .args(["linearize", path.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("eccentric.yaml"), "{err}");
    assert!(err.contains("circular orbits only"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
