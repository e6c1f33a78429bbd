//! One run on a worker thread: the samples collected column by column into one buffer, the
//! log written alongside, the products handed back.

use polhode::log::{McapLogger, samples};
use polhode::model::{Observation, Spacecraft};
use polhode::orbit::Orbit;
use polhode::scenario::{self, Overrides};
use polhode::sim::{self, Control, EventRecord, Outcome, Reference, Sink, Warning};
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// Output samples stored column-major in one buffer: column k holds `cap` slots starting at
/// `k * cap`, of which the first `len` are filled. Handed to numpy as one `(width, n)` array
/// whose rows are the columns, so the telemetry, `t`, `omega` and `q` are views of a single
/// allocation, made by Rust and owned by numpy without a copy.
pub(crate) struct ColumnStore {
    pub(crate) width: usize,
    pub(crate) cap: usize,
    pub(crate) len: usize,
    pub(crate) data: Vec<f64>,
}

/// Samples reserved up front at most; a longer run grows the buffer by doubling.
pub(crate) const MAX_RESERVED_SAMPLES: usize = 1 << 21;

impl ColumnStore {
    /// Room for `samples` samples (at most [`MAX_RESERVED_SAMPLES`]); the zeroed buffer is
    /// committed by the OS page by page as samples arrive. `Err` when it cannot be allocated.
    fn new(width: usize, samples: usize) -> Result<Self, String> {
        let cap = samples.clamp(1, MAX_RESERVED_SAMPLES);
        Ok(ColumnStore {
            width,
            cap,
            len: 0,
            data: zeroed(width * cap)?,
        })
    }

    fn push(&mut self, row: &[f64]) -> std::io::Result<()> {
        if self.len == self.cap {
            let cap = self.cap * 2;
            let mut data = zeroed(self.width * cap)
                .map_err(|m| std::io::Error::new(std::io::ErrorKind::OutOfMemory, m))?;
            for k in 0..self.width {
                data[k * cap..k * cap + self.len]
                    .copy_from_slice(&self.data[k * self.cap..k * self.cap + self.len]);
            }
            self.data = data;
            self.cap = cap;
        }
        for (k, v) in row.iter().take(self.width).enumerate() {
            self.data[k * self.cap + self.len] = *v;
        }
        self.len += 1;
        Ok(())
    }

    /// The filled columns back to back (`width * len` values), the buffer shrunk to fit.
    fn into_columns(mut self) -> Vec<f64> {
        if self.len < self.cap {
            for k in 1..self.width {
                let from = k * self.cap;
                self.data.copy_within(from..from + self.len, k * self.len);
            }
            self.data.truncate(self.width * self.len);
            self.data.shrink_to_fit();
        }
        self.data
    }
}

/// `n` zeros, or the allocation failure as a message (`try_reserve`: never an abort).
fn zeroed(n: usize) -> Result<Vec<f64>, String> {
    let mut v = Vec::new();
    v.try_reserve_exact(n)
        .map_err(|e| polhode::resources::reserve_failed("the run's samples", n, &e))?;
    v.resize(n, 0.0);
    Ok(v)
}

/// Keeps every output sample's telemetry and effector fields (the columns of
/// `polhode run --csv`) and forwards everything to the MCAP log when there is one.
pub(crate) struct Collector<'a> {
    pub(crate) spacecraft: &'a Spacecraft,
    /// The scenario's orbit, if any: the attitude relative to LVLH is then collected too.
    pub(crate) orbit: Option<&'a Orbit>,
    pub(crate) store: ColumnStore,
    /// The current sample's values (scratch).
    pub(crate) row: Vec<f64>,
    /// The log, when `log=` names one.
    pub(crate) log: Option<McapLogger<'a>>,
}

impl Sink for Collector<'_> {
    fn sample(&mut self, o: &Observation, y: &[f64], inv: &Reference) -> std::io::Result<()> {
        samples::fill_row(&mut self.row, self.spacecraft, self.orbit, o, y, inv);
        self.store.push(&self.row)?;
        match self.log.as_mut() {
            Some(log) => log.sample(o, y, inv),
            None => Ok(()),
        }
    }

    fn event(&mut self, e: &EventRecord, o: &Observation) -> std::io::Result<()> {
        match self.log.as_mut() {
            Some(log) => log.event(e, o),
            None => Ok(()),
        }
    }

    fn warning(&mut self, w: &Warning) -> std::io::Result<()> {
        match self.log.as_mut() {
            Some(log) => log.warning(w),
            None => Ok(()),
        }
    }
}

