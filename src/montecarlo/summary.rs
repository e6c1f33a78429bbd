//! Campaign statistics computed from the per-run table alone, so that a merged set of shards
//! and a single-process campaign give the same summary.

use super::table::{Row, RunStatus};
use serde::Serialize;
use std::fmt::Write as _;

/// Percentiles reported for every column.
pub const PERCENTILES: [f64; 7] = [1.0, 5.0, 25.0, 50.0, 75.0, 95.0, 99.0];

/// Statistics of one column over the runs that have a value.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ColumnStats {
    /// Column name.
    pub column: String,
    /// Runs with a value.
    pub count: usize,
    /// Sample mean.
    pub mean: f64,
    /// Sample standard deviation (n − 1 in the denominator; 0 for one value).
    pub sd: f64,
    /// Smallest value.
    pub min: f64,
    /// Values at [`PERCENTILES`] (linear interpolation between order statistics).
    pub percentiles: Vec<f64>,
    /// Largest value.
    pub max: f64,
}

/// Probability that an event has happened by a time.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ProbabilityBy {
    /// Time (s).
    pub t: f64,
    /// Runs in which the event happened at or before `t`.
    pub count: usize,
    /// `count` / usable runs.
    pub probability: f64,
    /// 95 % Wilson score interval of the probability.
    pub ci95: [f64; 2],
}

/// One event's statistics.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct EventStats {
    /// Its condition, e.g. `nutation_angle_deg above 80`.
    pub condition: String,
    /// Its time column.
    pub column: String,
    /// Usable runs (complete or stopped): the denominator of the probabilities.
    pub runs: usize,
    /// Runs left out of the probabilities: failed, invalid draws, and runs whose model left
    /// its validity range (`invalid_model`).
    pub excluded: usize,
    /// Of those, the runs stopped as `invalid_model`.
    pub excluded_invalid_model: usize,
    /// Runs in which it happened at all.
    pub reached: usize,
    /// Probabilities by the requested times.
    pub by: Vec<ProbabilityBy>,
}

/// Runs picked to stand for the campaign.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Ranking {
    /// Column ranked by.
    pub by: String,
    /// What "worst" means for it.
    pub worst_is: String,
    /// Run index of the worst run.
    pub worst: u64,
    /// Run index of the median run.
    pub median: u64,
    /// Run index of the best run.
    pub best: u64,
}

/// A run that failed or could not be built.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Failure {
    /// Run index.
    pub run: u64,
    /// `failed`, `invalid` or `invalid_model`.
    pub status: &'static str,
    /// Diagnosis.
    pub message: String,
}

/// Counts of each status.
#[derive(Debug, Clone, Default, Serialize, PartialEq)]
pub struct StatusCounts {
    /// Reached the duration.
    pub complete: usize,
    /// Ended by a stop condition.
    pub stopped: usize,
    /// Integration failed.
    pub failed: usize,
    /// Draw could not be made a valid scenario.
    pub invalid: usize,
    /// An effector left the range its model holds in.
    pub invalid_model: usize,
}

/// Up to this many failures are listed in the summary (all are in the table).
pub const LISTED_FAILURES: usize = 20;

/// How to rank runs: by an event time (earliest is worst) or by the largest nutation.
#[derive(Debug, Clone)]
pub struct RankRule {
    /// Column index.
    pub column: usize,
    /// Column name.
    pub name: String,
    /// `true` when a smaller value is worse (event times: an earlier flat spin).
    pub smaller_is_worse: bool,
    /// Value used for runs without one (an event never reached counts as +∞).
    pub missing: f64,
}

/// Counts each status.
pub fn status_counts(rows: &[Row]) -> StatusCounts {
    let mut c = StatusCounts::default();
    for r in rows {
        match r.status {
            RunStatus::Complete => c.complete += 1,
            RunStatus::Stopped => c.stopped += 1,
            RunStatus::Failed => c.failed += 1,
            RunStatus::Invalid => c.invalid += 1,
            RunStatus::InvalidModel => c.invalid_model += 1,
        }
    }
    c
}

