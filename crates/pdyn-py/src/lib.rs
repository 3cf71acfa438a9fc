//! `pdyn._pdyn`: the Rust half of the Python package `pdyn` (the pure-Python half, in
//! `python/pdyn/`, builds result objects, emits warnings and holds the docstrings users read).
//!
//! Every function here returns plain Python data (dicts, lists, float64 NumPy arrays) and
//! raises the exceptions defined in `pdyn._errors`. Errors are typed down to this boundary
//! ([`pdyn::Error`], [`pdyn_mech::ModelError`], ...) and rendered only here. Integrations run
//! with the GIL released, except when they must call back into Python.
#![warn(missing_docs)]

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pdyn::sim::measured::{measure, NonFinite};
use pdyn::sim::{self, sweep, Prepared, RunResult, RunSettings};
use pdyn::Error;
use pdyn_expr::{Id, Pool, Program};
use pdyn_mech::model::spec::{SimulateSpec, Stat};
use pdyn_ode::{Direction, Event, FnSystem, Method, Options, Solution, Status};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::cell::RefCell;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::{Arc, Mutex};

/// Builds an instance of an exception class of `pdyn._errors`.
fn py_error<'py>(
    py: Python<'py>,
    class: &str,
    make: impl FnOnce(&Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>>,
) -> PyErr {
    let made = py
        .import("pdyn._errors")
        .and_then(|m| m.getattr(class))
        .and_then(|c| make(&c));
    match made {
        Ok(inst) => PyErr::from_value(inst),
        Err(e) => e,
    }
}

/// `pdyn.PdynError(message)`, or a subclass named by `class`.
fn pdyn_error(py: Python<'_>, class: &str, message: String) -> PyErr {
    py_error(py, class, |c| c.call1((message,)))
}

/// Renders a [`pdyn::Error`]: `ModelError` (with file, line, column) for a model that does not
/// load, `ParameterError` for a bad parameter value or option, `PdynError` otherwise.
fn to_py(py: Python<'_>, e: &Error) -> PyErr {
    match e {
        Error::Model { error, .. } => {
            let loc = e.location();
            let (line, column) = loc.as_ref().map_or((None, None), |l| (l.line, l.column));
            py_error(py, "ModelError", |c| {
                c.call1((
                    e.to_string(),
                    error.origin.clone(),
                    line,
                    column,
                    error.message.clone(),
                ))
            })
        }
        Error::Value { .. } | Error::Argument { .. } => {
            pdyn_error(py, "ParameterError", e.to_string())
        }
        Error::Sim {
            error:
                sim::SimError::InvalidOption { .. }
                | sim::SimError::InvalidEndTime(_)
                | sim::SimError::InvalidTEval { .. }
                | sim::SimError::UnknownMethod { .. }
                | sim::SimError::NeedsStep { .. }
                | sim::SimError::NoEndTime
                | sim::SimError::InvalidValue(_),
            ..
        } => pdyn_error(py, "ParameterError", e.to_string()),
        _ => pdyn_error(py, "PdynError", e.to_string()),
    }
}

/// Runs `f`, turning a panic (a bug in pdyn) into `pdyn.PdynError` instead of unwinding into
/// the interpreter.
fn guarded<T>(py: Python<'_>, f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(payload) => {
            let msg = payload
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "panic".into());
            Err(pdyn_error(
                py,
                "PdynError",
                format!("internal error in pdyn (please report it): {msg}"),
            ))
        }
    }
}

/// SciPy's method names (`RK45`, `DOP853`, `Radau`) and pdyn's own (`tsit5`, `vern9`, ...).
fn method_name(name: &str) -> String {
    match name.to_ascii_lowercase().as_str() {
        "rk45" => "dopri5".into(),
        "radau" => "radau5".into(),
        other => other.into(),
    }
}

/// A model file, loaded (`pdyn.Model` wraps it).
#[pyclass(module = "pdyn._pdyn", name = "Model", frozen)]
struct PyModel {
    model: pdyn_mech::Model,
    /// The model compiled for an ensemble, keyed by its measures: an ensemble run chunk by
    /// chunk (pdyn.study) derives and compiles the model once, not once per chunk.
    prepared: Mutex<Option<(String, Prepared, Vec<Stat>)>>,
}

impl PyModel {
    fn new(model: pdyn_mech::Model) -> PyModel {
        PyModel {
            model,
            prepared: Mutex::new(None),
        }
    }
}

/// The run settings given from Python (any may be `None`: the model's `[simulate]` applies).
#[derive(Default)]
struct Overrides {
    t_end: Option<f64>,
    method: Option<String>,
    rtol: Option<f64>,
    atol: Option<f64>,
    t_eval: Option<Vec<f64>>,
    max_step: Option<f64>,
    dt: Option<f64>,
    max_steps: Option<usize>,
    points: Option<usize>,
    drift_tolerance: Option<f64>,
}

impl PyModel {
    /// The loaded model with `params` applied as `pdyn run --set` applies them.
    fn with_params(&self, params: Option<Vec<(String, f64)>>) -> Result<pdyn_mech::Model, Error> {
        let mut model = self.model.clone();
        if let Some(params) = params {
            pdyn::params::set_parameter_values(&mut model, &params, "params")?;
        }
        Ok(model)
    }

    /// The model with `measures` (`(name, expression, statistic)`) written into its
    /// `[sweep]` table and reloaded, so that they are checked and compiled exactly as a file's
    /// measures; the model itself when `measures` is `None`.
    fn with_measures(
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

    fn settings(model: &pdyn_mech::Model, o: Overrides) -> Result<RunSettings, Error> {
        let sim_err = |error| Error::Sim {
            origin: model.origin.clone(),
            context: "",
            error,
        };
        let overrides = SimulateSpec {
            t_end: o.t_end,
            method: o.method.map(|m| (method_name(&m), 0..0)),
            rtol: o.rtol,
            atol: o.atol,
            dt: o.dt,
            max_step: o.max_step,
            max_steps: o.max_steps,
            points: o.points,
            output_dt: None,
            drift_tolerance: o.drift_tolerance,
        };
        let mut file = model.run.simulate.clone();
        if o.t_eval.is_some() || o.points.is_some() {
            // Explicit output times replace the file's output spacing.
            file.output_dt = None;
            file.points = None;
        }
        RunSettings::resolve(&file, &overrides, o.t_eval).map_err(sim_err)
    }

    /// Derives and compiles `model`: the right-hand side as native code with `jit` (the
    /// interpreter otherwise, or where there is no JIT).
    fn prepare(model: &mut pdyn_mech::Model, jit: bool) -> Result<Prepared, Error> {
        let mode = if jit {
            sim::JitMode::Auto
        } else {
            sim::JitMode::Off
        };
        sim::prepare_with_jit(model, &sim::run_options(), mode).map_err(|error| Error::Sim {
            origin: model.origin.clone(),
            context: "",
            error,
        })
    }
}

/// Output columns, conservation scales, measures and events as native code (the right-hand
/// side already is, from [`sim::prepare`]): a sweep or an ensemble evaluates them at every
/// output point of every run. The same results bit for bit.
fn native_observers(p: &mut Prepared) {
    p.observer.make_native();
    p.scales.make_native();
    if let Some(m) = p.measures.as_mut() {
        m.make_native();
    }
    for e in &mut p.events {
        e.function.make_native();
    }
}

fn load_error(source: &str, error: pdyn_mech::ModelError) -> Error {
    Error::Model {
        error,
        source: source.into(),
    }
}

fn f64_array<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_vec(py, v)
}

