//! The seams between methods and features (docs/reliability.md, "The method contract"): each
//! defect once seen ending `complete` with a wrong answer, now either integrated correctly or
//! refused with the reason.

mod common;

use common::{run, scenario_with};
use polhode::scenario::{self, Overrides};
use polhode::sim::Status;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn with_method(method: &str, dt: Option<f64>, duration: f64) -> Overrides {
    Overrides {
        method: Some(method.into()),
        dt,
        duration: Some(duration),
        ..Overrides::default()
    }
}

fn load(file: &str, ov: &Overrides) -> Result<scenario::Scenario, String> {
    scenario::load(&root().join(file), ov).map_err(|e| e.to_string())
}

/// The hub's |ω| at the end over the start.
fn rate_ratio(file: &str, ov: &Overrides) -> f64 {
    let s = load(file, ov).expect("loads");
    let (out, _) = run(&s);
    assert_eq!(out.status, Status::Complete, "{file} under {:?}", ov.method);
    out.final_observation.omega.norm() / out.initial_observation.omega.norm()
}

#[test]
fn lie_and_splitting_update_held_states_at_breakpoints_like_dop853() {
    // B-dot (magnetorquer ticks) and a sampled rate-damping loop on four wheels: both hold
    // their command between ticks, and a method that never restarts kept T unchanged.
    for (file, duration) in [
        ("scenarios/cubesat-detumble.yaml", 300.0),
        ("scenarios/rwa-rate-damping.yaml", 30.0),
    ] {
        let reference = rate_ratio(file, &with_method("dop853", None, duration));
        assert!(
            reference < 0.9,
            "{file}: the controller slows the hub ({reference})"
        );
        for method in ["lie", "splitting"] {
            let ratio = rate_ratio(file, &with_method(method, Some(0.05), duration));
            assert!(
                (ratio - reference).abs() < 1e-5,
                "{file} {method}: |ω| ratio {ratio} against dop853's {reference}"
            );
        }
    }
}

/// The triaxial body (I = 2, 3, 4 kg m²) with an energy sink, as YAML, started at `omega`.
fn triaxial_sink(omega: [f64; 3], duration: f64) -> String {
    format!(
        "name: t\nbody: {{principal: [2.0, 3.0, 4.0]}}\n\
         effectors:\n  - energy_sink: {{name: sink, coefficient: 0.006}}\n\
         initial: {{omega: [{:e}, {:e}, {:e}]}}\nduration: {duration:e}\n\
         integrator: {{method: averaged}}\noutput: {{rate: 0.1}}\n",
        omega[0], omega[1], omega[2]
    )
}

#[test]
fn averaged_never_pumps_energy_into_a_body_whose_nutation_has_died() {
    // Spun about the major axis: the nutation decays to the flat spin T = |H|²/(2 I3) and
    // stays there. The averaged slow state overshot that floor and the rebuilt rates grew.
    let s = scenario_with(
        &triaxial_sink([0.3, 0.3, 10.0], 13_200.0),
        &Overrides::default(),
    );
    let (out, rec) = run(&s);
    assert_eq!(out.status, Status::Complete);
    let h0 = out.initial_observation.h_norm;
    let floor = h0 * h0 / (2.0 * 4.0);
    let mut previous = f64::INFINITY;
    for o in &rec.samples {
        assert!(
            o.kinetic_energy <= previous * (1.0 + 1e-12),
            "T rose at t = {}",
            o.t
        );
        assert!(
            o.kinetic_energy >= floor * (1.0 - 1e-12),
            "below the floor at {}",
            o.t
        );
        assert!(
            (o.h_norm - h0).abs() <= 1e-12 * h0,
            "|H| changed at {}",
            o.t
        );
        previous = o.kinetic_energy;
    }
    // dop853 at rtol 1e-10 ends at 200.1462499999 J on the floor 200.14625 J.
    assert!((out.final_observation.kinetic_energy - floor).abs() < 1e-9 * floor);
}

