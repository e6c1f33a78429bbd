//! Dispersions: where a perturbation acts in the scenario's YAML tree and how it is drawn.
//!
//! Each run starts from the scenario's tree (the YAML as a JSON value), applies every
//! dispersion in order with draws from its own random stream, and is then loaded like any
//! scenario file, so every numeric field can be perturbed and every perturbed scenario is
//! validated exactly as a hand-written one would be.

use super::covariance;
use super::second_moments::SecondMoments;
use nalgebra::{Matrix3, SymmetricEigen, UnitQuaternion, Vector3};
use rand::{Rng, RngExt};
use rand_distr::{Distribution as _, StandardNormal};
use serde_json::{Value, json};

/// Most redraws of an inertia dispersion before the run is given up as invalid.
pub const MAX_INERTIA_REDRAWS: u32 = 1000;

/// One perturbation.
#[derive(Debug, Clone)]
pub struct Dispersion {
    /// The path as written (the paths joined by `, `), or `attitude` / `inertia` /
    /// `physical_inertia`.
    pub label: String,
    /// Where it acts.
    pub target: Target,
    /// How it is drawn.
    pub distribution: Distribution,
    /// Line and column of its entry in the scenario file.
    pub at: Option<(u32, u32)>,
}

/// Where a dispersion acts.
#[derive(Debug, Clone)]
pub enum Target {
    /// A numeric field or list of numbers.
    Path(PathTarget),
    /// Several fields drawn together: one shared draw, or one draw from a covariance of all
    /// their components (each with its path as written).
    Paths(Vec<(String, PathTarget)>),
    /// `initial.attitude`.
    Attitude,
    /// `body.principal` / `body.inertia`.
    Inertia,
}

/// A resolved path: a JSON pointer into the tree and the number of components.
#[derive(Debug, Clone)]
pub struct PathTarget {
    /// JSON pointer (RFC 6901) of the value.
    pub pointer: String,
    /// Number of components (1 for a scalar).
    pub len: usize,
    /// Whether the value is a list (column names get `[j]`).
    pub is_list: bool,
}

impl PathTarget {
    /// The nominal components in `tree`.
    pub fn nominal(&self, tree: &Value) -> Vec<f64> {
        match tree.pointer(&self.pointer) {
            Some(Value::Array(a)) => a.iter().map(|v| v.as_f64().unwrap_or(f64::NAN)).collect(),
            Some(v) => vec![v.as_f64().unwrap_or(f64::NAN)],
            None => vec![f64::NAN; self.len],
        }
    }
}

