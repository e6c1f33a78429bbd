//! Dispersion statistics against their specification, and the independence of each run's
//! random stream. Sample statistics are compared with the specified ones within five
//! standard errors (the draws are seeded, so these tests are deterministic).

use super::*;
use nalgebra::UnitQuaternion;

/// Draws per statistic.
const N: u64 = 20_000;

fn prepared(extra_body: &str, effectors: &str, dispersions: &str) -> Prepared {
    let yaml = format!(
        "name: stats\n\
         body:\n  principal: [2.0, 2.1, 1.0]\n{extra_body}\
         {effectors}\
         initial:\n  omega: [0.05, 0.05, 2.0]\n  attitude: {{w: 0.8, x: 0.6, y: 0.0, z: 0.0}}\n\
         duration: 1.0\n\
         montecarlo:\n  runs: {N}\n  seed: 11\n  dispersions:\n{dispersions}"
    );
    let sc = scenario::parse(Path::new("stats.yaml"), yaml, &Overrides::default())
        .unwrap_or_else(|e| panic!("{e}"));
    Prepared::new(sc, "stats.yaml", None, None).unwrap_or_else(|e| panic!("{e}"))
}

/// Recorded inputs of `n` runs.
fn inputs(p: &Prepared, n: u64) -> Vec<Vec<f64>> {
    (0..n)
        .map(|i| p.build_run(i).unwrap_or_else(|e| panic!("run {i}: {e}")).1)
        .collect()
}

