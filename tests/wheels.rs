//! The driven `wheel`: checked against what polhode did not produce — the conservation of
//! H_N under internal motor torques, the work–energy balance with the motor's work and the
//! friction's dissipation, the closed-form motion of an axisymmetric gyrostat, an independent
//! integration of a triaxial gyrostat with a saturating PI loop written in this file — and the
//! located errors.

mod common;

use common::{run, scenario as load};
use nalgebra::{Matrix4, Vector3, Vector4};
use polhode::model::Observation;
use polhode::scenario::{Overrides, parse};
use polhode::sim::Status;
use std::path::Path;

/// A triaxial body (its inertia includes the rotor as if locked) with one wheel on a skewed
/// axis, tumbling.
fn scene(wheel: &str, duration: f64) -> String {
    format!(
        "name: wheel
body: {{principal: [10.0, 12.0, 8.0]}}
initial: {{omega: [0.3, -0.2, 0.5]}}
duration: {duration}
integrator: {{method: dop853, rtol: 1.0e-12, atol: 1.0e-12}}
output: {{rate: 10}}
effectors:
  - wheel:
      axial_inertia: 0.05
      transverse_inertia: 0.03
      axis: [1.0, 2.0, 3.0]
{wheel}"
    )
}

fn worst(samples: &[Observation], f: impl Fn(&Observation) -> f64) -> f64 {
    let f0 = f(&samples[0]);
    samples
        .iter()
        .map(|o| (f(o) - f0).abs())
        .fold(0.0, f64::max)
}

/// The motor and the friction are internal: H_N is conserved in every mode, and the energy
/// balance T + D − W (W the motor's work, D the friction's dissipation) holds, while T itself
/// changes by much more.
#[test]
fn h_n_and_the_energy_balance_hold_in_every_motor_mode() {
    let friction = "      friction: {viscous: 1.0e-4, coulomb: 1.0e-3, smoothing_speed: 0.05}\n";
    let modes = [
        ("free", "      motor: free\n      initial_rate: 100.0\n"),
        (
            "constant torque",
            "      motor: {torque: {constant: 0.01}}\n",
        ),
        (
            "linear torque",
            "      motor: {torque: {linear: [[0, 0.02], [10, -0.02], [20, 0.0]]}}\n",
        ),
        (
            "torque steps",
            "      motor: {torque: {steps: [[1, 0.02], [7.5, -0.03], [15, 0.0]]}}\n",
        ),
        (
            "speed hold, saturating",
            "      motor: {speed_hold: {rate: 200.0, bandwidth: 2.0}}\n      max_torque: 0.05\n",
        ),
    ];
    for (label, motor) in modes {
        let yaml = scene(&format!("{motor}{friction}"), 30.0);
        let s = load(&yaml);
        let (out, rec) = run(&s);
        assert_eq!(out.status, Status::Complete, "{label}");
        let h = rec.samples[0].h_inertial.norm();
        let drift_h = rec
            .samples
            .iter()
            .map(|o| (o.h_inertial - rec.samples[0].h_inertial).norm())
            .fold(0.0, f64::max)
            / h;
        let t_max = rec
            .samples
            .iter()
            .map(|o| o.kinetic_energy)
            .fold(0.0, f64::max);
        let drift_e = worst(&rec.samples, |o| o.energy_balance()) / t_max;
        let spread_t = worst(&rec.samples, |o| o.kinetic_energy) / t_max;
        assert!(drift_h < 1e-10, "{label}: H_N drift {drift_h:e} of |H|");
        assert!(
            drift_e < 1e-9,
            "{label}: energy balance drift {drift_e:e} of T"
        );
        assert!(spread_t > 1e-3, "{label}: T changes by only {spread_t:e}");
    }
}

/// An axisymmetric body with a rotor held at its rate on the symmetry axis is Volterra's
/// gyrostat with constant relative momentum h = I_a Ω: ω₃ stays constant and (ω₁, ω₂) turns at
/// λ = ((I_s − I_t) ω₃ + h)/I_t (from Euler's equations I ω̇ = −ω × (I ω + h ẑ); Hughes 1986,
/// on gyrostats). Here λ = ((60 − 100)·2 + 6·50)/100 = 2.2 rad/s.
#[test]
fn a_held_rotor_on_the_symmetry_axis_gives_the_gyrostat_closed_form() {
    let yaml = "name: gyrostat
body: {principal: [100.0, 100.0, 60.0]}
initial: {omega: [0.02, 0.0, 2.0]}
duration: 60.0
integrator: {method: dop853, rtol: 1.0e-12, atol: 1.0e-14}
output: {rate: 20}
effectors:
  - wheel:
      axial_inertia: 6.0
      axis: [0, 0, 1]
      initial_rate: 50.0
      motor: {speed_hold: {rate: 50.0, bandwidth: 10.0}}
";
    let s = load(yaml);
    let (out, rec) = run(&s);
    assert_eq!(out.status, Status::Complete);
    let lambda = ((60.0 - 100.0) * 2.0 + 6.0 * 50.0) / 100.0;
    let mut worst: f64 = 0.0;
    for o in &rec.samples {
        let expected = Vector3::new(
            0.02 * (lambda * o.t).cos(),
            0.02 * (lambda * o.t).sin(),
            2.0,
        );
        worst = worst.max((o.omega - expected).norm());
    }
    assert!(worst < 1e-10, "largest |ω − ω_exact| {worst:e} rad/s");
}

