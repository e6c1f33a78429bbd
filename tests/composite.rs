//! `body: {composite: true}`: mass properties given for the whole spacecraft (hub, rods and
//! dampers at rest, about the whole spacecraft's centre of mass), as mass-properties reports
//! give them; polhode subtracts the effectors at rest to get the hub's own.
//!
//! The composite numbers here are computed by hand in this file (thin rods and point masses
//! with the parallel-axis theorem), never by polhode, and the scene written both ways must run
//! the same. Also: placement is checked against `body.shape` only, and without it the run
//! says what is missing.

mod common;

use nalgebra::{Matrix3, Vector3};
use polhode::scenario::{self, Overrides, Scenario, ScenarioError};
use polhode::sim::{self, Control, EventRecord, Reference, Sink};
use std::path::Path;
use std::process::Command;
use std::sync::atomic::AtomicBool;

/// Keeps every sample's time and full state vector (ω, q, effector states).
#[derive(Default)]
struct States(Vec<(f64, Vec<f64>)>);

impl Sink for States {
    fn sample(
        &mut self,
        o: &polhode::model::Observation,
        y: &[f64],
        _: &Reference,
    ) -> std::io::Result<()> {
        self.0.push((o.t, y.to_vec()));
        Ok(())
    }
    fn event(&mut self, _: &EventRecord, _: &polhode::model::Observation) -> std::io::Result<()> {
        Ok(())
    }
}

fn parse(yaml: &str) -> Result<Scenario, ScenarioError> {
    scenario::parse(Path::new("c.yaml"), yaml.to_string(), &Overrides::default())
}

fn load(yaml: &str) -> Scenario {
    parse(yaml).unwrap_or_else(|e| panic!("invalid test scenario: {e}\n{yaml}"))
}

fn states(s: &Scenario) -> Vec<(f64, Vec<f64>)> {
    let mut rec = States::default();
    let stop = AtomicBool::new(false);
    sim::run(
        s,
        &mut rec,
        Control {
            interrupt: &stop,
            progress: None,
        },
    )
    .expect("in-memory sink");
    rec.0
}

/// |r|² 1 − r rᵀ: the parallel-axis term per unit mass.
fn shift(r: Vector3<f64>) -> Matrix3<f64> {
    Matrix3::identity() * r.norm_squared() - r * r.transpose()
}

fn v(a: Vector3<f64>) -> String {
    format!("[{:?}, {:?}, {:?}]", a[0], a[1], a[2])
}

fn m(a: &Matrix3<f64>) -> String {
    let row = |r: usize| format!("[{:?}, {:?}, {:?}]", a[(r, 0)], a[(r, 1)], a[(r, 2)]);
    format!("[{}, {}, {}]", row(0), row(1), row(2))
}

/// A thin uniform rod on a hinge, at rest along `dir`.
struct Rod {
    mass: f64,
    length: f64,
    hinge: Vector3<f64>,
    dir: Vector3<f64>,
    axis: Vector3<f64>,
    yaml_rest: &'static str,
}

/// A particle on a spring, at rest at `at`.
struct Particle {
    mass: f64,
    at: Vector3<f64>,
    yaml_rest: &'static str,
}

/// The test scene: a hub with a full (non-diagonal) inertia tensor, two hinged rods and a
/// spring–mass damper, every effector started away from rest.
struct Scene {
    hub_mass: f64,
    hub_inertia: Matrix3<f64>,
    rods: Vec<Rod>,
    particles: Vec<Particle>,
}

fn scene() -> Scene {
    Scene {
        hub_mass: 80.0,
        hub_inertia: Matrix3::new(30.0, -1.2, 0.8, -1.2, 25.0, 0.5, 0.8, 0.5, 20.0),
        rods: vec![
            Rod {
                mass: 2.0,
                length: 3.0,
                hinge: Vector3::new(0.6, 0.1, 0.0),
                dir: Vector3::x(),
                axis: Vector3::z(),
                yaml_rest: "stiffness: [2.0, 3.0], damping: 0.05, initial_angles: [0.05, -0.03], \
                            initial_rates: [0.01, 0.02]",
            },
            Rod {
                mass: 1.5,
                length: 2.0,
                hinge: Vector3::new(-0.5, 0.2, 0.3),
                dir: -Vector3::x(),
                axis: Vector3::y(),
                yaml_rest: "freedom: flap, stiffness: 1.5, damping: 0.02, \
                            initial_angles: [-0.04, 0.0]",
            },
        ],
        particles: vec![Particle {
            mass: 0.7,
            at: Vector3::new(0.1, -0.4, 0.35),
            yaml_rest: "direction: [0, 0, 1], stiffness: 50.0, damping: 0.3, \
                        initial_offset: 0.02",
        }],
    }
}

