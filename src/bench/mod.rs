//! Benchmarks of the integration methods: one timed solve (`polhode bench point`), and the
//! charts of docs/choosing-a-method.md (work-precision, invariant drift over long horizons,
//! stability map, error growth near the separatrix).
//!
//! Times are the minimum over repeated solves of the integration alone (no logging, no
//! output sampling), measured in this process: the machines are shared and noisy, and the
//! minimum is the least disturbed estimate of the method's cost.

pub mod failure;
pub mod secular;
pub mod work_precision;

use crate::integrate::Stats;
use crate::scenario::{self, Overrides, Scenario};
use crate::sim::{self, Solve};
use std::path::Path;

/// A method as the benchmarks run it: a scenario method name plus its variant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MethodSpec {
    /// Label in charts and tables (e.g. `gauss-2`, `splitting-4`).
    pub label: &'static str,
    /// Method name in scenarios.
    pub name: &'static str,
    /// `stages` (gauss).
    pub stages: Option<u32>,
    /// `order` (splitting).
    pub order: Option<u32>,
    /// The accuracy knob is the step `dt`.
    pub fixed_step: bool,
    /// The accuracy knob is the tolerance `rtol` (with `atol = 1e-3·rtol`).
    pub adaptive: bool,
}

const fn fixed(label: &'static str, name: &'static str) -> MethodSpec {
    MethodSpec {
        label,
        name,
        stages: None,
        order: None,
        fixed_step: true,
        adaptive: false,
    }
}

const fn adaptive(label: &'static str) -> MethodSpec {
    MethodSpec {
        label,
        name: label,
        stages: None,
        order: None,
        fixed_step: false,
        adaptive: true,
    }
}

/// Every method with its variants, in chart order.
pub const METHODS: [MethodSpec; 10] = [
    fixed("rk4", "rk4"),
    adaptive("dopri5"),
    adaptive("dop853"),
    adaptive("radau5"),
    MethodSpec {
        stages: Some(1),
        ..fixed("gauss-1", "gauss")
    },
    MethodSpec {
        stages: Some(2),
        ..fixed("gauss-2", "gauss")
    },
    fixed("lie", "lie"),
    MethodSpec {
        order: Some(2),
        ..fixed("splitting-2", "splitting")
    },
    MethodSpec {
        order: Some(4),
        ..fixed("splitting-4", "splitting")
    },
    MethodSpec {
        label: "exact",
        name: "exact",
        stages: None,
        order: None,
        fixed_step: false,
        adaptive: false,
    },
];

impl MethodSpec {
    /// The method labelled `label`.
    pub fn by_label(label: &str) -> Option<MethodSpec> {
        METHODS.iter().find(|m| m.label == label).copied()
    }

    /// Labels of all methods.
    pub fn labels() -> Vec<&'static str> {
        METHODS.iter().map(|m| m.label).collect()
    }
}

/// Limits of a sweep.
#[derive(Debug, Clone, Copy)]
pub struct Budget {
    /// A method's sweep stops after the first solve slower than this (s).
    pub seconds_per_point: f64,
    /// Most settings tried per method.
    pub max_points: usize,
}

/// Loads `path` with `method` at accuracy `knob` (dt, or rtol with atol = 1e-3·rtol) and
/// `duration` (s).
pub fn load_with(
    path: &Path,
    method: &MethodSpec,
    knob: Option<f64>,
    duration: Option<f64>,
) -> Result<Scenario, String> {
    let overrides = Overrides {
        method: Some(method.name.into()),
        dt: knob.filter(|_| method.fixed_step),
        rtol: knob.filter(|_| method.adaptive),
        atol: knob.filter(|_| method.adaptive).map(|r| 1e-3 * r),
        stages: method.stages,
        order: method.order,
        duration,
        mcap: None,
        max_log_mb: None,
    };
    scenario::load(path, &overrides).map_err(|e| e.to_string())
}

pub use crate::plot::svg_and_png;