/// A triaxial body with a wheel on a skewed axis, its rate driven from 0 toward 30 rad/s by a
/// PI loop that saturates at the start, against an independent integration written here: the
/// hub and rotor equations as one 4 × 4 system
///
/// ```text
/// [ I      I_a â ] [ ω̇ ]   [ −ω × (I ω + I_a Ω â) ]
/// [ I_a âᵀ  I_a  ] [ Ω̇ ] = [ u − c Ω              ]
/// ```
///
/// with u = sat(K_p e + K_i z), ż = e + (u − v)/K_p, stepped by classical RK4 at 1 ms.
#[test]
fn a_pi_driven_wheel_matches_an_independent_integration() {
    let (ia, c, kp, ki, umax, target) = (0.05, 2.0e-3, 0.2, 0.2, 0.15, 30.0);
    let yaml = scene(
        &format!(
            "      motor: {{speed_hold: {{rate: {target}, kp: {kp}, ki: {ki}}}}}\n      max_torque: {umax}\n      friction: {{viscous: {c}}}\n"
        ),
        20.0,
    );
    let s = load(&yaml);
    let (out, rec) = run(&s);
    assert_eq!(out.status, Status::Complete);
    let inertia = nalgebra::Matrix3::from_diagonal(&Vector3::new(10.0, 12.0, 8.0));
    let a = Vector3::new(1.0, 2.0, 3.0).normalize();
    // State: ω (3), Ω, z.
    let f = |y: &[f64; 5]| -> [f64; 5] {
        let w = Vector3::new(y[0], y[1], y[2]);
        let (rate, z) = (y[3], y[4]);
        let e = target - rate;
        let v = kp * e + ki * z;
        let u = v.clamp(-umax, umax);
        let h = inertia * w + ia * rate * a;
        let top = -w.cross(&h);
        let mut m = Matrix4::zeros();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&inertia);
        for i in 0..3 {
            m[(i, 3)] = ia * a[i];
            m[(3, i)] = ia * a[i];
        }
        m[(3, 3)] = ia;
        let rhs = Vector4::new(top[0], top[1], top[2], u - c * rate);
        let acc = m.lu().solve(&rhs).unwrap();
        [acc[0], acc[1], acc[2], acc[3], e + (u - v) / kp]
    };
    let mut y = [0.3, -0.2, 0.5, 0.0, 0.0];
    let h = 1e-3;
    let mut steps = 0u64;
    let mut worst: f64 = 0.0;
    let mut saturated_at_start = false;
    for o in &rec.samples {
        while ((steps + 1) as f64) * h <= o.t + 1e-9 {
            let k1 = f(&y);
            let add = |y: &[f64; 5], k: &[f64; 5], s: f64| {
                let mut r = *y;
                for i in 0..5 {
                    r[i] += s * k[i];
                }
                r
            };
            let k2 = f(&add(&y, &k1, 0.5 * h));
            let k3 = f(&add(&y, &k2, 0.5 * h));
            let k4 = f(&add(&y, &k3, h));
            for i in 0..5 {
                y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
            steps += 1;
        }
        if (steps as f64 * h - o.t).abs() > 1e-9 {
            continue;
        }
        let w = Vector3::new(y[0], y[1], y[2]);
        worst = worst.max((o.omega - w).norm());
        if o.t == 0.0 {
            saturated_at_start = (kp * target).abs() > umax;
        }
    }
    let rate = out.final_state[7];
    assert!(
        saturated_at_start,
        "the test should exercise the torque limit"
    );
    assert!(worst < 1e-9, "largest |ω − ω_RK4| {worst:e} rad/s");
    assert!(
        (rate - y[3]).abs() < 1e-8,
        "rotor rate {rate} against {}",
        y[3]
    );
    // The loop has settled near its command by the end.
    assert!((rate - target).abs() < 0.5, "rotor rate {rate}");
}

