//! `Model.ensemble`: the arguments checked and the model compiled (once per set of measures,
//! cached on the `Model`), then [`pdyn::sim::ensemble::run`] with the GIL released, and its
//! typed result turned into NumPy arrays, one row per run.

use crate::convert::{f64_array, f64_matrix};
use crate::errors::{pdyn_error, to_py};
use crate::model::{Overrides, PyModel};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pdyn::sim::ensemble::{self, Ensemble, Member, Rows};
use pdyn::Error;
use pdyn_mech::model::spec::Stat;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The arguments of `Model.ensemble` other than the run settings.
pub(crate) struct EnsembleArgs<'a, 'py> {
    /// Names of the parameters that `params` sets, one per column.
    pub(crate) param_names: Vec<String>,
    /// One row per run.
    pub(crate) params: &'a PyReadonlyArray2<'py, f64>,
    /// Names of the state components that `initial` sets, one per column.
    pub(crate) initial_names: Vec<String>,
    /// One row per run, when given.
    pub(crate) initial: Option<&'a PyReadonlyArray2<'py, f64>>,
    /// `(name, expression, statistic)` of each measure; the model's `[sweep.measures]` when
    /// `None`.
    pub(crate) measures: Option<Vec<(String, String, String)>>,
    /// Threads of a pool of its own; rayon's global pool when `None`.
    pub(crate) threads: Option<usize>,
    /// Only check the rows.
    pub(crate) dry_run: bool,
    /// Native code for the right-hand side and the observers.
    pub(crate) jit: bool,
}

/// The body of `Model.ensemble`.
pub(crate) fn ensemble(
    py: Python<'_>,
    model: &PyModel,
    a: EnsembleArgs<'_, '_>,
    o: Overrides,
) -> PyResult<PyObject> {
    let EnsembleArgs {
        param_names,
        params,
        initial_names,
        initial,
        measures,
        threads,
        dry_run,
        jit,
    } = a;
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
    let ivals: Vec<f64> = match initial {
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
    let cached = model
        .prepared
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .as_ref()
        .filter(|c| c.0 == key)
        .map(|c| (c.1.clone(), c.2.clone()));
    let base = match (&cached, &measures, model.model.parameters.first()) {
        (Some(_), _, _) | (None, None, _) => None,
        (None, Some(_), Some(p)) => {
            Some(model.with_measures(py, measures.as_deref(), &p.name, &[p.value])?)
        }
        (None, Some(_), None) => {
            return Err(pdyn_error(
                py,
                "ParameterError",
                "measures need a model with at least one parameter".into(),
            ))
        }
    };
    let rows = Rows {
        runs,
        param_names: &param_names,
        params: &pvals,
        initial_names: &initial_names,
        initial: &ivals,
    };
    let finished = crate::interrupt::interruptible(py, |stop| -> Result<Ensemble, Error> {
        let mut set = PyModel::settings(&model.model, o)?;
        set.interrupt = Some(stop);
        set.validate().map_err(|error| Error::Sim {
            origin: model.model.origin.clone(),
            context: "",
            error,
        })?;
        let (prep, stats) = match cached {
            Some(c) => c,
            None => {
                let mut m = match &base {
                    Some(b) => b.model.clone(),
                    None => model.model.clone(),
                };
                let mut p = PyModel::prepare(&mut m, jit)?;
                if jit {
                    p.make_observers_native();
                }
                let stats: Vec<Stat> = m
                    .run
                    .sweep
                    .as_ref()
                    .map(|s| s.measures.iter().map(|m| m.stat).collect())
                    .unwrap_or_default();
                *model.prepared.lock().unwrap_or_else(|e| e.into_inner()) =
                    Some((key, p.clone(), stats.clone()));
                (p, stats)
            }
        };
        ensemble::run(prep, &set, &stats, &rows, threads, dry_run)
    })?;
    let out = finished.value.map_err(|e| to_py(py, &e))?;
    let d = ensemble_dict(py, out, runs)?;
    d.bind(py).set_item("interrupted", finished.interrupted)?;
    Ok(d)
}

/// An ensemble's results as a dict of arrays with one row per run (only the names and the
/// problems after a dry run).
fn ensemble_dict(py: Python<'_>, e: Ensemble, runs: usize) -> PyResult<PyObject> {
    let d = PyDict::new(py);
    d.set_item("problems", e.problems)?;
    d.set_item("measure_names", &e.names.measures)?;
    d.set_item("event_names", &e.names.events)?;
    d.set_item("state_names", &e.names.states)?;
    d.set_item("monitor_names", &e.names.monitors)?;
    d.set_item("seconds", e.seconds)?;
    d.set_item("threads", e.threads)?;
    if e.members.is_empty() && runs > 0 {
        return Ok(d.into_any().unbind());
    }
    let o = &e.members;
    let ns = e.names.states.len();
    let nm = e.names.measures.len();
    let ne = e.names.events.len();
    let nd = e.names.monitors.len();
    let flat = |f: &dyn Fn(&Member) -> Vec<f64>| -> Vec<f64> { o.iter().flat_map(f).collect() };
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
