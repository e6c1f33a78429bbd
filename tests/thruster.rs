//! `thruster`: a spinning body expelling propellant, against things it did not produce.
//!
//! - **Closed form** (Thomson, *Introduction to Space Dynamics*, 1961, §9): an axisymmetric
//!   body whose propellant burns uniformly about its centre of mass at a constant mass flow ṁ
//!   through a nozzle on its axis a distance l aft keeps I_a ω_z, and its transverse rate
//!   obeys d ln|ω_t| / dt = −ṁ (l² − k_t²) / I_t(t), so |ω_t| = |ω_t₀| (I_t / I_t₀)^((l² −
//!   k_t²) / k_t²), with k_t² the propellant's transverse moment per kg; a nozzle exit of
//!   radius a adds a²/4 to l² and makes I_a ω_z fall as I_a^(a²/(2 k_a²)).
//! - **Conservation**: H plus the angular momentum the exhaust carried out, with the tank and
//!   the nozzle off the axis, an emptying tank whose centre moves, and a slosh pendulum.
//! - **Basilisk** (bsk 2.12.1, `peers/basilisk_burn.py`, results committed): the spin rate
//!   through the burn for the scenes whose tank and nozzle lie on the spin axis.
mod common;

use common::{run, scenario};
use polhode::sim::Status;
use serde_json::Value;

/// A 500 kg hub (transverse `it`, axial `ia`) with a uniform-burn grain about its centre of
/// mass and a nozzle `l` aft on the axis.
fn burner(it: f64, ia: f64, l: f64, exit: f64, omega: [f64; 3], duration: f64) -> String {
    format!(
        "name: burn
body: {{principal: [{it}, {it}, {ia}], mass: 500.0, spin_axis: [0, 0, 1]}}
initial: {{omega: [{}, {}, {}]}}
effectors:
  - thruster:
      nozzle: [0.0, 0.0, {}]
      direction: [0, 0, 1]
      exit_radius: {exit}
      thrust: {{constant: 6000.0}}
      isp: 290.0
      tank: {{model: uniform_burn, center: [0, 0, 0], axis: [0, 0, 1], radius: 0.5,
             length: 0.9, propellant: 350.0}}
duration: {duration}
integrator: {{method: dop853, rtol: 1.0e-12, atol: 1.0e-14}}
output: {{rate: 1}}
",
        omega[0], omega[1], omega[2], -l
    )
}

#[test]
fn jet_damping_of_a_uniform_burn_is_thomsons_closed_form() {
    let (it, ia, w0) = (420.0, 260.0, [0.03, -0.02, 5.0]);
    let flow = 6000.0 / (9.80665 * 290.0);
    let (r, len, m0) = (0.5f64, 0.9f64, 350.0);
    let (kt2, ka2) = (r * r / 4.0 + len * len / 12.0, r * r / 2.0);
    // A long nozzle damps (l² > k_t²); a short one pumps the coning up. An exit of radius a
    // adds a²/4 to l² for the transverse rates and takes a²/2 per kg of spin: I_a ω_z then
    // falls as I_a^(a²/(2 k_a²)).
    for (l, a) in [(1.2, 0.0), (0.2, 0.0), (1.2, 0.3)] {
        let s = scenario(&burner(it, ia, l, a, w0, 50.0));
        let (out, rec) = run(&s);
        assert_eq!(out.status, Status::Complete);
        let wt0 = (w0[0] * w0[0] + w0[1] * w0[1]).sqrt();
        let mut worst = (0.0f64, 0.0f64);
        for o in &rec.samples {
            let m = m0 - flow * o.t;
            let (it_t, ia_t) = (it + m * kt2, ia + m * ka2);
            let (it_0, ia_0) = (it + m0 * kt2, ia + m0 * ka2);
            let spin = w0[2] * (ia_t / ia_0).powf(a * a / (2.0 * ka2) - 1.0);
            let transverse = wt0 * (it_t / it_0).powf((l * l + a * a / 4.0 - kt2) / kt2);
            let wt = (o.omega[0].powi(2) + o.omega[1].powi(2)).sqrt();
            worst.0 = worst.0.max(((o.omega[2] - spin) / spin).abs());
            worst.1 = worst.1.max(((wt - transverse) / transverse).abs());
        }
        println!(
            "l = {l} m, exit radius {a} m: spin {:.2e}, transverse {:.2e} (relative)",
            worst.0, worst.1
        );
        assert!(worst.0 < 1e-11 && worst.1 < 1e-9, "l = {l}: {worst:?}");
        // Without the jet damping (l = 0) the answer would differ by far more than that.
        let last = rec.samples.last().unwrap();
        let m = m0 - flow * last.t;
        let no_damping = wt0 * ((it + m0 * kt2) / (it + m * kt2));
        let wt = (last.omega[0].powi(2) + last.omega[1].powi(2)).sqrt();
        assert!(((wt - no_damping) / no_damping).abs() > 5e-3);
    }
}

