//! `pdyn.kin_data`, `pdyn.integrate_accel`, `pdyn.fuse`, `pdyn.read_csv`: measured motion
//! (the library's `pdyn::data`, the same computations as `pdyn kin --data` and `pdyn fuse`),
//! run with the GIL released. Returned as plain data: a dict of float64 arrays (the table's
//! columns) and the summary as JSON text; `pdyn._data` builds the result objects.

use crate::convert::f64_array;
use crate::errors::{guarded, py_error, to_py};
use numpy::PyReadonlyArray1;
use pdyn::data::{self, lib, DataKind, Table};
use pdyn::Error;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A data problem as `pdyn.ModelError` (file, line, column: located like a model's), any
/// other error as usual.
pub(crate) fn data_py(py: Python<'_>, e: &Error) -> PyErr {
    match e {
        Error::Data { error } => py_error(py, "ModelError", |c| {
            c.call1((
                e.to_string(),
                error.file.clone(),
                error.line,
                error.column,
                error.message.clone(),
            ))
        }),
        _ => to_py(py, e),
    }
}

/// A float64 NumPy array.
type Array<'py> = Bound<'py, numpy::PyArray1<f64>>;

fn vecs(arrays: &[PyReadonlyArray1<'_, f64>]) -> Vec<Vec<f64>> {
    arrays.iter().map(|a| a.as_array().to_vec()).collect()
}

fn table_dict<'py>(py: Python<'py>, t: Table) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (n, c) in t.names.into_iter().zip(t.columns) {
        d.set_item(n, f64_array(py, c))?;
    }
    Ok(d)
}

fn series(
    t: Vec<f64>,
    names: Vec<String>,
    values: Vec<Vec<f64>>,
    min: usize,
    what: &str,
) -> Result<lib::csv::Series, Error> {
    lib::csv::Series::from_arrays(t, names, values, min, what).map_err(data::data_error)
}

/// Reads columns of a CSV file: `(names, t, [values...])` (names without the time's).
#[pyfunction]
#[pyo3(signature = (path, columns=Vec::new(), kind="position".to_string()))]
pub(crate) fn _read_csv<'py>(
    py: Python<'py>,
    path: std::path::PathBuf,
    columns: Vec<String>,
    kind: String,
) -> PyResult<(Vec<String>, Array<'py>, Vec<Array<'py>>)> {
    guarded(py, || {
        let kind = if kind == "accel" {
            DataKind::Acceleration
        } else {
            DataKind::Position
        };
        let s = py
            .allow_threads(|| data::read_series(&path, &columns, kind, 1, "reading"))
            .map_err(|e| data_py(py, &e))?;
        let values = s.values.into_iter().map(|v| f64_array(py, v)).collect();
        Ok((s.names, f64_array(py, s.t), values))
    })
}

/// Kinematics from sampled positions: `(columns, summary_json)`.
#[pyfunction]
#[pyo3(signature = (t, positions, names, lam=None))]
pub(crate) fn _kin_data<'py>(
    py: Python<'py>,
    t: PyReadonlyArray1<'py, f64>,
    positions: Vec<PyReadonlyArray1<'py, f64>>,
    names: Vec<String>,
    lam: Option<f64>,
) -> PyResult<(Bound<'py, PyDict>, String)> {
    let (t, values) = (t.as_array().to_vec(), vecs(&positions));
    guarded(py, || {
        let smoothing = match lam {
            None => lib::spline::Smoothing::Gcv,
            Some(l) => lib::spline::Smoothing::Lambda(l),
        };
        let (table, summary) = py
            .allow_threads(|| {
                let s = series(t, names, values, 5, "kinematics from samples")?;
                let k = lib::kinematics::kinematics(&s, smoothing).map_err(data::data_error)?;
                let summary = data::kin_summary(&k);
                Ok::<_, Error>((data::kin_table(k, &[])?, summary))
            })
            .map_err(|e| data_py(py, &e))?;
        Ok((table_dict(py, table)?, summary.to_string()))
    })
}

/// Sampled acceleration integrated: `(columns, summary_json)`.
#[pyfunction]
#[pyo3(signature = (t, accelerations, names, v0, x0, rule, bias, sigma_a=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn _integrate_accel<'py>(
    py: Python<'py>,
    t: PyReadonlyArray1<'py, f64>,
    accelerations: Vec<PyReadonlyArray1<'py, f64>>,
    names: Vec<String>,
    v0: Vec<f64>,
    x0: Vec<f64>,
    rule: String,
    bias: String,
    sigma_a: Option<f64>,
) -> PyResult<(Bound<'py, PyDict>, String)> {
    let (t, values) = (t.as_array().to_vec(), vecs(&accelerations));
    guarded(py, || {
        let (table, summary) = py
            .allow_threads(|| {
                let rule = lib::integrate::Rule::parse(&rule).ok_or_else(|| {
                    Error::argument(
                        "rule",
                        format!("rule={rule:?} is not 'simpson' or 'trapezoid'"),
                    )
                })?;
                let options = lib::integrate::AccelOptions {
                    rule,
                    bias: data::parse_bias(&bias)?,
                    sigma_a,
                    ..Default::default()
                };
                let s = series(t, names, values, 2, "integration")?;
                let r = data::integrate_accel(&s, &options, &v0, &x0)?;
                Ok::<_, Error>((data::accel_table(&r), data::accel_summary(&r, &options)))
            })
            .map_err(|e| data_py(py, &e))?;
        Ok((table_dict(py, table)?, summary.to_string()))
    })
}

