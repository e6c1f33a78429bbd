//! Campaign statistics computed from the per-run table alone, so that a merged set of shards
//! and a single-process campaign give the same summary. A [`Tally`] takes what one look at
//! each run gives as the runs arrive; [`statistics`] completes it by passes over the runs,
//! in memory that does not grow with their number.

use super::runs::Runs;
use super::select::{ExactSum, RadixSelect, from_ordered_key, ordered_key};
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
    /// The probability over all the runs, the excluded ones (failed, invalid, invalid_model)
    /// counted as not having had the event, and as having had it: the range the exclusion
    /// leaves open (equal to `probability` twice when no run is excluded).
    pub with_excluded: [f64; 2],
    /// The 95 % interval over all the runs whatever the excluded ones did: the lower Wilson
    /// bound of the first case of `with_excluded`, the upper of the second.
    pub ci95_with_excluded: [f64; 2],
}

/// What the summary counts of the draws that were not valid scenarios.
#[derive(Debug, Clone)]
pub struct InvalidDrawSpec {
    /// `redraw` or `exclude` (the campaign's `invalid_draws`).
    pub policy: &'static str,
    /// The column of the draws each run rejected (`redraws`), under `redraw`.
    pub run_column: Option<usize>,
    /// The columns of a dispersion's own redraws (`inertia_redraws`).
    pub dispersion_columns: Vec<usize>,
}

/// Draws rejected and drawn again, as one column counts them.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct RedrawCount {
    /// The column (`redraws`: whole draws of a run; `inertia_redraws`: the moments alone).
    pub column: String,
    /// Draws rejected.
    pub rejected: u64,
    /// Runs with at least one rejected draw.
    pub runs: usize,
    /// Rejected draws over all draws made (rejected and accepted).
    pub rejection_rate: f64,
}

/// How the campaign treated the draws that were not valid scenarios, and how many there were.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct InvalidDrawStats {
    /// `redraw` or `exclude`.
    pub policy: &'static str,
    /// What the probabilities then mean.
    pub meaning: String,
    /// Runs recorded `invalid` and left out of the probabilities (under `redraw`, the runs
    /// without a valid draw in the most draws allowed).
    pub invalid_runs: usize,
    /// Draws rejected and drawn again, per counting column.
    pub redrawn: Vec<RedrawCount>,
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

/// What the summary needs of one event column.
#[derive(Debug, Clone)]
pub struct EventColumn {
    /// Its condition, e.g. `nutation_angle_deg above 80`.
    pub condition: String,
    /// Its column name.
    pub name: String,
    /// Its column index.
    pub column: usize,
}

/// Everything the summary is computed from, besides the runs.
#[derive(Debug, Clone)]
pub struct SummarySpec {
    /// Column names.
    pub columns: Vec<String>,
    /// The event columns.
    pub events: Vec<EventColumn>,
    /// Times for the event probabilities (s).
    pub probability_by: Vec<f64>,
    /// How runs are ranked.
    pub rank: RankRule,
    /// What the invalid draws' counts are read from.
    pub invalid_draws: InvalidDrawSpec,
}

/// One column's counts in the first pass.
#[derive(Debug, Clone)]
struct ColumnTally {
    count: u64,
    min: u64,
    max: u64,
    sum: ExactSum,
}

/// One redraw column's counts in the first pass.
#[derive(Debug, Clone, Default)]
struct RedrawTally {
    rejected: u64,
    runs: usize,
    accepted: usize,
}

/// One event's counts in the first pass.
#[derive(Debug, Clone, Default)]
struct EventTally {
    reached: usize,
    by: Vec<usize>,
}

/// The statistics that need one look at each run, taken as runs are pushed in run order:
/// counts, first failures, extremes and exact sums. Holds a fixed amount whatever the number
/// of runs.
#[derive(Debug, Clone)]
pub struct Tally {
    spec: SummarySpec,
    runs: usize,
    usable: usize,
    status: StatusCounts,
    failures: Vec<Failure>,
    events: Vec<EventTally>,
    columns: Vec<ColumnTally>,
    /// Per redraw column: the run's (if any), then the dispersions'.
    redraws: Vec<RedrawTally>,
    /// Worst and best (key, run) under the rank rule, and the number of usable runs ranked.
    worst: Option<(u64, u64)>,
    best: Option<(u64, u64)>,
}

