//! Core benchmarks, reported as ratios against a baseline measured in the same process
//! (the machines are shared and noisy; absolute times are printed for reference only).
//!
//!   cargo bench --bench core            # full
//!   cargo bench --bench core -- --quick # fewer repeats
//!   cargo bench --bench core -- --effectors  # the effector scenes' right-hand sides only
//!   cargo bench --bench core -- --igrf       # the degree-13 IGRF-14 field against the dipole
//!
//! 1. One RK4 step of the torque-free body through polhode's `Rk4` stepper and `Spacecraft`
//!    system, against a minimal hand-written RK4 loop on `[f64; 7]` with the same equations.
//! 2. A run that logs MCAP at 100 Hz against the same run without logging, on a cheap
//!    adaptive scene (integration much cheaper than a sample) and a fixed-step one.
//! 3. The cost of one right-hand-side evaluation of each shipped scene with effectors,
//!    against the rigid body's (a scene pays only for the effects it includes), and the
//!    spring–mass damper's against its hand-written reduced form (one 3 × 3 solve).
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
        "spinning-stage-slosh",
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

/// a × b on plain arrays, for the hand-written reduced forms.
#[inline(always)]
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// a · b on plain arrays, for the hand-written reduced forms.
#[inline(always)]
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The nutation-damper scene's right-hand side in its reduced form, written by hand: the hub
/// (mass M, principal inertia I) and one particle (mass m) on the body line r = r₀ + ρ p̂ with
/// spring k and dashpot c. With the system's centre of mass fixed, the hub's translation is
/// eliminated by the reduced mass m* = m M/(M + m); eliminating ρ̈ too leaves one 3 × 3 solve,
///
/// ```text
/// (I + m* (|r|² 1 − r rᵀ − t tᵀ)) ω̇ = −ω × Iω − r × (p̂ Q + m* (c − p̂ (p̂·c))),
/// ρ̈ = Q/m* − p̂·(ω̇ × r) − p̂·c,
/// ```
///
/// with t = r × p̂, c = ω × (ω × r) + 2ρ̇ ω × p̂ and Q = −kρ − cρ̇. States as polhode's:
/// [ω, q, ρ, ρ̇, dissipated energy].
struct ReducedDamper {
    hub_mass: f64,
    inertia: [f64; 3],
    mass: f64,
    anchor: [f64; 3],
    direction: [f64; 3],
    stiffness: f64,
    damping: f64,
}

impl ReducedDamper {
    /// The parameters of scenarios/nutation-damper.yaml.
    fn nutation_damper() -> Self {
        ReducedDamper {
            hub_mass: 5274.4,
            inertia: [1375.7, 1292.5, 1402.4],
            mass: 52.744,
            anchor: [1.0, 0.0, 0.0],
            direction: [0.0, 0.0, 1.0],
            stiffness: 52.744,
            damping: 105.49,
        }
    }

