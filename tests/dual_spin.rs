//! Dual-spin stability: the nonlinear runs of the shipped dual-spin scenarios against the
//! eigenvalues of `polhode linearize` about their steady states, the weighted (dual-spin)
//! energy-sink estimate in the CLI, and the despin manoeuvre's conservation and end state.

mod common;

use common::run;
use polhode::linearize::{Linearization, linearize, spin_rate_of};
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
