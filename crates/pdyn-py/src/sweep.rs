//! `Model.sweep`: one run per value of a parameter, in parallel with the GIL released
//! ([`pdyn::sim::sweep`] does the work), returned as a dict of NumPy columns.

use crate::convert::f64_array;
use crate::errors::to_py;
use crate::model::{Overrides, PyModel};
use pdyn::sim::ensemble::thread_pool;
use pdyn::sim::sweep;
use pdyn::Error;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The arguments of `Model.sweep` other than the run settings.
pub(crate) struct SweepArgs {
    /// The parameter that varies.
    pub(crate) parameter: String,
    /// Its values, one run each.
    pub(crate) values: Vec<f64>,
    /// `(name, expression, statistic)` of each measure; the model's `[sweep.measures]` when
    /// `None`.
    pub(crate) measures: Option<Vec<(String, String, String)>>,
    /// Threads of a pool of its own; rayon's global pool when `None`.
    pub(crate) threads: Option<usize>,
    /// Parameter values applied before the sweep.
    pub(crate) params: Option<Vec<(String, f64)>>,
    /// Native code for the right-hand side and the observers.
    pub(crate) jit: bool,
}

/// The body of `Model.sweep`.
pub(crate) fn sweep(
    py: Python<'_>,
    model: &PyModel,
    a: SweepArgs,
    o: Overrides,
) -> PyResult<PyObject> {
    let SweepArgs {
        parameter,
        values,
        measures,
        threads,
        params,
        jit,
    } = a;
    let base = model.with_measures(py, measures.as_deref(), &parameter, &values)?;
    let finished = crate::interrupt::interruptible(py, |stop| -> Result<_, Error> {
        let mut model = base.with_params(params)?;
        let origin = model.origin.clone();
        let sim_err = |error| Error::Sim {
            origin: origin.clone(),
            context: "",
            error,
        };
        let index = model
            .parameters
            .iter()
            .position(|p| p.name == parameter)
            .ok_or_else(|| {
                Error::argument(
                    "parameter",
                    format!("`{parameter}` is not a parameter of the model"),
                )
            })?;
        let Some(mut spec) = model.run.sweep.clone() else {
            return Err(Error::argument(
                "measures",
                "the model has no [sweep.measures]: give measures={name: (expression, statistic)}",
            ));
        };
        spec.parameter = index;
        spec.values = values;
        spec.others.clear();
        let mut set = PyModel::settings(&model, o)?;
        set.interrupt = Some(stop);
        let mut prep = PyModel::prepare(&mut model, jit)?;
        if jit {
            prep.make_observers_native();
        }
        let stats: Vec<_> = spec.measures.iter().map(|m| m.stat).collect();
        match threads {
            Some(n) => {
                let pool = thread_pool(n)?;
                pool.install(move || sweep::sweep(&prep, &set, &spec, &stats, &sweep::quiet))
            }
            None => sweep::sweep(&prep, &set, &spec, &stats, &sweep::quiet),
        }
        .map_err(sim_err)
    })?;
    let res = finished.value.map_err(|e| to_py(py, &e))?;
    let d = PyDict::new(py);
    d.set_item("interrupted", finished.interrupted)?;
    d.set_item("parameter", res.parameter.clone())?;
    let nv = res.values.len();
    d.set_item("values", f64_array(py, res.values.clone()))?;
    let table = PyDict::new(py);
    if let Some(sl) = res.slices.first() {
        for (j, m) in res.measures.iter().enumerate() {
            let col: Vec<f64> = sl.table.iter().map(|r| r[j]).collect();
            debug_assert_eq!(col.len(), nv);
            table.set_item(m, f64_array(py, col))?;
        }
    }
    d.set_item("measures", table)?;
    let problems: Vec<(f64, String)> = res
        .problems
        .iter()
        .map(|(at, p)| (at.first().map_or(f64::NAN, |x| x.1), p.to_string()))
        .collect();
    d.set_item("problems", problems)?;
    d.set_item("runs", res.runs)?;
    d.set_item("seconds", res.seconds)?;
    d.set_item("threads", res.threads)?;
    Ok(d.into_any().unbind())
}