/// How a dispersion is drawn (per component unless stated; `z` is a standard normal draw).
#[derive(Debug, Clone)]
pub enum Distribution {
    /// x = x₀ + mean + sd·z (times x₀ if relative).
    Normal {
        /// Standard deviation.
        sd: Vec<f64>,
        /// Offset of the mean.
        mean: Vec<f64>,
        /// `sd`, `mean` are fractions of x₀.
        relative: bool,
    },
    /// x = x₀ + U(−w, w) (w times |x₀| if relative).
    UniformAbout {
        /// Half width.
        half_width: Vec<f64>,
        /// `half_width` is a fraction of |x₀|.
        relative: bool,
    },
    /// x = U(lo, hi).
    UniformBetween {
        /// Lower bounds.
        lo: Vec<f64>,
        /// Upper bounds.
        hi: Vec<f64>,
    },
    /// x = x₀ + sd·z conditioned on lo ≤ x ≤ hi.
    TruncatedNormal {
        /// Standard deviation before truncation.
        sd: Vec<f64>,
        /// Lower bounds (absolute).
        lo: Vec<f64>,
        /// Upper bounds (absolute).
        hi: Vec<f64>,
        /// `sd` is a fraction of |x₀|.
        relative: bool,
    },
    /// x = x₀·exp(σ z).
    LogNormal {
        /// σ of the logarithm.
        sigma: Vec<f64>,
    },
    /// A 3-vector rotated about a random axis perpendicular to it; the rotation vector's two
    /// components are N(0, sd²) (rad), so the tilt angle is Rayleigh with scale `sd`.
    Tilt {
        /// Standard deviation of each component (rad).
        sd: f64,
    },
    /// q = q₀ ⊗ Exp(θ), θ ~ N(0, sd² I₃) in body axes (rad).
    Rotation {
        /// Standard deviation of each component (rad).
        sd: f64,
    },
    /// Principal moments Iₖ(1 + sd zₖ), axes rotated by Exp(θ), θ ~ N(0, axes² I₃); draws
    /// that are not positive or break a triangle inequality are redrawn and counted (with
    /// `redraw`; otherwise the first such draw makes the run invalid).
    Inertia {
        /// Relative standard deviation of each moment.
        sd: f64,
        /// Standard deviation of each rotation-vector component (rad).
        axes: f64,
        /// Redraw unphysical moments (the campaign's `invalid_draws: redraw`).
        redraw: bool,
    },
    /// Principal moments drawn through the second moments of mass (physical by
    /// construction; equal moments share one draw with `keep_symmetry`), axes rotated by
    /// Exp(θ), θ ~ N(0, axes² I₃).
    PhysicalInertia {
        /// Relative standard deviation of each principal moment, in `body.principal` order.
        sd: [f64; 3],
        /// Standard deviation of each rotation-vector component (rad).
        axes: f64,
        /// Equal moments stay equal.
        keep_symmetry: bool,
    },
    /// x = x₀ + mean + L z over all the components of the paths together (times |x₀| if
    /// relative), z standard normal, L Lᵀ the covariance.
    Correlated {
        /// Lower-triangular factor of the covariance.
        factor: Vec<Vec<f64>>,
        /// Offset of the mean, per component.
        mean: Vec<f64>,
        /// `mean` and the covariance are in fractions of |x₀|.
        relative: bool,
    },
}

impl Dispersion {
    /// Names of the columns this dispersion records, one value each per run.
    pub fn columns(&self) -> Vec<String> {
        match &self.target {
            Target::Path(p) if p.is_list => {
                (0..p.len).map(|j| format!("{}[{j}]", self.label)).collect()
            }
            Target::Path(_) => vec![self.label.clone()],
            Target::Paths(list) => list
                .iter()
                .flat_map(|(label, p)| {
                    if p.is_list {
                        (0..p.len).map(|j| format!("{label}[{j}]")).collect()
                    } else {
                        vec![label.clone()]
                    }
                })
                .collect(),
            Target::Attitude => vec!["attitude_rotation_deg".into()],
            Target::Inertia
                if matches!(self.distribution, Distribution::PhysicalInertia { .. }) =>
            {
                vec![
                    "inertia_moment_1".into(),
                    "inertia_moment_2".into(),
                    "inertia_moment_3".into(),
                    "inertia_axes_rotation_deg".into(),
                ]
            }
            Target::Inertia => vec![
                "inertia_moment_1".into(),
                "inertia_moment_2".into(),
                "inertia_moment_3".into(),
                "inertia_axes_rotation_deg".into(),
                "inertia_redraws".into(),
            ],
        }
    }

    /// The position among [`Dispersion::columns`] of the column that counts this
    /// dispersion's own redraws (`inertia_redraws`), if it has one.
    pub fn redraw_column(&self) -> Option<usize> {
        matches!(self.distribution, Distribution::Inertia { .. }).then_some(4)
    }

    /// The fields this dispersion writes, with their paths as written (none for `attitude`
    /// and the inertia dispersions, whose targets are fixed).
    pub fn path_targets(&self) -> Vec<(&str, &PathTarget)> {
        match &self.target {
            Target::Path(p) => vec![(self.label.as_str(), p)],
            Target::Paths(list) => list.iter().map(|(l, p)| (l.as_str(), p)).collect(),
            Target::Attitude | Target::Inertia => Vec::new(),
        }
    }