#[test]
fn averaged_refuses_a_start_on_the_separatrix_where_its_rates_vanish() {
    let s = scenario_with(
        &triaxial_sink([1e-8, 10.0, 1e-8], 13_200.0),
        &Overrides::default(),
    );
    let (out, _) = run(&s);
    match out.status {
        Status::Failed { diagnosis } => {
            assert!(diagnosis.contains("separatrix"), "{diagnosis}");
            assert!(diagnosis.contains("use dop853"), "{diagnosis}");
        }
        other => panic!("expected a refusal, got {other:?}"),
    }
    // Off the separatrix by more than rounding, it crosses like dop853 and ends flat.
    let s = scenario_with(
        &triaxial_sink([1e-3, 10.0, 1e-3], 13_200.0),
        &Overrides::default(),
    );
    let (out, _) = run(&s);
    assert_eq!(out.status, Status::Complete);
    let h = out.final_observation.h_norm;
    let floor = h * h / 8.0;
    assert!((out.final_observation.kinetic_energy - floor).abs() < 1e-6 * floor);
}

#[test]
fn an_energy_sink_beside_any_effector_that_carries_momentum_is_refused() {
    let wheel = "  - wheel: {name: rw, axial_inertia: 0.01, axis: [0, 0, 1], \
                 motor: {torque: {constant: 0.001}}}\n";
    for (first, second) in [
        ("  - energy_sink: {name: sink, coefficient: 0.01}\n", wheel),
        (wheel, "  - energy_sink: {name: sink, coefficient: 0.01}\n"),
    ] {
        let yaml = format!(
            "name: t\nbody: {{principal: [1.0, 2.0, 3.0]}}\neffectors:\n{first}{second}\
             initial: {{omega: [0.1, 0.2, 1.0]}}\nduration: 10.0\n"
        );
        let e = scenario::parse(Path::new("t.yaml"), yaml, &Overrides::default())
            .expect_err("refused")
            .to_string();
        assert!(e.contains("energy_sink"), "{e}");
        assert!(e.contains("carry momentum"), "{e}");
    }
}

#[test]
fn a_spacecraft_built_in_code_refuses_a_sink_beside_a_rotor_too() {
    use polhode::effectors::EnergySink;
    let mut s = load("scenarios/wheel-damper.yaml", &Overrides::default()).expect("loads");
    let sink = EnergySink {
        name: "sink".into(),
        coefficient: 0.01,
        inertia: s.spacecraft.hub.inertia,
    };
    let e = s
        .simulation
        .spacecraft
        .add_effector(Box::new(sink))
        .expect_err("refused")
        .to_string();
    assert!(
        e.contains("quasi-rigid") && e.contains("wheel_damper"),
        "{e}"
    );
}

#[test]
fn linearize_refuses_sampled_controllers_naming_them() {
    use polhode::linearize::{linearize, spin_rate_of};
    for (file, kind) in [
        ("scenarios/rwa-rate-damping.yaml", "wheel"),
        ("scenarios/cubesat-detumble.yaml", "magnetorquer"),
    ] {
        let s = load(file, &Overrides::default()).expect("loads");
        let rate = spin_rate_of(&s.spacecraft, &s.omega0);
        let e = linearize(&s.spacecraft, rate).expect_err("refused");
        assert!(e.contains(kind) && e.contains("held"), "{file}: {e}");
    }
}

#[test]
fn every_run_is_checked_against_the_contract_whatever_built_it() {
    // A Simulation assembled in code with a method its scene does not support fails at
    // t = 0 with the refusal, before any step.
    let mut s = load("scenarios/nutation-damper.yaml", &Overrides::default()).expect("loads");
    s.simulation.method = polhode::sim::Method::Exact;
    let (out, _) = run(&s);
    match out.status {
        Status::Failed { diagnosis } => assert!(diagnosis.contains("torque-free"), "{diagnosis}"),
        other => panic!("expected a refusal, got {other:?}"),
    }
}

#[test]
fn gauss_converges_where_a_quaternion_component_stays_zero_by_symmetry() {
    // An axisymmetric body turning about a transverse axis: ω is constant and q_z stays
    // exactly zero, which the Newton iteration approached geometrically without ever meeting
    // its relative test (found by the `method_pairs` fuzz target).
    let yaml = "name: t\nbody: {principal: [1, 1, 1.85]}\n\
                initial: {omega: [-0.03125, 1.15625, 0]}\nduration: 0.2\n";
    for stages in [1, 2] {
        let ov = Overrides {
            method: Some("gauss".into()),
            dt: Some(0.005),
            stages: Some(stages),
            ..Overrides::default()
        };
        let (out, _) = run(&scenario_with(yaml, &ov));
        assert_eq!(out.status, Status::Complete, "{stages} stage(s)");
    }
}
