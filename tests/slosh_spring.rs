//! `spring_mass_damper: {tank: …}` (issue 36): the spring–mass analog of a tank's first
//! lateral slosh mode, against things this code did not produce.
//!
//! **Closed form.** A particle of mass m on a line p̂ through r₀, in a body spinning steadily
//! at Ω about ẑ, feels the centrifugal force m Ω² (r − ẑ (ẑ·r)) and the Coriolis force
//! −2 m Ω ẑ × ṙ. Along p̂ at r = r₀ + ρ p̂ the Coriolis force vanishes (ṙ ∥ p̂) and the
//! centrifugal one is m Ω² (p̂·r₀ − (ẑ·p̂)(ẑ·r₀) + ρ (1 − (ẑ·p̂)²)). With a spring k and a
//! dashpot c, for r₀ in the x–z plane:
//!
//! ```text
//! p̂ = ŷ (tangential):  m ρ̈ + c ρ̇ + (k − m Ω²) ρ = 0,
//! p̂ = ẑ (axial):       m ρ̈ + c ρ̇ + k ρ = 0,
//! ```
//!
//! so s² + (c/m) s + ω₀² = 0 with ω₀² = k/m − Ω² across the spin and k/m along its axis. A
//! hub of 10¹¹ kg and kg m² holds the spin, so `linearize` of the whole spacecraft returns
//! these roots. The tank form chooses k so that both are the analog's ω₁
//! ([`slosh_analog`], evaluated here directly in the field Ω² r_T).

mod common;

use common::{run, scenario};
use polhode::effectors::slosh_analog::{Liquid, Tank, slosh_analog};
use polhode::linearize::{linearize, spin_rate_of};
use polhode::model::HubState;
use polhode::scenario::{Overrides, parse};
use polhode::sim::Status;

const HYDRAZINE: Liquid = Liquid {
    density: 1004.0,
    kinematic_viscosity: 9.7e-7,
    surface_tension: 0.066,
};
const LIQUID: &str = "{density: 1004.0, kinematic_viscosity: 9.7e-7, surface_tension: 0.066}";
const HOLDING_HUB: &str = "body: {mass: 1.0e11, principal: [1.0e11, 1.05e11, 1.1e11], \
                           spin_axis: [0, 0, 1]}";

/// The roots of s² + 2ζω s + ω² = 0 with Im > 0.
fn roots(omega: f64, zeta: f64) -> (f64, f64) {
    (-zeta * omega, omega * (1.0 - zeta * zeta).sqrt())
}

/// `count` modes with Im > 0 at `(re, im)`, to `tol` of `im`.
fn assert_modes(s: &polhode::scenario::Scenario, re: f64, im: f64, count: usize, tol: f64) {
    let lin = linearize(&s.spacecraft, spin_rate_of(&s.spacecraft, &s.omega0)).unwrap();
    let near: Vec<_> = lin
        .modes
        .iter()
        .filter(|m| m.im > 0.0 && (m.im - im).abs() < 1e-3 * im)
        .collect();
    assert_eq!(near.len(), count, "{:?} against {re} + {im}i", lin.modes);
    let worst = near
        .iter()
        .map(|m| (m.re - re).abs().max((m.im - im).abs()) / im)
        .fold(0.0, f64::max);
    eprintln!("{count} modes at {re:.6e} + {im:.6}i, worst relative distance {worst:.1e}");
    for m in near {
        assert!(
            (m.re - re).abs() < tol * im && (m.im - im).abs() < tol * im,
            "{} + {}i against {re} + {im}i",
            m.re,
            m.im
        );
    }
}

/// The closed form above with the damper as it always was: springs across the spin lose
/// Ω² to the centrifugal field's gradient, springs along the spin axis do not.
#[test]
fn a_spring_across_the_spin_loses_omega_squared_and_one_along_it_does_not() {
    let (spin, b, m, k, c) = (3.0_f64, 0.6, 20.0, 900.0, 12.0);
    for (direction, w0_sq) in [("[0, 1, 0]", k / m - spin * spin), ("[0, 0, 1]", k / m)] {
        // Two opposite dampers keep the composite centre of mass on the hub's.
        let yaml = format!(
            "name: t\n{HOLDING_HUB}\ninitial: {{omega: [0, 0, {spin}]}}\nduration: 1.0\n\
             effectors:\n\
             \x20 - spring_mass_damper: {{name: a, mass: {m}, position: [{b}, 0, 0.3], \
             direction: {direction}, stiffness: {k}, damping: {c}}}\n\
             \x20 - spring_mass_damper: {{name: b, mass: {m}, position: [-{b}, 0, 0.3], \
             direction: {direction}, stiffness: {k}, damping: {c}}}\n"
        );
        let w0 = w0_sq.sqrt();
        let (re, im) = roots(w0, c / (2.0 * m * w0));
        assert_modes(&scenario(&yaml), re, im, 2, 1e-8);
    }
}

