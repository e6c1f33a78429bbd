//! Fuzz target `method_pairs`: valid scenarios built from structured input (a triaxial body,
//! optionally an orbit with environmental torques, eddy currents and hysteresis rods, wheels
//! with each kind of motor, B-dot magnetorquers, a dissipation torque), each run briefly under dop853 and under a second
//! method, which must agree with it within its own error or be refused cleanly
//! (docs/reliability.md, "The method contract").
//!
//! Properties:
//! - nothing panics or hangs;
//! - a scene the loader accepts with the second method is one the method contract accepts
//!   (`Method::refusal`), and a refusal names the method;
//! - where both run, the second method agrees with dop853 at rtol 1e-11: a fixed-step method
//!   at steps h and h/2 (h from the scene's fastest eigenvalue and its breakpoints), the h/2
//!   result within twice the distance between the two plus 1e-8; an adaptive method at rtol
//!   1e-7 and 1e-9, the latter within twice the distance plus ten times its tolerance
//!   (rtol + atol/|ω|, at least 1e-8); `exact` within 1e-8;
//!   `averaged` in T within 5 ε_max = 0.05 of T's band and |H| within 0.05, or stopped with a
//!   diagnosis. Errors are the hub's:
//!   rates relative to the larger |ω| of start and end (at least 1e-4 rad/s), and attitude
//!   (rad).

#![no_main]

use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use polhode::bench::attitude_error;
use polhode::scenario::{self, Overrides, Scenario};
use polhode::sim;
use std::path::Path;

#[derive(Debug, Arbitrary)]
enum Environment {
    GravityGradient,
    MagneticDipole([i8; 3]),
    SolarPressure { area: u8, normal: [i8; 3] },
    Aerodynamic,
    EddyCurrents { radius: u8 },
    HysteresisRod { axis: [i8; 3], length: u8 },
}

#[derive(Debug, Arbitrary)]
enum Motor {
    Free,
    Constant(i8),
    Steps([(u8, i8); 3]),
    RateDamping { gain: u8, rate: u8 },
    SpeedHold { rate: i8, bandwidth: u8 },
}

#[derive(Debug, Arbitrary)]
struct Wheel {
    axis: [i8; 3],
    initial_rate: i8,
    motor: Motor,
}

#[derive(Debug, Arbitrary)]
enum Dissipation {
    None,
    Rayleigh([u8; 3]),
    EnergySink(u8),
}

#[derive(Debug, Arbitrary)]
struct Case {
    /// Moments: I2 = I1 (1 + a/64), I3 = I2 + I1 b/300 (within the triangle inequality).
    moments: (u8, u8),
    omega: [i8; 3],
    orbit: Option<(u8, u8, u8)>,
    environment: Vec<Environment>,
    wheels: Vec<Wheel>,
    bdot: Option<u8>,
    dissipation: Dissipation,
    method: u8,
    duration: u8,
}

/// A unit-ish vector from bytes (the x axis when they are all zero).
fn axis(v: [i8; 3]) -> [f64; 3] {
    if v == [0; 3] {
        [1.0, 0.0, 0.0]
    } else {
        v.map(f64::from)
    }
}

