//! Discrete controllers inside the continuous simulation: magnetorquers under B-dot and
//! wheels under rate damping, each sampling at its own rate with a zero-order hold.
//!
//! - No adaptive or fixed step crosses a controller tick: a probe effector checks, at every
//!   right-hand-side evaluation, that the held state it sees belongs to the evaluation's time.
//! - Rate damping on a symmetry axis against its exact sampled-data solution.
//! - A reaction-wheel pyramid: the hub torque is −K ω at each tick, H_N kept, energy balanced.
//! - B-dot against an independent integration written here (RK4, the same law and field).
//! - Located errors for bad controllers.

mod common;

use common::{balance_drift_and_spread, run, scenario};
use nalgebra::{UnitQuaternion, Vector3};
use polhode::effectors::clock::SampleClock;
use polhode::model::{Effector, EnergyAccount, HubAcceleration, HubCoupling, HubState};
use polhode::orbit::{CentralBody, Elements, GeomagneticField, Orbit};
use polhode::scenario::{Overrides, parse};
use polhode::sim::Status;
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

/// An effector that does nothing to the dynamics but holds the time of the last tick of its
/// clock as a state, updated at its breakpoints, and counts right-hand-side evaluations whose
/// time lies outside [last tick, next tick]: an evaluation there means a step straddled a
/// tick (or its stages saw a held state from the wrong interval).
#[derive(Debug)]
struct TickProbe {
    clock: SampleClock,
    announce_ticks: bool,
    evaluations: Arc<AtomicU64>,
    straddles: Arc<AtomicU64>,
}

impl Effector for TickProbe {
    fn name(&self) -> &str {
        "probe"
    }
    fn kind(&self) -> &'static str {
        "probe"
    }
    fn num_states(&self) -> usize {
        1
    }
    fn state_names(&self) -> Vec<String> {
        vec!["last_tick".into()]
    }
    fn initial_state(&self) -> Vec<f64> {
        vec![0.0]
    }
    fn next_breakpoint(&self, t: f64) -> Option<f64> {
        self.announce_ticks.then(|| self.clock.next_tick(t))
    }
    fn at_breakpoint(&self, hub: &HubState, x: &mut [f64]) {
        x[0] = hub.t;
    }
    fn couple(&self, _hub: &HubState, _x: &[f64], _c: &mut HubCoupling, _s: &mut [f64]) {}
    fn derivatives(
        &self,
        hub: &HubState,
        _accel: &HubAcceleration,
        x: &[f64],
        _scratch: &[f64],
        dx: &mut [f64],
    ) {
        self.evaluations.fetch_add(1, Ordering::Relaxed);
        // RADAU5's finite-difference Jacobian perturbs the held state too, by about
        // √ε |x| ≈ 3e-7 s here; a straddling step would be off by a fraction of a step
        // (1e-3 to 0.37 s here).
        let slack = 1e-6 * (1.0 + hub.t);
        if hub.t < x[0] - slack || hub.t > x[0] + self.clock.period + slack {
            self.straddles.fetch_add(1, Ordering::Relaxed);
        }
        dx[0] = 0.0;
    }
    fn energy(&self, _hub: &HubState, _x: &[f64]) -> EnergyAccount {
        EnergyAccount::default()
    }
}

/// Runs a tumbling triaxial body with the probe under `method`; returns (evaluations,
/// evaluations outside their tick interval).
fn probe_run(method: &str, announce_ticks: bool) -> (u64, u64) {
    let mut s = scenario(&format!(
        "name: probe
body: {{principal: [1.0, 2.0, 3.0]}}
initial: {{omega: [0.3, 2.0, 0.4]}}
duration: 20.0
integrator: {method}
output: {{rate: 3}}
"
    ));
    let evaluations = Arc::new(AtomicU64::new(0));
    let straddles = Arc::new(AtomicU64::new(0));
    s.spacecraft
        .add_effector(Box::new(TickProbe {
            // Not a divisor of the output interval, nor of the duration.
            clock: SampleClock::from_rate(2.7),
            announce_ticks,
            evaluations: evaluations.clone(),
            straddles: straddles.clone(),
        }))
        .unwrap();
    let (out, _) = run(&s);
    assert_eq!(out.status, Status::Complete, "{method}");
    (
        evaluations.load(Ordering::Relaxed),
        straddles.load(Ordering::Relaxed),
    )
}