/// Two opposite tanks of `shape` (YAML) on a body spinning at `spin` about z, their centres
/// `x` from the axis; `extra` goes into the first entry.
fn tanks(body: &str, spin: f64, shape: &str, x: f64, fill: f64, extra: &str) -> String {
    let entry = |name: &str, sign: &str, extra: &str| {
        format!(
            "  - spring_mass_damper:\n      name: {name}\n{extra}      tank:\n        \
             shape: {shape}\n        center: [{sign}{x}, 0.0, 0.2]\n        fill: {fill}\n        \
             liquid: {LIQUID}\n"
        )
    };
    format!(
        "name: t\n{body}\ninitial: {{omega: [0.0, 0.0, {spin}]}}\nduration: 1.0\neffectors:\n{}{}",
        entry("a", "", extra),
        entry("b", "-", "")
    )
}

/// The tank's spring oscillates at the analog's ω₁ = √(g κ), g = Ω² r_T, damped at its ζ, in
/// both directions (tangential and axial, for each of two tanks: four modes), for a sphere,
/// a flat-bottomed cylinder and a capsule standing radially.
#[test]
fn a_tank_s_spring_oscillates_at_the_analog_s_frequency_in_both_directions() {
    let spin = 5.0;
    for (shape, tank, x) in [
        (
            "{sphere: {radius: 0.22}}",
            Tank::Sphere { radius: 0.22 },
            0.7,
        ),
        (
            "{cylinder: {radius: 0.2, height: 0.5}}",
            Tank::Cylinder {
                radius: 0.2,
                height: 0.5,
            },
            0.9,
        ),
        (
            "{capsule: {radius: 0.2, barrel: 0.3}}",
            Tank::Capsule {
                radius: 0.2,
                barrel: 0.3,
            },
            0.9,
        ),
    ] {
        let analog = slosh_analog(&tank, 0.6, &HYDRAZINE, spin * spin * x).unwrap();
        let (re, im) = roots(analog.frequency, analog.damping_ratio);
        let s = scenario(&tanks(HOLDING_HUB, spin, shape, x, 0.6, ""));
        assert_modes(&s, re, im, 4, 1e-8);
        // One direction only: two modes (one per tank), still at ω₁.
        for one in ["[tangential]", "[axial]"] {
            let extra = format!("      directions: {one}\n");
            let yaml = tanks(HOLDING_HUB, spin, shape, x, 0.6, &extra).replace(
                "  - spring_mass_damper:\n      name: b\n",
                &format!("  - spring_mass_damper:\n      name: b\n{extra}"),
            );
            assert_modes(&scenario(&yaml), re, im, 2, 1e-8);
        }
    }
}

/// The mass and first moment the effector carries, at rest.
fn liquid_at_rest(yaml: &str) -> (f64, nalgebra::Vector3<f64>) {
    let s = scenario(yaml);
    let sc = &s.spacecraft;
    let y = sc.initial_state(&s.omega0, &s.attitude0);
    let hub = HubState {
        t: 0.0,
        omega: s.omega0,
        attitude: &y[3..7],
    };
    let offset = sc.effector_offset(0);
    let tank = &sc.effectors()[0];
    let p = tank.momentum(&hub, &y[offset..offset + tank.num_states()]);
    (p.mass, p.first_moment / p.mass)
}

