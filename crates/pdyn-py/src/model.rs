//! `pdyn.Model`: a loaded model file and what every run of it shares (parameters applied,
//! settings resolved, the model derived and compiled).
//!
//! pyo3 without its `multiple-pymethods` feature allows one `#[pymethods]` block per class,
//! so that block is here and each method in it is thin: it states the Python signature, then
//! hands the body to the module of its concern ([`crate::run`], [`crate::derive`],
//! [`crate::sweep`], [`crate::ensemble`]) through [`guarded`].

use crate::convert::{dict_to_toml, method_name};
use crate::ensemble::EnsembleArgs;
use crate::errors::{guarded, load_error, pdyn_error, to_py};
use crate::sweep::SweepArgs;
use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use pdyn::sim::{self, Prepared, RunSettings};
use pdyn::Error;
use pdyn_mech::model::spec::Stat;
use pyo3::prelude::*;
use std::sync::Mutex;

/// A model file, loaded (`pdyn.Model` wraps it).
#[pyclass(module = "pdyn._pdyn", name = "Model", frozen)]
pub(crate) struct PyModel {
    /// The model as loaded; every call works on a clone (parameters applied, derived).
    pub(crate) model: pdyn_mech::Model,
    /// The model compiled for an ensemble, keyed by its measures: an ensemble run chunk by
    /// chunk (pdyn.study) derives and compiles the model once, not once per chunk.
    pub(crate) prepared: Mutex<Option<(String, Prepared, Vec<Stat>)>>,
}

/// The run settings given from Python (any may be `None`: the model's `[simulate]` applies).
#[derive(Default)]
pub(crate) struct Overrides {
    pub(crate) t_end: Option<f64>,
    pub(crate) method: Option<String>,
    pub(crate) rtol: Option<f64>,
    pub(crate) atol: Option<f64>,
    pub(crate) t_eval: Option<Vec<f64>>,
    pub(crate) max_step: Option<f64>,
    pub(crate) dt: Option<f64>,
    pub(crate) max_steps: Option<usize>,
    pub(crate) points: Option<usize>,
    pub(crate) drift_tolerance: Option<f64>,
}

impl PyModel {
    /// Wraps a loaded model, with nothing compiled yet.
    pub(crate) fn new(model: pdyn_mech::Model) -> PyModel {
        PyModel {
            model,
            prepared: Mutex::new(None),
        }
    }

    /// The loaded model with `params` applied as `pdyn run --set` applies them.
    pub(crate) fn with_params(
        &self,
        params: Option<Vec<(String, f64)>>,
    ) -> Result<pdyn_mech::Model, Error> {
        let mut model = self.model.clone();
        if let Some(params) = params {
            pdyn::params::set_parameter_values(&mut model, &params, "params")?;
        }
        Ok(model)
    }

    /// The model with `measures` (`(name, expression, statistic)`) written into its
    /// `[sweep]` table and reloaded, so that they are checked and compiled exactly as a file's
    /// measures; the model itself when `measures` is `None`.
    pub(crate) fn with_measures(
        &self,
        py: Python<'_>,
        measures: Option<&[(String, String, String)]>,
        parameter: &str,
        values: &[f64],
    ) -> PyResult<PyModel> {
        let Some(ms) = measures else {
            return Ok(PyModel::new(self.model.clone()));
        };
        let mut table: toml::Table = toml::from_str(&self.model.source)
            .map_err(|e| pdyn_error(py, "PdynError", e.to_string()))?;
        let mut sw = toml::Table::new();
        sw.insert("parameter".into(), toml::Value::String(parameter.into()));
        sw.insert(
            "values".into(),
            toml::Value::Array(values.iter().map(|&v| toml::Value::Float(v)).collect()),
        );
        let mut mt = toml::Table::new();
        for (name, of, stat) in ms {
            let mut one = toml::Table::new();
            one.insert("of".into(), toml::Value::String(of.clone()));
            one.insert("stat".into(), toml::Value::String(stat.clone()));
            mt.insert(name.clone(), toml::Value::Table(one));
        }
        sw.insert("measures".into(), toml::Value::Table(mt));
        table.insert("sweep".into(), toml::Value::Table(sw));
        let text =
            toml::to_string(&table).map_err(|e| pdyn_error(py, "PdynError", e.to_string()))?;
        let origin = format!("{} (with the measures)", self.model.origin);
        Ok(PyModel::new(
            pdyn_mech::load(&text, &origin).map_err(|e| to_py(py, &load_error(&text, e)))?,
        ))
    }

