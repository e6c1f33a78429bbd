//! The integration methods on polhode's own equations: convergence orders, conservation
//! claims, behaviour above the explicit stability bound, and `auto`'s choices
//! (docs/choosing-a-method.md). Each integrator also has unit tests on small ODEs.

use polhode::bench::attitude_error;
use polhode::integrate::Stepper;
use polhode::scenario::{self, Method, Overrides, Scenario};
use polhode::sim::{self, Control, LieStepper, NullSink, Status};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn method(name: &str) -> Overrides {
    Overrides {
        method: Some(name.into()),
        ..Overrides::default()
    }
}

fn load(file: &str, ov: Overrides) -> Scenario {
    scenario::load(&root().join(file), &ov).expect("valid scenario")
}

fn parse(yaml: &str, ov: Overrides) -> Scenario {
    scenario::parse(Path::new("inline.yaml"), yaml.into(), &ov).expect("valid scenario")
}

fn final_state(s: &Scenario) -> Vec<f64> {
    sim::integrate_only(s, s.duration)
        .expect("solve completes")
        .final_state
}

/// Attitude and ω error of `y` against `r`, combined into one number.
fn error(r: &[f64], y: &[f64]) -> f64 {
    let dw = (0..3).map(|i| (y[i] - r[i]).powi(2)).sum::<f64>().sqrt();
    attitude_error(&r[3..7], &y[3..7]).max(dw)
}

/// Least-squares slope of log(error) against log(h).
fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (xs, ys): (Vec<f64>, Vec<f64>) = points.iter().map(|(h, e)| (h.ln(), e.ln())).unzip();
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx).powi(2)).sum();
    sxy / sxx
}

/// A spinning hub with a Rayleigh damper: the splitting's B part (the torque) is not zero,
/// and the reference is dop853 at rtol 1e-13.
const DAMPED: &str = "
name: damped
body: {principal: [1.0, 2.0, 3.0], spin_axis: [0, 0, 1]}
effectors:
  - rayleigh: {name: drag, gamma: [[0.05, 0.01, 0], [0.01, 0.08, 0], [0, 0, 0.03]]}
initial: {omega: [0.4, 0.7, 1.1]}
duration: 8.0
";

/// Observed order of a fixed-step method: errors at steps h, h/2, …, against `reference`.
fn observed_order(yaml: &str, ov: &Overrides, steps: &[f64], reference: &[f64]) -> f64 {
    let points: Vec<(f64, f64)> = steps
        .iter()
        .map(|&dt| {
            let s = parse(
                yaml,
                Overrides {
                    dt: Some(dt),
                    ..ov.clone()
                },
            );
            // The attitude integrates ω, so its error carries both.
            let y = final_state(&s);
            (dt, attitude_error(&reference[3..7], &y[3..7]))
        })
        .collect();
    eprintln!("{:?}: {points:?}", ov.method);
    slope(&points)
}

fn damped_reference() -> Vec<f64> {
    let s = parse(
        DAMPED,
        Overrides {
            method: Some("dop853".into()),
            rtol: Some(1e-14),
            atol: Some(1e-16),
            ..Overrides::default()
        },
    );
    final_state(&s)
}

