//! `spring_mass_damper: {tank: …}` against Basilisk's `linearSpringMassDamper` (and, for the
//! mass on two lines, its `linearTranslationNDOFStateEffector`), along whole trajectories: the
//! four scenes of `peers/results/basilisk_slosh_spring.json` (written by
//! `peers/basilisk_slosh_spring.py` with bsk 2.12.1; this test reads the committed file and
//! needs neither Python nor Basilisk). A prolate hub (300 kg, principal moments 150, 150,
//! 60 kg m²) spun at about 3 rad/s about its minimum axis with a small transverse rate carries
//! one tank off the spin axis, stood for by polhode's spring–mass analog on one line: a
//! half-full sphere (radius 0.17 m, 1.8 m out) with the mass on the tangential line, the same
//! on the axial line, a 0.6-full upright cylinder with its damping raised 20 times, and the
//! sphere with the default directions (one mass on both lines); 80 s each, sampled every
//! second. Basilisk ran the parameters polhode derived from each tank (as
//! `polhode check` prints them, recorded in the JSON as `polhode_derived`): the sloshing mass
//! on one `linearSpringMassDamper` (on two lines: a chain of two translating bodies, the
//! first massless), the fixed liquid folded into the hub. Basilisk integrated
//! with its RKF78 at relTol 1e-13, absTol 1e-15 (task step 0.1 s); polhode integrates here
//! with dop853 at rtol 1e-12, atol 1e-14.
//!
//! Compared at every sample: the hub's ω (body axes), its attitude, the offsets ρ and their rates,
//! the angular momentum about the system's centre of mass in inertial axes (Basilisk's
//! `totRotAngMomPntC_N`) and the energy relative to the centre of mass (Basilisk's
//! `totRotEnergy`, which holds the spring's k ρ²/2 besides the kinetic energy: the script
//! checks that against its states to 5e-16; polhode's kinetic plus elastic energy here).
//!
//! Two `linearSpringMassDamper`s, one per line, would not be polhode's two-direction form: they
//! are two masses, each on its own line. Basilisk's N-DOF translating chain is the same system:
//! its first body (mass 0) moves along line 1 and carries the second (the sloshing mass) along
//! line 2, each with its own spring and the common dashpot.
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use polhode::effectors::{ParticleEffector, SloshSpring};
use polhode::scenario::{Overrides, Scenario, parse};
use polhode::sim::{self, Control, Memory, Status};
use serde_json::Value;
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// Largest allowed |polhode − Basilisk| over a scene's samples, in the order ω (rad/s),
/// attitude (rad), ρ (m), ρ̇ (m/s), H (relative to the largest |H|), energy (relative to the
/// largest).
///
/// Each is three times the two sides' integration errors added, both measured (largest over
/// the four scenes), rounded up:
///
/// | quantity | Basilisk's error¹ | polhode's error² | sum | tolerance | measured³ |
/// |---|---|---|---|---|---|
/// | ω (rad/s) | 1.7e-12 | 3.5e-13 | 2.1e-12 | 7e-12 | 8.2e-13 |
/// | attitude (rad) | 7.8e-12 | 1.0e-12 | 8.8e-12 | 3e-11 | 2.0e-12 |
/// | ρ (m) | 1.7e-12 | 3.8e-13 | 2.1e-12 | 7e-12 | 8.1e-13 |
/// | ρ̇ (m/s) | 2.2e-11 | 5.0e-12 | 2.7e-11 | 9e-11 | 1.0e-11 |
/// | H (relative) | 4.4e-14 | 8.8e-15 | 5.3e-14 | 1.6e-13 | 6.2e-15 |
/// | energy (relative) | 8.7e-14 | 1.7e-14 | 1.0e-13 | 3.2e-13 | 1.8e-14 |
///
/// ¹ the largest difference between Basilisk's recorded run (RKF78, relTol 1e-13) and its
/// three checks (RKF78 at relTol 1e-14, at half the task step, RK4 at 0.25 ms), as the JSON
/// records them; ² polhode's dop853 at rtol 1e-12 against rtol 1e-14; ³ polhode against
/// Basilisk. The test asserts that each side's own error stays within half the tolerance, so
/// that a regenerated JSON or a change of polhode's integrator cannot quietly eat the margin,
/// and that the cylinder's scene with its liquid 1e-6 denser (relative; every derived mass and
/// spring moves by that) lies far outside the tolerance (ω moves by 1.2e-5 rad/s, 1.7
/// million times it; asserted above 1e5).
const TOLERANCE: [f64; 6] = [7e-12, 3e-11, 7e-12, 9e-11, 1.6e-13, 3.2e-13];

