//! Derived equations compiled for the integrators: the bridge between `pdyn-mech` (symbols) and
//! `pdyn-ode` (numbers).
//!
//! State `w = [q, q']`. Inputs of every compiled program: `[t, q, q', parameters]`; the
//! "observation" inputs append the unknowns `[q'', reactions]` so that monitors, events and
//! output columns may use accelerations and reaction forces. When the derivation solved its
//! linear system exactly, one [`Program`] gives all unknowns; otherwise the system `A x = b` is
//! compiled and solved by LU at each evaluation (allocation-free).

use pdyn_expr::compile::{CompileError, CompiledLinearSystem};
use pdyn_expr::{Id, Node, Pool, Program};
use pdyn_mech::derive::{Derivation, UnknownKind};
use pdyn_mech::Model;
use pdyn_ode::{OdeSystem, SecondOrderSystem};
use std::cell::RefCell;

#[derive(Clone)]
enum Engine {
    /// One program computing every unknown.
    Exact(Program),
    /// `A x = b` solved numerically.
    Numeric(Box<CompiledLinearSystem>),
}

#[derive(Clone)]
struct Scratch {
    input: Vec<f64>,
    ws: Vec<f64>,
    out: Vec<f64>,
    numeric: Option<CompiledLinearSystem>,
    jac_ws: Vec<f64>,
    jac_out: Vec<f64>,
}

/// The equations of motion of a model as an [`OdeSystem`] (and a [`SecondOrderSystem`]).
#[derive(Clone)]
pub struct CompiledModel {
    /// Number of free coordinates.
    pub n: usize,
    /// Number of reactions (unknowns besides the accelerations).
    pub n_reactions: usize,
    /// For each unknown: its slot (`Ok(i)`: acceleration of free coordinate `i`; `Err(r)`:
    /// reaction `r`).
    slots: Vec<Result<usize, usize>>,
    engine: Engine,
    jacobian: Option<Program>,
    /// True when no acceleration depends on a rate (needed by Verlet and its compositions).
    pub separable: bool,
    scratch: RefCell<Scratch>,
    /// The leaves of the program inputs `[t, q, q', parameters]`.
    pub inputs: Vec<Id>,
    /// The observation inputs: `inputs` followed by `[q'', reactions]`.
    pub observation_inputs: Vec<Id>,
}

/// Leaves `[t, q, q', parameters]` and the unknowns of a derivation.
pub fn input_leaves(model: &mut Model, d: &Derivation) -> (Vec<Id>, Vec<Id>) {
    let t = model.pool.time();
    let mut inputs = vec![t];
    inputs.extend(&d.state);
    inputs.extend(model.parameters.iter().map(|p| p.id));
    let mut obs = inputs.clone();
    // Unknowns in a fixed order: accelerations by coordinate, then reactions.
    obs.extend(
        d.free
            .iter()
            .map(|&i| model.pool.coord(model.coordinates[i].sym, 2)),
    );
    obs.extend(model.reactions.iter().map(|r| r.id));
    (inputs, obs)
}