#[test]
fn fixed_step_methods_converge_at_their_nominal_order_on_a_damped_spacecraft() {
    let reference = damped_reference();
    // (method, stages, order, nominal order, steps)
    type Case = (&'static str, Option<u32>, Option<u32>, f64, [f64; 4]);
    let cases: [Case; 6] = [
        ("rk4", None, None, 4.0, [0.2, 0.1, 0.05, 0.025]),
        ("lie", None, None, 4.0, [0.2, 0.1, 0.05, 0.025]),
        ("splitting", None, Some(2), 2.0, [0.2, 0.1, 0.05, 0.025]),
        ("splitting", None, Some(4), 4.0, [0.4, 0.2, 0.1, 0.05]),
        ("gauss", Some(1), None, 2.0, [0.2, 0.1, 0.05, 0.025]),
        ("gauss", Some(2), None, 4.0, [0.4, 0.2, 0.1, 0.05]),
    ];
    for (name, stages, order, nominal, steps) in cases {
        let ov = Overrides {
            stages,
            order,
            ..method(name)
        };
        let p = observed_order(DAMPED, &ov, &steps, &reference);
        assert!(
            (p - nominal).abs() <= 0.3,
            "{name} stages {stages:?} order {order:?}: observed order {p}, nominal {nominal}"
        );
    }
}

#[test]
fn explicit_embedded_methods_converge_at_their_nominal_order_with_the_step_held_fixed() {
    // Tolerances so loose every step is accepted, and max_step fixes the step.
    let reference = damped_reference();
    for (name, nominal, steps) in [
        ("dopri5", 5.0, [0.2, 0.1, 0.05, 0.025]),
        ("dop853", 8.0, [0.8, 0.4, 0.2, 0.1]),
    ] {
        let points: Vec<(f64, f64)> = steps
            .iter()
            .map(|&h| {
                let yaml = format!(
                    "{DAMPED}integrator: {{method: {name}, rtol: 1.0e+3, atol: 1.0e+3, \
                     max_step: {h}}}\n"
                );
                let s = parse(&yaml, Overrides::default());
                (h, error(&reference, &final_state(&s)))
            })
            .collect();
        let p = slope(&points);
        eprintln!("{name}: {points:?} → {p}");
        assert!((p - nominal).abs() <= 0.3, "{name}: observed order {p}");
    }
}

#[test]
fn splitting_is_the_exact_flow_for_a_torque_free_body_at_any_step() {
    let exact = final_state(&load("scenarios/generic-tumble.yaml", {
        Overrides {
            duration: Some(100.0),
            ..method("exact")
        }
    }));
    for dt in [2.0, 0.5] {
        let s = load(
            "scenarios/generic-tumble.yaml",
            Overrides {
                dt: Some(dt),
                duration: Some(100.0),
                ..method("splitting")
            },
        );
        let e = error(&exact, &final_state(&s));
        assert!(e < 1e-10, "dt {dt}: error {e}");
    }
}

fn run_quietly(s: &Scenario) -> sim::Outcome {
    let interrupt = AtomicBool::new(false);
    sim::run(
        s,
        &mut NullSink,
        Control {
            interrupt: &interrupt,
            progress: None,
        },
    )
    .expect("no I/O")
}

#[test]
fn gauss_keeps_energy_and_momentum_over_1e5_seconds_of_free_tumbling() {
    for stages in [2, 1] {
        let mut s = load(
            "scenarios/generic-tumble.yaml",
            Overrides {
                dt: Some(0.5),
                stages: Some(stages),
                duration: Some(1e5),
                ..method("gauss")
            },
        );
        s.output_rate = 1e-3;
        let o = run_quietly(&s);
        assert_eq!(o.status, Status::Complete);
        assert_eq!(o.stats.steps, 200_000);
        eprintln!("gauss-{stages}: {:?}", o.drift);
        assert!(
            o.drift.energy_rel <= 1e-12,
            "T drift {}",
            o.drift.energy_rel
        );
        assert!(
            o.drift.h_norm_rel <= 1e-12,
            "|H| drift {}",
            o.drift.h_norm_rel
        );
    }
}

#[test]
fn lie_keeps_the_quaternion_unit_over_a_million_steps() {
    let s = load("scenarios/generic-tumble.yaml", method("exact"));
    let sc = &s.spacecraft;
    let y0 = sc.initial_state(&s.omega0, &s.attitude0);
    let mut lie = LieStepper::new(0.0, &y0, 0.01);
    let mut worst: f64 = 0.0;
    for _ in 0..1_000_000 {
        lie.step(sc, f64::INFINITY).expect("lie never fails");
        let q = &lie.y()[3..7];
        let norm = q.iter().map(|c| c * c).sum::<f64>().sqrt();
        worst = worst.max((norm - 1.0).abs());
    }
    eprintln!(
        "max ||q| − 1| = {worst:e}; largest rounding correction {:e}",
        lie.largest_rounding_correction()
    );
    assert!(worst <= 1e-14, "||q| − 1| reached {worst:e}");
    // What was divided out is accumulated rounding (a few ulp), never truncation error.
    assert!(lie.largest_rounding_correction() <= 8.0 * f64::EPSILON);
    // rk4 on the same run leaves the sphere by far more.
    let mut s4 = s;
    s4.method = Method::Rk4 { dt: 0.2 };
    s4.duration = 2000.0;
    let y = final_state(&s4);
    let norm = y[3..7].iter().map(|c| c * c).sum::<f64>().sqrt();
    assert!((norm - 1.0).abs() > 1e-10, "rk4 |q| − 1 = {:e}", norm - 1.0);
}

/// A hub with a stiff spring-mass damper: ω_n = √(k/m) = 1e3 rad/s against a 1 rad/s spin.
const STIFF: &str = "
name: stiff
body: {mass: 100.0, principal: [10.0, 12.0, 15.0], spin_axis: [0, 0, 1]}
effectors:
  - spring_mass_damper:
      {name: damper, mass: 1.0, position: [0.5, 0, 0], direction: [0, 0, 1],
       stiffness: 1.0e+6, damping: 2.0}
initial: {omega: [0.05, 0.0, 1.0]}
duration: 20.0
output: {rate: 10}
";

#[test]
fn an_explicit_method_above_its_stability_bound_stops_with_a_diagnosis() {
    // rk4's bound is h·|λ| ≈ 2.785; |λ| ≈ 1.0e3 here, so 0.01 s is well beyond it.
    let s = parse(
        STIFF,
        Overrides {
            dt: Some(0.01),
            ..method("rk4")
        },
    );
    let o = run_quietly(&s);
    let Status::Failed { diagnosis } = &o.status else {
        panic!("expected a failure, got {:?}", o.status);
    };
    eprintln!("{diagnosis}");
    assert!(diagnosis.contains("diverging"), "{diagnosis}");
    assert!(diagnosis.contains("numerical instability"), "{diagnosis}");
    // The stiffness is measured where the run stopped, while the state is still sane:
    // |λ| ≈ √(k/m) = 1e3 1/s.
    let rho: f64 = diagnosis
        .split("|λ| = ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|r| r.parse().ok())
        .expect("the diagnosis quotes |λ|");
    assert!((rho / 1.0e3 - 1.0).abs() < 0.1, "|λ| = {rho}");
    assert!(diagnosis.contains("radau5"), "{diagnosis}");
    assert!(o.final_state.iter().all(|v| v.is_finite()));
    // It stopped early, not at the end.
    assert!(o.final_observation.t < s.duration);
}

#[test]
fn implicit_methods_stay_bounded_above_the_explicit_bound() {
    for ov in [
        Overrides {
            dt: Some(0.01),
            stages: Some(2),
            ..method("gauss")
        },
        Overrides {
            dt: Some(0.01),
            stages: Some(1),
            ..method("gauss")
        },
        Overrides {
            rtol: Some(1e-6),
            atol: Some(1e-9),
            ..method("radau5")
        },
    ] {
        let label = format!("{:?} {:?}", ov.method, ov.stages);
        let s = parse(STIFF, ov);
        let o = run_quietly(&s);
        eprintln!("{label}: {:?} {:?} {:?}", o.status, o.drift, o.stats);
        assert_eq!(o.status, Status::Complete, "{label}");
        // Passive scene: the energy balance must not grow.
        // (Measured 3e-16 … 3e-11; an unstable method would grow it without bound.)
        assert!(o.drift.energy_rel < 1e-8, "{label}: {:?}", o.drift);
        assert!(o.final_state.iter().all(|v| v.is_finite()));
    }
}

#[test]
fn auto_picks_exact_explicit_or_implicit_from_the_scene_and_says_why() {
    let rigid = load("scenarios/tennis-racket.yaml", method("auto"));
    assert_eq!(rigid.method, Method::Exact);
    assert!(
        rigid
            .method_choice
            .as_deref()
            .unwrap()
            .contains("torque-free")
    );
    let damper = load("scenarios/nutation-damper.yaml", method("auto"));
    assert!(
        matches!(damper.method, Method::Dop853(_)),
        "{:?}",
        damper.method
    );
    assert!(
        damper
            .method_choice
            .as_deref()
            .unwrap()
            .contains("not stiff")
    );
    let stiff = parse(STIFF, method("auto"));
    assert!(
        matches!(stiff.method, Method::Radau5(_)),
        "{:?}",
        stiff.method
    );
    assert!(stiff.method_choice.as_deref().unwrap().contains("stiff"));
}

/// Keeps every output sample.
#[derive(Default)]
struct Samples(Vec<(f64, Vec<f64>)>);

impl sim::Sink for Samples {
    fn sample(
        &mut self,
        o: &polhode::model::Observation,
        y: &[f64],
        _: &sim::Reference,
    ) -> std::io::Result<()> {
        self.0.push((o.t, y.to_vec()));
        Ok(())
    }
    fn event(
        &mut self,
        _: &sim::EventRecord,
        _: &polhode::model::Observation,
    ) -> std::io::Result<()> {
        Ok(())
    }
}

fn samples(s: &Scenario) -> Vec<(f64, Vec<f64>)> {
    let interrupt = AtomicBool::new(false);
    let mut sink = Samples::default();
    sim::run(
        s,
        &mut sink,
        Control {
            interrupt: &interrupt,
            progress: None,
        },
    )
    .expect("no I/O");
    sink.0
}

/// Largest attitude and ω error of `test`'s samples against `reference`'s at the same times.
fn worst_sample_error(reference: &[(f64, Vec<f64>)], test: &[(f64, Vec<f64>)]) -> (f64, f64) {
    assert_eq!(reference.len(), test.len());
    let mut worst = (0.0f64, 0.0f64);
    for ((tr, yr), (tt, yt)) in reference.iter().zip(test) {
        assert!((tr - tt).abs() < 1e-12);
        let dw = (0..3).map(|i| (yt[i] - yr[i]).powi(2)).sum::<f64>().sqrt();
        worst.0 = worst.0.max(attitude_error(&yr[3..7], &yt[3..7]));
        worst.1 = worst.1.max(dw);
        let qn = yt[3..7].iter().map(|c| c * c).sum::<f64>().sqrt();
        assert!(
            (qn - 1.0).abs() < 1e-12,
            "|q| − 1 = {:e} at t = {tt}",
            qn - 1.0
        );
    }
    worst
}

#[test]
fn dense_output_between_steps_is_as_good_as_the_steps() {
    // Samples at 7 Hz fall inside long fixed steps (1 s, 0.05 s).
    let at_7_hz = |ov: Overrides, yaml: Option<&str>| {
        let mut s = match yaml {
            Some(y) => parse(y, ov),
            None => load(
                "scenarios/generic-tumble.yaml",
                Overrides {
                    duration: Some(20.0),
                    ..ov
                },
            ),
        };
        s.output_rate = 7.0;
        samples(&s)
    };
    // Torque-free: splitting interpolates along the exact free flow.
    let exact = at_7_hz(method("exact"), None);
    let split = at_7_hz(
        Overrides {
            dt: Some(1.0),
            ..method("splitting")
        },
        None,
    );
    let (att, w) = worst_sample_error(&exact, &split);
    eprintln!("splitting, torque-free, dt 1 s: samples off by {att:e} rad, {w:e} rad/s");
    assert!(att < 1e-10 && w < 1e-10);
    let lie = at_7_hz(
        Overrides {
            dt: Some(0.05),
            ..method("lie")
        },
        None,
    );
    let (att, w) = worst_sample_error(&exact, &lie);
    eprintln!("lie, torque-free, dt 0.05 s: samples off by {att:e} rad, {w:e} rad/s");
    assert!(att < 1e-5 && w < 1e-5);
    // Damped: against dop853's dense output at rtol 1e-13; interior samples no worse than
    // 10× the step ends' error of the same run.
    let reference = at_7_hz(
        Overrides {
            rtol: Some(1e-13),
            atol: Some(1e-15),
            ..method("dop853")
        },
        Some(DAMPED),
    );
    for (name, order) in [("splitting", Some(4)), ("lie", None)] {
        let dt = 0.1;
        let run = at_7_hz(
            Overrides {
                dt: Some(dt),
                order,
                ..method(name)
            },
            Some(DAMPED),
        );
        let (att, w) = worst_sample_error(&reference, &run);
        let end = error(
            &damped_reference(),
            &final_state(&parse(
                DAMPED,
                Overrides {
                    dt: Some(dt),
                    order,
                    ..method(name)
                },
            )),
        );
        eprintln!("{name}, damped, dt {dt}: samples off by {att:e} rad, {w:e} rad/s; end {end:e}");
        assert!(
            att.max(w) < 10.0 * end.max(1e-12),
            "{name}: {att:e} {w:e} vs {end:e}"
        );
    }
}
