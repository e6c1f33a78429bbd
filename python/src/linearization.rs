//! `polhode.linearize`: the CLI's `linearize --json` document.

use crate::errors::{internal_error, scenario_error};
use crate::py_scenario::scenario_argument;
use polhode::scenario::{self, Overrides};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// The linearisation `polhode linearize FILE --json OUT` writes, as a dict (its JSON text
/// parsed by Python's `json`): the modes about the steady spin, or about the LVLH
/// equilibrium for a gravity-gradient spacecraft in orbit, or the effectors' modes under a
/// driven hub (docs/cli.md has the fields and units).
///
/// `scenario` is a `Scenario` or a scenario file's path (`str` or `os.PathLike`). Raises
/// `ScenarioError` when the scenario does not validate, `ValueError` with the CLI's message
/// when it cannot be linearised, `TypeError` when `scenario` is neither.
#[pyfunction]
pub(crate) fn linearize(py: Python<'_>, scenario: &Bound<'_, PyAny>) -> PyResult<Py<PyAny>> {
    let (path, source) = scenario_argument(py, "linearize", scenario)?;
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
