//! `pdyn.Model.fit`: the library's `pdyn::fit` (the computation of `pdyn fit`), run with the
//! GIL released; returned as a dict that `pdyn._fit.FitResult` wraps (SciPy's
//! `least_squares` fields plus the standard errors and correlations).

use crate::convert::{f64_array, f64_matrix};
use crate::errors::guarded;
use pdyn::fit::{self, experiment, FitRequest};
use pdyn::Error;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// One experiment as Python gives it: a file path, or a name with times and named columns.
pub(crate) type DataArg = (String, Option<(Vec<f64>, Vec<(String, Vec<f64>)>)>);

/// The options of `Model.fit`, as Python passes them.
pub(crate) struct FitArgs {
    pub data: Vec<DataArg>,
    pub free: Vec<String>,
    pub bounds: Vec<(String, f64, f64)>,
    pub sigma: Vec<(String, f64)>,
    pub absolute_sigma: bool,
    pub rtol: f64,
    pub atol: f64,
    pub max_nfev: usize,
}

/// Fits `model` (parameter values set) and returns the result dict.
pub(crate) fn fit(py: Python<'_>, mut model: pdyn_mech::Model, a: FitArgs) -> PyResult<PyObject> {
    guarded(py, || {
        let res = py
            .allow_threads(|| -> Result<fit::FitResult, Error> {
                let names = experiment::state_names(&model);
                let exps = a
                    .data
                    .into_iter()
                    .map(|(name, arrays)| match arrays {
                        None => experiment::read(std::path::Path::new(&name), &names),
                        Some((t, cols)) => experiment::from_arrays(&name, t, cols, &names),
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                let req = FitRequest {
                    free: a.free,
                    bounds: a.bounds,
                    sigma: a.sigma,
                    absolute_sigma: a.absolute_sigma,
                    rtol: a.rtol,
                    atol: a.atol,
                    lm: fit::lm::Settings {
                        max_evaluations: a.max_nfev,
                        ..Default::default()
                    },
                    ..Default::default()
                };
                fit::fit(&mut model, &exps, &req)
            })
            .map_err(|e| crate::data::data_py(py, &e))?;
        let n = res.estimates.len();
        let d = PyDict::new(py);
        d.set_item(
            "names",
            res.estimates
                .iter()
                .map(|e| e.name.clone())
                .collect::<Vec<_>>(),
        )?;
        d.set_item(
            "x",
            f64_array(py, res.estimates.iter().map(|e| e.value).collect()),
        )?;
        d.set_item(
            "stderr",
            f64_array(py, res.estimates.iter().map(|e| e.stderr).collect()),
        )?;
        d.set_item(
            "x0",
            f64_array(py, res.estimates.iter().map(|e| e.start).collect()),
        )?;
        d.set_item("corr", f64_matrix(py, res.corr.clone(), n, n)?)?;
        d.set_item("cov", f64_matrix(py, res.cov.clone(), n, n)?)?;
        let m = res.fun.len();
        d.set_item("fun", f64_array(py, res.fun.clone()))?;
        d.set_item("jac", f64_matrix(py, res.jac.clone(), m, n)?)?;
        d.set_item("cost", res.cost)?;
        d.set_item("chi2", res.chi2)?;
        d.set_item("dof", res.dof)?;
        d.set_item("status", res.status.code())?;
        d.set_item("message", res.status.message())?;
        d.set_item("success", res.status.converged())?;
        d.set_item("nfev", res.evaluations)?;
        d.set_item("njev", res.evaluations)?;
        d.set_item("warnings", fit::report::warnings(&res))?;
        d.set_item(
            "unidentifiable",
            res.unidentifiable
                .iter()
                .map(|u| u.names.clone())
                .collect::<Vec<_>>(),
        )?;
        d.set_item("summary", fit::summary_text(&res))?;
        let exps = pyo3::types::PyList::empty(py);
        for e in &res.experiments {
            let x = PyDict::new(py);
            x.set_item("name", &e.name)?;
            x.set_item("t", f64_array(py, e.t.clone()))?;
            let cols = PyDict::new(py);
            for c in &e.columns {
                let cd = PyDict::new(py);
                cd.set_item("data", f64_array(py, c.data.clone()))?;
                cd.set_item("model", f64_array(py, c.model.clone()))?;
                cd.set_item("sigma", f64_array(py, c.sigma.clone()))?;
                cd.set_item("rms", c.rms)?;
                cols.set_item(&c.name, cd)?;
            }
            x.set_item("columns", cols)?;
            exps.append(x)?;
        }
        d.set_item("experiments", exps)?;
        Ok(d.into_any().unbind())
    })
}