#[test]
fn momentum_plus_what_the_exhaust_carried_is_conserved() {
    // Off-axis nozzle and tank, an emptying tank whose centre moves, a table profile with
    // kinks, and a slosh pendulum moving mass: every term of the bookkeeping at work.
    let yaml = "name: audit
body: {principal: [500.0, 450.0, 300.0], mass: 600.0, spin_axis: [0, 0, 1]}
initial: {omega: [0.04, -0.03, 3.0]}
effectors:
  - thruster:
      nozzle: [0.01, -0.02, -1.0]
      direction: [0.01, 0.0, 1.0]
      thrust: {table: [[0.0, 0.0], [2.0, 4000.0], [20.0, 3500.0], [30.0, 0.0]]}
      isp: 300.0
      tank: {model: emptying, center: [0.1, 0.05, -0.3], axis: [0, 0, 1], radius: 0.4,
             density: 1000.0, propellant: 200.0}
  - slosh_pendulum: {mass: 15.0, length: 0.3, pivot: [0.4, 0.0, 0.2], rest_direction: [1, 0, 0],
                     damping: 20.0, initial_angles: [0.1, 0.05]}
  - thruster:
      name: vernier
      nozzle: [0.0, 0.5, -0.8]
      direction: [0.0, 0.0, 1.0]
      thrust: {constant: 50.0}
      mass_flow: {constant: 0.02}
      tank: {model: constant_density, center: [-0.3, 0.0, 0.0], radius: 0.2, propellant: 20.0}
duration: 40.0
integrator: {method: dop853, rtol: 1.0e-12, atol: 1.0e-14}
";
    let s = scenario(yaml);
    let (out, rec) = run(&s);
    assert_eq!(out.status, Status::Complete);
    let first = &rec.samples[0];
    let h0 = first.h_inertial + first.h_carried_out;
    let last = rec.samples.last().unwrap();
    let carried = last.h_carried_out.norm() / h0.norm();
    println!(
        "drift |H + exhaust| {:.2e}, H_N + exhaust {:.2e}; the exhaust carried {carried:.2e} of |H₀|",
        out.drift.h_norm_rel, out.drift.h_inertial_rel
    );
    assert!(out.drift.h_inertial_rel < 1e-10, "{:?}", out.drift);
    // The audit is not empty: the exhaust carried a visible share, and H itself changed.
    assert!(carried > 1e-3);
    assert!((last.h_inertial - first.h_inertial).norm() / h0.norm() > 1e-3);
}

