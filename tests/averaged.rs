//! `method: averaged` (docs/averaging.md) against references it did not produce: the exact
//! torque-free solution, the closed-form nutation growth of an axisymmetric body with an
//! energy sink, the closed-form |H| decay of an axisymmetric body under isotropic Rayleigh
//! damping, and full integrations with dop853 across the separatrix.

mod common;

use common::{run, scenario, scenario_with};
use nalgebra::{Matrix3, Vector3};
use polhode::exact::TorqueFreeSolution;
use polhode::scenario::Overrides;
use polhode::sim::{Method, Status};
use std::path::Path;

fn averaged() -> Overrides {
    Overrides {
        method: Some("averaged".into()),
        ..Overrides::default()
    }
}

fn file(path: &str, ov: &Overrides) -> polhode::scenario::Scenario {
    polhode::scenario::load(Path::new(path), ov).unwrap()
}

/// The sample at time `t` (on the output grid).
fn at(samples: &[polhode::model::Observation], t: f64) -> &polhode::model::Observation {
    samples
        .iter()
        .find(|o| (o.t - t).abs() < 1e-9)
        .unwrap_or_else(|| panic!("no sample at {t}"))
}

#[test]
fn without_dissipation_it_is_the_exact_torque_free_motion() {
    // With nothing to average the slow state is constant, and the rebuilt state must be the
    // closed form's at every sample: phase and precession bookkeeping included.
    for (principal, omega) in [
        ([2.0, 3.0, 4.0], [1.0, 0.3, 0.2]),
        ([2.0, 3.0, 4.0], [0.1, 0.4, 1.0]),
        ([0.15, 4.95, 4.95], [78.5, 0.08, 0.05]),
    ] {
        let yaml = format!(
            "name: free\nbody: {{principal: [{}, {}, {}]}}\n\
             initial: {{omega: [{}, {}, {}], attitude: {{w: 0.8, x: 0.2, y: -0.4, z: 0.4}}}}\n\
             duration: 500\nintegrator: {{method: averaged, rtol: 1.0e-10}}\noutput: {{rate: 2}}\n",
            principal[0], principal[1], principal[2], omega[0], omega[1], omega[2]
        );
        let s = scenario(&yaml);
        let (out, rec) = run(&s);
        assert!(matches!(out.status, Status::Complete));
        let inertia = Matrix3::from_diagonal(&Vector3::from(principal));
        let exact = TorqueFreeSolution::new(&inertia, &s.omega0, &s.attitude0).unwrap();
        let mut worst: f64 = 0.0;
        for o in &rec.samples {
            let (w, q) = exact.state_at(o.t);
            worst = worst.max((o.omega - w).amax() / w.norm());
            worst = worst.max(o.attitude.angle_to(&q));
        }
        assert!(worst < 1e-9, "{principal:?} {omega:?}: off by {worst:e}");
        assert!(rec.samples.len() == 1001);
    }
}

#[test]
fn explorer_1s_energy_sink_nutation_grows_as_the_closed_form() {
    // Axisymmetric body (I_s spin, I_t transverse) with the sink τ = −c ω⊥ at fixed |H|:
    // θ̇ = c (1/I_s − 1/I_t) sin θ cos θ, so tan θ = tan θ₀ e^{t/τ}, 1/τ = c (I_t − I_s)/(I_s I_t)
    // (derivation in docs/averaging.md). The 45° and 80° crossings follow in closed form.
    let s = file("scenarios/explorer1-energy-sink.yaml", &averaged());
    let (out, rec) = run(&s);
    assert!(matches!(out.status, Status::Complete));
    let (i_s, i_t) = (0.1501585, 4.9483213);
    // The coefficient the loader solved from `time_constant`: the sink's power over |ω⊥|².
    let o = &rec.samples[0];
    let h = o.h_body.normalize();
    let perp = o.omega - h * o.omega.dot(&h);
    let c = o.dissipation_power / perp.norm_squared();
    let tau = i_s * i_t / (c * (i_t - i_s));
    let theta0 = rec.samples[0].nutation_angle;
    let crossing = |deg: f64| tau * (deg.to_radians().tan() / theta0.tan()).ln();
    assert_eq!(out.events.len(), 2);
    for (e, deg) in out.events.iter().zip([45.0, 80.0]) {
        let want = crossing(deg);
        assert!(
            ((e.t - want) / want).abs() < 1e-6,
            "{deg}°: {} s against the closed form's {want} s",
            e.t
        );
    }
    // 80° within 0.1 % of the full integration (dop853, rtol 1e-10: 10166.784 s).
    assert!((out.events[1].t / 10166.784 - 1.0).abs() < 1e-3);
}

