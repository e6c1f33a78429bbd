//! What a run reports: the `--summary` JSON document and the text summary.

use crate::integrate::OdeSystem;
use crate::model::RigidBody;
use crate::scenario::Scenario;
use crate::sim::{self, Outcome, Status};
use std::path::Path;

/// With `body.composite: true`, the hub's own mass properties polhode derived (the whole
/// spacecraft minus the effectors at rest), for `check` and `run`.
pub(super) fn hub_remainder_line(s: &Scenario) -> Option<String> {
    let c = s.composite.as_ref()?;
    let sc = &s.spacecraft;
    let p = sc.hub.principal_moments;
    // `+ 0.0` turns −0 into 0, so no component prints as `-0.000000000e0`.
    let o = c.hub_offset.map(|x| x + 0.0);
    let mass = match (c.total_mass, sc.hub_mass) {
        (Some(total), Some(hub)) => format!(
            "mass {hub:.9e} kg (of {total} kg; effectors {:.9e} kg), ",
            c.effector_mass
        ),
        _ => String::new(),
    };
    Some(format!(
        "  hub (composite body minus the effectors at rest): {mass}centre of mass \
         [{:+.9e}, {:+.9e}, {:+.9e}] m from the whole spacecraft's, principal moments \
         {:.9e}, {:.9e}, {:.9e} kg m²",
        o[0], o[1], o[2], p[0], p[1], p[2]
    ))
}

/// For each `spring_mass_damper` built from a `tank:`, what polhode derived from the tank, for
/// `check`: the sloshing mass, its rest point, each line's direction and spring, the dashpot and
/// the fixed liquid (m, body axes about the hub's centre of mass). The numbers are printed in
/// the shortest form that reads back to the same f64 (peers/basilisk_slosh_spring.py builds
/// Basilisk's scene from them).
pub(super) fn tank_spring_lines(s: &Scenario) -> Vec<String> {
    use crate::effectors::{ParticleEffector, SloshSpring};
    let v = |x: &nalgebra::Vector3<f64>| format!("[{:e}, {:e}, {:e}]", x[0], x[1], x[2]);
    s.spacecraft
        .effectors()
        .iter()
        .filter_map(|e| {
            let any = e.as_ref() as &dyn std::any::Any;
            let m = any.downcast_ref::<ParticleEffector<SloshSpring>>()?.model();
            let sp = &m.spring;
            let second = match &m.second {
                Some(l) => format!(
                    "; line 2 direction {} stiffness {:e} N/m",
                    v(&l.direction),
                    l.stiffness
                ),
                None => String::new(),
            };
            Some(format!(
                "  spring_mass_damper {} from its tank: sloshing mass {:e} kg at {} m; line 1 \
                 direction {} stiffness {:e} N/m{second}; damping {:e} N s/m; fixed liquid {:e} \
                 kg at {} m",
                e.name(),
                sp.mass,
                v(&sp.position),
                v(&sp.direction),
                sp.stiffness,
                sp.damping,
                m.fixed_mass,
                v(&m.fixed_position)
            ))
        })
        .collect()
}

/// Event lines the text summary prints; the rest are counted.
const PRINTED_EVENTS: usize = 10;

/// The `--summary` JSON document.
#[derive(serde::Serialize)]
struct Summary<'a> {
    polhode_version: &'static str,
    scenario: &'a str,
    scenario_file: String,
    method: &'static str,
    method_settings: String,
    /// Why `auto` picked the method (absent when it was named).
    #[serde(skip_serializing_if = "Option::is_none")]
    method_choice: Option<&'a str>,
    /// The geomagnetic field model the magnetic effectors see (absent without one).
    #[serde(skip_serializing_if = "Option::is_none")]
    magnetic_field: Option<&'a str>,
    body: Body,
    status: &'a Status,
    mcap: Option<String>,
    initial: State,
    #[serde(rename = "final")]
    final_state: State,
    drift: &'a sim::Drift,
    /// Whether H_N is conserved by the model (no external torque, no prescribed motion):
    /// then `drift.h_*` measure integration error; otherwise they are physical changes.
    conserves_momentum: bool,
    effectors: Vec<EffectorInfo>,
    steps: u64,
    rejected_steps: u64,
    rhs_evaluations: u64,
    /// Newton iterations, Jacobians and LU factorisations (implicit methods).
    newton_iterations: u64,
    jacobian_evaluations: u64,
    factorizations: u64,
    samples: u64,
    wall_time_s: f64,
    events: &'a [sim::EventRecord],
    /// Events beyond the first 10 000 (logged, not listed here).
    events_not_kept: u64,
    warnings: &'a [sim::Warning],
}

/// An effector as built from the scenario.
#[derive(serde::Serialize)]
struct EffectorInfo {
    name: String,
    kind: &'static str,
    states: Vec<String>,
}

