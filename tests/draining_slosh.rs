//! A slosh tank drained by a thruster (`slosh_pendulum` with `tank.drained_by`), against
//! things it did not produce:
//!
//! - **Conservation**: H plus the angular momentum the exhaust carried out, while the analog's
//!   masses, rod and pivot follow the falling fill and the bob swings.
//! - **The fixed-fill pendulum**: a tank the thruster does not drain during the run moves as
//!   the `slosh_pendulum` of the same tank (checked against Basilisk in tests/basilisk_slosh.rs).
//! - **Closed form, adiabatically**: on a hub that holds its spin Ω, a slowly drained sphere's
//!   pendulum swings at Ω √(r_T/L(f)) with L(f) the analog's at the fill of the moment
//!   (the spinning pendulum's small-oscillation frequency, pivot at the sphere's centre).
mod common;

use common::scenario;
use polhode::effectors::slosh_analog::{Liquid, Tank, slosh_analog};
use polhode::sim::Status;

use common::run_with_states as run;

const LIQUID: &str = "{density: 1004.0, kinematic_viscosity: 9.7e-7, surface_tension: 0.066}";

/// A spinning stage with one sphere (radius 0.22 m) at `centre`, filled to `fill`, drained
/// by a thruster at `nozzle` with `thrust` (a profile) at I_sp 300 s.
fn stage(body: &str, fill: f64, centre: [f64; 3], thrust: &str, extra: &str) -> String {
    format!(
        "name: drain
body: {body}
initial: {{omega: [0.03, -0.02, 5.0]}}
effectors:
  - slosh_pendulum:
      name: tank
      initial_angles: [0.08, 0.05]
      tank:
        shape: {{sphere: {{radius: 0.22}}}}
        center: [{}, {}, {}]
        fill: {fill}
        liquid: {LIQUID}
        drained_by: engine
  - thruster:
      name: engine
      nozzle: [0.02, -0.01, -1.2]
      direction: [0.0, 0.01, 1.0]
      thrust: {thrust}
      isp: 300.0
{extra}integrator: {{method: dop853, rtol: 1.0e-12, atol: 1.0e-14}}
",
        centre[0], centre[1], centre[2]
    )
}

const BODY: &str = "{mass: 800.0, principal: [900.0, 880.0, 250.0], spin_axis: [0, 0, 1]}";

#[test]
fn momentum_plus_what_the_exhaust_carried_is_conserved_while_the_tank_drains() {
    // 80 % to about 26 % full in 30 s, with kinks in the flow.
    let yaml = stage(
        BODY,
        0.8,
        [0.7, 0.05, 0.2],
        "{table: [[0.0, 0.0], [2.0, 3000.0], [20.0, 2600.0], [30.0, 0.0]]}",
        "duration: 40.0\noutput: {rate: 20}\n",
    )
    // A second tank, a cylinder whose pivot moves with the depth, drained by a second
    // thruster at a constant flow.
    .replace(
        "  - thruster:\n      name: engine\n",
        &format!(
            "  - slosh_pendulum:
      name: cylinder
      initial_angles: [-0.05, 0.1]
      tank:
        shape: {{cylinder: {{radius: 0.15, height: 0.5}}}}
        center: [-0.6, 0.1, -0.1]
        fill: 0.7
        liquid: {LIQUID}
        drained_by: vernier
  - thruster:
      name: vernier
      nozzle: [0.3, 0.3, -1.0]
      direction: [0.0, 0.0, 1.0]
      thrust: {{constant: 200.0}}
      mass_flow: {{constant: 0.5}}
  - thruster:\n      name: engine\n"
        ),
    );
    let s = scenario(&yaml);
    let (out, rec) = run(&s);
    assert_eq!(out.status, Status::Complete, "{out:?}");
    let first = &rec.samples[0];
    let h0 = first.h_inertial + first.h_carried_out;
    let last = rec.samples.last().unwrap();
    let carried = last.h_carried_out.norm() / h0.norm();
    let offset = s.spacecraft.effector_offset(0);
    let (m_start, m_end) = (
        rec.states[0][offset + 5],
        rec.states.last().unwrap()[offset + 5],
    );
    let cylinder = s.spacecraft.effector_offset(1) + 5;
    println!(
        "cylinder {:.2} kg -> {:.2} kg",
        rec.states[0][cylinder],
        rec.states.last().unwrap()[cylinder]
    );
    println!(
        "liquid {m_start:.2} kg -> {m_end:.2} kg; drift |H + exhaust| {:.2e}, H_N + exhaust \
         {:.2e}; the exhaust carried {carried:.2e} of |H0|",
        out.drift.h_norm_rel, out.drift.h_inertial_rel
    );
    assert!(out.drift.h_inertial_rel < 1e-11, "{:?}", out.drift);
    // Not an empty audit: the tank lost most of its liquid, the exhaust carried a visible
    // share of H, and the bob kept swinging.
    assert!(m_end < 0.4 * m_start);
    assert!(carried > 1e-3);
    let swing = rec
        .states
        .iter()
        .map(|y| y[offset + 1].abs())
        .fold(0.0, f64::max);
    assert!(swing > 0.01, "{swing}");
}

