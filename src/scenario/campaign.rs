//! The `montecarlo:` block as written in YAML (serde types with source spans). The campaign
//! module validates it into a campaign (docs/montecarlo.md); the scenario only carries it.

use serde::Deserialize;
use serde_saphyr::Spanned;

/// `montecarlo:` as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CampaignFile {
    /// Number of runs.
    pub runs: Spanned<u64>,
    /// Seed of the random streams (default 0); run i draws from stream (seed, i).
    #[serde(default)]
    pub seed: Option<Spanned<u64>>,
    /// Perturbations applied to each run, in order.
    #[serde(default)]
    pub dispersions: Vec<Spanned<DispersionFile>>,
    /// Times (s) at which the probability of each event is reported (default: the duration).
    #[serde(default)]
    pub probability_by: Vec<Spanned<f64>>,
    /// Telemetry fields (see `docs/logs.md`) recorded at the end of each run.
    #[serde(default)]
    pub final_telemetry: Vec<Spanned<String>>,
    /// What to do with a draw that is not a valid scenario: `redraw` (default) or `exclude`.
    #[serde(default)]
    pub invalid_draws: Option<Spanned<String>>,
}

/// One entry of `dispersions:`: a `path` and one distribution, or `attitude`, or `inertia`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DispersionFile {
    /// Dotted path of a numeric field or list (`initial.omega`, `effectors[antenna].damping`).
    #[serde(default)]
    pub path: Option<Spanned<String>>,
    /// Several paths sharing one draw (`normal.sd`, `uniform`, `log_normal`) or drawn together
    /// from one covariance (`normal.covariance`).
    #[serde(default)]
    pub paths: Option<Spanned<Vec<Spanned<String>>>>,
    /// Gaussian about the nominal value.
    #[serde(default)]
    pub normal: Option<NormalFile>,
    /// Uniform about the nominal value (`half_width`) or between absolute bounds (`min`, `max`).
    #[serde(default)]
    pub uniform: Option<UniformFile>,
    /// Gaussian about the nominal value, restricted to absolute bounds.
    #[serde(default)]
    pub truncated_normal: Option<TruncatedFile>,
    /// Nominal value times exp(σ z): median at the nominal value, sign kept.
    #[serde(default)]
    pub log_normal: Option<LogNormalFile>,
    /// A 3-vector's direction tilted by a random small angle, its length kept.
    #[serde(default)]
    pub tilt: Option<AngleFile>,
    /// A random small rotation of the initial attitude (no `path`).
    #[serde(default)]
    pub attitude: Option<AngleFile>,
    /// Principal moments and axes of the hub perturbed, kept physical (no `path`).
    #[serde(default)]
    pub inertia: Option<InertiaFile>,
    /// Principal moments drawn through the body's second moments of mass, physical by
    /// construction and keeping equal moments equal (no `path`).
    #[serde(default)]
    pub physical_inertia: Option<PhysicalInertiaFile>,
}

/// A number, or one number per component.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum OneOrMany {
    /// The same for every component.
    One(f64),
    /// One per component.
    Many(Vec<f64>),
}

/// `normal: {sd, mean, relative}` or `normal: {covariance, mean, relative}`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NormalFile {
    /// Standard deviation (field units, or a fraction of the nominal value if `relative`).
    #[serde(default)]
    pub sd: Option<OneOrMany>,
    /// Covariance matrix of all the components of `path`/`paths` together, instead of `sd`
    /// (squared field units, or of fractions of the nominal values if `relative`).
    #[serde(default)]
    pub covariance: Option<Spanned<Vec<Vec<f64>>>>,
    /// Offset of the mean from the nominal value (default 0).
    #[serde(default)]
    pub mean: Option<OneOrMany>,
    /// `sd` and `mean` are fractions of the nominal value.
    #[serde(default)]
    pub relative: bool,
}

/// `uniform: {half_width, relative}` or `uniform: {min, max}`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UniformFile {
    /// Half width about the nominal value.
    #[serde(default)]
    pub half_width: Option<OneOrMany>,
    /// Absolute lower bound (with `max`, instead of `half_width`).
    #[serde(default)]
    pub min: Option<OneOrMany>,
    /// Absolute upper bound.
    #[serde(default)]
    pub max: Option<OneOrMany>,
    /// `half_width` is a fraction of the nominal value.
    #[serde(default)]
    pub relative: bool,
}

/// `truncated_normal: {sd, min, max, relative}`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TruncatedFile {
    /// Standard deviation of the untruncated Gaussian about the nominal value.
    pub sd: OneOrMany,
    /// Absolute lower bound of the value (default none).
    #[serde(default)]
    pub min: Option<OneOrMany>,
    /// Absolute upper bound of the value (default none).
    #[serde(default)]
    pub max: Option<OneOrMany>,
    /// `sd` is a fraction of the nominal value.
    #[serde(default)]
    pub relative: bool,
}

/// `log_normal: {sigma}`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LogNormalFile {
    /// Standard deviation of the logarithm of the factor.
    pub sigma: OneOrMany,
}

/// `{sd_deg}`: a random rotation whose rotation-vector components are Gaussian.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AngleFile {
    /// Standard deviation of each rotation-vector component (degrees).
    pub sd_deg: f64,
}

/// `inertia: {sd, axes_sd_deg}`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InertiaFile {
    /// Relative standard deviation of each principal moment.
    pub sd: f64,
    /// Standard deviation of each component of the principal axes' rotation vector (degrees).
    #[serde(default)]
    pub axes_sd_deg: f64,
}

/// `physical_inertia: {sd, axes_sd_deg, symmetry}`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhysicalInertiaFile {
    /// Relative standard deviation of each principal moment: one number, or one per moment in
    /// the order of `body.principal`.
    pub sd: OneOrMany,
    /// Standard deviation of each component of the principal axes' rotation vector (degrees).
    #[serde(default)]
    pub axes_sd_deg: f64,
    /// `keep` (default): equal principal moments share one draw and stay equal; `break`:
    /// every moment is drawn on its own.
    #[serde(default)]
    pub symmetry: Option<String>,
}
