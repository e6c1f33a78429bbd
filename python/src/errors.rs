//! The exceptions Python sees: `ScenarioError` with its location, `RuntimeError` for an
//! internal error, `TypeError` for an argument of the wrong type (the
//! `ImportError`s for missing optional packages are raised by `polhode/_display.py` and
//! `polhode/_campaign.py`).

use polhode::scenario::{self};
use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyTypeError, PyValueError};
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

/// Longest `repr` of a wrong argument quoted in a `TypeError` (characters).
const REPR_CHARS: usize = 60;

/// A `TypeError` naming the function, the argument and what it takes:
/// `run(): duration must be a number of seconds (float), got str '100'`
/// (the same words as `polhode/_args.py` writes for the Python-side functions).
pub(crate) fn type_error(
    function: &str,
    argument: &str,
    expected: &str,
    value: &Bound<'_, PyAny>,
) -> PyErr {
    let kind = value
        .get_type()
        .name()
        .map_or_else(|_| "an object".to_string(), |n| n.to_string());
    let shown = value
        .repr()
        .map_or_else(|_| "?".to_string(), |r| r.to_string());
    let shown = if shown.chars().count() > REPR_CHARS {
        format!("{}…", shown.chars().take(REPR_CHARS).collect::<String>())
    } else {
        shown
    };
    PyTypeError::new_err(format!(
        "{function}(): {argument} must be {expected}, got {kind} {shown}"
    ))
}