#[test]
fn a_tank_the_run_does_not_drain_is_the_fixed_fill_pendulum() {
    // The thrust starts after the run ends: the same tank as a plain `slosh_pendulum`,
    // beside a thruster with a token tank of its own that does nothing during the run.
    let quiet = "{table: [[50.0, 0.0], [51.0, 100.0], [60.0, 0.0]]}";
    let drained = scenario(&stage(
        BODY,
        0.6,
        [0.7, 0.0, 0.2],
        quiet,
        "duration: 20.0\noutput: {rate: 10}\n",
    ));
    let plain_yaml = stage(
        BODY,
        0.6,
        [0.7, 0.0, 0.2],
        quiet,
        "      tank: {model: point, center: [0, 0, 0], propellant: 1.0e-9}\n\
         duration: 20.0\noutput: {rate: 10}\n",
    )
    .replace("        drained_by: engine\n", "");
    let plain = scenario(&plain_yaml);
    let (a, ra) = run(&drained);
    let (b, rb) = run(&plain);
    assert_eq!((a.status, b.status), (Status::Complete, Status::Complete));
    assert_eq!(ra.states.len(), 201);
    assert_eq!(rb.states.len(), 201);
    let mut worst = (0.0f64, 0.0f64);
    for (x, y) in rb.states.iter().zip(&ra.states) {
        worst.0 = worst.0.max(
            (x[0..3].iter().zip(&y[0..3]))
                .map(|(p, q)| (p - q).abs())
                .fold(0.0, f64::max),
        );
        // The rod's angles: [φ, θ] are the first states of both effectors.
        worst.1 = worst.1.max((x[7] - y[7]).abs().max((x[8] - y[8]).abs()));
    }
    println!(
        "largest difference: ω {:.2e} rad/s, angles {:.2e} rad",
        worst.0, worst.1
    );
    assert!(worst.0 < 1e-9 && worst.1 < 1e-8, "{worst:?}");
}

#[test]
fn a_slowly_drained_sphere_swings_at_the_analog_s_frequency_of_the_moment() {
    // A hub too heavy to move (Ω = 5 rad/s held), a tank 0.7 m out, drained from 85 % to
    // about 15 % full over 300 s by a thruster on the spin axis through the hub's centre of
    // mass (no torque on the hub).
    let body = "{mass: 1.0e11, principal: [1.0e11, 1.05e11, 1.1e11], spin_axis: [0, 0, 1]}";
    let (rho, radius, r_t, spin) = (1004.0, 0.22_f64, 0.7, 5.0);
    let full = rho * 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
    let flow = 0.70 * full / 300.0;
    let thrust = flow * 300.0 * 9.80665;
    let yaml = stage(
        body,
        0.85,
        [r_t, 0.0, 0.0],
        &format!("{{constant: {thrust}}}"),
        "duration: 300.0\noutput: {rate: 200}\n",
    )
    .replace(
        "initial: {omega: [0.03, -0.02, 5.0]}",
        "initial: {omega: [0.0, 0.0, 5.0]}",
    )
    .replace("nozzle: [0.02, -0.01, -1.2]", "nozzle: [0.0, 0.0, -1.2]")
    .replace("direction: [0.0, 0.01, 1.0]", "direction: [0.0, 0.0, 1.0]")
    .replace(
        "initial_angles: [0.08, 0.05]",
        "initial_angles: [0.0, 0.05]",
    )
    // A lightly damped liquid (a twentieth of the smooth wall's), so the swing lasts.
    .replace(
        "        drained_by: engine\n",
        "        drained_by: engine\n        damping_factor: 0.05\n",
    );
    let s = scenario(&yaml);
    let (out, rec) = run(&s);
    assert_eq!(out.status, Status::Complete, "{out:?}");
    let offset = s.spacecraft.effector_offset(0);
    // The times of θ's maxima (the swing in the plane of the spin), by a parabola through
    // each sampled peak and its neighbours: periods free of the small equilibrium offset
    // that the Coriolis force on the draining liquid's radial drift sets.
    let theta: Vec<f64> = rec.states.iter().map(|y| y[offset + 1]).collect();
    let dt = rec.samples[1].t - rec.samples[0].t;
    let mut crossings = Vec::new();
    for k in 1..theta.len() - 1 {
        let (a, b, c) = (theta[k - 1], theta[k], theta[k + 1]);
        if b > a && b >= c {
            let shift = 0.5 * (a - c) / (a - 2.0 * b + c);
            crossings.push(rec.samples[k].t + shift * dt);
        }
    }
    let liquid = Liquid {
        density: rho,
        kinematic_viscosity: 9.7e-7,
        surface_tension: 0.066,
    };
    let mut worst = 0.0f64;
    let mut lengths = (f64::MAX, 0.0f64);
    for pair in crossings.windows(2) {
        let mid = 0.5 * (pair[0] + pair[1]);
        let fill = 0.85 - flow * mid / full;
        let analog =
            slosh_analog(&Tank::Sphere { radius }, fill, &liquid, spin * spin * r_t).unwrap();
        let l = analog.pendulum_length;
        lengths = (lengths.0.min(l), lengths.1.max(l));
        let expected = 2.0 * std::f64::consts::PI
            / (spin * (r_t / l).sqrt())
            / (1.0 - analog.damping_ratio.powi(2)).sqrt();
        let error = ((pair[1] - pair[0]) - expected) / expected;
        if std::env::var("PROBE").is_ok() {
            println!(
                "t {mid:.2} fill {fill:.4} L {l:.5} period {:.6} expected {expected:.6} error {error:.2e}",
                pair[1] - pair[0]
            );
        }
        worst = worst.max(error.abs());
    }
    println!(
        "{} periods, L from {:.4} to {:.4} m: worst period error {worst:.2e} (relative)",
        crossings.len() - 1,
        lengths.0,
        lengths.1
    );
    assert!(crossings.len() > 100);
    // The rod's length doubles over the run and the period grows by 38 %, which a fixed-fill
    // pendulum would miss; what remains is the finite swing's own lengthening of the period,
    // θ₀²/16 = 1.6e-4 at 0.05 rad (and the drain's slowness, L̇/(L ω) ~ 1e-4).
    assert!(lengths.1 > 1.9 * lengths.0);
    assert!(worst < 3e-4, "{worst}");
}

