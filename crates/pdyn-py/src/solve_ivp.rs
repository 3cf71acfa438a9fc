//! `pdyn.solve_ivp`: SciPy's `solve_ivp` on pdyn's integrators. The right-hand side and the
//! events are Python callables (called back with the GIL held) or expression strings,
//! compiled once (native code by the Cranelift JIT, the interpreter where there is none) and
//! cached across calls; when nothing calls back into Python, the integration runs with the
//! GIL released.

use crate::convert::{f64_array, f64_matrix, method_name, stats_dict};
use crate::errors::{guarded, pdyn_error};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use pdyn_ode::{Direction, Event, Method, OdeSystem, Options, Solution, Status};
use pyo3::exceptions::{PyKeyboardInterrupt, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyFloat, PyInt, PyList, PyTuple};
use std::cell::{Cell, RefCell};
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

/// The Jacobian given to `solve_ivp`: a constant matrix or a callable `jac(t, y)`.
enum Jac {
    Constant(Vec<f64>),
    Callable(PyObject),
}

/// The options of one `solve_ivp` call.
struct IvpOptions {
    method: Method,
    t_span: (f64, f64),
    y0: Vec<f64>,
    opts: Options,
    /// SciPy's `vectorized`: `fun` takes a `(n, k)` array and returns one.
    vectorized: bool,
    jac: Option<Jac>,
}

/// What the callables were asked to do (SciPy's `nfev`, `njev`), counted at the calls.
#[derive(Default)]
struct Calls {
    fun: Cell<usize>,
    jac: Cell<usize>,
}

/// The system `solve_ivp` integrates: `f`, its batch form (the finite-difference Jacobian's
/// perturbed states in one call when `vectorized`), and the Jacobian when one was given.
struct IvpSystem<'a> {
    n: usize,
    f: &'a VecFn<'a>,
    batch: Option<&'a VecFn<'a>>,
    jac: Option<&'a VecFn<'a>>,
}

/// `f(t, y, out)`: a right-hand side, its batch form, or a Jacobian.
type VecFn<'a> = dyn Fn(f64, &[f64], &mut [f64]) + 'a;

impl OdeSystem for IvpSystem<'_> {
    fn dim(&self) -> usize {
        self.n
    }
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        (self.f)(t, y, dydt)
    }
    fn rhs_batch(&self, t: f64, ys: &[f64], out: &mut [f64]) {
        match self.batch {
            Some(b) => b(t, ys, out),
            None => {
                for (y, o) in ys.chunks_exact(self.n).zip(out.chunks_exact_mut(self.n)) {
                    (self.f)(t, y, o);
                }
            }
        }
    }
    fn has_jacobian(&self) -> bool {
        self.jac.is_some()
    }
    fn jacobian(&self, t: f64, y: &[f64], jac: &mut [f64]) {
        if let Some(j) = self.jac {
            j(t, y, jac)
        }
    }
}

/// Keeps the first Python error raised in a callback.
fn keep(err: &RefCell<Option<PyErr>>, e: PyErr) {
    if err.borrow().is_none() {
        *err.borrow_mut() = Some(e);
    }
}

/// `v` as a flat float64 vector (row-major for a matrix; a SciPy sparse matrix is made dense).
/// What a right-hand side usually returns (a list or tuple of floats, a 1-D float64 array) is
/// read directly, without calling NumPy: this runs once per evaluation.
fn to_vec(py: Python<'_>, v: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    if let Ok(a) = v.downcast::<PyArray1<f64>>() {
        if let Ok(ro) = a.try_readonly() {
            if let Ok(s) = ro.as_slice() {
                return Ok(s.to_vec());
            }
        }
    }
    let floats = |items: &mut dyn Iterator<Item = Bound<'_, PyAny>>, len: usize| {
        let mut out = Vec::with_capacity(len);
        for x in items {
            // Python floats (NumPy's float64 is one) and ints; anything else (a 0-d or
            // 1-element array, a nested list) goes through numpy.asarray.
            if x.is_instance_of::<PyFloat>() || x.is_instance_of::<PyInt>() {
                out.push(x.extract::<f64>().ok()?);
            } else {
                return None;
            }
        }
        Some(out)
    };
    if let Ok(l) = v.downcast::<PyList>() {
        if let Some(out) = floats(&mut l.iter(), l.len()) {
            return Ok(out);
        }
    } else if let Ok(t) = v.downcast::<PyTuple>() {
        if let Some(out) = floats(&mut t.iter(), t.len()) {
            return Ok(out);
        }
    }
    to_vec_numpy(py, v)
}

