//! The analytic orbit (`polhode::orbit`) against independent numerical integrations of the
//! equations of motion, the LVLH frame against finite differences, and element validation.
//!
//! `cargo test --release --locked --test orbit -- --nocapture` prints the measured numbers
//! quoted in `docs/environment.md` ("Orbit").

use nalgebra::Vector3;
use polhode::integrate::{Dop853, OdeSystem, Stepper, Tolerances};
use polhode::orbit::{CentralBody, Elements, Orbit};
use std::f64::consts::{PI, TAU};

const EARTH: CentralBody = CentralBody::EARTH;

/// `r̈ = −μ r/|r|³`, plus the J2 acceleration if asked (Vallado, *Fundamentals of
/// Astrodynamics and Applications*, 4th ed., §8.7; Curtis, *Orbital Mechanics for
/// Engineering Students*, §10.7):
/// `a = −(3/2) J2 μ R²/r⁵ (x(1 − 5z²/r²), y(1 − 5z²/r²), z(3 − 5z²/r²))`.
struct TwoBody {
    j2: bool,
}

impl OdeSystem for TwoBody {
    fn dim(&self) -> usize {
        6
    }
    fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
        let (x, yy, z) = (y[0], y[1], y[2]);
        let r2 = x * x + yy * yy + z * z;
        let r = r2.sqrt();
        let k = -EARTH.mu / (r2 * r);
        dy[..3].copy_from_slice(&y[3..]);
        dy[3] = k * x;
        dy[4] = k * yy;
        dy[5] = k * z;
        if self.j2 {
            let c = -1.5 * EARTH.j2 * EARTH.mu * EARTH.radius * EARTH.radius / (r2 * r2 * r);
            let s = 5.0 * z * z / r2;
            dy[3] += c * x * (1.0 - s);
            dy[4] += c * yy * (1.0 - s);
            dy[5] += c * z * (3.0 - s);
        }
    }
}

/// Integrates from the orbit's state at t = 0 and returns the states at `times`.
fn integrate(orbit: &Orbit, j2: bool, rtol: f64, times: &[f64]) -> Vec<[f64; 6]> {
    let (r0, v0) = orbit.state(0.0);
    let y0 = [r0.x, r0.y, r0.z, v0.x, v0.y, v0.z];
    // atol far below rtol·|y| for both positions (m) and velocities (m/s), so that rtol
    // alone sets the accuracy.
    let tol = Tolerances { rtol, atol: 1e-12 };
    let mut s = Dop853::new(0.0, &y0, tol, f64::INFINITY, None).with_dense_output(false);
    let sys = TwoBody { j2 };
    let mut out = Vec::with_capacity(times.len());
    for &t in times {
        while s.t() < t {
            s.step(&sys, t).expect("integration step");
        }
        out.push(s.y().try_into().unwrap());
    }
    out
}

fn split(y: &[f64; 6]) -> (Vector3<f64>, Vector3<f64>) {
    (
        Vector3::new(y[0], y[1], y[2]),
        Vector3::new(y[3], y[4], y[5]),
    )
}

fn orbit(a: f64, e: f64, j2: bool) -> Orbit {
    Orbit::new(
        EARTH,
        Elements::new(a, e, 51.6_f64.to_radians(), 0.7, 2.1, 0.3),
        j2,
    )
    .unwrap()
}

/// The three test orbits: LEO circular, LEO e = 0.1, and a Molniya-like e = 0.7 (perigee
/// 1602 km altitude).
const CASES: [(f64, f64); 3] = [(7.0e6, 0.0), (7.5e6, 0.1), (2.66e7, 0.7)];

