//! A campaign's runs in lockstep lanes against the same campaign on the scalar path, row by row
//! and bit for bit: statuses, messages, events, largest nutation, final state metrics, steps and
//! right-hand-side counts. The cases cover what the run monitor does around the lanes' steps:
//! output samples and events on the dense output, a terminal event, a drift bound that stops
//! runs, a step-size bound, dispersions that make some draws invalid, and runs of different
//! lengths (a lane that finishes takes the next run).
//!
//! Every lane engine this processor has (eight AVX-512 lanes, four AVX2 lanes, one lane) is
//! compared.
//!
//!   cargo test --release --test lanes_campaign

use polhode::lanes::ensemble::{Engine, resolved};
use polhode::montecarlo::{Integration, Prepared, Row};
use polhode::scenario::{self, Overrides};
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// scenarios/nutation-damper.yaml's scene, with `integrator`, `extra` top-level keys and a
/// campaign of `runs` runs over `dispersions`.
fn campaign(integrator: &str, extra: &str, runs: u64, dispersions: &str) -> Prepared {
    let yaml = format!(
        "name: lanes\n\
         body:\n  mass: 5274.4\n  principal: [1375.7, 1292.5, 1402.4]\n  spin_axis: [0, 0, 1]\n\
         effectors:\n  - spring_mass_damper:\n      name: damper\n      mass: 52.744\n      \
         position: [1.0, 0.0, 0.0]\n      direction: [0, 0, 1]\n      stiffness: 52.744\n      \
         damping: 105.49\n\
         initial:\n  omega: [0.1, 0.0, 1.0]\n\
         integrator: {integrator}\n\
         {extra}\
         montecarlo:\n  runs: {runs}\n  seed: 7\n  invalid_draws: exclude\n  dispersions:\n{dispersions}"
    );
    let sc = scenario::parse(Path::new("lanes.yaml"), yaml, &Overrides::default())
        .unwrap_or_else(|e| panic!("{e}"));
    Prepared::new(sc, "lanes.yaml", None, None).unwrap_or_else(|e| panic!("{e}"))
}

fn rows(p: &Prepared, threads: usize) -> Vec<Row> {
    let never = AtomicBool::new(false);
    let (rows, partial) = p
        .execute(0..p.campaign.runs, threads, &never, &|_| {})
        .expect("the campaign runs");
    assert!(!partial);
    rows
}

/// The lane engines this processor runs (each resolved: a width it lacks falls back).
fn engines() -> Vec<Engine> {
    let mut engines: Vec<Engine> = [Engine::Avx512, Engine::Avx2, Engine::Scalar]
        .into_iter()
        .map(resolved)
        .collect();
    engines.dedup();
    engines
}

/// Runs `p` in lanes with every engine this processor has and on the scalar path, and
/// compares every row bit for bit; returns the rows of the widest lanes.
fn assert_same_rows(p: Prepared) -> Vec<Row> {
    assert!(
        matches!(p.integration, Integration::Lanes(_)),
        "expected lanes: {:?}",
        p.integration
    );
    let mut in_lanes = Vec::new();
    let mut p = p;
    for engine in engines() {
        p = p.with_lane_engine(engine);
        assert_eq!(p.integration, Integration::Lanes(engine));
        in_lanes.push((engine, rows(&p, 2)));
    }
    let p = p.with_integration(false);
    assert!(matches!(p.integration, Integration::Scalar(_)));
    let scalar = rows(&p, 1);
    for (engine, lanes) in &in_lanes {
        assert_eq!(lanes.len(), scalar.len());
        for (a, b) in lanes.iter().zip(&scalar) {
            assert_eq!(a.run, b.run);
            assert_eq!(
                a.status, b.status,
                "{engine:?}, run {}: {} vs {}",
                a.run, a.message, b.message
            );
            assert_eq!(a.message, b.message, "{engine:?}, run {}", a.run);
            for (k, (x, y)) in a.values.iter().zip(&b.values).enumerate() {
                assert_eq!(
                    x.map(f64::to_bits),
                    y.map(f64::to_bits),
                    "{engine:?}, run {}, column {} ({}): {x:?} vs {y:?}",
                    a.run,
                    k,
                    p.columns[k]
                );
            }
        }
    }
    in_lanes.swap_remove(0).1
}