impl Tally {
    /// An empty tally.
    pub fn new(spec: SummarySpec) -> Self {
        let column = ColumnTally {
            count: 0,
            min: u64::MAX,
            max: 0,
            sum: ExactSum::default(),
        };
        Self {
            events: vec![
                EventTally {
                    reached: 0,
                    by: vec![0; spec.probability_by.len()],
                };
                spec.events.len()
            ],
            columns: vec![column; spec.columns.len()],
            redraws: vec![RedrawTally::default(); spec.invalid_draws.counting_columns().len()],
            spec,
            runs: 0,
            usable: 0,
            status: StatusCounts::default(),
            failures: Vec::new(),
            worst: None,
            best: None,
        }
    }

    /// Counts `r` (runs must come in run order).
    pub fn add(&mut self, r: &Row) {
        self.runs += 1;
        match r.status {
            RunStatus::Complete => self.status.complete += 1,
            RunStatus::Stopped => self.status.stopped += 1,
            RunStatus::Failed => self.status.failed += 1,
            RunStatus::Invalid => self.status.invalid += 1,
            RunStatus::InvalidModel => self.status.invalid_model += 1,
        }
        let invalid = r.status == RunStatus::Invalid;
        let run_column = self.spec.invalid_draws.run_column;
        for (j, t) in self
            .spec
            .invalid_draws
            .counting_columns()
            .into_iter()
            .zip(&mut self.redraws)
        {
            if let Some(n) = r.values[j].filter(|x| x.is_finite() && *x >= 0.0) {
                // A campaign's counts stay far below u64::MAX (MAX_RUNS runs of at most
                // MAX_DRAWS_PER_RUN draws); a row from elsewhere saturates, never wraps.
                t.rejected = t.rejected.saturating_add(n as u64);
                t.runs += usize::from(n > 0.0);
                // A run left invalid under `redraw` accepted no draw.
                t.accepted += usize::from(!(invalid && Some(j) == run_column));
            }
        }
        if !r.status.ok() {
            if self.failures.len() < LISTED_FAILURES {
                self.failures.push(Failure {
                    run: r.run,
                    status: r.status.label(),
                    message: r.message.clone(),
                });
            }
            return;
        }
        self.usable += 1;
        for (e, tally) in self.spec.events.iter().zip(&mut self.events) {
            if let Some(t) = r.values[e.column] {
                tally.reached += 1;
                for (count, by) in tally.by.iter_mut().zip(&self.spec.probability_by) {
                    *count += usize::from(t <= *by);
                }
            }
        }
        for (c, v) in self.columns.iter_mut().zip(&r.values) {
            if let Some(x) = v.filter(|x| x.is_finite()) {
                let k = ordered_key(x);
                c.count += 1;
                c.min = c.min.min(k);
                c.max = c.max.max(k);
                c.sum.add(x);
            }
        }
        let key = self.spec.rank.key(&r.values);
        if self.worst.is_none_or(|(k, _)| key < k) {
            self.worst = Some((key, r.run));
        }
        if self.best.is_none_or(|(k, _)| key >= k) {
            self.best = Some((key, r.run));
        }
    }

    /// Number of runs counted.
    pub fn runs(&self) -> usize {
        self.runs
    }

    /// Whether some usable run has a value in event column `k` (of the spec's events).
    pub fn event_reached(&self, k: usize) -> bool {
        self.events[k].reached > 0
    }
}

impl InvalidDrawSpec {
    /// The columns counting rejected draws: the run's first, then the dispersions'.
    fn counting_columns(&self) -> Vec<usize> {
        self.run_column
            .iter()
            .chain(&self.dispersion_columns)
            .copied()
            .collect()
    }
}

