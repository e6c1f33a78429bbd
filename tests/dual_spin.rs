//! Dual-spin stability: the nonlinear runs of the shipped dual-spin scenarios against the
//! eigenvalues of `polhode linearize` about their steady states, the weighted (dual-spin)
//! energy-sink estimate against those eigenvalues, and the despin manoeuvre's conservation
//! and end state.

mod common;

use common::run;
use polhode::linearize::{DualSpinEnergySink, Linearization, linearize, spin_rate_of};
use polhode::model::Observation;
use polhode::scenario::{self, Overrides, Scenario};
use polhode::sim::Status;
use std::path::Path;

fn load(name: &str) -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios")
        .join(name);
    scenario::load(&path, &Overrides::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// The exponential rate of the nutation angle over `[t0, t1]`: the least-squares slope of
/// ln θ against t (the damper's own mode has died out by t0).
fn fitted_rate(samples: &[Observation], t0: f64, t1: f64) -> f64 {
    let pts: Vec<(f64, f64)> = samples
        .iter()
        .filter(|o| o.t >= t0 && o.t <= t1)
        .map(|o| (o.t, o.nutation_angle.ln()))
        .collect();
    let n = pts.len() as f64;
    let (st, sy) = pts
        .iter()
        .fold((0.0, 0.0), |(a, b), &(t, y)| (a + t, b + y));
    let (mt, my) = (st / n, sy / n);
    let (num, den) = pts.iter().fold((0.0, 0.0), |(a, b), &(t, y)| {
        (a + (t - mt) * (y - my), b + (t - mt) * (t - mt))
    });
    num / den
}

/// The linearisation about the scenario's steady state.
fn linearization(s: &Scenario) -> Linearization {
    let w = spin_rate_of(&s.spacecraft, &s.omega0);
    linearize(&s.spacecraft, w).unwrap_or_else(|e| panic!("{e}"))
}

/// The nutation eigenvalue's real part (1/s) of the scenario's steady state.
fn nutation_rate(s: &Scenario) -> f64 {
    linearization(s).nutation.expect("a nutation mode").rate
}

/// The weighted (dual-spin) energy-sink estimate of the scenario's nutation rate.
fn weighted_estimate(s: &Scenario) -> DualSpinEnergySink {
    linearization(s)
        .nutation
        .expect("a nutation mode")
        .dual_spin_energy_sink
        .expect("a weighted energy-sink estimate")
}

/// The scenario's YAML with its 5 kg damper's stiffness and damping replaced: natural
/// frequency `ratio` × `lambda` (rad/s), damping ratio `zeta`; its mass scaled by
/// `mass_scale`.
fn retuned(name: &str, lambda: f64, ratio: f64, zeta: f64, mass_scale: f64) -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios")
        .join(name);
    let text = std::fs::read_to_string(path).unwrap();
    let mass = 5.0 * mass_scale;
    let stiffness = mass * (ratio * lambda).powi(2);
    let damping = 2.0 * zeta * (stiffness * mass).sqrt();
    let damper: String = text
        .lines()
        .map(|l| {
            let key = l.trim_start();
            let indent = &l[..l.len() - key.len()];
            let line = if key.starts_with("mass: 5.0") {
                format!("{indent}mass: {mass}")
            } else if key.starts_with("stiffness:") {
                format!("{indent}stiffness: {stiffness}")
            } else if key.starts_with("damping:") {
                format!("{indent}damping: {damping}")
            } else {
                l.to_string()
            };
            line + "\n"
        })
        .collect();
    common::scenario(&damper)
}

/// The damper on the despun platform damps the nutation of a minor-axis dual-spin
/// spacecraft; the nonlinear decay rate is the eigenvalue's within 5%.
#[test]
fn a_platform_damper_stabilises_the_minor_axis_dual_spin() {
    let s = load("dual-spin.yaml");
    let predicted = nutation_rate(&s);
    assert!(predicted < 0.0, "{predicted}");
    let (out, rec) = run(&s);
    assert_eq!(out.status, Status::Complete);
    let measured = fitted_rate(&rec.samples, 30.0, 200.0);
    let rel = (measured - predicted).abs() / predicted.abs();
    eprintln!("dual-spin: decay {measured:.5e} 1/s, eigenvalue {predicted:.5e} (rel {rel:.4})");
    assert!(
        rel < 0.05,
        "decay rate {measured:.5e} 1/s against the eigenvalue's {predicted:.5e} (rel {rel:.3})"
    );
}

