//! `Model.run`: one integration with the GIL released, returned as a dict of plain data (the
//! Python layer builds `pdyn.OdeResult` from it).
//!
//! The run is `pdyn::sim::request::execute`, as for `pdyn run`: numerical, or the closed form
//! with `method="exact"`; a run that finishes but tabulates NaN or infinity fails with the same
//! error (`pdyn::sim::request::non_finite`).

use crate::convert::{f64_matrix, stats_dict};
use crate::errors::to_py;
use crate::model::{Overrides, PyModel};
use pdyn::sim::{self, RunResult};
use pdyn::Error;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::PathBuf;

/// The body of `Model.run`: parameters applied, settings resolved, the model derived,
/// compiled and integrated with the GIL released; pdyn's plots written into `plots`.
pub(crate) fn run(
    py: Python<'_>,
    model: &PyModel,
    o: Overrides,
    params: Option<Vec<(String, f64)>>,
    initial: Vec<(String, f64)>,
    plots: Option<PathBuf>,
    jit: bool,
) -> PyResult<PyObject> {
    let finished = crate::interrupt::interruptible(py, |stop| -> Result<_, Error> {
        let mut m = model.with_params(params)?;
        let mut set = PyModel::settings(&m, o)?;
        set.interrupt = Some(stop);
        let mut prep = PyModel::prepare(&mut m, jit)?;
        sim::request::set_initial(&mut m, &mut prep, &initial)?;
        // The failure is read back from the result by `run_dict` (with the non-finite columns'
        // names for `OdeResult`).
        let (res, _) = sim::request::execute(&mut m, &prep, &set)?;
        if let Some(dir) = &plots {
            // pdyn's own PNG/SVG plots, as `pdyn run --out DIR`.
            std::fs::create_dir_all(dir).map_err(|e| {
                Error::argument("plots", format!("cannot create {}: {e}", dir.display()))
            })?;
            pdyn::plots::write_run_plots(&m, &prep, &res, dir)?;
        }
        let names = prep.events.iter().map(|e| e.name.clone()).collect();
        Ok((res, prep.state_names.len(), names, set.drift_tolerance))
    })?;
    match finished.value {
        Ok((res, n, names, tol)) => {
            let d = run_dict(py, &model.model.origin, res, n, names, tol)?;
            d.bind(py).set_item("interrupted", finished.interrupted)?;
            Ok(d)
        }
        Err(e) => Err(to_py(py, &e)),
    }
}

/// A run result as a dict of plain data (the Python layer builds `pdyn.OdeResult`).
fn run_dict(
    py: Python<'_>,
    origin: &str,
    res: RunResult,
    n_states: usize,
    event_names: Vec<String>,
    drift_tolerance: f64,
) -> PyResult<PyObject> {
    let d = PyDict::new(py);
    d.set_item("event_names", event_names)?;
    // A run that finished but tabulated NaN or infinity fails, as `pdyn run` exits 1 with a
    // `non_finite` error.
    let non_finite = if res.failure.is_none() {
        non_finite_columns(origin, &res)
    } else {
        None
    };
    let status = match &non_finite {
        Some(_) => -1,
        None => res.status.code(),
    };
    d.set_item("status", status)?;
    match &non_finite {
        Some((names, t, e)) => {
            d.set_item("non_finite", names.clone())?;
            d.set_item("non_finite_t", *t)?;
            d.set_item("failure", e.to_string())?;
        }
        None => {
            d.set_item("non_finite", PyList::empty(py))?;
            d.set_item("non_finite_t", py.None())?;
            d.set_item("failure", res.failure.as_ref().map(|f| f.to_string()))?;
        }
    }
    d.set_item("drift_tolerance", drift_tolerance)?;
    let rows = res.rows.len();
    let cols = res.columns.len();
    let flat: Vec<f64> = res.rows.into_iter().flatten().collect();
    d.set_item("columns", res.columns)?;
    d.set_item("table", f64_matrix(py, flat, rows, cols)?)?;
    d.set_item("n_states", n_states)?;
    let events = PyList::empty(py);
    for e in res.events {
        let k = e.state.len();
        events.append((e.name, e.t, f64_matrix(py, e.state, 1, k)?, e.rising))?;
    }
    d.set_item("events", events)?;
    let monitors = PyList::empty(py);
    for m in res.monitors {
        let md = PyDict::new(py);
        md.set_item("name", m.name)?;
        md.set_item("initial", m.initial)?;
        md.set_item("drift", m.drift)?;
        md.set_item("relative", m.relative)?;
        md.set_item("scale", m.scale)?;
        md.set_item("conserved", m.conserved)?;
        monitors.append(md)?;
    }
    d.set_item("monitors", monitors)?;
    d.set_item("warnings", res.warnings)?;
    d.set_item("stats", stats_dict(py, &res.stats)?)?;
    d.set_item("method", res.method.to_string())?;
    // The mode timeline, switches, impacts and energy accounting of a hybrid run, as the
    // `hybrid` object of `summary.json` (the Python layer reads it with `json`).
    d.set_item(
        "hybrid_json",
        res.hybrid.as_ref().map(pdyn::output::hybrid_json),
    )?;
    Ok(d.into_any().unbind())
}

/// The output columns of a run that hold NaN or infinity, the first time one does, and the
/// error `pdyn run` reports for them (`non_finite`, exit code 1); `None` when all are finite.
fn non_finite_columns(origin: &str, res: &RunResult) -> Option<(Vec<String>, f64, Error)> {
    let (nf, error) = sim::request::non_finite(origin, res)?;
    let names: Vec<String> = nf.columns.iter().map(|&c| res.columns[c].clone()).collect();
    Some((names, nf.t, error))
}
