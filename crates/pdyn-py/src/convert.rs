//! Conversions between Python data and pdyn's: NumPy arrays from flat vectors, dicts of solver
//! statistics, a dict as model TOML, expressions as `(text, latex)`, SciPy's method names.
//!
//! Shared by every concern of the extension, so that an array, a statistic or an expression
//! looks the same whichever function returned it.

use numpy::{PyArray1, PyArrayMethods};
use pdyn_expr::{Id, Pool};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// SciPy's method names (`RK45`, `DOP853`, `Radau`) and pdyn's own (`tsit5`, `vern9`, ...).
pub(crate) fn method_name(name: &str) -> String {
    match name.to_ascii_lowercase().as_str() {
        "rk45" => "dopri5".into(),
        "radau" => "radau5".into(),
        other => other.into(),
    }
}

/// A float64 array that takes over `v`'s buffer (no copy).
pub(crate) fn f64_array<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_vec(py, v)
}

/// A `(rows, cols)` float64 array from a flat row-major vector.
pub(crate) fn f64_matrix(
    py: Python<'_>,
    v: Vec<f64>,
    rows: usize,
    cols: usize,
) -> PyResult<PyObject> {
    let a = PyArray1::from_vec(py, v);
    Ok(a.reshape([rows, cols])?.into_any().unbind())
}

/// The solver's statistics as a dict (`OdeResult.nfev` and the others are read from it).
pub(crate) fn stats_dict<'py>(
    py: Python<'py>,
    s: &pdyn_ode::Stats,
) -> PyResult<Bound<'py, PyDict>> {
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
pub(crate) fn dict_to_toml(obj: &Bound<'_, PyAny>) -> PyResult<String> {
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

/// `(text, latex)` of an expression.
pub(crate) fn tl(pool: &Pool, id: Id) -> (String, String) {
    (pool.to_text(id), pool.to_latex(id))
}

/// A kinematic quantity: `(text, latex)` for a scalar, a list of three for a vector.
pub(crate) fn quantity_py(
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
