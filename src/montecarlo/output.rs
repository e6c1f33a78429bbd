//! What a campaign writes into its directory, and `merge`, which checks shard outputs and
//! writes the combined result.
//!
//! Files: `runs.csv`, `runs.parquet`, `summary.json`, `summary.txt`, `scenario.yaml` (the
//! scenario as given), and for a whole campaign (not a shard) the charts (three for each
//! event, named after its column, and the flat spin's under their historical names too) and
//! `campaign.mcap`. `campaign.json`, the manifest, is written last: a directory without it
//! holds no finished result. Every file is written under a temporary name and renamed, into
//! a directory taken through [`OwnedDir`] (new, empty, or polhode's; locked while written;
//! only the files its marker lists are removed).

use super::runs::{RunStore, Runs};
use super::summary::{self, ColumnStats, EventStats, Failure, Ranking, StatusCounts, Tally};
use super::table::{self, CsvWriter, ParquetWriter, Row};
use super::{Prepared, sha256_hex, shard_range};
use crate::log::{Attachment, McapLogger};
use crate::outputs::{OwnedDir, TempFile, check_replaceable, temporary_path, write_atomically};
use crate::plot::{Chart, Series, Style};
use crate::scenario::{self, Overrides};
use crate::sim::{self, Control};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::fs::File;
use std::io::{BufReader, BufWriter, Read};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

/// Format tag of `campaign.json`.
pub const MANIFEST_FORMAT: &str = "polhode-campaign/1";

/// Hash of the sources and `Cargo.lock` this binary was built from (build.rs).
pub const BUILD_ID: &str = env!("POLHODE_BUILD_ID");

/// Every fixed file name a campaign may write.
const OUTPUT_FILES: [&str; 13] = [
    "campaign.json",
    "runs.csv",
    "runs.parquet",
    "scenario.yaml",
    "summary.json",
    "summary.txt",
    "campaign.mcap",
    "flat_spin_time_histogram.svg",
    "flat_spin_time_histogram.png",
    "flat_spin_time_cdf.svg",
    "flat_spin_time_cdf.png",
    "transverse_rate_vs_flat_spin_time.svg",
    "transverse_rate_vs_flat_spin_time.png",
];

/// Suffixes of an event's chart files after its column name (`t_<condition>`): the
/// histogram, the CDF and the scatter against the initial transverse rate.
const EVENT_CHART_SUFFIXES: [&str; 3] = ["_histogram", "_cdf", "_vs_transverse_rate"];

/// Whether `name` is the file name of an event chart ([`EVENT_CHART_SUFFIXES`]); the events,
/// and so these names, differ between campaigns.
fn is_event_chart(name: &str) -> bool {
    let Some(stem) = name
        .strip_suffix(".svg")
        .or_else(|| name.strip_suffix(".png"))
    else {
        return false;
    };
    name.starts_with("t_")
        && !name.starts_with('.')
        && EVENT_CHART_SUFFIXES.iter().any(|s| stem.ends_with(s))
}

/// Whether a campaign may write a file named `name`: a directory holding such a file that
/// polhode did not write is refused ([`OwnedDir::claim`]).
pub fn may_write(name: &str) -> bool {
    OUTPUT_FILES.contains(&name) || is_event_chart(name)
}

/// The scratch file of the runs' values, under its temporary name while a campaign writes.
const SCRATCH_FILE: &str = "runs.scratch";

/// Takes `dir` for a campaign's outputs ([`OwnedDir::claim`] with [`may_write`]).
pub fn claim(dir: &Path) -> Result<OwnedDir, String> {
    OwnedDir::claim(dir, &may_write)
}

/// What [`write_outputs`] wrote.
#[derive(Debug, Default)]
pub struct Written {
    /// Files written.
    pub files: Vec<PathBuf>,
    /// Whether `campaign.mcap` was left out because `interrupt` was set while it was made.
    pub mcap_interrupted: bool,
}

/// `campaign.json`: what was run, so that shards can be checked against each other.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Manifest {
    /// [`MANIFEST_FORMAT`].
    pub format: String,
    /// polhode version that wrote it.
    pub polhode_version: String,
    /// Hash of the sources and `Cargo.lock` of the build that wrote it (`merge` refuses
    /// shards of another build: the version does not change between commits).
    pub build_id: String,
    /// Scenario `name:`.
    pub scenario: String,
    /// Hex SHA-256 of the scenario text.
    pub scenario_sha256: String,
    /// Campaign seed.
    pub seed: u64,
    /// Runs in the whole campaign.
    pub runs: u64,
    /// `[k, n]` for shard k of n (1-based); absent for a whole campaign.
    pub shard: Option<[u64; 2]>,
    /// Run indices this output covers, `[start, end)`.
    pub run_range: [u64; 2],
    /// Rows in `runs.csv`.
    pub runs_in_table: u64,
    /// Whether runs of the range are missing (interrupted).
    pub partial: bool,
    /// Columns after `run`, `status`, `message`.
    pub columns: Vec<String>,
    /// Hex SHA-256 of `runs.csv`.
    pub runs_csv_sha256: String,
    /// The method that replaced the scenario's (`--method`), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub method: Option<String>,
}

/// `summary.json`.
#[derive(Debug, Serialize)]
struct SummaryDoc {
    format: &'static str,
    polhode_version: String,
    scenario: String,
    scenario_sha256: String,
    seed: u64,
    runs: u64,
    shard: Option<[u64; 2]>,
    run_range: [u64; 2],
    runs_in_table: u64,
    partial: bool,
    status: StatusCounts,
    invalid_draws: summary::InvalidDrawStats,
    percentiles: &'static [f64],
    events: Vec<EventStats>,
    charts: Vec<EventCharts>,
    ranking: Option<Ranking>,
    columns: Vec<ColumnStats>,
    failures: Vec<Failure>,
}

