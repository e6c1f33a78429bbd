//! Core benchmarks, reported as ratios against a baseline measured in the same process
//! (the machines are shared and noisy; absolute times are printed for reference only).
//!
//!   cargo bench --bench core            # full
//!   cargo bench --bench core -- --quick # fewer repeats
//!
//! 1. One RK4 step of the torque-free body through polhode's `Rk4` stepper and `Spacecraft`
//!    system, against a minimal hand-written RK4 loop on `[f64; 7]` with the same equations.
//! 2. A run that logs MCAP at 100 Hz against the same run without logging, on a cheap
//!    adaptive scene (integration much cheaper than a sample) and a fixed-step one.
//! 3. The cost of one right-hand-side evaluation of each shipped scene with effectors,
//!    against the rigid body's (a scene pays only for the effects it includes).
//!
//! Each measurement is the minimum over repeats, and the two sides alternate so that both see
//! the same machine load.

use polhode::integrate::{Rk4, Stepper};
use polhode::log::McapLogger;
use polhode::model::{RigidBody, Spacecraft};
use polhode::scenario::{self, Overrides};
use polhode::sim::{self, Control, NullSink};
use std::hint::black_box;
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// The baseline: the torque-free body, RK4, fixed arrays, no abstraction.
fn hand_written_rk4(inertia: [f64; 3], y: &mut [f64; 7], dt: f64, steps: usize) {
    #[inline(always)]
    fn f(i: &[f64; 3], y: &[f64; 7]) -> [f64; 7] {
        let (p, q, r) = (y[0], y[1], y[2]);
        let (w, x, yy, z) = (y[3], y[4], y[5], y[6]);
        [
            (i[1] - i[2]) / i[0] * q * r,
            (i[2] - i[0]) / i[1] * r * p,
            (i[0] - i[1]) / i[2] * p * q,
            -0.5 * (x * p + yy * q + z * r),
            0.5 * (w * p + yy * r - z * q),
            0.5 * (w * q + z * p - x * r),
            0.5 * (w * r + x * q - yy * p),
        ]
    }
    let add = |a: &[f64; 7], k: &[f64; 7], h: f64| std::array::from_fn(|j| a[j] + h * k[j]);
    for _ in 0..steps {
        let k1 = f(&inertia, y);
        let k2 = f(&inertia, &add(y, &k1, 0.5 * dt));
        let k3 = f(&inertia, &add(y, &k2, 0.5 * dt));
        let k4 = f(&inertia, &add(y, &k3, dt));
        for j in 0..7 {
            y[j] += dt / 6.0 * (k1[j] + 2.0 * (k2[j] + k3[j]) + k4[j]);
        }
    }
}

