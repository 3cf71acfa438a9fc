//! `pdyn.solve_ivp`: SciPy's `solve_ivp` on pdyn's integrators. The right-hand side and the
//! events are Python callables (called back with the GIL held) or expression strings,
//! compiled once (native code by the Cranelift JIT, the interpreter where there is none) and
//! cached across calls; when nothing calls back into Python, the integration runs with the
//! GIL released.

use crate::convert::{f64_array, f64_matrix, method_name, stats_dict};
use crate::errors::{guarded, pdyn_error};
use numpy::{PyArray1, PyReadonlyArray1};
use pdyn_ode::{Direction, Event, FnSystem, Method, Options, Solution, Status};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::cell::RefCell;
use std::sync::Arc;

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
pub(crate) fn _solve_ivp(
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
    guarded(py, || {
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
        let to_rhs =
            |obj: &Bound<'_, PyAny>, what: &str, outputs: Option<usize>| -> PyResult<Rhs> {
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
                pdyn::ivp::compile_rhs(&exprs, n, &args, jit)
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
                let err = RefCell::new(None);
                integrate(None, rhs_ref, evs, args_ref, o_ref, &err)
            })
        } else {
            integrate(Some(py), &rhs, &ivp_events, &args, &o, &err)
        };
        if let Some(e) = err.into_inner() {
            return Err(e);
        }
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
    })
}
