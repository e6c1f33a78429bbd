//! The lockstep lanes of the nutation-damper class against the scalar path, bit for bit (states,
//! work, observations, grid samples and drift terms).
//!
//! The reference is the scalar `Dopri5` on a `Spacecraft` built the normal way (a hub with a
//! `spring_mass_damper` effector, whose right-hand side is its nalgebra closed form), stepped to
//! each run's end time. Each lane must give the same accepted and rejected steps, right-hand-side
//! evaluations, final time and final state, to the bit, on every engine (one lane, four lanes
//! compiled for the baseline target, four lanes compiled for AVX2 and eight in AVX-512
//! registers, where the processor has them).
//!
//!   cargo test --release --test lanes_damper
//!   cargo test --release --test lanes_damper -- --ignored --nocapture   # the runs/s figures

use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use polhode::effectors::particles::ParticleEffector;
use polhode::effectors::spring_mass::SpringMass;
use polhode::integrate::{Dopri5, Stats, Stepper, Tolerances};
use polhode::lanes::damper::{DIM, DamperRun};
use polhode::lanes::ensemble::{
    Engine, GridObservation, LaneMethodKind, LaneObservation, LaneOutcome, LaneSettings,
    LaneStatus, integrate_runs, integrate_runs_observed_with, integrate_runs_with,
};
use polhode::model::{RigidBody, Spacecraft};
use polhode::sim::Reference;
use std::time::Instant;

/// The scenario's tolerances (scenarios/nutation-damper.yaml).
const SETTINGS: LaneSettings = LaneSettings {
    method: LaneMethodKind::Dopri5,
    tolerances: Tolerances {
        rtol: 1e-11,
        atol: 1e-13,
    },
    h_max: f64::INFINITY,
};

/// A small deterministic generator (splitmix64), so the draws need no seed plumbing.
struct Draws(u64);