/// Statistics of column `j` over usable runs (None when no run has a value).
pub fn column_stats(name: &str, j: usize, rows: &[Row]) -> Option<ColumnStats> {
    let mut v: Vec<f64> = rows
        .iter()
        .filter(|r| r.status.ok())
        .filter_map(|r| r.values[j])
        .filter(|x| x.is_finite())
        .collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    // Two-pass mean and variance: sums in run order would depend on the order of the table,
    // sums of the sorted values do not.
    let mean = v.iter().sum::<f64>() / n as f64;
    let sd = if n > 1 {
        (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
    } else {
        0.0
    };
    Some(ColumnStats {
        column: name.to_string(),
        count: n,
        mean,
        sd,
        min: v[0],
        percentiles: PERCENTILES.iter().map(|p| percentile(&v, *p)).collect(),
        max: v[n - 1],
    })
}

/// The `p`-th percentile of sorted `v` by linear interpolation between order statistics
/// (Hyndman and Fan's definition 7, the default of NumPy and R).
pub fn percentile(v: &[f64], p: f64) -> f64 {
    let h = (v.len() - 1) as f64 * p / 100.0;
    let lo = h.floor() as usize;
    let hi = (lo + 1).min(v.len() - 1);
    v[lo] + (h - lo as f64) * (v[hi] - v[lo])
}

/// The 95 % Wilson score interval for `k` successes in `n` trials (Wilson 1927); it stays
/// inside [0, 1] and is not degenerate at k = 0 or k = n, unlike the normal approximation.
pub fn wilson95(k: usize, n: usize) -> [f64; 2] {
    if n == 0 {
        return [0.0, 1.0];
    }
    let z = 1.959_963_984_540_054;
    let (k, n) = (k as f64, n as f64);
    let p = k / n;
    let denom = 1.0 + z * z / n;
    let centre = (p + z * z / (2.0 * n)) / denom;
    let half = z * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt() / denom;
    [(centre - half).max(0.0), (centre + half).min(1.0)]
}

/// Statistics of an event time column.
pub fn event_stats(condition: &str, name: &str, j: usize, rows: &[Row], by: &[f64]) -> EventStats {
    let usable: Vec<&Row> = rows.iter().filter(|r| r.status.ok()).collect();
    let n = usable.len();
    let times: Vec<f64> = usable.iter().filter_map(|r| r.values[j]).collect();
    EventStats {
        condition: condition.to_string(),
        column: name.to_string(),
        runs: n,
        excluded: rows.len() - n,
        excluded_invalid_model: rows
            .iter()
            .filter(|r| r.status == RunStatus::InvalidModel)
            .count(),
        reached: times.len(),
        by: by
            .iter()
            .map(|&t| {
                let k = times.iter().filter(|&&x| x <= t).count();
                ProbabilityBy {
                    t,
                    count: k,
                    probability: if n > 0 { k as f64 / n as f64 } else { f64::NAN },
                    ci95: wilson95(k, n),
                }
            })
            .collect(),
    }
}

/// The worst, median and best usable runs under `rule` (ties broken by run index).
pub fn rank(rows: &[Row], rule: &RankRule) -> Option<Ranking> {
    let mut keyed: Vec<(f64, u64)> = rows
        .iter()
        .filter(|r| r.status.ok())
        .map(|r| (r.values[rule.column].unwrap_or(rule.missing), r.run))
        .collect();
    if keyed.is_empty() {
        return None;
    }
    // Worst first.
    keyed.sort_by(|a, b| {
        let by_value = if rule.smaller_is_worse {
            a.0.total_cmp(&b.0)
        } else {
            b.0.total_cmp(&a.0)
        };
        by_value.then(a.1.cmp(&b.1))
    });
    Some(Ranking {
        by: rule.name.clone(),
        worst_is: if rule.smaller_is_worse {
            "smallest"
        } else {
            "largest"
        }
        .into(),
        worst: keyed[0].1,
        median: keyed[(keyed.len() - 1) / 2].1,
        best: keyed[keyed.len() - 1].1,
    })
}

/// The first [`LISTED_FAILURES`] failed or invalid runs.
pub fn failures(rows: &[Row]) -> Vec<Failure> {
    rows.iter()
        .filter(|r| !r.status.ok())
        .take(LISTED_FAILURES)
        .map(|r| Failure {
            run: r.run,
            status: r.status.label(),
            message: r.message.clone(),
        })
        .collect()
}

/// A number for the text summary: 6 significant digits.
pub fn fmt(x: f64) -> String {
    if !x.is_finite() {
        return "-".into();
    }
    let a = x.abs();
    if a != 0.0 && !(1e-3..1e6).contains(&a) {
        format!("{x:.5e}")
    } else {
        let digits = if a == 0.0 {
            0
        } else {
            (5 - a.log10().floor() as i32).max(0) as usize
        };
        let mut s = format!("{x:.digits$}");
        if s.contains('.') {
            while s.ends_with('0') {
                s.pop();
            }
            if s.ends_with('.') {
                s.pop();
            }
        }
        s
    }
}

/// A fixed-width text table of column statistics.
pub fn stats_table(stats: &[ColumnStats]) -> String {
    let mut out = String::new();
    let width = stats
        .iter()
        .map(|s| s.column.len())
        .max()
        .unwrap_or(6)
        .max(6);
    let _ = write!(out, "{:width$}  {:>6}", "column", "n");
    for h in ["mean", "sd", "min", "p5", "p50", "p95", "max"] {
        let _ = write!(out, "  {h:>12}");
    }
    out.push('\n');
    for s in stats {
        let _ = write!(out, "{:width$}  {:>6}", s.column, s.count);
        for v in [
            s.mean,
            s.sd,
            s.min,
            s.percentiles[1],
            s.percentiles[3],
            s.percentiles[5],
            s.max,
        ] {
            let _ = write!(out, "  {:>12}", fmt(v));
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentile_matches_numpy_linear() {
        // numpy.percentile([1, 2, 3, 4], [0, 25, 50, 90, 100]) = 1, 1.75, 2.5, 3.7, 4.
        let v = [1.0, 2.0, 3.0, 4.0];
        let got: Vec<f64> = [0.0, 25.0, 50.0, 90.0, 100.0]
            .iter()
            .map(|p| percentile(&v, *p))
            .collect();
        for (g, e) in got.iter().zip([1.0, 1.75, 2.5, 3.7, 4.0]) {
            assert!((g - e).abs() < 1e-12, "{got:?}");
        }
    }

    #[test]
    fn wilson_interval_matches_published_values() {
        // Newcombe (1998), Table I: 81/263 → 0.2553 to 0.3662; 0/10 → 0 to 0.2775.
        let [lo, hi] = wilson95(81, 263);
        assert!(
            (lo - 0.2553).abs() < 5e-5 && (hi - 0.3662).abs() < 5e-5,
            "{lo} {hi}"
        );
        let [lo, hi] = wilson95(0, 10);
        assert!(lo == 0.0 && (hi - 0.2775).abs() < 5e-5, "{hi}");
    }

    #[test]
    fn ranking_puts_never_reached_last_and_breaks_ties_by_index() {
        let row = |run, t: Option<f64>| Row {
            run,
            status: RunStatus::Complete,
            message: String::new(),
            values: vec![t],
        };
        let rows = vec![
            row(0, Some(5.0)),
            row(1, None),
            row(2, Some(1.0)),
            row(3, Some(5.0)),
        ];
        let rule = RankRule {
            column: 0,
            name: "t".into(),
            smaller_is_worse: true,
            missing: f64::INFINITY,
        };
        let r = rank(&rows, &rule).unwrap();
        assert_eq!((r.worst, r.median, r.best), (2, 0, 1));
    }
}