fn yaml(c: &Case) -> String {
    let i1 = 1.0;
    let i2 = i1 * (1.0 + f64::from(c.moments.0) / 64.0);
    let i3 = i2 + i1 * f64::from(c.moments.1) / 300.0;
    let w = c.omega.map(|x| f64::from(x) / 32.0);
    let mut y = format!(
        "name: fuzz\nbody: {{mass: 10.0, principal: [{i1}, {i2}, {i3}], \
         shape: {{box: {{size: [0.5, 0.5, 0.5]}}}}}}\n\
         initial: {{omega: [{}, {}, {}]}}\nduration: {}\n",
        w[0],
        w[1],
        w[2],
        0.2 + f64::from(c.duration) / 64.0
    );
    if let Some((alt, inc, ecc)) = c.orbit {
        let perigee = 300.0 + 20.0 * f64::from(alt);
        let apogee = perigee + 40.0 * f64::from(ecc);
        y += &format!(
            "orbit: {{perigee_altitude_km: {perigee}, apogee_altitude_km: {apogee}, \
             inclination_deg: {}, raan_deg: 0.0, arg_perigee_deg: 0.0, \
             true_anomaly_deg: 0.0}}\n",
            f64::from(inc) * 180.0 / 255.0
        );
    }
    let mut effectors = Vec::new();
    if c.orbit.is_some() {
        for (k, e) in c.environment.iter().take(4).enumerate() {
            effectors.push(match e {
                Environment::GravityGradient => format!("gravity_gradient: {{name: gg{k}}}"),
                Environment::MagneticDipole(m) => {
                    let m = m.map(|x| f64::from(x) / 256.0);
                    format!(
                        "magnetic_dipole: {{name: m{k}, moment: [{}, {}, {}]}}",
                        m[0], m[1], m[2]
                    )
                }
                Environment::SolarPressure { area, normal } => {
                    let n = axis(*normal);
                    format!(
                        "solar_pressure: {{name: s{k}, area: {}, normal: [{}, {}, {}], \
                         center_of_pressure: [0.1, 0.0, 0.0], specular: 0.3, diffuse: 0.3}}",
                        0.1 + f64::from(*area) / 32.0,
                        n[0],
                        n[1],
                        n[2]
                    )
                }
                Environment::Aerodynamic => {
                    format!("aerodynamic: {{name: a{k}, drag_coefficient: 2.2, from_shape: true}}")
                }
                Environment::EddyCurrents { radius } => format!(
                    "eddy_currents: {{name: e{k}, conductivity: 3.5e7, \
                     shape: {{spherical_shell: {{radius: {}, thickness: 0.002}}}}}}",
                    0.05 + f64::from(*radius) / 1000.0
                ),
                Environment::HysteresisRod { axis: a, length } => {
                    let a = axis(*a);
                    format!(
                        "hysteresis_rod: {{name: h{k}, axis: [{}, {}, {}], length: {}, \
                         diameter: 0.001, coercivity: 1.59, remanence: 0.35, saturation: 0.73, \
                         properties: material}}",
                        a[0],
                        a[1],
                        a[2],
                        0.02 + f64::from(*length) / 2000.0
                    )
                }
            });
        }
        if let Some(rate) = c.bdot {
            effectors.push(format!(
                "magnetorquer: {{name: coils, max_dipole: 0.2, bdot: {{gain: auto, \
                 sample_rate: {}}}}}",
                1.0 + f64::from(rate % 16)
            ));
        }
    }
    for (k, wh) in c.wheels.iter().take(2).enumerate() {
        let a = axis(wh.axis);
        let motor = match &wh.motor {
            Motor::Free => String::new(),
            Motor::Constant(u) => {
                format!(", motor: {{torque: {{constant: {}}}}}", f64::from(*u) / 1e4)
            }
            Motor::Steps(s) => {
                let mut t = 0.0;
                let points: Vec<String> = s
                    .iter()
                    .map(|(dt, u)| {
                        t += 0.01 + f64::from(*dt) / 100.0;
                        format!("[{t}, {}]", f64::from(*u) / 1e4)
                    })
                    .collect();
                format!(", motor: {{torque: {{steps: [{}]}}}}", points.join(", "))
            }
            Motor::RateDamping { gain, rate } => format!(
                ", motor: {{rate_damping: {{gain: {}, sample_rate: {}}}}}",
                0.01 + f64::from(*gain) / 256.0,
                1.0 + f64::from(rate % 32)
            ),
            Motor::SpeedHold { rate, bandwidth } => format!(
                ", motor: {{speed_hold: {{rate: {}, bandwidth: {}}}}}",
                f64::from(*rate),
                0.1 + f64::from(bandwidth % 32) / 4.0
            ),
        };
        effectors.push(format!(
            "wheel: {{name: rw{k}, axial_inertia: 0.01, axis: [{}, {}, {}], initial_rate: {}{motor}}}",
            a[0],
            a[1],
            a[2],
            f64::from(wh.initial_rate)
        ));
    }
    match &c.dissipation {
        Dissipation::None => {}
        Dissipation::Rayleigh(g) => {
            let g = g.map(|x| f64::from(x) / 2560.0);
            effectors.push(format!(
                "rayleigh: {{name: drag, gamma: [[{}, 0, 0], [0, {}, 0], [0, 0, {}]]}}",
                g[0], g[1], g[2]
            ));
        }
        Dissipation::EnergySink(k) => effectors.push(format!(
            "energy_sink: {{name: sink, coefficient: {}}}",
            f64::from(*k) / 2560.0
        )),
    }
    if !effectors.is_empty() {
        y += "effectors:\n";
        for e in effectors {
            y += &format!("  - {e}\n");
        }
    }
    y
}