impl CompiledModel {
    /// Compiles `d` (derived from `model`).
    pub fn new(model: &mut Model, d: &Derivation) -> Result<CompiledModel, CompileError> {
        let n = d.free.len();
        let (inputs, observation_inputs) = input_leaves(model, d);
        let slots: Vec<Result<usize, usize>> = d
            .unknowns
            .iter()
            .map(|u| match u.kind {
                UnknownKind::Acceleration(ci) => {
                    Ok(d.free.iter().position(|&f| f == ci).unwrap_or(0))
                }
                UnknownKind::Reaction(r) => Err(r),
            })
            .collect();
        let p = &mut model.pool;
        let rates: Vec<Id> = d.state[n..].to_vec();
        let (engine, jacobian, separable) = match &d.solution {
            Some(sol) => {
                let prog = Program::compile(p, &inputs, sol)?;
                let accs: Vec<Id> = slots
                    .iter()
                    .zip(sol)
                    .filter(|(s, _)| s.is_ok())
                    .map(|(_, &e)| e)
                    .collect();
                let separable = !accs
                    .iter()
                    .any(|&a| rates.iter().any(|&r| p.contains(a, r)));
                let jac = p.jacobian(&accs, &d.state);
                let jprog = Program::compile(p, &inputs, &jac)?;
                (Engine::Exact(prog), Some(jprog), separable)
            }
            None => {
                let sys = CompiledLinearSystem::new(p, &d.system, &inputs)?;
                let depends_on_rates = d
                    .system
                    .a
                    .iter()
                    .chain(&d.system.b)
                    .any(|&e| rates.iter().any(|&r| p.contains(e, r)));
                (Engine::Numeric(Box::new(sys)), None, !depends_on_rates)
            }
        };
        let mut input = vec![0.0; inputs.len()];
        for (k, par) in model.parameters.iter().enumerate() {
            input[1 + 2 * n + k] = par.value;
        }
        let (ws, numeric) = match &engine {
            Engine::Exact(prog) => (prog.workspace(), None),
            Engine::Numeric(sys) => (Vec::new(), Some((**sys).clone())),
        };
        let (jac_ws, jac_out) = match &jacobian {
            Some(j) => (j.workspace(), vec![0.0; j.n_outputs()]),
            None => (Vec::new(), Vec::new()),
        };
        Ok(CompiledModel {
            n,
            n_reactions: model.reactions.len(),
            slots: slots.clone(),
            engine,
            jacobian,
            separable,
            scratch: RefCell::new(Scratch {
                input,
                ws,
                out: vec![0.0; slots.len()],
                numeric,
                jac_ws,
                jac_out,
            }),
            inputs,
            observation_inputs,
        })
    }

    /// Sets the parameter values (in model order).
    pub fn set_parameters(&self, values: &[f64]) {
        let mut s = self.scratch.borrow_mut();
        let base = 1 + 2 * self.n;
        s.input[base..base + values.len()].copy_from_slice(values);
    }

    /// The current parameter values.
    pub fn parameters(&self) -> Vec<f64> {
        let s = self.scratch.borrow();
        s.input[1 + 2 * self.n..].to_vec()
    }

    /// Solves for the unknowns at `(t, y)`: writes `q''` into `acc` and the reactions into
    /// `reactions`. A singular system gives NaN (the integrator then stops and reports it).
    pub fn unknowns(&self, t: f64, y: &[f64], acc: &mut [f64], reactions: &mut [f64]) {
        let s = &mut *self.scratch.borrow_mut();
        self.solve_into(s, t, &y[..2 * self.n]);
        for (k, slot) in self.slots.iter().enumerate() {
            match slot {
                Ok(i) => acc[*i] = s.out[k],
                Err(r) => {
                    if let Some(x) = reactions.get_mut(*r) {
                        *x = s.out[k];
                    }
                }
            }
        }
    }

    /// Solves for every unknown at `(t, y)` into `s.out`. A singular system gives NaN, which
    /// the integrator reports with the time and state.
    fn solve_into(&self, s: &mut Scratch, t: f64, y: &[f64]) {
        s.input[0] = t;
        s.input[1..1 + 2 * self.n].copy_from_slice(y);
        match &self.engine {
            Engine::Exact(prog) => prog.eval(&s.input, &mut s.ws, &mut s.out),
            Engine::Numeric(_) => {
                if let Some(sys) = s.numeric.as_mut() {
                    if sys.solve(&s.input, &mut s.out).is_err() {
                        s.out.iter_mut().for_each(|x| *x = f64::NAN);
                    }
                }
            }
        }
    }