const NAMES: [&str; 6] = [
    "ω (rad/s)",
    "attitude (rad)",
    "ρ (m)",
    "ρ̇ (m/s)",
    "H (relative)",
    "energy (relative)",
];

/// The tolerance for polhode's integration: what the scenes ask for.
const RTOL: f64 = 1e-12;
/// polhode's own check: the same scenes at rtol 1e-14, atol 1e-16.
const RTOL_CHECK: f64 = 1e-14;

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

fn v3(v: &Value) -> Vector3<f64> {
    let a = v.as_array().unwrap_or_else(|| panic!("not an array: {v}"));
    assert_eq!(a.len(), 3, "{v}");
    Vector3::new(f(&a[0]), f(&a[1]), f(&a[2]))
}

/// One sample of a trajectory, from either side.
struct Point {
    t: f64,
    omega: Vector3<f64>,
    attitude: UnitQuaternion<f64>,
    /// The offsets, one per line, then their rates.
    rho: Vec<f64>,
    h_inertial: Vector3<f64>,
    energy: f64,
}

fn basilisk_points(scene: &Value) -> Vec<Point> {
    let samples = scene["samples"].as_array().unwrap();
    samples
        .iter()
        .map(|b| {
            let q = &b["quaternion"];
            Point {
                t: f(&b["t"]),
                omega: v3(&b["omega"]),
                attitude: UnitQuaternion::from_quaternion(Quaternion::new(
                    f(&q[0]),
                    f(&q[1]),
                    f(&q[2]),
                    f(&q[3]),
                )),
                rho: [&b["rho"], &b["rho_dot"]]
                    .iter()
                    .flat_map(|v| v.as_array().unwrap().iter().map(f))
                    .collect(),
                h_inertial: v3(&b["h_inertial"]),
                energy: f(&b["energy"]),
            }
        })
        .collect()
}