#[test]
fn two_body_matches_numerical_integration_over_100_orbits() {
    println!(
        "  e     a (km)   max |Δr|, |Δv| analytic − DOP853(1e-13)   \
         max |Δr|, |Δv| DOP853 1e-13 − 1e-14   energy drift   |h| drift   \
         max |Δr| analytic − DOP853(1e-14)"
    );
    for (a, e) in CASES {
        let o = orbit(a, e, false);
        let times: Vec<f64> = (1..=1000).map(|k| o.period() * k as f64 / 10.0).collect();
        let loose = integrate(&o, false, 1e-13, &times);
        let tight = integrate(&o, false, 1e-14, &times);
        let (r0, v0) = o.state(0.0);
        let energy =
            |r: &Vector3<f64>, v: &Vector3<f64>| 0.5 * v.norm_squared() - EARTH.mu / r.norm();
        let (e0, h0) = (energy(&r0, &v0), r0.cross(&v0).norm());
        let (mut d_analytic, mut d_integrator, mut de, mut dh) =
            (0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64);
        let (mut dv_analytic, mut dv_integrator, mut d_tight) = (0.0_f64, 0.0_f64, 0.0_f64);
        for (k, &t) in times.iter().enumerate() {
            let (r, v) = o.state(t);
            let (rn, vn) = split(&loose[k]);
            let (rt, _) = split(&tight[k]);
            d_analytic = d_analytic.max((r - rn).norm());
            d_integrator = d_integrator.max((rt - rn).norm());
            d_tight = d_tight.max((r - rt).norm());
            de = de.max(((energy(&rn, &vn) - e0) / e0).abs());
            dh = dh.max(((rn.cross(&vn).norm() - h0) / h0).abs());
            let (_, vt) = split(&tight[k]);
            dv_analytic = dv_analytic.max((v - vn).norm());
            dv_integrator = dv_integrator.max((vt - vn).norm());
        }
        println!(
            "  {e:<4}  {:>6.0}   {d_analytic:>9.3e} m  {dv_analytic:>9.3e} m/s     \
             {d_integrator:>9.3e} m  {dv_integrator:>9.3e} m/s     {de:>9.2e}    {dh:>9.2e}    \
             {d_tight:>9.3e} m",
            a / 1e3
        );
        // The analytic orbit is exact up to rounding (a few ulp of M = n t: ~1e-13 rad after
        // 100 orbits, i.e. ~1e-6 m), so its distance from the rtol = 1e-13 run is that run's
        // own error, which the rtol = 1e-14 run estimates: allow a factor 2 on that estimate
        // plus 1e-5 m of rounding.
        assert!(
            d_analytic <= 2.0 * d_integrator + 1e-5,
            "e = {e}: analytic − numerical {d_analytic:e} m, integrator error {d_integrator:e} m"
        );
        assert!(
            dv_analytic <= 2.0 * dv_integrator + 1e-8,
            "e = {e}: analytic − numerical {dv_analytic:e} m/s, integrator error {dv_integrator:e} m/s"
        );
    }
}

/// Osculating Ω, ω and M from a state (Vallado, 4th ed., Algorithm 9 RV2COE).
fn osculating(r: &Vector3<f64>, v: &Vector3<f64>) -> (f64, f64, f64) {
    let mu = EARTH.mu;
    let h = r.cross(v);
    let node = Vector3::z().cross(&h);
    let ev = (r * (v.norm_squared() - mu / r.norm()) - v * r.dot(v)) / mu;
    let raan = node.y.atan2(node.x);
    let e = ev.norm();
    // ω: angle from the node to the eccentricity vector, positive about h.
    let argp = (node.cross(&ev).dot(&h) / h.norm()).atan2(node.dot(&ev));
    // ν, then M.
    let nu = (ev.cross(r).dot(&h) / h.norm()).atan2(ev.dot(r));
    let ea = ((1.0 - e * e).sqrt() * nu.sin()).atan2(e + nu.cos());
    (raan, argp, ea - e * ea.sin())
}

/// Least-squares slope of unwrapped angles against time.
fn slope(times: &[f64], angles: &[f64]) -> f64 {
    let mut unwrapped = Vec::with_capacity(angles.len());
    let mut offset = 0.0;
    for (k, &x) in angles.iter().enumerate() {
        if k > 0 {
            let prev = angles[k - 1];
            if x - prev > PI {
                offset -= TAU;
            } else if x - prev < -PI {
                offset += TAU;
            }
        }
        unwrapped.push(x + offset);
    }
    let n = times.len() as f64;
    let tm = times.iter().sum::<f64>() / n;
    let ym = unwrapped.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (t, y) in times.iter().zip(&unwrapped) {
        sxy += (t - tm) * (y - ym);
        sxx += (t - tm) * (t - tm);
    }
    sxy / sxx
}

