//! `polhode._polhode`: the Python extension module of polhode (re-exported by the `polhode`
//! package, `python/polhode/__init__.py`).
//!
//! Scenarios are validated by the same loader as the CLI (`polhode::scenario`; a dict is
//! written out as YAML by `polhode/_dict.py` first), and runs go through the same run loop
//! (`polhode::sim::run`), the same `--summary` document (`polhode::cli::summary_json`), the
//! same sample-table columns (`polhode::log::samples::columns`), the same linearisation
//! (`polhode::cli::linearize_json`) and the same campaign code (`polhode::montecarlo`), so
//! Python gets the CLI's numbers bit for bit. Long work releases the GIL and goes on a worker
//! thread; the calling thread wakes every [`SIGNAL_POLL`] to check for Ctrl-C (and to report
//! a campaign's progress), and on one sets the work's interrupt flag and raises
//! `KeyboardInterrupt`. No Rust panic reaches Python: it becomes a `RuntimeError`.
//!
//! Units are SI throughout (s, rad/s, N m s, J); quaternions are scalar-first `(w, x, y, z)`
//! and map body vectors to inertial ones (docs/conventions.md).

use numpy::{IntoPyArray, PyArrayMethods};
use polhode::log::{McapLogger, samples, telemetry};
use polhode::model::{HubState, Observation, Spacecraft};
use polhode::montecarlo;
use polhode::scenario::{self, Overrides};
use polhode::sim::{self, Control, EventRecord, Outcome, Reference, Sink, Warning};
use pyo3::create_exception;
use pyo3::exceptions::{PyImportError, PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList, PySlice};
use std::any::Any;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Condvar, Mutex};
use std::time::Duration;

/// How often a waiting run checks for Ctrl-C (and lets other Python threads run meanwhile).
const SIGNAL_POLL: Duration = Duration::from_millis(100);

/// The name a scenario given as text (`loads`) goes by in messages and `ScenarioError.path`.
const TEXT_SOURCE_NAME: &str = "<string>";

/// The name a scenario given as a dict (`Scenario.from_dict`) goes by.
const DICT_SOURCE_NAME: &str = "<dict>";

create_exception!(
    polhode,
    ScenarioError,
    PyValueError,
    "A scenario that does not validate: the CLI's message, with `.path`, `.line` and \
     `.column` (1-based, None when unknown), `.field` (dotted path such as `body.inertia`, \
     None when unknown) and `.message` (what is wrong and what was expected)."
);

/// The Python `ScenarioError` for a core validation error, its location as attributes.
fn scenario_error(py: Python<'_>, error: &scenario::ScenarioError) -> PyErr {
    let err = ScenarioError::new_err(error.to_string());
    let value = err.value(py);
    let located = value
        .setattr("path", error.file.display().to_string())
        .and_then(|()| value.setattr("line", error.line))
        .and_then(|()| value.setattr("column", error.column))
        .and_then(|()| value.setattr("field", error.field.clone()))
        .and_then(|()| value.setattr("message", error.message.clone()));
    match located {
        Ok(()) => err,
        Err(e) => e,
    }
}

