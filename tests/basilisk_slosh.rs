//! `slosh_pendulum` against Basilisk's `sphericalPendulum`, along whole trajectories: the
//! three scenes of `peers/results/basilisk_slosh.json` (written by `peers/basilisk_slosh.py`
//! with bsk 2.12.1; this test reads the committed file and needs neither Python nor
//! Basilisk). A prolate hub (600 kg, principal moments 400, 400, 100 kg m²) spun at 3 rad/s
//! about its minimum axis with a small transverse rate carries one spherical pendulum
//! (20 kg on 0.3 m) whose pivot is off the spin axis: `peers/slosh.yaml` as written (damping
//! 2 N s/m), the same undamped, and a pivot on the −y side with an oblique rest direction and
//! damping 5 N s/m; 80 s each (240 rad of spin), sampled every second. Basilisk integrated
//! them with its RKF78 at relTol 1e-13, absTol 1e-15 (task step 0.1 s); polhode integrates
//! them here with dop853 at rtol 1e-12, atol 1e-14.
//!
//! Compared at every sample: the hub's ω (body axes), its attitude, the pendulum's φ, θ and
//! their rates, the angular momentum about the system's centre of mass in inertial axes
//! (Basilisk's `totRotAngMomPntC_N`) and the kinetic energy relative to the centre of mass
//! (Basilisk's `totRotEnergy`). The first scene is built from `peers/slosh.yaml` itself,
//! after checking that it is the scene Basilisk ran; the variants from the parameters the
//! JSON records (JSON is YAML: its text goes through `polhode::scenario::parse` unchanged).
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use polhode::scenario::{Overrides, parse};
use polhode::sim::{self, Control, Memory, Status};
use serde_json::Value;
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// Largest allowed |polhode − Basilisk| over a scene's samples.
///
/// Each is three times the two sides' integration errors added, both measured (largest over
/// the three scenes):
///
/// | quantity | Basilisk's error¹ | polhode's error² | sum | tolerance | measured³ |
/// |---|---|---|---|---|---|
/// | ω (rad/s) | 7.1e-13 | 1.4e-13 | 8.5e-13 | 3e-12 | 3.3e-13 |
/// | attitude (rad) | 6.5e-12 | 3.5e-13 | 6.9e-12 | 2e-11 | 2.3e-12 |
/// | φ, θ (rad) | 8.6e-12 | 2.4e-12 | 1.1e-11 | 3e-11 | 6.8e-12 |
/// | φ̇, θ̇ (rad/s) | 3.9e-11 | 1.1e-11 | 5.0e-11 | 1.5e-10 | 3.0e-11 |
/// | H (relative) | 6.1e-14 | 1.4e-13 | 2.0e-13 | 6e-13 | 1.5e-13 |
/// | energy (relative) | 8.2e-14 | 7.2e-15 | 8.9e-14 | 3e-13 | 9.6e-15 |
///
/// ¹ the largest difference between Basilisk's recorded run (RKF78, relTol 1e-13) and its
/// three checks (RKF78 at relTol 1e-14, at half the task step, RK4 at 0.5 ms), as the JSON
/// records them; ² polhode's dop853 at rtol 1e-12 against rtol 1e-14; ³ polhode against
/// Basilisk. The test asserts that each side's own error stays within half the tolerance, so
/// that a regenerated JSON or a change of polhode's integrator cannot quietly eat the margin.
/// For scale: the amplitudes are 0.1–0.3 rad in φ and θ, and the oblique scene with its
/// damping made 1e-6 larger (relative) moves ω by 1.3e-8 rad/s, four thousand times the
/// tolerance.
struct Tolerance {
    omega: f64,
    attitude: f64,
    angle: f64,
    rate: f64,
    h_relative: f64,
    energy_relative: f64,
}

const TOLERANCE: Tolerance = Tolerance {
    omega: 3e-12,
    attitude: 2e-11,
    angle: 3e-11,
    rate: 1.5e-10,
    h_relative: 6e-13,
    energy_relative: 3e-13,
};

/// The tolerance for polhode's integration: what the scenes ask for.
const RTOL: f64 = 1e-12;
/// polhode's own check: the same scenes at rtol 1e-14, atol 1e-16.
const RTOL_CHECK: f64 = 1e-14;