fn mean_sd(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let s = (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    (m, s)
}

/// Asserts that sample mean and sd of `v` match (`mean`, `sd`) within 5 standard errors
/// (the sd's standard error is taken as sd/√(2n), exact for a Gaussian and close for the
/// others used here).
fn assert_matches(what: &str, v: &[f64], mean: f64, sd: f64) {
    let n = v.len() as f64;
    let (m, s) = mean_sd(v);
    assert!(
        (m - mean).abs() < 5.0 * sd / n.sqrt(),
        "{what}: sample mean {m} vs {mean} (sd {sd}, n {n})"
    );
    assert!(
        (s - sd).abs() < 5.0 * sd / (2.0 * n).sqrt() + 1e-15,
        "{what}: sample sd {s} vs {sd}"
    );
}

fn column(p: &Prepared, rows: &[Vec<f64>], name: &str) -> Vec<f64> {
    let j = p.columns.iter().position(|c| c == name).unwrap();
    rows.iter().map(|r| r[j]).collect()
}

#[test]
fn scalar_distributions_match_their_specification() {
    let p = prepared(
        "",
        "effectors:\n  - energy_sink: {name: sink, time_constant: 10.0}\n",
        "    - {path: \"initial.omega[0]\", normal: {sd: 0.01, mean: 0.002}}\n\
         \x20   - {path: \"initial.omega[2]\", normal: {sd: 0.01, relative: true}}\n\
         \x20   - {path: \"body.principal[0]\", uniform: {half_width: 0.02, relative: true}}\n\
         \x20   - {path: duration, uniform: {min: 1.0, max: 3.0}}\n\
         \x20   - {path: \"initial.omega[1]\", truncated_normal: {sd: 0.02, min: 0.03, max: 0.1}}\n\
         \x20   - {path: \"effectors[sink].time_constant\", log_normal: {sigma: 0.3}}\n",
    );
    let rows = inputs(&p, N);
    assert_matches(
        "normal",
        &column(&p, &rows, "initial.omega[0]"),
        0.052,
        0.01,
    );
    assert_matches(
        "relative normal",
        &column(&p, &rows, "initial.omega[2]"),
        2.0,
        0.02,
    );
    let u = column(&p, &rows, "body.principal[0]");
    assert!(u.iter().all(|x| (1.96..=2.04).contains(x)));
    assert_matches("uniform about", &u, 2.0, 0.04 / 3f64.sqrt());
    let u = column(&p, &rows, "duration");
    assert!(u.iter().all(|x| (1.0..=3.0).contains(x)));
    assert_matches("uniform between", &u, 2.0, 2.0 / 12f64.sqrt());

    // Truncated normal: moments of the density on [a, b] by Simpson's rule, independent of
    // the sampler.
    let (mu, s, a, b) = (0.05, 0.02, 0.03, 0.1);
    let density = |x: f64| (-0.5 * ((x - mu) / s).powi(2)).exp();
    let k = 20_000;
    let h = (b - a) / k as f64;
    let mut m = [0.0; 3];
    for i in 0..=k {
        let x = a + h * i as f64;
        let w = if i == 0 || i == k {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        for (p, mp) in m.iter_mut().enumerate() {
            *mp += w * x.powi(p as i32) * density(x);
        }
    }
    let mean = m[1] / m[0];
    let sd = (m[2] / m[0] - mean * mean).sqrt();
    let t = column(&p, &rows, "initial.omega[1]");
    assert!(t.iter().all(|x| (a..=b).contains(x)));
    assert_matches("truncated normal", &t, mean, sd);

    let logs: Vec<f64> = column(&p, &rows, "effectors[sink].time_constant")
        .iter()
        .map(|x| (x / 10.0).ln())
        .collect();
    assert_matches("log-normal (log of the factor)", &logs, 0.0, 0.3);
}

#[test]
fn rotations_have_the_specified_spread() {
    let sd = 2f64.to_radians();
    let p = prepared(
        "",
        "",
        "    - {path: initial.omega, tilt: {sd_deg: 2.0}}\n\
         \x20   - {attitude: {sd_deg: 2.0}}\n",
    );
    let w0 = nalgebra::Vector3::<f64>::new(0.05, 0.05, 2.0);
    let q0 = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(0.8, 0.6, 0.0, 0.0));
    let mut tilt2 = Vec::new();
    let mut att2 = Vec::new();
    // Per-axis components: the tilt must be isotropic about ω₀ and the attitude rotation
    // about all three body axes.
    let u = w0.normalize();
    let ea = u.cross(&nalgebra::Vector3::x()).normalize();
    let eb = u.cross(&ea);
    let (mut ta, mut tb) = (Vec::new(), Vec::new());
    let mut axes: [Vec<f64>; 3] = Default::default();
    for i in 0..N {
        let (sc, rec) = p.build_run(i).unwrap();
        // The tilt keeps |ω| and moves its direction; the angle is Rayleigh: E θ² = 2 sd².
        assert!((sc.omega0.norm() - w0.norm()).abs() < 1e-12 * w0.norm());
        tilt2.push(sc.omega0.angle(&w0).powi(2));
        let d = sc.omega0.normalize() - u;
        ta.push(d.dot(&ea));
        tb.push(d.dot(&eb));
        // The rotation vector of q0⁻¹ q, in body axes.
        let v = (q0.inverse() * sc.attitude0).scaled_axis();
        for (k, a) in axes.iter_mut().enumerate() {
            a.push(v[k]);
        }
        // The attitude is q0 ⊗ Exp(θ) with θ ~ N(0, sd² I₃): E θ² = 3 sd².
        let angle = q0.rotation_to(&sc.attitude0).angle();
        let recorded = rec[3].to_radians();
        assert!((angle - recorded).abs() < 1e-9, "{angle} vs {recorded}");
        att2.push(angle * angle);
    }
    let (m, _) = mean_sd(&tilt2);
    // θ² of a Rayleigh angle is exponential with mean 2 sd² and the same sd.
    assert!(
        (m - 2.0 * sd * sd).abs() < 5.0 * 2.0 * sd * sd / (N as f64).sqrt(),
        "{m}"
    );
    // Small angles: each component is N(0, sd²) to O(sd²) relative.
    assert_matches("tilt, first perpendicular", &ta, 0.0, sd);
    assert_matches("tilt, second perpendicular", &tb, 0.0, sd);
    for (k, a) in axes.iter().enumerate() {
        assert_matches(&format!("attitude axis {k}"), a, 0.0, sd);
    }
    let (m, _) = mean_sd(&att2);
    // θ² / sd² is chi-square with 3 degrees of freedom: mean 3, variance 6.
    assert!(
        (m - 3.0 * sd * sd).abs() < 5.0 * 6f64.sqrt() * sd * sd / (N as f64).sqrt(),
        "{m}"
    );
}

#[test]
fn inertia_draws_stay_physical_and_redraws_are_counted() {
    // Moments and axes: far from the triangle boundary, almost nothing is redrawn.
    let p = prepared("", "", "    - {inertia: {sd: 0.01, axes_sd_deg: 1.0}}\n");
    let rows = inputs(&p, 5000);
    for (k, nominal) in [2.0, 2.1, 1.0].iter().enumerate() {
        let v: Vec<f64> = column(&p, &rows, &format!("inertia_moment_{}", k + 1))
            .iter()
            .map(|x| x / nominal)
            .collect();
        assert_matches("moment", &v, 1.0, 0.01);
    }
    let axes: Vec<f64> = column(&p, &rows, "inertia_axes_rotation_deg")
        .iter()
        .map(|d| d.to_radians().powi(2))
        .collect();
    let s2 = 1f64.to_radians().powi(2);
    let (m, _) = mean_sd(&axes);
    assert!((m - 3.0 * s2).abs() < 5.0 * 6f64.sqrt() * s2 / (5000f64).sqrt());
    // The built hub has the drawn moments.
    let (sc, rec) = p.build_run(3).unwrap();
    let mut drawn = [rec[0], rec[1], rec[2]];
    drawn.sort_by(f64::total_cmp);
    for (k, want) in drawn.iter().enumerate() {
        let got = sc.spacecraft.hub.principal_moments[k];
        assert!((got - want).abs() < 1e-12 * want, "{got} vs {want}");
    }

    // A flat plate (1, 1, 2) sits on the boundary I1 + I2 = I3: a draw breaks it exactly when
    // z1 + z2 − 2 z3 < 0, with probability 1/2. Redraws are then geometric with mean 1 and
    // standard deviation √2.
    let p = prepared("", "", "    - {inertia: {sd: 0.01}}\n");
    let mut plate = p.tree.clone();
    plate["body"]["principal"] = serde_json::json!([1.0, 1.0, 2.0]);
    let p = Prepared { tree: plate, ..p };
    let rows = inputs(&p, N);
    let redraws = column(&p, &rows, "inertia_redraws");
    let (m, _) = mean_sd(&redraws);
    assert!(
        (m - 1.0).abs() < 5.0 * 2f64.sqrt() / (N as f64).sqrt(),
        "mean redraws {m}"
    );
    for r in &rows {
        let (a, b, c) = (r[0], r[1], r[2]);
        assert!(a + b >= c && b + c >= a && c + a >= b, "{a} {b} {c}");
    }
}

fn reparse(p: &Prepared) -> Scenario {
    scenario::parse(
        Path::new("stats.yaml"),
        p.scenario.source.clone(),
        &Overrides::default(),
    )
    .unwrap()
}

#[test]
fn each_run_draws_from_its_own_stream() {
    let p = prepared("", "", "    - {path: initial.omega, normal: {sd: 0.01}}\n");
    let forward: Vec<Vec<f64>> = inputs(&p, 50);
    // Any order, any campaign size: run i draws the same numbers.
    let q = Prepared::new(reparse(&p), "stats.yaml", Some(7), None).unwrap();
    for i in (0..50).rev() {
        assert_eq!(p.build_run(i).unwrap().1, forward[i as usize]);
        if i < 7 {
            assert_eq!(q.build_run(i).unwrap().1, forward[i as usize]);
        }
    }
    // Different runs and different seeds draw differently.
    assert_ne!(forward[0], forward[1]);
    let r = Prepared::new(reparse(&p), "stats.yaml", None, Some(12)).unwrap();
    assert_ne!(r.build_run(0).unwrap().1, forward[0]);
}

#[test]
fn shards_partition_the_runs() {
    for runs in [1u64, 2, 7, 100, 10_001] {
        for n in 1..=runs.min(13) {
            let mut next = 0;
            for k in 1..=n {
                let r = shard_range(runs, k, n);
                assert_eq!(r.start, next);
                let len = r.end - r.start;
                assert!(len == runs / n || len == runs / n + 1);
                next = r.end;
            }
            assert_eq!(next, runs);
        }
    }
}

#[test]
fn dealt_chunks_hold_every_run_once_longest_first() {
    assert_eq!(
        dealt(&[9, 4, 7, 0, 2, 8, 1], 3),
        vec![vec![9, 0, 1], vec![4, 2], vec![7, 8]]
    );
    for n in [0usize, 1, 5, 64, 130] {
        let order: Vec<usize> = (0..n).rev().collect();
        for chunks in [0usize, 1, 2, 7, 200] {
            let dealt = dealt(&order, chunks);
            let sizes: Vec<usize> = dealt.iter().map(Vec::len).collect();
            let (smallest, largest) = (sizes.iter().min(), sizes.iter().max());
            assert!(
                largest.zip(smallest).is_none_or(|(l, s)| l - s <= 1),
                "{sizes:?}"
            );
            // Each chunk keeps the order's order.
            assert!(dealt.iter().all(|c| c.windows(2).all(|w| w[0] > w[1])));
            let mut all: Vec<usize> = dealt.concat();
            all.sort_unstable();
            assert_eq!(
                all,
                (0..n).collect::<Vec<_>>(),
                "{n} runs in {chunks} chunks"
            );
        }
    }
}

#[test]
fn erfc_matches_tabulated_values() {
    // Abramowitz and Stegun, Table 7.1: erf(0.5) = 0.5204998778, erf(1) = 0.8427007929,
    // erf(2) = 0.9953222650.
    for (x, erf) in [
        (0.5, 0.520_499_877_8),
        (1.0, 0.842_700_792_9),
        (2.0, 0.995_322_265_0),
    ] {
        assert!((1.0 - erfc(x) - erf).abs() < 2e-7, "{x}");
        assert!((erfc(-x) - (1.0 + erf)).abs() < 2e-7, "{x}");
    }
    assert!((normal_mass(-1.959_963_985, 1.959_963_985) - 0.95).abs() < 1e-6);
}

/// The list schedule's order: the runs expected to be longest first, which is what their
/// integrations then cost (RHS evaluations, counted by running them).
#[test]
fn the_runs_expected_longest_start_first_and_do_cost_the_most() {
    // A damper whose dashpot spans two decades: the stiffer runs take smaller explicit steps.
    let yaml = "name: order\n\
                body:\n  mass: 100.0\n  principal: [10.0, 9.0, 12.0]\n  spin_axis: [0, 0, 1]\n\
                effectors:\n  - spring_mass_damper: {name: damper, mass: 1.0, \
                position: [0.5, 0.0, 0.0], direction: [0, 0, 1], stiffness: 4.0, damping: 1.0}\n\
                initial:\n  omega: [0.1, 0.0, 1.0]\n\
                duration: 20.0\n\
                integrator: {method: dopri5, rtol: 1.0e-8, atol: 1.0e-10}\n\
                montecarlo:\n  runs: 12\n  seed: 5\n  dispersions:\n\
                \x20   - {path: \"effectors[damper].damping\", uniform: {min: 1.0, max: 400.0}}\n";
    let sc = scenario::parse(
        Path::new("order.yaml"),
        yaml.to_string(),
        &Overrides::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let p = Prepared::new(sc, "order.yaml", None, None).unwrap_or_else(|e| panic!("{e}"));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let never = AtomicBool::new(false);
    let (order, _) = p.longest_first(0..12, &pool, false, &never);
    let mut sorted = order.clone();
    sorted.sort_unstable();
    assert_eq!(
        sorted,
        (0..12).collect::<Vec<_>>(),
        "not a permutation: {order:?}"
    );
    let rhs = p
        .columns
        .iter()
        .position(|c| c == "rhs_evaluations")
        .expect("an rhs_evaluations column");
    let cost: Vec<f64> = order
        .iter()
        .map(|&j| {
            let row = p.run_one(j as u64, &never).expect("a row");
            row.values[rhs].expect("a count")
        })
        .collect();
    let (first, last) = (cost[..4].iter().sum::<f64>(), cost[8..].iter().sum::<f64>());
    assert!(
        first > 2.0 * last,
        "the first four runs in the order cost {first} evaluations, the last four {last}: {cost:?}"
    );
    // One thread, or many runs per thread: index order, and no prediction.
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    assert_eq!(
        p.longest_first(0..12, &one, false, &never).0,
        (0..12).collect::<Vec<_>>()
    );
    let many = ORDERED_RUNS_PER_THREAD * 2 + 1;
    assert_eq!(
        p.longest_first(0..many as u64, &pool, false, &never).0,
        (0..many).collect::<Vec<_>>()
    );
    // In lanes, one thread orders too (a chunk's lanes idle while its last runs finish), and
    // up to a chunk of runs.
    assert_eq!(p.longest_first(0..12, &one, true, &never).0, order);
    assert_ne!(
        p.longest_first(0..many as u64, &one, true, &never).0,
        (0..many).collect::<Vec<_>>()
    );
    let more = LANE_CHUNK_RUNS.max(ORDERED_RUNS_PER_THREAD * 2) + 1;
    assert_eq!(
        p.longest_first(0..more as u64, &pool, true, &never).0,
        (0..more).collect::<Vec<_>>()
    );
}

/// A campaign over a body with principal moments `principal` (a YAML list) and the given
/// `dispersions` (and campaign-level `extra` keys), as the loader prepares it.
fn prepared_body(principal: &str, extra: &str, dispersions: &str) -> Result<Prepared, String> {
    let yaml = format!(
        "name: body\n\
         body:\n  principal: {principal}\n  spin_axis: [0, 0, 1]\n\
         effectors:\n  - energy_sink: {{name: sink, time_constant: 10.0}}\n\
         initial:\n  omega: [0.05, 0.05, 2.0]\n\
         duration: 1.0\n\
         montecarlo:\n  runs: {N}\n  seed: 11\n{extra}  dispersions:\n{dispersions}"
    );
    let sc = scenario::parse(Path::new("body.yaml"), yaml, &Overrides::default())
        .map_err(|e| e.to_string())?;
    Prepared::new(sc, "body.yaml", None, None).map_err(|e| e.to_string())
}

/// Sample correlation of `a` and `b`.
fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let (ma, sa) = mean_sd(a);
    let (mb, sb) = mean_sd(b);
    let n = a.len() as f64;
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - ma) * (y - mb))
        .sum::<f64>()
        / ((n - 1.0) * sa * sb)
}