    /// Draws from `rng`, writes the perturbed value into `tree` and appends the recorded
    /// values to `record` (as many as [`Dispersion::columns`]). `Err` says why the draw
    /// could not be made physical.
    pub fn apply<R: Rng + ?Sized>(
        &self,
        tree: &mut Value,
        rng: &mut R,
        record: &mut Vec<f64>,
    ) -> Result<(), String> {
        match (&self.target, &self.distribution) {
            (Target::Path(p), d) => {
                let x0 = p.nominal(tree);
                let x = draw(d, &x0, rng)?;
                record.extend_from_slice(&x);
                write_path(tree, &self.label, p, &x)
            }
            (Target::Paths(list), d) => {
                let x0: Vec<Vec<f64>> = list.iter().map(|(_, p)| p.nominal(tree)).collect();
                let drawn: Vec<Vec<f64>> = match d {
                    Distribution::Correlated {
                        factor,
                        mean,
                        relative,
                    } => {
                        let z: Vec<f64> = (0..factor.len()).map(|_| gauss(rng)).collect();
                        let y = covariance::correlate(factor, &z);
                        let mut k = 0;
                        x0.iter()
                            .map(|x0| {
                                x0.iter()
                                    .map(|x| {
                                        let scale = if *relative { x.abs() } else { 1.0 };
                                        let v = x + scale * (mean[k] + y[k]);
                                        k += 1;
                                        v
                                    })
                                    .collect()
                            })
                            .collect()
                    }
                    _ => {
                        // One draw shared by every path: the same variates, each path about
                        // its own nominal value.
                        let u = variates(d, list[0].1.len, rng)?;
                        x0.iter()
                            .map(|x0| transform(d, x0, &u))
                            .collect::<Result<_, _>>()?
                    }
                };
                for x in &drawn {
                    record.extend_from_slice(x);
                }
                for ((label, p), x) in list.iter().zip(&drawn) {
                    write_path(tree, label, p, x)?;
                }
                Ok(())
            }
            (Target::Attitude, Distribution::Rotation { sd }) => {
                let q0 = attitude(tree);
                let theta = Vector3::from_fn(|_, _| sd * gauss(rng));
                let q = q0 * UnitQuaternion::from_scaled_axis(theta);
                record.push(theta.norm().to_degrees());
                let initial = tree
                    .as_object_mut()
                    .and_then(|m| m.get_mut("initial"))
                    .and_then(|v| v.as_object_mut())
                    .ok_or("the scenario has no `initial` mapping")?;
                initial.insert(
                    "attitude".into(),
                    json!({"w": q.w, "x": q.i, "y": q.j, "z": q.k}),
                );
                Ok(())
            }
            (Target::Inertia, Distribution::Inertia { sd, axes, redraw }) => {
                let (moments, frame, _) = principal(tree)?;
                let mut redraws = 0u32;
                let drawn = loop {
                    let m = Vector3::from_fn(|k, _| moments[k] * (1.0 + sd * gauss(rng)));
                    if physical(&m) {
                        break m;
                    }
                    if !redraw {
                        record.extend_from_slice(&[m[0], m[1], m[2]]);
                        return Err(format!(
                            "inertia: the drawn moments [{}, {}, {}] are not a physical body \
                             (a moment is not positive or exceeds the sum of the other two)",
                            m[0], m[1], m[2]
                        ));
                    }
                    redraws += 1;
                    if redraws >= MAX_INERTIA_REDRAWS {
                        return Err(format!(
                            "inertia: {MAX_INERTIA_REDRAWS} draws in a row broke the triangle \
                             inequalities; reduce `inertia.sd`"
                        ));
                    }
                };
                let theta = Vector3::from_fn(|_, _| axes * gauss(rng));
                record.extend_from_slice(&[
                    drawn[0],
                    drawn[1],
                    drawn[2],
                    theta.norm().to_degrees(),
                    f64::from(redraws),
                ]);
                write_inertia(tree, &drawn, &frame, &theta, false)
            }
            (
                Target::Inertia,
                Distribution::PhysicalInertia {
                    sd,
                    axes,
                    keep_symmetry,
                },
            ) => {
                let (moments, frame, principal_given) = principal(tree)?;
                let z = [gauss(rng), gauss(rng), gauss(rng)];
                let theta = Vector3::from_fn(|_, _| axes * gauss(rng));
                let draw = SecondMoments::new(moments.into(), *sd, *keep_symmetry)
                    .map_err(|e| format!("physical_inertia: {e}"))?;
                let drawn = Vector3::from(draw.draw(&z));
                record.extend_from_slice(&[
                    drawn[0],
                    drawn[1],
                    drawn[2],
                    theta.norm().to_degrees(),
                ]);
                // Without a rotation, moments written as `body.principal` stay principal
                // moments exactly (models that need principal axes accept them).
                let keep_principal = principal_given && *axes == 0.0;
                write_inertia(tree, &drawn, &frame, &theta, keep_principal)
            }
            _ => Err(format!(
                "`{}`: target and distribution do not match",
                self.label
            )),
        }
    }
}