/// A `(rows, cols)` float64 array from a flat row-major vector.
fn f64_matrix(py: Python<'_>, v: Vec<f64>, rows: usize, cols: usize) -> PyResult<PyObject> {
    let a = PyArray1::from_vec(py, v);
    Ok(a.reshape([rows, cols])?.into_any().unbind())
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
    let nf = NonFinite::of_rows(&res.rows)?;
    Some(non_finite_error(origin, &res.columns, &nf))
}

/// [`non_finite_columns`] from the non-finite columns of a run (table or not).
fn non_finite_error(origin: &str, columns: &[String], nf: &NonFinite) -> (Vec<String>, f64, Error) {
    let names: Vec<String> = nf.columns.iter().map(|&c| columns[c].clone()).collect();
    let quoted: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    let error = Error::NonFinite {
        what: format!(
            "{origin}: the output column(s) {} (first at t = {:e})",
            quoted.join(", "),
            nf.t
        ),
        components: nf.columns.clone(),
    };
    (names, nf.t, error)
}

fn stats_dict<'py>(py: Python<'py>, s: &pdyn_ode::Stats) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("steps", s.steps)?;
    d.set_item("accepted", s.accepted)?;
    d.set_item("rejected", s.rejected)?;
    d.set_item("fevals", s.fevals)?;
    d.set_item("jac_fevals", s.jac_fevals)?;
    d.set_item("jacobians", s.jacobians)?;
    d.set_item("lu_decompositions", s.lu_decompositions)?;
    d.set_item("linear_solves", s.linear_solves)?;
    d.set_item("stiffness_detected_at", s.stiffness_detected_at)?;
    Ok(d)
}

/// A Python dict as TOML text (the keys in insertion order).
fn dict_to_toml(obj: &Bound<'_, PyAny>) -> PyResult<String> {
    fn value(obj: &Bound<'_, PyAny>, at: &str) -> PyResult<toml::Value> {
        if let Ok(b) = obj.downcast::<pyo3::types::PyBool>() {
            return Ok(toml::Value::Boolean(b.is_true()));
        }
        if let Ok(i) = obj.downcast::<pyo3::types::PyInt>() {
            return Ok(toml::Value::Integer(i.extract()?));
        }
        if let Ok(f) = obj.downcast::<pyo3::types::PyFloat>() {
            return Ok(toml::Value::Float(f.value()));
        }
        if let Ok(s) = obj.downcast::<pyo3::types::PyString>() {
            return Ok(toml::Value::String(s.extract::<String>()?));
        }
        if let Ok(d) = obj.downcast::<PyDict>() {
            let mut t = toml::Table::new();
            for (k, v) in d.iter() {
                let k: String = k.extract().map_err(|_| {
                    PyTypeError::new_err(format!("{at}: dictionary keys must be strings"))
                })?;
                let sub = value(&v, &format!("{at}.{k}"))?;
                t.insert(k, sub);
            }
            return Ok(toml::Value::Table(t));
        }
        if let Ok(seq) = obj.try_iter() {
            let mut out = Vec::new();
            for (i, item) in seq.enumerate() {
                out.push(value(&item?, &format!("{at}[{i}]"))?);
            }
            return Ok(toml::Value::Array(out));
        }
        // NumPy scalars and other numbers.
        if let Ok(x) = obj.extract::<f64>() {
            return Ok(toml::Value::Float(x));
        }
        Err(PyTypeError::new_err(format!(
            "{at}: cannot write a {} into a model (use str, int, float, bool, list or dict)",
            obj.get_type().name()?
        )))
    }
    match value(obj, "model")? {
        toml::Value::Table(t) => toml::to_string(&t)
            .map_err(|e| PyTypeError::new_err(format!("cannot write the model as TOML: {e}"))),
        _ => Err(PyTypeError::new_err("a model must be a dict")),
    }
}

#[pymethods]
impl PyModel {
    /// Loads a model from TOML text; `origin` names it in error messages.
    #[staticmethod]
    #[pyo3(signature = (text, origin = "<string>"))]
    fn from_toml(py: Python<'_>, text: &str, origin: &str) -> PyResult<PyModel> {
        guarded(py, || {
            pdyn_mech::load(text, origin)
                .map(PyModel::new)
                .map_err(|e| to_py(py, &load_error(text, e)))
        })
    }

    /// Loads a model from a dict with the layout of a model file.
    #[staticmethod]
    fn from_dict(py: Python<'_>, d: &Bound<'_, PyAny>) -> PyResult<PyModel> {
        let text = dict_to_toml(d)?;
        Self::from_toml(py, &text, "<dict>")
    }

    /// The TOML text the model was loaded from.
    #[getter]
    fn source(&self) -> String {
        self.model.source.clone()
    }

    /// The model's name.
    #[getter]
    fn name(&self) -> String {
        self.model.name.clone()
    }

    /// The file name used in messages.
    #[getter]
    fn origin(&self) -> String {
        self.model.origin.clone()
    }

    /// `[(name, value in SI units)]`, in file order.
    #[getter]
    fn parameters(&self) -> Vec<(String, f64)> {
        self.model
            .parameters
            .iter()
            .map(|p| (p.name.clone(), p.value))
            .collect()
    }