/// Every method stops exactly on each tick and restarts there: no evaluation sees a held
/// state from another interval. With the ticks not announced (the stops turned off), the
/// same probe counts straddling evaluations, so the check can fail.
#[test]
fn no_step_crosses_a_controller_tick() {
    for method in [
        "{method: dopri5, rtol: 1.0e-6, atol: 1.0e-9}",
        "{method: dop853, rtol: 1.0e-6, atol: 1.0e-9}",
        "{method: radau5, rtol: 1.0e-6, atol: 1.0e-9}",
        "{method: rk4, dt: 0.05}",
    ] {
        let (evaluations, straddles) = probe_run(method, true);
        assert!(evaluations > 0, "{method}");
        assert_eq!(
            straddles, 0,
            "{method}: {straddles} of {evaluations} evaluations"
        );
        let (evaluations, straddles) = probe_run(method, false);
        assert!(
            straddles > evaluations / 2,
            "{method} without stops: only {straddles} of {evaluations} evaluations straddle"
        );
    }
}

/// One wheel on the symmetry axis of a body spinning about it, rate damping sampled every Δt
/// and held: (I_s − I_a) ω̇₃ = −u with u = K ω₃(t_k) held over [t_k, t_k+1), so exactly
/// ω₃(t_k+1) = ω₃(t_k) (1 − K Δt/(I_s − I_a)) and ω₃ is linear in between. Every method
/// integrates a linear function exactly, so only rounding separates them.
#[test]
fn rate_damping_on_the_symmetry_axis_follows_the_sampled_data_solution() {
    let (is, ia, k, rate, w0) = (60.0, 6.0, 2.0, 4.0, 0.3);
    let dt = 1.0 / rate;
    for method in [
        "{method: dopri5, rtol: 1.0e-9, atol: 1.0e-12}",
        "{method: dop853, rtol: 1.0e-9, atol: 1.0e-12}",
        "{method: radau5, rtol: 1.0e-9, atol: 1.0e-12}",
    ] {
        let s = scenario(&format!(
            "name: rd
body: {{principal: [100.0, 100.0, {is}]}}
initial: {{omega: [0.0, 0.0, {w0}]}}
duration: 10.0
integrator: {method}
output: {{rate: 10}}
effectors:
  - wheel:
      axial_inertia: {ia}
      axis: [0, 0, 1]
      motor: {{rate_damping: {{gain: {k}, sample_rate: {rate}}}}}
"
        ));
        let (out, rec) = run(&s);
        assert_eq!(out.status, Status::Complete, "{method}");
        let factor = 1.0 - k * dt / (is - ia);
        let exact = |t: f64| {
            let j = (t / dt + 1e-9).floor();
            let at_tick = w0 * factor.powi(j as i32);
            at_tick - k * at_tick / (is - ia) * (t - j * dt)
        };
        let worst = rec
            .samples
            .iter()
            .map(|o| (o.omega[2] - exact(o.t)).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-14, "{method}: largest ω₃ error {worst:e} rad/s");
        assert!(
            rec.samples
                .iter()
                .all(|o| o.omega[0] == 0.0 && o.omega[1] == 0.0)
        );
    }
}