#[test]
fn across_the_separatrix_the_energy_follows_the_full_integration() {
    let full = file("scenarios/triaxial-energy-sink.yaml", &Overrides::default());
    let avg = file("scenarios/triaxial-energy-sink.yaml", &averaged());
    let (_, a) = run(&full);
    let (out, b) = run(&avg);
    assert!(matches!(out.status, Status::Complete));
    // Before, near and after the crossing (about 2690 s) and toward the flat spin.
    for t in [1000.0, 2500.0, 3000.0, 5000.0] {
        let (ta, tb) = (
            at(&a.samples, t).kinetic_energy,
            at(&b.samples, t).kinetic_energy,
        );
        assert!(
            ((tb - ta) / ta).abs() < 5e-4,
            "T({t} s): {tb} J against {ta} J"
        );
    }
    // Both circulations were visited: about axis 1 first (H closest to it), axis 3 last.
    let first = &b.samples[0];
    let last = b.samples.last().unwrap();
    // (Angles from ω to either end of an axis: which pole is taken is the fast phase's call.)
    let off_axis = |a: f64| a.min(std::f64::consts::PI - a).to_degrees();
    assert!(off_axis(first.angles_to_principal[0]) < 10.0);
    assert!(off_axis(last.angles_to_principal[2]) < 20.0);
    // The sink keeps |H| and the balance T + W closes.
    for o in &b.samples {
        assert!((o.h_norm / first.h_norm - 1.0).abs() < 1e-12);
        assert!((o.energy_balance() / first.energy_balance() - 1.0).abs() < 1e-12);
    }
}

#[test]
fn isotropic_rayleigh_damping_drains_h_as_the_closed_form() {
    // Axisymmetric body, τ = −γ ω: I_s ω̇_s = −γ ω_s and the transverse rate's magnitude decays
    // as e^{−γ t / I_t}, so |H|² = I_s² ω_s0² e^{−2γt/I_s} + I_t² ω_t0² e^{−2γt/I_t}.
    let (i_s, i_t, gamma) = (2.0_f64, 5.0_f64, 0.0005_f64);
    let (ws, wt) = (3.0_f64, 0.4_f64);
    let yaml = format!(
        "name: rayleigh\nbody: {{principal: [{i_s}, {i_t}, {i_t}]}}\n\
         effectors:\n  - rayleigh: {{name: drag, gamma_diagonal: [{gamma}, {gamma}, {gamma}]}}\n\
         initial: {{omega: [{ws}, {wt}, 0.0]}}\nduration: 5000\n\
         integrator: {{method: averaged, rtol: 1.0e-10}}\noutput: {{rate: 0.1}}\n"
    );
    let (out, rec) = run(&scenario(&yaml));
    assert!(matches!(out.status, Status::Complete), "{:?}", out.status);
    for o in &rec.samples {
        let t = o.t;
        let h = ((i_s * ws).powi(2) * (-2.0 * gamma * t / i_s).exp()
            + (i_t * wt).powi(2) * (-2.0 * gamma * t / i_t).exp())
        .sqrt();
        assert!(
            (o.h_norm / h - 1.0).abs() < 1e-8,
            "|H|({t} s) = {} against {h}",
            o.h_norm
        );
    }
}