/// Φ, the standard normal distribution function.
fn phi(x: f64) -> f64 {
    0.5 * erfc(-x / std::f64::consts::SQRT_2)
}

#[test]
fn physical_inertia_keeps_explorer1s_symmetry_and_never_rejects() {
    // Explorer 1's slender hull: transverse moments 4.90, axial 0.065 kg m², the transverse
    // ones within 1 % and the axial one within 3 %.
    let p = prepared_body(
        "[4.90, 4.90, 0.065]",
        "",
        "    - {physical_inertia: {sd: [0.01, 0.01, 0.03]}}\n",
    )
    .unwrap();
    let rows = inputs(&p, N);
    let redraws = column(&p, &rows, "redraws");
    assert!(redraws.iter().all(|r| *r == 0.0), "a draw was rejected");
    let (i1, i2, i3) = (
        column(&p, &rows, "inertia_moment_1"),
        column(&p, &rows, "inertia_moment_2"),
        column(&p, &rows, "inertia_moment_3"),
    );
    for ((a, b), c) in i1.iter().zip(&i2).zip(&i3) {
        assert_eq!(
            a.to_bits(),
            b.to_bits(),
            "the transverse pair split: {a} {b}"
        );
        assert!(*c > 0.0 && a + a >= *c, "{a} {b} {c}");
    }
    // The axial moment is twice the transverse second moment J = ∫x² dm, drawn log-normal
    // with mean J: ln(I₃/0.065) is exactly N(−0.03²/2, 0.03²).
    let logs: Vec<f64> = i3.iter().map(|x| (x / 0.065).ln()).collect();
    assert_matches("ln I3", &logs, -0.00045, 0.03);
    // The transverse moments: 1 % to first order (the second-order terms, ~1e-4 of the
    // spread, are far inside the five standard errors).
    assert_matches("I1", &i1, 4.90, 0.049);
    // Independent of the axial moment, as asked.
    let r = correlation(&i1, &i3);
    assert!(r.abs() < 5.0 / (N as f64).sqrt(), "correlation {r}");
    // The run is built with those moments, as principal moments.
    let (sc, rec) = p.build_run(5).unwrap();
    let mut drawn = [rec[0], rec[1], rec[2]];
    drawn.sort_by(f64::total_cmp);
    for (k, want) in drawn.iter().enumerate() {
        assert_eq!(sc.spacecraft.hub.principal_moments[k], *want);
    }
}

