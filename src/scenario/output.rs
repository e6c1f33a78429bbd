//! `output:`: the sampling rate, the log file and its limits, as written and validated.

use super::{DEFAULT_MAX_LOG_MB, MAX_SAMPLES, Overrides, ScenarioError, loc};
use serde::Deserialize;
use serde_saphyr::Spanned;
use std::path::{Path, PathBuf};

/// `output:` sampling and log file.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Samples per second of sim time (Hz).
    #[serde(default)]
    pub rate: Option<Spanned<f64>>,
    /// MCAP path (relative paths are relative to the working directory).
    #[serde(default)]
    pub mcap: Option<Spanned<String>>,
    /// Largest rate of `/scene` updates (Hz, default 10): the body is drawn at every `/tf`
    /// sample through its frame; only the ω and H arrows need scene updates.
    #[serde(default)]
    pub scene_rate: Option<Spanned<f64>>,
    /// Chunk compression: `lz4` (default: fast), `zstd` (smaller, ~2× slower to write) or
    /// `none` (fastest, largest).
    #[serde(default)]
    pub compression: Option<Compression>,
    /// Largest log a run may write (MB = 10⁶ bytes, estimated before the run starts; default
    /// [`DEFAULT_MAX_LOG_MB`]).
    #[serde(default)]
    pub max_log_mb: Option<Spanned<f64>>,
}

/// MCAP chunk compression.
#[derive(Debug, Clone, Copy, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Compression {
    /// LZ4 frames: fast, moderate size.
    #[default]
    Lz4,
    /// Zstandard: smaller files, slower to write.
    Zstd,
    /// Uncompressed chunks.
    None,
}

/// The validated output settings.
pub(super) struct OutputSettings {
    /// Samples per second of sim time (Hz).
    pub output_rate: f64,
    /// Largest rate of `/scene` updates (Hz).
    pub scene_rate: f64,
    /// Where the MCAP log goes.
    pub mcap_path: PathBuf,
    /// Largest log the run may write (MB).
    pub max_log_mb: f64,
}

impl OutputSpec {
    /// Checks the settings (with the overrides `ov`) for the scenario `name`, run for
    /// `duration` (s; written at `file_duration_loc`).
    pub(super) fn settings(
        &self,
        path: &Path,
        ov: &Overrides,
        name: &str,
        (duration, file_duration_loc): (f64, Option<(u32, u32)>),
    ) -> Result<OutputSettings, ScenarioError> {
        let err = |l: Option<(u32, u32)>, field: &str, msg: String| {
            ScenarioError::at(path, l, field, msg)
        };
        let output_rate = match &self.rate {
            None => 100.0,
            Some(r) if r.value.is_finite() && r.value > 0.0 => r.value,
            Some(r) => {
                return Err(err(
                    loc(r),
                    "output.rate",
                    format!(
                        "expected a positive number of samples per second, got {}",
                        r.value
                    ),
                ));
            }
        };
        if duration * output_rate > MAX_SAMPLES {
            let (l, f) = if ov.duration.is_some() {
                (None, "--duration")
            } else {
                (
                    self.rate.as_ref().and_then(loc).or(file_duration_loc),
                    "output.rate",
                )
            };
            return Err(err(
                l,
                f,
                format!(
                    "{:.3e} samples ({duration:e} s at {output_rate:e} Hz) exceed the limit of \
                     {MAX_SAMPLES:e}; lower the rate or the duration",
                    duration * output_rate
                ),
            ));
        }
        let scene_rate = match &self.scene_rate {
            None => 10.0,
            Some(r) if r.value.is_finite() && r.value > 0.0 => r.value,
            Some(r) => {
                return Err(err(
                    loc(r),
                    "output.scene_rate",
                    format!(
                        "expected a positive number of updates per second, got {}",
                        r.value
                    ),
                ));
            }
        };
        let mcap_path = match (&ov.mcap, &self.mcap) {
            (Some(p), _) => p.clone(),
            (None, Some(p)) if !p.value.trim().is_empty() => PathBuf::from(&p.value),
            (None, Some(p)) => {
                return Err(err(loc(p), "output.mcap", "expected a file path".into()));
            }
            (None, None) => default_log_path(name),
        };
        let max_log_mb = match (ov.max_log_mb, &self.max_log_mb) {
            (Some(v), _) if v.is_finite() && v > 0.0 => v,
            (Some(v), _) => {
                return Err(err(
                    None,
                    "--max-log-mb",
                    format!("expected a positive number of megabytes, got {v}"),
                ));
            }
            (None, Some(m)) if m.value.is_finite() && m.value > 0.0 => m.value,
            (None, Some(m)) => {
                return Err(err(
                    loc(m),
                    "output.max_log_mb",
                    format!("expected a positive number of megabytes, got {}", m.value),
                ));
            }
            (None, None) => DEFAULT_MAX_LOG_MB,
        };
        Ok(OutputSettings {
            output_rate,
            scene_rate,
            mcap_path,
            max_log_mb,
        })
    }
}

/// The output rate as given (Hz), or the default, before validation (for work estimates).
pub(super) fn output_rate_hint(out: &Option<OutputSpec>) -> f64 {
    out.as_ref()
        .and_then(|o| o.rate.as_ref())
        .map(|r| r.value)
        .filter(|r| r.is_finite() && *r > 0.0)
        .unwrap_or(100.0)
}

/// Where a scenario's log goes unless `output.mcap` or `--mcap` says otherwise:
/// `logs/<name>.mcap`, the name made one plain file name ([`crate::outputs::sanitize`]).
pub(super) fn default_log_path(name: &str) -> PathBuf {
    let suffix = ".mcap";
    PathBuf::from("logs").join(format!(
        "{}{suffix}",
        crate::outputs::sanitize(name, suffix.len())
    ))
}