/// Mass properties as polhode computed them: the whole spacecraft, effectors locked in their
/// initial configuration, about its centre of mass.
#[derive(serde::Serialize)]
struct Body {
    /// Principal moments, ascending (kg m²).
    principal_moments: [f64; 3],
    /// Unit principal axes in body coordinates, in the order of the moments.
    principal_axes: [[f64; 3]; 3],
    /// Unit spin axis (body) whose nutation angle is reported.
    spin_axis: [f64; 3],
}

/// The reported mass properties of the spacecraft at its initial state.
fn body(s: &Scenario) -> Body {
    let sc = &s.spacecraft;
    let (p, axes) = if sc.effectors().is_empty() {
        (sc.hub.principal_moments, sc.hub.principal_axes)
    } else {
        let y0 = sc.initial_state(&s.omega0, &s.attitude0);
        match RigidBody::new(sc.system_inertia(&y0)) {
            Ok(b) => (b.principal_moments, b.principal_axes),
            Err(_) => (sc.hub.principal_moments, sc.hub.principal_axes),
        }
    };
    let sa = s.spacecraft.spin_axis;
    Body {
        principal_moments: [p[0], p[1], p[2]],
        principal_axes: RigidBody::reported_axes(&axes),
        spin_axis: [sa[0], sa[1], sa[2]],
    }
}

/// A state as the summary reports it.
#[derive(serde::Serialize)]
struct State {
    t: f64,
    omega: [f64; 3],
    q: Quat,
    kinetic_energy: f64,
    elastic_energy: f64,
    dissipated_energy: f64,
    h_norm: f64,
    h_inertial: [f64; 3],
    nutation_angle_deg: f64,
}

/// A quaternion, scalar `w` first.
#[derive(serde::Serialize)]
struct Quat {
    w: f64,
    x: f64,
    y: f64,
    z: f64,
}

/// The summary's form of an observation.
fn state(o: &crate::model::Observation) -> State {
    State {
        t: o.t,
        omega: [o.omega[0], o.omega[1], o.omega[2]],
        q: Quat {
            w: o.attitude.w,
            x: o.attitude.i,
            y: o.attitude.j,
            z: o.attitude.k,
        },
        kinetic_energy: o.kinetic_energy,
        elastic_energy: o.elastic_energy,
        dissipated_energy: o.dissipated_energy,
        h_norm: o.h_norm,
        h_inertial: [o.h_inertial[0], o.h_inertial[1], o.h_inertial[2]],
        nutation_angle_deg: o.nutation_angle.to_degrees(),
    }
}

/// The `run --summary` JSON document of `outcome` (pretty-printed, newline-terminated): `mcap`
/// is the log written, if any. Floats are written so that they read back bit for bit. Shared
/// with the Python package, whose `Result.summary` is this document.
pub fn summary_json(s: &Scenario, o: &Outcome, mcap: Option<&Path>) -> String {
    let summary = Summary {
        polhode_version: env!("CARGO_PKG_VERSION"),
        scenario: &s.name,
        scenario_file: s.path.display().to_string(),
        method: s.method.name(),
        method_settings: s.method.describe(),
        method_choice: s.method_choice.as_deref(),
        magnetic_field: s.magnetic_field.as_deref(),
        body: body(s),
        status: &o.status,
        mcap: mcap.map(|p| p.display().to_string()),
        initial: state(&o.initial_observation),
        final_state: state(&o.final_observation),
        drift: &o.drift,
        conserves_momentum: s.spacecraft.conserves_momentum(),
        effectors: s
            .spacecraft
            .effectors()
            .iter()
            .map(|e| EffectorInfo {
                name: e.name().to_string(),
                kind: e.kind(),
                states: e.state_names(),
            })
            .collect(),
        steps: o.stats.steps,
        rejected_steps: o.stats.rejected_steps,
        rhs_evaluations: o.stats.rhs_evaluations,
        newton_iterations: o.stats.newton_iterations,
        jacobian_evaluations: o.stats.jacobian_evaluations,
        factorizations: o.stats.factorizations,
        samples: o.samples,
        wall_time_s: o.wall_time,
        events: &o.events,
        events_not_kept: o.events_not_kept,
        warnings: &o.warnings,
    };
    serde_json::to_string_pretty(&summary).unwrap_or_default() + "\n"
}