/// Writes a campaign's outputs into a directory as its runs finish, in run order: the CSV
/// and Parquet tables row by row (under temporary names), the runs' values to a scratch file
/// for the summary's later passes, and the one-look statistics (`Tally`). Its memory does
/// not grow with the number of runs. [`CampaignWriter::finish`] writes the rest; dropped
/// before that, it leaves nothing behind.
pub struct CampaignWriter<'a> {
    dir: OwnedDir,
    prep: &'a Prepared,
    shard: Option<[u64; 2]>,
    /// The open writers (taken by `finish`).
    open: Option<OpenTables>,
    tally: Tally,
    /// The tables under their temporary names (removed on drop until renamed), and their
    /// final names.
    temporary: Vec<(TempFile, PathBuf)>,
    /// Threads `finish` may use ([`CampaignWriter::use_threads`]).
    threads: usize,
}

/// The writers of a [`CampaignWriter`] while runs are pushed.
struct OpenTables {
    csv: CsvWriter<BufWriter<File>>,
    parquet: ParquetWriter<BufWriter<File>>,
    store: RunStore,
}

impl<'a> CampaignWriter<'a> {
    /// Starts writing a campaign's outputs into `dir` ([`claim`]; `shard`: which shard, or
    /// `None` for a whole campaign).
    pub fn create(
        mut dir: OwnedDir,
        prep: &'a Prepared,
        shard: Option<[u64; 2]>,
    ) -> Result<Self, String> {
        let mut open = |name: &str| -> Result<(BufWriter<File>, (TempFile, PathBuf)), String> {
            let target = dir.file(name)?;
            check_replaceable(&target)
                .map_err(|e| format!("cannot write {}: {e}", target.display()))?;
            let (tmp, f) = TempFile::beside(&target, name)
                .map_err(|e| format!("cannot write {}: {e}", target.display()))?;
            Ok((BufWriter::with_capacity(1 << 20, f), (tmp, target)))
        };
        let (csv_file, csv_names) = open("runs.csv")?;
        let (parquet_file, parquet_names) = open("runs.parquet")?;
        let temporary = vec![csv_names, parquet_names];
        let scratch = temporary_path(&dir.file(SCRATCH_FILE)?, SCRATCH_FILE);
        let io = |e: std::io::Error| format!("cannot write runs.csv: {e}");
        let csv = CsvWriter::new(csv_file, &prep.columns).map_err(io)?;
        let parquet = ParquetWriter::new(parquet_file, &prep.columns)
            .map_err(|e| format!("cannot write runs.parquet: {e}"))?;
        let store = RunStore::create(&scratch, prep.columns.len())?;
        Ok(Self {
            dir,
            prep,
            shard,
            open: Some(OpenTables {
                csv,
                parquet,
                store,
            }),
            tally: Tally::new(prep.summary_spec()),
            temporary,
            threads: 1,
        })
    }

    /// Appends a finished run (runs come in run order).
    pub fn push(&mut self, row: Row) -> Result<(), String> {
        let Some(open) = self.open.as_mut() else {
            return Err("the campaign's tables are already closed".into());
        };
        open.csv.push(&row).map_err(|e| {
            format!(
                "cannot write {}: {e}",
                self.dir.dir().join("runs.csv").display()
            )
        })?;
        open.store.push(&row)?;
        self.tally.add(&row);
        open.parquet.push(row).map_err(|e| {
            format!(
                "cannot write {}: {e}",
                self.dir.dir().join("runs.parquet").display()
            )
        })
    }

    /// Lets [`CampaignWriter::finish`] use `threads` threads (1 unless set): with two or
    /// more, the MCAP's runs are integrated on a second thread while the first writes them.
    pub fn use_threads(&mut self, threads: usize) {
        self.threads = threads.max(1);
    }

    /// Runs pushed so far.
    pub fn rows(&self) -> u64 {
        self.tally.runs() as u64
    }

    /// Moves the tables into place and writes the rest: the scenario, the summaries and, for
    /// a whole campaign, the charts and (unless `partial`) the MCAP of its worst, median and
    /// best runs, which are re-run: if `interrupt` is set meanwhile, the MCAP is left out and
    /// everything else is still written. The manifest comes last.
    pub fn finish(mut self, partial: bool, interrupt: &AtomicBool) -> Result<Written, String> {
        let mut written = Vec::new();
        let dir = self.dir.dir().to_path_buf();
        let fail = |name: &str, e: &dyn std::fmt::Display| {
            format!("cannot write {}: {e}", dir.join(name).display())
        };
        let OpenTables {
            csv,
            parquet,
            store,
        } = self
            .open
            .take()
            .ok_or("the campaign's tables are already closed")?;
        let (file, sha) = csv.finish().map_err(|e| fail("runs.csv", &e))?;
        sync(file).map_err(|e| fail("runs.csv", &e))?;
        let file = parquet.finish().map_err(|e| fail("runs.parquet", &e))?;
        sync(file).map_err(|e| fail("runs.parquet", &e))?;
        for (tmp, target) in std::mem::take(&mut self.temporary) {
            tmp.persist(&target)
                .map_err(|e| format!("cannot write {}: {e}", target.display()))?;
            written.push(target);
        }
        let put = |owned: &mut OwnedDir,
                   written: &mut Vec<PathBuf>,
                   name: &str,
                   bytes: &[u8]|
         -> Result<(), String> {
            let p = owned.file(name)?;
            write_atomically(&p, bytes)
                .map_err(|e| format!("cannot write {}: {e}", p.display()))?;
            written.push(p);
            Ok(())
        };
        let prep = self.prep;
        let owned = &mut self.dir;
        put(
            owned,
            &mut written,
            "scenario.yaml",
            prep.scenario.source.as_bytes(),
        )?;
        let runs = store.finish()?;
        let rows = self.tally.runs() as u64;
        let manifest = manifest(prep, rows, self.shard, partial, sha);
        let stats = summary::statistics(&self.tally, &runs)?;
        let plan = chart_plan(prep, &self.tally, self.shard);
        let doc = summary_doc(&manifest, stats, plan);
        let json = serde_json::to_string_pretty(&doc).map_err(|e| e.to_string())? + "\n";
        put(owned, &mut written, "summary.json", json.as_bytes())?;
        put(
            owned,
            &mut written,
            "summary.txt",
            summary_text(&doc).as_bytes(),
        )?;
        let mut mcap_interrupted = false;
        if self.shard.is_none() {
            written.extend(charts(owned, prep, &runs, &doc)?);
            if let Some(r) = &doc.ranking
                && !partial
            {
                let path = owned.file("campaign.mcap")?;
                match trajectories(&path, prep, r, &json, interrupt, self.threads)? {
                    Some(p) => written.push(p),
                    None => mcap_interrupted = true,
                }
            }
        }
        drop(runs);
        let m = serde_json::to_string_pretty(&manifest).map_err(|e| e.to_string())? + "\n";
        put(owned, &mut written, "campaign.json", m.as_bytes())?;
        Ok(Written {
            files: written,
            mcap_interrupted,
        })
    }
}