/// Parses a scenario, expecting an error.
fn refused(yaml: &str) -> String {
    polhode::scenario::parse(
        std::path::Path::new("test.yaml"),
        yaml.to_string(),
        &Default::default(),
    )
    .err()
    .unwrap_or_else(|| panic!("expected a refusal of\n{yaml}"))
    .to_string()
}

#[test]
fn drains_that_cannot_be_followed_are_refused_at_load() {
    let thrust = "{constant: 3000.0}";
    let base = stage(BODY, 0.6, [0.7, 0.0, 0.2], thrust, "duration: 10.0\n");
    // A name that no thruster has.
    let e = refused(&base.replace("drained_by: engine", "drained_by: motor"));
    println!("{e}");
    assert!(
        e.contains("tank.drained_by")
            && e.contains("no thruster is named `motor` (thrusters: engine)"),
        "{e}"
    );
    // A thruster with a tank of its own.
    let own = base.replace(
        "      isp: 300.0\n",
        "      isp: 300.0\n      tank: {model: point, center: [0, 0, 0], propellant: 50.0}\n",
    );
    let e = refused(&own);
    println!("{e}");
    assert!(e.contains("draws on its own `tank:`"), "{e}");
    // A thruster with no tank and nobody draining it.
    let e = refused(&base.replace("        drained_by: engine\n", ""));
    println!("{e}");
    assert!(
        e.contains("effectors[1].thruster.tank") && e.contains("missing field `tank`"),
        "{e}"
    );
    // Burnout: 3000 N at 300 s for 60 s is 61 kg; the tank holds 27 kg.
    let e = refused(&base.replace("duration: 10.0", "duration: 60.0"));
    println!("{e}");
    assert!(e.contains("burnout is not modelled"), "{e}");
    // Drained below the sphere analog's range (2 % full): 26.9 kg at 60 %, 26.5 kg expelled.
    let e = refused(&base.replace("duration: 10.0", "duration: 26.0"));
    println!("{e}");
    assert!(
        e.contains("the slosh analog cannot follow it there") && e.contains("fill"),
        "{e}"
    );
    // Two tanks on one thruster.
    let second = base.replace(
        "  - thruster:\n",
        "  - slosh_pendulum:\n      name: other\n      tank:\n        shape: {sphere: {radius: 0.22}}\n        center: [-0.7, 0.0, 0.2]\n        fill: 0.6\n        liquid: {density: 1004.0, kinematic_viscosity: 9.7e-7, surface_tension: 0.066}\n        drained_by: engine\n  - thruster:\n",
    );
    let e = refused(&second);
    println!("{e}");
    assert!(e.contains("already drained by an earlier tank"), "{e}");
}

#[test]
fn methods_that_need_a_constant_mass_refuse_a_draining_tank() {
    let yaml = stage(
        BODY,
        0.6,
        [0.7, 0.0, 0.2],
        "{constant: 300.0}",
        "duration: 10.0\n",
    );
    for method in ["averaged", "exact"] {
        let e = refused(&yaml.replace(
            "integrator: {method: dop853, rtol: 1.0e-12, atol: 1.0e-14}",
            &format!("integrator: {{method: {method}}}"),
        ));
        assert!(e.contains("variable mass"), "{method}: {e}");
    }
}