fn results() -> Value {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/peers/results/basilisk_slosh.json"
    );
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{path}: {e}"))
}

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
    /// [φ, θ, φ̇, θ̇].
    pendulum: [f64; 4],
    h_inertial: Vector3<f64>,
    energy: f64,
}

fn basilisk_points(scene: &Value) -> Vec<Point> {
    scene["samples"]
        .as_array()
        .unwrap()
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
                pendulum: [
                    f(&b["phi"]),
                    f(&b["theta"]),
                    f(&b["phi_dot"]),
                    f(&b["theta_dot"]),
                ],
                h_inertial: v3(&b["h_inertial"]),
                energy: f(&b["energy"]),
            }
        })
        .collect()
}

/// The YAML text of a scene: `peers/slosh.yaml` for the first (checked to be what Basilisk
/// ran), the recorded parameters for the others.
fn scene_yaml(scene: &Value) -> String {
    let recorded = &scene["scenario"];
    if scene["name"] == "spinner-damped" {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("peers/slosh.yaml");
        let text = std::fs::read_to_string(&path).unwrap();
        let file: Value = serde_saphyr::from_str(&text).unwrap();
        assert_eq!(
            &file, recorded,
            "peers/slosh.yaml is not the scene of peers/results/basilisk_slosh.json: run \
             peers/basilisk_slosh.py again"
        );
        text
    } else {
        serde_json::to_string_pretty(recorded).unwrap()
    }
}

/// polhode's samples of a scene given as YAML text, with the effector's states by name.
fn polhode_points(yaml: &str, label: &str) -> Vec<Point> {
    let scenario = parse(
        Path::new(&format!("{label}.yaml")),
        yaml.to_string(),
        &Overrides::default(),
    )
    .unwrap_or_else(|e| panic!("{label}: {e}"));
    let mut rec = Memory::with_states();
    let stop = AtomicBool::new(false);
    let out = sim::run(
        &scenario,
        &mut rec,
        Control {
            interrupt: &stop,
            progress: None,
        },
    )
    .unwrap();
    assert_eq!(out.status, Status::Complete, "{label}");
    let sc = &scenario.spacecraft;
    assert_eq!(sc.effectors().len(), 1, "{label}");
    assert_eq!(sc.effectors()[0].kind(), "slosh_pendulum", "{label}");
    let names = sc.effectors()[0].state_names();
    let index = |n: &str| {
        names
            .iter()
            .position(|s| s == n)
            .unwrap_or_else(|| panic!("{label}: no state {n} in {names:?}"))
    };
    let i = [
        index("phi"),
        index("theta"),
        index("phi_rate"),
        index("theta_rate"),
    ];
    rec.samples
        .iter()
        .zip(&rec.states)
        .map(|(o, y)| {
            let x = sc.effector_states(0, y);
            Point {
                t: o.t,
                omega: o.omega,
                attitude: o.attitude,
                pendulum: i.map(|k| x[k]),
                h_inertial: o.h_inertial,
                energy: o.kinetic_energy,
            }
        })
        .collect()
}

/// Largest differences between two trajectories at their common samples.
#[derive(Debug, Default)]
struct Worst {
    omega: f64,
    attitude: f64,
    angle: f64,
    rate: f64,
    h_relative: f64,
    energy_relative: f64,
}

impl std::fmt::Display for Worst {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(
            f,
            "ω {:.1e} rad/s, attitude {:.1e} rad, φ/θ {:.1e} rad, φ̇/θ̇ {:.1e} rad/s, \
             H {:.1e}, energy {:.1e} (relative)",
            self.omega, self.attitude, self.angle, self.rate, self.h_relative, self.energy_relative
        )
    }
}

fn worst(label: &str, a: &[Point], b: &[Point]) -> Worst {
    assert_eq!(a.len(), b.len(), "{label}: sample count");
    let h = b.iter().map(|p| p.h_inertial.norm()).fold(0.0, f64::max);
    let e = b.iter().map(|p| p.energy).fold(0.0, f64::max);
    let mut w = Worst::default();
    for (p, r) in a.iter().zip(b) {
        assert!(
            (p.t - r.t).abs() <= 1e-9,
            "{label}: sample at {} vs {}",
            p.t,
            r.t
        );
        let d = p.attitude.inverse() * r.attitude;
        w.omega = w.omega.max((p.omega - r.omega).norm());
        w.attitude = w.attitude.max(2.0 * d.imag().norm().atan2(d.w.abs()));
        for k in 0..2 {
            w.angle = w.angle.max((p.pendulum[k] - r.pendulum[k]).abs());
            w.rate = w.rate.max((p.pendulum[k + 2] - r.pendulum[k + 2]).abs());
        }
        w.h_relative = w.h_relative.max((p.h_inertial - r.h_inertial).norm() / h);
        w.energy_relative = w.energy_relative.max((p.energy - r.energy).abs() / e);
    }
    w
}