/// Flushes a table's file to disk.
fn sync(file: BufWriter<File>) -> std::io::Result<()> {
    file.into_inner().map_err(|e| e.into_error())?.sync_all()
}

/// Writes every output of `rows` (the runs of the range that finished, in run order) into
/// `dir` ([`claim`]ed), as [`CampaignWriter`] does.
pub fn write_outputs(
    dir: &Path,
    prep: &Prepared,
    rows: &[Row],
    shard: Option<[u64; 2]>,
    partial: bool,
    interrupt: &AtomicBool,
) -> Result<Written, String> {
    let mut w = CampaignWriter::create(claim(dir)?, prep, shard)?;
    for r in rows {
        w.push(r.clone())?;
    }
    w.finish(partial, interrupt)
}

/// The manifest of a table of `rows` runs whose `runs.csv` has the hex SHA-256 `csv_sha256`.
fn manifest(
    prep: &Prepared,
    rows: u64,
    shard: Option<[u64; 2]>,
    partial: bool,
    csv_sha256: String,
) -> Manifest {
    let range = match shard {
        Some([k, n]) => shard_range(prep.campaign.runs, k, n),
        None => 0..prep.campaign.runs,
    };
    Manifest {
        format: MANIFEST_FORMAT.into(),
        polhode_version: env!("CARGO_PKG_VERSION").into(),
        build_id: BUILD_ID.into(),
        scenario: prep.scenario.name.clone(),
        scenario_sha256: prep.scenario_sha256.clone(),
        seed: prep.campaign.seed,
        runs: prep.campaign.runs,
        shard,
        run_range: [range.start, range.end],
        runs_in_table: rows,
        partial,
        columns: prep.columns.clone(),
        runs_csv_sha256: csv_sha256,
        method: prep.method.clone(),
    }
}

/// The text of `summary.json` that [`write_outputs`] would write for `rows`, without writing
/// anything (for callers that keep the campaign in memory, e.g. the Python package). Its
/// `charts` name the files `write_outputs` would draw.
pub fn summary_json(
    prep: &Prepared,
    rows: &[Row],
    shard: Option<[u64; 2]>,
    partial: bool,
) -> Result<String, String> {
    let mut tally = Tally::new(prep.summary_spec());
    rows.iter().for_each(|r| tally.add(r));
    let manifest = manifest(prep, rows.len() as u64, shard, partial, String::new());
    let stats = summary::statistics(&tally, &rows)?;
    let plan = chart_plan(prep, &tally, shard);
    let doc = summary_doc(&manifest, stats, plan);
    Ok(serde_json::to_string_pretty(&doc).map_err(|e| e.to_string())? + "\n")
}

fn summary_doc(m: &Manifest, stats: summary::Statistics, charts: Vec<EventCharts>) -> SummaryDoc {
    SummaryDoc {
        format: "polhode-campaign-summary/1",
        polhode_version: m.polhode_version.clone(),
        scenario: m.scenario.clone(),
        scenario_sha256: m.scenario_sha256.clone(),
        seed: m.seed,
        runs: m.runs,
        shard: m.shard,
        run_range: m.run_range,
        runs_in_table: m.runs_in_table,
        partial: m.partial,
        status: stats.status,
        invalid_draws: stats.invalid_draws,
        percentiles: &summary::PERCENTILES,
        events: stats.events,
        charts,
        ranking: stats.ranking,
        columns: stats.columns,
        failures: stats.failures,
    }
}