    #[inline(always)]
    fn rhs(&self, y: &[f64; 10], dy: &mut [f64; 10]) {
        let w = [y[0], y[1], y[2]];
        let (rho, rho_dot) = (y[7], y[8]);
        let (i, p) = (self.inertia, self.direction);
        let m_star = self.mass * self.hub_mass / (self.hub_mass + self.mass);
        let r = std::array::from_fn::<f64, 3, _>(|k| self.anchor[k] + rho * p[k]);
        let w_r = cross(w, r);
        let w_p = cross(w, p);
        let ww_r = cross(w, w_r);
        let c = std::array::from_fn::<f64, 3, _>(|k| ww_r[k] + 2.0 * rho_dot * w_p[k]);
        let q_force = -self.stiffness * rho - self.damping * rho_dot;
        let pc = dot(p, c);
        let pull =
            std::array::from_fn::<f64, 3, _>(|k| p[k] * q_force + m_star * (c[k] - p[k] * pc));
        let iw = [i[0] * w[0], i[1] * w[1], i[2] * w[2]];
        let gyro = cross(w, iw);
        let r_pull = cross(r, pull);
        let b = std::array::from_fn::<f64, 3, _>(|k| -gyro[k] - r_pull[k]);
        let t = cross(r, p);
        let r2 = dot(r, r);
        let a = |j: usize, k: usize| {
            let diagonal = if j == k { i[j] + m_star * r2 } else { 0.0 };
            diagonal - m_star * (r[j] * r[k] + t[j] * t[k])
        };
        // The symmetric 3 × 3 solve by cofactors.
        let (a00, a01, a02, a11, a12, a22) = (a(0, 0), a(0, 1), a(0, 2), a(1, 1), a(1, 2), a(2, 2));
        let c00 = a11 * a22 - a12 * a12;
        let c01 = a02 * a12 - a01 * a22;
        let c02 = a01 * a12 - a02 * a11;
        let c11 = a00 * a22 - a02 * a02;
        let c12 = a01 * a02 - a00 * a12;
        let c22 = a00 * a11 - a01 * a01;
        let inv_det = 1.0 / (a00 * c00 + a01 * c01 + a02 * c02);
        let w_dot = [
            (c00 * b[0] + c01 * b[1] + c02 * b[2]) * inv_det,
            (c01 * b[0] + c11 * b[1] + c12 * b[2]) * inv_det,
            (c02 * b[0] + c12 * b[1] + c22 * b[2]) * inv_det,
        ];
        let rho_ddot = q_force / m_star - dot(p, cross(w_dot, r)) - pc;
        let (qw, qx, qy, qz) = (y[3], y[4], y[5], y[6]);
        *dy = [
            w_dot[0],
            w_dot[1],
            w_dot[2],
            -0.5 * (qx * w[0] + qy * w[1] + qz * w[2]),
            0.5 * (qw * w[0] + qy * w[2] - qz * w[1]),
            0.5 * (qw * w[1] + qz * w[0] - qx * w[2]),
            0.5 * (qw * w[2] + qx * w[1] - qy * w[0]),
            rho_dot,
            rho_ddot,
            self.damping * rho_dot * rho_dot,
        ];
    }
}

/// Checks that polhode's right-hand side of `sc` and a hand-written `reduced` one agree at
/// `y` (to 1e-10 of each derivative), then times both, interleaved (`nudged` is the state
/// nudged from call to call, so that nothing is hoisted); returns (polhode, reduced) in ns.
fn against_reduced<const N: usize>(
    sc: &polhode::model::Spacecraft,
    y: [f64; N],
    nudged: usize,
    reduced: impl Fn(&[f64; N], &mut [f64; N]),
    repeats: usize,
) -> (f64, f64) {
    use polhode::integrate::OdeSystem;
    let (mut ours, mut theirs) = ([0.0; N], [0.0; N]);
    sc.rhs(0.0, &y, &mut ours);
    reduced(&y, &mut theirs);
    for k in 0..N {
        let scale = ours[k].abs().max(1e-9);
        assert!(
            (ours[k] - theirs[k]).abs() <= 1e-10 * scale,
            "the reduced form disagrees at state {k}: {} against {}",
            theirs[k],
            ours[k]
        );
    }
    let calls = 100_000;
    let (mut best_reduced, mut best_ours) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..repeats {
        best_reduced = best_reduced.min(min_time(1, || {
            let mut dy = [0.0; N];
            for k in 0..calls {
                let mut state = y;
                state[nudged] += black_box(k as f64 * 1e-9);
                reduced(black_box(&state), &mut dy);
                black_box(&dy);
            }
        }));
        best_ours = best_ours.min(min_time(1, || {
            let mut dy = [0.0; N];
            for k in 0..calls {
                let mut state = y;
                state[nudged] += black_box(k as f64 * 1e-9);
                sc.rhs(0.0, black_box(&state), &mut dy);
                black_box(&dy);
            }
        }));
    }
    (
        best_ours / calls as f64 * 1e9,
        best_reduced / calls as f64 * 1e9,
    )
}

/// polhode's right-hand side of the nutation-damper scene against [`ReducedDamper`] at the
/// same state (after checking that they agree).
fn bench_reduced_damper(repeats: usize) {
    let s = scenario::load(
        Path::new("scenarios/nutation-damper.yaml"),
        &Overrides::default(),
    )
    .expect("scenario");
    let sc = &s.spacecraft;
    let mut y = sc.initial_state(&s.omega0, &s.attitude0);
    // Off the rest point, so that every term is at work.
    y[7] = 0.05;
    y[8] = -0.2;
    let y: [f64; 10] = y.try_into().expect("10 states");
    let reduced = ReducedDamper::nutation_damper();
    let (ns_ours, ns_reduced) = against_reduced(sc, y, 8, |y, dy| reduced.rhs(y, dy), repeats);
    println!(
        "\nspring–mass damper (nutation-damper), one right-hand side against the hand-written \
         reduced form (one 3 × 3 solve):\n  polhode {ns_ours:.1} ns, reduced form {ns_reduced:.1} ns, \
         ratio {:.2}",
        ns_ours / ns_reduced
    );
}