impl Scene {
    /// The whole spacecraft at rest by hand, about the hub's centre of mass: mass, centre of
    /// mass, and inertia about that centre of mass.
    fn composite(&self) -> (f64, Vector3<f64>, Matrix3<f64>) {
        // (mass, centre of mass, inertia about its own centre of mass) of every part.
        let mut parts = vec![(self.hub_mass, Vector3::zeros(), self.hub_inertia)];
        for r in &self.rods {
            let own = r.mass * r.length * r.length / 12.0
                * (Matrix3::identity() - r.dir * r.dir.transpose());
            parts.push((r.mass, r.hinge + 0.5 * r.length * r.dir, own));
        }
        for p in &self.particles {
            parts.push((p.mass, p.at, Matrix3::zeros()));
        }
        let total: f64 = parts.iter().map(|p| p.0).sum();
        let cm = parts.iter().map(|p| p.0 * p.1).sum::<Vector3<f64>>() / total;
        let inertia = parts
            .iter()
            .map(|(mass, c, own)| own + *mass * shift(c - cm))
            .sum();
        (total, cm, inertia)
    }

    /// The scene as YAML: the hub's own mass properties and positions about the hub's centre
    /// of mass, or (`composite`) the whole spacecraft's and positions about its centre of mass.
    fn yaml(&self, composite: bool, shape: bool) -> String {
        let (body, origin) = if composite {
            let (mass, cm, inertia) = self.composite();
            (
                format!(
                    "{{composite: true, mass: {mass:?}, inertia: {}",
                    m(&inertia)
                ),
                cm,
            )
        } else {
            (
                format!(
                    "{{mass: {:?}, inertia: {}",
                    self.hub_mass,
                    m(&self.hub_inertia)
                ),
                Vector3::zeros(),
            )
        };
        let shape = if shape {
            ", shape: {box: {size: [1.6, 1.2, 1.0]}}"
        } else {
            ""
        };
        let mut y = format!(
            "name: composite\nbody: {body}, spin_axis: [0, 0, 1]{shape}}}\n\
             initial: {{omega: [0.05, 0.1, 1.2]}}\nduration: 20.0\n\
             integrator: {{method: rk4, dt: 0.002}}\noutput: {{rate: 5}}\neffectors:\n"
        );
        for r in &self.rods {
            y += &format!(
                "  - hinged_rod: {{mass: {:?}, length: {:?}, hinge: {}, direction: {}, axis: {}, {}}}\n",
                r.mass,
                r.length,
                v(r.hinge - origin),
                v(r.dir),
                v(r.axis),
                r.yaml_rest
            );
        }
        for p in &self.particles {
            y += &format!(
                "  - spring_mass_damper: {{mass: {:?}, position: {}, {}}}\n",
                p.mass,
                v(p.at - origin),
                p.yaml_rest
            );
        }
        y
    }
}

fn max_abs(a: &Matrix3<f64>) -> f64 {
    a.amax()
}