fn summary_text(d: &SummaryDoc) -> String {
    let mut out = String::new();
    let f = summary::fmt;
    let _ = writeln!(
        out,
        "polhode {} Monte Carlo campaign: {} (seed {}, {} runs)",
        d.polhode_version, d.scenario, d.seed, d.runs
    );
    if let Some([k, n]) = d.shard {
        let _ = writeln!(
            out,
            "shard {k} of {n}: runs {} to {}",
            d.run_range[0],
            d.run_range[1].saturating_sub(1)
        );
    }
    if d.partial {
        let _ = writeln!(
            out,
            "PARTIAL: interrupted; {} of the {} runs of this range finished",
            d.runs_in_table,
            d.run_range[1] - d.run_range[0]
        );
    }
    let s = &d.status;
    let _ = writeln!(
        out,
        "runs: {} complete, {} stopped, {} failed, {} invalid, {} invalid_model",
        s.complete, s.stopped, s.failed, s.invalid, s.invalid_model
    );
    let v = &d.invalid_draws;
    let _ = writeln!(
        out,
        "invalid draws ({}): {}; {} run(s) left invalid",
        v.policy, v.meaning, v.invalid_runs
    );
    for r in &v.redrawn {
        let _ = writeln!(
            out,
            "  {}: {} draw(s) rejected and drawn again, in {} run(s) (rejection rate {})",
            r.column,
            r.rejected,
            r.runs,
            f(r.rejection_rate)
        );
    }
    for e in &d.events {
        let excluded = if e.excluded == 0 {
            String::new()
        } else {
            format!(
                "; {} runs excluded ({} invalid_model, {} failed or invalid)",
                e.excluded,
                e.excluded_invalid_model,
                e.excluded - e.excluded_invalid_model
            )
        };
        let _ = writeln!(
            out,
            "\nevent `{}`: reached in {} of {} usable runs{excluded}",
            e.condition, e.reached, e.runs
        );
        for b in &e.by {
            let _ = writeln!(
                out,
                "  by t = {} s: P = {} (95% CI {} to {}; {} runs)",
                f(b.t),
                f(b.probability),
                f(b.ci95[0]),
                f(b.ci95[1]),
                b.count
            );
            if e.excluded > 0 {
                let _ = writeln!(
                    out,
                    "    with the {} excluded runs as not having had it / as having had it: \
                     {} to {} (95% CI {} to {})",
                    e.excluded,
                    f(b.with_excluded[0]),
                    f(b.with_excluded[1]),
                    f(b.ci95_with_excluded[0]),
                    f(b.ci95_with_excluded[1])
                );
            }
        }
    }
    if !d.charts.is_empty() {
        let _ = writeln!(out, "\ncharts:");
        for c in &d.charts {
            let list = |stems: &[String]| {
                stems
                    .iter()
                    .map(|s| format!("{s}.svg/png"))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            let flat = if c.flat_spin.is_empty() {
                String::new()
            } else {
                format!("\n    the flat spin, also as {}", list(&c.flat_spin))
            };
            let _ = writeln!(out, "  event `{}`: {}{flat}", c.condition, list(&c.charts));
        }
    }
    if let Some(r) = &d.ranking {
        let _ = writeln!(
            out,
            "\nranked by {} ({} is worst): worst run {}, median run {}, best run {}",
            r.by, r.worst_is, r.worst, r.median, r.best
        );
    }
    let _ = writeln!(out, "\n{}", summary::stats_table(&d.columns));
    if !d.failures.is_empty() {
        let _ = writeln!(
            out,
            "failed or invalid runs (first {}):",
            summary::LISTED_FAILURES
        );
        for x in &d.failures {
            let _ = writeln!(out, "  run {} ({}): {}", x.run, x.status, x.message);
        }
    }
    out
}

/// The charts of one event, as listed in the summary (stems: add `.svg` and `.png`).
#[derive(Debug, Clone, Serialize)]
struct EventCharts {
    /// The event's condition.
    condition: String,
    /// Its table column (`t_<condition>`), which names its charts.
    column: String,
    /// Table column index.
    #[serde(skip)]
    j: usize,
    /// Histogram, CDF and scatter: `<column>_histogram`, `<column>_cdf`,
    /// `<column>_vs_transverse_rate` (stems).
    #[serde(skip)]
    charts: Vec<String>,
    /// For the flat-spin event, the same charts under their historical names
    /// (`flat_spin_time_histogram`, `flat_spin_time_cdf`,
    /// `transverse_rate_vs_flat_spin_time`); empty for the others.
    #[serde(skip)]
    flat_spin: Vec<String>,
    /// The files: each of `charts` as `.svg` and `.png`.
    files: Vec<String>,
    /// The same for `flat_spin`: the flat spin's charts under their historical names.
    flat_spin_files: Vec<String>,
}

/// `<stem>.svg` and `<stem>.png` of each stem.
fn svg_png(stems: &[String]) -> Vec<String> {
    stems
        .iter()
        .flat_map(|s| [format!("{s}.svg"), format!("{s}.png")])
        .collect()
}

/// Historical names of the flat-spin event's charts, in the order of [`EVENT_CHART_SUFFIXES`].
const FLAT_SPIN_CHARTS: [&str; 3] = [
    "flat_spin_time_histogram",
    "flat_spin_time_cdf",
    "transverse_rate_vs_flat_spin_time",
];

/// The charts a whole campaign draws: three for each event that some usable run reached, in
/// the order of the events. None for a shard (the merge draws them).
fn chart_plan(prep: &Prepared, tally: &Tally, shard: Option<[u64; 2]>) -> Vec<EventCharts> {
    if shard.is_some() {
        return Vec::new();
    }
    prep.event_conditions
        .iter()
        .enumerate()
        .filter(|(k, _)| tally.event_reached(*k))
        .map(|(k, condition)| {
            let j = prep.event_start + k;
            let column = prep.columns[j].clone();
            let charts: Vec<String> = EVENT_CHART_SUFFIXES
                .iter()
                .map(|s| format!("{column}{s}"))
                .collect();
            let flat_spin = if prep.primary_event == Some(j) {
                FLAT_SPIN_CHARTS.map(String::from).to_vec()
            } else {
                Vec::new()
            };
            EventCharts {
                condition: condition.clone(),
                column,
                j,
                files: svg_png(&charts),
                flat_spin_files: svg_png(&flat_spin),
                charts,
                flat_spin,
            }
        })
        .collect()
}

/// Draws every event's charts as planned in `doc`.
fn charts(
    dir: &mut OwnedDir,
    prep: &Prepared,
    runs: &dyn Runs,
    doc: &SummaryDoc,
) -> Result<Vec<PathBuf>, String> {
    let mut data: Vec<EventChartData> = doc
        .charts
        .iter()
        .filter_map(|p| EventChartData::new(doc, p))
        .collect();
    runs.scan(&mut |r| {
        if r.ok {
            for d in &mut data {
                d.add(r.values[prep.transverse_column], r.values[d.j]);
            }
        }
    })?;
    let mut out = Vec::new();
    for (p, d) in doc.charts.iter().zip(&data) {
        let drawn = d.charts(prep, !p.flat_spin.is_empty());
        for (k, chart) in drawn.iter().enumerate() {
            let mut stems = Vec::new();
            for name in std::iter::once(&p.charts[k]).chain(p.flat_spin.get(k)) {
                dir.file(&format!("{name}.svg"))?;
                dir.file(&format!("{name}.png"))?;
                stems.push(dir.dir().join(name));
            }
            let stems: Vec<&Path> = stems.iter().map(PathBuf::as_path).collect();
            out.extend(
                crate::plot::svg_and_png_as(chart, &stems)
                    .map_err(|e| format!("cannot write {e}"))?,
            );
        }
    }
    Ok(out)
}

/// Up to this many event times are drawn as the CDF's exact staircase; beyond, the CDF is
/// drawn through [`CDF_BINS`] bins.
const CDF_EXACT_POINTS: usize = 4096;
/// Bins of a CDF drawn from more than [`CDF_EXACT_POINTS`] times.
const CDF_BINS: usize = 1024;
/// The scatter chart shows at most twice this many runs: past that, every other run shown
/// is dropped, and so on (every 2ᵏ-th run, in run order).
const SCATTER_POINTS: usize = 4096;

/// What one event's charts are drawn from, gathered in one pass over the runs in a memory
/// that does not grow with their number.
struct EventChartData {
    /// Event column.
    j: usize,
    /// Usable runs, and those in which the event happened.
    usable: usize,
    reached: usize,
    /// Earliest and latest event time (s).
    lo: f64,
    hi: f64,
    /// Histogram counts over [lo, hi].
    counts: Vec<usize>,
    /// Every event time, sorted once gathered (for at most [`CDF_EXACT_POINTS`] times), or
    /// the CDF's bin counts over [lo, hi].
    times: Vec<f64>,
    cdf_counts: Vec<usize>,
    /// Scatter points (initial transverse rate, time in minutes), every `stride`-th run with
    /// both values; `seen` counts those runs.
    points: Vec<(f64, f64)>,
    stride: usize,
    seen: usize,
}

impl EventChartData {
    /// The data of planned chart `p`, with the extremes and quartiles from the summary.
    fn new(doc: &SummaryDoc, p: &EventCharts) -> Option<Self> {
        let e = doc.events.iter().find(|e| e.column == p.column)?;
        let c = doc.columns.iter().find(|c| c.column == p.column)?;
        // Histogram: bins by the Freedman–Diaconis rule, 10 to 60 of them.
        let (lo, hi) = (c.min, c.max);
        let iqr = c.percentiles[4] - c.percentiles[2];
        debug_assert_eq!(
            (summary::PERCENTILES[2], summary::PERCENTILES[4]),
            (25.0, 75.0)
        );
        let width = 2.0 * iqr / (c.count as f64).cbrt();
        let bins = if width > 0.0 && hi > lo {
            (((hi - lo) / width).ceil() as usize).clamp(10, 60)
        } else {
            10
        };
        let exact = e.reached <= CDF_EXACT_POINTS;
        Some(Self {
            j: p.j,
            usable: e.runs,
            reached: e.reached,
            lo,
            hi,
            counts: vec![0; bins],
            times: Vec::new(),
            cdf_counts: if exact { Vec::new() } else { vec![0; CDF_BINS] },
            points: Vec::new(),
            stride: 1,
            seen: 0,
        })
    }

    /// The bin of `t` among `bins` over [lo, hi].
    fn bin(&self, t: f64, bins: usize) -> usize {
        let span = if self.hi > self.lo {
            self.hi - self.lo
        } else {
            1.0
        };
        ((((t - self.lo) / span) * bins as f64).floor() as usize).min(bins - 1)
    }

    /// Counts a usable run with initial transverse rate `rate` and event time `t`.
    fn add(&mut self, rate: Option<f64>, t: Option<f64>) {
        let Some(t) = t else { return };
        let b = self.bin(t, self.counts.len());
        self.counts[b] += 1;
        if self.cdf_counts.is_empty() {
            self.times.push(t);
        } else {
            let b = self.bin(t, CDF_BINS);
            self.cdf_counts[b] += 1;
        }
        if let Some(rate) = rate {
            if self.seen.is_multiple_of(self.stride) {
                self.points.push((rate, t / 60.0));
                if self.points.len() == 2 * SCATTER_POINTS {
                    self.points = self.points.iter().copied().step_by(2).collect();
                    self.stride *= 2;
                }
            }
            self.seen += 1;
        }
    }

    /// Histogram and CDF of the event time, and initial transverse rate against it (titled
    /// as the flat spin when `flat_spin`).
    fn charts(&self, prep: &Prepared, flat_spin: bool) -> Vec<Chart> {
        let condition = &prep.event_conditions[self.j - prep.event_start];
        let (n, reached, lo, hi) = (self.usable, self.reached, self.lo, self.hi);
        let minutes = |t: f64| t / 60.0;
        let mut out = Vec::new();

        let bins = self.counts.len();
        let span = if hi > lo { hi - lo } else { 1.0 };
        let mut outline = vec![(minutes(lo), 0.0)];
        for (b, c) in self.counts.iter().enumerate() {
            let x0 = minutes(lo + span * b as f64 / bins as f64);
            let x1 = minutes(lo + span * (b + 1) as f64 / bins as f64);
            outline.push((x0, *c as f64));
            outline.push((x1, *c as f64));
        }
        outline.push((minutes(lo + span), 0.0));
        let title = if flat_spin {
            format!("Time to flat spin ({condition}): {reached} of {n} runs")
        } else {
            format!("Time to `{condition}`: {reached} of {n} runs")
        };
        let mut h = Chart::new(title, "time (min)", "runs per bin");
        h.x_range = Some((minutes(lo - 0.05 * span), minutes(hi + 0.05 * span)));
        let tallest = self.counts.iter().copied().max().unwrap_or(1) as f64;
        h.y_range = Some((0.0, 1.1 * tallest));
        h.series.push(Series::new("", outline, Style::Line));
        out.push(h);

        // CDF over all usable runs: it ends below 1 when some runs never reach the event.
        // From t = 0 to the end of the scenario, so both ends of the staircase are visible.
        let mut cdf = vec![(0.0, 0.0)];
        if self.cdf_counts.is_empty() {
            let mut times = self.times.clone();
            times.sort_by(f64::total_cmp);
            for (k, t) in times.iter().enumerate() {
                cdf.push((minutes(*t), k as f64 / n as f64));
                cdf.push((minutes(*t), (k + 1) as f64 / n as f64));
            }
        } else {
            cdf.push((minutes(lo), 0.0));
            let mut below = 0;
            for (b, c) in self.cdf_counts.iter().enumerate() {
                below += c;
                let edge = lo + span * (b + 1) as f64 / CDF_BINS as f64;
                cdf.push((minutes(edge), below as f64 / n as f64));
            }
        }
        cdf.push((
            minutes(prep.scenario.duration.max(hi)),
            reached as f64 / n as f64,
        ));
        let title = if flat_spin {
            format!("Probability of a flat spin ({condition}) by time")
        } else {
            format!("Probability of `{condition}` by time")
        };
        let mut c = Chart::new(title, "time (min)", "fraction of runs");
        c.y_range = Some((0.0, 1.05));
        c.series.push(Series::new("", cdf, Style::Line));
        out.push(c);

        let shown = if self.stride > 1 {
            format!(" (1 in {} of {} runs shown)", self.stride, self.seen)
        } else {
            String::new()
        };
        let mut s = if flat_spin {
            Chart::new(
                format!("Initial transverse rate against time to flat spin{shown}"),
                "initial transverse rate (rad/s)",
                "time to flat spin (min)",
            )
        } else {
            Chart::new(
                format!("Initial transverse rate against time to `{condition}`{shown}"),
                "initial transverse rate (rad/s)",
                "time of the event (min)",
            )
        };
        s.series
            .push(Series::new("", self.points.clone(), Style::Markers));
        out.push(s);
        out
    }
}

/// `campaign.mcap`: the worst, median and best runs re-run with full logging under
/// `/worst`, `/median`, `/best`, with the summary attached. With `threads` ≥ 2 the runs are
/// integrated on a thread of their own while this one writes them (through a
/// [`sim::Relay`]); the file is the same, byte for byte.
fn trajectories(
    path: &Path,
    prep: &Prepared,
    ranking: &Ranking,
    summary_json: &str,
    interrupt: &AtomicBool,
    threads: usize,
) -> Result<Option<PathBuf>, String> {
    let picks = [
        ("worst", ranking.worst),
        ("median", ranking.median),
        ("best", ranking.best),
    ];
    let mut scenarios = Vec::new();
    for (_, i) in picks {
        scenarios.push(prep.build_run(i).map_err(|e| format!("run {i}: {e}"))?.0);
    }
    let control = || Control {
        interrupt,
        progress: None,
    };
    let logged = if threads >= 2 {
        std::thread::scope(|scope| {
            let (to_writer, from_runs) = std::sync::mpsc::sync_channel(RELAYED_BATCHES);
            let runs = &scenarios;
            scope.spawn(move || {
                for sc in runs {
                    let mut relay = sim::Relay::new(to_writer.clone());
                    let outcome = sim::run(sc, &mut relay, control());
                    let go_on = matches!(&outcome, Ok(o) if o.status != sim::Status::Interrupted);
                    if !relay.finish(outcome) || !go_on {
                        break;
                    }
                }
            });
            // `from_runs` is dropped on leaving, before the scope waits for the runs: a run
            // still sending then stops.
            log_picks(path, &picks, &scenarios, &mut |_, logger| {
                sim::receive_run(&from_runs, logger)
            })
        })
    } else {
        log_picks(path, &picks, &scenarios, &mut |k, logger| {
            sim::run(&scenarios[k], logger, control())
        })
    };
    let Some((l, mut meta, mut attachments)) = logged? else {
        return Ok(None);
    };
    meta.insert("version".into(), env!("CARGO_PKG_VERSION").into());
    meta.insert("scenario".into(), prep.scenario.name.clone());
    meta.insert("seed".into(), prep.campaign.seed.to_string());
    meta.insert("runs".into(), prep.campaign.runs.to_string());
    meta.insert("ranked_by".into(), ranking.by.clone());
    attachments.push(Attachment {
        name: "summary.json".into(),
        media_type: "application/json".into(),
        data: summary_json.as_bytes().to_vec(),
    });
    attachments.push(Attachment {
        name: "scenario.yaml".into(),
        media_type: "application/yaml".into(),
        data: prep.scenario.source.as_bytes().to_vec(),
    });
    l.finish_with("polhode_campaign", meta, attachments)
        .map(Some)
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// Batches of records a [`sim::Relay`] may send ahead of the MCAP writer.
const RELAYED_BATCHES: usize = 16;

/// What [`log_picks`] leaves for the file's end: the logger, its metadata and attachments.
type Picked<'a> = (McapLogger<'a>, BTreeMap<String, String>, Vec<Attachment>);

/// Writes the `picks` (label, run index) into `path`, one after the other, the sink calls of
/// pick `k` (whose scenario is `scenarios[k]`) coming from `run(k, logger)`. `None` when a
/// run was interrupted (the temporary file is removed).
fn log_picks<'a>(
    path: &Path,
    picks: &[(&str, u64)],
    scenarios: &'a [scenario::Scenario],
    run: &mut dyn FnMut(usize, &mut dyn sim::Sink) -> std::io::Result<sim::Outcome>,
) -> Result<Option<Picked<'a>>, String> {
    let fail = |e: std::io::Error| format!("cannot write {}: {e}", path.display());
    let mut logger: Option<McapLogger> = None;
    let mut meta = BTreeMap::new();
    let mut attachments = Vec::new();
    for (k, ((label, i), sc)) in picks.iter().zip(scenarios).enumerate() {
        let prefix = format!("/{label}");
        let mut l = match logger.take() {
            None => McapLogger::create_prefixed(path, sc, sc.omega0.norm(), &prefix),
            Some(prev) => prev.continue_with(sc, sc.omega0.norm(), &prefix),
        }
        .map_err(fail)?;
        let outcome = run(k, &mut l).map_err(fail)?;
        if outcome.status == crate::sim::Status::Interrupted {
            // Dropping the logger removes its temporary file.
            return Ok(None);
        }
        l.end_run(&outcome).map_err(fail)?;
        meta.insert(format!("{label}_run"), i.to_string());
        meta.insert(
            format!("{label}_status"),
            outcome.status.label().to_string(),
        );
        attachments.push(Attachment {
            name: format!("{label}.scenario.json"),
            media_type: "application/json".into(),
            data: sc.source.as_bytes().to_vec(),
        });
        logger = Some(l);
    }
    match logger {
        Some(l) => Ok(Some((l, meta, attachments))),
        None => Err("no run to log".into()),
    }
}

