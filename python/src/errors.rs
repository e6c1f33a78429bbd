//! The exceptions Python sees: `ScenarioError` with its location, `RuntimeError` for an
//! internal error, `ImportError` for a missing optional package.

use polhode::scenario::{self};
use pyo3::create_exception;
use pyo3::exceptions::{PyImportError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::any::Any;

create_exception!(
    polhode,
    ScenarioError,
    PyValueError,
    "A scenario that does not validate: the CLI's message, with `.path`, `.line` and \
     `.column` (1-based, None when unknown), `.field` (dotted path such as `body.inertia`, \
     None when unknown) and `.message` (what is wrong and what was expected)."
);

/// The Python `ScenarioError` for a core validation error, its location as attributes.
pub(crate) fn scenario_error(py: Python<'_>, error: &scenario::ScenarioError) -> PyErr {
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
pub(crate) fn panic_text(payload: &(dyn Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

/// A `RuntimeError` for a Rust panic, asking for a report.
pub(crate) fn internal_error(what: &str, payload: &(dyn Any + Send)) -> PyErr {
    PyRuntimeError::new_err(format!(
        "polhode internal error while {what}: {}; please report it with the scenario",
        panic_text(payload)
    ))
}

/// `module`, imported, or an `ImportError` saying what needs it and how to install it.
pub(crate) fn import_optional<'py>(
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