/// The second method: its name, and whether it takes a fixed step; order or stages.
const METHODS: [(&str, bool, Option<u32>, Option<u32>); 10] = [
    ("dopri5", false, None, None),
    ("radau5", false, None, None),
    ("rk4", true, None, None),
    ("gauss", true, None, Some(1)),
    ("gauss", true, None, Some(2)),
    ("lie", true, None, None),
    ("splitting", true, Some(2), None),
    ("splitting", true, Some(4), None),
    ("exact", false, None, None),
    ("averaged", false, None, None),
];

/// The finer of the two tolerances an adaptive method runs at (its atol is 1e-3 of it).
const FINE_RTOL: f64 = 1e-9;

fn hub_error(r: &[f64], y: &[f64], scale: f64) -> f64 {
    let dw = (0..3).map(|i| (y[i] - r[i]).powi(2)).sum::<f64>().sqrt() / scale;
    attitude_error(&r[3..7], &y[3..7]).max(dw)
}

fuzz_target!(|c: Case| {
    let text = yaml(&c);
    let path = Path::new("fuzz.yaml");
    let parse = |ov: &Overrides| scenario::parse(path, text.clone(), ov);
    // The scene itself may be refused (an unphysical combination): a clean error, done.
    let Ok(base) = parse(&Overrides::default()) else {
        return;
    };
    let duration = base.duration;
    let solve = |s: &Scenario| sim::integrate_only(s, duration).map(|o| o.final_state);
    let tight = Overrides {
        method: Some("dop853".into()),
        rtol: Some(1e-11),
        atol: Some(1e-14),
        ..Overrides::default()
    };
    let Ok(reference_scene) = parse(&tight) else {
        panic!("dop853 refused a scene the loader accepts:\n{text}");
    };
    // A scene the reference cannot integrate (a diagnosis) has nothing to compare with.
    let Ok(reference) = solve(&reference_scene) else {
        return;
    };
    let (name, fixed, order, stages) = METHODS[usize::from(c.method) % METHODS.len()];
    let settings = |dt: Option<f64>, rtol: Option<f64>| Overrides {
        method: Some(name.into()),
        dt,
        rtol,
        atol: rtol.map(|r| r * 1e-3),
        order,
        stages,
        ..Overrides::default()
    };
    let y0 = base.spacecraft.initial_state(&base.omega0, &base.attitude0);
    let rho = polhode::linearize::stiffness(&base.spacecraft, 0.0, &y0, duration)
        .spectral_radius
        .max(base.omega0.norm())
        .max(1e-3);
    let first_breakpoint = base
        .spacecraft
        .next_breakpoint(0.0)
        .unwrap_or(f64::INFINITY);
    let h = (0.1 / rho).min(duration / 20.0).min(first_breakpoint / 4.0);
    if fixed && duration / h > 2e4 {
        return;
    }
    let end_rate = (0..3).map(|i| reference[i].powi(2)).sum::<f64>().sqrt();
    // Below 1e-4 rad/s the rates are compared absolutely: an adaptive method's absolute
    // tolerance (atol = 1e-3 rtol, 1e-12 rad/s at rtol 1e-9) bounds what it resolves there,
    // and a body nearly at rest (a B-dot scene starting from ω = 0) reaches 1e-8 rad/s, where
    // a 1e-14 rad/s difference would read as 1e-6 relative.
    let scale = base.omega0.norm().max(end_rate).max(1e-4);
    let (first, second) = if fixed {
        (settings(Some(h), None), settings(Some(h / 2.0), None))
    } else if name == "exact" {
        (settings(None, None), settings(None, None))
    } else {
        (settings(None, Some(1e-7)), settings(None, Some(FINE_RTOL)))
    };
    let scene = match parse(&second) {
        Ok(s) => s,
        Err(e) => {
            let e = e.to_string();
            assert!(
                e.contains(&format!("method `{name}`")),
                "{name} refused without naming itself: {e}\n{text}"
            );
            return;
        }
    };
    let contract = scene.method.refusal(&scene.spacecraft, duration);
    assert!(
        contract.is_none(),
        "loaded but the contract refuses: {contract:?}\n{text}"
    );
    let fine = match solve(&scene) {
        Ok(y) => y,
        Err(e) => {
            assert!(
                name == "averaged",
                "{name} failed where dop853 ran: {e}\n{text}"
            );
            return;
        }
    };
    if name == "averaged" {
        let a = scene.spacecraft.observe(duration, &fine);
        let r = scene.spacecraft.observe(duration, &reference);
        // Its documented error is O(ε) with ε ≤ 0.01 (else it stops): 5 ε of T's band, over
        // a horizon that may be shorter than one polhode period.
        let moments = scene.spacecraft.hub.principal_moments;
        let (i1, i3) = (moments.min(), moments.max());
        let band = r.h_norm * r.h_norm * (1.0 / (2.0 * i1) - 1.0 / (2.0 * i3));
        let dt = (a.kinetic_energy - r.kinetic_energy).abs() / band;
        let dh = ((a.h_norm - r.h_norm) / r.h_norm).abs();
        assert!(
            dt <= 0.05 && dh <= 0.05,
            "averaged: T off by {dt:e} of its band, |H| by {dh:e}\n{text}"
        );
        return;
    }
    let error = hub_error(&reference, &fine, scale);
    let bound = if name == "exact" {
        1e-8
    } else {
        // The coarser setting may stop with a diagnosis where the finer one runs (a Newton
        // iteration meeting a hysteresis rod's kink at the larger step): a clean failure, and
        // without it there is no error estimate to compare with.
        let Some(coarse) = parse(&first).ok().and_then(|s| solve(&s).ok()) else {
            return;
        };
        let distance = 2.0 * hub_error(&coarse, &fine, scale);
        if fixed {
            distance + 1e-8
        } else {
            // An adaptive method's global error is of the order of the tolerance it was
            // given, rtol + atol/|ω| on the rates. The distance between the two tolerances
            // estimates it only where the error test sets the steps: where breakpoints do
            // (a sampled controller restarting the method at every sample, each step shorter
            // than the error test would allow), both tolerances take the same steps, their
            // distance is nil, and radau5 at rtol 1e-9 (atol 1e-12) ends 2.8e-12 rad/s from
            // dop853 on a body at rest under B-dot and an energy sink. Ten times the
            // tolerance bounds that accumulation over the steps of a short run.
            let tolerance = FINE_RTOL + FINE_RTOL * 1e-3 / scale;
            distance + (10.0 * tolerance).max(1e-8)
        }
    };
    assert!(
        error <= bound,
        "{name}: error {error:e} against dop853 beyond its bound {bound:e}\n{text}"
    );
});