/// One shard output read back for `merge`.
struct ShardOutput {
    dir: PathBuf,
    manifest: Manifest,
    scenario: String,
}

/// Hex SHA-256 of the file `path`, read a block at a time.
fn file_sha256(path: &Path) -> std::io::Result<String> {
    use sha2::{Digest, Sha256};
    let mut input = BufReader::with_capacity(1 << 20, File::open(path)?);
    let mut hash = Sha256::new();
    let mut block = vec![0u8; 1 << 20];
    loop {
        let n = input.read(&mut block)?;
        if n == 0 {
            break;
        }
        hash.update(&block[..n]);
    }
    Ok(super::hex(&hash.finalize()))
}

fn read_shard(dir: &Path) -> Result<ShardOutput, String> {
    let d = dir.display();
    for name in ["campaign.json", "runs.csv", "scenario.yaml"] {
        crate::outputs::note_input(&dir.join(name));
    }
    let manifest_text = std::fs::read_to_string(dir.join("campaign.json"))
        .map_err(|e| format!("{d}: no finished campaign output here (campaign.json: {e})"))?;
    let manifest: Manifest = serde_json::from_str(&manifest_text)
        .map_err(|e| format!("{d}/campaign.json is not a polhode campaign manifest: {e}"))?;
    if manifest.format != MANIFEST_FORMAT {
        return Err(format!(
            "{d}/campaign.json has format `{}`; expected `{MANIFEST_FORMAT}`",
            manifest.format
        ));
    }
    if let Some([k, n]) = manifest.shard
        && !(1 <= k && k <= n && n <= manifest.runs)
    {
        return Err(format!(
            "{d}/campaign.json names shard {k} of {n} of {} runs, which does not exist",
            manifest.runs
        ));
    }
    let [start, end] = manifest.run_range;
    if start > end || end > manifest.runs {
        return Err(format!(
            "{d}/campaign.json has the impossible run range [{start}, {end}) of {} runs",
            manifest.runs
        ));
    }
    let csv_sha256 =
        file_sha256(&dir.join("runs.csv")).map_err(|e| format!("{d}/runs.csv: {e}"))?;
    if csv_sha256 != manifest.runs_csv_sha256 {
        return Err(format!(
            "{d}/runs.csv does not match its manifest (truncated or altered after it was \
             written); re-run this shard"
        ));
    }
    let scenario = std::fs::read_to_string(dir.join("scenario.yaml"))
        .map_err(|e| format!("{d}/scenario.yaml: {e}"))?;
    if sha256_hex(scenario.as_bytes()) != manifest.scenario_sha256 {
        return Err(format!(
            "{d}/scenario.yaml does not match its manifest (altered after it was written)"
        ));
    }
    Ok(ShardOutput {
        dir: dir.to_path_buf(),
        manifest,
        scenario,
    })
}

