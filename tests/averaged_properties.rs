//! Properties of `method: averaged` over random triaxial bodies and initial states
//! (docs/averaging.md, "Validity"; docs/reliability.md): near each axis and near the
//! separatrix (down to 1e-12 of it), with an energy sink or a Rayleigh torque. For every case
//! the run is refused before its first step or stopped with a diagnosis, or:
//! - T never rises (both scenes are passive), and never falls below the flat spin
//!   |H|²/(2 I3), within the slow stepper's rtol;
//! - with the sink, |H| is kept to rounding (the model keeps it);
//! - T and |H| at the end agree with dop853 at rtol 1e-11 within the averaging's O(ε) error:
//!   50 ε (1 + |ln ε|) of the band of T, H²(1/(2 I1) − 1/(2 I3)), with ε the fast period over
//!   the dissipation time measured on the dop853 run (the ln ε allows for the separatrix
//!   crossing, Neishtadt's O(ε |ln ε|)).

mod common;

use common::{run, scenario_with};
use polhode::scenario::Overrides;
use polhode::sim::Status;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::TAU;

/// One random case: the scene as YAML, its moments and whether |H| is kept.
struct Case {
    yaml: String,
    moments: [f64; 3],
    keeps_h: bool,
    what: String,
}

fn case(rng: &mut ChaCha8Rng, k: usize) -> Case {
    let i1: f64 = 1.0;
    let i2 = i1 + rng.random_range(0.1..1.5);
    // I3 ≤ I1 + I2 (the triangle inequality of a rigid body).
    let i3 = i2 + i1 * rng.random_range(0.05..0.95);
    let rate = rng.random_range(0.5..3.0);
    // Near an axis (a small tilt), or near the separatrix (δ of its energy away).
    let (omega, where_) = match k % 4 {
        0 | 1 => {
            let axis = [0usize, 2][k % 2];
            let tilt: f64 = 10f64.powf(rng.random_range(-3.0..-0.3));
            let mut w = [0.0; 3];
            w[axis] = rate;
            w[(axis + 1) % 3] = rate * tilt;
            w[(axis + 2) % 3] = rate * tilt * 0.7;
            (w, format!("axis {} tilt {tilt:.1e}", axis + 1))
        }
        _ => {
            // On the separatrix H² = 2 T I2 with ω1, ω3 in the ratio that puts it there,
            // then moved off by δ (relative, either side) in ω3.
            let delta: f64 = 10f64.powf(rng.random_range(-12.0..-2.0));
            let side = if k % 8 < 4 { 1.0 } else { -1.0 };
            let w1 = rate * 0.3;
            let w3 = w1 * ((i1 * (i2 - i1)) / (i3 * (i3 - i2))).sqrt() * (1.0 + side * delta);
            (
                [w1, rate, w3],
                format!("separatrix δ {:+.1e}", side * delta),
            )
        }
    };
    let t_spin = TAU / rate;
    let sink = k % 3 != 2;
    let (effector, keeps_h, what) = if sink {
        // Dissipation time ≈ band / (c |ω|²) of 200 to 1000 spin periods.
        let periods = rng.random_range(200.0..1000.0);
        let c = (i3 - i1) / (periods * t_spin);
        (
            format!("energy_sink: {{name: sink, coefficient: {c:e}}}"),
            true,
            "sink",
        )
    } else {
        let g = i1 / (rng.random_range(200.0..1000.0) * t_spin);
        (
            format!(
                "rayleigh: {{name: drag, gamma: [[{:e}, 0, 0], [0, {:e}, 0], [0, 0, {:e}]]}}",
                g,
                g * rng.random_range(0.2..2.0),
                g * rng.random_range(0.2..2.0)
            ),
            false,
            "rayleigh",
        )
    };
    // Several dissipation times: long after the nutation has died, where a slow stepper that
    // overshoots the flat spin shows it.
    let duration = rng.random_range(1000.0..6000.0) * t_spin;
    Case {
        yaml: format!(
            "name: p\nbody: {{principal: [{i1:e}, {i2:e}, {i3:e}]}}\neffectors:\n  - {effector}\n\
             initial: {{omega: [{:e}, {:e}, {:e}]}}\nduration: {duration:e}\n\
             integrator: {{method: averaged}}\noutput: {{rate: {:e}}}\n",
            omega[0],
            omega[1],
            omega[2],
            20.0 / duration
        ),
        moments: [i1, i2, i3],
        keeps_h,
        what: format!("{what}, {where_}, I = [{i1:.3}, {i2:.3}, {i3:.3}]"),
    }
}

