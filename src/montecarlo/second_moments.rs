//! Principal moments of inertia drawn through the body's second moments of mass, so that
//! every draw is a physical body and equal moments stay equal (`physical_inertia`,
//! docs/montecarlo.md).
//!
//! In principal axes the second moments of the mass distribution are Jᵢ = ∫ xᵢ² dm ≥ 0, and
//! the moments of inertia are Iᵢ = Jⱼ + Jₖ ({i, j, k} = {1, 2, 3}), so
//! Jᵢ = (Iⱼ + Iₖ − Iᵢ)/2. Any three positive J give positive moments satisfying the three
//! triangle inequalities (Iᵢ + Iⱼ − Iₖ = 2Jₖ), and every physical body has such J. So the
//! draw is made on log J: J′ₖ = Jₖ exp(yₖ − Var(yₖ)/2), y = L z with z standard normal,
//! never rejected. The shift makes E J′ = J, so the moments' means are the nominal ones.
//!
//! The covariance of log J is chosen so that the moments have, to first order, the relative
//! standard deviations asked for, each moment (or each group of equal moments) independent of
//! the others: with I = B J on the groups, Cov(J) = B⁻¹ diag(sₖ Iₖ)² B⁻ᵀ and
//! Cov(log J) = D⁻¹ Cov(J) D⁻¹, D = diag(J). Equal moments form one group, drawn once: they
//! have equal J, so they stay equal to the last bit.

use super::covariance;
use nalgebra::DMatrix;

/// Relative difference below which two principal moments count as equal (a symmetry of the
/// body): eigenvalues of a written tensor differ by rounding.
pub const EQUAL_MOMENTS: f64 = 1e-9;

/// Largest standard deviation of the logarithm of a second moment: beyond it the log-normal
/// draw is too skewed for the moments to have the spread asked for, a sign that the body
/// cannot move its moments that independently.
pub const MAX_LOG_SD: f64 = 0.5;

/// The draw of one body's moments.
#[derive(Debug, Clone)]
pub struct SecondMoments {
    /// Group of each principal moment (index into `j0`).
    group: [usize; 3],
    /// Nominal second moment of each group (kg m²).
    j0: Vec<f64>,
    /// Lower-triangular factor of the covariance of log J on the groups.
    factor: Vec<Vec<f64>>,
    /// Half the variance of each group's log J: subtracted so that E J′ = J.
    half_variance: Vec<f64>,
}

impl SecondMoments {
    /// The draw for nominal principal moments `moments` (kg m²) with relative standard
    /// deviations `sd`; with `keep_symmetry`, equal moments share one draw (their `sd` must
    /// then be equal). `Err` says why the body cannot be drawn this way.
    pub fn new(moments: [f64; 3], sd: [f64; 3], keep_symmetry: bool) -> Result<Self, String> {
        let total: f64 = moments.iter().sum();
        if moments.iter().any(|m| !(m.is_finite() && *m > 0.0)) {
            return Err(format!(
                "the principal moments {moments:?} are not all positive"
            ));
        }
        let mut group = [0usize; 3];
        let mut members: Vec<Vec<usize>> = Vec::new();
        for k in 0..3 {
            let same = keep_symmetry
                .then(|| {
                    members
                        .iter()
                        .position(|g| (moments[g[0]] - moments[k]).abs() <= EQUAL_MOMENTS * total)
                })
                .flatten();
            match same {
                Some(g) => {
                    let first = members[g][0];
                    if sd[first] != sd[k] {
                        return Err(format!(
                            "moments {} and {} are equal ({}), so they move together and \
                             need the same sd, got {} and {} (or set `symmetry: break` to draw \
                             them apart)",
                            first + 1,
                            k + 1,
                            moments[k],
                            sd[first],
                            sd[k]
                        ));
                    }
                    members[g].push(k);
                    group[k] = g;
                }
                None => {
                    group[k] = members.len();
                    members.push(vec![k]);
                }
            }
        }
        let n = members.len();
        // The group's moment: the mean of its members (equal to rounding).
        let moment: Vec<f64> = members
            .iter()
            .map(|g| g.iter().map(|&k| moments[k]).sum::<f64>() / g.len() as f64)
            .collect();
        let j0: Vec<f64> = moment.iter().map(|i| 0.5 * total - i).collect();
        for (g, j) in j0.iter().enumerate() {
            if *j <= EQUAL_MOMENTS * total {
                let k = members[g][0];
                return Err(format!(
                    "the body is flat across principal axis {} (I{} = {} is the sum of the \
                     other two moments): its mass has no extent along that axis, and a draw \
                     by second moments cannot give it one; disperse it with `inertia:`, \
                     which redraws",
                    k + 1,
                    k + 1,
                    moments[k]
                ));
            }
        }
        // I_g = Σ_h B_gh J_h: a moment is the sum of the second moments along the other two
        // axes, so B_gh counts the members of h other than g's own axis.
        let b = DMatrix::from_fn(n, n, |g, h| {
            members[h].len() as f64 - if g == h { 1.0 } else { 0.0 }
        });
        let b_inv = b
            .try_inverse()
            .ok_or("the moments' groups give a singular map (this is a bug)")?;
        let s = DMatrix::from_fn(n, n, |g, h| {
            if g == h {
                (sd[members[g][0]] * moment[g]).powi(2)
            } else {
                0.0
            }
        });
        let cov_j = &b_inv * s * b_inv.transpose();
        let cov_log: Vec<Vec<f64>> = (0..n)
            .map(|g| {
                (0..n)
                    .map(|h| 0.5 * (cov_j[(g, h)] + cov_j[(h, g)]) / (j0[g] * j0[h]))
                    .collect()
            })
            .collect();
        for g in 0..n {
            let log_sd = cov_log[g][g].sqrt();
            if log_sd > MAX_LOG_SD {
                let k = members[g][0];
                return Err(format!(
                    "these sds ask the body's second moment along axis {} (J{} = {:.6e} kg m², \
                     half of I{}+I{}−I{}) to vary by {:.0} %: the moments cannot move that \
                     independently for this body; keep equal moments together (`symmetry: \
                     keep`) or give smaller sds (at most {MAX_LOG_SD} on the logarithm)",
                    k + 1,
                    k + 1,
                    j0[g],
                    (k + 1) % 3 + 1,
                    (k + 2) % 3 + 1,
                    k + 1,
                    100.0 * log_sd
                ));
            }
        }
        let factor = covariance::factor(&cov_log, n).map_err(|e| {
            format!("the covariance of the second moments is not one ({e}; this is a bug)")
        })?;
        let half_variance = (0..n).map(|g| 0.5 * cov_log[g][g]).collect();
        Ok(Self {
            group,
            j0,
            factor,
            half_variance,
        })
    }

    /// The principal moments (kg m²) for the standard normal draws `z` (the first
    /// as many as there are groups of equal moments are used).
    pub fn draw(&self, z: &[f64; 3]) -> [f64; 3] {
        let n = self.j0.len();
        let y = covariance::correlate(&self.factor, &z[..n]);
        let j: Vec<f64> = self
            .j0
            .iter()
            .zip(&y)
            .zip(&self.half_variance)
            .map(|((j, y), h)| j * (y - h).exp())
            .collect();
        let by_axis = |k: usize| j[self.group[k]];
        // Iₖ = the second moments along the two other axes, added in axis order so that
        // equal moments come out bit for bit equal.
        [
            by_axis(1) + by_axis(2),
            by_axis(0) + by_axis(2),
            by_axis(0) + by_axis(1),
        ]
    }
}