    /// Integrates the model; returns a dict of plain data (see `pdyn.Model.run`).
    #[pyo3(signature = (t_end=None, method=None, rtol=None, atol=None, t_eval=None, max_step=None, dt=None, max_steps=None, points=None, drift_tolerance=None, params=None, plots=None, jit=true))]
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
    ) -> PyResult<PyObject> {
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
        let outcome = py.allow_threads(|| {
            catch_unwind(AssertUnwindSafe(
                || -> Result<(RunResult, usize, Vec<String>, f64), Error> {
                    let mut model = self.with_params(params)?;
                    let set = Self::settings(&model, o)?;
                    let prep = Self::prepare(&mut model, jit)?;
                    let res = sim::run(&prep, &set).map_err(|error| Error::Sim {
                        origin: model.origin.clone(),
                        context: "",
                        error,
                    })?;
                    if let Some(dir) = &plots {
                        // pdyn's own PNG/SVG plots, as `pdyn run --out DIR`.
                        std::fs::create_dir_all(dir).map_err(|e| {
                            Error::argument(
                                "plots",
                                format!("cannot create {}: {e}", dir.display()),
                            )
                        })?;
                        pdyn::plots::write_run_plots(&model, &prep, &res, dir)?;
                    }
                    let names = prep.events.iter().map(|e| e.name.clone()).collect();
                    Ok((res, prep.state_names.len(), names, set.drift_tolerance))
                },
            ))
        });
        match outcome {
            Ok(Ok((res, n, names, tol))) => run_dict(py, &self.model.origin, res, n, names, tol),
            Ok(Err(e)) => Err(to_py(py, &e)),
            Err(_) => Err(pdyn_error(
                py,
                "PdynError",
                "internal error in pdyn during the run (please report it)".into(),
            )),
        }
    }

    /// The equations of motion, as text and LaTeX (see `pdyn.Model.derive`).
    fn derive(&self, py: Python<'_>) -> PyResult<PyObject> {
        guarded(py, || {
            let mut model = self.model.clone();
            let d = pdyn_mech::derive(&mut model, &pdyn_mech::DeriveOptions::default()).map_err(
                |error| {
                    to_py(
                        py,
                        &Error::Derive {
                            origin: model.origin.clone(),
                            error,
                        },
                    )
                },
            )?;
            // `M q'' = f` with entries collected and factored, as `pdyn derive` prints it
            // (`None` when some unknown is a reaction).
            let matrix = pdyn_mech::matrix_form::matrix_form(&mut model.pool, &d).map(|m| {
                let p = &mut model.pool;
                let mut entry =
                    |x: &pdyn_mech::matrix_form::Entry| (x.render(p, false), x.render(p, true));
                let mass: Vec<Vec<(String, String)>> = (0..m.n)
                    .map(|j| (0..m.n).map(|k| entry(&m.mass[j * m.n + k])).collect())
                    .collect();
                let forcing: Vec<(String, String)> = m.forcing.iter().map(&mut entry).collect();
                (mass, forcing)
            });
            let p: &Pool = &model.pool;
            let e = |id: Id| (p.to_text(id), p.to_latex(id));
            let out = PyDict::new(py);
            let (mass, forcing) = matrix.unzip();
            out.set_item("mass_matrix", mass)?;
            out.set_item("forcing", forcing)?;
            let eqs: Vec<_> = d
                .equations
                .iter()
                .map(|q| (q.label.clone(), e(q.lhs), e(q.rhs)))
                .collect();
            out.set_item("equations", eqs)?;
            out.set_item(
                "unknowns",
                d.unknowns
                    .iter()
                    .map(|u| u.name.clone())
                    .collect::<Vec<_>>(),
            )?;
            out.set_item(
                "solution",
                d.solution.as_ref().map(|s| {
                    d.unknowns
                        .iter()
                        .zip(s)
                        .map(|(u, &x)| (u.name.clone(), e(x)))
                        .collect::<Vec<_>>()
                }),
            )?;
            out.set_item("state", d.state_names.clone())?;
            // d/dt q = q' for each free coordinate, then d/dt q' = the solved acceleration.
            let first_order = d.accelerations().map(|acc| {
                let n = d.free.len();
                let mut rows: Vec<(String, (String, String))> = Vec::new();
                for i in 0..n {
                    let rate = &d.state_names[n + i];
                    rows.push((d.state_names[i].clone(), (rate.clone(), rate.clone())));
                }
                for (i, &a) in acc.iter().enumerate() {
                    rows.push((d.state_names[n + i].clone(), e(a)));
                }
                rows
            });
            out.set_item("first_order", first_order)?;
            out.set_item("notes", d.notes.clone())?;
            out.set_item("form", format!("{:?}", d.form).to_lowercase())?;
            Ok(out.into_any().unbind())
        })
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
            let mut model = self.with_params(params).map_err(|e| to_py(py, &e))?;
            let opts = pdyn_mech::prescribed::ForcesOptions {
                at: at.unwrap_or_default(),
            };
            let res = pdyn_mech::prescribed::solve_forces(&mut model, &opts).map_err(|error| {
                to_py(
                    py,
                    &Error::Forces {
                        origin: model.origin.clone(),
                        error,
                    },
                )
            })?;
            let p: &Pool = &model.pool;
            let e = |id: Id| (p.to_text(id), p.to_latex(id));
            let out = PyDict::new(py);
            out.set_item("instant", res.instant.clone())?;
            out.set_item(
                "equations",
                res.equations
                    .iter()
                    .map(|q| (q.label.clone(), e(q.lhs), e(q.rhs)))
                    .collect::<Vec<_>>(),
            )?;
            out.set_item("unknowns", res.unknowns.clone())?;
            out.set_item(
                "symbolic",
                res.symbolic
                    .as_ref()
                    .map(|s| s.iter().map(|&x| e(x)).collect::<Vec<_>>()),
            )?;
            out.set_item("numeric", res.numeric.clone())?;
            let checks = PyList::empty(py);
            for c in &res.checks {
                let d = PyDict::new(py);
                d.set_item("name", c.name.clone())?;
                d.set_item("condition", c.condition.clone())?;
                d.set_item("parameter", c.parameter.clone())?;
                d.set_item(
                    "symbolic",
                    c.symbolic.iter().map(|&x| e(x)).collect::<Vec<_>>(),
                )?;
                d.set_item("min", c.min)?;
                d.set_item("max", c.max)?;
                d.set_item("over", c.over.clone())?;
                d.set_item("forces_at_critical", c.forces_at_critical.clone())?;
                d.set_item(
                    "critical",
                    c.critical
                        .iter()
                        .map(|k| (k.value, k.forces.clone()))
                        .collect::<Vec<_>>(),
                )?;
                checks.append(d)?;
            }
            out.set_item("checks", checks)?;
            out.set_item("notes", res.notes.clone())?;
            Ok(out.into_any().unbind())
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
        let values = values.as_slice()?.to_vec();
        let base = self.with_measures(py, measures.as_deref(), &parameter, &values)?;
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
        let outcome = py.allow_threads(|| {
            catch_unwind(AssertUnwindSafe(|| -> Result<sweep::SweepResult, Error> {
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
                let set = Self::settings(&model, o)?;
                let mut prep = Self::prepare(&mut model, jit)?;
                if jit {
                    native_observers(&mut prep);
                }
                let stats: Vec<_> = spec.measures.iter().map(|m| m.stat).collect();
                match threads {
                    Some(n) => {
                        let pool = rayon_pool(n)?;
                        pool.install(move || sweep::sweep(&prep, &set, &spec, &stats, false))
                    }
                    None => sweep::sweep(&prep, &set, &spec, &stats, false),
                }
                .map_err(sim_err)
            }))
        });
        let res = match outcome {
            Ok(Ok(r)) => r,
            Ok(Err(e)) => return Err(to_py(py, &e)),
            Err(_) => {
                return Err(pdyn_error(
                    py,
                    "PdynError",
                    "internal error in pdyn during the sweep (please report it)".into(),
                ))
            }
        };
        let d = PyDict::new(py);
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
        let shape = params.shape();
        let (runs, k) = (shape[0], shape[1]);
        if k != param_names.len() {
            return Err(pdyn_error(
                py,
                "ParameterError",
                format!(
                    "params has {k} columns for {} parameter names",
                    param_names.len()
                ),
            ));
        }
        let pvals: Vec<f64> = params.as_array().iter().copied().collect();
        let ivals: Vec<f64> = match &initial {
            Some(a) => {
                let sh = a.shape();
                if sh[0] != runs || sh[1] != initial_names.len() {
                    return Err(pdyn_error(
                        py,
                        "ParameterError",
                        format!(
                            "initial has shape ({}, {}); expected ({runs}, {}): one row per run, one column per name in initial_names",
                            sh[0],
                            sh[1],
                            initial_names.len()
                        ),
                    ));
                }
                a.as_array().iter().copied().collect()
            }
            None if initial_names.is_empty() => Vec::new(),
            None => {
                return Err(pdyn_error(
                    py,
                    "ParameterError",
                    "initial_names given without initial values".into(),
                ))
            }
        };
        // The compiled model and its measures' statistics, from the cache when this model
        // already ran an ensemble with the same measures.
        let key = format!("{measures:?} jit={jit}");
        let cached = self
            .prepared
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .as_ref()
            .filter(|c| c.0 == key)
            .map(|c| (c.1.clone(), c.2.clone()));
        let base = match (&cached, &measures, self.model.parameters.first()) {
            (Some(_), _, _) | (None, None, _) => None,
            (None, Some(_), Some(p)) => {
                Some(self.with_measures(py, measures.as_deref(), &p.name, &[p.value])?)
            }
            (None, Some(_), None) => {
                return Err(pdyn_error(
                    py,
                    "ParameterError",
                    "measures need a model with at least one parameter".into(),
                ))
            }
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
        let outcome = py.allow_threads(|| {
            catch_unwind(AssertUnwindSafe(|| -> Result<EnsembleOut, Error> {
                let set = Self::settings(&self.model, o)?;
                set.validate().map_err(|error| Error::Sim {
                    origin: self.model.origin.clone(),
                    context: "",
                    error,
                })?;
                let (prep, stats) = match cached {
                    Some(c) => c,
                    None => {
                        let mut model = match &base {
                            Some(b) => b.model.clone(),
                            None => self.model.clone(),
                        };
                        let mut p = Self::prepare(&mut model, jit)?;
                        if jit {
                            native_observers(&mut p);
                        }
                        let stats: Vec<Stat> = model
                            .run
                            .sweep
                            .as_ref()
                            .map(|s| s.measures.iter().map(|m| m.stat).collect())
                            .unwrap_or_default();
                        *self.prepared.lock().unwrap_or_else(|e| e.into_inner()) =
                            Some((key, p.clone(), stats.clone()));
                        (p, stats)
                    }
                };
                let pidx = param_names
                    .iter()
                    .map(|name| {
                        prep.parameter_names
                            .iter()
                            .position(|p| p == name)
                            .ok_or_else(|| {
                                Error::argument(
                                    "params",
                                    format!(
                                        "`{name}` is not a parameter (parameters: {})",
                                        prep.parameter_names.join(", ")
                                    ),
                                )
                            })
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                let sidx = initial_names
                    .iter()
                    .map(|name| {
                        prep.state_names
                            .iter()
                            .position(|p| p == name)
                            .ok_or_else(|| {
                                Error::argument(
                                    "initial",
                                    format!(
                                        "`{name}` is not a state component (state: {})",
                                        prep.state_names.join(", ")
                                    ),
                                )
                            })
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                let defaults = prep.system.parameters();
                let derived = prep.derived.clone();
                // A row's parameters: the given ones, the model's values for the rest, and the
                // derived ones (`m = "4/3*pi*a^3*rho"`) recomputed unless given.
                let row_params = |r: usize| -> Vec<f64> {
                    let mut v = defaults.clone();
                    for (j, &i) in pidx.iter().enumerate() {
                        v[i] = pvals[r * k + j];
                    }
                    derived.apply(&mut v, &pidx);
                    v
                };
                if dry_run {
                    let mut problems = Vec::new();
                    for r in 0..runs {
                        let v = row_params(r);
                        if let Some(x) = v.iter().find(|x| !x.is_finite()) {
                            problems.push((r, format!("a parameter value is not finite ({x})")));
                        } else if let Err(e) = prep.check_parameters(&v) {
                            problems.push((r, e.to_string()));
                        }
                    }
                    return Ok(EnsembleOut::dry(problems, &prep));
                }
                let ni = sidx.len();
                let names = EnsembleOut::names(&prep);
                let work = move || -> Vec<RunOut> {
                    use rayon::prelude::*;
                    (0..runs)
                        .into_par_iter()
                        .map_with(prep.clone(), |p, r| {
                            p.set_parameters(&row_params(r));
                            for (j, &i) in sidx.iter().enumerate() {
                                p.y0[i] = ivals[r * ni + j];
                            }
                            one_run(p, &set, &stats)
                        })
                        .collect()
                };
                let start = std::time::Instant::now();
                let (outs, threads) = match threads {
                    Some(n) => {
                        let pool = rayon_pool(n)?;
                        (pool.install(work), n.max(1))
                    }
                    None => (work(), rayon::current_num_threads()),
                };
                Ok(EnsembleOut::new(
                    outs,
                    names,
                    start.elapsed().as_secs_f64(),
                    threads,
                ))
            }))
        });
        let out = match outcome {
            Ok(Ok(r)) => r,
            Ok(Err(e)) => return Err(to_py(py, &e)),
            Err(_) => {
                return Err(pdyn_error(
                    py,
                    "PdynError",
                    "internal error in pdyn during the ensemble (please report it)".into(),
                ))
            }
        };
        out.into_py_dict(py, runs)
    }
}

/// What one run of an ensemble keeps: its measures, final state, first event hits, monitor
/// drifts, status and the message of a problem.
struct RunOut {
    measures: Vec<f64>,
    t_final: f64,
    final_state: Vec<f64>,
    /// `(t, state)` of each event's first occurrence.
    events: Vec<Option<(f64, Vec<f64>)>>,
    drifts: Vec<f64>,
    drifted: bool,
    status: i32,
    nfev: usize,
    message: Option<String>,
}

/// Runs one member of an ensemble, without its table ([`measure`]: the same bits as
/// `sim::run`'s rows would give).
fn one_run(p: &Prepared, set: &RunSettings, stats: &[Stat]) -> RunOut {
    let n_states = p.state_names.len();
    let mut out = RunOut {
        measures: vec![f64::NAN; stats.len()],
        t_final: f64::NAN,
        final_state: vec![f64::NAN; n_states],
        events: vec![None; p.events.len()],
        drifts: Vec::new(),
        drifted: false,
        status: -2,
        nfev: 0,
        message: None,
    };
    let res = match measure(p, set, stats) {
        Ok(r) => r,
        Err(e) => {
            out.message = Some(e.to_string());
            return out;
        }
    };
    out.status = res.status.code();
    out.nfev = res.stats.fevals;
    out.message = res.failure.as_ref().map(|f| f.to_string());
    if let (None, Some(nf)) = (&res.failure, &res.non_finite) {
        out.status = -1;
        out.message = Some(non_finite_error("this run", &p.columns(), nf).2.to_string());
    }
    if let Some((t, y)) = res.last {
        out.t_final = t;
        out.final_state.copy_from_slice(&y[..n_states]);
    }
    out.events = res.first_hits;
    for m in res.monitors.iter().filter(|m| m.conserved) {
        out.drifts.push(m.drift);
        if m.drift.is_nan() || m.drift > set.drift_tolerance {
            out.drifted = true;
        }
    }
    if p.measures.is_some() {
        out.measures = res.measures;
    }
    out
}

/// The names of an ensemble's measures, events, state components and conserved monitors.
type Names = (Vec<String>, Vec<String>, Vec<String>, Vec<String>);

/// An ensemble's results, gathered column by column.
struct EnsembleOut {
    measure_names: Vec<String>,
    event_names: Vec<String>,
    state_names: Vec<String>,
    monitor_names: Vec<String>,
    outs: Vec<RunOut>,
    problems: Vec<(usize, String)>,
    seconds: f64,
    threads: usize,
}

impl EnsembleOut {
    fn names(prep: &Prepared) -> Names {
        let measures = prep
            .measures
            .as_ref()
            .map(|m| m.names.clone())
            .unwrap_or_default();
        let events = prep.events.iter().map(|e| e.name.clone()).collect();
        let monitors = prep
            .observer
            .names
            .iter()
            .zip(&prep.conserved)
            .filter(|(_, &c)| c)
            .map(|(n, _)| n.clone())
            .collect();
        (measures, events, prep.state_names.clone(), monitors)
    }

    fn dry(problems: Vec<(usize, String)>, prep: &Prepared) -> EnsembleOut {
        let (measure_names, event_names, state_names, monitor_names) = Self::names(prep);
        EnsembleOut {
            measure_names,
            event_names,
            state_names,
            monitor_names,
            outs: Vec::new(),
            problems,
            seconds: 0.0,
            threads: 0,
        }
    }

    fn new(outs: Vec<RunOut>, names: Names, seconds: f64, threads: usize) -> EnsembleOut {
        let (measure_names, event_names, state_names, monitor_names) = names;
        let problems = outs
            .iter()
            .enumerate()
            .filter_map(|(r, o)| o.message.clone().map(|m| (r, m)))
            .collect();
        EnsembleOut {
            measure_names,
            event_names,
            state_names,
            monitor_names,
            outs,
            problems,
            seconds,
            threads,
        }
    }

    fn into_py_dict(self, py: Python<'_>, runs: usize) -> PyResult<PyObject> {
        let d = PyDict::new(py);
        d.set_item("problems", self.problems)?;
        d.set_item("measure_names", &self.measure_names)?;
        d.set_item("event_names", &self.event_names)?;
        d.set_item("state_names", &self.state_names)?;
        d.set_item("monitor_names", &self.monitor_names)?;
        d.set_item("seconds", self.seconds)?;
        d.set_item("threads", self.threads)?;
        if self.outs.is_empty() && runs > 0 {
            return Ok(d.into_any().unbind());
        }
        let o = &self.outs;
        let ns = self.state_names.len();
        let nm = self.measure_names.len();
        let ne = self.event_names.len();
        let nd = self.monitor_names.len();
        let flat = |f: &dyn Fn(&RunOut) -> Vec<f64>| -> Vec<f64> { o.iter().flat_map(f).collect() };
        d.set_item(
            "measures",
            f64_matrix(py, flat(&|r| r.measures.clone()), runs, nm)?,
        )?;
        d.set_item(
            "t_final",
            f64_array(py, o.iter().map(|r| r.t_final).collect()),
        )?;
        d.set_item(
            "final",
            f64_matrix(py, flat(&|r| r.final_state.clone()), runs, ns)?,
        )?;
        d.set_item(
            "event_t",
            f64_matrix(
                py,
                flat(&|r| {
                    r.events
                        .iter()
                        .map(|e| e.as_ref().map_or(f64::NAN, |x| x.0))
                        .collect()
                }),
                runs,
                ne,
            )?,
        )?;
        let ev_state = flat(&|r| {
            r.events
                .iter()
                .flat_map(|e| match e {
                    Some((_, y)) => y.clone(),
                    None => vec![f64::NAN; ns],
                })
                .collect()
        });
        let a = PyArray1::from_vec(py, ev_state);
        d.set_item("event_state", a.reshape([runs, ne, ns])?)?;
        d.set_item(
            "drift",
            f64_matrix(
                py,
                flat(&|r| {
                    if r.drifts.len() == nd {
                        r.drifts.clone()
                    } else {
                        vec![f64::NAN; nd]
                    }
                }),
                runs,
                nd,
            )?,
        )?;
        d.set_item("drifted", o.iter().map(|r| r.drifted).collect::<Vec<_>>())?;
        d.set_item("status", o.iter().map(|r| r.status).collect::<Vec<_>>())?;
        d.set_item("nfev", o.iter().map(|r| r.nfev).collect::<Vec<_>>())?;
        Ok(d.into_any().unbind())
    }
}

/// A rayon pool with `n` threads (a sweep's `threads=`).
fn rayon_pool(n: usize) -> Result<rayon::ThreadPool, Error> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(n.max(1))
        .build()
        .map_err(|e| Error::argument("threads", format!("cannot start {n} threads: {e}")))
}

/// An event for `solve_ivp`: a Python callable or an expression, with SciPy's attributes.
struct IvpEvent {
    function: Rhs,
    terminal: Option<usize>,
    direction: Direction,
}

/// A right-hand side or event function: compiled expressions (native code by the Cranelift
/// JIT, or the interpreter where there is none), or a Python callable.
enum Rhs {
    Compiled(Arc<pdyn_jit::Evaluator>),
    Callable(PyObject),
}

/// Compiled right-hand sides by their expressions, state size, parameter names and JIT mode:
/// a loop calling `solve_ivp` with the same expressions (other values of `args`, `y0`)
/// compiles them once. Bounded: cleared when it holds [`CACHE_SIZE`] programs.
type CacheKey = (Vec<String>, usize, Vec<String>, bool);
static COMPILED: Mutex<Vec<(CacheKey, Arc<pdyn_jit::Evaluator>)>> = Mutex::new(Vec::new());
const CACHE_SIZE: usize = 64;

/// [`compile_exprs`], then native code (`jit`) with the interpreter as fallback; cached.
fn compile_rhs(
    exprs: &[String],
    n: usize,
    params: &[(String, f64)],
    jit: bool,
) -> Result<Arc<pdyn_jit::Evaluator>, String> {
    let key: CacheKey = (
        exprs.to_vec(),
        n,
        params.iter().map(|p| p.0.clone()).collect(),
        jit,
    );
    let mut cache = COMPILED.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, ev)) = cache.iter().find(|(k, _)| *k == key) {
        return Ok(ev.clone());
    }
    let program = compile_exprs(exprs, n, params)?;
    let mode = if jit {
        pdyn_jit::JitMode::Auto
    } else {
        pdyn_jit::JitMode::Off
    };
    let ev = Arc::new(pdyn_jit::Evaluator::new(program, mode));
    if cache.len() >= CACHE_SIZE {
        cache.clear();
    }
    cache.push((key, ev.clone()));
    Ok(ev)
}

/// Compiles expressions in `t`, `y0..y{n-1}` and the names of `params` into one program
/// over the inputs `[t, y0.., params..]`.
fn compile_exprs(exprs: &[String], n: usize, params: &[(String, f64)]) -> Result<Program, String> {
    let mut pool = Pool::new();
    let mut outputs = Vec::new();
    for (i, src) in exprs.iter().enumerate() {
        let id = pool.parse_scalar(src).map_err(|e| {
            let (_, col) = pdyn_expr::error::line_col(src, e.span.start);
            format!("expression {i} (`{src}`), column {col}: {}", e.message)
        })?;
        outputs.push(id);
    }
    let mut inputs = vec![pool.var("t")];
    for k in 0..n {
        inputs.push(pool.var(&format!("y{k}")));
    }
    for (name, _) in params {
        inputs.push(pool.var(name));
    }
    Program::compile(&mut pool, &inputs, &outputs).map_err(|e| {
        format!(
            "{e} (the expressions may use t, y0..y{}, and the names given in args)",
            n.saturating_sub(1)
        )
    })
}

/// Evaluates one compiled program with its own registers.
struct Evaluator<'a> {
    program: &'a pdyn_jit::Evaluator,
    inputs: RefCell<Vec<f64>>,
    ws: RefCell<Vec<f64>>,
}