/// The effector holds the tank's liquid where the liquid at rest has it (facts of the
/// geometry, not of the analog): a half-full sphere is a hemisphere of liquid on the outer
/// side, ρ (2/3) π R³ with its centre of mass 3R/8 outward from the centre; a cylinder standing
/// radially, filled to f, holds ρ π R² H f with its centre of mass at the middle of the liquid
/// column, (H − f H)/2 outward from the centre.
#[test]
fn a_tank_s_spring_holds_its_liquid_where_the_liquid_rests() {
    use std::f64::consts::PI;
    let (rho, x) = (1004.0, 0.7);
    let centre = nalgebra::Vector3::new(x, 0.0, 0.2);
    let body = "body: {mass: 800.0, principal: [900.0, 900.0, 250.0], spin_axis: [0, 0, 1]}";
    let radius = 0.22_f64;
    let (mass, at) = liquid_at_rest(&tanks(body, 5.0, "{sphere: {radius: 0.22}}", x, 0.5, ""));
    let liquid = rho * 2.0 / 3.0 * PI * radius.powi(3);
    assert!(
        (mass - liquid).abs() < 1e-12 * liquid,
        "{mass} against {liquid}"
    );
    let expected = centre + 3.0 * radius / 8.0 * nalgebra::Vector3::x();
    assert!(
        (at - expected).norm() < 1e-9 * radius,
        "{at} against {expected}"
    );

    let (r, h, f) = (0.2_f64, 0.5, 0.35);
    let (mass, at) = liquid_at_rest(&tanks(
        body,
        5.0,
        "{cylinder: {radius: 0.2, height: 0.5}}",
        x,
        f,
        "",
    ));
    let liquid = rho * PI * r * r * h * f;
    assert!(
        (mass - liquid).abs() < 1e-12 * liquid,
        "{mass} against {liquid}"
    );
    let expected = centre + 0.5 * (h - f * h) * nalgebra::Vector3::x();
    assert!((at - expected).norm() < 1e-9 * h, "{at} against {expected}");
}

/// Free flight: |H| is kept to rounding with or without the dashpot, and so is the energy
/// balance (T plus the springs' energy, plus what the dashpot dissipated). The spacecraft nutates, so the sloshing mass
/// moves in both directions off rest.
#[test]
fn momentum_and_the_energy_balance_close_in_free_flight() {
    for factor in [0.0, 300.0] {
        let yaml = format!(
            "name: t\nbody: {{mass: 300.0, principal: [120.0, 150.0, 90.0], \
             spin_axis: [0, 0, 1]}}\ninitial: {{omega: [0.4, -0.3, 3.0]}}\nduration: 20.0\n\
             integrator: {{method: dop853, rtol: 1.0e-12, atol: 1.0e-14}}\noutput: {{rate: 5}}\n\
             effectors:\n\
             \x20 - spring_mass_damper:\n      initial_offset: [0.004, -0.003]\n      \
             initial_rate: [0.01, 0.02]\n      tank:\n        \
             shape: {{sphere: {{radius: 0.2}}}}\n        center: [0.8, 0.1, 0.2]\n        \
             fill: 0.4\n        liquid: {LIQUID}\n        damping_factor: {factor}\n"
        );
        let (out, rec) = run(&scenario(&yaml));
        assert_eq!(out.status, Status::Complete, "damping factor {factor}");
        let first = &rec.samples[0];
        let (h0, t0) = (first.h_inertial, first.kinetic_energy);
        let mut worst_h: f64 = 0.0;
        let mut worst_balance: f64 = 0.0;
        for o in &rec.samples {
            worst_h = worst_h.max((o.h_inertial - h0).norm() / h0.norm());
            worst_balance =
                worst_balance.max((o.energy_balance() - first.energy_balance()).abs() / t0);
        }
        eprintln!(
            "damping factor {factor}: |ΔH|/|H| {worst_h:e}, energy balance {worst_balance:e}"
        );
        assert!(worst_h < 1e-10, "factor {factor}: H drifts by {worst_h:e}");
        assert!(
            worst_balance < 1e-10,
            "factor {factor}: the energy balance drifts by {worst_balance:e}"
        );
        let last = rec.samples.last().unwrap();
        if factor > 0.0 {
            assert!(
                last.dissipated_energy > 1e-6 * t0,
                "{}",
                last.dissipated_energy
            );
        } else {
            assert_eq!(last.dissipated_energy, 0.0);
        }
    }
}