/// [`to_vec`] through `numpy.asarray`.
fn to_vec_numpy(py: Python<'_>, v: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    let np = py.import("numpy")?;
    let v = if v.hasattr("toarray")? && !v.is_instance(&np.getattr("ndarray")?)? {
        v.call_method0("toarray")?
    } else {
        v.clone()
    };
    let a = np.call_method1("asarray", (v, "float64"))?;
    a.call_method0("ravel")?.extract::<Vec<f64>>()
}

/// Integrates with the given right-hand side and events; Python errors raised inside
/// callbacks are kept in `err` (the solver then sees NaN and stops).
#[allow(clippy::too_many_arguments)]
fn integrate(
    py: Option<Python<'_>>,
    rhs: &Rhs,
    events: &[IvpEvent],
    params: &[(String, f64)],
    o: &IvpOptions,
    err: &RefCell<Option<PyErr>>,
    calls: &Calls,
    watch: Option<&crate::interrupt::SignalWatch>,
) -> Result<Solution, pdyn_ode::OdeError> {
    let n = o.y0.len();
    // Calls a Python function of (t, y) with y of shape (n,), or (n, k) for `k` states given
    // one after the other (`cols`).
    let call_py = |f: &PyObject, t: f64, y: &[f64], cols: Option<usize>| -> Option<Vec<f64>> {
        let py = py?;
        if err.borrow().is_some() {
            return None;
        }
        let r = (|| -> PyResult<Vec<f64>> {
            let arr = PyArray1::from_slice(py, y);
            let arg: Bound<'_, PyAny> = match cols {
                // k states of n one after the other = the (k, n) array, transposed.
                Some(k) => arr.call_method1("reshape", (k, n))?.getattr("T")?,
                None => arr.into_any(),
            };
            let v = f.call1(py, (t, arg))?;
            let v = v.bind(py);
            match cols {
                Some(k) => {
                    // The (n, k) result, read state by state.
                    let np = py.import("numpy")?;
                    let a = np.call_method1("asarray", (v, "float64"))?;
                    let shape: Vec<usize> = a.getattr("shape")?.extract()?;
                    if shape != [n, k] {
                        return Err(PyValueError::new_err(format!(
                            "fun (vectorized) returned an array of shape {shape:?} for y of \
                             shape ({n}, {k}); expected ({n}, {k})"
                        )));
                    }
                    a.getattr("T")?.call_method0("ravel")?.extract()
                }
                None => to_vec(py, v),
            }
        })();
        match r {
            Ok(v) => Some(v),
            Err(e) => {
                keep(err, e);
                None
            }
        }
    };
    let evaluator = match rhs {
        Rhs::Compiled(p) => Some(Evaluator::new(p, n, params)),
        Rhs::Callable(_) => None,
    };
    let fill = |dy: &mut [f64], v: Option<Vec<f64>>| match v {
        Some(v) if v.len() == dy.len() => dy.copy_from_slice(&v),
        Some(v) => {
            keep(
                err,
                PyValueError::new_err(format!(
                    "fun returned {} values; expected {} (y0 has {n} components)",
                    v.len(),
                    dy.len()
                )),
            );
            dy.fill(f64::NAN);
        }
        None => dy.fill(f64::NAN),
    };
    let f = |t: f64, y: &[f64], dy: &mut [f64]| match (rhs, &evaluator) {
        (Rhs::Compiled(_), Some(ev)) => {
            if let Some(w) = watch {
                w.tick();
            }
            ev.eval(t, y, dy)
        }
        (Rhs::Callable(func), _) => {
            calls.fun.set(calls.fun.get() + 1);
            let v = call_py(func, t, y, o.vectorized.then_some(1));
            fill(dy, v)
        }
        _ => dy.fill(f64::NAN),
    };
    let batch = |t: f64, ys: &[f64], out: &mut [f64]| match rhs {
        Rhs::Callable(func) => {
            calls.fun.set(calls.fun.get() + 1);
            let v = call_py(func, t, ys, Some(ys.len() / n));
            fill(out, v)
        }
        Rhs::Compiled(_) => {
            for (y, o) in ys.chunks_exact(n).zip(out.chunks_exact_mut(n)) {
                f(t, y, o);
            }
        }
    };
    let jac = |t: f64, y: &[f64], out: &mut [f64]| {
        calls.jac.set(calls.jac.get() + 1);
        match &o.jac {
            Some(Jac::Constant(m)) => out.copy_from_slice(m),
            Some(Jac::Callable(j)) => match call_py(j, t, y, None) {
                Some(v) if v.len() == out.len() => out.copy_from_slice(&v),
                Some(v) => {
                    keep(
                        err,
                        PyValueError::new_err(format!(
                            "jac returned {} values; expected an array of shape ({n}, {n})",
                            v.len()
                        )),
                    );
                    out.fill(f64::NAN);
                }
                None => out.fill(f64::NAN),
            },
            None => out.fill(f64::NAN),
        }
    };
    let system = IvpSystem {
        n,
        f: &f,
        batch: (o.vectorized && matches!(rhs, Rhs::Callable(_))).then_some(&batch as _),
        jac: o.jac.as_ref().map(|_| &jac as _),
    };
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
                    call_py(func, t, y, None)
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

