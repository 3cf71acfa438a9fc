//! The one place where Rust errors and panics become Python exceptions.
//!
//! Errors stay typed ([`pdyn::Error`], [`pdyn_mech::ModelError`], ...) down to the Python
//! boundary and are rendered here into the classes of `pdyn._errors`. Every entry point of
//! the extension (each `#[pyfunction]` and each method of `#[pymethods]`) runs its body
//! through [`guarded`], so that a panic (a bug in pdyn) raises `pdyn.PdynError` with one
//! message shape instead of unwinding into the interpreter as a `PanicException`.

use pdyn::sim;
use pdyn::Error;
use pyo3::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// Builds an instance of an exception class of `pdyn._errors`.
pub(crate) fn py_error<'py>(
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
pub(crate) fn pdyn_error(py: Python<'_>, class: &str, message: String) -> PyErr {
    py_error(py, class, |c| c.call1((message,)))
}

/// Renders a [`pdyn::Error`]: `ModelError` (with file, line, column) for a model that does not
/// load, `ParameterError` for a bad parameter value or option, `PdynError` otherwise.
pub(crate) fn to_py(py: Python<'_>, e: &Error) -> PyErr {
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
                | sim::SimError::TooManySweepRuns { .. }
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

/// An error of `pdyn.kin` / `pdyn.dsolve`: `ModelError` located in the argument it came from
/// (`file` is the argument: `<position>`, `--at`, `<equation 1>`...; `line`/`column` within
/// its text when the error is in an expression), `PdynError` for a bug.
pub(crate) fn input_error(py: Python<'_>, e: &Error) -> PyErr {
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

/// A model that did not load, with the text it was loaded from (for the located message).
pub(crate) fn load_error(source: &str, error: pdyn_mech::ModelError) -> Error {
    Error::Model {
        error,
        source: source.into(),
    }
}

/// Runs `f`, turning a panic (a bug in pdyn) into
/// `pdyn.PdynError("internal error in pdyn (please report it): <panic message>")` instead of
/// unwinding into the interpreter.
///
/// Bodies that release the GIL call `py.allow_threads` inside `f`: pyo3 takes the GIL back
/// while a panic unwinds out of `allow_threads`, so this one `catch_unwind` covers them too,
/// and the exception is built with the GIL held.
pub(crate) fn guarded<T>(py: Python<'_>, f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
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