/// A four-wheel pyramid (β = 54.74°) on a tumbling triaxial body under rate damping: at each
/// tick the wheels' reaction on the hub, −Σ u_j â_j, is −K ω sampled there (the pseudo-inverse
/// spreads it over four wheels), H_N stays put (internal torques), the energy balance
/// T + D − W closes, and the body's rate decays as its momentum moves into the wheels.
#[test]
fn a_wheel_pyramid_damps_the_rate_and_keeps_the_momentum() {
    let (k, rate) = (0.05, 10.0);
    let yaml = format!(
        "name: pyramid
body: {{principal: [0.9, 1.1, 0.7]}}
initial: {{omega: [0.1, -0.15, 0.12]}}
duration: 120.0
integrator: {{method: dop853, rtol: 1.0e-10, atol: 1.0e-13}}
output: {{rate: 10}}
effectors:
  - wheel:
      name: rw
      axial_inertia: 0.01
      axis: [0.8164966, 0.0, 0.5773503]
      friction: {{viscous: 1.0e-5}}
      motor: {{rate_damping: {{gain: {k}, sample_rate: {rate}}}}}
      copies: {{count: 4, about: [0, 0, 1]}}
"
    );
    let s = scenario(&yaml);
    let (out, rec) = run(&s);
    assert_eq!(out.status, Status::Complete);
    // The commanded torques against −K ω at the last tick: the final state holds the
    // commands sampled at 119.9 s (the end, 120 s, is not a restart), and ω is continuous
    // across ticks, so the sample at 119.9 s is what the controller saw.
    let axes: Vec<Vector3<f64>> = (0..4)
        .map(|j| {
            let rot = UnitQuaternion::from_axis_angle(
                &Vector3::z_axis(),
                std::f64::consts::FRAC_PI_2 * j as f64,
            );
            rot * Vector3::new(0.8164966, 0.0, 0.5773503).normalize()
        })
        .collect();
    let y = &out.final_state;
    // Each wheel: [Ω, held torque, motor work, dissipated]; the hub takes −u â.
    let hub_torque: Vector3<f64> = (0..4).map(|j| -y[7 + 4 * j + 1] * axes[j]).sum();
    let at_last_tick = rec
        .samples
        .iter()
        .rev()
        .find(|o| (o.t - 119.9).abs() < 1e-9)
        .expect("a sample at 119.9 s");
    let expected = -k * at_last_tick.omega;
    assert!(
        (hub_torque - expected).norm() < 1e-12 * expected.norm().max(1e-300) + 1e-15,
        "{hub_torque:?} against {expected:?}"
    );
    // Over six times I/K ≈ 20 s the rate falls by more than a factor of 20 (measured: 49).
    let first = &rec.samples[0];
    let last = rec.samples.last().unwrap();
    assert!(
        last.omega.norm() < first.omega.norm() / 20.0,
        "|ω| {} → {}",
        first.omega.norm(),
        last.omega.norm()
    );
    let h_drift = rec
        .samples
        .iter()
        .map(|o| (o.h_inertial - first.h_inertial).norm())
        .fold(0.0, f64::max)
        / first.h_inertial.norm();
    assert!(h_drift < 1e-10, "H_N drift {h_drift:e}");
    // Both as fractions of the initial kinetic energy.
    let (balance, spread) = balance_drift_and_spread(&rec.samples);
    assert!(spread > 0.5, "T spread {spread}");
    assert!(
        balance < 1e-9,
        "energy balance moved by {balance:e} of T₀ (T spread {spread})"
    );
}

/// The CubeSat's B-dot law against an independent integration written here: the rigid body
/// and quaternion by classical RK4 at 10 ms, the controller sampling the field every second
/// and holding m = sat(−(k/|B|)(b_j − b_j−1)/Δt), with the orbit and the IGRF-14 field built
/// here from the scenario's elements and epoch. The gain is the scenario's `auto`, recomputed
/// here from μ, a, i and J_min.
#[test]
fn bdot_matches_an_independent_integration() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cubesat-detumble.yaml");
    let ov = Overrides {
        duration: Some(300.0),
        ..Overrides::default()
    };
    let s = polhode::scenario::load(&path, &ov).unwrap();
    let (out, _) = run(&s);
    assert_eq!(out.status, Status::Complete);

    let inertia = Vector3::new(0.035, 0.035, 0.008);
    let mu: f64 = 3.986_004_418e14;
    let a = 6878.137e3;
    let n = (mu / (a * a * a)).sqrt();
    let gain = 2.0 * n * (1.0 + 51.6f64.to_radians().sin()) * 0.008;
    let max_dipole = 0.2;
    let orbit = Orbit::new(
        CentralBody::EARTH,
        Elements::new(a, 0.0, 51.6f64.to_radians(), 40f64.to_radians(), 0.0, 0.0),
        false,
    )
    .unwrap();
    // 2025-06-01T00:00:00Z.
    // The IGRF-14 field summed from its harmonics at every evaluation (the run reads it
    // from the table along the orbit).
    let field = GeomagneticField::igrf(1_748_736_000_000_000_000, None);
    let field_body = |t: f64, q: &UnitQuaternion<f64>| {
        let (r, _) = orbit.state(t);
        q.inverse_transform_vector(&field.field_eci(t, &(r / r.norm()), r.norm()))
    };
    let rhs = |t: f64, w: &Vector3<f64>, q: &UnitQuaternion<f64>, m: &Vector3<f64>| {
        let tau = m.cross(&field_body(t, q));
        let h = inertia.component_mul(w);
        (tau - w.cross(&h)).component_div(&inertia)
    };
    let mut w = Vector3::repeat(0.174533);
    let mut q = UnitQuaternion::identity();
    let mut m = Vector3::zeros();
    let mut previous: Option<Vector3<f64>> = None;
    let h = 0.01;
    let per_tick = 100;
    for tick in 0..300 {
        let t0 = tick as f64;
        let b = field_body(t0, &q);
        let dir = b / b.norm();
        if let Some(before) = previous {
            let raw = -(gain / b.norm()) * (dir - before) / 1.0;
            m = raw.map(|c| c.clamp(-max_dipole, max_dipole));
        }
        previous = Some(dir);
        for step in 0..per_tick {
            let t = t0 + step as f64 * h;
            // RK4 on (ω, q) with q̇ = ½ q ⊗ (0, ω).
            let qdot = |q: &UnitQuaternion<f64>, w: &Vector3<f64>| {
                let p = q.quaternion() * nalgebra::Quaternion::from_imag(*w) * 0.5;
                p.coords
            };
            let advance = |q: &UnitQuaternion<f64>, dq: &nalgebra::Vector4<f64>, s: f64| {
                UnitQuaternion::new_normalize(nalgebra::Quaternion::from(
                    q.quaternion().coords + s * dq,
                ))
            };
            let k1w = rhs(t, &w, &q, &m);
            let k1q = qdot(&q, &w);
            let (w2, q2) = (w + 0.5 * h * k1w, advance(&q, &k1q, 0.5 * h));
            let k2w = rhs(t + 0.5 * h, &w2, &q2, &m);
            let k2q = qdot(&q2, &w2);
            let (w3, q3) = (w + 0.5 * h * k2w, advance(&q, &k2q, 0.5 * h));
            let k3w = rhs(t + 0.5 * h, &w3, &q3, &m);
            let k3q = qdot(&q3, &w3);
            let (w4, q4) = (w + h * k3w, advance(&q, &k3q, h));
            let k4w = rhs(t + h, &w4, &q4, &m);
            let k4q = qdot(&q4, &w4);
            w += h / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
            q = advance(&q, &(k1q + 2.0 * k2q + 2.0 * k3q + k4q), h / 6.0);
        }
    }
    let y = &out.final_state;
    let got = Vector3::new(y[0], y[1], y[2]);
    let err = (got - w).norm();
    // The rates fall from 0.30 rad/s by about a sixth over these 300 s.
    assert!(
        (w.norm() - 0.302).abs() > 0.02,
        "the law did little: |ω| = {}",
        w.norm()
    );
    assert!(
        err < 1e-8,
        "|ω − ω_RK4| = {err:e} rad/s (|ω| = {})",
        w.norm()
    );
    let held = Vector3::new(y[7], y[8], y[9]);
    assert!(
        (held - m).norm() < 1e-8,
        "held dipole {held:?} against {m:?}"
    );
}

