//! What a run checks at every step, and what it does when a check fails.

/// What the run does when a check fails: an invariant drifts beyond its bound, or an
/// effector leaves the range its model holds in.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum OnBreach {
    /// End the run as failed (the log up to there is kept, marked partial).
    #[default]
    Stop,
    /// Print and log a warning once per invariant, and go on.
    Warn,
}

/// Bounds on invariant drift checked after every step (`checks:`); `None` is unchecked.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct DriftLimits {
    /// Relative angular-momentum drift bound.
    pub momentum: Option<f64>,
    /// Relative energy-balance drift bound.
    pub energy: Option<f64>,
    /// Bound on ||q| − 1|.
    pub quaternion_norm: Option<f64>,
    /// Stop or warn on drift.
    pub on_drift: OnBreach,
    /// Stop or warn when a model leaves its validity range.
    pub on_validity: OnBreach,
}
