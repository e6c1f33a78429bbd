//! `integrator:`: the method and its settings as written, validated into a [`Method`] with the
//! command line's overrides.

use super::{MIN_ATOL, OutputSpec, Overrides, ScenarioError, loc, nearest, output_rate_hint};
use crate::sim::{Adaptive, Method};
use nalgebra::Vector3;
use serde::Deserialize;
use serde_saphyr::Spanned;
use std::path::Path;

/// `integrator:` method and settings.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntegratorSpec {
    /// One of [`Method::NAMES`].
    #[serde(default)]
    pub method: Option<Spanned<String>>,
    /// Fixed step (s), for `rk4`, `gauss`, `lie` and `splitting`.
    #[serde(default)]
    pub dt: Option<Spanned<f64>>,
    /// Relative tolerance, for adaptive methods.
    #[serde(default)]
    pub rtol: Option<Spanned<f64>>,
    /// Absolute tolerance, for adaptive methods.
    #[serde(default)]
    pub atol: Option<Spanned<f64>>,
    /// Largest step (s), for adaptive methods.
    #[serde(default)]
    pub max_step: Option<Spanned<f64>>,
    /// Stages of `gauss`: 1 (implicit midpoint) or 2 (default).
    #[serde(default)]
    pub stages: Option<Spanned<u32>>,
    /// Order of `splitting`: 2 (Strang) or 4 (default).
    #[serde(default)]
    pub order: Option<Spanned<u32>>,
}

/// The method the file and the options name, before `auto` is resolved.
pub(super) struct MethodChoice {
    /// The method (dop853 stands in for `auto` until the spacecraft is built).
    pub method: Method,
    /// `auto` was asked for.
    pub auto: bool,
    /// The tolerances an adaptive method (or `auto`'s choice) uses.
    pub adaptive: Adaptive,
    /// Where the method was named: its line and column in the file, or none for `--method`.
    pub location: Option<(u32, u32)>,
    /// `integrator.method` or `--method`.
    pub field: &'static str,
}

/// Where a value came from: a command-line option (no line; the option is named) or the file
/// (its line and field).
pub(super) fn from(
    option: Option<f64>,
    l: Option<(u32, u32)>,
    field: &'static str,
    flag: &'static str,
) -> (Option<(u32, u32)>, &'static str) {
    if option.is_some() {
        (None, flag)
    } else {
        (l, field)
    }
}