#[test]
fn independent_moment_draws_reject_a_third_of_explorer1s_hull() {
    // The anchor: moments drawn each on its own, Iₖ(1 + 0.01 zₖ), break I₁ − I₂ ≤ I₃ when
    // 0.049|z₁ − z₂| > 0.065 (1 + 0.01 z₃); to the first order in 0.01,
    // p = 2 Φ(−0.065 / (0.049 √2)) ≈ 0.348, so the redraws per run are geometric with mean
    // p/(1 − p). The second-moment draw above rejects none.
    let p = prepared_body("[4.90, 4.90, 0.065]", "", "    - {inertia: {sd: 0.01}}\n").unwrap();
    let n = 5000;
    let rows = inputs(&p, n);
    let redraws = column(&p, &rows, "inertia_redraws");
    let rejected: f64 = redraws.iter().sum();
    let rate = rejected / (rejected + n as f64);
    let expected = 2.0 * phi(-0.065 / (0.049 * 2f64.sqrt()));
    let se = (expected * (1.0 - expected) / (rejected + n as f64)).sqrt();
    assert!(
        (rate - expected).abs() < 5.0 * se + 2e-3,
        "rejection rate {rate} vs {expected}"
    );
}

#[test]
fn physical_inertia_gives_each_moment_its_spread_on_a_triaxial_body() {
    // (No energy sink here: turned axes would leave the spin axis off a principal axis.)
    let p = prepared(
        "",
        "",
        "    - {physical_inertia: {sd: [0.01, 0.02, 0.03], axes_sd_deg: 1.0}}\n",
    );
    let rows = inputs(&p, N);
    let moments: Vec<Vec<f64>> = (1..=3)
        .map(|k| column(&p, &rows, &format!("inertia_moment_{k}")))
        .collect();
    for (k, (nominal, sd)) in [(2.0, 0.01), (2.1, 0.02), (1.0, 0.03)].iter().enumerate() {
        let v: Vec<f64> = moments[k].iter().map(|x| x / nominal).collect();
        assert_matches(&format!("moment {}", k + 1), &v, 1.0, *sd);
    }
    for (a, b) in [(0, 1), (0, 2), (1, 2)] {
        let r = correlation(&moments[a], &moments[b]);
        assert!(r.abs() < 5.0 / (N as f64).sqrt(), "moments {a} {b}: {r}");
    }
    // Turned axes: the hub has the drawn moments as its principal moments.
    let (sc, rec) = p.build_run(7).unwrap();
    let mut drawn = [rec[0], rec[1], rec[2]];
    drawn.sort_by(f64::total_cmp);
    for (k, want) in drawn.iter().enumerate() {
        let got = sc.spacecraft.hub.principal_moments[k];
        assert!((got - want).abs() < 1e-12 * want, "{got} vs {want}");
    }
}

