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

mod campaign;
mod detach;
mod errors;
mod linearization;
mod py_scenario;
mod result;
mod run;

use campaign::_montecarlo;
use errors::ScenarioError;
use linearization::linearize;
use py_scenario::{PyScenario, load, loads};
use pyo3::prelude::*;
use result::RunResult;
use std::time::Duration;

/// How often a waiting run checks for Ctrl-C (and lets other Python threads run meanwhile).
pub(crate) const SIGNAL_POLL: Duration = Duration::from_millis(100);

/// The name a scenario given as text (`loads`) goes by in messages and `ScenarioError.path`.
pub(crate) const TEXT_SOURCE_NAME: &str = "<string>";

/// The name a scenario given as a dict (`Scenario.from_dict`) goes by.
pub(crate) const DICT_SOURCE_NAME: &str = "<dict>";

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
