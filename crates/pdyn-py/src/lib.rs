//! `pdyn._pdyn`: the Rust half of the Python package `pdyn` (the pure-Python half, in
//! `python/pdyn/`, builds result objects, emits warnings and holds the docstrings users read).
//!
//! Every function here returns plain Python data (dicts, lists, float64 NumPy arrays) and
//! raises the exceptions defined in `pdyn._errors`. Errors are typed down to this boundary
//! ([`pdyn::Error`], [`pdyn_mech::ModelError`], ...) and rendered only in [`errors`], and every
//! entry point runs through [`errors::guarded`], so that a panic raises `pdyn.PdynError`.
//! Integrations run with the GIL released, except when they must call back into Python.
//!
//! One module per concern:
//!
//! | module | what |
//! |---|---|
//! | [`errors`] | exceptions from errors and panics |
//! | [`convert`] | arrays, statistics, dicts as TOML, `(text, latex)` |
//! | [`model`] | `pdyn.Model` and its one `#[pymethods]` block |
//! | [`run`] | `Model.run` |
//! | [`particles`] | `[nbody]` and `[md]` model files: load, run |
//! | [`derive`] | `Model.derive`, `Model.forces` |
//! | [`sweep`] | `Model.sweep` |
//! | [`ensemble`] | `Model.ensemble` (the engine is [`pdyn::sim::ensemble`]) |
//! | [`solve_ivp`] | `pdyn.solve_ivp` and its cache of compiled right-hand sides |
//! | [`symbolic`] | `pdyn.kin`, `pdyn.dsolve` |
//! | [`data`] | `pdyn.kin_data`, `pdyn.integrate_accel`, `pdyn.fuse`, `pdyn.read_csv`, `pdyn.interp` |
#![warn(missing_docs)]

mod convert;
mod data;
mod derive;
mod ensemble;
mod errors;
mod fit;
mod interrupt;
mod model;
mod optimize;
mod particles;
mod run;
mod solve_ivp;
mod statics;
mod sweep;
mod symbolic;

use pdyn_ode::Method;
use pyo3::prelude::*;

/// Names and descriptions of the integration methods.
#[pyfunction]
fn methods(py: Python<'_>) -> PyResult<Vec<(String, String)>> {
    errors::guarded(py, || {
        Ok(Method::all()
            .iter()
            .map(|m| {
                (
                    m.name().to_string(),
                    m.doc().split_whitespace().collect::<Vec<_>>().join(" "),
                )
            })
            .collect())
    })
}

/// The Rust half of `pdyn`.
#[pymodule]
fn _pdyn(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // The library's messages name options as Python's keywords (`t_end`, `rtol=1e-9`), never
    // as the command line's flags.
    pdyn::options::name_options_as(pdyn::options::Naming::Keywords);
    // NumPy's C API is imported now, not by the first array a call returns: a Ctrl-C pending
    // at that moment would make the import fail inside Rust (a PanicException, not a
    // KeyboardInterrupt).
    let _ = numpy::PyArray1::<f64>::zeros(m.py(), 0, false);
    m.add_class::<model::PyModel>()?;
    m.add_class::<particles::PyParticleModel>()?;
    m.add_function(wrap_pyfunction!(particles::load_model, m)?)?;
    m.add_function(wrap_pyfunction!(solve_ivp::_solve_ivp, m)?)?;
    m.add_function(wrap_pyfunction!(methods, m)?)?;
    m.add_function(wrap_pyfunction!(optimize::_optimize, m)?)?;
    m.add_function(wrap_pyfunction!(symbolic::_kin, m)?)?;
    m.add_function(wrap_pyfunction!(symbolic::_dsolve, m)?)?;
    m.add_function(wrap_pyfunction!(data::_read_csv, m)?)?;
    m.add_function(wrap_pyfunction!(data::_kin_data, m)?)?;
    m.add_function(wrap_pyfunction!(data::_integrate_accel, m)?)?;
    m.add_function(wrap_pyfunction!(data::_fuse, m)?)?;
    m.add_function(wrap_pyfunction!(data::_interp, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