#[test]
fn j2_secular_rates_match_a_numerical_j2_integration() {
    println!(
        "  a (km)  e     i (°)   quantity   fitted (°/day)   secular model (°/day)   difference"
    );
    for (a, e, inc) in [(7.5e6, 0.1, 51.6), (7.5e6, 0.1, 98.0), (2.66e7, 0.7, 30.0)] {
        let o = Orbit::new(
            EARTH,
            Elements::new(a, e, inc_rad(inc), 0.7, 2.1, 0.3),
            true,
        )
        .unwrap();
        // 50 orbits, 64 samples per orbit (whole orbits, so the short-period terms average
        // out of the fit as far as possible).
        let times: Vec<f64> = (0..=50 * 64)
            .map(|k| o.period() * k as f64 / 64.0)
            .collect();
        let states = integrate(&o, true, 1e-12, &times);
        let (mut raans, mut argps, mut means, mut a_sum) = (vec![], vec![], vec![], 0.0);
        for y in &states[..states.len() - 1] {
            let (r, v) = split(y);
            let (raan, argp, m) = osculating(&r, &v);
            raans.push(raan);
            argps.push(argp);
            means.push(m);
            a_sum += 1.0 / (2.0 / r.norm() - v.norm_squared() / EARTH.mu);
        }
        let times = &times[..times.len() - 1];
        // The mean semi-major axis: the time average of the osculating one (its short-period
        // terms average to zero over whole orbits at first order in J2), and the Keplerian
        // mean motion it implies. dM/dt − n(ā) isolates the J2 correction to dM/dt.
        let a_mean = a_sum / times.len() as f64;
        let n_mean = (EARTH.mu / a_mean.powi(3)).sqrt();
        let rates = o.secular_rates();
        let day = 86_400.0_f64.to_degrees() / 86_400.0 * 86_400.0;
        for (name, fitted, model, tol) in [
            ("dΩ/dt", slope(times, &raans), rates.raan, 0.03),
            ("dω/dt", slope(times, &argps), rates.arg_perigee, 0.05),
            (
                "dM/dt−n",
                slope(times, &means) - n_mean,
                (rates.mean_anomaly / o.mean_motion() - 1.0) * n_mean,
                0.03,
            ),
        ] {
            let rel = (fitted - model) / model;
            println!(
                "  {:>6.0}  {e:<4}  {inc:>5.1}   {name:<8}   {:>14.6}   {:>20.6}   {:>+8.2}%",
                a / 1e3,
                fitted * day,
                model * day,
                100.0 * rel
            );
            assert!(
                rel.abs() <= tol,
                "{name}: fitted {fitted:e}, model {model:e}"
            );
        }
    }
}

fn inc_rad(deg: f64) -> f64 {
    deg.to_radians()
}

#[test]
fn lvlh_rate_matches_finite_differences() {
    // Fourth-order central differences, with the step the power of two nearest 1e-4/|ω| s
    // (a frame turn of ~1e-4 rad): truncation ≈ (ωh)⁴/30 ≈ 1e-17, and rounding ≈ (a few
    // ulp of the angles M, Ω, ω, which reach ~20 rad late in the run)/(ωh) ≈ 1e-10. With t
    // in whole seconds, t ± h and t ± 2h are exact.
    let mut worst: f64 = 0.0;
    let mut worst_dot: f64 = 0.0;
    for (a, e) in [CASES[0], CASES[2]] {
        for j2 in [false, true] {
            let o = orbit(a, e, j2);
            let scale_dot = (0..200)
                .map(|k| o.lvlh(o.period() * k as f64 / 200.0).omega_dot.norm())
                .fold(0.0, f64::max)
                .max(1e-30);
            for k in 0..300 {
                let t = (o.period() * k as f64 / 97.0).round();
                let f = o.lvlh(t);
                let h = (1e-4 / f.omega.norm()).log2().round().exp2();
                let frames = [
                    o.lvlh(t - 2.0 * h),
                    o.lvlh(t - h),
                    o.lvlh(t + h),
                    o.lvlh(t + 2.0 * h),
                ];
                // ω = ½ Σ o_i × ȯ_i for an orthonormal triad.
                let mut w = Vector3::zeros();
                for i in 0..3 {
                    let oi: Vector3<f64> = f.eci_to_lvlh.row(i).transpose();
                    let row = |k: usize| frames[k].eci_to_lvlh.row(i).transpose();
                    let d = ((row(2) - row(1)) * 8.0 - (row(3) - row(0))) / (12.0 * h);
                    w += oi.cross(&d) * 0.5;
                }
                let rel = (w - f.omega).norm() / f.omega.norm();
                worst = worst.max(rel);
                assert!(rel <= 1e-9, "a = {a}, e = {e}, j2 = {j2}, t = {t}: {rel:e}");
                // ω̇ against a central difference of ω (step 1 s), relative to its size
                // over the orbit.
                let hd = 1.0;
                let wd = (o.lvlh(t + hd).omega - o.lvlh(t - hd).omega) / (2.0 * hd);
                let rel_dot = (wd - f.omega_dot).norm() / scale_dot;
                worst_dot = worst_dot.max(rel_dot);
                assert!(
                    rel_dot <= 1e-5,
                    "a = {a}, e = {e}, j2 = {j2}, t = {t}: ω̇ {rel_dot:e}"
                );
            }
            if e == 0.0 && !j2 {
                assert_eq!(o.lvlh(123.0).omega_dot, Vector3::zeros());
            }
        }
    }
    println!(
        "LVLH: worst relative |ω − ω_fd| = {worst:.2e}, worst |ω̇ − ω̇_fd|/max|ω̇| = {worst_dot:.2e}"
    );
}