    /// Fills the observation input vector `[t, q, q', parameters, q'', reactions]` at `(t, y)`.
    pub fn observation_input(&self, t: f64, y: &[f64], out: &mut Vec<f64>) {
        let n = self.n;
        let mut acc = vec![0.0; n];
        let mut reac = vec![0.0; self.n_reactions];
        self.unknowns(t, y, &mut acc, &mut reac);
        out.clear();
        let s = self.scratch.borrow();
        out.extend_from_slice(&s.input);
        out.extend_from_slice(&acc);
        out.extend_from_slice(&reac);
    }
}

impl OdeSystem for CompiledModel {
    fn dim(&self) -> usize {
        2 * self.n
    }

    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        let n = self.n;
        let s = &mut *self.scratch.borrow_mut();
        self.solve_into(s, t, y);
        dydt[..n].copy_from_slice(&y[n..]);
        for (k, slot) in self.slots.iter().enumerate() {
            if let Ok(i) = slot {
                dydt[n + i] = s.out[k];
            }
        }
    }

    fn has_jacobian(&self) -> bool {
        self.jacobian.is_some()
    }

    fn jacobian(&self, t: f64, y: &[f64], jac: &mut [f64]) {
        let Some(prog) = &self.jacobian else { return };
        let n = self.n;
        let s = &mut *self.scratch.borrow_mut();
        s.input[0] = t;
        s.input[1..1 + 2 * n].copy_from_slice(y);
        prog.eval(&s.input, &mut s.jac_ws, &mut s.jac_out);
        let m = 2 * n;
        jac[..m * m].iter_mut().for_each(|x| *x = 0.0);
        for i in 0..n {
            jac[i * m + n + i] = 1.0;
            for j in 0..m {
                jac[(n + i) * m + j] = s.jac_out[i * m + j];
            }
        }
    }
}

impl SecondOrderSystem for CompiledModel {
    fn dim(&self) -> usize {
        self.n
    }

    fn accel(&self, t: f64, q: &[f64], v: &[f64], acc: &mut [f64]) {
        let n = self.n;
        let mut y = [0.0f64; 64];
        if 2 * n <= y.len() {
            y[..n].copy_from_slice(q);
            y[n..2 * n].copy_from_slice(v);
            let mut d = [0.0f64; 64];
            self.rhs(t, &y[..2 * n], &mut d[..2 * n]);
            acc.copy_from_slice(&d[n..2 * n]);
        } else {
            let mut yv = q.to_vec();
            yv.extend_from_slice(v);
            let mut d = vec![0.0; 2 * n];
            self.rhs(t, &yv, &mut d);
            acc.copy_from_slice(&d[n..]);
        }
    }

    fn separable(&self) -> bool {
        self.separable
    }
}

/// A set of expressions of the observation inputs, evaluated together.
#[derive(Clone)]
pub struct Observer {
    /// Column names.
    pub names: Vec<String>,
    prog: Program,
    ws: RefCell<Vec<f64>>,
}

impl Observer {
    /// Compiles `exprs` over `inputs` (the observation inputs of a [`CompiledModel`]).
    pub fn new(
        pool: &mut Pool,
        inputs: &[Id],
        names: Vec<String>,
        exprs: &[Id],
    ) -> Result<Observer, CompileError> {
        let prog = Program::compile(pool, inputs, exprs)?;
        let ws = RefCell::new(prog.workspace());
        Ok(Observer { names, prog, ws })
    }

    /// Evaluates every expression.
    pub fn eval(&self, input: &[f64], out: &mut [f64]) {
        self.prog.eval(input, &mut self.ws.borrow_mut(), out);
    }

    /// Number of outputs.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// True when there is nothing to evaluate.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }
}

/// True when every leaf of `e` (symbol, coordinate derivative, `t`) is one of `inputs`: `e`
/// can then be compiled over them.
pub fn depends_only_on(pool: &Pool, e: Id, inputs: &[Id]) -> bool {
    pool.topo_order(&[e]).into_iter().all(|n| {
        !matches!(pool.node(n), Node::Sym(_) | Node::Coord(..) | Node::Time) || inputs.contains(&n)
    })
}