#[test]
fn anisotropic_rayleigh_damping_follows_the_full_integration() {
    let yaml = |method: &str| {
        format!(
            "name: rayleigh\nbody: {{principal: [2.0, 3.0, 4.0]}}\n\
             effectors:\n  - rayleigh: {{name: drag, gamma_diagonal: [0.0008, 0.0002, 0.0004]}}\n\
             initial: {{omega: [0.3, 0.5, 2.0]}}\nduration: 3000\n\
             integrator: {{method: {method}, rtol: 1.0e-10, atol: 1.0e-12}}\n\
             output: {{rate: 0.02}}\n"
        )
    };
    let (_, a) = run(&scenario(&yaml("dop853")));
    let (out, b) = run(&scenario(&yaml("averaged")));
    assert!(matches!(out.status, Status::Complete), "{:?}", out.status);
    assert_eq!(a.samples.len(), b.samples.len());
    let (mut dh, mut dt): (f64, f64) = (0.0, 0.0);
    for (x, y) in a.samples.iter().zip(&b.samples) {
        dh = dh.max((y.h_norm / x.h_norm - 1.0).abs());
        dt = dt.max((y.kinetic_energy / x.kinetic_energy - 1.0).abs());
    }
    assert!(dh < 1e-4 && dt < 1e-4, "|H| within {dh:e}, T within {dt:e}");
    // It did drain |H| (by more than the tolerance above).
    let last = b.samples.last().unwrap();
    assert!(last.h_norm < 0.9 * b.samples[0].h_norm);
}

#[test]
fn it_stops_with_a_diagnosis_where_dissipation_is_too_fast() {
    // Slow at first (small nutation), then the sink drains T within a few polhode periods.
    let yaml = std::fs::read_to_string("scenarios/triaxial-energy-sink.yaml")
        .unwrap()
        .replace("coefficient: 0.006", "coefficient: 3.0");
    let s = scenario_with(&yaml, &averaged());
    let (out, _) = run(&s);
    match &out.status {
        Status::Failed { diagnosis } => {
            assert!(
                diagnosis.contains("averaging no longer holds"),
                "{diagnosis}"
            );
            assert!(diagnosis.contains("dissipation time"), "{diagnosis}");
        }
        other => panic!("{other:?}"),
    }
    // Too fast from the start: refused before any step.
    let yaml = yaml.replace("omega: [10.0, 0.3, 0.3]", "omega: [10.0, 3.0, 3.0]");
    let s = scenario_with(&yaml, &averaged());
    let (out, rec) = run(&s);
    match &out.status {
        Status::Failed { diagnosis } => assert!(diagnosis.contains("fast period"), "{diagnosis}"),
        other => panic!("{other:?}"),
    }
    assert!(rec.samples.len() <= 1);
}

#[test]
fn scenes_it_cannot_average_are_refused_naming_the_effector() {
    for (path, effector, why) in [
        (
            "scenarios/wheel-damper.yaml",
            "wheel",
            "internal degrees of freedom",
        ),
        (
            "scenarios/gravity-gradient-smallsat.yaml",
            "gravity_gradient",
            "environmental or control torque",
        ),
    ] {
        let e = polhode::scenario::load(Path::new(path), &averaged()).unwrap_err();
        let text = e.to_string();
        assert!(text.contains(&format!("`{effector}`")), "{text}");
        assert!(text.contains(why), "{text}");
        assert!(text.contains("--method"), "{text}");
    }
}

#[test]
fn auto_never_picks_it() {
    let ov = Overrides {
        method: Some("auto".into()),
        ..Overrides::default()
    };
    for path in [
        "scenarios/explorer1-energy-sink.yaml",
        "scenarios/triaxial-energy-sink.yaml",
    ] {
        let s = file(path, &ov);
        assert!(!matches!(s.method, Method::Averaged(_)), "{path}");
    }
}

