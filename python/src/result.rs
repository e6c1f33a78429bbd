//! `Result`: a run's arrays (views of one Rust-owned buffer), events and summary.

use crate::run::Products;
use numpy::{IntoPyArray, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PySlice};

/// The result of `Scenario.run`: arrays over the output samples, events and the summary.
///
/// Every array is a view of one `(columns, n)` float64 buffer filled by the run and handed to
/// numpy without a copy: `telemetry[name]` is a row of it, `t` the `sim_time` row, `omega`
/// and `q` the transposed `omega_*` and `q_*` rows.
#[pyclass(frozen, module = "polhode", name = "Result")]
pub(crate) struct RunResult {
    /// Sim time of each output sample (s), shape (n,).
    #[pyo3(get)]
    pub(crate) t: Py<PyAny>,
    /// Body rates (rad/s, body frame), shape (n, 3).
    #[pyo3(get)]
    pub(crate) omega: Py<PyAny>,
    /// Attitude quaternion body→inertial, scalar-first (w, x, y, z), shape (n, 4).
    #[pyo3(get)]
    pub(crate) q: Py<PyAny>,
    /// Attitude relative to LVLH, `q_OB` body→LVLH, scalar-first, sign with w ≥ 0, shape
    /// (n, 4); `None` without an orbit. The `/orbit` fields `q_lvlh_*`.
    #[pyo3(get)]
    pub(crate) q_lvlh: Option<Py<PyAny>>,
    /// Roll, pitch, yaw relative to LVLH (deg; 3-2-1 Euler angles of `q_lvlh`), shape (n, 3);
    /// `None` without an orbit. The `/orbit` fields `roll_deg`, `pitch_deg`, `yaw_deg`.
    #[pyo3(get)]
    pub(crate) lvlh_rpy: Option<Py<PyAny>>,
    /// Body rates relative to LVLH (rad/s, body frame), shape (n, 3); `None` without an
    /// orbit. The `/orbit` fields `omega_lvlh_*`.
    #[pyo3(get)]
    pub(crate) omega_lvlh: Option<Py<PyAny>>,
    /// Every `/telemetry` field of the MCAP log, then every effector's fields as
    /// `<effector>.<field>`, then with an orbit the attitude relative to LVLH (the columns of
    /// `polhode run --csv`), each of shape (n,).
    #[pyo3(get)]
    pub(crate) telemetry: Py<PyDict>,
    /// Events in time order: dicts with `t` (s), `condition` and `terminal`.
    #[pyo3(get)]
    pub(crate) events: Py<PyList>,
    /// The `polhode run --summary` document, as a dict.
    #[pyo3(get)]
    pub(crate) summary: Py<PyAny>,
    /// How the run ended: complete, stopped, interrupted, failed or invalid_model.
    #[pyo3(get)]
    pub(crate) status: String,
    /// The unit of each `telemetry` column by name (`"rad/s"`; `""` when it has none), as
    /// the `polhode run --csv` header carries them.
    #[pyo3(get)]
    pub(crate) units: Py<PyDict>,
}

/// Rows of the `omega_*` and `q_*` columns in [`telemetry::FIELDS`].
pub(crate) const OMEGA_ROWS: (usize, usize) = (1, 4);
pub(crate) const Q_ROWS: (usize, usize) = (4, 8);
/// Columns of the attitude relative to LVLH, last in the buffer with an orbit.
const LVLH_COLUMNS: usize = polhode::log::orbit::ATTITUDE_FIELDS.len();

impl RunResult {
    pub(crate) fn new(py: Python<'_>, p: Products) -> PyResult<Self> {
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
        // The attitude relative to LVLH: the last ten columns, with an orbit.
        let lvlh = |(a, b): (usize, usize)| -> PyResult<Option<Py<PyAny>>> {
            p.has_lvlh
                .then(|| {
                    let first = p.names.len() - LVLH_COLUMNS;
                    rows_t((first + a, first + b)).map(Bound::unbind)
                })
                .transpose()
        };
        let (q_lvlh, lvlh_rpy, omega_lvlh) = (lvlh((0, 4))?, lvlh((4, 7))?, lvlh((7, 10))?);
        let telemetry = PyDict::new(py);
        let units = PyDict::new(py);
        for (k, (name, unit)) in p.names.iter().zip(&p.units).enumerate() {
            telemetry.set_item(name, block.get_item(k)?)?;
            units.set_item(name, unit)?;
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
            q_lvlh,
            lvlh_rpy,
            omega_lvlh,
            telemetry: telemetry.unbind(),
            events: events.unbind(),
            summary: summary.unbind(),
            status: p.outcome.status.label().to_string(),
            units: units.unbind(),
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

    /// A pandas DataFrame of the samples, a column per `telemetry` column in its order, named
    /// as the `polhode run --csv` header names them (`omega_x [rad/s]`), or by the bare names
    /// with `units=False`: `polhode/_display.py`. A copy; pandas is imported here
    /// (`ImportError` saying what to install when missing).
    #[pyo3(signature = (units=None), text_signature = "($self, units=True)")]
    fn to_pandas(slf: &Bound<'_, Self>, units: Option<&Bound<'_, PyAny>>) -> PyResult<Py<PyAny>> {
        let display = slf.py().import("polhode._display")?;
        Ok(display.call_method1("to_pandas", (slf, units))?.unbind())
    }

    /// A matplotlib Figure of the usual series (body rates, nutation angle, energies, |H|
    /// drift) against time: `polhode/_display.py`. matplotlib is imported here.
    #[pyo3(signature = (figsize=None))]
    fn plot(slf: &Bound<'_, Self>, figsize: Option<&Bound<'_, PyAny>>) -> PyResult<Py<PyAny>> {
        let display = slf.py().import("polhode._display")?;
        Ok(display.call_method1("plot", (slf, figsize))?.unbind())
    }

    /// An HTML summary for Jupyter (status, method, duration, drift, work, events).
    fn _repr_html_(slf: &Bound<'_, Self>) -> PyResult<Py<PyAny>> {
        let display = slf.py().import("polhode._display")?;
        Ok(display.call_method1("result_html", (slf,))?.unbind())
    }
}