/// Writes the drawn components `x` of the field `p` (written `label`) into `tree`.
fn write_path(tree: &mut Value, label: &str, p: &PathTarget, x: &[f64]) -> Result<(), String> {
    if x.iter().any(|v| !v.is_finite()) {
        return Err(format!("`{label}`: the draw is not finite"));
    }
    let value = if p.is_list {
        Value::Array(x.iter().map(|v| json!(v)).collect())
    } else {
        json!(x[0])
    };
    match tree.pointer_mut(&p.pointer) {
        Some(slot) => {
            *slot = value;
            Ok(())
        }
        None => Err(format!("`{label}` is missing from the scenario")),
    }
}

/// Writes the hub's principal moments `moments` (kg m²) with axes `frame` (columns) turned by
/// Exp(`theta`): as `body.principal` when `as_principal` (the frame is then the identity and
/// `theta` zero), else as the tensor `body.inertia`.
fn write_inertia(
    tree: &mut Value,
    moments: &Vector3<f64>,
    frame: &Matrix3<f64>,
    theta: &Vector3<f64>,
    as_principal: bool,
) -> Result<(), String> {
    let body = tree
        .as_object_mut()
        .and_then(|m| m.get_mut("body"))
        .and_then(|v| v.as_object_mut())
        .ok_or("the scenario has no `body` mapping")?;
    if as_principal {
        body.insert(
            "principal".into(),
            json!([moments[0], moments[1], moments[2]]),
        );
        return Ok(());
    }
    let rotation = UnitQuaternion::from_scaled_axis(*theta).to_rotation_matrix();
    let r = rotation.matrix() * frame;
    let j = r * Matrix3::from_diagonal(moments) * r.transpose();
    let j = 0.5 * (j + j.transpose());
    body.remove("principal");
    body.insert(
        "inertia".into(),
        json!([
            [j[(0, 0)], j[(0, 1)], j[(0, 2)]],
            [j[(1, 0)], j[(1, 1)], j[(1, 2)]],
            [j[(2, 0)], j[(2, 1)], j[(2, 2)]]
        ]),
    );
    Ok(())
}

/// One standard normal draw.
pub fn gauss<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    StandardNormal.sample(rng)
}

/// Positive moments satisfying the three triangle inequalities.
fn physical(m: &Vector3<f64>) -> bool {
    m.iter().all(|v| v.is_finite() && *v > 0.0)
        && m[0] + m[1] >= m[2]
        && m[1] + m[2] >= m[0]
        && m[2] + m[0] >= m[1]
}