impl IntegratorSpec {
    /// Checks the settings (with the overrides `ov`) for a run of `duration` (s; written at
    /// `file_duration_loc`) from rates `omega0` (rad/s), and names the method.
    pub(super) fn method(
        &self,
        path: &Path,
        ov: &Overrides,
        (duration, file_duration_loc): (f64, Option<(u32, u32)>),
        omega0: &Vector3<f64>,
        output: &Option<OutputSpec>,
    ) -> Result<MethodChoice, ScenarioError> {
        let spec = self;
        let err = |l: Option<(u32, u32)>, field: &str, msg: String| {
            ScenarioError::at(path, l, field, msg)
        };
        let method_loc = spec.method.as_ref().and_then(loc);
        let method_name = ov
            .method
            .clone()
            .or(spec.method.as_ref().map(|m| m.value.clone()))
            .unwrap_or_else(|| "dopri5".into());
        let positive = |v: Option<f64>,
                        s: &Option<Spanned<f64>>,
                        field: &'static str,
                        flag: &'static str,
                        what: &str| {
            match v.or(s.as_ref().map(|x| x.value)) {
                None => Ok(None),
                Some(x) if x.is_finite() && x > 0.0 => Ok(Some(x)),
                Some(x) => {
                    let (l, f) = from(v, s.as_ref().and_then(loc), field, flag);
                    Err(err(
                        l,
                        f,
                        format!("expected a positive, finite {what}, got {x}"),
                    ))
                }
            }
        };
        let dt = positive(ov.dt, &spec.dt, "integrator.dt", "--dt", "step in seconds")?;
        let rtol = positive(
            ov.rtol,
            &spec.rtol,
            "integrator.rtol",
            "--rtol",
            "relative tolerance",
        )?;
        let atol = positive(
            ov.atol,
            &spec.atol,
            "integrator.atol",
            "--atol",
            "absolute tolerance",
        )?;
        let max_step = positive(
            None,
            &spec.max_step,
            "integrator.max_step",
            "integrator.max_step",
            "step in seconds",
        )?;
        let (method_field, method_l) = if ov.method.is_some() {
            ("--method", None)
        } else {
            ("integrator.method", method_loc)
        };
        let need_dt = |name: &str| {
            dt.ok_or_else(|| {
                err(
                    method_l,
                    "integrator.dt",
                    format!("{name} has a fixed step: expected `dt: <seconds>` (or --dt)"),
                )
            })
        };
        let adaptive = Adaptive {
            rtol: rtol.unwrap_or(1e-10),
            atol: atol.unwrap_or(1e-12),
            max_step: max_step.unwrap_or(f64::INFINITY),
        };
        let choice = |v: Option<u32>,
                      s: &Option<Spanned<u32>>,
                      field: &'static str,
                      flag: &'static str,
                      allowed: [u32; 2],
                      default: u32| {
            let x = v.or(s.as_ref().map(|x| x.value)).unwrap_or(default);
            if allowed.contains(&x) {
                Ok(x as u8)
            } else {
                let (l, f) = from(v.map(f64::from), s.as_ref().and_then(loc), field, flag);
                Err(err(
                    l,
                    f,
                    format!("expected {} or {}, got {x}", allowed[0], allowed[1]),
                ))
            }
        };
        let stages = choice(
            ov.stages,
            &spec.stages,
            "integrator.stages",
            "--stages",
            [1, 2],
            2,
        )?;
        let order = choice(
            ov.order,
            &spec.order,
            "integrator.order",
            "--order",
            [2, 4],
            4,
        )?;
        // Settings of one method given to another are mistakes, not no-ops.
        for (given, flag, field, owner) in [
            (
                ov.stages.is_some() || spec.stages.is_some(),
                ov.stages.is_some(),
                "stages",
                "gauss",
            ),
            (
                ov.order.is_some() || spec.order.is_some(),
                ov.order.is_some(),
                "order",
                "splitting",
            ),
        ] {
            if given && method_name != owner {
                let l = if flag {
                    None
                } else if field == "stages" {
                    spec.stages.as_ref().and_then(loc)
                } else {
                    spec.order.as_ref().and_then(loc)
                };
                let f = match (flag, field) {
                    (true, "stages") => "--stages",
                    (true, _) => "--order",
                    (false, "stages") => "integrator.stages",
                    (false, _) => "integrator.order",
                };
                return Err(err(
                    l,
                    f,
                    format!(
                        "`{field}` applies to method `{owner}` only, and the method is \
                             `{method_name}`"
                    ),
                ));
            }
        }
        let mut auto = false;
        let method = match method_name.as_str() {
            "rk4" => Method::Rk4 {
                dt: need_dt("rk4")?,
            },
            "dopri5" => Method::Dopri5(adaptive),
            "dop853" => Method::Dop853(adaptive),
            "radau5" => Method::Radau5(adaptive),
            "gauss" => Method::Gauss {
                dt: need_dt("gauss")?,
                stages,
            },
            "lie" => Method::Lie {
                dt: need_dt("lie")?,
            },
            "splitting" => Method::Splitting {
                dt: need_dt("splitting")?,
                order,
            },
            "exact" => Method::Exact,
            "averaged" => Method::Averaged(adaptive),
            "auto" => {
                // Resolved once the spacecraft is built; dop853 stands in for the checks.
                auto = true;
                Method::Dop853(adaptive)
            }
            other => {
                let hint = nearest(other, Method::NAMES)
                    .map(|b| format!("; did you mean `{b}`?"))
                    .unwrap_or_default();
                return Err(err(
                    method_l,
                    method_field,
                    format!(
                        "unknown method `{other}`, expected one of {}{hint}",
                        Method::NAMES.join(", ")
                    ),
                ));
            }
        };
        if let Some(dt) = method.fixed_step()
            && duration / dt > 1e11
        {
            let (l, f) = if ov.dt.is_some() || ov.duration.is_some() {
                (None, "--dt / --duration")
            } else {
                (spec.dt.as_ref().and_then(loc), "integrator.dt")
            };
            return Err(err(
                l,
                f,
                format!(
                    "{:.1e} steps of {dt:e} s over {duration:e} s is too many (limit 1e11)",
                    duration / dt
                ),
            ));
        }
        // Bound the work a valid-looking file can ask for.
        let max_steps = match method {
            Method::Exact => duration * output_rate_hint(output).max(4.0 * omega0.norm()),
            m => m.adaptive().map_or(0.0, |a| duration / a.max_step),
        };
        if max_steps > 1e11 {
            let (l, f) = match (&spec.max_step, ov.duration) {
                (Some(m), _) => (loc(m), "integrator.max_step"),
                (None, Some(_)) => (None, "--duration"),
                (None, None) => (file_duration_loc, "duration"),
            };
            return Err(err(
                l,
                f,
                format!(
                    "the run would need at least {max_steps:.1e} steps; the limit is 1e11 \
                         (a larger max_step, or a shorter duration)"
                ),
            ));
        }
        if let Some(Adaptive { rtol, .. }) = method.adaptive()
            && rtol < 1e-15
        {
            let (l, f) = from(
                ov.rtol,
                spec.rtol.as_ref().and_then(loc),
                "integrator.rtol",
                "--rtol",
            );
            return Err(err(
                l,
                f,
                format!("rtol {rtol:e} is below double precision; use at least 1e-15"),
            ));
        }

        if let Some(Adaptive { atol, .. }) = method.adaptive()
            && atol < MIN_ATOL
        {
            let (l, f) = from(
                ov.atol,
                spec.atol.as_ref().and_then(loc),
                "integrator.atol",
                "--atol",
            );
            return Err(err(
                l,
                f,
                format!(
                    "atol {atol:e} is below {MIN_ATOL:e}: the error of a component near zero, \
                         divided by it, overflows; use at least {MIN_ATOL:e}"
                ),
            ));
        }
        Ok(MethodChoice {
            method,
            auto,
            adaptive,
            location: method_l,
            field: method_field,
        })
    }
}
