//! `Scenario`: `load`, `loads`, `Scenario.from_dict` and `Scenario.run`.

use crate::detach::run_detached;
use crate::errors::{internal_error, scenario_error, type_error};
use crate::result::RunResult;
use crate::run::{RunError, execute};
use crate::{DICT_SOURCE_NAME, TEXT_SOURCE_NAME};
use polhode::scenario::{self, Overrides};
use pyo3::exceptions::{PyMemoryError, PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyInt, PyString};
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

/// What a scenario file's path argument takes.
const PATH_EXPECTED: &str = "a scenario file's path (str or os.PathLike)";

/// A path argument (`str` or `os.PathLike`), or a `TypeError` naming `function` and
/// `argument` and saying what `expected` is.
pub(crate) fn path_argument(
    function: &str,
    argument: &str,
    expected: &str,
    value: &Bound<'_, PyAny>,
) -> PyResult<PathBuf> {
    value
        .extract::<PathBuf>()
        .map_err(|_| type_error(function, argument, expected, value))
}

/// The scenario a `Scenario` or a file's path (loaded and validated) argument names, as a
/// `(path, YAML text)` pair, or a `TypeError` naming `function` and `scenario`.
pub(crate) fn scenario_argument(
    py: Python<'_>,
    function: &str,
    value: &Bound<'_, PyAny>,
) -> PyResult<(PathBuf, String)> {
    if let Ok(s) = value.cast::<PyScenario>() {
        let s = s.get();
        return Ok((s.path.clone(), s.source.clone()));
    }
    let path = path_argument(
        function,
        "scenario",
        "a Scenario or a scenario file's path (str or os.PathLike)",
        value,
    )?;
    let s = validate(py, &path, None)?;
    Ok((s.path, s.source))
}

/// Reads and validates a scenario file (YAML); `path` is a `str` or an `os.PathLike`.
///
/// Raises `ScenarioError` (a `ValueError`) with the CLI's message when it does not validate,
/// `TypeError` when `path` is not a path.
#[pyfunction]
pub(crate) fn load(py: Python<'_>, path: &Bound<'_, PyAny>) -> PyResult<PyScenario> {
    let path = path_argument("load", "path", PATH_EXPECTED, path)?;
    validate(py, &path, None)
}

/// Validates a scenario given as YAML text (a `str`); messages name it `<string>`.
///
/// Raises `ScenarioError` (a `ValueError`) with the CLI's message when it does not validate,
/// `TypeError` when `yaml_text` is not a `str`.
#[pyfunction]
pub(crate) fn loads(py: Python<'_>, yaml_text: &Bound<'_, PyAny>) -> PyResult<PyScenario> {
    let text = yaml_text
        .cast::<PyString>()
        .map_err(|_| {
            type_error(
                "loads",
                "yaml_text",
                "the scenario's YAML text (str)",
                yaml_text,
            )
        })?
        .extract::<String>()?;
    validate(py, Path::new(TEXT_SOURCE_NAME), Some(text))
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

    /// An HTML summary for Jupyter (name, file, method, duration): `polhode/_display.py`.
    fn _repr_html_(slf: &Bound<'_, Self>) -> PyResult<Py<PyAny>> {
        let display = slf.py().import("polhode._display")?;
        Ok(display.call_method1("scenario_html", (slf,))?.unbind())
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
        method: Option<Bound<'_, PyAny>>,
        dt: Option<Bound<'_, PyAny>>,
        rtol: Option<Bound<'_, PyAny>>,
        atol: Option<Bound<'_, PyAny>>,
        duration: Option<Bound<'_, PyAny>>,
        log: Option<Bound<'_, PyAny>>,
    ) -> PyResult<RunResult> {
        let method = method
            .map(|m| {
                m.cast::<PyString>()
                    .map_err(|_| {
                        type_error(
                            "run",
                            "method",
                            "an integration method's name (str, e.g. \"dop853\")",
                            &m,
                        )
                    })
                    .and_then(|m| m.extract::<String>())
            })
            .transpose()?;
        let log = log
            .map(|l| {
                path_argument(
                    "run",
                    "log",
                    "the path of the MCAP file to write (str or os.PathLike)",
                    &l,
                )
            })
            .transpose()?;
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
            dt: real("dt", "a step in seconds (float)", dt)?,
            rtol: real("rtol", "a relative tolerance (float)", rtol)?,
            atol: real("atol", "an absolute tolerance (float)", atol)?,
            duration: real("duration", "a number of seconds (float)", duration)?,
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

/// An optional real-valued keyword argument of `run`: a float or an int (or anything with
/// `__float__`, as numpy's scalars), not a bool (`True` is an int to Python, but
/// `duration=True` is a mistake, as `from_dict` already says) and not text.
fn real(name: &str, expected: &str, value: Option<Bound<'_, PyAny>>) -> PyResult<Option<f64>> {
    let Some(v) = value else { return Ok(None) };
    if v.is_instance_of::<PyBool>() {
        return Err(type_error("run", name, expected, &v));
    }
    v.extract::<f64>().map(Some).map_err(|e| {
        // An int too large for a float keeps Python's own OverflowError: its type is right.
        if v.is_instance_of::<PyInt>() {
            e
        } else {
            type_error("run", name, expected, &v)
        }
    })
}