/// The `n` variates a shareable distribution draws (standard normals for `normal` and
/// `log_normal`, uniforms on [0, 1) for `uniform`), one per component in order.
fn variates<R: Rng + ?Sized>(d: &Distribution, n: usize, rng: &mut R) -> Result<Vec<f64>, String> {
    match d {
        Distribution::Normal { .. } | Distribution::LogNormal { .. } => {
            Ok((0..n).map(|_| gauss(rng)).collect())
        }
        Distribution::UniformAbout { .. } | Distribution::UniformBetween { .. } => {
            Ok((0..n).map(|_| rng.random::<f64>()).collect())
        }
        _ => Err("this distribution cannot share one draw between fields".into()),
    }
}

/// The components drawn about the nominal `x0` from the variates `u` ([`variates`]).
fn transform(d: &Distribution, x0: &[f64], u: &[f64]) -> Result<Vec<f64>, String> {
    let scale = |relative: bool, j: usize| if relative { x0[j].abs() } else { 1.0 };
    let n = x0.len();
    Ok(match d {
        Distribution::Normal { sd, mean, relative } => (0..n)
            .map(|j| x0[j] + scale(*relative, j) * (mean[j] + sd[j] * u[j]))
            .collect(),
        Distribution::UniformAbout {
            half_width,
            relative,
        } => (0..n)
            .map(|j| x0[j] + scale(*relative, j) * half_width[j] * (2.0 * u[j] - 1.0))
            .collect(),
        Distribution::UniformBetween { lo, hi } => {
            (0..n).map(|j| lo[j] + (hi[j] - lo[j]) * u[j]).collect()
        }
        Distribution::LogNormal { sigma } => {
            (0..n).map(|j| x0[j] * (sigma[j] * u[j]).exp()).collect()
        }
        _ => return Err("this distribution cannot share one draw between fields".into()),
    })
}

/// Draws the components of a path dispersion about the nominal `x0`.
fn draw<R: Rng + ?Sized>(d: &Distribution, x0: &[f64], rng: &mut R) -> Result<Vec<f64>, String> {
    let scale = |relative: bool, j: usize| if relative { x0[j].abs() } else { 1.0 };
    Ok(match d {
        Distribution::Normal { .. }
        | Distribution::UniformAbout { .. }
        | Distribution::UniformBetween { .. }
        | Distribution::LogNormal { .. } => {
            let u = variates(d, x0.len(), rng)?;
            transform(d, x0, &u)?
        }
        Distribution::TruncatedNormal {
            sd,
            lo,
            hi,
            relative,
        } => {
            let mut x = Vec::with_capacity(x0.len());
            for j in 0..x0.len() {
                let s = sd[j] * scale(*relative, j);
                let mut tries = 0u32;
                x.push(loop {
                    let v = x0[j] + s * gauss(rng);
                    if lo[j] <= v && v <= hi[j] {
                        break v;
                    }
                    tries += 1;
                    if tries > 1_000_000 {
                        return Err("truncated_normal: no draw fell within the bounds".into());
                    }
                });
            }
            x
        }
        Distribution::Tilt { sd } => {
            let v = Vector3::new(x0[0], x0[1], x0[2]);
            let n = v.norm();
            if n == 0.0 {
                return Err("tilt: the nominal vector is zero and has no direction".into());
            }
            let u = v / n;
            // The basis axis least aligned with u gives a well-conditioned perpendicular.
            let (imin, _) = u.abs().argmin();
            let e1 = u.cross(&Vector3::ith(imin, 1.0)).normalize();
            let e2 = u.cross(&e1);
            let theta = *sd * (gauss(rng) * e1 + gauss(rng) * e2);
            let w = UnitQuaternion::from_scaled_axis(theta) * v;
            vec![w[0], w[1], w[2]]
        }
        Distribution::Correlated {
            factor,
            mean,
            relative,
        } => {
            let z: Vec<f64> = (0..factor.len()).map(|_| gauss(rng)).collect();
            let y = covariance::correlate(factor, &z);
            (0..x0.len())
                .map(|j| x0[j] + scale(*relative, j) * (mean[j] + y[j]))
                .collect()
        }
        Distribution::Rotation { .. }
        | Distribution::Inertia { .. }
        | Distribution::PhysicalInertia { .. } => {
            return Err(
                "this distribution needs `attitude`, `inertia` or `physical_inertia`".into(),
            );
        }
    })
}