    /// The model's `[simulate]` with the overrides given from Python applied, by the same
    /// library call as `pdyn run`'s flags (`pdyn::sim::request::settings`).
    pub(crate) fn settings(model: &pdyn_mech::Model, o: Overrides) -> Result<RunSettings, Error> {
        let req = pdyn::Request {
            method: o.method.map(|m| method_name(&m)),
            rtol: o.rtol,
            atol: o.atol,
            t_end: o.t_end,
            dt: o.dt,
            max_step: o.max_step,
            max_steps: o.max_steps,
            points: o.points,
            t_eval: o.t_eval,
            drift_tolerance: o.drift_tolerance,
            ..Default::default()
        };
        sim::request::settings(model, &req)
    }

    /// Derives and compiles `model`: the right-hand side as native code with `jit` (the
    /// interpreter otherwise, or where there is no JIT).
    pub(crate) fn prepare(model: &mut pdyn_mech::Model, jit: bool) -> Result<Prepared, Error> {
        let mode = if jit {
            sim::JitMode::Auto
        } else {
            sim::JitMode::Off
        };
        sim::request::prepare(model, mode)
    }
}

#[pymethods]
impl PyModel {
    /// Loads a model from TOML text; `origin` names it in error messages.
    #[staticmethod]
    #[pyo3(signature = (text, origin = "<string>"))]
    pub(crate) fn from_toml(py: Python<'_>, text: &str, origin: &str) -> PyResult<PyModel> {
        guarded(py, || {
            pdyn_mech::load(text, origin)
                .map(PyModel::new)
                .map_err(|e| to_py(py, &load_error(text, e)))
        })
    }

    /// Loads a model from a dict with the layout of a model file.
    #[staticmethod]
    fn from_dict(py: Python<'_>, d: &Bound<'_, PyAny>) -> PyResult<PyModel> {
        guarded(py, || {
            let text = dict_to_toml(d)?;
            Self::from_toml(py, &text, "<dict>")
        })
    }

    /// The TOML text the model was loaded from.
    #[getter]
    fn source(&self, py: Python<'_>) -> PyResult<String> {
        guarded(py, || Ok(self.model.source.clone()))
    }

    /// The model's name.
    #[getter]
    fn name(&self, py: Python<'_>) -> PyResult<String> {
        guarded(py, || Ok(self.model.name.clone()))
    }

    /// The file name used in messages.
    #[getter]
    fn origin(&self, py: Python<'_>) -> PyResult<String> {
        guarded(py, || Ok(self.model.origin.clone()))
    }

    /// `[(name, value in SI units)]`, in file order.
    #[getter]
    fn parameters(&self, py: Python<'_>) -> PyResult<Vec<(String, f64)>> {
        guarded(py, || {
            Ok(self
                .model
                .parameters
                .iter()
                .map(|p| (p.name.clone(), p.value))
                .collect())
        })
    }

