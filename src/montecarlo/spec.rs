//! The `montecarlo:` block as written in YAML, and its validation into a [`Campaign`]
//! (documented in `docs/montecarlo.md`).

use super::dispersion::{Dispersion, Distribution, PathTarget, Target, resolve_path};
use crate::log::telemetry::FIELDS;
use crate::scenario::campaign::{AngleFile, CampaignFile, DispersionFile, OneOrMany};
use crate::scenario::{ScenarioError, loc};
use serde_json::Value;
use serde_saphyr::Spanned;
use std::path::Path;

/// Most runs one campaign may ask for: the per-run table is held in memory, about 2 kB a run at
/// its peak (20 GB for this many).
pub const MAX_RUNS: u64 = 10_000_000;

/// A validated campaign.
#[derive(Debug, Clone)]
pub struct Campaign {
    /// Number of runs.
    pub runs: u64,
    /// Seed.
    pub seed: u64,
    /// Perturbations, in order of drawing.
    pub dispersions: Vec<Dispersion>,
    /// Times (s) of the event probabilities.
    pub probability_by: Vec<f64>,
    /// Indices into [`FIELDS`] recorded at the end.
    pub final_telemetry: Vec<usize>,
}

impl Campaign {
    /// Checks `file` against the scenario's YAML tree `tree` (paths must name numbers).
    pub fn new(
        path: &Path,
        file: &CampaignFile,
        tree: &Value,
        duration: f64,
    ) -> Result<Self, ScenarioError> {
        let err = |l, field: &str, msg: String| ScenarioError::at(path, l, field, msg);
        let runs = file.runs.value;
        if runs == 0 || runs > MAX_RUNS {
            return Err(err(
                loc(&file.runs),
                "montecarlo.runs",
                format!("expected a number of runs from 1 to {MAX_RUNS}, got {runs}"),
            ));
        }
        let mut dispersions = Vec::new();
        for (k, d) in file.dispersions.iter().enumerate() {
            let field = format!("montecarlo.dispersions[{k}]");
            dispersions.push(dispersion(path, &field, d, tree)?);
        }
        let mut probability_by = Vec::new();
        for (k, t) in file.probability_by.iter().enumerate() {
            if !(t.value.is_finite() && t.value > 0.0) {
                return Err(err(
                    loc(t),
                    &format!("montecarlo.probability_by[{k}]"),
                    format!("expected a positive time in seconds, got {}", t.value),
                ));
            }
            probability_by.push(t.value);
        }
        if probability_by.is_empty() {
            probability_by.push(duration);
        }
        let mut final_telemetry = Vec::new();
        for (k, name) in file.final_telemetry.iter().enumerate() {
            match FIELDS.iter().position(|f| *f == name.value) {
                Some(i) => final_telemetry.push(i),
                None => {
                    let hint = crate::scenario::nearest(&name.value, FIELDS.iter().copied())
                        .map(|b| format!("; did you mean `{b}`?"))
                        .unwrap_or_default();
                    return Err(err(
                        loc(name),
                        &format!("montecarlo.final_telemetry[{k}]"),
                        format!(
                            "unknown telemetry field `{}`{hint} (the fields are listed in \
                             docs/logs.md)",
                            name.value
                        ),
                    ));
                }
            }
        }
        Ok(Campaign {
            runs,
            seed: file.seed.as_ref().map_or(0, |s| s.value),
            dispersions,
            probability_by,
            final_telemetry,
        })
    }
}

