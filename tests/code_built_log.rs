//! A run built in code and logged through `Scenario::from_simulation` writes the same MCAP
//! telemetry, bit for bit, as the same run written as a scenario file and loaded by the YAML
//! front end: the typed API and the loader are two doors to one run loop.

mod common;

use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use polhode::effectors::energy_sink::EnergySink;
use polhode::log::{McapLogger, charts};
use polhode::model::{RigidBody, Spacecraft};
use polhode::scenario::{self, Overrides, Scenario};
use polhode::sim::{self, Adaptive, Condition, Control, Method, Quantity, Simulation};
use std::path::Path;

const YAML: &str = "\
name: sink in code
body:
  principal: [10.0, 12.0, 14.0]
  spin_axis: [1, 0, 0]
effectors:
  - energy_sink: {name: sink, coefficient: 0.5}
initial:
  omega: [2.0, 0.02, 0.0]
duration: 300.0
integrator: {method: dop853, rtol: 1.0e-9, atol: 1.0e-12}
output: {rate: 10}
events:
  - {nutation_angle_deg: {above: 80.0}}
";

/// A fresh, empty scratch directory for one test, removed when it passes.
fn scratch() -> common::Scratch {
    common::Scratch::new("polhode-code-log", "log")
}

fn log(scene: &Scenario, path: &Path) -> charts::RunLog {
    let mut logger = McapLogger::create(path, scene, scene.omega0.norm()).unwrap();
    let outcome = sim::run(scene, &mut logger, Control::uninterrupted()).unwrap();
    let written = logger
        .finish(scene, &scene.method.describe(), &outcome)
        .unwrap();
    charts::read(&written).unwrap()
}

#[test]
fn a_run_built_in_code_logs_what_its_scenario_file_logs() {
    let dir = scratch();
    let file = dir.join("sink.yaml");
    std::fs::write(&file, YAML).unwrap();
    let loaded = scenario::load(&file, &Overrides::default()).unwrap();

    let inertia = Matrix3::from_diagonal(&Vector3::new(10.0, 12.0, 14.0));
    let mut spacecraft = Spacecraft::new(RigidBody::new(inertia).unwrap(), Vector3::x());
    let sink = EnergySink {
        name: "sink".into(),
        coefficient: 0.5,
        inertia,
    };
    spacecraft.add_effector(Box::new(sink)).unwrap();
    let tolerances = Adaptive {
        rtol: 1e-9,
        atol: 1e-12,
        max_step: f64::INFINITY,
    };
    let mut run = Simulation::new(
        spacecraft,
        Vector3::new(2.0, 0.02, 0.0),
        UnitQuaternion::identity(),
        300.0,
        Method::Dop853(tolerances),
    );
    run.events
        .push(Condition::crossing(Quantity::NutationAngleDeg, 80.0, true));
    let built = Scenario::from_simulation("sink in code", run);

    let from_file = log(&loaded, &dir.join("file.mcap"));
    let from_code = log(&built, &dir.join("code.mcap"));
    assert_eq!(from_code.name, "sink in code");
    assert_eq!(from_file.telemetry.fields, from_code.telemetry.fields);
    assert!(from_file.telemetry.columns[0].len() > 3000);
    for (name, (a, b)) in from_file.telemetry.fields.iter().zip(
        from_file
            .telemetry
            .columns
            .iter()
            .zip(&from_code.telemetry.columns),
    ) {
        let same = a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same, "/telemetry field {name} differs");
    }
    assert_eq!(from_file.effectors.len(), 1);
    assert_eq!(from_file.effectors[0].0, from_code.effectors[0].0);
    assert_eq!(
        from_file.effectors[0].1.columns, from_code.effectors[0].1.columns,
        "the sink's channel differs"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