/// What a finished run hands back to the calling thread.
pub(crate) struct Products {
    /// Column names: the `/telemetry` fields, then `<effector>.<field>`, then with an orbit
    /// the attitude relative to LVLH (`polhode::log::orbit::ATTITUDE_FIELDS`).
    pub(crate) names: Vec<String>,
    /// Each column's unit (`rad/s`; `""` when it has none), as the `--csv` header gives it.
    pub(crate) units: Vec<String>,
    /// Whether the last columns are the attitude relative to LVLH (the scenario has an orbit).
    pub(crate) has_lvlh: bool,
    /// The columns back to back, `n` values each.
    pub(crate) columns: Vec<f64>,
    /// Output samples.
    pub(crate) n: usize,
    pub(crate) outcome: Outcome,
    pub(crate) summary_json: String,
}

/// Why a run produced nothing.
pub(crate) enum RunError {
    /// The scenario with the overrides does not validate.
    Scenario(scenario::ScenarioError),
    /// The log would be too large (the CLI's message).
    LogTooLarge(String),
    /// The log would be written over the scenario's file ([`polhode::outputs::Plan`]).
    Refused(String),
    /// The log could not be created, written or finished.
    Io(String),
    /// The samples would not fit in the memory limit, or could not be allocated.
    Memory(String),
}

/// Validates with `overrides` and runs, on the worker thread (no Python here).
pub(crate) fn execute(
    path: &Path,
    source: String,
    overrides: &Overrides,
    log: bool,
    interrupt: &AtomicBool,
) -> Result<Products, RunError> {
    let s = scenario::parse(path, source, overrides).map_err(RunError::Scenario)?;
    if log {
        let mut plan = polhode::outputs::Plan::new();
        if path != Path::new(crate::TEXT_SOURCE_NAME) && path != Path::new(crate::DICT_SOURCE_NAME)
        {
            plan.input("the scenario", path);
        }
        plan.output("log=", &s.mcap_path)
            .check()
            .map_err(RunError::Refused)?;
    }
    let (names, units): (Vec<String>, Vec<String>) =
        samples::columns(&s.spacecraft, s.orbit.as_deref())
            .into_iter()
            .map(|c| (c.name, c.unit))
            .unzip();
    // Known before anything is allocated or integrated: refused with the numbers.
    polhode::resources::check_sample_memory(
        &format!("{}: the run's samples", s.path.display()),
        s.duration,
        s.output_rate,
        names.len(),
    )
    .map_err(RunError::Memory)?;
    let logger = if log {
        let mut logger = McapLogger::create(&s.mcap_path, &s, s.omega0.norm()).map_err(|e| {
            RunError::Io(format!(
                "cannot write the log to {}: {e}",
                s.mcap_path.display()
            ))
        })?;
        let estimate_mb = logger.estimate_bytes(&s) / 1e6;
        if estimate_mb > s.max_log_mb {
            logger.abandon();
            return Err(RunError::LogTooLarge(format!(
                "{}: the log would be about {estimate_mb:.3e} MB before compression, above \
                 the limit of {} MB; lower `output.rate`, shorten the run, or raise \
                 `output.max_log_mb`",
                s.path.display(),
                s.max_log_mb
            )));
        }
        Some(logger)
    } else {
        None
    };
    // Samples at k / rate up to the end, and the last instant.
    let expected = polhode::resources::sample_count(s.duration, s.output_rate) as usize;
    let store = match ColumnStore::new(names.len(), expected) {
        Ok(store) => store,
        Err(m) => {
            if let Some(l) = logger {
                l.abandon();
            }
            return Err(RunError::Memory(m));
        }
    };
    let mut collector = Collector {
        spacecraft: &s.spacecraft,
        orbit: s.orbit.as_deref(),
        store,
        row: Vec::with_capacity(names.len()),
        log: logger,
    };
    let control = Control {
        interrupt,
        progress: None,
    };
    let outcome = match sim::run(&s, &mut collector, control) {
        Ok(outcome) => outcome,
        Err(e) => {
            if let Some(l) = collector.log.take() {
                l.abandon();
            }
            if e.kind() == std::io::ErrorKind::OutOfMemory {
                return Err(RunError::Memory(e.to_string()));
            }
            return Err(RunError::Io(format!(
                "writing the log failed: {e}; no log was kept"
            )));
        }
    };
    let written = match collector.log.take() {
        Some(l) => Some(
            l.finish(&s, &s.method.describe(), &outcome)
                .map_err(|e| RunError::Io(format!("finishing the log failed: {e}")))?,
        ),
        None => None,
    };
    let summary_json = polhode::cli::summary_json(&s, &outcome, written.as_deref());
    let n = collector.store.len;
    Ok(Products {
        names,
        units,
        has_lvlh: s.orbit.is_some(),
        columns: collector.store.into_columns(),
        n,
        outcome,
        summary_json,
    })
}