fn min_time(repeats: usize, mut f: impl FnMut()) -> f64 {
    (0..repeats)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn bench_rk4_step(repeats: usize) {
    const STEPS: usize = 100_000;
    let principal = [1.0, 2.0, 3.0];
    let sc = Spacecraft::new(
        RigidBody::from_principal(principal).unwrap(),
        nalgebra::Vector3::z(),
    );
    let y0 = [0.3, 0.5, 0.8, 1.0, 0.0, 0.0, 0.0];
    let dt = 1e-3;
    let (mut best_polhode, mut best_hand) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..repeats {
        best_polhode = best_polhode.min(min_time(1, || {
            let mut s = Rk4::new(0.0, &y0, dt);
            for _ in 0..STEPS {
                s.step(black_box(&sc), f64::INFINITY).unwrap();
            }
            black_box(s.y());
        }));
        best_hand = best_hand.min(min_time(1, || {
            let mut y = y0;
            hand_written_rk4(black_box(principal), &mut y, dt, STEPS);
            black_box(y);
        }));
    }
    let (p, h) = (best_polhode / STEPS as f64, best_hand / STEPS as f64);
    println!(
        "rk4 step, torque-free body: polhode {:.1} ns, hand-written {:.1} ns, ratio {:.2}",
        p * 1e9,
        h * 1e9,
        p / h
    );
}

/// Logging at 100 Hz against no logging, on one scene (`method` overrides the scenario's).
fn bench_logging(repeats: usize, label: &str, method: &str, dt: Option<f64>) {
    let path = Path::new("scenarios/generic-tumble.yaml");
    let ov = Overrides {
        duration: Some(200.0),
        method: Some(method.into()),
        dt,
        ..Default::default()
    };
    let mut s = scenario::load(path, &ov).expect("scenario");
    s.output_rate = 100.0;
    let dir = std::env::temp_dir().join(format!("polhode-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("bench.mcap");
    let stop = AtomicBool::new(false);
    let ctl = || Control {
        interrupt: &stop,
        progress: None,
    };
    let (mut best_log, mut best_plain) = (f64::INFINITY, f64::INFINITY);
    let (mut steps, mut samples) = (0, 0);
    for _ in 0..repeats {
        best_plain = best_plain.min(min_time(1, || {
            let o = sim::run(&s, &mut NullSink, ctl()).unwrap();
            (steps, samples) = (o.stats.steps, o.samples);
        }));
        // The whole logged run: create, integrate and write, finish (including the fsync).
        best_log = best_log.min(min_time(1, || {
            let mut l = McapLogger::create(&out, &s, s.omega0.norm()).unwrap();
            let o = sim::run(&s, &mut l, ctl()).unwrap();
            l.finish(&s, method, &o).unwrap();
        }));
    }
    let _ = std::fs::remove_dir_all(&dir);
    println!(
        "logging at 100 Hz, {label} ({steps} steps, {samples} samples): logged {:.2} ms, \
         unlogged {:.2} ms, ratio {:.2}; logging costs {:.2} us per sample",
        best_log * 1e3,
        best_plain * 1e3,
        best_log / best_plain,
        (best_log - best_plain) / samples as f64 * 1e6
    );
}

/// One right-hand-side evaluation of each scene, against the rigid body's, alternating.
fn bench_effector_rhs(repeats: usize) {
    use polhode::integrate::OdeSystem;
    let rigid = scenario::load(
        Path::new("scenarios/generic-tumble.yaml"),
        &Overrides::default(),
    )
    .expect("scenario");
    let calls = 20_000;
    println!("\none right-hand-side evaluation, against the rigid body (7 states):");
    for file in [
        "wheel-damper",
        "nutation-damper",
        "explorer1-pydy-energy-sink",
        "explorer1",
        "flexible-boom",
        "explorer1-pydy-modal",
    ] {
        let s = scenario::load(
            Path::new(&format!("scenarios/{file}.yaml")),
            &Overrides::default(),
        )
        .expect("scenario");
        let (base_ns, ns) = rhs_times(&rigid, &s, calls, repeats);
        println!(
            "  {file:<28} {:>3} states  {ns:>9.1} ns  rigid {base_ns:>6.1} ns  ratio {:>7.1}",
            s.spacecraft.dim(),
            ns / base_ns
        );
    }
}

/// `calls` right-hand-side evaluations of `s` at its initial state, at times spread by
/// 0.37 s (the environment's orbit phase changes from call to call; time-independent scenes
/// do not care).
fn time_rhs(s: &scenario::Scenario, calls: usize) -> impl FnMut() + '_ {
    use polhode::integrate::OdeSystem;
    let sc = &s.spacecraft;
    let y = sc.initial_state(&s.omega0, &s.attitude0);
    let mut dy = vec![0.0; sc.dim()];
    move || {
        for k in 0..calls {
            sc.rhs(black_box(k as f64 * 0.37), black_box(&y), &mut dy);
            black_box(&dy);
        }
    }
}

/// One right-hand side of `rigid` and of `with` (ns), each the best of `repeats` runs of
/// `calls` evaluations, interleaved.
fn rhs_times(
    rigid: &scenario::Scenario,
    with: &scenario::Scenario,
    calls: usize,
    repeats: usize,
) -> (f64, f64) {
    let (mut base_best, mut best) = (f64::INFINITY, f64::INFINITY);
    let mut f_base = time_rhs(rigid, calls);
    let mut f = time_rhs(with, calls);
    for _ in 0..repeats {
        base_best = base_best.min(min_time(1, &mut f_base));
        best = best.min(min_time(1, &mut f));
    }
    (base_best / calls as f64 * 1e9, best / calls as f64 * 1e9)
}

/// Prints what `with` adds to `rigid`'s right-hand side, and the ratio.
fn print_added(
    label: &str,
    rigid: &scenario::Scenario,
    with: &scenario::Scenario,
    calls: usize,
    repeats: usize,
) {
    let (base_ns, ns) = rhs_times(rigid, with, calls, repeats);
    println!(
        "  {label:<16} {ns:>7.1} ns  rigid {base_ns:>6.1} ns  added {:>6.1} ns  ratio {:>5.2}",
        ns - base_ns,
        ns / base_ns
    );
}

/// What the gravity gradient adds to a rigid body's right-hand side, as a ratio in one run:
/// the same body without and with it, in a circular orbit and in an eccentric one (where
/// every call solves Kepler's equation at its own time; times spread over an orbit).
fn bench_environment_rhs(repeats: usize) {
    let yaml = |orbit: &str, effectors: &str| {
        format!(
            "name: b\nbody: {{principal: [3, 5, 7]}}\n{orbit}initial: {{omega: [0.01, 0.02, 0.03]}}\nduration: 1\n{effectors}"
        )
    };
    let load = |text: String| {
        scenario::parse(Path::new("bench.yaml"), text, &Overrides::default()).expect("scenario")
    };
    let calls = 20_000;
    let rigid = load(yaml("", ""));
    println!(
        "\ntorque effectors (the machinery alone, then the gravity gradient and the magnetic \
         dipole), one right-hand-side evaluation against the rigid body:"
    );
    let gravity = "effectors:\n  - gravity_gradient: {}\n";
    for (label, orbit, effectors) in [
        (
            "rayleigh (Γ = 0)",
            "",
            "effectors:\n  - rayleigh: {gamma_diagonal: [0, 0, 0]}\n",
        ),
        (
            "circular orbit",
            "orbit: {semi_major_axis_km: 6978.137}\n",
            gravity,
        ),
        (
            "e = 0.7 orbit",
            "orbit: {semi_major_axis_km: 25000, eccentricity: 0.7}\n",
            gravity,
        ),
        (
            "magnetic dipole",
            "orbit: {semi_major_axis_km: 6878.137, inclination_deg: 51.6}\n",
            "effectors:\n  - magnetic_dipole: {moment: [0.05, 0, 0]}\n",
        ),
    ] {
        let with = load(yaml(orbit, effectors));
        print_added(label, &rigid, &with, calls, repeats);
    }
}

/// What a driven wheel costs: the gyrostat of scenarios/gyrostat.yaml with its rotor as a
/// frictionless `wheel_damper`, then as a `wheel` coasting, held by its PI loop, and held with
/// friction, against the rigid body, one right-hand side each.
fn bench_wheel_rhs(repeats: usize) {
    let load = |rotor: &str| {
        let text = format!(
            "name: b\nbody: {{principal: [100.0, 100.0, 60.0]}}\n\
             initial: {{omega: [0.02, 0.0, 2.0]}}\nduration: 1\neffectors:\n{rotor}"
        );
        scenario::parse(Path::new("bench.yaml"), text, &Overrides::default()).expect("scenario")
    };
    let rigid = scenario::parse(
        Path::new("bench.yaml"),
        "name: b\nbody: {principal: [100.0, 100.0, 60.0]}\ninitial: {omega: [0.02, 0.0, 2.0]}\n\
         duration: 1\n"
            .into(),
        &Overrides::default(),
    )
    .expect("scenario");
    let calls = 20_000;
    println!("\ndriven wheels, one right-hand-side evaluation against the rigid body:");
    for (label, rotor) in [
        (
            "wheel_damper",
            "  - wheel_damper: {inertia: 6.0, axis: [0, 0, 1], damping: 0.0, initial_rate: 50.0}\n",
        ),
        (
            "wheel, free",
            "  - wheel: {axial_inertia: 6.0, axis: [0, 0, 1], initial_rate: 50.0}\n",
        ),
        (
            "wheel, held",
            "  - wheel: {axial_inertia: 6.0, axis: [0, 0, 1], initial_rate: 50.0, \
             motor: {speed_hold: {rate: 50.0, bandwidth: 10.0}}, max_torque: 5.0}\n",
        ),
        (
            "held, friction",
            "  - wheel: {axial_inertia: 6.0, axis: [0, 0, 1], initial_rate: 50.0, \
             motor: {speed_hold: {rate: 50.0, bandwidth: 10.0}}, max_torque: 5.0, \
             friction: {viscous: 1.0e-3, coulomb: 1.0e-2}}\n",
        ),
    ] {
        let with = load(rotor);
        print_added(label, &rigid, &with, calls, repeats);
    }
}

/// The orbit angle's sine and cosine, the largest single part of the gravity gradient in a
/// circular orbit: the table-driven `polhode::sincos` against the C library's, at
/// the angles a LEO orbit reaches in a day.
fn bench_sin_cos(repeats: usize) {
    let calls = 100_000;
    let angle = |k: usize| black_box(0.3 + k as f64 * 1.1e-3 * 0.37);
    let mut table = || {
        for k in 0..calls {
            black_box(polhode::sincos::sin_cos(angle(k)));
        }
    };
    let mut library = || {
        for k in 0..calls {
            black_box(angle(k).sin_cos());
        }
    };
    let (mut t_best, mut l_best) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..repeats {
        t_best = t_best.min(min_time(1, &mut table));
        l_best = l_best.min(min_time(1, &mut library));
    }
    let (t_ns, l_ns) = (t_best / calls as f64 * 1e9, l_best / calls as f64 * 1e9);
    println!(
        "  sin_cos of the orbit angle: table {t_ns:.1} ns, C library {l_ns:.1} ns, ratio {:.2}",
        t_ns / l_ns
    );
}

/// What aerodynamic drag adds to a rigid body's right-hand side: one constant area, and the
/// facets of a box and of a cylinder (`from_shape: true`), in LEO.
fn bench_drag_rhs(repeats: usize) {
    let yaml = |shape: &str, drag: &str| {
        format!(
            "name: b\nbody: {{principal: [3, 5, 7]{shape}}}\n\
             orbit: {{semi_major_axis_km: 6778.137, inclination_deg: 51.6}}\n\
             initial: {{omega: [0.01, 0.02, 0.03]}}\nduration: 1\n\
             effectors:\n  - aerodynamic: {{drag_coefficient: 2.2, {drag}}}\n"
        )
    };
    let load = |text: String| {
        scenario::parse(Path::new("bench.yaml"), text, &Overrides::default()).expect("scenario")
    };
    let calls = 20_000;
    let rigid = load(
        "name: b\nbody: {principal: [3, 5, 7]}\ninitial: {omega: [0.01, 0.02, 0.03]}\n\
         duration: 1\n"
            .into(),
    );
    println!("\naerodynamic drag, one right-hand-side evaluation against the rigid body:");
    let from_shape = "from_shape: true, shape_center: [0, 0.02, 0.01]";
    for (label, shape, drag) in [
        (
            "one area",
            "",
            "area: 0.03, center_of_pressure: [0, 0.02, 0.01]",
        ),
        (
            "box facets",
            ", shape: {box: {size: [1, 1.4, 1.8]}}",
            from_shape,
        ),
        (
            "cylinder",
            ", shape: {cylinder: {radius: 0.8, length: 1.8}}",
            from_shape,
        ),
    ] {
        let with = load(yaml(shape, drag));
        print_added(label, &rigid, &with, calls, repeats);
    }
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let repeats = if quick { 3 } else { 15 };
    bench_environment_rhs(repeats);
    bench_sin_cos(repeats);
    bench_drag_rhs(repeats);
    // `--environment`: the environment torques alone.
    if std::env::args().any(|a| a == "--environment") {
        return;
    }
    bench_effector_rhs(repeats);
    bench_wheel_rhs(repeats);
    bench_rk4_step(repeats);
    bench_logging(
        repeats,
        "200 s generic tumble, dopri5 rtol 1e-12",
        "dopri5",
        None,
    );
    bench_logging(
        repeats,
        "200 s generic tumble, rk4 dt 1e-4",
        "rk4",
        Some(1e-4),
    );
}