/// The same spacecraft spinning as one body (rotor held at rest relative to it): the damper
/// now drives the minor-axis spin away; the nonlinear growth rate at small angles is the
/// eigenvalue's within 5%, and it reaches a flat spin.
#[test]
fn spinning_as_one_body_the_same_spacecraft_goes_flat() {
    let s = load("dual-spin-all-spun.yaml");
    let predicted = nutation_rate(&s);
    assert!(predicted > 0.0, "{predicted}");
    let (out, rec) = run(&s);
    assert_eq!(out.status, Status::Complete);
    // From 0.6° at the start to about 6° by 120 s: small enough to be linear.
    let measured = fitted_rate(&rec.samples, 20.0, 120.0);
    let rel = (measured - predicted).abs() / predicted;
    eprintln!("all-spun: growth {measured:.5e} 1/s, eigenvalue {predicted:.5e} (rel {rel:.4})");
    assert!(
        rel < 0.05,
        "growth rate {measured:.5e} 1/s against the eigenvalue's {predicted:.5e} (rel {rel:.3})"
    );
    assert!(out.events.iter().any(|e| e.condition.contains("above 80")));
}

/// The despin manoeuvre: the motor's torque is internal, so H_N is kept while the platform
/// goes from 44.45 rpm to rest, and the rotor ends at its commanded 60 rpm relative rate.
#[test]
fn the_despin_manoeuvre_keeps_h_n_and_ends_despun() {
    let s = load("dual-spin-despin.yaml");
    let (out, rec) = run(&s);
    assert_eq!(out.status, Status::Complete);
    let h0 = rec.samples[0].h_inertial;
    let worst = rec
        .samples
        .iter()
        .map(|o| (o.h_inertial - h0).norm() / h0.norm())
        .fold(0.0, f64::max);
    assert!(worst < 1e-10, "H_N drift {worst:e}");
    let end = &out.final_observation;
    assert!(
        end.omega.norm() < 1e-4,
        "platform rate at the end {:?}",
        end.omega
    );
    // The rotor's command as written in the scenario (60 rpm rounded to 6.2832 rad/s).
    #[allow(clippy::approx_constant)]
    let commanded = 6.2832;
    let rotor_rate = out.final_state[7];
    assert!((rotor_rate - commanded).abs() < 1e-6, "{rotor_rate}");
    let despun = out
        .events
        .iter()
        .find(|e| e.condition.contains("omega_z"))
        .expect("the platform despins");
    // Torque-limited: Δω = 4.65458 rad/s at 20 N m on the platform's 104.969 kg m² (all but
    // the rotor's 300), about 24.4 s.
    assert!((despun.t - 24.4).abs() < 0.5, "despun at {} s", despun.t);
}

/// The same spacecraft with the damper on the rotor (the hub is the rotor, the despun
/// platform a wheel held at minus its rate): the same locked inertia and |H| as
/// dual-spin.yaml, and the damper now drives the nutation. The nonlinear growth rate at small
/// angles is the eigenvalue's within 5%, the weighted energy-sink estimate has the
/// eigenvalue's sign, and the spacecraft goes flat.
#[test]
fn a_rotor_damper_drives_the_same_spacecraft_flat() {
    let platform = load("dual-spin.yaml");
    let s = load("dual-spin-rotor-damper.yaml");
    let (lin_p, lin_r) = (linearization(&platform), linearization(&s));
    for (a, b) in lin_p.principal_moments.iter().zip(lin_r.principal_moments) {
        assert!((a - b).abs() < 1e-9 * a, "locked inertia {a} against {b}");
    }
    let momentum = |s: &Scenario| {
        let y = s.spacecraft.initial_state(&s.omega0, &s.attitude0);
        s.spacecraft.invariants(0.0, &y).h_body.z
    };
    let (h_p, h_r) = (momentum(&platform), momentum(&s));
    // Both start with 0.6° of nutation: H·ẑ is |H| cos 0.6° in both; 1885 N m s written to
    // five figures in each.
    assert!((h_p - h_r).abs() < 1e-4 * h_p, "H·z {h_p} against {h_r}");

    let predicted = lin_r.nutation.clone().expect("a nutation mode").rate;
    assert!(predicted > 0.0, "{predicted}");
    let estimate = weighted_estimate(&s);
    assert!(estimate.rate > 0.0, "{estimate:?}");
    let (out, rec) = run(&s);
    assert_eq!(out.status, Status::Complete);
    // From 0.6° at the start to about 4.5° at 20 s: small enough to be linear; the damper's
    // own mode (1.8 s) has died out by 5 s.
    let measured = fitted_rate(&rec.samples, 5.0, 20.0);
    let rel = (measured - predicted).abs() / predicted;
    eprintln!(
        "rotor damper: growth {measured:.5e} 1/s, eigenvalue {predicted:.5e} (rel {rel:.4}), \
         weighted estimate {:.5e}",
        estimate.rate
    );
    assert!(
        rel < 0.05,
        "growth rate {measured:.5e} 1/s against the eigenvalue's {predicted:.5e} (rel {rel:.3})"
    );
    assert!(out.events.iter().any(|e| e.condition.contains("above 80")));
}