#[test]
fn composite_round_trip_gives_the_hub_and_the_trajectory_back() {
    let sc = scene();
    let (total_mass, cm, total_inertia) = sc.composite();
    // The hand calculation itself, on numbers small enough to check on paper: the mass.
    assert_eq!(total_mass, 80.0 + 2.0 + 1.5 + 0.7);
    for shape in [true, false] {
        let plain = load(&sc.yaml(false, shape));
        let comp = load(&sc.yaml(true, shape));
        let c = comp.composite.as_ref().expect("composite report");
        // The hub's own mass, centre of mass and inertia come back.
        let hub_mass = comp.spacecraft.hub_mass.expect("hub mass");
        assert!(
            (hub_mass - sc.hub_mass).abs() < 1e-12 * sc.hub_mass,
            "{hub_mass}"
        );
        assert!((c.effector_mass - 4.2).abs() < 1e-12, "{}", c.effector_mass);
        assert_eq!(c.total_mass, Some(total_mass));
        // The hub's centre of mass is −(the whole's, measured from the hub's).
        assert!(
            (c.hub_offset + cm).amax() < 1e-13,
            "{} vs {}",
            c.hub_offset,
            -cm
        );
        let d = max_abs(&(comp.spacecraft.hub.inertia - sc.hub_inertia));
        assert!(d < 1e-12 * 30.0, "hub inertia off by {d:e}");
        assert!(max_abs(&(plain.spacecraft.hub.inertia - sc.hub_inertia)) == 0.0);
        // polhode's own composite at rest (system_inertia) is the total given, about the
        // whole's centre of mass: the subtraction and the model agree.
        for s in [&plain, &comp] {
            let rest = s.spacecraft.rest_state(&s.omega0, &s.attitude0);
            let d = max_abs(&(s.spacecraft.system_inertia(&rest) - total_inertia));
            assert!(d < 1e-11, "system inertia at rest off by {d:e}");
        }
        // The same motion, sample by sample: ω, q, rod angles and rates, damper offset.
        let (a, b) = (states(&plain), states(&comp));
        assert_eq!(a.len(), b.len());
        assert_eq!(a.len(), 101);
        let mut worst = 0.0f64;
        for ((ta, ya), (tb, yb)) in a.iter().zip(&b) {
            assert_eq!(ta, tb);
            for (x, y) in ya.iter().zip(yb) {
                worst = worst.max((x - y).abs());
            }
        }
        eprintln!(
            "shape {shape}: hub inertia off by {d:e}, trajectories differ by at most {worst:e}"
        );
        assert!(worst < 1e-12, "trajectories differ by {worst:e}");
        // It moved: the rods swing and the spin precesses, so agreement is not trivial.
        let last = &a.last().unwrap().1;
        assert!((last[0] - 0.05).abs() > 1e-3 && (last[7] - 0.05).abs() > 1e-3);
    }
}

#[test]
fn composite_effector_positions_are_about_the_whole_spacecraft_centre_of_mass() {
    // A point mass m on a spring at +x from the whole spacecraft's centre of mass: the hub's
    // centre of mass is at −m x / (M − m) from it, and the point sits at x M / (M − m) from the
    // hub's. With M = 10, m = 2, x = 0.4: offset −0.1, position 0.5.
    let y = "name: c\nbody: {composite: true, mass: 10.0, principal: [5.0, 6.0, 7.0]}\n\
             initial: {omega: [0.0, 0.0, 1.0]}\nduration: 1.0\n\
             effectors:\n  - spring_mass_damper: {mass: 2.0, position: [0.4, 0, 0], \
             direction: [0, 0, 1], stiffness: 10.0, damping: 0.1}\n";
    let s = load(y);
    let c = s.composite.as_ref().unwrap();
    assert!((c.hub_offset - Vector3::new(-0.1, 0.0, 0.0)).amax() < 1e-15);
    assert!((s.spacecraft.hub_mass.unwrap() - 8.0).abs() < 1e-15);
    // Hub about its own centre of mass: I − m P(x) − m_h P(c) = diag(5, 6, 7) − diag(0, 0.32, 0.32)
    // − diag(0, 0.08, 0.08) = diag(5, 5.6, 6.6).
    let want = Matrix3::from_diagonal(&Vector3::new(5.0, 5.6, 6.6));
    assert!(
        max_abs(&(s.spacecraft.hub.inertia - want)) < 1e-14,
        "{}",
        s.spacecraft.hub.inertia
    );
    let rest = s.spacecraft.rest_state(&s.omega0, &s.attitude0);
    let h = s.spacecraft.observe(0.0, &rest);
    // At rest the particle is 0.5 m from the hub's centre of mass: H_z = 7 (the total) × 1.
    assert!((h.h_body[2] - 7.0).abs() < 1e-13, "{}", h.h_body);
}