/// The scene's scenario, with its integrator's rtol set to `rtol` (atol = rtol / 100) and its
/// liquid's density scaled by `density`. The first scene is `peers/slosh_spring.yaml` itself,
/// checked to be what Basilisk ran.
fn scenario(scene: &Value, rtol: f64, density: f64) -> Scenario {
    let name = scene["name"].as_str().unwrap();
    let mut s = scene["scenario"].clone();
    if name == "sphere-tangential" {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("peers/slosh_spring.yaml");
        let file: Value = serde_saphyr::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        assert_eq!(
            file, s,
            "peers/slosh_spring.yaml is not the scene of \
             peers/results/basilisk_slosh_spring.json: run peers/basilisk_slosh_spring.py again"
        );
    }
    s["integrator"] = serde_json::json!({"method": "dop853", "rtol": rtol, "atol": rtol / 100.0});
    let liquid = &mut s["effectors"][0]["spring_mass_damper"]["tank"]["liquid"];
    liquid["density"] = (f(&liquid["density"]) * density).into();
    // JSON is YAML: its text goes through `polhode::scenario::parse` unchanged.
    let text = serde_json::to_string_pretty(&s).unwrap();
    parse(
        Path::new(&format!("{name}.yaml")),
        text,
        &Overrides::default(),
    )
    .unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The tank's spring as polhode derived it.
fn spring(s: &Scenario) -> &SloshSpring {
    let e = &s.spacecraft.effectors()[0];
    (e.as_ref() as &dyn std::any::Any)
        .downcast_ref::<ParticleEffector<SloshSpring>>()
        .expect("a spring_mass_damper from a tank")
        .model()
}

fn polhode_points(s: &Scenario) -> Vec<Point> {
    let mut rec = Memory::with_states();
    let stop = AtomicBool::new(false);
    let control = Control {
        interrupt: &stop,
        progress: None,
    };
    let out = sim::run(s, &mut rec, control).unwrap();
    assert_eq!(out.status, Status::Complete, "{}", s.name);
    let sc = &s.spacecraft;
    assert_eq!(sc.effectors().len(), 1);
    // [offset, (offset_2,) offset_rate, (offset_2_rate,) dissipated_energy]
    let n = (sc.effectors()[0].num_states() - 1) / 2;
    assert_eq!(sc.effectors()[0].state_names()[n], "offset_rate");
    rec.samples
        .iter()
        .zip(&rec.states)
        .map(|(o, y)| {
            let x = sc.effector_states(0, y);
            Point {
                t: o.t,
                omega: o.omega,
                attitude: o.attitude,
                rho: x[..2 * n].to_vec(),
                h_inertial: o.h_inertial,
                energy: o.kinetic_energy + o.elastic_energy,
            }
        })
        .collect()
}

/// Largest differences between two trajectories at their common samples, in the order of
/// [`TOLERANCE`].
fn worst(label: &str, a: &[Point], b: &[Point]) -> [f64; 6] {
    assert_eq!(a.len(), b.len(), "{label}: sample count");
    let h = b.iter().map(|p| p.h_inertial.norm()).fold(0.0, f64::max);
    let e = b.iter().map(|p| p.energy).fold(0.0, f64::max);
    let mut w = [0.0_f64; 6];
    for (p, r) in a.iter().zip(b) {
        assert_eq!(p.rho.len(), r.rho.len(), "{label}: lines");
        let n = p.rho.len() / 2;
        assert!((p.t - r.t).abs() <= 1e-9, "{label}: t {} vs {}", p.t, r.t);
        let d = p.attitude.inverse() * r.attitude;
        let now = [
            (p.omega - r.omega).norm(),
            2.0 * d.imag().norm().atan2(d.w.abs()),
            (0..n)
                .map(|k| (p.rho[k] - r.rho[k]).abs())
                .fold(0.0, f64::max),
            (n..2 * n)
                .map(|k| (p.rho[k] - r.rho[k]).abs())
                .fold(0.0, f64::max),
            (p.h_inertial - r.h_inertial).norm() / h,
            (p.energy - r.energy).abs() / e,
        ];
        for (x, y) in w.iter_mut().zip(now) {
            *x = x.max(y);
        }
    }
    w
}

fn show(w: &[f64; 6]) -> String {
    NAMES
        .iter()
        .zip(w)
        .map(|(n, x)| format!("{n} {x:.1e}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Asserts `w` within `scale` × the tolerance.
fn within(label: &str, w: &[f64; 6], scale: f64) {
    for ((what, got), allowed) in NAMES.iter().zip(w).zip(TOLERANCE) {
        assert!(
            *got <= scale * allowed,
            "{label}: {what} differs by {got:.2e} > {:.2e}",
            scale * allowed
        );
    }
}

#[test]
fn tank_spring_agrees_with_basilisk_linear_spring_mass_damper() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/peers/results/basilisk_slosh_spring.json"
    );
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let data: Value = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{path}: {e}"));
    assert_eq!(data["basilisk"], "2.12.1", "the Basilisk version");
    let scenes = data["scenes"].as_array().unwrap();
    assert_eq!(scenes.len(), 4);
    for scene in scenes {
        let name = scene["name"].as_str().unwrap();
        let s = scenario(scene, RTOL, 1.0);
        let integrator = &scene["scenario"]["integrator"];
        assert_eq!(integrator["method"], "dop853", "{name}");
        assert_eq!(f(&integrator["rtol"]), RTOL, "{name}");

        // The spring Basilisk ran is the one polhode derives from the tank today, bit for bit.
        let d = &scene["polhode_derived"];
        let m = spring(&s);
        let sp = &m.spring;
        match &m.second {
            None => assert!(d.get("direction_2").is_none(), "{name}: one line"),
            Some(l) => {
                assert_eq!(l.direction, v3(&d["direction_2"]), "{name}");
                assert_eq!(l.stiffness, f(&d["stiffness_2"]), "{name}");
            }
        }
        for (what, ours, theirs) in [
            ("mass", sp.mass, f(&d["mass"])),
            ("stiffness", sp.stiffness, f(&d["stiffness"])),
            ("damping", sp.damping, f(&d["damping"])),
            ("fixed mass", m.fixed_mass, f(&d["fixed_mass"])),
        ] {
            assert_eq!(ours, theirs, "{name}: {what}: run the peer script again");
        }
        for (what, ours, theirs) in [
            ("position", sp.position, v3(&d["position"])),
            ("direction", sp.direction, v3(&d["direction"])),
            ("fixed position", m.fixed_position, v3(&d["fixed_position"])),
        ] {
            assert_eq!(ours, theirs, "{name}: {what}: run the peer script again");
        }
        let mass_at_end = &scene["facts"]["mass_at_end"];
        assert!(
            mass_at_end.is_null() || f(mass_at_end) == sp.mass,
            "{name}: Basilisk's mass changed"
        );

        // Each side's own integration error within half the tolerance.
        for check in scene["convergence"].as_array().unwrap() {
            let d = &check["max_difference"];
            let w = [
                "omega",
                "attitude",
                "rho",
                "rho_dot",
                "h_relative",
                "energy_relative",
            ]
            .map(|k| f(&d[k]));
            println!(
                "{name}: Basilisk against {}: {}",
                check["against"],
                show(&w)
            );
            within(
                &format!("{name}: Basilisk against {}", check["against"]),
                &w,
                0.5,
            );
        }
        let polhode = polhode_points(&s);
        let own = worst(
            name,
            &polhode,
            &polhode_points(&scenario(scene, RTOL_CHECK, 1.0)),
        );
        println!(
            "{name}: polhode rtol {RTOL:e} against {RTOL_CHECK:e}: {}",
            show(&own)
        );
        within(&format!("{name}: polhode's own error"), &own, 0.5);

        // polhode against Basilisk.
        let basilisk = basilisk_points(scene);
        let w = worst(name, &polhode, &basilisk);
        println!("{name}: polhode against Basilisk: {}", show(&w));
        within(&format!("{name}: polhode against Basilisk"), &w, 1.0);

        // The comparison sees a change of 1e-6 in the liquid.
        if name == "cylinder-damped" {
            let denser = polhode_points(&scenario(scene, RTOL, 1.0 + 1e-6));
            let w = worst(name, &denser, &basilisk);
            println!("{name}: liquid 1e-6 denser against Basilisk: {}", show(&w));
            let ratio = w[0] / TOLERANCE[0];
            assert!(ratio > 1e5, "{name}: ω moves by only {ratio:.1} tolerances");
        }
    }
}

/// `polhode check` prints what the tank gave its spring, in numbers that read back to the
/// model's own, bit for bit (peers/basilisk_slosh_spring.py builds Basilisk's scene from them).
#[test]
fn check_prints_the_derived_spring_exactly() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let file = root.join("peers/slosh_spring.yaml");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_polhode"))
        .arg("check")
        .arg(&file)
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text
        .lines()
        .filter(|l| l.starts_with("  spring_mass_damper tank from its tank: "))
        .collect();
    assert_eq!(lines.len(), 1, "{text}");
    // Every token that reads as a number, in order ("line 1" gives the 1).
    let printed: Vec<f64> = lines[0]
        .split([' ', '[', ']', ',', ';'])
        .filter_map(|t| t.parse().ok())
        .collect();
    let s = parse(
        &file,
        std::fs::read_to_string(&file).unwrap(),
        &Overrides::default(),
    )
    .unwrap();
    let m = spring(&s);
    let sp = &m.spring;
    let mut want = vec![sp.mass];
    want.extend(sp.position.iter());
    want.push(1.0);
    want.extend(sp.direction.iter());
    want.extend([sp.stiffness, sp.damping, m.fixed_mass]);
    want.extend(m.fixed_position.iter());
    assert_eq!(printed, want, "{}", lines[0]);
}