/// Every shard of one campaign, checked by [`check_shards`] and ready to merge.
pub struct ShardSet {
    prep: Prepared,
    /// The shards by index (1-based), and their count.
    shards: BTreeMap<u64, ShardOutput>,
    count: u64,
}

/// Checks that `dirs` hold every shard of one campaign exactly once, unaltered and finished,
/// reading every row of their tables (one at a time); nothing is written.
pub fn check_shards(dirs: &[PathBuf]) -> Result<ShardSet, String> {
    if dirs.is_empty() {
        return Err("expected the shard directories to merge".into());
    }
    let shards: Vec<ShardOutput> = dirs
        .iter()
        .map(|d| read_shard(d))
        .collect::<Result<_, _>>()?;
    let first = &shards[0];
    let m0 = &first.manifest;
    let Some([_, n]) = m0.shard else {
        return Err(format!(
            "{} holds a whole campaign, not a shard; there is nothing to merge",
            first.dir.display()
        ));
    };
    for s in &shards {
        let m = &s.manifest;
        let d = s.dir.display();
        let mismatch = |what: &str, a: &dyn std::fmt::Display, b: &dyn std::fmt::Display| {
            format!(
                "{d} does not belong with {}: {what} {a} differs from {b}",
                first.dir.display()
            )
        };
        if m.polhode_version != m0.polhode_version {
            return Err(mismatch(
                "polhode version",
                &m.polhode_version,
                &m0.polhode_version,
            ));
        }
        if m.build_id != m0.build_id {
            return Err(mismatch("polhode build", &m.build_id, &m0.build_id));
        }
        if m.build_id != BUILD_ID {
            return Err(format!(
                "{d} was written by another polhode build ({}) than this one ({BUILD_ID}); \
                 merge with the binary that ran the shards",
                m.build_id
            ));
        }
        if m.scenario_sha256 != m0.scenario_sha256 {
            return Err(mismatch(
                "scenario (SHA-256)",
                &m.scenario_sha256,
                &m0.scenario_sha256,
            ));
        }
        if m.seed != m0.seed {
            return Err(mismatch("seed", &m.seed, &m0.seed));
        }
        if m.runs != m0.runs {
            return Err(mismatch("run count", &m.runs, &m0.runs));
        }
        if m.columns != m0.columns {
            // Name what differs: the count, or the first column that is not the same.
            let (a, b) = match m.columns.iter().zip(&m0.columns).position(|(a, b)| a != b) {
                Some(k) if m.columns.len() == m0.columns.len() => (
                    format!("column {} `{}`", k + 1, m.columns[k]),
                    format!("`{}`", m0.columns[k]),
                ),
                _ => (
                    format!("{} columns", m.columns.len()),
                    format!("{}", m0.columns.len()),
                ),
            };
            return Err(mismatch("table", &a, &b));
        }
        match m.shard {
            Some([_, n2]) if n2 == n => {}
            Some([_, n2]) => return Err(mismatch("shard count", &n2, &n)),
            None => return Err(format!("{d} holds a whole campaign, not a shard")),
        }
        if m.partial {
            return Err(format!(
                "{d} is partial (interrupted: {} of {} runs finished); re-run that shard",
                m.runs_in_table,
                m.run_range[1] - m.run_range[0]
            ));
        }
    }
    let mut by_index: BTreeMap<u64, &ShardOutput> = BTreeMap::new();
    for s in &shards {
        let k = s.manifest.shard.map_or(0, |[k, _]| k);
        if let Some(other) = by_index.insert(k, s) {
            return Err(format!(
                "shard {k} of {n} is given twice: {} and {}",
                other.dir.display(),
                s.dir.display()
            ));
        }
    }
    let missing: Vec<String> = (1..=n)
        .filter(|k| !by_index.contains_key(k))
        .map(|k| k.to_string())
        .collect();
    if !missing.is_empty() {
        return Err(format!(
            "shard(s) {} of {n} are missing; merge needs all {n}",
            missing.join(", ")
        ));
    }
    let scenario_path = first.dir.join("scenario.yaml");
    let sc = scenario::parse(
        &scenario_path,
        first.scenario.clone(),
        &Overrides::default(),
    )
    .map_err(|e| format!("the shards' scenario no longer loads: {e}"))?;
    let prep = Prepared::new(
        sc,
        &scenario_path.display().to_string(),
        Some(m0.runs),
        Some(m0.seed),
    )
    .and_then(|p| p.with_method(m0.method.clone()))
    .map_err(|e| format!("the shards' campaign no longer loads: {e}"))?;
    if prep.columns != m0.columns {
        return Err("the shards were written with other table columns".into());
    }
    let count = n;
    let shards: BTreeMap<u64, ShardOutput> = shards
        .into_iter()
        .map(|s| (s.manifest.shard.map_or(0, |[k, _]| k), s))
        .collect();
    let set = ShardSet {
        prep,
        shards,
        count,
    };
    set.read_rows(&mut |_| Ok(()))?;
    Ok(set)
}