#[test]
fn lvlh_axes_for_a_circular_equatorial_orbit() {
    // i = 0, Ω = ω = ν₀ = 0: at t = 0, r along x, v along y, h along z.
    let o = Orbit::new(EARTH, Elements::new(7.0e6, 0.0, 0.0, 0.0, 0.0, 0.0), false).unwrap();
    let f = o.lvlh(0.0);
    let close = |a: Vector3<f64>, b: Vector3<f64>| (a - b).norm() < 1e-15;
    assert!(close(f.o1(), Vector3::y()), "o1 along track");
    assert!(close(f.o2(), -Vector3::z()), "o2 = −orbit normal");
    assert!(close(f.o3(), -Vector3::x()), "o3 nadir");
    assert!(close(f.omega, Vector3::z() * o.mean_motion()));
    // ECI → LVLH: the position vector is (0, 0, −r) in LVLH.
    let (r, _) = o.state(0.0);
    assert!((f.eci_to_lvlh * r - Vector3::new(0.0, 0.0, -7.0e6)).norm() < 1e-8);
    assert!((o.argument_of_latitude(o.period() / 4.0) - PI / 2.0).abs() < 1e-14);
}

#[test]
fn bad_elements_are_refused_with_messages() {
    let check = |el: Elements, needles: &[&str]| {
        let err = Orbit::new(EARTH, el, false).unwrap_err();
        for n in needles {
            assert!(err.contains(n), "`{err}` lacks `{n}`");
        }
    };
    check(
        Elements::new(f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0),
        &["semi-major axis", "finite"],
    );
    check(
        Elements::new(7e6, 0.0, f64::INFINITY, 0.0, 0.0, 0.0),
        &["inclination", "finite"],
    );
    check(
        Elements::new(7e6, 0.0, 0.0, 0.0, 0.0, f64::NAN),
        &["true anomaly", "finite"],
    );
    check(
        Elements::new(-7e6, 0.0, 0.0, 0.0, 0.0, 0.0),
        &["semi-major axis", "a > 0"],
    );
    check(
        Elements::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        &["semi-major axis", "a > 0"],
    );
    for e in [-0.1, 1.0, 1.5] {
        check(
            Elements::new(7e7, e, 0.0, 0.0, 0.0, 0.0),
            &[
                "eccentricity",
                "polhode propagates closed orbits: 0 ≤ e < 1",
            ],
        );
    }
    check(
        Elements::new(7e6, 0.1, 0.0, 0.0, 0.0, 0.0),
        &["perigee", "km below the surface"],
    );
    check(
        Elements::new(6e6, 0.0, 0.0, 0.0, 0.0, 0.0),
        &["perigee", "378.137 km below the surface"],
    );
    check(
        Elements::new(7e6, 0.0, -0.1, 0.0, 0.0, 0.0),
        &["inclination", "0 ≤ i ≤ π"],
    );
    check(
        Elements::new(7e6, 0.0, 3.2, 0.0, 0.0, 0.0),
        &["inclination", "0 ≤ i ≤ π"],
    );
    let err = Elements::from_altitudes(&EARTH, -10e3, 500e3, 0.5, 0.0, 0.0, 0.0).unwrap_err();
    assert!(err.contains("10.000 km below the surface"), "{err}");
    let err = Elements::from_altitudes(&EARTH, 800e3, 500e3, 0.5, 0.0, 0.0, 0.0).unwrap_err();
    assert!(err.contains("apogee") && err.contains("perigee"), "{err}");
}

#[test]
fn elements_from_altitudes() {
    // Explorer 1 (NSSDCA 1958-001A): perigee 358 km, apogee 2550 km, i = 33.24°,
    // period 114.8 min.
    let el = Elements::from_altitudes(&EARTH, 358e3, 2550e3, 33.24_f64.to_radians(), 0.0, 0.0, 0.0)
        .unwrap();
    let o = Orbit::new(EARTH, el, false).unwrap();
    assert!((o.altitude(0.0) - 358e3).abs() < 1e-6);
    assert!((o.altitude(o.period() / 2.0) - 2550e3).abs() < 1e-6);
    let minutes = o.period() / 60.0;
    println!(
        "Explorer 1: a = {:.3} km, e = {:.6}, period {minutes:.2} min",
        el.semi_major_axis / 1e3,
        el.eccentricity
    );
    assert!((minutes - 114.8).abs() < 0.2, "{minutes}");
}