fn dispersion(
    path: &Path,
    field: &str,
    d: &Spanned<DispersionFile>,
    tree: &Value,
) -> Result<Dispersion, ScenarioError> {
    let at = loc(d);
    let err = |msg: String| ScenarioError::at(path, at, field, msg);
    let f = &d.value;
    let given: Vec<&str> = [
        ("normal", f.normal.is_some()),
        ("uniform", f.uniform.is_some()),
        ("truncated_normal", f.truncated_normal.is_some()),
        ("log_normal", f.log_normal.is_some()),
        ("tilt", f.tilt.is_some()),
        ("attitude", f.attitude.is_some()),
        ("inertia", f.inertia.is_some()),
    ]
    .into_iter()
    .filter_map(|(n, g)| g.then_some(n))
    .collect();
    if given.len() != 1 {
        return Err(err(format!(
            "expected exactly one of `normal`, `uniform`, `truncated_normal`, `log_normal`, \
             `tilt` (each with `path`), `attitude` or `inertia`; got {}",
            if given.is_empty() {
                "none".to_string()
            } else {
                given.join(", ")
            }
        )));
    }
    let angle = |a: &AngleFile, what: &str| {
        if a.sd_deg.is_finite() && a.sd_deg >= 0.0 && a.sd_deg <= 30.0 {
            Ok(a.sd_deg.to_radians())
        } else {
            Err(err(format!(
                "{what}.sd_deg: expected a standard deviation from 0 to 30 degrees (a small \
                 rotation), got {}",
                a.sd_deg
            )))
        }
    };
    if let Some(a) = &f.attitude {
        if f.path.is_some() {
            return Err(err(
                "`attitude` acts on `initial.attitude`; remove `path`".into()
            ));
        }
        return Ok(Dispersion {
            label: "attitude".into(),
            target: Target::Attitude,
            distribution: Distribution::Rotation {
                sd: angle(a, "attitude")?,
            },
            at,
        });
    }
    if let Some(i) = &f.inertia {
        if f.path.is_some() {
            return Err(err("`inertia` acts on `body`; remove `path`".into()));
        }
        if !(i.sd.is_finite() && (0.0..=0.3).contains(&i.sd)) {
            return Err(err(format!(
                "inertia.sd: expected a relative standard deviation from 0 to 0.3, got {}",
                i.sd
            )));
        }
        let axes = angle(
            &AngleFile {
                sd_deg: i.axes_sd_deg,
            },
            "inertia.axes",
        )?;
        if tree.pointer("/body/principal").is_none() && tree.pointer("/body/inertia").is_none() {
            return Err(err(
                "`inertia` needs `body.principal` or `body.inertia` in the scenario".into(),
            ));
        }
        return Ok(Dispersion {
            label: "inertia".into(),
            target: Target::Inertia,
            distribution: Distribution::Inertia { sd: i.sd, axes },
            at,
        });
    }
    let Some(p) = &f.path else {
        return Err(err(format!(
            "`{}` needs `path`: the field it perturbs",
            given[0]
        )));
    };
    let target: PathTarget = resolve_path(&p.value, tree)
        .map_err(|m| ScenarioError::at(path, loc(p), format!("{field}.path"), m))?;
    let n = target.len;
    let vector = |v: &OneOrMany, what: &str| -> Result<Vec<f64>, ScenarioError> {
        let values = match v {
            OneOrMany::One(x) => vec![*x; n],
            OneOrMany::Many(xs) if xs.len() == n => xs.clone(),
            OneOrMany::Many(xs) => {
                return Err(err(format!(
                    "{what}: expected one number or {n} (one per component of `{}`), got {}",
                    p.value,
                    xs.len()
                )));
            }
        };
        if values.iter().all(|x| x.is_finite()) {
            Ok(values)
        } else {
            Err(err(format!("{what}: expected finite numbers")))
        }
    };
    let non_negative = |v: Vec<f64>, what: &str| {
        if v.iter().all(|x| *x >= 0.0) {
            Ok(v)
        } else {
            Err(err(format!("{what}: expected values ≥ 0")))
        }
    };
    let distribution = if let Some(g) = &f.normal {
        Distribution::Normal {
            sd: non_negative(vector(&g.sd, "normal.sd")?, "normal.sd")?,
            mean: match &g.mean {
                Some(m) => vector(m, "normal.mean")?,
                None => vec![0.0; n],
            },
            relative: g.relative,
        }
    } else if let Some(u) = &f.uniform {
        match (&u.half_width, &u.min, &u.max) {
            (Some(h), None, None) => Distribution::UniformAbout {
                half_width: non_negative(vector(h, "uniform.half_width")?, "uniform.half_width")?,
                relative: u.relative,
            },
            (None, Some(lo), Some(hi)) => {
                if u.relative {
                    return Err(err(
                        "uniform: `relative` applies to `half_width`; `min` and `max` are \
                         absolute values"
                            .into(),
                    ));
                }
                let (lo, hi) = (vector(lo, "uniform.min")?, vector(hi, "uniform.max")?);
                if lo.iter().zip(&hi).any(|(a, b)| a > b) {
                    return Err(err("uniform: expected min ≤ max".into()));
                }
                Distribution::UniformBetween { lo, hi }
            }
            _ => {
                return Err(err(
                    "uniform: expected either `half_width` or both `min` and `max`".into(),
                ));
            }
        }
    } else if let Some(t) = &f.truncated_normal {
        let sd = non_negative(vector(&t.sd, "truncated_normal.sd")?, "truncated_normal.sd")?;
        let lo = match &t.min {
            Some(v) => vector(v, "truncated_normal.min")?,
            None => vec![f64::NEG_INFINITY; n],
        };
        let hi = match &t.max {
            Some(v) => vector(v, "truncated_normal.max")?,
            None => vec![f64::INFINITY; n],
        };
        let nominal = target.nominal(tree);
        for j in 0..n {
            let s = if t.relative {
                sd[j] * nominal[j].abs()
            } else {
                sd[j]
            };
            let (a, b) = ((lo[j] - nominal[j]) / s, (hi[j] - nominal[j]) / s);
            let mass = super::dispersion::normal_mass(a, b);
            if lo[j] >= hi[j] || (s > 0.0 && mass < 1e-3) || (s == 0.0 && (a > 0.0 || b < 0.0)) {
                return Err(err(format!(
                    "truncated_normal: the bounds [{}, {}] keep too little of the distribution \
                     about the nominal value {} (component {j}); expected bounds around the \
                     nominal value",
                    lo[j], hi[j], nominal[j]
                )));
            }
        }
        Distribution::TruncatedNormal {
            sd,
            lo,
            hi,
            relative: t.relative,
        }
    } else if let Some(l) = &f.log_normal {
        Distribution::LogNormal {
            sigma: non_negative(vector(&l.sigma, "log_normal.sigma")?, "log_normal.sigma")?,
        }
    } else if let Some(a) = &f.tilt {
        if n != 3 {
            return Err(err(format!(
                "tilt: expected a 3-vector field; `{}` has {n} component(s)",
                p.value
            )));
        }
        Distribution::Tilt {
            sd: angle(a, "tilt")?,
        }
    } else {
        return Err(err("expected a distribution".into()));
    };
    Ok(Dispersion {
        label: p.value.trim().to_string(),
        target: Target::Path(target),
        distribution,
        at: loc(p),
    })
}