/// The nominal initial attitude in `tree` (identity when absent).
fn attitude(tree: &Value) -> UnitQuaternion<f64> {
    let get = |k: &str| {
        tree.pointer(&format!("/initial/attitude/{k}"))
            .and_then(Value::as_f64)
    };
    match (get("w"), get("x"), get("y"), get("z")) {
        (Some(w), Some(x), Some(y), Some(z)) => {
            UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z))
        }
        _ => UnitQuaternion::identity(),
    }
}

/// Nominal principal moments and axes (columns) of the hub in `tree`, and whether they were
/// written as `body.principal` (the axes are then the body axes).
fn principal(tree: &Value) -> Result<(Vector3<f64>, Matrix3<f64>, bool), String> {
    let numbers = |v: &Value| -> Option<Vec<f64>> {
        v.as_array()?
            .iter()
            .map(Value::as_f64)
            .collect::<Option<Vec<f64>>>()
    };
    if let Some(p) = tree.pointer("/body/principal").and_then(numbers)
        && p.len() == 3
    {
        return Ok((Vector3::new(p[0], p[1], p[2]), Matrix3::identity(), true));
    }
    if let Some(rows) = tree.pointer("/body/inertia").and_then(Value::as_array) {
        let mut m = Matrix3::zeros();
        for (r, row) in rows.iter().enumerate().take(3) {
            let row = numbers(row).ok_or("body.inertia: expected rows of numbers")?;
            for (c, v) in row.iter().enumerate().take(3) {
                m[(r, c)] = *v;
            }
        }
        let eig = SymmetricEigen::new(0.5 * (m + m.transpose()));
        return Ok((eig.eigenvalues, eig.eigenvectors, false));
    }
    Err("inertia: the scenario has neither `body.principal` nor `body.inertia`".into())
}