/// The detumbling scenario: the kinetic energy drained by the coils is their work (T − W
/// constant: the torque is the only one), and the rate falls below 0.5 deg/s within the run.
#[test]
fn the_cubesat_detumbles_with_its_energy_balanced() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cubesat-detumble.yaml");
    let s = polhode::scenario::load(&path, &Overrides::default()).unwrap();
    let (out, rec) = run(&s);
    assert_eq!(out.status, Status::Complete);
    let first = &rec.samples[0];
    let last = rec.samples.last().unwrap();
    let (balance, _) = balance_drift_and_spread(&rec.samples);
    assert!(balance < 1e-9, "T − W moved by {balance:e} of T₀");
    assert!(last.kinetic_energy < 1e-3 * first.kinetic_energy);
    let reached = rec
        .events
        .iter()
        .find(|e| e.condition.starts_with("rate_deg_s below 0.5"))
        .expect("the rate falls below 0.5 deg/s");
    // Within the sampled rates: the first sample below 0.5 deg/s and the one before it.
    let k = rec
        .samples
        .iter()
        .position(|o| o.omega.norm().to_degrees() < 0.5)
        .unwrap();
    assert!(rec.samples[k - 1].t <= reached.t && reached.t <= rec.samples[k].t);
    eprintln!(
        "cubesat-detumble: 0.5 deg/s at {:.1} s; final |ω| {:.4} deg/s (2n = {:.4} deg/s)",
        reached.t,
        last.omega.norm().to_degrees(),
        2.0 * (3.986_004_418e14f64 / 6878.137e3f64.powi(3))
            .sqrt()
            .to_degrees()
    );
}

