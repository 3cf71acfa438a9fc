//! `Model.modes`: the library's `pdyn::sim::net::statics::modes_about` (what `pdyn modes` computes)
//! with its arrays as NumPy.

use crate::convert::{f64_array, f64_matrix};
use crate::errors::to_py;
use crate::model::PyModel;
use pdyn::sim::net::statics::modes_about;
use pdyn::Error;
use pdyn_mech::statics::{About, ModesRequest, Solver};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The modes as a dict of arrays (`pdyn._modes.Modes` wraps it).
pub(crate) fn modes(
    py: Python<'_>,
    model: &PyModel,
    count: Option<usize>,
    about: &str,
    solver: &str,
    params: Option<Vec<(String, f64)>>,
) -> PyResult<PyObject> {
    let about = match about {
        "equilibrium" => About::Equilibrium,
        "initial" => About::Initial,
        other => {
            return Err(PyValueError::new_err(format!(
                "about must be 'equilibrium' or 'initial', not {other:?}"
            )))
        }
    };
    let solver = match solver {
        "auto" => Solver::Auto,
        "dense" => Solver::Dense,
        "sparse" => Solver::Sparse,
        other => {
            return Err(PyValueError::new_err(format!(
                "solver must be 'auto', 'dense' or 'sparse', not {other:?}"
            )))
        }
    };
    if count == Some(0) {
        return Err(PyValueError::new_err("count must be at least 1"));
    }
    let request = ModesRequest {
        about,
        solver,
        count,
    };
    let report = py
        .allow_threads(|| -> Result<_, Error> {
            let mut m = model.with_params(params)?;
            let origin = m.origin.clone();
            modes_about(&mut m, &request).map_err(|error| Error::Statics { origin, error })
        })
        .map_err(|e| to_py(py, &e))?;
    let n = report.names.len();
    let modes = &report.modes.modes;
    let k = modes.len();
    let d = PyDict::new(py);
    let col =
        |f: &dyn Fn(&pdyn_mech::modes::Mode) -> f64| modes.iter().map(f).collect::<Vec<f64>>();
    d.set_item("omega_squared", f64_array(py, col(&|m| m.omega_squared)))?;
    d.set_item("omega", f64_array(py, col(&|m| m.omega)))?;
    d.set_item("modal_mass", f64_array(py, col(&|m| m.modal_mass)))?;
    d.set_item(
        "modal_stiffness",
        f64_array(py, col(&|m| m.modal_stiffness)),
    )?;
    // Per mode and axis (k × 3): how a ground acceleration along x, y, z excites the mode.
    let per_axis = |f: &dyn Fn(&pdyn_mech::modes::Mode) -> [f64; 3]| {
        modes.iter().flat_map(f).collect::<Vec<f64>>()
    };
    d.set_item(
        "participation",
        f64_matrix(py, per_axis(&|m| m.participation), k, 3)?,
    )?;
    d.set_item(
        "effective_mass",
        f64_matrix(py, per_axis(&|m| m.effective_mass), k, 3)?,
    )?;
    d.set_item(
        "total_mass",
        f64_array(py, report.modes.total_mass.to_vec()),
    )?;
    // Shapes as columns: shapes[:, j] is mode j.
    let mut shapes = vec![0.0; n * k];
    for (j, m) in modes.iter().enumerate() {
        for (i, &x) in m.shape.iter().enumerate() {
            shapes[i * k + j] = x;
        }
    }
    d.set_item("shapes", f64_matrix(py, shapes, n, k)?)?;
    d.set_item("coordinates", report.names.clone())?;
    d.set_item("q", f64_array(py, report.q.clone()))?;
    d.set_item("residual", report.residual)?;
    d.set_item("solver", if report.sparse { "sparse" } else { "dense" })?;
    d.set_item("about", report.about.describe())?;
    d.set_item("stiffness_asymmetry", report.modes.stiffness_asymmetry)?;
    match &report.damped {
        Some(dm) => {
            let dd = PyDict::new(py);
            let c = |f: &dyn Fn(&pdyn_mech::damped::DampedMode) -> f64| {
                dm.iter().map(f).collect::<Vec<f64>>()
            };
            dd.set_item("natural_frequency", f64_array(py, c(&|x| x.omega_n)))?;
            dd.set_item("damping_ratio", f64_array(py, c(&|x| x.damping_ratio)))?;
            dd.set_item("damped_frequency", f64_array(py, c(&|x| x.im)))?;
            dd.set_item("real", f64_array(py, c(&|x| x.re)))?;
            dd.set_item("path", report.damped_path.map(|p| p.name()))?;
            d.set_item("damped", dd)?;
        }
        None => d.set_item("damped", py.None())?,
    }
    d.set_item("damped_path", report.damped_path.map(|p| p.name()))?;
    Ok(d.into_any().unbind())
}