/// Resolves a dotted path (`initial.omega`, `initial.omega[2]`, `effectors[0].damping`,
/// `effectors[antenna].hinged_rod.damping`) to a numeric value of `tree`. A key that an
/// effector entry lacks is looked up inside its one kind mapping, so the kind may be left
/// out; `[name]` selects the list entry with that `name`.
pub fn resolve_path(path: &str, tree: &Value) -> Result<PathTarget, String> {
    let path = path.trim();
    if path.is_empty() {
        return Err("expected a dotted path such as `initial.omega`".into());
    }
    let mut pointer = String::new();
    let mut at = tree;
    let mut walked = String::new();
    for segment in path.split('.') {
        let (key, selectors) = match segment.find('[') {
            Some(i) => (&segment[..i], &segment[i..]),
            None => (segment, ""),
        };
        if !key.is_empty() {
            let Some(map) = at.as_object() else {
                return Err(format!("`{walked}` is not a mapping, so it has no `{key}`"));
            };
            if walked.is_empty() && key == "montecarlo" {
                return Err("the campaign cannot perturb its own `montecarlo` block".into());
            }
            if let Some(v) = map.get(key) {
                push(&mut pointer, key);
                at = v;
            } else if let Some((kind, inner)) = single_entry(map)
                && let Some(v) = inner.get(key)
            {
                push(&mut pointer, kind);
                push(&mut pointer, key);
                at = v;
            } else {
                let mut keys: Vec<&str> = map.keys().map(String::as_str).collect();
                if let Some((_, inner)) = single_entry(map) {
                    keys.extend(inner.keys().map(String::as_str));
                }
                let hint = crate::scenario::nearest(key, keys.iter().copied())
                    .map(|b| format!("; did you mean `{b}`?"))
                    .unwrap_or_default();
                let place = if walked.is_empty() {
                    "the scenario".to_string()
                } else {
                    format!("`{walked}`")
                };
                return Err(format!(
                    "{place} has no field `{key}`{hint} (it has: {})",
                    keys.join(", ")
                ));
            }
        } else if walked.is_empty() {
            return Err(format!("`{path}`: expected a field name before `[`"));
        }
        walked.push_str(if walked.is_empty() { "" } else { "." });
        walked.push_str(key);
        let mut rest = selectors;
        while !rest.is_empty() {
            let Some(close) = rest.find(']') else {
                return Err(format!("`{segment}`: expected `]`"));
            };
            if !rest.starts_with('[') {
                return Err(format!("`{segment}`: expected `[` after `]`"));
            }
            let sel = rest[1..close].trim();
            rest = &rest[close + 1..];
            let Some(list) = at.as_array() else {
                return Err(format!(
                    "`{walked}` is not a list, so `[{sel}]` selects nothing"
                ));
            };
            let index = match sel.parse::<usize>() {
                Ok(i) if i < list.len() => i,
                Ok(i) => {
                    return Err(format!(
                        "`{walked}` has {} entries; index {i} is out of range (indices start at 0)",
                        list.len()
                    ));
                }
                Err(_) => {
                    let names: Vec<&str> = list.iter().filter_map(entry_name).collect();
                    match list.iter().position(|e| entry_name(e) == Some(sel)) {
                        Some(i) => i,
                        None => {
                            return Err(format!(
                                "`{walked}` has no entry named `{sel}` (names: {})",
                                if names.is_empty() {
                                    "none".to_string()
                                } else {
                                    names.join(", ")
                                }
                            ));
                        }
                    }
                }
            };
            pointer.push('/');
            pointer.push_str(&index.to_string());
            walked.push_str(&format!("[{sel}]"));
            at = &list[index];
        }
    }
    match at {
        Value::Number(_) => Ok(PathTarget {
            pointer,
            len: 1,
            is_list: false,
        }),
        Value::Array(a) if !a.is_empty() && a.iter().all(Value::is_number) => Ok(PathTarget {
            pointer,
            len: a.len(),
            is_list: true,
        }),
        _ => Err(format!(
            "`{path}` is not a number or a list of numbers; a dispersion needs a numeric field"
        )),
    }
}

fn push(pointer: &mut String, key: &str) {
    pointer.push('/');
    pointer.push_str(&key.replace('~', "~0").replace('/', "~1"));
}

/// The one `kind: {…}` entry of an effector-style mapping.
fn single_entry(
    map: &serde_json::Map<String, Value>,
) -> Option<(&str, &serde_json::Map<String, Value>)> {
    if map.len() != 1 {
        return None;
    }
    let (k, v) = map.iter().next()?;
    Some((k.as_str(), v.as_object()?))
}

/// The `name` of a list entry, directly or inside its one kind mapping.
fn entry_name(e: &Value) -> Option<&str> {
    let map = e.as_object()?;
    if let Some(n) = map.get("name").and_then(Value::as_str) {
        return Some(n);
    }
    single_entry(map)?.1.get("name")?.as_str()
}

/// Probability mass of the standard normal between `a` and `b` (for the truncation check).
pub fn normal_mass(a: f64, b: f64) -> f64 {
    let cdf = |x: f64| {
        if x == f64::INFINITY {
            1.0
        } else if x == f64::NEG_INFINITY {
            0.0
        } else {
            0.5 * erfc(-x / std::f64::consts::SQRT_2)
        }
    };
    (cdf(b) - cdf(a)).max(0.0)
}

/// Complementary error function, relative error below 1.2e-7 everywhere (the Chebyshev fit
/// of Press et al., Numerical Recipes, 2nd ed., §6.2).
pub fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let r = t * poly.exp();
    if x >= 0.0 { r } else { 2.0 - r }
}