/// scenarios/`file` with each `(from, to)` of `edits` made (each must be there), prepared as a
/// campaign.
fn edited_scenario(file: &str, edits: Vec<(&str, String)>) -> Prepared {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios")
        .join(file);
    let mut yaml = std::fs::read_to_string(&path).expect("the scenario");
    for (from, to) in edits {
        assert!(yaml.contains(from), "{file} has `{from}`");
        yaml = yaml.replace(from, &to);
    }
    let sc = scenario::parse(Path::new(file), yaml, &Overrides::default())
        .unwrap_or_else(|e| panic!("{e}"));
    Prepared::new(sc, file, None, None).unwrap_or_else(|e| panic!("{e}"))
}

/// Asserts that some but not all of `rows` stopped on a condition whose message has `word`.
fn assert_some_stopped(rows: &[Row], word: &str, integrator: &str) {
    let stopped = rows.iter().filter(|r| r.message.contains(word)).count();
    assert!(
        stopped > 0 && stopped < rows.len(),
        "{integrator}: {stopped} of {} runs stopped: the case should mix both",
        rows.len()
    );
}

const DISPERSED: &str = "    - {path: \"initial.omega[0]\", normal: {sd: 0.02}}\n    \
                         - {path: \"initial.omega[2]\", normal: {sd: 0.01, relative: true}}\n    \
                         - {path: \"effectors[damper].damping\", log_normal: {sigma: 0.2}}\n";

/// The nutation-damper campaign's events (a `once` crossing and a `for:` settling time) on
/// 20 Hz output samples, runs of different lengths.
#[test]
fn a_damper_campaign_gives_the_scalar_rows_in_lanes() {
    let p = campaign(
        "{method: dopri5, rtol: 1.0e-10, atol: 1.0e-12}",
        "duration: 200.0\noutput: {rate: 20}\nevents:\n  \
         - nutation_angle_deg: {below: 1.0, once: true}\n  \
         - nutation_angle_deg: {below: 1.0, for: 20.0}\n",
        11,
        &format!("{DISPERSED}    - {{path: duration, uniform: {{min: 50.0, max: 200.0}}}}\n"),
    );
    let rows = assert_same_rows(p);
    // The events did fire, so their location on the lanes' dense output was compared.
    assert!(
        rows.iter()
            .filter(|r| r.values.iter().flatten().count() > 0)
            .count()
            == 11
    );
}

/// A terminal condition ends some runs part-way (the lane takes the next run), and loose
/// tolerances bring rejected steps.
#[test]
fn a_terminal_event_and_rejections_give_the_scalar_rows_in_lanes() {
    let p = campaign(
        "{method: dopri5, rtol: 1.0e-5, atol: 1.0e-7}",
        "duration: 120.0\noutput: {rate: 5}\nstop: [{nutation_angle_deg: {below: 3.0}}]\n",
        10,
        &format!("{DISPERSED}    - {{path: duration, uniform: {{min: 5.0, max: 120.0}}}}\n"),
    );
    assert_some_stopped(&assert_same_rows(p), "below", "dopri5");
}

/// A drift bound under `on_drift: stop` fails some runs at the step that breaches it, a
/// largest step bounds the steps, and invalid draws (a negative damping) are rows too.
#[test]
fn checks_a_step_bound_and_invalid_draws_give_the_scalar_rows_in_lanes() {
    let p = campaign(
        "{method: dopri5, rtol: 1.0e-6, atol: 1.0e-8, max_step: 0.5}",
        "duration: 60.0\noutput: {rate: 2}\n\
         checks: {max_drift: {momentum: 3.0e-9}, on_drift: stop}\n",
        12,
        "    - {path: \"initial.omega[0]\", normal: {sd: 0.05}}\n    \
         - {path: \"effectors[damper].damping\", normal: {sd: 200.0}}\n",
    );
    let rows = assert_same_rows(p);
    let statuses: std::collections::BTreeSet<String> =
        rows.iter().map(|r| format!("{:?}", r.status)).collect();
    assert!(statuses.len() > 2, "too few statuses: {statuses:?}");
}

/// The damper's events and a terminal condition with dop853 (its stage 13 only for steps that
/// pass, its dense stages only for steps read inside), at a tolerance that rejects steps.
#[test]
fn a_damper_campaign_with_dop853_gives_the_scalar_rows_in_lanes() {
    let p = campaign(
        "{method: dop853, rtol: 1.0e-6, atol: 1.0e-8}",
        "duration: 150.0\noutput: {rate: 20}\nevents:\n  \
         - nutation_angle_deg: {below: 1.0, once: true}\n  \
         - nutation_angle_deg: {below: 1.0, for: 20.0}\n\
         stop: [{nutation_angle_deg: {below: 3.0}}]\n",
        11,
        &format!("{DISPERSED}    - {{path: duration, uniform: {{min: 20.0, max: 150.0}}}}\n"),
    );
    let rows = assert_same_rows(p);
    assert!(
        rows.iter().any(|r| r.message.contains("below")),
        "no run stopped"
    );
}

