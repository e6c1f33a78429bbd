//! The integration method of a run and its settings (docs/choosing-a-method.md).

/// Tolerances and step cap of an adaptive method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Adaptive {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
    /// Largest step (s).
    pub max_step: f64,
}

impl Adaptive {
    fn describe(&self) -> String {
        let cap = if self.max_step.is_finite() {
            format!(", max_step {:e} s", self.max_step)
        } else {
            String::new()
        };
        format!("rtol {:e}, atol {:e}{cap}", self.rtol, self.atol)
    }
}

/// The integration method and its settings, validated (see docs/choosing-a-method.md).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// Classic RK4 with fixed step `dt` (s).
    Rk4 {
        /// Step (s).
        dt: f64,
    },
    /// Adaptive Dormand–Prince 5(4).
    Dopri5(Adaptive),
    /// Adaptive Dormand–Prince 8(5,3) (Hairer's DOP853).
    Dop853(Adaptive),
    /// Adaptive Radau IIA of order 5 (L-stable, implicit): for stiff effectors.
    Radau5(Adaptive),
    /// Gauss–Legendre collocation with a fixed step: implicit midpoint (1 stage, order 2) or
    /// 2 stages (order 4). Keeps every quadratic invariant of the free body.
    Gauss {
        /// Step (s).
        dt: f64,
        /// Stages: 1 or 2.
        stages: u8,
    },
    /// Runge–Kutta–Munthe-Kaas of order 4 with a fixed step: the attitude advances by
    /// exponentials, so it stays a unit quaternion.
    Lie {
        /// Step (s).
        dt: f64,
    },
    /// Composition of the exact torque-free flow with the flow of the torques and effectors:
    /// Strang (order 2) or the order-4 triple jump, fixed step.
    Splitting {
        /// Step (s).
        dt: f64,
        /// Order: 2 or 4.
        order: u8,
    },
    /// Closed-form torque-free solution.
    Exact,
    /// Averaged (secular) propagation of a slowly dissipating spinner: the slow variables
    /// (|H|, T, each effector's dissipated energy) stepped by DOP853 with these tolerances
    /// on their period-averaged rates, the fast motion rebuilt from the exact solution.
    Averaged(Adaptive),
}

impl Method {
    /// Names accepted in YAML and on the command line (`auto` picks one of the others).
    pub const NAMES: [&'static str; 10] = [
        "rk4",
        "dopri5",
        "dop853",
        "radau5",
        "gauss",
        "lie",
        "splitting",
        "exact",
        "averaged",
        "auto",
    ];

    /// Its name.
    pub fn name(&self) -> &'static str {
        match self {
            Method::Rk4 { .. } => "rk4",
            Method::Dopri5(_) => "dopri5",
            Method::Dop853(_) => "dop853",
            Method::Radau5(_) => "radau5",
            Method::Gauss { .. } => "gauss",
            Method::Lie { .. } => "lie",
            Method::Splitting { .. } => "splitting",
            Method::Exact => "exact",
            Method::Averaged(_) => "averaged",
        }
    }

    /// Name and settings, e.g. `dopri5 (rtol 1e-10, atol 1e-12)`.
    pub fn describe(&self) -> String {
        match self {
            Method::Rk4 { dt } => format!("rk4 (dt {dt:e} s)"),
            Method::Dopri5(a) => format!("dopri5 ({})", a.describe()),
            Method::Dop853(a) => format!("dop853 ({})", a.describe()),
            Method::Radau5(a) => format!("radau5 ({})", a.describe()),
            Method::Gauss { dt, stages } => {
                format!(
                    "gauss ({stages} stage(s), order {}, dt {dt:e} s)",
                    2 * stages
                )
            }
            Method::Lie { dt } => format!("lie (RKMK4, dt {dt:e} s)"),
            Method::Splitting { dt, order } => format!("splitting (order {order}, dt {dt:e} s)"),
            Method::Exact => "exact (closed-form torque-free solution)".into(),
            Method::Averaged(a) => {
                // The slow variables are scaled by their initial values: no atol applies.
                let cap = if a.max_step.is_finite() {
                    format!(", max_step {:e} s", a.max_step)
                } else {
                    String::new()
                };
                format!("averaged (secular, rtol {:e}{cap})", a.rtol)
            }
        }
    }

    /// The fixed step (s) of a fixed-step method.
    pub fn fixed_step(&self) -> Option<f64> {
        match *self {
            Method::Rk4 { dt }
            | Method::Gauss { dt, .. }
            | Method::Lie { dt }
            | Method::Splitting { dt, .. } => Some(dt),
            _ => None,
        }
    }

    /// The settings of an adaptive method.
    pub fn adaptive(&self) -> Option<Adaptive> {
        match *self {
            Method::Dopri5(a) | Method::Dop853(a) | Method::Radau5(a) | Method::Averaged(a) => {
                Some(a)
            }
            _ => None,
        }
    }

    /// Whether the method is implicit (A-stable: no step-size limit from stiffness).
    pub fn is_implicit(&self) -> bool {
        matches!(self, Method::Radau5(_) | Method::Gauss { .. })
    }
}