    /// Integrates the model; returns a dict of plain data (see `pdyn.Model.run`).
    #[pyo3(signature = (t_end=None, method=None, rtol=None, atol=None, t_eval=None, max_step=None, dt=None, max_steps=None, points=None, drift_tolerance=None, params=None, plots=None, jit=true, initial=None))]
    #[allow(clippy::too_many_arguments)]
    fn run(
        &self,
        py: Python<'_>,
        t_end: Option<f64>,
        method: Option<String>,
        rtol: Option<f64>,
        atol: Option<f64>,
        t_eval: Option<PyReadonlyArray1<'_, f64>>,
        max_step: Option<f64>,
        dt: Option<f64>,
        max_steps: Option<usize>,
        points: Option<usize>,
        drift_tolerance: Option<f64>,
        params: Option<Vec<(String, f64)>>,
        plots: Option<std::path::PathBuf>,
        jit: bool,
        initial: Option<Vec<(String, f64)>>,
    ) -> PyResult<PyObject> {
        guarded(py, || {
            let t_eval = match t_eval {
                Some(a) => Some(a.as_slice()?.to_vec()),
                None => None,
            };
            let o = Overrides {
                t_end,
                method,
                rtol,
                atol,
                t_eval,
                max_step,
                dt,
                max_steps,
                points,
                drift_tolerance,
            };
            crate::run::run(py, self, o, params, initial.unwrap_or_default(), plots, jit)
        })
    }

    /// The equations linearized about a state (see `pdyn.Model.linearize`).
    #[pyo3(signature = (at=None, params=None, t=0.0))]
    fn linearize(
        &self,
        py: Python<'_>,
        at: Option<Vec<(String, f64)>>,
        params: Option<Vec<(String, f64)>>,
        t: f64,
    ) -> PyResult<PyObject> {
        guarded(py, || {
            let lin = py
                .allow_threads(|| -> Result<_, Error> {
                    let mut m = self.with_params(params)?;
                    let mut prep = PyModel::prepare(&mut m, false)?;
                    pdyn::sim::request::set_initial(&mut m, &mut prep, &at.unwrap_or_default())?;
                    let lin = pdyn::sim::linearize::linearize(&prep, t, &prep.y0);
                    Ok((lin, prep.state_names.clone(), prep.y0.clone()))
                })
                .map_err(|e| to_py(py, &e))?;
            let (lin, names, y0) = lin;
            let n = lin.dim / 2;
            let (k, c) = lin.stiffness_and_damping();
            let d = pyo3::types::PyDict::new(py);
            d.set_item(
                "A",
                crate::convert::f64_matrix(py, lin.a, lin.dim, lin.dim)?,
            )?;
            d.set_item("K", crate::convert::f64_matrix(py, k, n, n)?)?;
            d.set_item("C", crate::convert::f64_matrix(py, c, n, n)?)?;
            d.set_item("f0", crate::convert::f64_array(py, lin.f0))?;
            d.set_item("y0", crate::convert::f64_array(py, y0))?;
            d.set_item("state", names)?;
            d.set_item("analytic", lin.analytic)?;
            Ok(d.into_any().unbind())
        })
    }