#[test]
fn physical_inertia_refuses_what_no_body_can_do() {
    let err = |principal: &str, d: &str| match prepared_body(principal, "", d) {
        Ok(_) => panic!("{principal} {d}: accepted"),
        Err(e) => e,
    };
    // A flat plate has no extent across its plane: its moments cannot move apart.
    let e = err("[1.0, 1.0, 2.0]", "    - {physical_inertia: {sd: 0.01}}\n");
    assert!(e.contains("flat across principal axis 3"), "{e}");
    assert!(e.contains("montecarlo.dispersions[0]"), "{e}");
    // Equal moments move together.
    let e = err(
        "[4.90, 4.90, 0.065]",
        "    - {physical_inertia: {sd: [0.01, 0.02, 0.03]}}\n",
    );
    assert!(e.contains("need the same sd"), "{e}");
    // Explorer 1's transverse moments 1 % apart would need its radial spread to vary by
    // about 100 %.
    let e = err(
        "[4.90, 4.90, 0.065]",
        "    - {physical_inertia: {sd: [0.01, 0.01, 0.03], symmetry: break}}\n",
    );
    assert!(e.contains("cannot move that"), "{e}");
    let e = err(
        "[4.90, 4.90, 0.065]",
        "    - {physical_inertia: {sd: 0.01, symmetry: sometimes}}\n",
    );
    assert!(e.contains("expected `keep` or `break`"), "{e}");
}

