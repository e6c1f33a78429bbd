//! `Scenario`: `load`, `loads`, `Scenario.from_dict` and `Scenario.run`.

use crate::detach::run_detached;
use crate::errors::{internal_error, scenario_error};
use crate::result::RunResult;
use crate::run::{RunError, execute};
use crate::{DICT_SOURCE_NAME, TEXT_SOURCE_NAME};
use polhode::scenario::{self, Overrides};
use pyo3::exceptions::{PyMemoryError, PyOSError, PyValueError};
use pyo3::prelude::*;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

/// A scenario, validated; `run` validates it again with its overrides.
#[pyclass(frozen, module = "polhode", name = "Scenario")]
pub(crate) struct PyScenario {
    /// Where it came from (`<string>` for `loads`).
    pub(crate) path: PathBuf,
    /// The YAML text.
    pub(crate) source: String,
    /// `name:`.
    pub(crate) name: String,
    /// Simulated duration (s).
    pub(crate) duration: f64,
    /// The integration method's name (`dopri5`, …; what `auto` picked).
    pub(crate) method: String,
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
pub(crate) fn validate(
    py: Python<'_>,
    path: &Path,
    source: Option<String>,
) -> PyResult<PyScenario> {
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
pub(crate) fn load(py: Python<'_>, path: PathBuf) -> PyResult<PyScenario> {
    validate(py, &path, None)
}

/// Validates a scenario given as YAML text; messages name it `<string>`.
///
/// Raises `ScenarioError` (a `ValueError`) with the CLI's message when it does not validate.
#[pyfunction]
pub(crate) fn loads(py: Python<'_>, yaml_text: String) -> PyResult<PyScenario> {
    validate(py, Path::new(TEXT_SOURCE_NAME), Some(yaml_text))
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
        dt: Option<Bound<'_, PyAny>>,
        rtol: Option<Bound<'_, PyAny>>,
        atol: Option<Bound<'_, PyAny>>,
        duration: Option<Bound<'_, PyAny>>,
        log: Option<PathBuf>,
    ) -> PyResult<RunResult> {
        // Checked before the run starts, not after it has been integrated.
        if let Some(p) = &log
            && p.as_os_str().is_empty()
        {
            return Err(PyValueError::new_err(
                "log: expected the path of the MCAP file to write, got an empty string (leave \
                 `log` out to write no log)",
            ));
        }
        let write_log = log.is_some();
        let overrides = Overrides {
            method,
            dt: real("dt", dt)?,
            rtol: real("rtol", rtol)?,
            atol: real("atol", atol)?,
            duration: real("duration", duration)?,
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
            Ok(Err(RunError::LogTooLarge(m) | RunError::Refused(m))) => {
                return Err(PyValueError::new_err(m));
            }
            Ok(Err(RunError::Io(m))) => return Err(PyOSError::new_err(m)),
            Ok(Err(RunError::Memory(m))) => return Err(PyMemoryError::new_err(m)),
            Err(panic) => {
                return Err(internal_error("running the scenario", panic.as_ref()));
            }
        };
        RunResult::new(py, products)
    }
}

/// An optional real-valued keyword argument: a float or an int, not a bool (`True` is an int
/// to Python, but `duration=True` is a mistake, as `from_dict` already says).
fn real(name: &str, value: Option<Bound<'_, PyAny>>) -> PyResult<Option<f64>> {
    let Some(v) = value else { return Ok(None) };
    if v.is_instance_of::<pyo3::types::PyBool>() {
        return Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "{name}: expected a number, got the boolean {}",
            if v.is_truthy()? { "True" } else { "False" }
        )));
    }
    v.extract::<f64>().map(Some).map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err(format!(
            "{name}: expected a number, got {}",
            v.get_type()
                .name()
                .map_or_else(|_| "another type".to_string(), |n| n.to_string())
        ))
    })
}