#[test]
fn an_unphysical_remainder_is_refused_with_the_numbers() {
    let sc = scene();
    // Outweighed: the whole spacecraft given lighter than its rods and damper (4.2 kg).
    let y = sc.yaml(true, true).replacen("mass: 84.2,", "mass: 4.0,", 1);
    assert!(y.contains("mass: 4.0,"));
    let e = parse(&y).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("body.mass"));
    assert_eq!((e.line, e.column), (Some(2), Some(31)), "{e}");
    for part in ["4 kg", "4.2 kg", "-0.2", "outweigh the total"] {
        assert!(e.message.contains(part), "{part}: {e}");
    }
    // Out-inertia'd: 3 m and 2 m rods of 2 and 1.5 kg about a 1 kg m² "whole spacecraft".
    let y = "name: c\nbody:\n  composite: true\n  mass: 50.0\n  principal: [1.0, 1.0, 1.0]\n\
             initial: {omega: [0.0, 0.0, 1.0]}\nduration: 1.0\neffectors:\n\
             \x20 - hinged_rod: {mass: 2.0, length: 3.0, hinge: [0.5, 0, 0], direction: [1, 0, 0], \
             axis: [0, 0, 1], stiffness: 1.0, damping: 0.1}\n";
    let e = parse(y).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("body.principal"));
    assert_eq!((e.line, e.column), (Some(5), Some(14)), "{e}");
    // By hand: the rod's centre at x = 2 m, hub mass 48 kg with its centre of mass at
    // c = −2·2/48 = −1/12 m; about the whole's centre of mass the rod gives
    // 2·3²/12 + 2·2² = 9.5 about y and z and 0 about x, the hub's shift 48/144 = 1/3:
    // 59/6 = 9.833333 taken from 1 kg m², leaving −8.833333.
    let taken = 2.0 * 9.0 / 12.0 + 2.0 * 4.0 + 48.0 / 144.0;
    for part in [
        "1.000000e0, 1.000000e0, 1.000000e0".to_string(),
        format!("0.000000e0, {taken:.6e}, {taken:.6e}"),
        "out-inertia the total given".into(),
        "not a physical inertia tensor".into(),
        format!("{:.6e}", 1.0 - taken),
    ] {
        assert!(e.message.contains(&part), "{part}: {e}");
    }
}

#[test]
fn composite_without_mass_moving_effectors_is_the_plain_body() {
    let base = "initial: {omega: [0.02, 0.3, 1.1]}\nduration: 10.0\n\
                integrator: {method: dop853, rtol: 1.0e-11, atol: 1.0e-13}\noutput: {rate: 5}\n";
    let effectors = "effectors:\n  - wheel_damper: {inertia: 0.4, axis: [0, 0, 1], damping: 0.05}\n  \
                     - rayleigh: {gamma_diagonal: [0.01, 0.01, 0.0]}\n";
    for (fx, bodies) in [
        (
            "",
            [
                "body: {principal: [10.0, 12.0, 15.0]}",
                "body: {composite: true, principal: [10.0, 12.0, 15.0]}",
            ],
        ),
        (
            effectors,
            [
                "body: {mass: 40.0, inertia: [[10, 0.1, 0], [0.1, 12, 0], [0, 0, 15]]}",
                "body: {composite: true, mass: 40.0, inertia: [[10, 0.1, 0], [0.1, 12, 0], [0, 0, 15]]}",
            ],
        ),
    ] {
        let [plain, comp] = bodies.map(|b| load(&format!("name: c\n{b}\n{base}{fx}")));
        assert_eq!(plain.spacecraft.hub.inertia, comp.spacecraft.hub.inertia);
        assert_eq!(plain.spacecraft.hub_mass, comp.spacecraft.hub_mass);
        assert_eq!(plain.spacecraft.spin_axis, comp.spacecraft.spin_axis);
        assert_eq!(comp.composite.as_ref().unwrap().effector_mass, 0.0);
        assert_eq!(states(&plain), states(&comp), "{fx}");
    }
    // The wheel's rotor stays in the body's inertia: its limit is the given body's.
    let big = format!(
        "name: c\nbody: {{composite: true, principal: [10.0, 12.0, 15.0]}}\n{base}effectors:\n  \
         - wheel_damper: {{inertia: 15.0, axis: [0, 0, 1], damping: 0.05}}\n"
    );
    let e = parse(&big).unwrap_err();
    assert!(
        e.message.contains("less than 1 / (âᵀ I⁻¹ â) = 15 kg m²"),
        "{e}"
    );
}