#[test]
fn grouped_paths_share_one_draw() {
    let p = prepared(
        "",
        "",
        "    - {paths: [\"initial.omega[0]\", \"initial.omega[2]\"], normal: {sd: 0.01, relative: true}}\n\
         \x20   - {paths: [\"body.principal[0]\", \"body.principal[1]\"], log_normal: {sigma: 0.02}}\n",
    );
    let rows = inputs(&p, N);
    let (a, b) = (
        column(&p, &rows, "initial.omega[0]"),
        column(&p, &rows, "initial.omega[2]"),
    );
    for (x, y) in a.iter().zip(&b) {
        let (u, v) = ((x - 0.05) / 0.05, (y - 2.0) / 2.0);
        assert!((u - v).abs() < 1e-12, "{u} {v}");
    }
    assert_matches("shared relative normal", &b, 2.0, 0.02);
    let (a, b) = (
        column(&p, &rows, "body.principal[0]"),
        column(&p, &rows, "body.principal[1]"),
    );
    for (x, y) in a.iter().zip(&b) {
        assert!((x / 2.0 - y / 2.1).abs() < 1e-14, "{x} {y}");
    }
    let logs: Vec<f64> = a.iter().map(|x| (x / 2.0).ln()).collect();
    assert_matches("shared log-normal", &logs, 0.0, 0.02);
}