/// One timed solve of a scenario with its method.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Point {
    /// Scenario file.
    pub scenario: String,
    /// Method name.
    pub method: String,
    /// Method and settings.
    pub settings: String,
    /// Simulated time (s).
    pub duration: f64,
    /// State dimension.
    pub dim: usize,
    /// State at t = 0.
    pub initial_state: Vec<f64>,
    /// State at `duration`.
    pub final_state: Vec<f64>,
    /// Fastest of the repeated solves (s).
    pub cpu_seconds: f64,
    /// Every repeat (s).
    pub cpu_seconds_all: Vec<f64>,
    /// Accepted steps.
    pub steps: u64,
    /// Rejected steps.
    pub rejected_steps: u64,
    /// Right-hand-side evaluations (including finite-difference Jacobians).
    pub rhs_evaluations: u64,
    /// Newton iterations (implicit methods).
    pub newton_iterations: u64,
}

/// Solves `scenario` over its duration `repeats` times (at least once) and keeps the fastest.
/// `repeats = 0` adapts the count to the cost: up to 7 solves while they total under 0.3 s,
/// so that quick solves are not timed from a single noisy sample.
pub fn point(scenario: &Scenario, repeats: usize) -> Result<Point, String> {
    let mut best: Option<Solve> = None;
    let mut all: Vec<f64> = Vec::new();
    for k in 0.. {
        let done = if repeats == 0 {
            k >= 7 || (k >= 1 && all.iter().sum::<f64>() > 0.3)
        } else {
            k >= repeats.max(1)
        };
        if done {
            break;
        }
        let s = sim::integrate_only(scenario, scenario.duration)?;
        all.push(s.seconds);
        if best.as_ref().is_none_or(|b| s.seconds < b.seconds) {
            best = Some(s);
        }
    }
    let best = best.expect("at least one repeat");
    let Stats {
        steps,
        rejected_steps,
        rhs_evaluations,
        newton_iterations,
        ..
    } = best.stats;
    let sc = &scenario.spacecraft;
    Ok(Point {
        scenario: scenario.path.display().to_string(),
        method: scenario.method.name().into(),
        settings: scenario.method.describe(),
        duration: scenario.duration,
        dim: crate::integrate::OdeSystem::dim(sc),
        initial_state: sc.initial_state(&scenario.omega0, &scenario.attitude0),
        final_state: best.final_state,
        cpu_seconds: best.seconds,
        cpu_seconds_all: all,
        steps,
        rejected_steps,
        rhs_evaluations,
        newton_iterations,
    })
}

/// The angle (rad) of the rotation between two attitude quaternions (scalar first):
/// `2·atan2(|vec(a* ⊗ b)|, |scalar(a* ⊗ b)|)`, accurate down to rounding, unlike the
/// `acos` form, which floors near 1e-8 rad.
pub fn attitude_error(a: &[f64], b: &[f64]) -> f64 {
    // a* ⊗ b
    let (aw, ax, ay, az) = (a[0], -a[1], -a[2], -a[3]);
    let (bw, bx, by, bz) = (b[0], b[1], b[2], b[3]);
    let w = aw * bw - ax * bx - ay * by - az * bz;
    let x = aw * bx + ax * bw + ay * bz - az * by;
    let y = aw * by - ax * bz + ay * bw + az * bx;
    let z = aw * bz + ax * by - ay * bx + az * bw;
    let v = (x * x + y * y + z * z).sqrt();
    2.0 * v.atan2(w.abs())
}

#[cfg(test)]
mod tests {
    use super::attitude_error;

    #[test]
    fn attitude_error_resolves_tiny_angles() {
        // A rotation of 1e-12 rad about z, and its sign-flipped twin (same rotation).
        let a = [1.0, 0.0, 0.0, 0.0];
        let half: f64 = 0.5e-12;
        let b = [half.cos(), 0.0, 0.0, half.sin()];
        assert!((attitude_error(&a, &b) - 1e-12).abs() < 1e-24);
        let nb = b.map(|x| -x);
        assert!((attitude_error(&a, &nb) - 1e-12).abs() < 1e-24);
        // A large angle: 3 rad about x.
        let c = [1.5f64.cos(), 1.5f64.sin(), 0.0, 0.0];
        assert!((attitude_error(&a, &c) - 3.0).abs() < 1e-15);
    }
}