/// Asserts `w` within `scale` × the tolerance.
fn within(label: &str, w: &Worst, scale: f64) {
    let t = &TOLERANCE;
    for (what, got, allowed) in [
        ("ω (rad/s)", w.omega, t.omega),
        ("attitude (rad)", w.attitude, t.attitude),
        ("φ or θ (rad)", w.angle, t.angle),
        ("φ̇ or θ̇ (rad/s)", w.rate, t.rate),
        ("H (relative)", w.h_relative, t.h_relative),
        ("energy (relative)", w.energy_relative, t.energy_relative),
    ] {
        assert!(
            got <= scale * allowed,
            "{label}: {what} differs by {got:.2e} > {:.2e}",
            scale * allowed
        );
    }
}

/// The scene's scenario with polhode's tolerances set to `rtol` (atol = rtol / 100).
fn with_rtol(scene: &Value, rtol: f64) -> String {
    let mut s = scene["scenario"].clone();
    s["integrator"] = serde_json::json!({"method": "dop853", "rtol": rtol, "atol": rtol / 100.0});
    serde_json::to_string_pretty(&s).unwrap()
}

#[test]
fn slosh_pendulum_agrees_with_basilisk_sphericalpendulum() {
    let data = results();
    assert_eq!(
        data["basilisk"], "2.12.1",
        "the Basilisk version of the results"
    );
    let scenes = data["scenes"].as_array().unwrap();
    assert_eq!(scenes.len(), 3);
    for scene in scenes {
        let name = scene["name"].as_str().unwrap();
        let facts = &scene["facts"];
        // Basilisk's angles are polhode's only while it keeps its pendulum frame (it re-bases
        // it when |cos θ| < √2/2) and its mass constant (no fuel tank).
        assert_eq!(
            facts["rebased"], false,
            "{name}: Basilisk re-based its P0 frame"
        );
        assert_eq!(
            f(&facts["mass_at_end"]),
            f(&scene["scenario"]["effectors"][0]["slosh_pendulum"]["mass"]),
            "{name}: Basilisk's pendulum mass changed"
        );
        // The scene as polhode integrates it: the file's (or recorded) dop853 at rtol 1e-12.
        let integrator = &scene["scenario"]["integrator"];
        assert_eq!(integrator["method"], "dop853", "{name}");
        assert_eq!(f(&integrator["rtol"]), RTOL, "{name}");

        // Each side's own integration error within half the tolerance.
        for check in scene["convergence"].as_array().unwrap() {
            let d = &check["max_difference"];
            let w = Worst {
                omega: f(&d["omega"]),
                attitude: f(&d["attitude"]),
                angle: f(&d["phi"]).max(f(&d["theta"])),
                rate: f(&d["phi_dot"]).max(f(&d["theta_dot"])),
                h_relative: f(&d["h_relative"]),
                energy_relative: f(&d["energy_relative"]),
            };
            within(
                &format!("{name}: Basilisk's run against {}", check["against"]),
                &w,
                0.5,
            );
        }
        let polhode = polhode_points(&scene_yaml(scene), name);
        let tight = polhode_points(&with_rtol(scene, RTOL_CHECK), name);
        let own = worst(name, &polhode, &tight);
        println!("{name}: polhode rtol {RTOL:e} against rtol {RTOL_CHECK:e}: {own}");
        within(&format!("{name}: polhode's own error"), &own, 0.5);

        // polhode against Basilisk.
        let basilisk = basilisk_points(scene);
        let w = worst(name, &polhode, &basilisk);
        println!("{name}: polhode against Basilisk: {w}");
        within(&format!("{name}: polhode against Basilisk"), &w, 1.0);
    }
}
