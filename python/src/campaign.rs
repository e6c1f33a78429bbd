//! `polhode.montecarlo`'s engine: a campaign run in process, its table and summary.

use crate::detach::run_detached;
use crate::errors::{internal_error, scenario_error};
use crate::py_scenario::PyScenario;
use polhode::montecarlo;
use polhode::scenario::{self, Overrides};
use pyo3::exceptions::{PyRuntimeError, PyRuntimeWarning, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// Runs a Monte Carlo campaign in process (`polhode.montecarlo` wraps it): the runs of the
/// range, the `runs.parquet` bytes and `summary.json` text `polhode montecarlo` writes for
/// them, whether runs are missing, the exception raised meanwhile (Ctrl-C), if any, and how
/// the runs were integrated (`lanes`: in lanes where the scene has a lane form).
/// `on_progress(done, total)` is called from this thread: once before, then on the 0.1 s
/// wake-ups when the count changed, and once at the end.
#[pyfunction]
#[pyo3(signature = (scenario, runs=None, seed=None, threads=None, shard=None, on_progress=None, method=None, lanes=true))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub(crate) fn _montecarlo(
    py: Python<'_>,
    scenario: PyRef<'_, PyScenario>,
    runs: Option<u64>,
    seed: Option<u64>,
    threads: Option<usize>,
    shard: Option<(u64, u64)>,
    on_progress: Option<Bound<'_, PyAny>>,
    method: Option<String>,
    lanes: bool,
) -> PyResult<(Py<PyBytes>, String, bool, Option<Py<PyAny>>, String)> {
    let (path, source) = (scenario.path.clone(), scenario.source.clone());
    let prepared = catch_unwind(AssertUnwindSafe(|| {
        let s = scenario::parse(&path, source, &Overrides::default())?;
        Ok::<_, polhode::scenario::ScenarioError>(
            montecarlo::Prepared::new(s, &path.display().to_string(), runs, seed)?
                .with_method(method)?
                .with_integration(lanes),
        )
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
    let (threads, note) =
        montecarlo::thread_count(threads, "threads").map_err(PyValueError::new_err)?;
    if let Some(note) = note {
        // A RuntimeWarning, shown once per call site like any warning; the campaign goes on.
        let text = std::ffi::CString::new(note).unwrap_or_default();
        PyErr::warn(py, &py.get_type::<PyRuntimeWarning>(), &text, 2)?;
    }
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
        prep.integration.describe(),
    ))
}