impl ShardSet {
    /// Hands every shard's rows to `each`, in run order, checking that each shard holds
    /// exactly its range's runs. An error of `each` is returned as it is.
    fn read_rows(&self, each: &mut dyn FnMut(Row) -> Result<(), String>) -> Result<(), String> {
        let runs = self.prep.campaign.runs;
        for (k, s) in &self.shards {
            let d = s.dir.display();
            let range = shard_range(runs, *k, self.count);
            let wrong = || {
                format!(
                    "{d}/runs.csv does not hold exactly runs {} to {} of shard {k}",
                    range.start,
                    range.end.saturating_sub(1)
                )
            };
            if s.manifest.run_range != [range.start, range.end] {
                return Err(wrong());
            }
            let file =
                File::open(s.dir.join("runs.csv")).map_err(|e| format!("{d}/runs.csv: {e}"))?;
            let mut next = range.start;
            // Errors of the row check and of `each` pass through unchanged; only the reader's
            // own get the file's name.
            let mut passed = None;
            let read = table::read_csv(BufReader::new(file), &self.prep.columns, |row| {
                let result = if row.run != next || next >= range.end {
                    Err(wrong())
                } else {
                    next += 1;
                    each(row)
                };
                result.map_err(|e| {
                    passed = Some(e);
                    String::new()
                })
            });
            if let Some(e) = passed {
                return Err(e);
            }
            read.map_err(|e| format!("{d}/runs.csv: {e}"))?;
            if next != range.end {
                return Err(wrong());
            }
        }
        Ok(())
    }

    /// Writes the whole campaign's outputs into `out` ([`claim`]ed; see [`CampaignWriter::finish`] for
    /// `interrupt`), reading the shards' rows once more. Returns what was written and the
    /// number of runs.
    pub fn write(&self, out: OwnedDir, interrupt: &AtomicBool) -> Result<(Written, u64), String> {
        let mut writer = CampaignWriter::create(out, &self.prep, None)?;
        self.read_rows(&mut |row| writer.push(row))?;
        let runs = writer.rows();
        Ok((writer.finish(false, interrupt)?, runs))
    }
}