/// Bad wheels are located errors.
#[test]
fn bad_wheels_are_refused_with_located_errors() {
    let base = "name: x\nbody: {principal: [10, 12, 8]}\ninitial: {omega: [0, 0, 0.1]}\nduration: 1\neffectors:\n  - wheel:\n      axis: [0, 0, 1]\n";
    let cases = [
        (
            "      axial_inertia: 0.05\n      transverse_inertia: 0.02\n",
            "field `effectors[0].wheel.transverse_inertia`: a rotor's axial inertia cannot exceed twice its transverse inertia",
        ),
        (
            "      axial_inertia: 9.0\n",
            "field `effectors[0].wheel.axial_inertia`: the rotor's axial inertia must be less than",
        ),
        (
            "      axial_inertia: 0.05\n      max_torque: 0.0\n",
            "field `effectors[0].wheel.max_torque`: expected a positive value",
        ),
        (
            "      axial_inertia: 0.05\n      motor: {torque: {steps: [[0, 1], [2, 0], [1, 3]]}}\n",
            "field `effectors[0].wheel.motor.torque.steps`: the times must increase strictly (s): 2 is followed by 1",
        ),
        (
            "      axial_inertia: 0.05\n      motor: {speed_hold: {rate: 10, kp: 1.0}}\n",
            "field `effectors[0].wheel.motor.speed_hold`: expected either `bandwidth`",
        ),
        (
            "      axial_inertia: 0.05\n      motor: {torque: {constant: 1, linear: [[0, 1]]}}\n",
            "field `effectors[0].wheel.motor.torque`: expected exactly one of",
        ),
    ];
    for (extra, expect) in cases {
        let yaml = format!("{base}{extra}");
        let e = parse(Path::new("test.yaml"), yaml.clone(), &Overrides::default());
        let Err(e) = e else {
            panic!("accepted:\n{yaml}");
        };
        let e = e.to_string();
        assert!(e.contains(expect), "expected {expect:?} in {e}\n{yaml}");
        assert!(e.starts_with("test.yaml:"), "{e}");
    }
}

/// A torque profile's steps are breakpoints: the integrators stop exactly on each, the held
/// torque takes its new value and the method restarts on the far side, so no step straddles a
/// jump. With the rotor on the symmetry axis of a body
/// spinning about it, ω₃ and Ω are exactly piecewise linear (ω̇₃ = −u/(I_s − I_a),
/// Ω̇ = u/I_a + u/(I_s − I_a)), which every Runge–Kutta or collocation step integrates exactly
/// when it does not cross a jump: the error stays at rounding. The step profile's value is a
/// held state updated at the stops, so with the stops turned off the torque would never
/// change (checked: the error is then 2e-2 rad/s).
#[test]
fn adaptive_methods_stop_exactly_at_torque_steps() {
    let (is, ia) = (60.0, 6.0);
    let steps = [(1.0, 0.5), (2.5, -1.25), (4.0, 0.75), (6.2, 0.0)];
    let table: Vec<String> = steps.iter().map(|(t, u)| format!("[{t}, {u}]")).collect();
    for method in [
        "{method: dopri5, rtol: 1.0e-9, atol: 1.0e-12}",
        "{method: dop853, rtol: 1.0e-9, atol: 1.0e-12}",
        "{method: radau5, rtol: 1.0e-9, atol: 1.0e-12}",
    ] {
        let yaml = format!(
            "name: steps
body: {{principal: [100.0, 100.0, {is}]}}
initial: {{omega: [0.0, 0.0, 0.1]}}
duration: 8.0
integrator: {method}
output: {{rate: 4}}
effectors:
  - wheel:
      axial_inertia: {ia}
      axis: [0, 0, 1]
      motor: {{torque: {{steps: [{}]}}}}
",
            table.join(", ")
        );
        let s = load(&yaml);
        let (out, rec) = run(&s);
        assert_eq!(out.status, Status::Complete, "{method}");
        // ω₃ and Ω by hand: integrate the piecewise-constant torque.
        let exact = |t: f64| {
            let (mut w3, mut rate, mut t0, mut u) = (0.1, 0.0, 0.0, 0.0);
            for &(tk, uk) in &steps {
                if tk > t {
                    break;
                }
                w3 -= u / (is - ia) * (tk - t0);
                rate += u * (1.0 / ia + 1.0 / (is - ia)) * (tk - t0);
                (t0, u) = (tk, uk);
            }
            w3 -= u / (is - ia) * (t - t0);
            rate += u * (1.0 / ia + 1.0 / (is - ia)) * (t - t0);
            (w3, rate)
        };
        let mut worst: f64 = 0.0;
        for o in &rec.samples {
            worst = worst.max((o.omega[2] - exact(o.t).0).abs());
        }
        let (_, rate) = exact(8.0);
        let rate_err = (out.final_state[7] - rate).abs();
        assert!(worst < 1e-14, "{method}: largest ω₃ error {worst:e} rad/s");
        assert!(
            rate_err < 1e-13,
            "{method}: rotor rate error {rate_err:e} rad/s"
        );
    }
}
