//! `pdyn.Model.optimize`: the library's `pdyn::optimize` (the computation of `pdyn
//! optimize`), run with the GIL released; returned as a dict that
//! `pdyn._optimize.OptimizeResult` wraps (SciPy's `OptimizeResult` fields).

use crate::errors::{guarded, to_py};
use crate::model::PyModel;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The parameter values within bounds that maximise (or minimise) a measure of the runs.
/// `over` is `[(name, lo, hi)]`; `measures` (`[(name, expression, statistic)]`) replaces
/// the model's `[sweep.measures]` as `Model.sweep`'s do; `params` sets parameter values.
#[pyfunction]
#[pyo3(signature = (model, measure, over, maximize=true, params=None, measures=None, jit=true))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn _optimize(
    py: Python<'_>,
    model: PyRef<'_, PyModel>,
    measure: String,
    over: Vec<(String, f64, f64)>,
    maximize: bool,
    params: Option<Vec<(String, f64)>>,
    measures: Option<Vec<(String, String, String)>>,
    jit: bool,
) -> PyResult<PyObject> {
    guarded(py, || {
        let first = over.first().map_or(String::new(), |o| o.0.clone());
        let values: Vec<f64> = over.first().map_or(Vec::new(), |o| vec![o.1, o.2]);
        let with = model.with_measures(py, measures.as_deref(), &first, &values)?;
        let m = with.with_params(params).map_err(|e| to_py(py, &e))?;
        let goal = pdyn::optimize::goal_of(&m, &measure, maximize, &over, "measure")
            .map_err(|e| to_py(py, &e))?;
        let req = pdyn::Request {
            jit: if jit {
                pdyn::sim::JitMode::Auto
            } else {
                pdyn::sim::JitMode::Off
            },
            ..Default::default()
        };
        let best = py
            .allow_threads(|| pdyn::optimize::run(m, &req, &goal))
            .map_err(|e| to_py(py, &e))?;
        let d = PyDict::new(py);
        d.set_item("x", best.x.clone())?;
        d.set_item(
            "names",
            over.iter().map(|o| o.0.clone()).collect::<Vec<_>>(),
        )?;
        d.set_item("fun", best.value)?;
        d.set_item("nfev", best.evaluations)?;
        d.set_item("method", best.method)?;
        d.set_item("at_bound", best.at_bound)?;
        d.set_item("slope_bracket", best.slope_bracket)?;
        d.set_item("maximize", maximize)?;
        d.set_item("success", best.value.is_finite())?;
        Ok(d.into_any().unbind())
    })
}