/// One slosh pendulum alone on a hub, reduced by hand: with the system's centre of mass fixed
/// the bob moves as one of reduced mass m* = m M/(M + m) about a fixed hub centre, and since
/// the rod's Jacobian columns span the plane ⊥ ê, eliminating (φ̈, θ̈) leaves a rank-one update
/// of the hub's inertia (t = r × ê = d × ê, F = −c ṙ′ the dashpot's force, c_a the bob's
/// acceleration at ω̇ = 0, u̇ = 0):
///
/// ```text
/// (I + m* t tᵀ) ω̇ = −ω × Iω − r × (m* ê (ê·c_a) + F),
/// q̈_k = (j_k·F/m* − j_k·(ω̇ × r + c_a)) / |j_k|²,
/// ```
///
/// solved by Sherman–Morrison. States as polhode's: [ω, q, φ, θ, φ̇, θ̇, dissipated energy].
struct ReducedPendulum {
    hub_mass: f64,
    inertia: [f64; 3],
    mass: f64,
    length: f64,
    pivot: [f64; 3],
    /// p̂₁, p̂₂, p̂₃ (body axes).
    frame: [[f64; 3]; 3],
    damping: f64,
}

impl ReducedPendulum {
    #[inline(always)]
    fn rhs(&self, y: &[f64; 12], dy: &mut [f64; 12]) {
        let w = [y[0], y[1], y[2]];
        let (phi, theta, phi_dot, theta_dot) = (y[7], y[8], y[9], y[10]);
        let [p1, p2, p3] = self.frame;
        let (l, i) = (self.length, self.inertia);
        let m_star = self.mass * self.hub_mass / (self.hub_mass + self.mass);
        let (sp, cp) = phi.sin_cos();
        let (st, ct) = theta.sin_cos();
        let radial = std::array::from_fn::<f64, 3, _>(|k| cp * p1[k] + sp * p2[k]);
        let across = std::array::from_fn::<f64, 3, _>(|k| -sp * p1[k] + cp * p2[k]);
        let e = std::array::from_fn::<f64, 3, _>(|k| ct * radial[k] - st * p3[k]);
        let j_phi = std::array::from_fn::<f64, 3, _>(|k| l * ct * across[k]);
        let j_theta = std::array::from_fn::<f64, 3, _>(|k| l * (-st * radial[k] - ct * p3[k]));
        let r = std::array::from_fn::<f64, 3, _>(|k| self.pivot[k] + l * e[k]);
        let v = std::array::from_fn::<f64, 3, _>(|k| j_phi[k] * phi_dot + j_theta[k] * theta_dot);
        let w_r = cross(w, r);
        let ww_r = cross(w, w_r);
        let w_v = cross(w, v);
        let c_a = std::array::from_fn::<f64, 3, _>(|k| {
            ww_r[k] + 2.0 * w_v[k]
                - l * (ct * phi_dot * phi_dot * radial[k]
                    + 2.0 * st * phi_dot * theta_dot * across[k]
                    + theta_dot * theta_dot * e[k])
        });
        let force = v.map(|x| -self.damping * x);
        let ec = m_star * dot(e, c_a);
        let pull = std::array::from_fn::<f64, 3, _>(|k| ec * e[k] + force[k]);
        let iw = [i[0] * w[0], i[1] * w[1], i[2] * w[2]];
        let gyro = cross(w, iw);
        let r_pull = cross(r, pull);
        let b = std::array::from_fn::<f64, 3, _>(|k| -gyro[k] - r_pull[k]);
        let t = cross(self.pivot, e);
        // Sherman–Morrison on the diagonal I.
        let ib = [b[0] / i[0], b[1] / i[1], b[2] / i[2]];
        let it = [t[0] / i[0], t[1] / i[1], t[2] / i[2]];
        let k = m_star * dot(t, ib) / (1.0 + m_star * dot(t, it));
        let w_dot = std::array::from_fn::<f64, 3, _>(|n| ib[n] - k * it[n]);
        let wd_r = cross(w_dot, r);
        let a = std::array::from_fn::<f64, 3, _>(|n| wd_r[n] + c_a[n]);
        let accel = |j: [f64; 3], j2: f64| (dot(j, force) / m_star - dot(j, a)) / j2;
        let (qw, qx, qy, qz) = (y[3], y[4], y[5], y[6]);
        *dy = [
            w_dot[0],
            w_dot[1],
            w_dot[2],
            -0.5 * (qx * w[0] + qy * w[1] + qz * w[2]),
            0.5 * (qw * w[0] + qy * w[2] - qz * w[1]),
            0.5 * (qw * w[1] + qz * w[0] - qx * w[2]),
            0.5 * (qw * w[2] + qx * w[1] - qy * w[0]),
            phi_dot,
            theta_dot,
            accel(j_phi, l * l * ct * ct),
            accel(j_theta, l * l),
            self.damping * dot(v, v),
        ];
    }
}

