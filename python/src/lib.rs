//! `polhode._polhode`: the Python extension module of polhode (re-exported by the `polhode`
//! package, `python/polhode/__init__.py`).
//!
//! Scenarios are validated by the same loader as the CLI (`polhode::scenario`), and runs go
//! through the same run loop (`polhode::sim::run`) and the same `--summary` document
//! (`polhode::cli::summary_json`), so a run from Python gives the CLI's numbers bit for bit.
//! A run releases the GIL and goes on a worker thread; the calling thread wakes every
//! [`SIGNAL_POLL`] to check for Ctrl-C, and on one sets the run loop's interrupt flag and
//! raises `KeyboardInterrupt`. No Rust panic reaches Python: it becomes a `RuntimeError`.
//!
//! Units are SI throughout (s, rad/s, N m s, J); quaternions are scalar-first `(w, x, y, z)`
//! and map body vectors to inertial ones (docs/conventions.md).

use numpy::{IntoPyArray, PyArrayMethods};
use polhode::log::{McapLogger, telemetry};
use polhode::model::Observation;
use polhode::scenario::{self, Overrides};
use polhode::sim::{self, Control, EventRecord, Outcome, Reference, Sink, Warning};
use pyo3::create_exception;
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::any::Any;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Condvar, Mutex};
use std::time::Duration;

/// How often a waiting run checks for Ctrl-C (and lets other Python threads run meanwhile).
const SIGNAL_POLL: Duration = Duration::from_millis(100);

/// The name a scenario given as text (`loads`) goes by in messages and `ScenarioError.path`.
const TEXT_SOURCE_NAME: &str = "<string>";

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

/// Keeps every output sample's telemetry (column by column) and forwards everything to the
/// MCAP log when there is one.
struct Collector<'a> {
    /// One column per [`telemetry::FIELDS`] entry, one value per sample.
    columns: Vec<Vec<f64>>,
    /// Body rates (rad/s), three per sample, row-major.
    omega: Vec<f64>,
    /// Attitude quaternion body→inertial, scalar-first, four per sample, row-major.
    q: Vec<f64>,
    /// The log, when `log=` names one.
    log: Option<McapLogger<'a>>,
}

/// Column indices of the body rates and of the quaternion in [`telemetry::FIELDS`].
const OMEGA_COLUMNS: std::ops::Range<usize> = 1..4;
const Q_COLUMNS: std::ops::Range<usize> = 4..8;

impl Sink for Collector<'_> {
    fn sample(&mut self, o: &Observation, y: &[f64], inv: &Reference) -> std::io::Result<()> {
        let values = telemetry::values(o, inv);
        for (column, value) in self.columns.iter_mut().zip(values) {
            column.push(value);
        }
        self.omega.extend_from_slice(&values[OMEGA_COLUMNS]);
        self.q.extend_from_slice(&values[Q_COLUMNS]);
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
    columns: Vec<Vec<f64>>,
    omega: Vec<f64>,
    q: Vec<f64>,
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
    let mut collector = Collector {
        columns: vec![Vec::new(); telemetry::FIELDS.len()],
        omega: Vec::new(),
        q: Vec::new(),
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
    Ok(Products {
        columns: collector.columns,
        omega: collector.omega,
        q: collector.q,
        outcome,
        summary_json,
    })
}

/// Runs `work` on a worker thread with the GIL released, waking every [`SIGNAL_POLL`] to run
/// Python's signal handlers; on an exception from them (Ctrl-C: `KeyboardInterrupt`) sets
/// `interrupt`, waits for the worker to stop and returns the exception.
fn run_detached<T: Send>(
    py: Python<'_>,
    interrupt: &AtomicBool,
    work: impl FnOnce() -> T + Send,
) -> PyResult<Result<T, Box<dyn Any + Send>>> {
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
        let mut signal = None;
        while !py.detach(wait) {
            if let Err(e) = py.check_signals() {
                interrupt.store(true, Ordering::SeqCst);
                signal = Some(e);
                break;
            }
        }
        // The worker ends soon after the flag is set (after the current step).
        let result = py.detach(|| worker.join());
        let result = result.unwrap_or_else(Err);
        match signal {
            Some(e) => Err(e),
            None => Ok(result),
        }
    })
}

#[pymethods]
impl PyScenario {
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
        let result = run_detached(py, &interrupt, || {
            execute(&path, source, &overrides, write_log, &interrupt)
        })?;
        let products = match result {
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
    /// Every `/telemetry` field of the MCAP log by name, each an array of shape (n,).
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

impl RunResult {
    fn new(py: Python<'_>, p: Products) -> PyResult<Self> {
        let n = p.columns.first().map_or(0, Vec::len);
        let t = p.columns[0].clone().into_pyarray(py);
        let omega = p.omega.into_pyarray(py).reshape([n, 3])?;
        let q = p.q.into_pyarray(py).reshape([n, 4])?;
        let telemetry = PyDict::new(py);
        for (name, column) in telemetry::FIELDS.iter().zip(p.columns) {
            telemetry.set_item(name, column.into_pyarray(py))?;
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
            t: t.into_any().unbind(),
            omega: omega.into_any().unbind(),
            q: q.into_any().unbind(),
            telemetry: telemetry.unbind(),
            events: events.unbind(),
            summary: summary.unbind(),
            status: p.outcome.status.label().to_string(),
        })
    }
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
}

/// polhode's simulator: `load`/`loads` a scenario, `Scenario.run` it.
#[pymodule]
fn _polhode(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(loads, m)?)?;
    m.add_class::<PyScenario>()?;
    m.add_class::<RunResult>()?;
    m.add("ScenarioError", m.py().get_type::<ScenarioError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