/// Bad controllers are located errors.
#[test]
fn bad_controllers_are_refused_with_located_errors() {
    let orbit = "orbit: {semi_major_axis_km: 6878.137, inclination_deg: 51.6}\n";
    let base = "name: x\nepoch: 2025-06-01T00:00:00Z\nbody: {principal: [0.035, 0.035, 0.008]}\ninitial: {omega: [0.1, 0.1, 0.1]}\nduration: 100\n";
    let mtq = |extra: &str| format!("effectors:\n  - magnetorquer:\n{extra}");
    let cases = [
        (
            mtq("      max_dipole: 0.2\n      bdot: {gain: auto, sample_rate: 1}\n"),
            "field `effectors[0].magnetorquer`: a magnetorquer acts in the Earth's magnetic field, so it needs the spacecraft's orbit",
            false,
        ),
        (
            mtq("      max_dipole: [0.2, 0.0, 0.2]\n      bdot: {gain: auto, sample_rate: 1}\n"),
            "field `effectors[0].magnetorquer.max_dipole`: expected positive dipoles",
            true,
        ),
        (
            mtq("      max_dipole: 0.2\n      bdot: {gain: fast, sample_rate: 1}\n"),
            "field `effectors[0].magnetorquer.bdot.gain`: expected a gain (N m s) or `auto`, got `fast`",
            true,
        ),
        (
            mtq("      max_dipole: 0.2\n      bdot: {gain: -1.0, sample_rate: 1}\n"),
            "field `effectors[0].magnetorquer.bdot.gain`: expected a positive value",
            true,
        ),
        (
            mtq("      max_dipole: 0.2\n      bdot: {gain: auto, sample_rate: 1.0e6}\n"),
            "field `effectors[0].magnetorquer.bdot.sample_rate`: 1.000e8 controller samples",
            true,
        ),
        (
            "effectors:\n  - wheel:\n      axial_inertia: 0.001\n      axis: [0, 0, 1]\n      motor: {rate_damping: {gain: 0.01, sample_rate: 0}}\n".to_string(),
            "field `effectors[0].wheel.motor.rate_damping.sample_rate`: expected a positive value",
            false,
        ),
        (
            "effectors:\n  - wheel:\n      axial_inertia: 0.001\n      axis: [0, 0, 1]\n      motor: {rate_damping: {gain: 0.01, sample_rate: 1.0e6}}\n".to_string(),
            "field `effectors[0].wheel.motor.rate_damping.sample_rate`: 1.000e8 controller samples",
            false,
        ),
        (
            "effectors:\n  - wheel:\n      axial_inertia: 0.001\n      axis: [0, 0, 1]\n      motor: {rate_damping: {gain: 0.01, sample_rate: 5}}\n  - wheel:\n      axial_inertia: 0.001\n      axis: [1, 0, 0]\n      motor: {rate_damping: {gain: 0.02, sample_rate: 5}}\n".to_string(),
            "field `effectors[1].wheel.motor.rate_damping`: the wheels under rate damping form one assembly with one law",
            false,
        ),
    ];
    for (effectors, expect, with_orbit) in cases {
        let yaml = format!("{base}{}{effectors}", if with_orbit { orbit } else { "" });
        let Err(e) = parse(Path::new("test.yaml"), yaml.clone(), &Overrides::default()) else {
            panic!("accepted:\n{yaml}");
        };
        let e = e.to_string();
        assert!(e.contains(expect), "expected {expect:?} in {e}\n{yaml}");
        assert!(e.starts_with("test.yaml:"), "{e}");
    }
}

/// B-dot's backward difference holds while the body turns by much less than a radian between
/// samples: the run warns past 1 rad and stops with a diagnosis past π, where the samples
/// alias. The CubeSat at 0.30 rad/s sampled every 5 s turns 1.5 rad per sample; every 12 s,
/// 3.6 rad.
#[test]
fn bdot_sampled_too_slowly_warns_then_stops() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cubesat-detumble.yaml");
    let text = std::fs::read_to_string(&path).unwrap();
    let with_rate = |hz: &str| {
        let yaml = text.replace("sample_rate: 1.0}", &format!("sample_rate: {hz}}}"));
        assert!(yaml.contains(&format!("sample_rate: {hz}}}")));
        let ov = Overrides {
            duration: Some(600.0),
            ..Overrides::default()
        };
        parse(Path::new("slow.yaml"), yaml, &ov).unwrap()
    };
    let (out, _) = run(&with_rate("0.2"));
    assert_eq!(out.status, Status::Complete);
    assert_eq!(out.warnings.len(), 1, "{:?}", out.warnings);
    assert!(
        out.warnings[0].message.contains("the body turned by 1.51"),
        "{}",
        out.warnings[0].message
    );
    let (out, _) = run(&with_rate("0.0833333333333"));
    let Status::InvalidModel { diagnosis } = &out.status else {
        panic!("{:?}", out.status);
    };
    assert!(
        diagnosis.contains("magnetorquer `coils` left the range")
            && diagnosis.contains("a higher `bdot.sample_rate`"),
        "{diagnosis}"
    );
    // At 1 Hz (0.30 rad per sample) nothing is said.
    let (out, _) = run(&with_rate("1.0"));
    assert!(out.warnings.is_empty(), "{:?}", out.warnings);
}