/// The averaged method's default rtol on its slow variables.
const RTOL: f64 = 1e-10;

#[test]
fn averaged_keeps_its_promises_or_refuses_over_random_triaxial_cases() {
    let mut rng = ChaCha8Rng::seed_from_u64(35);
    let (mut ran, mut refused) = (0, 0);
    let mut failures = Vec::new();
    for k in 0..240 {
        let c = case(&mut rng, k);
        let s = scenario_with(&c.yaml, &Overrides::default());
        let (out, rec) = run(&s);
        match &out.status {
            Status::Complete => ran += 1,
            Status::Failed { diagnosis } => {
                // Refused or stopped: with a diagnosis that says why and what to use.
                assert!(diagnosis.contains("dop853"), "{}: {diagnosis}", c.what);
                refused += 1;
                continue;
            }
            other => panic!("{}: {other:?}", c.what),
        }
        let [i1, _, i3] = c.moments;
        let h0 = rec.samples[0].h_norm;
        let mut previous = f64::INFINITY;
        for o in &rec.samples {
            let floor = o.h_norm * o.h_norm / (2.0 * i3);
            // Within the slow stepper's tolerance (rtol 1e-10, the default): samples between
            // its steps come from DOP853's dense output, which may wiggle by that much.
            if o.kinetic_energy > previous * (1.0 + RTOL) {
                failures.push(format!(
                    "{}: T rose at t = {} by {:.2e} of T",
                    c.what,
                    o.t,
                    o.kinetic_energy / previous - 1.0
                ));
            }
            if o.kinetic_energy < floor * (1.0 - RTOL) {
                failures.push(format!("{}: T below the flat spin at {}", c.what, o.t));
            }
            if c.keeps_h && (o.h_norm - h0).abs() > 1e-12 * h0 {
                failures.push(format!("{}: |H| changed at {}", c.what, o.t));
            }
            previous = o.kinetic_energy;
        }
        // The reference, and ε measured on it.
        let ov = Overrides {
            method: Some("dop853".into()),
            rtol: Some(1e-11),
            atol: Some(1e-14),
            ..Overrides::default()
        };
        let (reference, ref_rec) = run(&scenario_with(&c.yaml, &ov));
        assert_eq!(reference.status, Status::Complete, "{}", c.what);
        let (r, a) = (&reference.final_observation, &out.final_observation);
        let band = r.h_norm * r.h_norm * (1.0 / (2.0 * i1) - 1.0 / (2.0 * i3));
        let mut epsilon: f64 = 0.0;
        for w in ref_rec.samples.windows(2) {
            let rate = (w[1].kinetic_energy - w[0].kinetic_energy).abs() / (w[1].t - w[0].t);
            let fast = TAU * w[0].h_norm / (2.0 * w[0].kinetic_energy);
            epsilon = epsilon.max(fast * rate / band);
        }
        let bound = 50.0 * epsilon * (1.0 + epsilon.ln().abs()) + 1e-6;
        let dt = (a.kinetic_energy - r.kinetic_energy).abs() / band;
        let dh = (a.h_norm - r.h_norm).abs() / r.h_norm;
        if dt.max(dh) > bound {
            failures.push(format!(
                "{}: T off by {dt:.2e} of its band and |H| by {dh:.2e}, beyond 50 ε (1 + |ln ε|) \
                 = {bound:.2e} (ε = {epsilon:.2e})",
                c.what
            ));
        }
    }
    assert!(
        ran >= 150,
        "only {ran} of 240 cases ran ({refused} refused)"
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
