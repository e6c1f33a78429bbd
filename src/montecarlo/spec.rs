//! The `montecarlo:` block as written in YAML, and its validation into a [`Campaign`]
//! (documented in `docs/montecarlo.md`).

use super::covariance;
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
    /// What is done with a draw that is not a valid scenario.
    pub invalid_draws: InvalidDraws,
}

/// What a campaign does with a draw that is not a valid scenario (`invalid_draws:`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InvalidDraws {
    /// Draw the run again from its own stream, up to [`MAX_DRAWS_PER_RUN`] times, and count
    /// the rejected draws (the `redraws` column).
    Redraw,
    /// Record the run as `invalid` and leave it out of the probabilities, each given with its
    /// range if every excluded run had or had not the event.
    Exclude,
}

impl InvalidDraws {
    /// The name written in the scenario and the summaries.
    pub fn label(self) -> &'static str {
        match self {
            Self::Redraw => "redraw",
            Self::Exclude => "exclude",
        }
    }
}

/// Most draws of one run under `invalid_draws: redraw`; a run with no valid draw among them
/// is recorded `invalid`.
pub const MAX_DRAWS_PER_RUN: u32 = 1000;

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
        let invalid_draws = match &file.invalid_draws {
            None => InvalidDraws::Redraw,
            Some(p) => match p.value.trim() {
                "redraw" => InvalidDraws::Redraw,
                "exclude" => InvalidDraws::Exclude,
                other => {
                    return Err(err(
                        loc(p),
                        "montecarlo.invalid_draws",
                        format!("expected `redraw` or `exclude`, got `{other}`"),
                    ));
                }
            },
        };
        let mut dispersions = Vec::new();
        for (k, d) in file.dispersions.iter().enumerate() {
            let field = format!("montecarlo.dispersions[{k}]");
            let mut d = dispersion(path, &field, d, tree)?;
            if let Distribution::Inertia { redraw, .. } = &mut d.distribution {
                *redraw = invalid_draws == InvalidDraws::Redraw;
            }
            dispersions.push(d);
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
            invalid_draws,
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
        ("physical_inertia", f.physical_inertia.is_some()),
    ]
    .into_iter()
    .filter_map(|(n, g)| g.then_some(n))
    .collect();
    if given.len() != 1 {
        return Err(err(format!(
            "expected exactly one of `normal`, `uniform`, `truncated_normal`, `log_normal`, \
             `tilt` (each with `path`), `attitude`, `inertia` or `physical_inertia`; got {}",
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
    if f.paths.is_some()
        && (f.attitude.is_some() || f.inertia.is_some() || f.physical_inertia.is_some())
    {
        return Err(err(format!(
            "`{}` acts on a fixed field; remove `paths`",
            given[0]
        )));
    }
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
            distribution: Distribution::Inertia {
                sd: i.sd,
                axes,
                redraw: true,
            },
            at,
        });
    }
    if let Some(i) = &f.physical_inertia {
        if f.path.is_some() {
            return Err(err(
                "`physical_inertia` acts on `body`; remove `path`".into()
            ));
        }
        let principal_given = tree.pointer("/body/principal").is_some();
        if !principal_given && tree.pointer("/body/inertia").is_none() {
            return Err(err(
                "`physical_inertia` needs `body.principal` or `body.inertia` in the scenario"
                    .into(),
            ));
        }
        let sd = match &i.sd {
            OneOrMany::One(x) => [*x; 3],
            OneOrMany::Many(v) if v.len() == 3 && principal_given => [v[0], v[1], v[2]],
            OneOrMany::Many(v) if v.len() == 3 => {
                return Err(err(
                    "physical_inertia.sd: one sd per moment follows the order of \
                     `body.principal`; with `body.inertia` give one number"
                        .into(),
                ));
            }
            OneOrMany::Many(v) => {
                return Err(err(format!(
                    "physical_inertia.sd: expected one number or 3 (one per principal moment), \
                     got {}",
                    v.len()
                )));
            }
        };
        if sd
            .iter()
            .any(|s| !(s.is_finite() && (0.0..=0.3).contains(s)))
        {
            return Err(err(format!(
                "physical_inertia.sd: expected relative standard deviations from 0 to 0.3, got \
                 {sd:?}"
            )));
        }
        let keep_symmetry = match i.symmetry.as_deref().map(str::trim) {
            None | Some("keep") => true,
            Some("break") => false,
            Some(other) => {
                return Err(err(format!(
                    "physical_inertia.symmetry: expected `keep` or `break`, got `{other}`"
                )));
            }
        };
        let axes = angle(
            &AngleFile {
                sd_deg: i.axes_sd_deg,
            },
            "physical_inertia.axes",
        )?;
        let distribution = Distribution::PhysicalInertia {
            sd,
            axes,
            keep_symmetry,
        };
        let d = Dispersion {
            label: "physical_inertia".into(),
            target: Target::Inertia,
            distribution,
            at,
        };
        // The nominal body must be drawable (not flat, sds its shape allows).
        let mut probe = tree.clone();
        let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(0);
        d.apply(&mut probe, &mut rng, &mut Vec::new())
            .map_err(err)?;
        return Ok(d);
    }
    if f.path.is_some() && f.paths.is_some() {
        return Err(err(
            "give `path` (one field) or `paths` (several sharing the draw), not both".into(),
        ));
    }
    // The fields: one `path`, or `paths` drawn together.
    let (targets, label, at_path) = match (&f.path, &f.paths) {
        (Some(p), _) => {
            let target: PathTarget = resolve_path(&p.value, tree)
                .map_err(|m| ScenarioError::at(path, loc(p), format!("{field}.path"), m))?;
            (
                vec![(p.value.trim().to_string(), target)],
                p.value.trim().to_string(),
                loc(p),
            )
        }
        (None, Some(list)) => {
            if list.value.is_empty() {
                return Err(ScenarioError::at(
                    path,
                    loc(list),
                    format!("{field}.paths"),
                    "expected a list of dotted paths, got none",
                ));
            }
            let mut targets: Vec<(String, PathTarget)> = Vec::new();
            for (j, p) in list.value.iter().enumerate() {
                let where_ = format!("{field}.paths[{j}]");
                let target = resolve_path(&p.value, tree)
                    .map_err(|m| ScenarioError::at(path, loc(p), where_.clone(), m))?;
                if let Some((other, _)) = targets.iter().find(|(_, t)| t.pointer == target.pointer)
                {
                    return Err(ScenarioError::at(
                        path,
                        loc(p),
                        where_,
                        format!("`{}` names the same field as `{other}`", p.value.trim()),
                    ));
                }
                targets.push((p.value.trim().to_string(), target));
            }
            let label = targets
                .iter()
                .map(|(l, _)| l.as_str())
                .collect::<Vec<_>>()
                .join(", ");
            (targets, label, loc(list))
        }
        (None, None) => {
            return Err(err(format!(
                "`{}` needs `path` (the field it perturbs) or `paths` (several fields sharing \
                 one draw)",
                given[0]
            )));
        }
    };
    let grouped = f.paths.is_some();
    let covariance_given = f.normal.as_ref().is_some_and(|g| g.covariance.is_some());
    if grouped && !covariance_given {
        let n0 = targets[0].1.len;
        if let Some((l, t)) = targets.iter().find(|(_, t)| t.len != n0) {
            return Err(err(format!(
                "paths: one draw is shared by fields of the same size; `{}` has {n0} \
                 component(s) and `{l}` has {}",
                targets[0].0, t.len
            )));
        }
        if f.truncated_normal.is_some() || f.tilt.is_some() {
            return Err(err(format!(
                "`{}` cannot share one draw between fields (it depends on each field's \
                 nominal value); give each its own `path`",
                given[0]
            )));
        }
    }
    let target = targets[0].1.clone();
    let p_value = label.clone();
    // Components per drawn value: one field's under a shared draw, all of them together
    // under a covariance.
    let n = if covariance_given {
        targets.iter().map(|(_, t)| t.len).sum()
    } else {
        target.len
    };
    let vector = |v: &OneOrMany, what: &str| -> Result<Vec<f64>, ScenarioError> {
        let values = match v {
            OneOrMany::One(x) => vec![*x; n],
            OneOrMany::Many(xs) if xs.len() == n => xs.clone(),
            OneOrMany::Many(xs) => {
                return Err(err(format!(
                    "{what}: expected one number or {n} (one per component of `{}`), got {}",
                    p_value,
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
        let mean = match &g.mean {
            Some(m) => vector(m, "normal.mean")?,
            None => vec![0.0; n],
        };
        match (&g.sd, &g.covariance) {
            (Some(sd), None) => Distribution::Normal {
                sd: non_negative(vector(sd, "normal.sd")?, "normal.sd")?,
                mean,
                relative: g.relative,
            },
            (None, Some(c)) => {
                let factor = covariance::factor(&c.value, n).map_err(|e| {
                    ScenarioError::at(
                        path,
                        loc(c),
                        format!("{field}.normal.covariance"),
                        format!("{e} (the components, in order: {})", {
                            let mut names = Vec::new();
                            for (l, t) in &targets {
                                if t.is_list {
                                    names.extend((0..t.len).map(|j| format!("{l}[{j}]")));
                                } else {
                                    names.push(l.clone());
                                }
                            }
                            names.join(", ")
                        }),
                    )
                })?;
                Distribution::Correlated {
                    factor,
                    mean,
                    relative: g.relative,
                }
            }
            (Some(_), Some(_)) => {
                return Err(err(
                    "normal: give `sd` (independent components, or one draw shared by \
                     `paths`) or `covariance` (correlated components), not both"
                        .into(),
                ));
            }
            (None, None) => {
                return Err(err("normal: expected `sd` or `covariance`".into()));
            }
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
                p_value
            )));
        }
        Distribution::Tilt {
            sd: angle(a, "tilt")?,
        }
    } else {
        return Err(err("expected a distribution".into()));
    };
    Ok(Dispersion {
        label,
        target: if grouped {
            Target::Paths(targets)
        } else {
            Target::Path(target)
        },
        distribution,
        at: at_path,
    })
}