impl<'a> Evaluator<'a> {
    fn new(program: &'a pdyn_jit::Evaluator, n: usize, params: &[(String, f64)]) -> Self {
        let mut inputs = vec![0.0; 1 + n];
        inputs.extend(params.iter().map(|p| p.1));
        Evaluator {
            program,
            inputs: RefCell::new(inputs),
            ws: RefCell::new(program.workspace()),
        }
    }
    fn eval(&self, t: f64, y: &[f64], out: &mut [f64]) {
        let mut inp = self.inputs.borrow_mut();
        inp[0] = t;
        inp[1..1 + y.len()].copy_from_slice(y);
        self.program.eval(&inp, &mut self.ws.borrow_mut(), out);
    }
}

/// An event function `g(t, y)`.
type EventFn<'a> = dyn Fn(f64, &[f64]) -> f64 + 'a;

/// The options of one `solve_ivp` call.
struct IvpOptions {
    method: Method,
    t_span: (f64, f64),
    y0: Vec<f64>,
    opts: Options,
}

/// Integrates with the given right-hand side and events; Python errors raised inside
/// callbacks are kept in `err` (the solver then sees NaN and stops).
fn integrate(
    py: Option<Python<'_>>,
    rhs: &Rhs,
    events: &[IvpEvent],
    params: &[(String, f64)],
    o: &IvpOptions,
    err: &RefCell<Option<PyErr>>,
) -> Result<Solution, pdyn_ode::OdeError> {
    let n = o.y0.len();
    let call_py = |f: &PyObject, t: f64, y: &[f64]| -> Option<Vec<f64>> {
        let py = py?;
        if err.borrow().is_some() {
            return None;
        }
        let arr = PyArray1::from_slice(py, y);
        let r = f.call1(py, (t, arr)).and_then(|v| {
            let v = v.bind(py);
            // Arrays, lists and scalars (for an event) alike.
            let np = py.import("numpy")?;
            let a = np.call_method1("asarray", (v, "float64"))?;
            let a = a.call_method0("ravel")?;
            a.extract::<Vec<f64>>()
        });
        match r {
            Ok(v) => Some(v),
            Err(e) => {
                *err.borrow_mut() = Some(e);
                None
            }
        }
    };
    let evaluator = match rhs {
        Rhs::Compiled(p) => Some(Evaluator::new(p, n, params)),
        Rhs::Callable(_) => None,
    };
    let f = |t: f64, y: &[f64], dy: &mut [f64]| match (rhs, &evaluator) {
        (Rhs::Compiled(_), Some(ev)) => ev.eval(t, y, dy),
        (Rhs::Callable(func), _) => match call_py(func, t, y) {
            Some(v) if v.len() == dy.len() => dy.copy_from_slice(&v),
            Some(v) => {
                if err.borrow().is_none() {
                    *err.borrow_mut() = Some(PyErr::new::<pyo3::exceptions::PyValueError, _>(
                        format!("fun returned {} values for {} states", v.len(), dy.len()),
                    ));
                }
                dy.fill(f64::NAN);
            }
            None => dy.fill(f64::NAN),
        },
        _ => dy.fill(f64::NAN),
    };
    let system = FnSystem::new(n, f);
    let event_evals: Vec<Option<Evaluator<'_>>> = events
        .iter()
        .map(|e| match &e.function {
            Rhs::Compiled(p) => Some(Evaluator::new(p, n, params)),
            Rhs::Callable(_) => None,
        })
        .collect();
    let gs: Vec<Box<EventFn<'_>>> = events
        .iter()
        .zip(&event_evals)
        .map(|(e, ev)| {
            let g: Box<EventFn<'_>> = match (&e.function, ev) {
                (Rhs::Compiled(_), Some(ev)) => Box::new(move |t, y| {
                    let mut out = [0.0];
                    ev.eval(t, y, &mut out);
                    out[0]
                }),
                (Rhs::Callable(func), _) => Box::new(move |t, y| {
                    call_py(func, t, y)
                        .and_then(|v| v.first().copied())
                        .unwrap_or(f64::NAN)
                }),
                _ => Box::new(|_, _| f64::NAN),
            };
            g
        })
        .collect();
    let evs: Vec<Event<'_>> = events
        .iter()
        .zip(&gs)
        .map(|(e, g)| {
            let mut ev = Event::new(g.as_ref()).direction(e.direction);
            if let Some(k) = e.terminal {
                ev = ev.terminal(k);
            }
            ev
        })
        .collect();
    pdyn_ode::solve_with_events(o.method, &system, o.t_span, &o.y0, &o.opts, &evs)
}