/// One slosh pendulum on a prolate stage (one tank of scenarios/spinning-stage-slosh.yaml,
/// off its rest point), polhode's right-hand side against [`ReducedPendulum`] at the same
/// state, after checking that they agree.
fn bench_reduced_pendulum(repeats: usize) {
    let yaml = "name: b\nbody: {mass: 800.0, principal: [900.0, 900.0, 250.0]}\n\
                initial: {omega: [0.05, 0.0, 5.0]}\nduration: 1\neffectors:\n  \
                - slosh_pendulum: {mass: 25.0, length: 0.3, pivot: [0.45, 0.0, 0.2], \
                rest_direction: [1, 0, 0], damping: 100.0, initial_angles: [0.2, -0.1], \
                initial_rates: [0.3, 0.4]}\n";
    let s = scenario::parse(Path::new("bench.yaml"), yaml.into(), &Overrides::default())
        .expect("scenario");
    let sc = &s.spacecraft;
    let y: [f64; 12] = sc
        .initial_state(&s.omega0, &s.attitude0)
        .try_into()
        .expect("12 states");
    let reduced = ReducedPendulum {
        hub_mass: 800.0,
        inertia: [900.0, 900.0, 250.0],
        mass: 25.0,
        length: 0.3,
        pivot: [0.45, 0.0, 0.2],
        frame: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        damping: 100.0,
    };
    let (ns_ours, ns_reduced) = against_reduced(sc, y, 10, |y, dy| reduced.rhs(y, dy), repeats);
    println!(
        "\nslosh pendulum (one tank), one right-hand side against the hand-written reduced form \
         (a rank-one update):\n  polhode {ns_ours:.1} ns, reduced form {ns_reduced:.1} ns, \
         ratio {:.2}",
        ns_ours / ns_reduced
    );
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

/// One evaluation of the IGRF-14 field to degree 13 (`orbit::igrf::Coefficients::field_ecef`,
/// the coefficients of the year already formed) against the dipole's
/// (`orbit::magnetic::Dipole::field_ecef`), at points spread over a LEO shell; and the cost of
/// forming the year's coefficients (`Coefficients::igrf14`), once per epoch or per step.
fn bench_igrf(repeats: usize) {
    use nalgebra::Vector3;
    use polhode::orbit::igrf::Coefficients;
    use polhode::orbit::magnetic::Dipole;
    let calls = 20_000;
    let points: Vec<Vector3<f64>> = (0..calls)
        .map(|k| {
            let (lat, lon) = (1.3 * (k as f64 * 0.0137).sin(), k as f64 * 0.611);
            let r = 6.878e6 + 3e5 * (k as f64 * 0.29).cos();
            r * Vector3::new(lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin())
        })
        .collect();
    let full = Coefficients::igrf14(2026.3).expect("in range");
    let dipole = Dipole::igrf14(2026.3);
    let mut igrf = || {
        for p in &points {
            black_box(full.field_ecef(black_box(p)));
        }
    };
    let mut dip = || {
        for p in &points {
            black_box(dipole.field_ecef(black_box(p)));
        }
    };
    let years = || (0..calls).map(|k| 1900.0 + 130.0 * k as f64 / calls as f64);
    let mut coefficients = || {
        for y in years() {
            black_box(Coefficients::igrf14(black_box(y)).ok());
        }
    };
    let mut dipole_coefficients = || {
        for y in years() {
            black_box(Dipole::igrf14(black_box(y)));
        }
    };
    let (mut i_best, mut d_best, mut c_best, mut dc_best) =
        (f64::INFINITY, f64::INFINITY, f64::INFINITY, f64::INFINITY);
    for _ in 0..repeats {
        i_best = i_best.min(min_time(1, &mut igrf));
        d_best = d_best.min(min_time(1, &mut dip));
        c_best = c_best.min(min_time(1, &mut coefficients));
        dc_best = dc_best.min(min_time(1, &mut dipole_coefficients));
    }
    let ns = |t: f64| t / calls as f64 * 1e9;
    println!(
        "
IGRF-14 to degree 13 against the dipole (magnetic.rs), one call:"
    );
    println!(
        "  field at a point: degree 13 {:.0} ns, dipole {:.1} ns, ratio {:.0}",
        ns(i_best),
        ns(d_best),
        i_best / d_best
    );
    println!(
        "  coefficients of a year: degree 13 {:.0} ns, dipole {:.1} ns, ratio {:.0}",
        ns(c_best),
        ns(dc_best),
        c_best / dc_best
    );
    bench_field_on_orbit(repeats);
}

/// The field along a 500 km, 51.6° orbit over one day as a run sees it
/// (`GeomagneticField::field_on_orbit`): the dipole, IGRF-14 tabulated along the orbit (the
/// default), and IGRF-14 from the harmonics at every call (coefficients of the year included).
fn bench_field_on_orbit(repeats: usize) {
    use polhode::orbit::GeomagneticField;
    use polhode::orbit::field_table::FieldTable;
    let s = scenario::parse(
        std::path::Path::new("bench.yaml"),
        "name: b\nbody: {principal: [3, 5, 7]}\ninitial: {omega: [0, 0, 0.1]}\n\
         duration: 86400\norbit: {semi_major_axis_km: 6878.137, inclination_deg: 51.6}\n"
            .to_string(),
        &Overrides::default(),
    )
    .expect("valid");
    let orbit = s.orbit.clone().expect("an orbit");
    let epoch = s.epoch_unix_ns;
    let table = FieldTable::build(&orbit, epoch, 86_400.0)
        .expect("in range")
        .expect("a table");
    let fields = [
        ("dipole", GeomagneticField::new(epoch)),
        (
            "IGRF-14 tabulated",
            GeomagneticField::igrf(epoch, Some(std::sync::Arc::new(table))),
        ),
        ("IGRF-14 harmonics", GeomagneticField::igrf(epoch, None)),
    ];
    let calls = 20_000;
    let times: Vec<f64> = (0..calls)
        .map(|k| k as f64 * 86_400.0 / calls as f64)
        .collect();
    let mut best = [f64::INFINITY; 3];
    for _ in 0..repeats {
        for (b, (_, field)) in best.iter_mut().zip(&fields) {
            let mut along = || {
                for &t in &times {
                    black_box(field.field_on_orbit(&orbit, black_box(t)));
                }
            };
            *b = b.min(min_time(1, &mut along));
        }
    }
    println!("  along the orbit, one call (position, rotation and field):");
    for (b, (name, _)) in best.iter().zip(&fields) {
        println!(
            "    {name}: {:.1} ns, {:.1} × the dipole",
            b / calls as f64 * 1e9,
            b / best[0]
        );
    }
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
    // `--effectors`: the effector scenes' right-hand sides alone.
    if std::env::args().any(|a| a == "--effectors") {
        bench_effector_rhs(repeats);
        bench_reduced_damper(repeats);
        bench_reduced_pendulum(repeats);
        return;
    }
    // `--igrf`: the IGRF-14 field against the dipole alone.
    if std::env::args().any(|a| a == "--igrf") {
        bench_igrf(repeats);
        return;
    }
    bench_environment_rhs(repeats);
    bench_igrf(repeats);
    bench_sin_cos(repeats);
    bench_drag_rhs(repeats);
    // `--environment`: the environment torques alone.
    if std::env::args().any(|a| a == "--environment") {
        return;
    }
    bench_effector_rhs(repeats);
    bench_reduced_damper(repeats);
    bench_reduced_pendulum(repeats);
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