#[test]
fn the_spin_rate_through_a_burn_is_basilisks_for_an_axisymmetric_stage() {
    let text = std::fs::read_to_string("peers/results/basilisk_burn.json").unwrap();
    let json: Value = serde_json::from_str(&text).unwrap();
    let mut compared = 0;
    for scene in json["scenes"].as_array().unwrap() {
        let p = &scene["scene"];
        let (tank, thr) = (&p["tank"], &p["thruster"]);
        let vec3 = |v: &Value| -> [f64; 3] {
            let a = v.as_array().unwrap();
            [0, 1, 2].map(|i| a[i].as_f64().unwrap())
        };
        let (loc, center) = (vec3(&thr["location"]), vec3(&tank["r_TB_B"]));
        // Basilisk 2.12.1's nozzle torque is +ṁ (1 − t̂ t̂ᵀ) ω, which has no axial part; the
        // jet damping −ṁ r_e × (ω × r_e) has one when the nozzle is off the axis (and the
        // stage is not axisymmetric when the tank is): only the on-axis scenes compare.
        if loc[0] != 0.0 || loc[1] != 0.0 || center[0] != 0.0 || center[1] != 0.0 {
            continue;
        }
        let model = match tank["model"].as_str().unwrap() {
            "CentrifugalBurn" => "centrifugal_burn",
            "UniformBurn" => "uniform_burn",
            "ConstantVolume" => "constant_volume",
            "ConstantDensity" => "constant_density",
            other => panic!("unexpected tank model {other}"),
        };
        let cylinder = model.ends_with("burn");
        let shape = if cylinder {
            format!(
                "radius: {}, length: {}, axis: [0, 0, 1]",
                tank["radius"], tank["length"]
            )
        } else {
            format!("radius: {}", tank["radius"])
        };
        let hub = vec3(&p["hub"]["inertia"]);
        let w = vec3(&p["omega"]);
        let yaml = format!(
            "name: b
body: {{principal: [{}, {}, {}], mass: {}, spin_axis: [0, 0, 1]}}
initial: {{omega: [{}, {}, {}]}}
effectors:
  - thruster:
      nozzle: [{}, {}, {}]
      direction: {}
      thrust: {{constant: {}}}
      isp: {}
      tank: {{model: {model}, center: [{}, {}, {}], {shape}, propellant: {}}}
duration: {}
integrator: {{method: dop853, rtol: 1.0e-13, atol: 1.0e-14}}
output: {{rate: 1}}
",
            hub[0],
            hub[1],
            hub[2],
            p["hub"]["mass"],
            w[0],
            w[1],
            w[2],
            loc[0],
            loc[1],
            loc[2],
            thr["direction"],
            thr["max_thrust"],
            thr["isp"],
            center[0],
            center[1],
            center[2],
            tank["propellant"],
            p["duration"]
        );
        let (out, rec) = run(&scenario(&yaml));
        assert_eq!(out.status, Status::Complete);
        let samples = scene["samples"].as_array().unwrap();
        let mut worst: f64 = 0.0;
        for (o, b) in rec.samples.iter().zip(samples) {
            assert!((o.t - b["t"].as_f64().unwrap()).abs() < 1e-9);
            let spin = b["omega"][2].as_f64().unwrap();
            worst = worst.max((o.omega[2] - spin).abs());
        }
        assert_eq!(rec.samples.len(), samples.len());
        let start = w[2];
        let end = rec.samples.last().unwrap().omega[2];
        println!(
            "{}: spin {start} → {end:.9} rad/s, largest difference from Basilisk {worst:.1e} rad/s",
            scene["name"]
        );
        // Basilisk's own integration error in ω is 1.1e-12 rad/s (the JSON's convergence
        // block); the spin-up itself is 0.2–0.5 rad/s.
        assert!(worst < 1e-10, "{}: {worst}", scene["name"]);
        assert!((end - start).abs() > 1e-2);
        compared += 1;
    }
    assert_eq!(compared, 3, "the three on-axis scenes");
}

/// The scene of `burner` with `change` applied to its text, parsed.
fn parsed(change: impl Fn(String) -> String) -> Result<polhode::scenario::Scenario, String> {
    let yaml = change(burner(420.0, 260.0, 1.2, 0.0, [0.03, -0.02, 5.0], 50.0));
    polhode::scenario::parse(
        std::path::Path::new("burn.yaml"),
        yaml,
        &polhode::scenario::Overrides::default(),
    )
    .map_err(|e| e.to_string())
}