/// The text of a panic's payload.
fn panic_text(payload: &(dyn Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

/// A `RuntimeError` for a Rust panic, asking for a report.
fn internal_error(what: &str, payload: &(dyn Any + Send)) -> PyErr {
    PyRuntimeError::new_err(format!(
        "polhode internal error while {what}: {}; please report it with the scenario",
        panic_text(payload)
    ))
}

/// A scenario, validated; `run` validates it again with its overrides.
#[pyclass(frozen, module = "polhode", name = "Scenario")]
struct PyScenario {
    /// Where it came from (`<string>` for `loads`).
    path: PathBuf,
    /// The YAML text.
    source: String,
    /// `name:`.
    name: String,
    /// Simulated duration (s).
    duration: f64,
    /// The integration method's name (`dopri5`, …; what `auto` picked).
    method: String,
}

impl PyScenario {
    fn from_core(s: scenario::Scenario) -> Self {
        PyScenario {
            name: s.name.clone(),
            duration: s.duration,
            method: s.method.name().to_string(),
            path: s.path,
            source: s.source,
        }
    }
}

/// Validates `path`'s text (or `source` when given) without overrides; panics become errors.
fn validate(py: Python<'_>, path: &Path, source: Option<String>) -> PyResult<PyScenario> {
    let defaults = Overrides::default();
    let parsed = catch_unwind(AssertUnwindSafe(|| match source {
        Some(text) => scenario::parse(path, text, &defaults),
        None => scenario::load(path, &defaults),
    }))
    .map_err(|p| internal_error("validating the scenario", p.as_ref()))?;
    match parsed {
        Ok(s) => Ok(PyScenario::from_core(s)),
        Err(e) => Err(scenario_error(py, &e)),
    }
}

/// Reads and validates a scenario file (YAML).
///
/// Raises `ScenarioError` (a `ValueError`) with the CLI's message when it does not validate.
#[pyfunction]
fn load(py: Python<'_>, path: PathBuf) -> PyResult<PyScenario> {
    validate(py, &path, None)
}

/// Validates a scenario given as YAML text; messages name it `<string>`.
///
/// Raises `ScenarioError` (a `ValueError`) with the CLI's message when it does not validate.
#[pyfunction]
fn loads(py: Python<'_>, yaml_text: String) -> PyResult<PyScenario> {
    validate(py, Path::new(TEXT_SOURCE_NAME), Some(yaml_text))
}

/// Output samples stored column-major in one buffer: column k holds `cap` slots starting at
/// `k * cap`, of which the first `len` are filled. Handed to numpy as one `(width, n)` array
/// whose rows are the columns, so the telemetry, `t`, `omega` and `q` are views of a single
/// allocation, made by Rust and owned by numpy without a copy.
struct ColumnStore {
    width: usize,
    cap: usize,
    len: usize,
    data: Vec<f64>,
}

/// Samples reserved up front at most; a longer run grows the buffer by doubling.
const MAX_RESERVED_SAMPLES: usize = 1 << 21;

impl ColumnStore {
    /// Room for `samples` samples (at most [`MAX_RESERVED_SAMPLES`]); the zeroed buffer is
    /// committed by the OS page by page as samples arrive.
    fn new(width: usize, samples: usize) -> Self {
        let cap = samples.clamp(1, MAX_RESERVED_SAMPLES);
        ColumnStore {
            width,
            cap,
            len: 0,
            data: vec![0.0; width * cap],
        }
    }

    fn push(&mut self, row: &[f64]) {
        if self.len == self.cap {
            let cap = self.cap * 2;
            let mut data = vec![0.0; self.width * cap];
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

/// Keeps every output sample's telemetry and effector fields (the columns of
/// `polhode run --csv`) and forwards everything to the MCAP log when there is one.
struct Collector<'a> {
    spacecraft: &'a Spacecraft,
    store: ColumnStore,
    /// The current sample's values (scratch).
    row: Vec<f64>,
    /// The log, when `log=` names one.
    log: Option<McapLogger<'a>>,
}

impl Sink for Collector<'_> {
    fn sample(&mut self, o: &Observation, y: &[f64], inv: &Reference) -> std::io::Result<()> {
        // The same values, in the same order, as the sample tables (polhode::log::samples).
        self.row.clear();
        self.row.extend_from_slice(&telemetry::values(o, inv));
        let hub = HubState {
            t: o.t,
            omega: o.omega,
            attitude: &y[3..7],
        };
        for (k, e) in self.spacecraft.effectors().iter().enumerate() {
            self.row
                .extend(e.telemetry(&hub, self.spacecraft.effector_states(k, y)));
        }
        self.store.push(&self.row);
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
struct Products {
    /// Column names: the `/telemetry` fields, then `<effector>.<field>`.
    names: Vec<String>,
    /// The columns back to back, `n` values each.
    columns: Vec<f64>,
    /// Output samples.
    n: usize,
    outcome: Outcome,
    summary_json: String,
}

/// Why a run produced nothing.
enum RunError {
    /// The scenario with the overrides does not validate.
    Scenario(scenario::ScenarioError),
    /// The log would be too large (the CLI's message).
    LogTooLarge(String),
    /// The log could not be created, written or finished.
    Io(String),
}

/// Validates with `overrides` and runs, on the worker thread (no Python here).
fn execute(
    path: &Path,
    source: String,
    overrides: &Overrides,
    log: bool,
    interrupt: &AtomicBool,
) -> Result<Products, RunError> {
    let s = scenario::parse(path, source, overrides).map_err(RunError::Scenario)?;
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
    let names: Vec<String> = samples::columns(&s.spacecraft)
        .into_iter()
        .map(|c| c.name)
        .collect();
    // Samples at k / rate up to the end, and the last instant.
    let expected = (s.duration * s.output_rate).floor().max(0.0) as usize + 2;
    let mut collector = Collector {
        spacecraft: &s.spacecraft,
        store: ColumnStore::new(names.len(), expected),
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
        columns: collector.store.into_columns(),
        n,
        outcome,
        summary_json,
    })
}

/// How a detached piece of work ended: its value (or the panic that stopped it), and the
/// exception raised on the calling thread meanwhile (Ctrl-C's `KeyboardInterrupt`, or one
/// from `on_wake`), after which the work was told to stop and then waited for.
struct Detached<T> {
    value: Result<T, Box<dyn Any + Send>>,
    raised: Option<PyErr>,
}

/// Runs `work` on a worker thread with the GIL released, waking every [`SIGNAL_POLL`] to run
/// Python's signal handlers and then `on_wake`; on an exception from either (Ctrl-C:
/// `KeyboardInterrupt`) sets `interrupt` and waits for the worker to stop.
fn run_detached<T: Send>(
    py: Python<'_>,
    interrupt: &AtomicBool,
    mut on_wake: impl FnMut(Python<'_>) -> PyResult<()>,
    work: impl FnOnce() -> T + Send,
) -> Detached<T> {
    let finished = (Mutex::new(false), Condvar::new());
    std::thread::scope(|scope| {
        let worker = scope.spawn(|| {
            let result = catch_unwind(AssertUnwindSafe(work));
            let (done, wake) = &finished;
            *done.lock().unwrap_or_else(|p| p.into_inner()) = true;
            wake.notify_all();
            result
        });
        let wait = || {
            let (done, wake) = &finished;
            let guard = done.lock().unwrap_or_else(|p| p.into_inner());
            let (guard, _) = wake
                .wait_timeout_while(guard, SIGNAL_POLL, |finished| !*finished)
                .unwrap_or_else(|p| p.into_inner());
            *guard
        };
        let mut raised = None;
        while !py.detach(wait) {
            if let Err(e) = py.check_signals().and_then(|()| on_wake(py)) {
                interrupt.store(true, Ordering::SeqCst);
                raised = Some(e);
                break;
            }
        }
        // The worker ends soon after the flag is set (after the current step).
        let value = py.detach(|| worker.join());
        Detached {
            value: value.unwrap_or_else(Err),
            raised,
        }
    })
}

#[pymethods]
impl PyScenario {
    /// Validates a scenario given as a dict (as the YAML file would read: nested dicts, lists,
    /// numbers, text, booleans; numpy arrays and scalars are taken as lists and numbers).
    ///
    /// The dict is written out as YAML text (non-finite floats as `.nan`, `.inf`) and goes
    /// through the CLI's loader, so the checks and messages are the CLI's. On an error,
    /// `ScenarioError.path` is `<dict>`, `.field` the dotted path of the field
    /// (`body.inertia`, `effectors[0].mass`) and `.line`/`.column` None (the text they would
    /// point into is generated). A value of a type YAML has no word for (a set, an object)
    /// raises `ScenarioError` naming its field too.
    #[staticmethod]
    fn from_dict(py: Python<'_>, d: &Bound<'_, PyAny>) -> PyResult<PyScenario> {
        let written = py.import("polhode._dict")?.call_method1("to_yaml", (d,))?;
        let (text, fields): (String, Vec<Option<String>>) = written.extract()?;
        let defaults = Overrides::default();
        let parsed = catch_unwind(AssertUnwindSafe(|| {
            scenario::parse(Path::new(DICT_SOURCE_NAME), text, &defaults)
        }))
        .map_err(|p| internal_error("validating the scenario", p.as_ref()))?;
        match parsed {
            Ok(s) => Ok(PyScenario::from_core(s)),
            Err(mut e) => {
                if e.field.is_none() {
                    // The key on the line the loader points at (an unknown key, say).
                    e.field = e
                        .line
                        .and_then(|l| fields.get((l as usize).checked_sub(1)?).cloned())
                        .flatten();
                }
                e.line = None;
                e.column = None;
                Err(scenario_error(py, &e))
            }
        }
    }

    /// `name:` of the scenario.
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }

    /// Where the scenario came from: its file, or `<string>` for `loads`.
    #[getter]
    fn path(&self) -> String {
        self.path.display().to_string()
    }

    /// Simulated duration (s), as the scenario sets it.
    #[getter]
    fn duration(&self) -> f64 {
        self.duration
    }

    /// The integration method's name (for `auto`, the one it picked).
    #[getter]
    fn method(&self) -> &str {
        &self.method
    }

    /// The scenario's YAML text.
    #[getter]
    fn source(&self) -> &str {
        &self.source
    }

    fn __repr__(&self) -> String {
        format!(
            "Scenario(name={:?}, path={:?}, method={:?}, duration={} s)",
            self.name,
            self.path.display().to_string(),
            self.method,
            self.duration
        )
    }

    /// Runs the scenario, as `polhode run` does with the same options, and returns a `Result`.
    ///
    /// `method` (e.g. "dop853"), `dt` (s, fixed-step methods), `rtol`, `atol` and `duration`
    /// (s) override the scenario's; `log` is the MCAP file to write (none is written
    /// without it, whatever `output.mcap` says). The GIL is released while the run goes;
    /// Ctrl-C stops it within 0.1 s and raises `KeyboardInterrupt` (a log being written is
    /// kept, marked partial).
    #[pyo3(signature = (method=None, dt=None, rtol=None, atol=None, duration=None, log=None))]
    #[allow(clippy::too_many_arguments)]
    fn run(
        &self,
        py: Python<'_>,
        method: Option<String>,
        dt: Option<f64>,
        rtol: Option<f64>,
        atol: Option<f64>,
        duration: Option<f64>,
        log: Option<PathBuf>,
    ) -> PyResult<RunResult> {
        let write_log = log.is_some();
        let overrides = Overrides {
            method,
            dt,
            rtol,
            atol,
            duration,
            mcap: log,
            ..Overrides::default()
        };
        let interrupt = AtomicBool::new(false);
        let (path, source) = (self.path.clone(), self.source.clone());
        let detached = run_detached(
            py,
            &interrupt,
            |_| Ok(()),
            || execute(&path, source, &overrides, write_log, &interrupt),
        );
        if let Some(e) = detached.raised {
            return Err(e);
        }
        let products = match detached.value {
            Ok(Ok(p)) => p,
            Ok(Err(RunError::Scenario(e))) => return Err(scenario_error(py, &e)),
            Ok(Err(RunError::LogTooLarge(m))) => return Err(PyValueError::new_err(m)),
            Ok(Err(RunError::Io(m))) => return Err(PyOSError::new_err(m)),
            Err(panic) => {
                return Err(internal_error("running the scenario", panic.as_ref()));
            }
        };
        RunResult::new(py, products)
    }
}

/// The result of `Scenario.run`: arrays over the output samples, events and the summary.
///
/// Every array is a view of one `(columns, n)` float64 buffer filled by the run and handed to
/// numpy without a copy: `telemetry[name]` is a row of it, `t` the `sim_time` row, `omega`
/// and `q` the transposed `omega_*` and `q_*` rows.
#[pyclass(frozen, module = "polhode", name = "Result")]
struct RunResult {
    /// Sim time of each output sample (s), shape (n,).
    #[pyo3(get)]
    t: Py<PyAny>,
    /// Body rates (rad/s, body frame), shape (n, 3).
    #[pyo3(get)]
    omega: Py<PyAny>,
    /// Attitude quaternion body→inertial, scalar-first (w, x, y, z), shape (n, 4).
    #[pyo3(get)]
    q: Py<PyAny>,
    /// Every `/telemetry` field of the MCAP log, then every effector's fields as
    /// `<effector>.<field>` (the columns of `polhode run --csv`), each of shape (n,).
    #[pyo3(get)]
    telemetry: Py<PyDict>,
    /// Events in time order: dicts with `t` (s), `condition` and `terminal`.
    #[pyo3(get)]
    events: Py<PyList>,
    /// The `polhode run --summary` document, as a dict.
    #[pyo3(get)]
    summary: Py<PyAny>,
    /// How the run ended: complete, stopped, interrupted, failed or invalid_model.
    #[pyo3(get)]
    status: String,
}

/// Rows of the `omega_*` and `q_*` columns in [`telemetry::FIELDS`].
const OMEGA_ROWS: (usize, usize) = (1, 4);
const Q_ROWS: (usize, usize) = (4, 8);

impl RunResult {
    fn new(py: Python<'_>, p: Products) -> PyResult<Self> {
        let block = p.columns.into_pyarray(py).reshape([p.names.len(), p.n])?;
        let block = block.as_any();
        let rows_t = |(a, b): (usize, usize)| -> PyResult<Bound<'_, PyAny>> {
            block
                .get_item(PySlice::new(py, a as isize, b as isize, 1))?
                .getattr("T")
        };
        let t = block.get_item(0)?;
        let omega = rows_t(OMEGA_ROWS)?;
        let q = rows_t(Q_ROWS)?;
        let telemetry = PyDict::new(py);
        for (k, name) in p.names.iter().enumerate() {
            telemetry.set_item(name, block.get_item(k)?)?;
        }
        let events = PyList::empty(py);
        for e in &p.outcome.events {
            let event = PyDict::new(py);
            event.set_item("t", e.t)?;
            event.set_item("condition", &e.condition)?;
            event.set_item("terminal", e.terminal)?;
            events.append(event)?;
        }
        let summary = py
            .import("json")?
            .call_method1("loads", (p.summary_json,))?;
        Ok(RunResult {
            t: t.unbind(),
            omega: omega.unbind(),
            q: q.unbind(),
            telemetry: telemetry.unbind(),
            events: events.unbind(),
            summary: summary.unbind(),
            status: p.outcome.status.label().to_string(),
        })
    }
}

/// `module`, imported, or an `ImportError` saying what needs it and how to install it.
fn import_optional<'py>(
    py: Python<'py>,
    module: &str,
    what: &str,
) -> PyResult<Bound<'py, PyModule>> {
    py.import(module).map_err(|e| {
        if e.is_instance_of::<PyImportError>(py) {
            PyImportError::new_err(format!(
                "{what} needs {module}, which is not installed: `pip install {module}` \
                 ({})",
                e.value(py)
            ))
        } else {
            e
        }
    })
}

#[pymethods]
impl RunResult {
    fn __repr__(&self, py: Python<'_>) -> String {
        let n = self.t.bind(py).len().unwrap_or(0);
        format!(
            "Result(status={:?}, samples={n}, events={})",
            self.status,
            self.events.bind(py).len()
        )
    }

    /// A pandas DataFrame: `t` (s), then every column of `telemetry` (units as there).
    ///
    /// pandas is imported here (not a dependency of polhode): `ImportError` when missing.
    /// The DataFrame holds a copy of the arrays.
    fn to_pandas(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let pandas = import_optional(py, "pandas", "Result.to_pandas()")?;
        let data = PyDict::new(py);
        data.set_item("t", self.t.bind(py))?;
        for (name, column) in self.telemetry.bind(py).iter() {
            data.set_item(name, column)?;
        }
        Ok(pandas.getattr("DataFrame")?.call1((data,))?.unbind())
    }
}

/// The linearisation `polhode linearize FILE --json OUT` writes, as a dict (its JSON text
/// parsed by Python's `json`): the modes about the steady spin, or about the LVLH
/// equilibrium for a gravity-gradient spacecraft in orbit, or the effectors' modes under a
/// driven hub (docs/linearize.md has the fields and units).
///
/// Raises `ScenarioError` when the scenario no longer validates, `ValueError` with the CLI's
/// message when it cannot be linearised.
#[pyfunction]
fn linearize(py: Python<'_>, scenario: PyRef<'_, PyScenario>) -> PyResult<Py<PyAny>> {
    let (path, source) = (scenario.path.clone(), scenario.source.clone());
    let analysed = catch_unwind(AssertUnwindSafe(|| {
        scenario::parse(&path, source, &Overrides::default())
            .map(|s| polhode::cli::linearize_json(&s))
    }))
    .map_err(|p| internal_error("linearising the scenario", p.as_ref()))?;
    let json = match analysed {
        Err(e) => return Err(scenario_error(py, &e)),
        Ok(Err(m)) => {
            return Err(PyValueError::new_err(format!("{}: {m}", path.display())));
        }
        Ok(Ok(json)) => json,
    };
    Ok(py.import("json")?.call_method1("loads", (json,))?.unbind())
}

/// Runs a Monte Carlo campaign in process (`polhode.montecarlo` wraps it): the runs of the
/// range, the `runs.parquet` bytes and `summary.json` text `polhode montecarlo` writes for
/// them, whether runs are missing, and the exception raised meanwhile (Ctrl-C), if any.
/// `on_progress(done, total)` is called from this thread: once before, then on the 0.1 s
/// wake-ups when the count changed, and once at the end.
#[pyfunction]
#[pyo3(signature = (scenario, runs=None, seed=None, threads=None, shard=None, on_progress=None))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn _montecarlo(
    py: Python<'_>,
    scenario: PyRef<'_, PyScenario>,
    runs: Option<u64>,
    seed: Option<u64>,
    threads: Option<usize>,
    shard: Option<(u64, u64)>,
    on_progress: Option<Bound<'_, PyAny>>,
) -> PyResult<(Py<PyBytes>, String, bool, Option<Py<PyAny>>)> {
    let (path, source) = (scenario.path.clone(), scenario.source.clone());
    let prepared = catch_unwind(AssertUnwindSafe(|| {
        let s = scenario::parse(&path, source, &Overrides::default())?;
        montecarlo::Prepared::new(s, &path.display().to_string(), runs, seed)
    }))
    .map_err(|p| internal_error("preparing the campaign", p.as_ref()))?;
    let prep = prepared.map_err(|e| scenario_error(py, &e))?;
    let total_runs = prep.campaign.runs;
    if let Some((k, n)) = shard {
        if k == 0 || k > n {
            return Err(PyValueError::new_err(format!(
                "shard {k}/{n}: expected K/N with 1 <= K <= N, e.g. 2/8"
            )));
        }
        if n > total_runs {
            return Err(PyValueError::new_err(format!(
                "shard: {n} shards for {total_runs} runs would leave some empty; use at most \
                 {total_runs} shards"
            )));
        }
    }
    let threads = match threads {
        Some(0) => return Err(PyValueError::new_err("threads: expected at least 1")),
        Some(t) => t,
        None => std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get),
    };
    let range = match shard {
        Some((k, n)) => montecarlo::shard_range(total_runs, k, n),
        None => 0..total_runs,
    };
    let total = range.end - range.start;
    let done = AtomicU64::new(0);
    let mut shown = None;
    let mut report = |_py: Python<'_>| -> PyResult<()> {
        let now = done.load(Ordering::Relaxed);
        match &on_progress {
            Some(f) if shown != Some(now) => {
                shown = Some(now);
                f.call1((now, total)).map(|_| ())
            }
            _ => Ok(()),
        }
    };
    report(py)?;
    let interrupt = AtomicBool::new(false);
    let on_row = |_: &montecarlo::Row| {
        done.fetch_add(1, Ordering::Relaxed);
    };
    let detached = run_detached(py, &interrupt, &mut report, || {
        prep.execute(range, threads, &interrupt, &on_row)
    });
    let (rows, partial) = match detached.value {
        Ok(Ok(x)) => x,
        Ok(Err(m)) => return Err(PyRuntimeError::new_err(m)),
        Err(panic) => return Err(internal_error("running the campaign", panic.as_ref())),
    };
    let raised = detached.raised.map(|e| e.into_value(py).into_any());
    if raised.is_none() {
        report(py)?;
    }
    let shard = shard.map(|(k, n)| [k, n]);
    let tables = catch_unwind(AssertUnwindSafe(|| {
        let parquet = montecarlo::table::to_parquet(&prep.columns, &rows)?;
        let summary = montecarlo::output::summary_json(&prep, &rows, shard, partial)?;
        Ok::<_, String>((parquet, summary))
    }))
    .map_err(|p| internal_error("writing the campaign's table", p.as_ref()))?;
    let (parquet, summary) = tables.map_err(PyRuntimeError::new_err)?;
    Ok((
        PyBytes::new(py, &parquet).unbind(),
        summary,
        partial,
        raised,
    ))
}

/// polhode's simulator: `load`/`loads` a scenario, `Scenario.run` it.
#[pymodule]
fn _polhode(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(loads, m)?)?;
    m.add_function(wrap_pyfunction!(_montecarlo, m)?)?;
    m.add_function(wrap_pyfunction!(linearize, m)?)?;
    m.add_class::<PyScenario>()?;
    m.add_class::<RunResult>()?;
    m.add("ScenarioError", m.py().get_type::<ScenarioError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