impl Draws {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        lo + (hi - lo) * (z >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// `count` runs of scenarios/nutation-damper.yaml with dispersed products of inertia, ω₀,
/// attitude, damper state and damper mass, stiffness and damping, ending at `t_end(i)`.
fn dispersed_runs(count: usize, seed: u64, t_end: impl Fn(usize) -> f64) -> Vec<DamperRun> {
    let mut d = Draws(seed);
    (0..count)
        .map(|i| DamperRun {
            hub_inertia: {
                // Products of inertia too, so that every entry of the matrix is read.
                let (xy, xz, yz) = (
                    d.uniform(-8.0, 8.0),
                    d.uniform(-8.0, 8.0),
                    d.uniform(-8.0, 8.0),
                );
                Matrix3::new(1375.7, xy, xz, xy, 1292.5, yz, xz, yz, 1402.4)
            },
            hub_mass: 5274.4,
            damper: SpringMass {
                mass: 52.744 * d.uniform(0.8, 1.2),
                position: Vector3::new(1.0, 0.0, 0.0),
                direction: Vector3::z(),
                stiffness: 52.744 * d.uniform(0.5, 1.5),
                damping: 105.49 * d.uniform(0.2, 3.0),
                travel: None,
            },
            omega0: Vector3::new(
                d.uniform(0.02, 0.2),
                d.uniform(-0.05, 0.05),
                d.uniform(0.8, 1.2),
            ),
            attitude0: UnitQuaternion::from_euler_angles(
                d.uniform(-0.3, 0.3),
                d.uniform(-0.3, 0.3),
                d.uniform(-3.0, 3.0),
            ),
            offset0: d.uniform(-0.05, 0.05),
            rate0: d.uniform(-0.02, 0.02),
            // Tilted from z, so that every component of the axis is read.
            spin_axis: Vector3::new(d.uniform(-0.1, 0.1), d.uniform(-0.1, 0.1), 1.0).normalize(),
            t_end: t_end(i),
            sample_rate: 0.0,
        })
        .collect()
}

/// The run's spacecraft, built as the scenario loader builds it.
fn spacecraft(run: &DamperRun) -> Spacecraft {
    let mut sc = Spacecraft::new(RigidBody::new(run.hub_inertia).unwrap(), run.spin_axis);
    // The run holds the spacecraft's axis as `lane_form` copies it, already unit: normalising
    // it again could move it by a unit in the last place.
    sc.spin_axis = run.spin_axis;
    sc.hub_mass = Some(run.hub_mass);
    let damper = ParticleEffector::new("damper", run.damper.clone(), &[run.offset0], &[run.rate0]);
    sc.add_effector(Box::new(damper)).unwrap();
    sc
}

/// The scalar path: `Dopri5` on the run's `Spacecraft`, stepped to its end time.
fn scalar(run: &DamperRun) -> (f64, Vec<f64>, Stats) {
    let sc = spacecraft(run);
    let y0 = sc.initial_state(&run.omega0, &run.attitude0);
    assert_eq!(y0, run.initial_state().to_vec(), "state layouts differ");
    let mut s = Dopri5::new(0.0, &y0, SETTINGS.tolerances, SETTINGS.h_max, None);
    while s.t() < run.t_end {
        s.step(&sc, run.t_end).expect("the scalar run completes");
    }
    (s.t(), s.y().to_vec(), s.stats())
}

fn assert_bitwise_equal(engine: Engine, runs: &[DamperRun], lanes: &[LaneOutcome<DIM>]) {
    assert_eq!(lanes.len(), runs.len());
    for (i, (run, lane)) in runs.iter().zip(lanes).enumerate() {
        let (t, y, stats) = scalar(run);
        assert_eq!(lane.status, LaneStatus::Complete, "{engine:?}, run {i}");
        assert_eq!(lane.stats, stats, "{engine:?}, run {i}: work");
        assert_eq!(lane.t.to_bits(), t.to_bits(), "{engine:?}, run {i}: t");
        for (j, (a, b)) in lane.y.iter().zip(&y).enumerate() {
            assert_eq!(
                a.to_bits(),
                b.to_bits(),
                "{engine:?}, run {i}, state {j}: {a} vs {b}"
            );
        }
    }
}

fn engines() -> Vec<Engine> {
    let mut e = vec![Engine::Scalar, Engine::Portable4];
    if polhode::cpu::avx2_available() {
        e.push(Engine::Avx2);
    }
    if polhode::cpu::avx512_available() {
        e.push(Engine::Avx512);
    }
    e
}

/// `lane`'s values against the scalar observation of `sc` at (`t`, `y`), bit for bit.
fn assert_observed_as_scalar(
    sc: &Spacecraft,
    t: f64,
    y: &[f64],
    lane: &LaneObservation,
    what: &str,
) {
    let o = sc.observe(t, y);
    let q = o.attitude.quaternion();
    let pairs = [
        ("attitude w", lane.attitude[0], q.w),
        ("attitude x", lane.attitude[1], q.i),
        ("attitude y", lane.attitude[2], q.j),
        ("attitude z", lane.attitude[3], q.k),
        ("|q| - 1", lane.q_norm_error, o.q_norm_error),
        ("H body x", lane.h_body[0], o.h_body.x),
        ("H body y", lane.h_body[1], o.h_body.y),
        ("H body z", lane.h_body[2], o.h_body.z),
        ("H inertial x", lane.h_inertial[0], o.h_inertial.x),
        ("H inertial y", lane.h_inertial[1], o.h_inertial.y),
        ("H inertial z", lane.h_inertial[2], o.h_inertial.z),
        ("kinetic", lane.kinetic_energy, o.kinetic_energy),
        ("elastic", lane.elastic_energy, o.elastic_energy),
        ("dissipated", lane.dissipated_energy, o.dissipated_energy),
        ("power", lane.dissipation_power, o.dissipation_power),
        ("|H|", lane.h_norm, o.h_norm),
        ("nutation angle", lane.nutation_angle, o.nutation_angle),
    ];
    for (name, a, b) in pairs {
        assert_eq!(a.to_bits(), b.to_bits(), "{what}, {name}: {a} vs {b}");
    }
}

/// An observed integration hands each step's end observation and, where the output grid has a
/// time strictly inside the step, the state there and its observation: each bit for bit what
/// the scalar interpolation and `Spacecraft::observe` give. Every grid time is either a step's
/// end, its first grid time inside, or a further one inside the same step (left to the
/// observer); the test counts them so that the handed samples cannot be silently absent.
#[test]
fn observed_steps_carry_the_scalar_observations_and_grid_samples() {
    let rate = 20.0;
    let mut runs = dispersed_runs(6, 11, |i| 20.0 + 3.0 * i as f64);
    for run in &mut runs {
        run.sample_rate = rate;
    }
    let craft: Vec<Spacecraft> = runs.iter().map(spacecraft).collect();
    // What the run monitor measures each run's drift against.
    let references: Vec<Reference> = runs
        .iter()
        .zip(&craft)
        .map(|(run, sc)| Reference::of(&sc.observe(0.0, &run.initial_state())))
        .collect();
    for engine in engines() {
        // Per run: grid times handed inside steps, at step ends, and left over.
        let mut counts = vec![(0u64, 0u64, 0u64); runs.len()];
        let mut buf = [0.0; 10];
        integrate_runs_observed_with(
            engine,
            &runs,
            &SETTINGS,
            GridObservation::Full,
            &mut |k, step, rest| {
                let sc = &craft[k];
                let what = format!("{engine:?}, run {k}, step to t = {}", step.t);
                let mut y = [0.0; 10];
                rest.state(&mut y);
                assert_eq!(step.finite, y.iter().all(|v| v.is_finite()), "{what}");
                let end = rest.end();
                assert_observed_as_scalar(sc, step.t, &y, &end, &what);
                // The numbers handed at every step are those of the end observation.
                for (name, a, b) in [
                    (
                        "nutation angle",
                        step.end_nutation_angle,
                        end.nutation_angle,
                    ),
                    (
                        "kinetic energy",
                        step.end_kinetic_energy,
                        end.kinetic_energy,
                    ),
                ] {
                    assert_eq!(a.to_bits(), b.to_bits(), "{what}: handed {name}");
                }
                // The drift terms, as the monitor computes them from the scalar observation.
                let terms = references[k].terms(&sc.observe(step.t, &y).invariants());
                for (name, a, b) in [
                    ("|H|", step.drift.h_norm_rel, terms.h_norm_rel),
                    ("H_N", step.drift.h_inertial_rel, terms.h_inertial_rel),
                    ("energy", step.drift.energy_rel, terms.energy_rel),
                    ("|q|", step.drift.q_norm, terms.q_norm),
                ] {
                    assert_eq!(
                        a.to_bits(),
                        b.to_bits(),
                        "{what}: {name} drift {a:e} vs {b:e}"
                    );
                }
                // The grid times in (t_prev, t].
                let first = (step.t_prev * rate).floor() as u64 + 1;
                let grid: Vec<f64> = (first..)
                    .map(|j| j as f64 / rate)
                    .skip_while(|&tk| tk <= step.t_prev)
                    .take_while(|&tk| tk <= step.t)
                    .collect();
                let inside: Vec<f64> = grid.iter().copied().filter(|&tk| tk < step.t).collect();
                match (rest.sample(), inside.first()) {
                    (Some(s), Some(&tk)) => {
                        assert_eq!(s.t.to_bits(), tk.to_bits(), "{what}: sample time");
                        let handed = step.sample.expect("the grid time is handed");
                        assert_eq!(handed.t.to_bits(), tk.to_bits(), "{what}: handed time");
                        assert_eq!(
                            handed.nutation_angle.to_bits(),
                            s.observation.nutation_angle.to_bits(),
                            "{what}: handed nutation angle"
                        );
                        assert!(rest.prepare_interpolation());
                        let interpolant = rest.interpolant();
                        interpolant.value(tk, step.t_prev, step.t, &y, &mut buf);
                        for (j, (a, b)) in s.y.iter().zip(&buf).enumerate() {
                            assert_eq!(a.to_bits(), b.to_bits(), "{what}: sample state {j}");
                        }
                        assert_observed_as_scalar(sc, tk, &s.y, &s.observation, &what);
                        counts[k].0 += 1;
                        counts[k].2 += inside.len() as u64 - 1;
                    }
                    (None, None) => assert!(step.sample.is_none(), "{what}: a grid time handed"),
                    (s, tk) => panic!("{what}: sample {s:?} for the grid time {tk:?}"),
                }
                counts[k].1 += (grid.len() - inside.len()) as u64;
                true
            },
        );
        for (k, (run, &(inside, at_end, left))) in runs.iter().zip(&counts).enumerate() {
            // Every grid time in (0, t_end] is accounted for once.
            let whole = (run.t_end * rate).floor() as u64;
            assert_eq!(inside + at_end + left, whole, "{engine:?}, run {k}");
            assert!(
                inside > whole / 2,
                "{engine:?}, run {k}: {inside} of {whole} handed"
            );
        }
    }
}

/// An observer that reads only the nutation angle at the output grid is handed the same
/// angles at the same times as one that reads everything there, and nothing else.
#[test]
fn the_nutation_angle_alone_is_the_full_observations_angle() {
    let mut runs = dispersed_runs(6, 5, |i| 15.0 + 2.0 * i as f64);
    for run in &mut runs {
        run.sample_rate = 20.0;
    }
    for engine in engines() {
        let handed = |grid: GridObservation| {
            let mut angles = vec![Vec::new(); runs.len()];
            integrate_runs_observed_with(engine, &runs, &SETTINGS, grid, &mut |k, step, rest| {
                if let Some(s) = step.sample {
                    let full = rest.sample();
                    assert_eq!(full.is_some(), grid == GridObservation::Full);
                    angles[k].push((s.t.to_bits(), s.nutation_angle.to_bits()));
                }
                true
            });
            angles
        };
        let full = handed(GridObservation::Full);
        assert!(full.iter().all(|a| a.len() > 100), "{engine:?}");
        assert_eq!(full, handed(GridObservation::NutationAngle), "{engine:?}");
    }
}

/// 12 dispersed draws to 60 s, all ending together: three full lanes of four.
#[test]
fn lanes_equal_the_scalar_runs_bit_for_bit() {
    let runs = dispersed_runs(12, 1958, |_| 60.0);
    for engine in engines() {
        assert_bitwise_equal(
            engine,
            &runs,
            &integrate_runs_with(engine, &runs, &SETTINGS),
        );
    }
}

/// 10 draws ending at different times (10 to 100 s, not in order): lanes finish apart, are
/// refilled with the next run, and the last group is not full.
#[test]
fn lanes_that_end_at_different_times_equal_the_scalar_runs() {
    let ends = [37.0, 10.0, 100.0, 55.5, 23.25, 80.0, 12.0, 64.0, 99.9, 41.0];
    let runs = dispersed_runs(10, 7, |i| ends[i]);
    for engine in engines() {
        assert_bitwise_equal(
            engine,
            &runs,
            &integrate_runs_with(engine, &runs, &SETTINGS),
        );
    }
}

/// A loose tolerance makes the controller reject steps; the rejections match too.
#[test]
fn rejected_steps_match_the_scalar_runs() {
    let loose = LaneSettings {
        method: LaneMethodKind::Dopri5,
        tolerances: Tolerances {
            rtol: 1e-3,
            atol: 1e-6,
        },
        h_max: f64::INFINITY,
    };
    let runs: Vec<DamperRun> = dispersed_runs(8, 99, |i| 20.0 + 7.0 * i as f64)
        .into_iter()
        .map(|mut r| {
            r.omega0 *= 3.0;
            r
        })
        .collect();
    let mut rejected = 0;
    for engine in engines() {
        let lanes = integrate_runs_with(engine, &runs, &loose);
        for (run, lane) in runs.iter().zip(&lanes) {
            let sc = spacecraft(run);
            let y0 = sc.initial_state(&run.omega0, &run.attitude0);
            let mut s = Dopri5::new(0.0, &y0, loose.tolerances, loose.h_max, None);
            while s.t() < run.t_end {
                s.step(&sc, run.t_end).unwrap();
            }
            assert_eq!(lane.stats, s.stats());
            assert_eq!(lane.y.to_vec(), s.y().to_vec());
            rejected += s.stats().rejected_steps;
        }
    }
    assert!(
        rejected > 0,
        "no step was rejected: the test does not test rejections"
    );
}

/// A direction that is not a unit vector is declined (the scalar path takes its general form
/// there), and a run that ends at its start takes no step; the other runs are unaffected.
#[test]
fn declined_and_empty_runs_are_reported() {
    let mut runs = dispersed_runs(5, 31, |_| 5.0);
    runs[1].damper.direction = Vector3::new(0.0, 0.6, 0.6);
    runs[3].t_end = 0.0;
    let lanes = integrate_runs(&runs, &SETTINGS);
    assert_eq!(lanes[1].status, LaneStatus::Declined { t: 0.0 });
    assert_eq!(lanes[3].status, LaneStatus::Complete);
    assert_eq!(lanes[3].stats, Stats::default());
    for i in [0, 2, 4] {
        let (_, y, stats) = scalar(&runs[i]);
        assert_eq!(lanes[i].stats, stats);
        assert_eq!(lanes[i].y.to_vec(), y);
    }
}

/// Runs per second of the lane engines against the plain scalar loop over the same draws, in
/// this process (the scenario's 600 s, rtol 1e-11, atol 1e-13). Prints; asserts nothing about
/// time.
#[test]
#[ignore]
fn bench_lanes_against_the_scalar_loop() {
    let runs = dispersed_runs(32, 2024, |_| 600.0);
    let repeats = 3;
    let time = |f: &mut dyn FnMut()| {
        (0..repeats)
            .map(|_| {
                let start = Instant::now();
                f();
                start.elapsed().as_secs_f64()
            })
            .fold(f64::INFINITY, f64::min)
    };
    let scalar_loop = time(&mut || {
        for run in &runs {
            std::hint::black_box(scalar(run));
        }
    });
    let rate = |t: f64| runs.len() as f64 / t;
    println!(
        "{} runs of 600 s: scalar Dopri5 loop {:.1} runs/s",
        runs.len(),
        rate(scalar_loop)
    );
    for engine in engines() {
        let t = time(&mut || {
            std::hint::black_box(integrate_runs_with(engine, &runs, &SETTINGS));
        });
        println!(
            "  {engine:?}: {:.1} runs/s, {:.2}x the scalar loop",
            rate(t),
            scalar_loop / t
        );
    }
    // What the lanes' observations cost, with an observer that reads nothing: each step's
    // end observation and drift and its dense output, without and with a grid time inside
    // it at 20 Hz (as a campaign of scenarios/nutation-damper.yaml asks).
    for sample_rate in [0.0, 20.0] {
        let mut sampled = runs.clone();
        for run in &mut sampled {
            run.sample_rate = sample_rate;
        }
        for engine in engines() {
            let plain = time(&mut || {
                std::hint::black_box(integrate_runs_with(engine, &sampled, &SETTINGS));
            });
            let observed = time(&mut || {
                std::hint::black_box(integrate_runs_observed_with(
                    engine,
                    &sampled,
                    &SETTINGS,
                    GridObservation::NutationAngle,
                    &mut |_, _, _| true,
                ));
            });
            println!(
                "  {engine:?} observed, grid at {sample_rate} Hz: {:.1} runs/s, {:.2}x the \
                 time unobserved",
                rate(observed),
                observed / plain
            );
        }
    }
}