/// Prints the text summary of a run.
pub(super) fn print_summary(s: &Scenario, o: &Outcome, mcap: Option<&Path>) {
    let f = &o.final_observation;
    let q = f.attitude;
    println!("{} — {}", s.name, s.method.describe());
    if let Some(why) = &s.method_choice {
        println!("  {why}");
    }
    let b = body(s);
    let m = b.principal_moments;
    println!(
        "  principal moments {:.9e}, {:.9e}, {:.9e} kg m²",
        m[0], m[1], m[2]
    );
    // Rounded to the digits printed before the sign is chosen, so that a component of
    // −1e-17 from the eigensolver prints as +0, not −0.
    let digits = |v: f64| (v * 1e9).round() / 1e9 + 0.0;
    for (i, a) in b.principal_axes.iter().enumerate() {
        println!(
            "    axis {}: [{:+.9}, {:+.9}, {:+.9}]",
            i + 1,
            digits(a[0]),
            digits(a[1]),
            digits(a[2])
        );
    }
    if let Some(line) = hub_remainder_line(s) {
        println!("{line}");
    }
    if let Some(field) = &s.magnetic_field {
        println!("  magnetic field: {field}");
    }
    println!(
        "  status: {}{}",
        o.status.label(),
        match &o.status {
            Status::Stopped { condition } => format!(" ({condition})"),
            _ => String::new(),
        }
    );
    println!("  t = {}", crate::timefmt::seconds(f.t));
    println!(
        "  ω = [{:.9e}, {:.9e}, {:.9e}] rad/s",
        f.omega[0], f.omega[1], f.omega[2]
    );
    println!(
        "  q = {{w: {:.12}, x: {:.12}, y: {:.12}, z: {:.12}}}",
        q.w, q.i, q.j, q.k
    );
    println!(
        "  T = {:.12e} J   |H| = {:.12e} N m s   nutation {:.6}°",
        f.kinetic_energy,
        f.h_norm,
        f.nutation_angle.to_degrees()
    );
    if !s.spacecraft.effectors().is_empty() {
        println!(
            "  elastic {:.6e} J   dissipated {:.6e} J   ({} effectors, {} states)",
            f.elastic_energy,
            f.dissipated_energy,
            s.spacecraft.effectors().len(),
            OdeSystem::dim(&s.spacecraft)
        );
    }
    let (label, energy) = if s.spacecraft.effectors().is_empty() {
        ("T", "drift")
    } else {
        ("T+V+W", "drift")
    };
    if s.spacecraft.expels_mass() && s.spacecraft.conserves_momentum() {
        // H plus what the exhaust carried out is conserved; the motor supplies energy.
        println!(
            "  drift: |H + exhaust| {:.3e}  H_N + exhaust {:.3e}; energy: supplied by the \
             motor, not audited  |q| {:.3e}",
            o.drift.h_norm_rel, o.drift.h_inertial_rel, o.drift.q_norm
        );
    } else if s.spacecraft.conserves_momentum() {
        println!(
            "  {energy}: |H| {:.3e}  H_N {:.3e}  {label} {:.3e}  |q| {:.3e}",
            o.drift.h_norm_rel, o.drift.h_inertial_rel, o.drift.energy_rel, o.drift.q_norm
        );
    } else if s.spacecraft.keeps_momentum_norm() {
        // The torques turn H but keep |H| (an energy sink): a change of |H| is drift.
        println!(
            "  {energy}: |H| {:.3e}; change (torque that turns H): H_N {:.3e}; {energy}: \
             {label} {:.3e}  |q| {:.3e}",
            o.drift.h_norm_rel, o.drift.h_inertial_rel, o.drift.energy_rel, o.drift.q_norm
        );
    } else if s.spacecraft.conserves_energy() {
        println!(
            "  change (external torque): |H| {:.3e}  H_N {:.3e}; {energy}: {label} {:.3e}  \
             |q| {:.3e}",
            o.drift.h_norm_rel, o.drift.h_inertial_rel, o.drift.energy_rel, o.drift.q_norm
        );
    } else {
        println!(
            "  prescribed hub motion: momentum and energy are not conserved; {energy}: |q| \
             {:.3e}",
            o.drift.q_norm
        );
    }
    println!(
        "  work: {} steps ({} rejected), {} RHS evaluations, {} samples, {:.3} s wall",
        o.stats.steps, o.stats.rejected_steps, o.stats.rhs_evaluations, o.samples, o.wall_time
    );
    if s.method.is_implicit() {
        println!(
            "  implicit: {} Newton iterations, {} Jacobians, {} LU factorisations",
            o.stats.newton_iterations, o.stats.jacobian_evaluations, o.stats.factorizations
        );
    }
    for e in o.events.iter().take(PRINTED_EVENTS) {
        println!(
            "  event: t = {}  {}{}",
            crate::timefmt::seconds(e.t),
            e.condition,
            if e.terminal { " (stop)" } else { "" }
        );
    }
    let more = (o.events.len() - o.events.len().min(PRINTED_EVENTS)) as u64 + o.events_not_kept;
    if more > 0 {
        println!(
            "  … and {more} more events (all are in the log and in --summary; `once: true` or \
             `for: SECONDS` on a condition records only what answers the question)"
        );
    }
    if let Some(p) = mcap {
        println!("  log: {}", p.display());
    }
}
