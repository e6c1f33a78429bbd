//! `rayleigh:` in the scenario file: the dissipation torque −Γω of Rayleigh's function
//! R = ½ ωᵀ Γ ω ([`crate::effectors::rayleigh`]).
//!
//! ```yaml
//! - rayleigh:
//!     gamma_diagonal: [0.01, 0.01, 0.02]   # N m s/rad, body axes
//!     # or gamma: [[0.01, 0, 0], [0, 0.01, 0], [0, 0, 0.02]], symmetric and PSD
//! ```

use super::{Check, Context, ScenarioError};
use crate::effectors::Rayleigh;
use nalgebra::{Matrix3, Vector3};
use serde::Deserialize;
use serde_saphyr::Spanned;

/// `rayleigh:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RayleighSpec {
    /// Name (default `rayleigh`).
    #[serde(default)]
    pub name: Option<String>,
    /// Γ as a full symmetric matrix (N m s/rad, body axes, rows).
    #[serde(default)]
    pub gamma: Option<Spanned<[[f64; 3]; 3]>>,
    /// Γ as a diagonal (N m s/rad), instead of `gamma`.
    #[serde(default)]
    pub gamma_diagonal: Option<Spanned<[f64; 3]>>,
}

/// Validates a `rayleigh:` entry and builds it; `item` is where the list item starts.
pub(super) fn build(
    ck: &Check,
    cx: &Context,
    spec: &RayleighSpec,
    name: String,
    item: Option<(u32, u32)>,
) -> Result<Rayleigh, ScenarioError> {
    let gamma = match (&spec.gamma, &spec.gamma_diagonal) {
        (Some(g), None) => {
            let m = Matrix3::from_row_slice(&g.value.concat());
            check_psd(ck, g, "gamma", &m)?;
            m
        }
        (None, Some(d)) => {
            let m = Matrix3::from_diagonal(&Vector3::from(d.value));
            check_psd(ck, d, "gamma_diagonal", &m)?;
            m
        }
        _ => {
            return Err(ScenarioError::at(
                cx.path,
                item,
                ck.prefix.clone(),
                "expected exactly one of `gamma: [[..],[..],[..]]` or \
                 `gamma_diagonal: [g1, g2, g3]` (N m s/rad)",
            ));
        }
    };
    Ok(Rayleigh { name, gamma })
}

fn check_psd<T>(
    ck: &Check,
    s: &Spanned<T>,
    key: &str,
    m: &Matrix3<f64>,
) -> Result<(), ScenarioError> {
    if !m.iter().all(|x| x.is_finite()) {
        return Err(ck.err(s, key, "expected finite numbers (N m s/rad)"));
    }
    let scale = m.amax().max(f64::MIN_POSITIVE);
    if (m - m.transpose()).amax() > 1e-12 * scale {
        return Err(ck.err(s, key, "expected a symmetric matrix"));
    }
    let eig = m.symmetric_eigenvalues();
    if eig.min() < -1e-12 * scale {
        return Err(ck.err(
            s,
            key,
            format!(
                "expected a positive semi-definite matrix (a dissipation function cannot be \
                 negative); its smallest eigenvalue is {:e}",
                eig.min()
            ),
        ));
    }
    Ok(())
}