/// A hinge 10 m from the centre of a 1 m hub.
fn far_hinge(shape: bool) -> String {
    format!(
        "name: far\nbody:\n  mass: 10.0\n  principal: [1.0, 2.0, 3.0]\n{}initial:\n  omega: [0.1, 0.0, 1.0]\n\
         duration: 0.5\noutput: {{rate: 10}}\neffectors:\n  - hinged_rod:\n      mass: 0.1\n      \
         length: 0.5\n      hinge: [10.0, 0.0, 0.0]\n      direction: [1, 0, 0]\n      \
         axis: [0, 0, 1]\n      stiffness: 1.0\n      damping: 0.1\n",
        if shape {
            "  shape: {box: {size: [1.0, 1.0, 1.0]}}\n"
        } else {
            ""
        }
    )
}

#[test]
fn placement_is_checked_against_the_given_shape_only() {
    // With a shape: refused as before, at the hinge.
    let e = parse(&far_hinge(true)).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("effectors[0].hinged_rod.hinge"));
    assert_eq!((e.line, e.column), (Some(14), Some(14)), "{e}");
    assert!(
        e.message
            .contains("[10, 0, 0] m is outside the body by 9.5000 m"),
        "{e}"
    );
    // Without one: accepted, with a located note naming what to add.
    let s = load(&far_hinge(false));
    assert_eq!(s.warnings.len(), 1);
    let w = &s.warnings[0];
    assert_eq!(w.field.as_deref(), Some("effectors[0].hinged_rod.hinge"));
    assert_eq!((w.line, w.column), (Some(13), Some(14)), "{w}");
    assert!(
        w.message
            .starts_with("placement not checked: give `body.shape`"),
        "{w}"
    );
    assert!(
        w.message.contains("the hinge is on or inside the body"),
        "{w}"
    );
    // Nothing is said when there is nothing to place, or when the shape was given.
    let plain = "name: p\nbody: {principal: [1.0, 2.0, 3.0]}\ninitial: {omega: [0.1, 0.0, 1.0]}\n\
                 duration: 0.5\n";
    assert!(load(plain).warnings.is_empty());
    let inside = far_hinge(true).replace("hinge: [10.0", "hinge: [0.5");
    assert!(load(&inside).warnings.is_empty());
}

fn polhode() -> Command {
    Command::new(env!("CARGO_BIN_EXE_polhode"))
}

/// A fresh, empty scratch directory for one test, removed when it passes.
fn scratch(name: &str) -> common::Scratch {
    common::Scratch::new("polhode-composite", name)
}

#[test]
fn check_and_run_print_the_note_and_the_hub_remainder() {
    let dir = scratch("cli");
    let far = dir.join("far.yaml");
    std::fs::write(&far, far_hinge(false)).unwrap();
    let want = format!(
        "warning: {}:13:14: field `effectors[0].hinged_rod.hinge`: placement not checked: give \
         `body.shape`",
        far.display()
    );
    let out = polhode().arg("check").arg(&far).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(err.contains(&want), "{err}");
    let out = polhode()
        .args(["run", "--no-log"])
        .arg(&far)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(err.contains(&want), "{err}");

    // The remainder, printed: the point-mass case of the test above (hub 8 kg at −0.1 m,
    // principal moments 5, 5.6, 6.6 kg m²).
    let comp = dir.join("comp.yaml");
    std::fs::write(
        &comp,
        "name: c\nbody: {composite: true, mass: 10.0, principal: [5.0, 6.0, 7.0], \
         shape: {box: {size: [1, 1, 1]}}}\ninitial: {omega: [0.0, 0.0, 1.0]}\nduration: 0.5\n\
         effectors:\n  - spring_mass_damper: {mass: 2.0, position: [0.4, 0, 0], \
         direction: [0, 0, 1], stiffness: 10.0, damping: 0.1}\n",
    )
    .unwrap();
    let line = "  hub (composite body minus the effectors at rest): mass 8.000000000e0 kg (of 10 \
                kg; effectors 2.000000000e0 kg), centre of mass [-1.000000000e-1, +0.000000000e0, \
                +0.000000000e0] m from the whole spacecraft's, principal moments 5.000000000e0, \
                5.600000000e0, 6.600000000e0 kg m²";
    for cmd in [vec!["check"], vec!["run", "--no-log"]] {
        let out = polhode().args(&cmd).arg(&comp).output().unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{cmd:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(text.lines().any(|l| l == line), "{cmd:?}: {text}");
        assert!(
            out.stderr.is_empty(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
