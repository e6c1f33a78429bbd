use super::kepler::{self, KeplerSolution};
use super::*;
use crate::scenario::parse_epoch;
use std::f64::consts::PI;

const ECCENTRICITIES: [f64; 9] = [0.0, 1e-6, 0.1, 0.5, 0.7, 0.9, 0.99, 0.999, 0.999_999];

/// `x − sin x` summed term by term until the terms stop mattering (the test's own
/// evaluation, independent of the solver's Horner polynomial).
fn x_minus_sin_sum(x: f64) -> f64 {
    let mut term = x * x * x / 6.0;
    let mut sum = 0.0;
    let mut k = 3.0;
    while term.abs() > 1e-40 * x.abs().max(1e-300) && term != 0.0 {
        sum += term;
        term *= -x * x / ((k + 1.0) * (k + 2.0));
        k += 2.0;
    }
    sum
}

/// Plain bisection for `M ∈ [0, π]` on `[0, π]`, with `E − e sin E` evaluated without
/// cancellation where it matters.
fn bisection(m: f64, e: f64) -> f64 {
    let f = |x: f64| {
        if x < 1.0 {
            (1.0 - e) * x + e * x_minus_sin_sum(x) - m
        } else {
            x - e * x.sin() - m
        }
    };
    let (mut lo, mut hi) = (0.0_f64, PI);
    for _ in 0..2000 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if f(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

fn mean_anomalies() -> Vec<f64> {
    let mut ms: Vec<f64> = (0..=4000)
        .map(|k| -PI + 2.0 * PI * k as f64 / 4000.0)
        .collect();
    for tiny in [1e-300, 1e-200, 1e-15, 1e-12, 1e-9, 1e-6, 1e-4, 1e-3, 1e-2] {
        ms.push(tiny);
        ms.push(-tiny);
    }
    ms.extend([0.0, PI, -PI, PI - 1e-12, 3.0, 3.1]);
    ms
}

#[test]
fn kepler_residual_and_bisection_agreement() {
    println!("   e         max|res|/eps  max|E-E_bis|   max it  mean it");
    for &e in &ECCENTRICITIES {
        let (mut worst_res, mut worst_diff, mut max_it, mut sum_it, mut count) =
            (0.0_f64, 0.0_f64, 0, 0u64, 0u64);
        for &m in &mean_anomalies() {
            let KeplerSolution {
                eccentric_anomaly: ea,
                sin_e,
                cos_e,
                one_minus_cos_e,
                iterations,
            } = kepler::solve(m, e);
            assert!(
                (one_minus_cos_e - (1.0 - cos_e)).abs() <= 4.0 * f64::EPSILON,
                "e = {e}, M = {m}: 1 − cos E {one_minus_cos_e:e}, cos E {cos_e}"
            );
            let res = (ea - e * ea.sin() - m).abs();
            let bound = 4.0 * f64::EPSILON * m.abs().max(1.0);
            assert!(
                res <= bound,
                "e = {e}, M = {m}: residual {res:e} > {bound:e}"
            );
            let reference = m.signum() * bisection(m.abs(), e);
            let diff = (ea - reference).abs();
            assert!(
                diff <= 1e-14,
                "e = {e}, M = {m}: E = {ea}, bisection {reference}"
            );
            if m.abs() < 1e-3 && m != 0.0 {
                // Relative accuracy down to the smallest M.
                assert!(
                    diff <= 8.0 * f64::EPSILON * reference.abs(),
                    "e = {e}, M = {m:e}: E = {ea:e}, bisection {reference:e}"
                );
            }
            assert!(
                (sin_e - ea.sin()).abs() <= 2.0 * f64::EPSILON,
                "sin, e = {e}, M = {m}"
            );
            assert!(
                (cos_e - ea.cos()).abs() <= 2.0 * f64::EPSILON,
                "cos, e = {e}, M = {m}"
            );
            worst_res = worst_res.max(res / f64::EPSILON);
            worst_diff = worst_diff.max(diff);
            max_it = max_it.max(iterations);
            sum_it += u64::from(iterations);
            count += 1;
        }
        println!(
            "   {e:<9}  {worst_res:>10.2}    {worst_diff:>9.2e}    {max_it:>5}   {:>6.2}",
            sum_it as f64 / count as f64
        );
        assert!(max_it <= 6, "e = {e}: {max_it} iterations");
    }
}

#[test]
fn kepler_large_mean_anomaly() {
    for &e in &ECCENTRICITIES {
        for m in [
            10.0,
            -57.3,
            1e3 + 0.25,
            -2.5e4,
            1e6 + 1.0,
            -7.7e7,
            1e9 + 0.5,
        ] {
            let ea = kepler::eccentric_anomaly(m, e);
            let res = (ea - e * ea.sin() - m).abs();
            let bound = 4.0 * f64::EPSILON * m.abs().max(1.0);
            assert!(
                res <= bound,
                "e = {e}, M = {m}: residual {res:e} > {bound:e}"
            );
            // The same turn as M: |E − M| ≤ e.
            assert!((ea - m).abs() <= e + bound, "e = {e}, M = {m}: E = {ea}");
        }
    }
}

#[test]
fn kepler_odd_and_periodic() {
    for &e in &ECCENTRICITIES {
        for k in 1..50 {
            let m = 0.0637 * k as f64;
            let a = kepler::eccentric_anomaly(m, e);
            assert_eq!(
                kepler::eccentric_anomaly(-m, e),
                -a,
                "odd, e = {e}, M = {m}"
            );
        }
    }
}

#[test]
fn mean_from_eccentric_inverts_the_solver() {
    for &e in &ECCENTRICITIES {
        for &m in &mean_anomalies() {
            let ea = kepler::eccentric_anomaly(m, e);
            let back = kepler::mean_from_eccentric(ea, e);
            // Relative accuracy where the series is used, absolute (like the residual) else.
            let scale = if e >= 0.5 && ea.abs() < 1.0 {
                m.abs()
            } else {
                1.0
            };
            assert!(
                (back - m).abs() <= 4.0 * f64::EPSILON * scale.max(f64::MIN_POSITIVE),
                "e = {e}, M = {m:e}: back {back:e}"
            );
        }
    }
}

#[test]
fn earth_by_name() {
    assert_eq!(CentralBody::by_name("earth"), Ok(CentralBody::EARTH));
    assert_eq!(CentralBody::by_name(" Earth "), Ok(CentralBody::EARTH));
    let err = CentralBody::by_name("mars").unwrap_err();
    assert!(err.contains("mars") && err.contains("`earth`"), "{err}");
    let b = CentralBody::EARTH;
    assert_eq!(
        (b.mu, b.radius, b.j2, b.rotation_rate),
        (3.986004418e14, 6378137.0, 1.08262668e-3, 7.292115e-5)
    );
}

fn leo(e: f64, j2: bool) -> Orbit {
    let a = if e == 0.0 {
        7.0e6
    } else if e < 0.5 {
        7.5e6
    } else {
        2.66e7
    };
    Orbit::new(
        CentralBody::EARTH,
        Elements::new(a, e, 0.9, 0.4, 1.3, 0.2),
        j2,
    )
    .unwrap()
}

#[test]
fn epoch_state_matches_the_elements() {
    // At t = 0 the state reproduces ν₀ and the perifocal geometry (Vallado COE2RV:
    // r = p/(1 + e cos ν), v = √(μ/p)(−sin ν P̂ + (e + cos ν) Q̂)).
    for &e in &[0.0, 0.1, 0.7] {
        for j2 in [false, true] {
            let o = leo(e, j2);
            let el = *o.elements();
            let mu = o.body().mu;
            let p = el.semi_major_axis * (1.0 - e * e);
            let nu = el.true_anomaly;
            let [pp, qq, _] = perifocal_axes(
                el.raan,
                el.inclination.cos(),
                el.inclination.sin(),
                el.arg_perigee,
            );
            let rr = p / (1.0 + e * nu.cos());
            let r_ref = (pp * nu.cos() + qq * nu.sin()) * rr;
            let v_ref = (pp * -nu.sin() + qq * (e + nu.cos())) * (mu / p).sqrt();
            let (r, v) = o.state(0.0);
            assert!(
                (r - r_ref).norm() <= 1e-15 * rr * 8.0,
                "e = {e}: {}",
                (r - r_ref).norm()
            );
            assert!((v - v_ref).norm() <= 1e-15 * v_ref.norm() * 8.0, "e = {e}");
            assert!((o.true_anomaly(0.0) - nu).abs() < 1e-15);
            assert!((o.argument_of_latitude(0.0) - (el.arg_perigee + nu)).abs() < 1e-14);
            assert!((o.altitude(0.0) - (rr - 6378137.0)).abs() < 1e-8);
        }
    }
}

#[test]
fn reruns_are_bit_identical_and_order_free() {
    for &e in &[0.0, 0.1, 0.7] {
        let o = leo(e, true);
        let times: Vec<f64> = (0..500).map(|k| 13.7 * k as f64).collect();
        let forward: Vec<_> = times.iter().map(|&t| o.state(t)).collect();
        let backward: Vec<_> = times.iter().rev().map(|&t| o.state(t)).collect();
        let again = o.clone();
        for (k, &t) in times.iter().enumerate() {
            assert_eq!(forward[k], backward[times.len() - 1 - k]);
            assert_eq!(forward[k], again.state(t));
            assert_eq!(o.lvlh(t), again.lvlh(t));
        }
    }
}

#[test]
fn lvlh_is_orthonormal_right_handed_nadir() {
    for &e in &[0.0, 0.1, 0.7] {
        for j2 in [false, true] {
            let o = leo(e, j2);
            for k in 0..400 {
                let t = 37.1 * k as f64;
                let f = o.lvlh(t);
                let c = f.eci_to_lvlh;
                let dev = (c * c.transpose() - Matrix3::identity()).abs().max();
                assert!(dev <= 1e-15, "e = {e}, t = {t}: |CCᵀ − I| = {dev:e}");
                assert!((c.determinant() - 1.0).abs() <= 1e-15);
                assert!((f.o1().cross(&f.o2()) - f.o3()).norm() <= 1e-15);
                let (r, v) = o.state(t);
                assert!((f.o3() + r.normalize()).norm() <= 1e-15);
                assert!((f.o2() + r.cross(&v).normalize()).norm() <= 1e-15);
                if e == 0.0 {
                    assert!((f.o1() - v.normalize()).norm() <= 1e-15);
                }
                // The quaternion maps LVLH components to ECI.
                let q = f.lvlh_to_eci();
                let dq = (q * Vector3::z() - f.o3())
                    .norm()
                    .max((q * Vector3::x() - f.o1()).norm());
                assert!(dq <= 2e-15, "quaternion {dq:e}");
            }
        }
    }
}

#[test]
fn keplerian_lvlh_rate_is_h_over_r_squared() {
    for &e in &[0.0, 0.1, 0.7] {
        let o = leo(e, false);
        for k in 0..100 {
            let t = 71.3 * k as f64;
            let (r, v) = o.state(t);
            let h = r.cross(&v);
            let expected = h * (1.0 / r.norm_squared()); // |h|/r² about ĥ = −o2
            let f = o.lvlh(t);
            assert!((f.omega - expected).norm() <= 1e-14 * expected.norm());
            assert!(
                (f.omega_in_lvlh() - Vector3::new(0.0, -expected.norm(), 0.0)).norm()
                    <= 1e-14 * expected.norm()
            );
        }
    }
}

#[test]
#[allow(clippy::excessive_precision)] // the IERS digits, as published
fn earth_rotation_angle_and_gmst() {
    // ERA at J2000.0: 2π · 0.7790572732640 (IERS Conventions 2010, eq. 5.15).
    let j2000 = parse_epoch("2000-01-01T12:00:00Z").unwrap();
    let era0 = earth_rotation_angle(j2000, 0.0);
    assert!((era0 - TAU * 0.779_057_273_264_0).abs() < 1e-15);
    // One sidereal day later (in UT1 seconds) it is back, to the resolution of the rate.
    let sidereal_day = 86_400.0 / 1.002_737_811_911_354_48;
    let era1 = earth_rotation_angle(j2000, sidereal_day);
    assert!((era1 - era0).abs() < 1e-12, "{}", era1 - era0);
    // The epoch can be split anywhere between the date and t.
    let later = earth_rotation_angle(j2000 + 3_600_000_000_000, 0.0);
    assert!((later - earth_rotation_angle(j2000, 3600.0)).abs() < 1e-14);
    // The rate is ω_E (WGS-84 7.292115e-5 rad/s) to its quoted digits.
    let rate = TAU * 1.002_737_811_911_354_48 / 86_400.0;
    assert!((rate - CentralBody::EARTH.rotation_rate).abs() < 1e-11);
    // GMST (IAU 1982) at J2000.0: 18h41m50.54841s = 280.46061837°.
    let g0 = gmst_iau82(j2000, 0.0).to_degrees();
    assert!((g0 - 280.460_618_375).abs() < 1e-8, "{g0}");
    // Vallado, 4th ed., Example 3-5: 1992-08-20 12:14 UT1, GMST = 152.578787...°.
    let ex = parse_epoch("1992-08-20T12:14:00Z").unwrap();
    let g = gmst_iau82(ex, 0.0).to_degrees();
    assert!((g - 152.578_787_8).abs() < 1e-6, "{g}");
    // GMST − ERA = precession in right ascension: 0.014506″ + 4612.156534″ T
    // + 1.3915817″ T² (IERS Conventions 2010, eq. 5.32, IAU 2006). GMST82 lacks the
    // 0.014506″ constant and the IAU 2000 correction to the precession rate in longitude,
    // −0.29965″/century (IERS Conventions 2010, §5.6.4), i.e. −0.29965 cos ε₀ = −0.2749″
    // per century in right ascension, so GMST82 − GMST2006 ≈ −0.0145″ + 0.2749″ T.
    let mut worst: f64 = 0.0;
    for year in [1970, 1985, 1992, 2000, 2010, 2025, 2050, 2080, 2100] {
        let ns = parse_epoch(&format!("{year}-03-21T06:00:00Z")).unwrap();
        let tc = (ns as f64 * 1e-9 - 946_728_000.0) / 86_400.0 / 36_525.0;
        let diff = (gmst_iau82(ns, 0.0) - earth_rotation_angle(ns, 0.0) + PI).rem_euclid(TAU) - PI;
        let arcsec = diff.to_degrees() * 3600.0;
        let model = 4_612.156_534 * tc
            + 1.391_581_7 * tc * tc
            + 0.299_65 * 23.439_279_f64.to_radians().cos() * tc;
        println!("{year}: T = {tc:+.4}  GMST82 − ERA = {arcsec:.4}″  IAU 2006 {model:.4}″");
        worst = worst.max((arcsec - model).abs());
    }
    println!(
        "GMST82 − ERA vs IAU 2006 polynomial corrected to IAU 1976 precession: worst {worst:.4e} arcsec"
    );
    assert!(worst < 0.01, "{worst}");
}

#[test]
fn secular_rates_match_the_formulas() {
    // Sun-synchronous check: at a = R + 800 km, e = 0, the node drifts +360°/year
    // (0.9856°/day) for i ≈ 98.6° (Vallado §9.6 / Curtis §4.7 worked examples).
    let a = CentralBody::EARTH.radius + 800e3;
    let i_sso = 98.6_f64.to_radians();
    let o = Orbit::new(
        CentralBody::EARTH,
        Elements::new(a, 0.0, i_sso, 0.0, 0.0, 0.0),
        true,
    )
    .unwrap();
    let deg_per_day = o.secular_rates().raan.to_degrees() * 86_400.0;
    assert!((deg_per_day - 0.9856).abs() < 0.01, "{deg_per_day}");
    // Critical inclination: ω̇ = 0 at cos² i = 1/5 (63.43°).
    let ic = (0.2_f64).sqrt().acos();
    let o = Orbit::new(
        CentralBody::EARTH,
        Elements::new(2.66e7, 0.7, ic, 0.0, 0.0, 0.0),
        true,
    )
    .unwrap();
    assert!(o.secular_rates().arg_perigee.abs() < 1e-20);
    // Without J2 the rates are Keplerian.
    let o = leo(0.1, false);
    assert_eq!(o.secular_rates().mean_anomaly, o.mean_motion());
    assert_eq!(
        (o.secular_rates().raan, o.secular_rates().arg_perigee),
        (0.0, 0.0)
    );
}

/// Cost of `state` and `lvlh`: `cargo test --release --locked --lib orbit::tests::bench -- --ignored --nocapture`.
#[test]
#[ignore]
fn bench() {
    use std::hint::black_box;
    use std::time::Instant;
    let calls = 2_000_000;
    for j2 in [false, true] {
        for &e in &[0.0, 0.1, 0.7] {
            let o = leo(e, j2);
            let dt = o.period() / 997.3;
            let mut acc = Vector3::zeros();
            let start = Instant::now();
            for k in 0..calls {
                let (r, v) = o.state(black_box(k as f64 * dt));
                acc += r + v;
            }
            let ns_state = start.elapsed().as_nanos() as f64 / calls as f64;
            black_box(acc);
            let start = Instant::now();
            for k in 0..calls {
                acc += o.lvlh(black_box(k as f64 * dt)).omega;
            }
            let ns_lvlh = start.elapsed().as_nanos() as f64 / calls as f64;
            black_box(acc);
            let start = Instant::now();
            let mut s = 0.0;
            for k in 0..calls {
                s += kepler::eccentric_anomaly(black_box(k as f64 * 6.28e-3), e);
            }
            let ns_kepler = start.elapsed().as_nanos() as f64 / calls as f64;
            black_box(s);
            println!(
                "j2_secular = {j2:<5}  e = {e:<4}  state {ns_state:6.1} ns  lvlh {ns_lvlh:6.1} ns  \
                 kepler {ns_kepler:6.1} ns"
            );
        }
    }
}