#[test]
fn correlated_draws_have_the_given_mean_and_covariance() {
    // Covariance of three components (correlations 0.5, −0.3 and 0), and an offset mean.
    let c = [
        [1.0e-4, 0.5e-4, 0.0],
        [0.5e-4, 1.0e-4, -0.6e-4],
        [0.0, -0.6e-4, 4.0e-4],
    ];
    let p = prepared(
        "",
        "",
        "    - {paths: [\"initial.omega[0]\", \"initial.omega[1]\", \"initial.omega[2]\"], \
         normal: {mean: [0.01, 0.0, -0.02], covariance: [[1.0e-4, 0.5e-4, 0.0], \
         [0.5e-4, 1.0e-4, -0.6e-4], [0.0, -0.6e-4, 4.0e-4]]}}\n",
    );
    let rows = inputs(&p, N);
    let n = N as f64;
    let x: Vec<Vec<f64>> = (0..3)
        .map(|k| column(&p, &rows, &format!("initial.omega[{k}]")))
        .collect();
    let mean = [0.06, 0.05, 1.98];
    let m: Vec<f64> = x.iter().map(|v| v.iter().sum::<f64>() / n).collect();
    for k in 0..3 {
        assert!(
            (m[k] - mean[k]).abs() < 5.0 * (c[k][k] / n).sqrt(),
            "mean {k}: {} vs {}",
            m[k],
            mean[k]
        );
    }
    // A Gaussian's sample covariance has variance (CᵢᵢCⱼⱼ + Cᵢⱼ²)/n.
    for i in 0..3 {
        for j in 0..3 {
            let s = x[i]
                .iter()
                .zip(&x[j])
                .map(|(a, b)| (a - m[i]) * (b - m[j]))
                .sum::<f64>()
                / (n - 1.0);
            let se = ((c[i][i] * c[j][j] + c[i][j] * c[i][j]) / n).sqrt();
            assert!(
                (s - c[i][j]).abs() < 5.0 * se,
                "covariance [{i}][{j}]: {s} vs {}",
                c[i][j]
            );
        }
    }
    // A singular covariance (correlation 1) is a shared draw.
    let p = prepared(
        "",
        "",
        "    - {path: initial.omega, normal: {covariance: [[1.0e-4, 1.0e-4, 0.0], \
         [1.0e-4, 1.0e-4, 0.0], [0.0, 0.0, 0.0]]}}\n",
    );
    for r in inputs(&p, 100) {
        assert!((r[0] - r[1]).abs() < 1e-15, "{r:?}");
        assert_eq!(r[2], 2.0);
    }
}