/// The weighted energy-sink estimate against the eigenvalues: the same 5 kg damper, 1 m off
/// the axis, on the despun platform (dual-spin.yaml) and on the rotor
/// (dual-spin-rotor-damper.yaml), retuned to twice the nutation frequency seen in its body and
/// lightly damped (damping ratio 0.05). The energy-sink argument drops the damper's reaction on
/// the motion, an effect first order in its inertia ratio ε = μ r²/I_t (μ = 4.97 kg reduced
/// mass, r = 1 m, I_t = 1000 kg m²: ε = 0.005), amplified near resonance by
/// ω_d²/|ω_d² − λ²| = 4/3 here: the estimate must agree within 2ε = 1%, with the sign right
/// (platform damper: decay; rotor damper: growth). With a tenth of the damper's mass the
/// error must fall tenfold (first order in ε: within 0.2 of the error at full mass).
/// Tuned near the nutation frequency it is only approximate: the table printed here is the
/// one in docs/actuators.md.
#[test]
fn the_weighted_estimate_matches_the_eigenvalue_for_a_detuned_damper() {
    let epsilon = 4.968944 * 1.0 / 1000.0;
    for (name, stable) in [
        ("dual-spin.yaml", true),
        ("dual-spin-rotor-damper.yaml", false),
    ] {
        let lambda = linearization(&load(name)).rigid_body_prediction.frequency;
        let case = |ratio: f64, zeta: f64, mass_scale: f64| {
            let lin = linearization(&retuned(name, lambda, ratio, zeta, mass_scale));
            let nut = lin.nutation.expect("a nutation mode");
            let w = nut.dual_spin_energy_sink.expect("a weighted estimate");
            (nut.rate, w.rate, w.relative_difference)
        };
        let (eigen, estimate, rel) = case(2.0, 0.05, 1.0);
        eprintln!(
            "{name}, ω_d = 2|λ|, ζ = 0.05: eigenvalue {eigen:.6e}, estimate {estimate:.6e} (rel {rel:+.5})"
        );
        assert_eq!(eigen < 0.0, stable, "{eigen}");
        assert_eq!(estimate < 0.0, stable, "{estimate}");
        assert!(rel.abs() < 2.0 * epsilon, "{name}: rel {rel}");
        let (_, _, rel_light) = case(2.0, 0.05, 0.1);
        assert!(
            rel_light.abs() < 0.2 * rel.abs(),
            "{name}: a tenth of the mass leaves rel {rel_light} against {rel}"
        );
        // The table of docs/actuators.md: natural frequency / |λ| and damping ratio.
        eprintln!("{name} (|λ| = {lambda:.4} rad/s): ω_d/|λ|, ζ, eigenvalue, estimate, rel");
        for ratio in [0.5, 0.9, 1.0, 1.1, 2.0] {
            for zeta in [0.01, 0.1, 0.5] {
                let (eigen, estimate, rel) = case(ratio, zeta, 1.0);
                eprintln!(
                    "| {ratio} | {zeta} | {eigen:+.4e} | {estimate:+.4e} | {:+.1}% |",
                    100.0 * rel
                );
            }
        }
    }
}

/// `polhode linearize` prints the weighted estimate beside the eigenvalue, and `--json` has
/// it with its relative difference, the frequencies seen in each body and the damper's share.
#[test]
fn the_cli_prints_the_weighted_estimate() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/dual-spin.yaml");
    let bin = env!("CARGO_BIN_EXE_polhode");
    let text = std::process::Command::new(bin)
        .arg("linearize")
        .arg(&path)
        .output()
        .unwrap();
    assert!(text.status.success());
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(
        text.contains("weighted (dual-spin) energy-sink estimate: -2.")
            && text.contains("% from the eigenvalue"),
        "{text}"
    );
    let json = std::process::Command::new(bin)
        .args(["linearize", "--json", "-"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(json.status.success());
    let v: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    let w = &v["nutation"]["dual_spin_energy_sink"];
    let rate = w["rate"].as_f64().unwrap();
    let eigen = v["nutation"]["rate"].as_f64().unwrap();
    let rel = w["relative_difference"].as_f64().unwrap();
    assert!((rel - (rate - eigen) / eigen.abs()).abs() < 1e-12, "{w}");
    assert_eq!(w["bodies"][0]["body"], "hub");
    assert_eq!(w["bodies"][1]["body"], "rotor");
    assert_eq!(w["sinks"][0]["effector"], "damper");
}