/// A rigid body with an energy sink (the energy-sink class), a quick one, with dop853 and
/// dopri5: the nutation grows through two events to a terminal one.
#[test]
fn an_energy_sink_campaign_gives_the_scalar_rows_in_lanes() {
    for integrator in [
        "{method: dop853, rtol: 1.0e-9, atol: 1.0e-11}",
        "{method: dopri5, rtol: 1.0e-7, atol: 1.0e-9}",
    ] {
        let yaml = format!(
            "name: sink\n\
             body:\n  principal: [4.9, 4.9, 0.15]\n  spin_axis: [0, 0, 1]\n\
             effectors:\n  - energy_sink: {{name: antennas, time_constant: 60.0}}\n\
             initial:\n  omega: [0.08, 0.08, 8.0]\n\
             integrator: {integrator}\n\
             duration: 400.0\noutput: {{rate: 5}}\n\
             events:\n  - {{nutation_angle_deg: {{above: 45.0}}}}\n\
             stop: [{{nutation_angle_deg: {{above: 80.0}}}}]\n\
             montecarlo:\n  runs: 10\n  seed: 3\n  dispersions:\n    \
             - {{path: \"initial.omega[0]\", normal: {{sd: 0.03}}}}\n    \
             - {{path: \"effectors[antennas].time_constant\", log_normal: {{sigma: 0.4}}}}\n    \
             - {{inertia: {{sd: 0.01}}}}\n    \
             - {{attitude: {{sd_deg: 1.0}}}}\n    \
             - {{path: duration, uniform: {{min: 5.0, max: 400.0}}}}\n"
        );
        let sc = scenario::parse(Path::new("sink.yaml"), yaml, &Overrides::default())
            .unwrap_or_else(|e| panic!("{e}"));
        let p = Prepared::new(sc, "sink.yaml", None, None).unwrap_or_else(|e| panic!("{e}"));
        assert_some_stopped(&assert_same_rows(p), "above", integrator);
    }
}

/// A scene without a lane form, or a method the lanes do not have, runs on the scalar path
/// and says why.
#[test]
fn a_scene_without_a_lane_form_says_why() {
    let p = campaign("{method: rk4, dt: 0.01}", "duration: 10.0\n", 2, DISPERSED);
    match &p.integration {
        Integration::Scalar(why) => assert!(why.contains("rk4"), "{why}"),
        other => panic!("expected the scalar path, got {other:?}"),
    }
    let p = campaign(
        "{method: dopri5, rtol: 1.0e-10, atol: 1.0e-12}",
        "duration: 10.0\n",
        2,
        DISPERSED,
    )
    .with_method(Some("radau5".into()))
    .unwrap();
    assert!(matches!(&p.integration, Integration::Scalar(why) if why.contains("radau5")));
}

/// The hinged-rods class: explorer1-pydy's four flap–lag rods with its dispersions (rates,
/// hinge damping, stiffness and rod mass, the hull's axial moment and axes) and runs of
/// different lengths, a terminal event that stops some of them, with dop853 and dopri5.
#[test]
fn a_hinged_rods_campaign_gives_the_scalar_rows_in_lanes() {
    for integrator in [
        "{method: dop853, rtol: 1.0e-10, atol: 1.0e-12}",
        "{method: dopri5, rtol: 1.0e-8, atol: 1.0e-10}",
    ] {
        let p = edited_scenario(
            "explorer1-pydy.yaml",
            vec![
                (
                    "integrator: {method: dop853, rtol: 1.0e-10, atol: 1.0e-12}",
                    format!(
                        "integrator: {integrator}\nstop: [{{nutation_angle_deg: {{above: 80.0}}}}]"
                    ),
                ),
                ("runs: 100", "runs: 12".into()),
                ("duration: 150.0", "duration: 70.0".into()),
                (
                    "output: {rate: 200, scene_rate: 50}",
                    "output: {rate: 20}".into(),
                ),
                (
                    "probability_by: [60, 100, 150]",
                    "probability_by: [30, 60]".into(),
                ),
                (
                    "    - {inertia: {sd: 0.0, axes_sd_deg: 0.2}}\n",
                    "    - {inertia: {sd: 0.0, axes_sd_deg: 0.2}}\n    \
                     - {path: duration, uniform: {min: 5.0, max: 70.0}}\n"
                        .into(),
                ),
            ],
        );
        assert_some_stopped(&assert_same_rows(p), "above", integrator);
    }
}