#[test]
fn invalid_draws_are_redrawn_from_the_runs_own_stream_and_counted() {
    // A time constant drawn from N(10, 10²) is not positive with probability p = Φ(−1):
    // the rejected draws before a valid one are geometric, mean p/(1 − p) and variance
    // p/(1 − p)², and the accepted values follow N(10, 10²) given > 0, of mean
    // 10 + 10 φ(1)/Φ(1) and variance 100 (1 − φ(1)/Φ(1) (1 + φ(1)/Φ(1))).
    let d = "    - {path: \"effectors[sink].time_constant\", normal: {sd: 10.0}}\n";
    let p = prepared_body("[2.0, 2.1, 1.0]", "", d).unwrap();
    let rows = inputs(&p, N);
    let pr = phi(-1.0);
    let (m, _) = mean_sd(&column(&p, &rows, "redraws"));
    let (mean, sd) = (pr / (1.0 - pr), pr.sqrt() / (1.0 - pr));
    assert!(
        (m - mean).abs() < 5.0 * sd / (N as f64).sqrt(),
        "mean redraws {m} vs {mean}"
    );
    let tau = column(&p, &rows, "effectors[sink].time_constant");
    assert!(tau.iter().all(|t| *t > 0.0));
    let density = (-0.5f64).exp() / (2.0 * std::f64::consts::PI).sqrt();
    let ratio = density / phi(1.0);
    assert_matches(
        "accepted time constants",
        &tau,
        10.0 + 10.0 * ratio,
        10.0 * (1.0 - ratio * (1.0 + ratio)).sqrt(),
    );
    // Reproducible: run i gives the same draws, whatever was built before it.
    for i in [3u64, 0, 17] {
        assert_eq!(p.build_run(i).unwrap().1, rows[i as usize]);
    }
    // `exclude`: the same first draws, the invalid ones recorded as such.
    let q = prepared_body("[2.0, 2.1, 1.0]", "  invalid_draws: exclude\n", d).unwrap();
    assert!(!q.columns.iter().any(|c| c == "redraws"));
    for i in 0..200u64 {
        let redrawn = rows[i as usize][1];
        match q.build_run(i) {
            Ok((_, r)) => {
                assert_eq!(redrawn, 0.0);
                assert_eq!(r[0], rows[i as usize][0]);
            }
            Err(e) => {
                assert!(redrawn > 0.0, "run {i}");
                assert!(e.message.contains("expected a positive"), "{}", e.message);
            }
        }
    }
}