/// `sol.sol` of `pdyn.solve_ivp(..., dense_output=True)`: every step's own interpolant (the
/// method's continuous extension: order 7 for DOP853, 4 for RK45 and Tsit5, 3 for RK23 and
/// Radau), called like SciPy's `OdeSolution`: `sol(t)` is the state at `t`, shape `(n,)` for
/// a scalar and `(n, len(t))` for an array.
#[pyclass(module = "pdyn", name = "OdeSolution", frozen)]
pub(crate) struct IvpDense {
    inner: pdyn_ode::DenseSolution,
    n: usize,
}

#[pymethods]
impl IvpDense {
    fn __call__<'py>(&self, py: Python<'py>, t: &Bound<'py, PyAny>) -> PyResult<PyObject> {
        let np = py.import("numpy")?;
        let a = np.call_method1("asarray", (t, "float64"))?;
        let ndim: usize = a.getattr("ndim")?.extract()?;
        if ndim > 1 {
            return Err(PyValueError::new_err("`t` must be a float or a 1-D array."));
        }
        let ts: Vec<f64> = a.call_method0("ravel")?.extract()?;
        let n = self.n;
        let mut out = vec![0.0; n * ts.len()];
        if !self.inner.is_empty() {
            for (k, &t) in ts.iter().enumerate() {
                self.inner.eval(t, &mut out[k * n..(k + 1) * n]);
            }
        }
        if ndim == 0 {
            return Ok(f64_array(py, out).into_any().unbind());
        }
        let m = f64_matrix(py, out, ts.len(), n)?;
        Ok(m.bind(py).getattr("T")?.call_method0("copy")?.unbind())
    }

    /// The step boundaries (SciPy's `OdeSolution.ts`).
    #[getter]
    fn ts<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.steps())
    }

    /// The start of the interval covered.
    #[getter]
    fn t_min(&self) -> f64 {
        let s = self.inner.steps();
        s.first()
            .copied()
            .unwrap_or(f64::NAN)
            .min(s.last().copied().unwrap_or(f64::NAN))
    }

    /// The end of the interval covered.
    #[getter]
    fn t_max(&self) -> f64 {
        let s = self.inner.steps();
        s.first()
            .copied()
            .unwrap_or(f64::NAN)
            .max(s.last().copied().unwrap_or(f64::NAN))
    }

    /// Number of steps (SciPy's `n_segments`).
    #[getter]
    fn n_segments(&self) -> usize {
        self.inner.len()
    }

    /// The interpolant's name and order.
    #[getter]
    fn interpolant(&self) -> String {
        if self.inner.is_empty() {
            return "none".into();
        }
        match self.inner.interpolant(self.inner.len() - 1) {
            pdyn_ode::Interpolant::Dopri5 => "dopri5 (order 4)".into(),
            pdyn_ode::Interpolant::Tsit5 => "tsit5 (order 4)".into(),
            pdyn_ode::Interpolant::Dop853 => "dop853 (order 7)".into(),
            pdyn_ode::Interpolant::Radau5 { .. } => "radau5 collocation (order 3)".into(),
            pdyn_ode::Interpolant::Hermite => "cubic Hermite (order 3)".into(),
            pdyn_ode::Interpolant::Bdf { .. } => {
                // Each step's own order: the highest used.
                let top = (0..self.inner.len())
                    .filter_map(|k| match self.inner.interpolant(k) {
                        pdyn_ode::Interpolant::Bdf { order } => Some(order),
                        _ => None,
                    })
                    .max()
                    .unwrap_or(1);
                format!("bdf interpolating polynomial (each step's order, up to {top})")
            }
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "OdeSolution({} steps on [{}, {}], {})",
            self.inner.len(),
            self.t_min(),
            self.t_max(),
            self.interpolant()
        )
    }
}