/// The driven-wheel class, whose runs stop at breakpoints: scenarios/momentum-transfer.yaml's
/// wheel spun up by a stepped torque (its last step two breakpoints 10⁻¹³ s apart, one stop),
/// with dispersed rates and inertia, the time of the torque's second step dispersed (so each
/// lane stops at its own times), runs of different lengths (ending before, between and after
/// the steps), and a terminal event that stops some of them, with dop853 and dopri5. Each
/// lane stops exactly on its own run's steps and restarts there while the others step on.
#[test]
fn a_stepped_wheel_campaign_stops_at_its_breakpoints_in_lanes() {
    for integrator in [
        "{method: dop853, rtol: 1.0e-10, atol: 1.0e-12}",
        "{method: dopri5, rtol: 1.0e-8, atol: 1.0e-10}",
    ] {
        let p = edited_scenario(
            "momentum-transfer.yaml",
            vec![
                (
                    "integrator: {method: dop853, rtol: 1.0e-10, atol: 1.0e-12}",
                    format!(
                        "integrator: {integrator}\nstop: [{{nutation_angle_deg: {{below: 12.0}}}}]"
                    ),
                ),
                ("runs: 200", "runs: 12".into()),
                (
                    "steps: [[0.0, 0.02], [600.0, 0.01], [1200.0, 0.0]]",
                    "steps: [[0.0, 0.04], [150.0, 0.02], [300.0, 0.0], [300.0000000000001, 0.0]]"
                        .into(),
                ),
                ("duration: 1500.0", "duration: 500.0".into()),
                (
                    "probability_by: [1000, 1500]",
                    "probability_by: [200, 500]".into(),
                ),
                (
                    "    - {inertia: {sd: 0.03, axes_sd_deg: 0.5}}\n",
                    "    - {inertia: {sd: 0.03, axes_sd_deg: 0.5}}\n    \
                     - {path: duration, uniform: {min: 100.0, max: 500.0}}\n    \
                     - {path: \"effectors[rotor].motor.torque.steps[1][0]\", \
                     uniform: {min: 100.0, max: 250.0}}\n"
                        .into(),
                ),
            ],
        );
        assert_some_stopped(&assert_same_rows(p), "below", integrator);
    }
}

/// The driven-wheel class under a sampled controller: one wheel on z under rate damping at
/// 10 Hz (a breakpoint every 0.1 s, where each lane samples its own ω), its motor saturated
/// at first, with dispersed rates and durations and a terminal condition, with dop853 and
/// dopri5.
#[test]
fn a_rate_damping_wheel_campaign_restarts_at_every_tick_in_lanes() {
    for integrator in [
        "{method: dop853, rtol: 1.0e-10, atol: 1.0e-12}",
        "{method: dopri5, rtol: 1.0e-8, atol: 1.0e-10}",
    ] {
        let yaml = format!(
            "name: despin\n\
             body:\n  principal: [12.0, 14.0, 9.0]\n  spin_axis: [0, 0, 1]\n\
             effectors:\n  - wheel:\n      name: rw\n      axial_inertia: 0.01\n      \
             axis: [0, 0, 1]\n      max_torque: 0.02\n      friction: {{viscous: 1.0e-6}}\n      \
             motor: {{rate_damping: {{gain: 0.5, sample_rate: 10.0}}}}\n\
             initial:\n  omega: [0.002, -0.001, 0.05]\n\
             integrator: {integrator}\n\
             duration: 60.0\noutput: {{rate: 5}}\n\
             events:\n  - {{omega_z: {{below: 0.02, once: true}}}}\n\
             stop: [{{omega_z: {{below: 0.01}}}}]\n\
             montecarlo:\n  runs: 10\n  seed: 5\n  dispersions:\n    \
             - {{path: \"initial.omega[2]\", normal: {{sd: 0.2, relative: true}}}}\n    \
             - {{path: \"initial.omega[0]\", normal: {{sd: 0.002}}}}\n    \
             - {{path: duration, uniform: {{min: 5.0, max: 60.0}}}}\n"
        );
        let sc = scenario::parse(Path::new("despin.yaml"), yaml, &Overrides::default())
            .unwrap_or_else(|e| panic!("{e}"));
        let p = Prepared::new(sc, "despin.yaml", None, None).unwrap_or_else(|e| panic!("{e}"));
        assert_some_stopped(&assert_same_rows(p), "below", integrator);
    }
}