#[test]
fn what_a_thruster_cannot_do_is_refused_at_load_with_the_field_named() {
    let refused = |change: &dyn Fn(String) -> String, wanted: &[&str]| {
        let e = parsed(change).expect_err("must be refused");
        for w in wanted {
            assert!(e.contains(w), "`{w}` not in: {e}");
        }
    };
    // Burnout is not modelled: a run that would empty the tank is refused.
    refused(
        &|y| y.replace("duration: 50", "duration: 200"),
        &[
            "effectors[0].thruster.tank.propellant",
            "expels 4",
            "burnout is not modelled",
        ],
    );
    refused(
        &|y| y.replace("uniform_burn", "conical"),
        &[
            "tank.model",
            "expected point, constant_volume",
            "got `conical`",
        ],
    );
    refused(
        &|y| y.replace("length: 0.9, ", ""),
        &["tank.length", "a `uniform_burn` tank needs `length` (m)"],
    );
    refused(
        &|y| y.replace("isp: 290.0", "isp: 290.0\n      mass_flow: {constant: 2.0}"),
        &["thruster.isp", "expected exactly one of `isp`"],
    );
    refused(
        &|y| y.replace("{constant: 6000.0}", "{table: [[0, 1], [0, 2]]}"),
        &["thrust.table", "the times must increase strictly"],
    );
    refused(
        &|y| {
            y.replace(
                "model: uniform_burn",
                "model: centrifugal_burn, density: 1.0",
            )
        },
        &["tank.propellant", "the tank holds at most"],
    );
    // A method that cannot integrate a body of changing mass refuses it, naming the thruster.
    refused(
        &|y| y.replace("method: dop853", "method: averaged"),
        &[
            "method `averaged`",
            "effector `thruster` (thruster) brings variable mass",
        ],
    );
    // Without the hub's mass the centre of mass is unknown.
    refused(&|y| y.replace(" mass: 500.0,", ""), &["body.mass"]);
    // An emptying sphere may not be drained to its last percent.
    refused(
        &|y| {
            y.replace(
                "{model: uniform_burn, center: [0, 0, 0], axis: [0, 0, 1], radius: 0.5,\n             length: 0.9, propellant: 350.0}",
                "{model: emptying, center: [0, 0, 0], axis: [0, 0, 1], radius: 0.4,\n             density: 1000.0, propellant: 107.0}",
            )
        },
        &["tank.propellant", "under 1 % of the sphere"],
    );
    // The motor supplies energy: no energy-drift bound applies (the momentum audit does).
    refused(
        &|y| format!("{y}checks: {{max_drift: {{energy: 1.0e-8}}}}\n"),
        &[
            "checks.max_drift.energy",
            "a thruster's motor supplies energy to it",
        ],
    );
    assert!(
        parsed(|y| format!("{y}checks: {{max_drift: {{momentum: 1.0e-10}}}}\n")).is_ok(),
        "the momentum audit takes a bound"
    );
}

#[test]
fn linearize_refuses_a_burning_stage() {
    let s = parsed(|y| y).unwrap();
    let refusal = polhode::sim::linearize_refusal(&s.spacecraft, polhode::sim::Linearisation::Spin)
        .expect("a burning stage has no equilibrium");
    assert!(refusal.reason.contains("expels mass"), "{}", refusal.reason);
}

#[test]
fn a_tank_analog_beside_a_thruster_is_warned_at_its_tank() {
    let stage = std::fs::read_to_string("scenarios/spinning-stage-tanks.yaml").unwrap();
    let engine = |thrust: f64| {
        stage.replace("duration: 600.0", "duration: 10.0").replace(
            "initial:\n",
            &format!(
                "  - thruster: {{name: engine, nozzle: [0, 0, -1.2], direction: [0, 0, 1],
      thrust: {{constant: {thrust}}}, isp: 300.0,
      tank: {{model: point, center: [0, 0, -0.5], propellant: 100.0}}}}
initial:\n"
            ),
        )
    };
    let warned = |yaml: &str| {
        scenario(yaml)
            .warnings
            .iter()
            .filter(|w| {
                w.to_string()
                    .contains("`engine` accelerates the spacecraft")
            })
            .count()
    };
    // The stage and its liquid and propellant weigh 953.7 kg: 1000 N is 1.05 m/s², 0.06 of the
    // 17.5 m/s² at the tanks, quiet; 4000 N (0.24 of it) warns at both tanks.
    assert_eq!(warned(&engine(1000.0)), 0);
    assert_eq!(warned(&engine(4000.0)), 2);
}