/// `polhode montecarlo FILE --method M --runs N` into a fresh directory; its summary.
fn campaign(method: &str, runs: u32) -> serde_json::Value {
    let out = std::env::temp_dir().join(format!(
        "polhode-averaged-mc-{}-{method}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&out);
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_polhode"))
        .args([
            "montecarlo",
            "tests/data/montecarlo-averaged.yaml",
            "--quiet",
        ])
        .args(["--method", method, "--runs", &runs.to_string(), "--out"])
        .arg(&out)
        .status()
        .unwrap();
    assert!(status.success());
    let text = std::fs::read_to_string(out.join("summary.json")).unwrap();
    let _ = std::fs::remove_dir_all(&out);
    serde_json::from_str(&text).unwrap()
}

#[test]
fn an_averaged_campaign_gives_the_full_campaigns_event_probabilities() {
    let full = campaign("dop853", 60);
    let averaged = campaign("averaged", 60);
    assert_eq!(averaged["status"]["complete"], 60);
    let (fe, ae) = (
        full["events"].as_array().unwrap(),
        averaged["events"].as_array().unwrap(),
    );
    assert_eq!(fe.len(), 2);
    for (f, a) in fe.iter().zip(ae) {
        for (bf, ba) in f["by"]
            .as_array()
            .unwrap()
            .iter()
            .zip(a["by"].as_array().unwrap())
        {
            let p = ba["probability"].as_f64().unwrap();
            let (lo, hi) = (
                bf["ci95"][0].as_f64().unwrap(),
                bf["ci95"][1].as_f64().unwrap(),
            );
            assert!(
                (lo..=hi).contains(&p),
                "{} by {} s: {p} outside the full campaign's [{lo}, {hi}]",
                f["condition"],
                bf["t"]
            );
        }
    }
}

#[test]
fn explorer_1s_hinged_antennas_reach_the_flat_spin_with_the_full_model() {
    // The full multibody run (dop853, rtol 1e-8; docs/explorer1.md): 45° at 95.9 min and 80°
    // at 111.1 min. The averaged run tabulates the antennas' dissipation over the coupled
    // periodic orbits of the undamped spacecraft.
    let s = file("scenarios/explorer1.yaml", &averaged());
    let (out, rec) = run(&s);
    assert!(matches!(out.status, Status::Complete), "{:?}", out.status);
    assert_eq!(out.events.len(), 2);
    for (e, full) in out.events.iter().zip([95.9 * 60.0, 111.1 * 60.0]) {
        assert!(
            ((e.t - full) / full).abs() < 0.02,
            "{}: {} s against the full model's {full} s",
            e.condition,
            e.t
        );
    }
    // The small-nutation growth is the coupled linearisation's eigenvalue (an independent
    // computation: `polhode linearize`), not the one-way energy-sink estimate 17 % below it.
    let nominal = file("scenarios/explorer1.yaml", &Overrides::default());
    let lin: serde_json::Value =
        serde_json::from_str(&polhode::cli::linearize_json(&nominal).unwrap()).unwrap();
    let tau_lin = lin["nutation"]["time_constant"].as_f64().unwrap();
    let theta0 = rec.samples[0].nutation_angle;
    let o = at(&rec.samples, 1500.0);
    let tau = 1500.0 / (o.nutation_angle.tan() / theta0.tan()).ln();
    assert!(
        (tau / tau_lin - 1.0).abs() < 0.01,
        "growth time constant {tau} s against the linearisation's {tau_lin} s"
    );
    // |H| is kept and the energy balance closes.
    let first = &rec.samples[0];
    for o in &rec.samples {
        assert!((o.h_norm / first.h_norm - 1.0).abs() < 1e-9);
        assert!((o.energy_balance() / first.energy_balance() - 1.0).abs() < 1e-9);
    }
}