impl RankRule {
    /// A usable run's ranking key: ascending from the worst run.
    fn key(&self, values: &[Option<f64>]) -> u64 {
        let k = ordered_key(values[self.column].unwrap_or(self.missing));
        if self.smaller_is_worse { k } else { !k }
    }
}

/// The statistics of a campaign.
#[derive(Debug, Clone)]
pub struct Statistics {
    /// Counts of each status.
    pub status: StatusCounts,
    /// Per event.
    pub events: Vec<EventStats>,
    /// The worst, median and best runs.
    pub ranking: Option<Ranking>,
    /// Per column with values.
    pub columns: Vec<ColumnStats>,
    /// The first failed or invalid runs.
    pub failures: Vec<Failure>,
    /// The invalid draws: how they were treated, how many.
    pub invalid_draws: InvalidDrawStats,
}

/// Completes `tally` by passes over `runs` (the runs it counted, in the same order): the
/// percentiles and the median run by exact radix selection ([`select::PASSES`] passes),
/// the standard deviations around the exact mean, and the median's tie-break by run index
/// (one more pass). Gives the same bits whatever held the runs.
pub fn statistics(tally: &Tally, runs: &dyn Runs) -> Result<Statistics, String> {
    let spec = &tally.spec;
    // Ranks of each column's order statistics: for every percentile, the two around it.
    let ranks: Vec<Vec<u64>> = tally
        .columns
        .iter()
        .map(|c| {
            if c.count == 0 {
                return Vec::new();
            }
            PERCENTILES
                .iter()
                .flat_map(|p| {
                    let (lo, hi, _) = percentile_ranks(c.count, *p);
                    [lo, hi]
                })
                .collect()
        })
        .collect();
    let mut selections: Vec<RadixSelect> = ranks.iter().map(|r| RadixSelect::new(r)).collect();
    let median_rank = (tally.usable as u64).saturating_sub(1) / 2;
    let median_ranks = if tally.usable > 0 {
        vec![median_rank]
    } else {
        Vec::new()
    };
    let mut median = RadixSelect::new(&median_ranks);
    let means: Vec<f64> = tally
        .columns
        .iter()
        .map(|c| c.sum.value() / c.count.max(1) as f64)
        .collect();
    let mut squares = vec![ExactSum::default(); spec.columns.len()];
    let mut first = true;
    while !(median.done() && selections.iter().all(RadixSelect::done)) || first {
        runs.scan(&mut |r| {
            if !r.ok {
                return;
            }
            for (j, v) in r.values.iter().enumerate() {
                if let Some(x) = v.filter(|x| x.is_finite()) {
                    selections[j].observe(ordered_key(x));
                    if first {
                        squares[j].add((x - means[j]).powi(2));
                    }
                }
            }
            median.observe(spec.rank.key(r.values));
        })?;
        selections.iter_mut().for_each(RadixSelect::end_pass);
        median.end_pass();
        first = false;
    }
    let ranking = match (tally.worst, tally.best) {
        (Some((_, worst)), Some((_, best))) => {
            let key = median.key(median_rank);
            let mut skip = median.rank_among_equals(median_rank);
            let mut run = None;
            runs.scan(&mut |r| {
                if r.ok && run.is_none() && spec.rank.key(r.values) == key {
                    if skip == 0 {
                        run = Some(r.run);
                    } else {
                        skip -= 1;
                    }
                }
            })?;
            Some(Ranking {
                by: spec.rank.name.clone(),
                worst_is: if spec.rank.smaller_is_worse {
                    "smallest"
                } else {
                    "largest"
                }
                .into(),
                worst,
                median: run.ok_or("the median run was not found on the second reading")?,
                best,
            })
        }
        _ => None,
    };
    let columns = tally
        .columns
        .iter()
        .enumerate()
        .filter(|(_, c)| c.count > 0)
        .map(|(j, c)| {
            let n = c.count;
            let s = &selections[j];
            ColumnStats {
                column: spec.columns[j].clone(),
                count: n as usize,
                mean: means[j],
                sd: if n > 1 {
                    (squares[j].value() / (n - 1) as f64).sqrt()
                } else {
                    0.0
                },
                min: from_ordered_key(c.min),
                percentiles: PERCENTILES
                    .iter()
                    .map(|p| {
                        let (lo, hi, frac) = percentile_ranks(n, *p);
                        let (a, b) = (from_ordered_key(s.key(lo)), from_ordered_key(s.key(hi)));
                        a + frac * (b - a)
                    })
                    .collect(),
                max: from_ordered_key(c.max),
            }
        })
        .collect();
    let usable = tally.usable;
    let all = tally.runs;
    let events = spec
        .events
        .iter()
        .zip(&tally.events)
        .map(|(e, t)| EventStats {
            condition: e.condition.clone(),
            column: e.name.clone(),
            runs: usable,
            excluded: tally.runs - usable,
            excluded_invalid_model: tally.status.invalid_model,
            reached: t.reached,
            by: spec
                .probability_by
                .iter()
                .zip(&t.by)
                .map(|(&t, &k)| ProbabilityBy {
                    t,
                    count: k,
                    probability: if usable > 0 {
                        k as f64 / usable as f64
                    } else {
                        f64::NAN
                    },
                    ci95: wilson95(k, usable),
                    with_excluded: if all > 0 {
                        [
                            k as f64 / all as f64,
                            (k + all - usable) as f64 / all as f64,
                        ]
                    } else {
                        [f64::NAN; 2]
                    },
                    ci95_with_excluded: [wilson95(k, all)[0], wilson95(k + all - usable, all)[1]],
                })
                .collect(),
        })
        .collect();
    let invalid_draws = InvalidDrawStats {
        policy: spec.invalid_draws.policy,
        meaning: if spec.invalid_draws.policy == "redraw" {
            "a draw that is not a valid scenario is drawn again from the run's own stream: \
             the probabilities are those of the dispersions restricted to valid scenarios"
                .into()
        } else {
            "a draw that is not a valid scenario is recorded `invalid` and left out: each \
             probability is over the usable runs, with its range if every excluded run had \
             not or had the event (`with_excluded`)"
                .into()
        },
        invalid_runs: tally.status.invalid,
        redrawn: spec
            .invalid_draws
            .counting_columns()
            .iter()
            .zip(&tally.redraws)
            .map(|(&j, t)| RedrawCount {
                column: spec.columns[j].clone(),
                rejected: t.rejected,
                runs: t.runs,
                rejection_rate: if t.rejected > 0 {
                    t.rejected as f64 / (t.rejected as f64 + t.accepted as f64)
                } else {
                    0.0
                },
            })
            .collect(),
    };
    Ok(Statistics {
        status: tally.status.clone(),
        events,
        ranking,
        columns,
        failures: tally.failures.clone(),
        invalid_draws,
    })
}