/// `solve_ivp`'s Rust part: returns a dict of plain data (`pdyn.solve_ivp` builds the
/// `OdeResult`). `fun` is a callable `fun(t, y)` or a list of expression strings.
#[pyfunction]
#[pyo3(signature = (fun, t0, tf, y0, method, t_eval, rtol, atol, max_step, first_step, max_steps, events, args, dense=false, jit=true))]
#[allow(clippy::too_many_arguments)]
fn _solve_ivp(
    py: Python<'_>,
    fun: &Bound<'_, PyAny>,
    t0: f64,
    tf: f64,
    y0: PyReadonlyArray1<'_, f64>,
    method: &str,
    t_eval: Option<PyReadonlyArray1<'_, f64>>,
    rtol: Vec<f64>,
    atol: Vec<f64>,
    max_step: Option<f64>,
    first_step: Option<f64>,
    max_steps: Option<usize>,
    events: Vec<(Bound<'_, PyAny>, Option<usize>, i32)>,
    args: Vec<(String, f64)>,
    dense: bool,
    jit: bool,
) -> PyResult<PyObject> {
    let y0 = y0.as_slice()?.to_vec();
    let n = y0.len();
    let Some(m) = Method::from_name(&method_name(method)) else {
        return Err(pdyn_error(
            py,
            "ParameterError",
            format!(
                "unknown method `{method}`: use RK45, DOP853, Radau or one of pdyn's ({})",
                Method::all()
                    .iter()
                    .map(|m| m.name())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ));
    };
    let to_rhs = |obj: &Bound<'_, PyAny>, what: &str, outputs: Option<usize>| -> PyResult<Rhs> {
        if obj.is_callable() {
            return Ok(Rhs::Callable(obj.clone().unbind()));
        }
        let exprs: Vec<String> = if let Ok(s) = obj.extract::<String>() {
            vec![s]
        } else {
            obj.extract().map_err(|_| {
                PyTypeError::new_err(format!(
                    "{what} must be a callable or a list of expression strings"
                ))
            })?
        };
        if let Some(k) = outputs {
            if exprs.len() != k {
                return Err(pdyn_error(
                    py,
                    "ParameterError",
                    format!("{what} has {} expressions for {k} states", exprs.len()),
                ));
            }
        }
        compile_rhs(&exprs, n, &args, jit)
            .map(Rhs::Compiled)
            .map_err(|e| pdyn_error(py, "ParameterError", format!("{what}: {e}")))
    };
    let rhs = to_rhs(fun, "fun", Some(n))?;
    let mut ivp_events = Vec::new();
    for (k, (g, terminal, direction)) in events.iter().enumerate() {
        ivp_events.push(IvpEvent {
            function: to_rhs(g, &format!("events[{k}]"), Some(1))?,
            terminal: *terminal,
            direction: match direction.signum() {
                1 => Direction::Rising,
                -1 => Direction::Falling,
                _ => Direction::Both,
            },
        });
    }
    let tol = |v: Vec<f64>| -> pdyn_ode::Tolerance {
        if v.len() == 1 {
            v[0].into()
        } else {
            v.into()
        }
    };
    let mut opts = Options {
        rtol: tol(rtol),
        atol: tol(atol),
        h0: first_step,
        max_step,
        ..Options::default()
    };
    if let Some(ms) = max_steps {
        opts.max_steps = ms;
    }
    if let Some(te) = t_eval {
        opts.t_eval = Some(te.as_slice()?.to_vec());
    }
    let o = IvpOptions {
        method: m,
        t_span: (t0, tf),
        y0,
        opts,
    };
    let all_compiled = matches!(rhs, Rhs::Compiled(_))
        && ivp_events
            .iter()
            .all(|e| matches!(e.function, Rhs::Compiled(_)));
    let err = RefCell::new(None);
    let result = if all_compiled {
        // No Python in the loop: the GIL is released for the whole integration.
        let rhs_ref = &rhs;
        let evs = &ivp_events;
        let args_ref = &args;
        let o_ref = &o;
        py.allow_threads(move || {
            catch_unwind(AssertUnwindSafe(|| {
                let err = RefCell::new(None);
                integrate(None, rhs_ref, evs, args_ref, o_ref, &err)
            }))
        })
    } else {
        catch_unwind(AssertUnwindSafe(|| {
            integrate(Some(py), &rhs, &ivp_events, &args, &o, &err)
        }))
    };
    if let Some(e) = err.into_inner() {
        return Err(e);
    }
    let result = result.map_err(|_| {
        pdyn_error(
            py,
            "PdynError",
            "internal error in pdyn during solve_ivp (please report it)".into(),
        )
    })?;
    let (sol, message, status) = match result {
        Ok(sol) => {
            let (msg, status) = match sol.status {
                Status::Finished => (
                    "The solver successfully reached the end of the integration interval."
                        .to_string(),
                    0,
                ),
                Status::TerminalEvent(_) => ("A termination event occurred.".to_string(), 1),
            };
            (sol, msg, status)
        }
        Err(e) => match e.failure_point() {
            Some(fp) => ((*fp.partial).clone(), e.to_string(), -1),
            None => return Err(pdyn_error(py, "ParameterError", e.to_string())),
        },
    };
    let d = PyDict::new(py);
    let len = sol.len();
    let hits = PyList::empty(py);
    for h in &sol.events {
        hits.append((h.index, h.t, f64_array(py, h.y.clone())))?;
    }
    d.set_item("events", hits)?;
    d.set_item("stats", stats_dict(py, &sol.stats)?)?;
    d.set_item("message", message)?;
    d.set_item("status", status)?;
    d.set_item("method", sol.method.name())?;
    d.set_item("gil_released", all_compiled)?;
    d.set_item(
        "native",
        matches!(&rhs, Rhs::Compiled(ev) if ev.is_native()),
    )?;
    if dense {
        // f(t, y) at every output point, for the Hermite interpolant of `sol.sol` (extra
        // evaluations, not counted in nfev).
        let mut f_rows = vec![0.0; len * n];
        match &rhs {
            Rhs::Compiled(p) => {
                let ev = Evaluator::new(p, n, &args);
                for k in 0..len {
                    ev.eval(sol.t[k], sol.y_at(k), &mut f_rows[k * n..(k + 1) * n]);
                }
            }
            Rhs::Callable(func) => {
                let np = py.import("numpy")?;
                for k in 0..len {
                    let arr = PyArray1::from_slice(py, sol.y_at(k));
                    let v = func.call1(py, (sol.t[k], arr))?;
                    let v = np.call_method1("asarray", (v, "float64"))?;
                    let v: Vec<f64> = v.call_method0("ravel")?.extract()?;
                    if v.len() != n {
                        return Err(PyErr::new::<pyo3::exceptions::PyValueError, _>(format!(
                            "fun returned {} values for {n} states",
                            v.len()
                        )));
                    }
                    f_rows[k * n..(k + 1) * n].copy_from_slice(&v);
                }
            }
        }
        d.set_item("f_rows", f64_matrix(py, f_rows, len, n)?)?;
    }
    // The solution's own buffers become the arrays: no copy.
    d.set_item("t", f64_array(py, sol.t))?;
    d.set_item("y_rows", f64_matrix(py, sol.y, len, n)?)?;
    Ok(d.into_any().unbind())
}

/// An error of `pdyn.kin` / `pdyn.dsolve`: `ModelError` located in the argument it came from
/// (`file` is the argument: `<position>`, `--at`, `<equation 1>`...; `line`/`column` within
/// its text when the error is in an expression), `PdynError` for a bug.
fn input_error(py: Python<'_>, e: &Error) -> PyErr {
    let loc = e.location();
    let (file, line, column) = loc.as_ref().map_or((String::new(), None, None), |l| {
        (l.file.clone(), l.line, l.column)
    });
    let message = match e {
        Error::Expr { error, .. } => error.message.clone(),
        other => other.to_string(),
    };
    match e {
        Error::Internal { .. } => to_py(py, e),
        _ => py_error(py, "ModelError", |c| {
            c.call1((e.to_string(), file, line, column, message))
        }),
    }
}

/// `(text, latex)` of an expression.
fn tl(pool: &Pool, id: Id) -> (String, String) {
    (pool.to_text(id), pool.to_latex(id))
}

/// A kinematic quantity: `(text, latex)` for a scalar, a list of three for a vector.
fn quantity_py(
    py: Python<'_>,
    pool: &Pool,
    q: pdyn_mech::kinematics::Quantity,
) -> PyResult<PyObject> {
    use pdyn_mech::kinematics::Quantity;
    Ok(match q {
        Quantity::Scalar(s) => tl(pool, s).into_pyobject(py)?.into_any().unbind(),
        Quantity::Vector(v) => PyList::new(py, v.iter().map(|&c| tl(pool, c)))?
            .into_any()
            .unbind(),
    })
}

/// `pdyn kin`'s computation: returns a dict of plain data (`pdyn.kin` builds the result).
#[pyfunction]
#[pyo3(signature = (position=None, polar=None, path=None, param="s".to_string(), speed="V".to_string(), at=Vec::new(), set=Vec::new(), max=None, over=None, signed=Vec::new()))]
#[allow(clippy::too_many_arguments)]
fn _kin(
    py: Python<'_>,
    position: Option<String>,
    polar: Option<String>,
    path: Option<String>,
    param: String,
    speed: String,
    at: Vec<String>,
    set: Vec<String>,
    max: Option<String>,
    over: Option<String>,
    signed: Vec<String>,
) -> PyResult<PyObject> {
    let input = pdyn::kin::KinInput {
        position,
        polar,
        path,
        param,
        speed,
        at,
        set,
        max,
        over,
        signed,
    };
    let r = py
        .allow_threads(|| catch_unwind(AssertUnwindSafe(|| pdyn::kin::kin(&input))))
        .map_err(|_| {
            pdyn_error(
                py,
                "PdynError",
                "internal error in pdyn during kin (please report it)".into(),
            )
        })?
        .map_err(|e| input_error(py, &e))?;
    guarded(py, || {
        let pool = &r.pool;
        let d = PyDict::new(py);
        d.set_item("variable", &r.variable)?;
        d.set_item("straight", r.straight)?;
        let qs = PyList::empty(py);
        for (name, q) in &r.quantities {
            qs.append((*name, quantity_py(py, pool, *q)?))?;
        }
        d.set_item("quantities", qs)?;
        let instants = PyList::empty(py);
        for i in &r.instants {
            let vals = PyList::empty(py);
            for (name, q, nums) in &i.values {
                vals.append((*name, quantity_py(py, pool, *q)?, nums.clone()))?;
            }
            instants.append((i.spec.clone(), i.resolved.clone(), vals))?;
        }
        d.set_item("instants", instants)?;
        match &r.max {
            None => d.set_item("max", py.None())?,
            Some(m) => {
                let md = PyDict::new(py);
                md.set_item("expr", &m.expr)?;
                md.set_item("over", &m.over)?;
                md.set_item("variable", &m.variable)?;
                match &m.found {
                    pdyn_mech::kinematics::Maximum::Numeric(e) => {
                        md.set_item("value", e.value)?;
                        md.set_item("at", e.at)?;
                        md.set_item("exact", false)?;
                        md.set_item("parameters", PyList::empty(py))?;
                    }
                    pdyn_mech::kinematics::Maximum::Exact {
                        at,
                        value,
                        parameters,
                    } => {
                        md.set_item("value", tl(pool, *value))?;
                        md.set_item("at", tl(pool, *at))?;
                        md.set_item("exact", true)?;
                        md.set_item("parameters", parameters.clone())?;
                    }
                }
                d.set_item("max", md)?;
            }
        }
        d.set_item("assumed_positive", r.assumed_positive.clone())?;
        Ok(d.into_any().unbind())
    })
}

/// `pdyn dsolve`'s computation: returns a dict of plain data (`pdyn.dsolve` builds the
/// result).
#[pyfunction]
#[pyo3(signature = (equations=Vec::new(), ic=None, rule=None, set=Vec::new(), at=Vec::new(), when=None, signed=Vec::new()))]
#[allow(clippy::too_many_arguments)]
fn _dsolve(
    py: Python<'_>,
    equations: Vec<String>,
    ic: Option<String>,
    rule: Option<String>,
    set: Vec<String>,
    at: Vec<String>,
    when: Option<String>,
    signed: Vec<String>,
) -> PyResult<PyObject> {
    use pdyn::dsolve::Solved;
    use pdyn_mech::dsolve::{Method, Relation};
    let input = pdyn::dsolve::DsolveInput {
        equations,
        ic,
        rule,
        set,
        at,
        when,
        signed,
    };
    let r = py
        .allow_threads(|| catch_unwind(AssertUnwindSafe(|| pdyn::dsolve::dsolve(&input))))
        .map_err(|_| {
            pdyn_error(
                py,
                "PdynError",
                "internal error in pdyn during dsolve (please report it)".into(),
            )
        })?
        .map_err(|e| input_error(py, &e))?;
    guarded(py, || {
        let pool = &r.pool;
        let d = PyDict::new(py);
        match &r.solved {
            Solved::Equations(s) => {
                let cf = &s.closed_form;
                d.set_item("kind", "equations")?;
                let coords: Vec<String> = cf
                    .coords
                    .iter()
                    .map(|&c| pool.name(c).to_string())
                    .collect();
                d.set_item("coords", coords.clone())?;
                d.set_item(
                    "method",
                    match cf.method {
                        Method::Exact => "exact",
                        Method::Numeric => "numeric",
                    },
                )?;
                d.set_item("residual", cf.residual)?;
                let cases = PyList::empty(py);
                for (ci, c) in cf.cases.iter().enumerate() {
                    let cd = PyDict::new(py);
                    let cond = c.condition.map(|k| {
                        (
                            tl(pool, k.expr),
                            match k.relation {
                                Relation::Positive => ">",
                                Relation::Zero => "=",
                                Relation::Negative => "<",
                            },
                        )
                    });
                    cd.set_item("condition", cond)?;
                    cd.set_item(
                        "solution",
                        coords
                            .iter()
                            .zip(&c.solution)
                            .map(|(n, &e)| (n.clone(), tl(pool, e)))
                            .collect::<Vec<_>>(),
                    )?;
                    cd.set_item("roots", c.roots.clone())?;
                    cd.set_item(
                        "constants",
                        c.constants
                            .iter()
                            .map(|&k| pool.to_text(k))
                            .collect::<Vec<_>>(),
                    )?;
                    match s.table.get(ci) {
                        Some(rows) => {
                            let w = 2 * coords.len();
                            let flat: Vec<f64> = rows.iter().flatten().copied().collect();
                            cd.set_item("values", f64_matrix(py, flat, rows.len(), w)?)?;
                        }
                        None => cd.set_item("values", py.None())?,
                    }
                    cases.append(cd)?;
                }
                d.set_item("cases", cases)?;
                d.set_item("times", f64_array(py, s.times.clone()))?;
                match &s.when {
                    None => d.set_item("when", py.None())?,
                    Some(w) => {
                        let wd = PyDict::new(py);
                        wd.set_item("condition", &w.condition)?;
                        wd.set_item("t", tl(pool, w.found.t))?;
                        wd.set_item("exact", w.found.exact)?;
                        wd.set_item("value", w.found.value)?;
                        wd.set_item(
                            "state",
                            w.found
                                .state
                                .iter()
                                .map(|st| (st.name.clone(), tl(pool, st.exact), st.value))
                                .collect::<Vec<_>>(),
                        )?;
                        d.set_item("when", wd)?;
                    }
                }
                d.set_item("assumed_positive", s.assumed_positive.clone())?;
            }
            Solved::Rule(s) => {
                d.set_item("kind", "rule")?;
                d.set_item("rule", &s.rule)?;
                d.set_item("variable", s.variable)?;
                d.set_item("points", f64_array(py, s.points.clone()))?;
                let qs = PyList::empty(py);
                for (q, vals) in s.solution.quantities.iter().zip(&s.values) {
                    let qd = PyDict::new(py);
                    qd.set_item("name", &q.name)?;
                    qd.set_item("closed", q.closed.map(|c| tl(pool, c)))?;
                    qd.set_item("describe", q.describe(pool))?;
                    qd.set_item(
                        "values",
                        f64_array(
                            py,
                            vals.iter()
                                .map(|v| v.as_ref().map_or(f64::NAN, |e| e.value))
                                .collect(),
                        ),
                    )?;
                    qd.set_item(
                        "errors",
                        f64_array(
                            py,
                            vals.iter()
                                .map(|v| v.as_ref().map_or(f64::NAN, |e| e.error))
                                .collect(),
                        ),
                    )?;
                    qd.set_item(
                        "messages",
                        vals.iter()
                            .map(|v| v.as_ref().err().cloned())
                            .collect::<Vec<_>>(),
                    )?;
                    qs.append(qd)?;
                }
                d.set_item("quantities", qs)?;
                d.set_item("assumed_positive", s.assumed_positive.clone())?;
            }
        }
        Ok(d.into_any().unbind())
    })
}

/// Names and descriptions of the integration methods.
#[pyfunction]
fn methods() -> Vec<(String, String)> {
    Method::all()
        .iter()
        .map(|m| {
            (
                m.name().to_string(),
                m.doc().split_whitespace().collect::<Vec<_>>().join(" "),
            )
        })
        .collect()
}

/// The Rust half of `pdyn`.
#[pymodule]
fn _pdyn(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyModel>()?;
    m.add_function(wrap_pyfunction!(_solve_ivp, m)?)?;
    m.add_function(wrap_pyfunction!(methods, m)?)?;
    m.add_function(wrap_pyfunction!(_kin, m)?)?;
    m.add_function(wrap_pyfunction!(_dsolve, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