/// What the tank form cannot stand for is refused at load, with the place and the reason.
#[test]
fn the_tank_form_refuses_what_it_cannot_stand_for() {
    let body = "body: {mass: 800.0, principal: [900.0, 900.0, 250.0], spin_axis: [0, 0, 1]}";
    let sphere = "{sphere: {radius: 0.22}}";
    let refuse = |yaml: String, expected: &str| {
        let e = parse(std::path::Path::new("t.yaml"), yaml, &Overrides::default())
            .expect_err(expected)
            .to_string();
        assert_eq!(e, expected);
    };
    refuse(
        tanks(body, 5.0, sphere, 0.7, 0.5, "").replace(
            "        liquid: {density",
            "        drained_by: main\n        liquid: {density",
        ),
        "t.yaml:12:21: field `effectors[0].spring_mass_damper.tank.drained_by`: the \
         spring–mass analog is for a tank at a fixed fill; a tank that drains is supported by \
         the pendulum form: `slosh_pendulum: {tank: {…, drained_by}}` (docs/slosh-analogs.md)",
    );
    refuse(
        tanks(body, 5.0, sphere, 0.7, 0.5, "      stiffness: 3.0\n"),
        "t.yaml:10:9: field `effectors[0].spring_mass_damper.tank`: `stiffness` and `tank` are \
         both given: with a tank, the spring's mass, position, directions, stiffness, damping \
         and travel follow from it; remove `stiffness`, or the tank",
    );
    refuse(
        tanks(body, 5.0, sphere, 0.7, 0.99, ""),
        "t.yaml:11:15: field `effectors[0].spring_mass_damper.tank.fill`: slosh analog: fill \
         fraction 0.99 is outside the range provided, [0.02, 0.95]",
    );
    refuse(
        tanks(
            body,
            5.0,
            sphere,
            0.7,
            0.5,
            "      directions: [axial, axial]\n",
        ),
        "t.yaml:8:19: field `effectors[0].spring_mass_damper.directions`: expected one or \
         both of `tangential` and `axial`, each once",
    );
    refuse(
        tanks(body, 5.0, sphere, 0.7, 0.5, "      initial_offset: 0.01\n"),
        "t.yaml:8:23: field `effectors[0].spring_mass_damper.initial_offset`: expected a \
         list of 2 numbers (m), one per direction the mass moves on",
    );
    // On the spin axis: no centrifugal field to restore the liquid (as the pendulum's).
    let on_axis = parse(
        std::path::Path::new("t.yaml"),
        tanks(body, 5.0, sphere, 0.0, 0.5, ""),
        &Overrides::default(),
    )
    .expect_err("on the axis")
    .to_string();
    assert!(
        on_axis.contains("spring_mass_damper.tank.center"),
        "{on_axis}"
    );
    // `directions` without a tank.
    let yaml = format!(
        "name: t\n{body}\ninitial: {{omega: [0, 0, 5.0]}}\nduration: 1.0\neffectors:\n  - \
         spring_mass_damper: {{mass: 1.0, position: [0.5, 0, 0], direction: [0, 0, 1], \
         stiffness: 1.0, damping: 0.1, directions: [axial]}}\n"
    );
    let e = parse(std::path::Path::new("t.yaml"), yaml, &Overrides::default())
        .expect_err("directions without a tank")
        .to_string();
    assert!(
        e.contains("`directions` chooses a tank's slosh directions"),
        "{e}"
    );
}

/// The springs are derived at the initial spin, and the liquid's restoring field (Ω² r_T)
/// follows the spin while the springs do not: a thruster spinning the stage up is warned past
/// a 5 % change and stopped past 25 %, with a diagnosis naming both spins. Hub about z (its
/// major axis) at 5 rad/s; 20 N at 1 m tangentially spin it up at about 0.1 rad/s².
#[test]
fn a_spin_change_the_springs_were_not_derived_for_is_warned_then_stopped() {
    let yaml = format!(
        "name: t\nbody: {{mass: 500.0, principal: [100.0, 110.0, 200.0], spin_axis: [0, 0, 1]}}\n\
         initial: {{omega: [0.0, 0.0, 5.0]}}\nduration: 40.0\neffectors:\n\
         {}\n  - thruster:\n      name: spin_up\n      nozzle: [0.0, 1.0, 0.0]\n      \
         direction: [-1.0, 0.0, 0.0]\n      thrust: {{constant: 20.0}}\n      isp: 300.0\n      \
         tank: {{model: point, center: [0, 0, 0], propellant: 5.0}}\n",
        tanks("", 5.0, "{sphere: {radius: 0.15}}", 0.7, 0.6, "")
            .split_once("effectors:\n")
            .unwrap()
            .1
            .trim_end()
    );
    let s = scenario(&yaml);
    let (out, _) = run(&s);
    let Status::InvalidModel { diagnosis } = &out.status else {
        panic!("expected invalid_model, got {:?}", out.status);
    };
    assert!(diagnosis.contains("springs were derived"), "{diagnosis}");
    let spin = out.final_observation.omega.z;
    // Stopped at the first accepted step past 25 %: the step is short against the 12 s the
    // spin-up takes, so the spin is within 2 % of the limit.
    assert!(
        (1.25..1.27).contains(&(spin / 5.0)),
        "stopped at {spin} rad/s"
    );
    let warned = out
        .warnings
        .iter()
        .any(|w| format!("{w:?}").contains("springs were derived"));
    assert!(warned, "no warning: {:?}", out.warnings);
}