/// The order statistics (0-based ranks) around the `p`-th percentile of `n` values and the
/// fraction between them, as [`percentile`] interpolates.
fn percentile_ranks(n: u64, p: f64) -> (u64, u64, f64) {
    let h = (n - 1) as f64 * p / 100.0;
    let lo = h.floor() as u64;
    (lo, (lo + 1).min(n - 1), h - lo as f64)
}

/// The `p`-th percentile of sorted `v` by linear interpolation between order statistics
/// (Hyndman and Fan's definition 7, the default of NumPy and R).
pub fn percentile(v: &[f64], p: f64) -> f64 {
    let (lo, hi, frac) = percentile_ranks(v.len() as u64, p);
    let (a, b) = (v[lo as usize], v[hi as usize]);
    a + frac * (b - a)
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

    fn no_redraws() -> InvalidDrawSpec {
        InvalidDrawSpec {
            policy: "exclude",
            run_column: None,
            dispersion_columns: Vec::new(),
        }
    }

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
    fn huge_redraw_counts_saturate_instead_of_overflowing() {
        // Rows that no campaign writes (the fuzzer's): two counts of 1e300 draws each.
        let spec = SummarySpec {
            columns: vec!["redraws".into()],
            events: Vec::new(),
            probability_by: Vec::new(),
            rank: RankRule {
                column: 0,
                name: "redraws".into(),
                smaller_is_worse: true,
                missing: f64::INFINITY,
            },
            invalid_draws: InvalidDrawSpec {
                policy: "redraw",
                run_column: Some(0),
                dispersion_columns: Vec::new(),
            },
        };
        let rows: Vec<Row> = (0..2)
            .map(|run| Row {
                run,
                status: RunStatus::Complete,
                message: String::new(),
                values: vec![Some(1e300)],
            })
            .collect();
        let mut tally = Tally::new(spec);
        rows.iter().for_each(|r| tally.add(r));
        let stats = statistics(&tally, &rows.as_slice()).unwrap();
        let counted = &stats.invalid_draws.redrawn[0];
        assert_eq!((counted.rejected, counted.runs), (u64::MAX, 2));
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
        let spec = SummarySpec {
            columns: vec!["t".into()],
            events: Vec::new(),
            probability_by: Vec::new(),
            rank: rule,
            invalid_draws: no_redraws(),
        };
        let mut tally = Tally::new(spec);
        rows.iter().for_each(|r| tally.add(r));
        let r = statistics(&tally, &rows.as_slice())
            .unwrap()
            .ranking
            .unwrap();
        assert_eq!((r.worst, r.median, r.best), (2, 0, 1));
    }

    #[test]
    fn streamed_statistics_equal_those_of_the_sorted_values() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let status = [RunStatus::Complete, RunStatus::Stopped, RunStatus::Failed];
        let rows: Vec<Row> = (0..3001)
            .map(|run| Row {
                run,
                status: status[(run % 3) as usize],
                message: String::new(),
                values: vec![
                    Some(rng.random::<f64>() * 100.0),
                    (run % 5 != 0).then(|| (rng.random_range(0..20) as f64).exp()),
                    Some(if run % 7 == 0 {
                        f64::INFINITY
                    } else {
                        -(run as f64)
                    }),
                ],
            })
            .collect();
        let spec = SummarySpec {
            columns: vec!["a".into(), "b".into(), "c".into()],
            events: Vec::new(),
            probability_by: Vec::new(),
            rank: RankRule {
                column: 1,
                name: "b".into(),
                smaller_is_worse: false,
                missing: f64::NEG_INFINITY,
            },
            invalid_draws: no_redraws(),
        };
        let mut tally = Tally::new(spec);
        rows.iter().for_each(|r| tally.add(r));
        let stats = statistics(&tally, &rows.as_slice()).unwrap();
        let usable: Vec<&Row> = rows.iter().filter(|r| r.status.ok()).collect();
        for (j, c) in stats.columns.iter().enumerate() {
            let mut v: Vec<f64> = usable
                .iter()
                .filter_map(|r| r.values[j])
                .filter(|x| x.is_finite())
                .collect();
            v.sort_by(f64::total_cmp);
            assert_eq!(c.count, v.len());
            assert_eq!((c.min, c.max), (v[0], v[v.len() - 1]));
            for (p, got) in PERCENTILES.iter().zip(&c.percentiles) {
                assert_eq!(
                    got.to_bits(),
                    percentile(&v, *p).to_bits(),
                    "{} p{p}",
                    c.column
                );
            }
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            assert!(
                (c.mean - mean).abs() <= 1e-13 * mean.abs(),
                "{} {mean}",
                c.column
            );
            let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (v.len() - 1) as f64;
            assert!(
                (c.sd - var.sqrt()).abs() <= 1e-12 * var.sqrt(),
                "{}",
                c.column
            );
        }
        // Ranking by b, largest worst, a missing b counting as -inf (best), ties by run.
        let mut keyed: Vec<(f64, u64)> = usable
            .iter()
            .map(|r| (r.values[1].unwrap_or(f64::NEG_INFINITY), r.run))
            .collect();
        keyed.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        let r = stats.ranking.unwrap();
        let median = keyed[(keyed.len() - 1) / 2].1;
        assert_eq!(
            (r.worst, r.median, r.best),
            (keyed[0].1, median, keyed[keyed.len() - 1].1)
        );
        assert_eq!(stats.status.failed, 1000);
    }
}