/// Kalman filter + RTS smoother: `(columns, summary_json, covariances or None)`; the
/// covariances an `(axes, n, 3, 3)` array as a flat vector with its shape.
#[pyfunction]
#[pyo3(signature = (ta, accelerations, tf, fixes, names, sigma_a=None, sigma_p=None, sigma_b=0.0, bias0=1.0, v0_sd=1e3, p0_sd=1e4, covariance=false))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn _fuse<'py>(
    py: Python<'py>,
    ta: PyReadonlyArray1<'py, f64>,
    accelerations: Vec<PyReadonlyArray1<'py, f64>>,
    tf: PyReadonlyArray1<'py, f64>,
    fixes: Vec<PyReadonlyArray1<'py, f64>>,
    names: Vec<String>,
    sigma_a: Option<f64>,
    sigma_p: Option<f64>,
    sigma_b: f64,
    bias0: f64,
    v0_sd: f64,
    p0_sd: f64,
    covariance: bool,
) -> PyResult<(Bound<'py, PyDict>, String, Option<Array<'py>>)> {
    let (ta, a) = (ta.as_array().to_vec(), vecs(&accelerations));
    let (tf, z) = (tf.as_array().to_vec(), vecs(&fixes));
    guarded(py, || {
        let noise = lib::fusion::Noise {
            sigma_a,
            sigma_p,
            sigma_b,
            bias0,
            v0: v0_sd,
            p0: p0_sd,
        };
        for (name, v) in [("bias0", bias0), ("v0_sd", v0_sd), ("p0_sd", p0_sd)] {
            if !(v > 0.0 && v.is_finite()) {
                return Err(to_py(
                    py,
                    &Error::argument(name, format!("{name}={v} must be a positive number")),
                ));
            }
        }
        let (table, summary, cov) = py
            .allow_threads(|| {
                let n_axes = a.len();
                let acc_names: Vec<String> = (0..n_axes).map(|i| format!("a{i}")).collect();
                let sa = series(ta, acc_names, a, 2, "fusion")?;
                let sf = series(tf, names.clone(), z, 1, "fusion")?;
                let f = lib::fusion::fuse(&sa.t, &sa.values, &sf.t, &sf.values, &noise, covariance)
                    .map_err(data::data_error)?;
                let cov: Option<Vec<f64>> = covariance.then(|| {
                    f.axes
                        .iter()
                        .flat_map(|ax| ax.cov.iter().flatten().copied())
                        .collect()
                });
                Ok::<_, Error>((
                    data::fuse_table(&f, &names),
                    data::fuse_summary(&f, &names),
                    cov,
                ))
            })
            .map_err(|e| data_py(py, &e))?;
        Ok((
            table_dict(py, table)?,
            summary.to_string(),
            cov.map(|c| f64_array(py, c)),
        ))
    })
}

/// Interpolation of samples at the times `at` (`kind`: linear, cubic, pchip).
#[pyfunction]
#[pyo3(signature = (t, y, at, kind="linear".to_string()))]
pub(crate) fn _interp<'py>(
    py: Python<'py>,
    t: PyReadonlyArray1<'py, f64>,
    y: PyReadonlyArray1<'py, f64>,
    at: PyReadonlyArray1<'py, f64>,
    kind: String,
) -> PyResult<Array<'py>> {
    let (t, y, at) = (
        t.as_array().to_vec(),
        y.as_array().to_vec(),
        at.as_array().to_vec(),
    );
    guarded(py, || {
        let values = py
            .allow_threads(|| {
                let k = lib::interp::Kind::parse(&kind).ok_or_else(|| {
                    Error::argument(
                        "kind",
                        format!("kind={kind:?} is not 'linear', 'cubic' or 'pchip'"),
                    )
                })?;
                let s = series(t, vec!["y".into()], vec![y], 2, "interpolation")?;
                let f = lib::interp::Interpolant::new(k, &s.t, &s.values[0], "y")
                    .map_err(data::data_error)?;
                at.iter()
                    .map(|&x| f.eval(x).map_err(data::data_error))
                    .collect::<Result<Vec<f64>, Error>>()
            })
            .map_err(|e| data_py(py, &e))?;
        Ok(f64_array(py, values))
    })
}