/// Doubles a solve may store before pdyn's memory guard stops it (2^28 = 2 GiB) when no
/// `max_steps` is given: the outputs after every step (without `t_eval`) and the dense output
/// grow with the number of steps.
const MEMORY_GUARD_DOUBLES: usize = 1 << 28;

/// `solve_ivp`'s Rust part: returns a dict of plain data (`pdyn.solve_ivp` builds the
/// `OdeResult`). `fun` is a callable `fun(t, y)` (arguments already bound) or a list of
/// expression strings; `jac` a callable, a matrix (row-major, flat) or `None`.
#[pyfunction]
#[pyo3(signature = (fun, t0, tf, y0, method, t_eval, rtol, atol, max_step, first_step, min_step, max_steps, events, args, dense=false, jit=true, jac=None, vectorized=false, jac_sparsity=None))]
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
    min_step: Option<f64>,
    max_steps: Option<usize>,
    events: Vec<(Bound<'_, PyAny>, Option<usize>, i32)>,
    args: Vec<(String, f64)>,
    dense: bool,
    jit: bool,
    jac: Option<Bound<'_, PyAny>>,
    vectorized: bool,
    jac_sparsity: Option<(Vec<usize>, Vec<usize>)>,
) -> PyResult<PyObject> {
    guarded(py, || {
        let y0 = y0.as_slice()?.to_vec();
        let n = y0.len();
        let Some(m) = Method::from_name(&method_name(method)) else {
            return Err(pdyn_error(
                py,
                "ParameterError",
                format!(
                    "unknown method `{method}`: use RK45, RK23, DOP853, Radau, BDF, LSODA or \
                     one of pdyn's ({})",
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
        let jac = match jac {
            None => None,
            Some(j) if j.is_callable() => Some(Jac::Callable(j.unbind())),
            Some(j) => {
                let v = to_vec(py, &j)?;
                if v.len() != n * n {
                    return Err(PyValueError::new_err(format!(
                        "`jac` is expected to have shape ({n}, {n}), but actually has {} \
                         elements.",
                        v.len()
                    )));
                }
                Some(Jac::Constant(v))
            }
        };
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
            min_step,
            dense_output: dense,
            // SciPy: t is exactly t_eval; a terminal event is in t_events/y_events.
            output_terminal_event: false,
            ..Options::default()
        };
        // No step cap unless asked (SciPy has none), but a memory guard when what is stored
        // grows with the steps: the outputs of every step (no t_eval) and the dense output.
        let per_step = if t_eval.is_none() { n + 1 } else { 0 }
            + if dense {
                pdyn_ode::DenseSolution::doubles_per_step(pdyn_ode::Interpolant::Dop853, n) + 1
            } else {
                0
            };
        let guard = match max_steps {
            Some(ms) => {
                opts.max_steps = ms;
                None
            }
            None if per_step == 0 => {
                opts.max_steps = usize::MAX;
                None
            }
            None => {
                let g = MEMORY_GUARD_DOUBLES / per_step;
                opts.max_steps = g;
                Some(g)
            }
        };
        if let Some(te) = t_eval {
            opts.t_eval = Some(te.as_slice()?.to_vec());
        }
        if let Some((rows, cols)) = jac_sparsity {
            // The entries (row, column) where the Jacobian may be nonzero.
            let mut by_column: Vec<Vec<usize>> = vec![Vec::new(); n];
            for (&i, &j) in rows.iter().zip(&cols) {
                if i >= n || j >= n {
                    return Err(PyValueError::new_err(format!(
                        "`jac_sparsity` has an entry ({i}, {j}) outside the {n} × {n} Jacobian."
                    )));
                }
                by_column[j].push(i);
            }
            let sparsity = pdyn_ode::Sparsity::from_columns(n, by_column)
                .map_err(|e| PyValueError::new_err(e.to_string()))?;
            opts.jac_sparsity = Some(Arc::new(sparsity));
        }
        if m == Method::Auto {
            // LSODA: the stiffness test at every step (as LSODA weighs a switch at every
            // step), not every 1000 steps as dopri5.f.
            opts.stiffness_check_interval = 1;
        }
        let mut o = IvpOptions {
            method: m,
            t_span: (t0, tf),
            y0,
            opts,
            vectorized,
            jac,
        };
        let all_compiled = matches!(rhs, Rhs::Compiled(_))
            && !matches!(o.jac, Some(Jac::Callable(_)))
            && ivp_events
                .iter()
                .all(|e| matches!(e.function, Rhs::Compiled(_)));
        let err = RefCell::new(None);
        let calls = Calls::default();
        let mut interrupted = false;
        let result = if all_compiled {
            // No Python in the loop: the GIL is released for the whole integration, which
            // runs on this thread; Ctrl-C stops it at the next step (`SignalWatch`: Python's
            // signal handlers run every 20 ms from the right-hand side's evaluations).
            let stop: pdyn_ode::Interrupt = Default::default();
            o.opts.interrupt = Some(stop.clone());
            let rhs_ref = &rhs;
            let evs = &ivp_events;
            let args_ref = &args;
            let o_ref = &o;
            let (value, raised) = py.allow_threads(move || {
                let err = RefCell::new(None);
                let watch = crate::interrupt::SignalWatch::new(stop);
                let r = integrate(
                    None,
                    rhs_ref,
                    evs,
                    args_ref,
                    o_ref,
                    &err,
                    &Calls::default(),
                    Some(&watch),
                );
                (r, watch.into_raised())
            });
            match raised {
                Some(e) if !e.is_instance_of::<PyKeyboardInterrupt>(py) => return Err(e),
                Some(_) => interrupted = true,
                None => {}
            }
            value
        } else {
            integrate(Some(py), &rhs, &ivp_events, &args, &o, &err, &calls, None)
        };
        if let Some(e) = err.into_inner() {
            // Ctrl-C while a Python callback ran: the solve stopped there (the callback's
            // NaN), and what it computed goes back with the interrupt, as for compiled
            // expressions.
            if e.is_instance_of::<PyKeyboardInterrupt>(py) && result.is_err() {
                interrupted = true;
            } else {
                return Err(e);
            }
        }
        let (sol, message, status) = match result.map_err(|mut e| {
            let partial = e.take_partial();
            (e, partial)
        }) {
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
            Err((e, partial)) => match (e.failure_point(), partial) {
                (Some(fp), Some(partial)) => {
                    let msg = match (&e, guard) {
                        (pdyn_ode::OdeError::MaxSteps { at, .. }, Some(g)) => format!(
                            "pdyn's memory guard: more than {g} steps would store over 2 GiB \
                             (outputs{} of {n} states); stopped at t = {}. Pass t_eval= (without \
                             dense_output) for no limit, or max_steps= to set one.",
                            if dense { " and dense output" } else { "" },
                            at.t
                        ),
                        _ if interrupted => format!(
                            "interrupted (Ctrl-C) at t = {}; the result holds what was \
                             computed until then",
                            fp.t
                        ),
                        (pdyn_ode::OdeError::StepSizeUnderflow { .. }, _) => format!(
                            "Required step size is less than spacing between numbers. ({e})"
                        ),
                        _ => e.to_string(),
                    };
                    (partial, msg, -1)
                }
                _ => return Err(pdyn_error(py, "ParameterError", e.to_string())),
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
        // What was done: the callable's calls when fun is Python, the solver's count of
        // evaluations of the compiled right-hand side otherwise; LU factorizations counted
        // one per matrix (Radau5 factors a real and a complex one per decomposition).
        let nfev = match rhs {
            Rhs::Callable(_) => calls.fun.get(),
            Rhs::Compiled(_) => sol.stats.fevals,
        };
        let njev = if o.jac.is_some() {
            calls.jac.get()
        } else {
            sol.stats.jacobians
        };
        let nlu = sol.stats.lu_decompositions
            * if matches!(sol.method, Method::Radau5) {
                2
            } else {
                1
            };
        d.set_item("nfev", nfev)?;
        d.set_item("njev", njev)?;
        d.set_item("nlu", nlu)?;
        d.set_item("message", message)?;
        d.set_item("interrupted", interrupted)?;
        d.set_item("status", status)?;
        d.set_item("method", sol.method.name())?;
        d.set_item("gil_released", all_compiled)?;
        d.set_item(
            "native",
            matches!(&rhs, Rhs::Compiled(ev) if ev.is_native()),
        )?;
        if let Some(inner) = sol.dense {
            d.set_item("sol", Py::new(py, IvpDense { inner, n })?)?;
        }
        // The solution's own buffers become the arrays: no copy.
        d.set_item("t", f64_array(py, sol.t))?;
        d.set_item("y_rows", f64_matrix(py, sol.y, len, n)?)?;
        Ok(d.into_any().unbind())
    })
}