    /// Parameters and initial values fitted to measured runs (see `pdyn.Model.fit`).
    #[pyo3(signature = (data, free, params=None, bounds=Vec::new(), sigma=Vec::new(),
                        absolute_sigma=false, rtol=1e-10, atol=1e-12, max_nfev=200))]
    #[allow(clippy::too_many_arguments)]
    fn fit(
        &self,
        py: Python<'_>,
        data: Vec<crate::fit::DataArg>,
        free: Vec<String>,
        params: Option<Vec<(String, f64)>>,
        bounds: Vec<(String, f64, f64)>,
        sigma: Vec<(String, f64)>,
        absolute_sigma: bool,
        rtol: f64,
        atol: f64,
        max_nfev: usize,
    ) -> PyResult<PyObject> {
        let model = guarded(py, || self.with_params(params).map_err(|e| to_py(py, &e)))?;
        let args = crate::fit::FitArgs {
            data,
            free,
            bounds,
            sigma,
            absolute_sigma,
            rtol,
            atol,
            max_nfev,
        };
        crate::fit::fit(py, model, args)
    }

    /// Natural frequencies and mode shapes (see `pdyn.Model.modes`).
    #[pyo3(signature = (count=None, about=None, solver=None, params=None))]
    fn modes(
        &self,
        py: Python<'_>,
        count: Option<usize>,
        about: Option<String>,
        solver: Option<String>,
        params: Option<Vec<(String, f64)>>,
    ) -> PyResult<PyObject> {
        guarded(py, || {
            let about = about.as_deref().unwrap_or("equilibrium");
            let solver = solver.as_deref().unwrap_or("auto");
            crate::statics::modes(py, self, count, about, solver, params)
        })
    }

    /// The equations of motion, as text and LaTeX (see `pdyn.Model.derive`).
    fn derive(&self, py: Python<'_>) -> PyResult<PyObject> {
        guarded(py, || crate::derive::derive(py, &self.model))
    }

    /// The unknown forces of a prescribed motion at an instant (see `pdyn.Model.forces`).
    #[pyo3(signature = (at=None, params=None))]
    fn forces(
        &self,
        py: Python<'_>,
        at: Option<Vec<(String, f64)>>,
        params: Option<Vec<(String, f64)>>,
    ) -> PyResult<PyObject> {
        guarded(py, || {
            let model = self.with_params(params).map_err(|e| to_py(py, &e))?;
            crate::derive::forces(py, model, at.unwrap_or_default())
        })
    }

    /// Runs the model once per value of `parameter`, in parallel (see `pdyn.Model.sweep`).
    #[pyo3(signature = (parameter, values, measures=None, t_end=None, method=None, rtol=None, atol=None, max_step=None, dt=None, points=None, threads=None, params=None, jit=true))]
    #[allow(clippy::too_many_arguments)]
    fn sweep(
        &self,
        py: Python<'_>,
        parameter: String,
        values: PyReadonlyArray1<'_, f64>,
        measures: Option<Vec<(String, String, String)>>,
        t_end: Option<f64>,
        method: Option<String>,
        rtol: Option<f64>,
        atol: Option<f64>,
        max_step: Option<f64>,
        dt: Option<f64>,
        points: Option<usize>,
        threads: Option<usize>,
        params: Option<Vec<(String, f64)>>,
        jit: bool,
    ) -> PyResult<PyObject> {
        guarded(py, || {
            let args = SweepArgs {
                parameter,
                values: values.as_slice()?.to_vec(),
                measures,
                threads,
                params,
                jit,
            };
            let o = Overrides {
                t_end,
                method,
                rtol,
                atol,
                max_step,
                dt,
                points,
                ..Overrides::default()
            };
            crate::sweep::sweep(py, self, args, o)
        })
    }

    /// Runs the model once per row of `params` (and of `initial`), in parallel on all cores
    /// with the GIL released (see `pdyn.Model.ensemble`). With `dry_run`, only checks every
    /// row (names, masses > 0) and returns the problems.
    #[pyo3(signature = (param_names, params, initial_names, initial=None, measures=None, t_end=None, method=None, rtol=None, atol=None, max_step=None, dt=None, points=None, drift_tolerance=None, threads=None, dry_run=false, jit=true))]
    #[allow(clippy::too_many_arguments)]
    fn ensemble(
        &self,
        py: Python<'_>,
        param_names: Vec<String>,
        params: PyReadonlyArray2<'_, f64>,
        initial_names: Vec<String>,
        initial: Option<PyReadonlyArray2<'_, f64>>,
        measures: Option<Vec<(String, String, String)>>,
        t_end: Option<f64>,
        method: Option<String>,
        rtol: Option<f64>,
        atol: Option<f64>,
        max_step: Option<f64>,
        dt: Option<f64>,
        points: Option<usize>,
        drift_tolerance: Option<f64>,
        threads: Option<usize>,
        dry_run: bool,
        jit: bool,
    ) -> PyResult<PyObject> {
        guarded(py, || {
            let args = EnsembleArgs {
                param_names,
                params: &params,
                initial_names,
                initial: initial.as_ref(),
                measures,
                threads,
                dry_run,
                jit,
            };
            let o = Overrides {
                t_end,
                method,
                rtol,
                atol,
                max_step,
                dt,
                points,
                drift_tolerance,
                ..Overrides::default()
            };
            crate::ensemble::ensemble(py, self, args, o)
        })
    }
}
