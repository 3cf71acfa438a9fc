//! The forward sensitivity equations of a model, derived symbolically and compiled.
//!
//! For the state `y = (q, q')` with `y' = f(t, y, p)` and `y(0) = y₀(p)`, the sensitivity
//! `S = ∂y/∂θ` to the free quantities `θ` (parameters, then initial values) obeys
//!
//! ```text
//! S' = (∂f/∂y) S + ∂f/∂θ,      S(0) = ∂y₀/∂θ
//! ```
//!
//! (∂f/∂θ = 0 and ∂y₀/∂θ a unit vector for an initial value set free). `∂f/∂y` and `∂f/∂p`
//! are differentiated by pdyn-expr from the derived accelerations, with the chain rule through
//! derived parameters (`m = "4/3*pi*a^3*rho"`: `df/da = ∂f/∂a + ∂f/∂m · dm/da`); `(y, S)` is
//! integrated as one system whose right-hand side is one compiled [`Program`] (native code by
//! pdyn-jit where the platform allows), with `S` stored column by column after `y`.

use crate::Error;
use pdyn_expr::{Id, Pool, Program};
use pdyn_jit::{Evaluator, JitMode};
use pdyn_mech::derive::{Derivation, UnknownKind};
use pdyn_mech::model::CoordinateKind;
use pdyn_mech::parameters::DerivedParameters;
use pdyn_mech::Model;
use pdyn_ode::OdeSystem;
use std::cell::RefCell;

/// The model's equations with their sensitivities to a chosen set of free quantities.
#[derive(Clone)]
pub struct Sensitivities {
    /// State dimension `2n` (`q`, then `q'`).
    pub dim: usize,
    /// The state's names (`x`, then `x'`).
    pub state_names: Vec<String>,
    /// Free parameters (indices into the model's parameters).
    pub params: Vec<usize>,
    /// Free initial values (indices into the state).
    pub initials: Vec<usize>,
    /// `[t, y, S, parameters] → [f, S']`.
    rhs: Evaluator,
    /// `parameters → [y₀, ∂y₀/∂p (dim × params, column by column)]`.
    ic: Program,
    /// The derived parameters, recomputed from the free ones.
    pub derived: DerivedParameters,
}

/// The total derivative of `e` by the parameter symbol `p`, through the derived parameters
/// (`chain`: each derived parameter's symbol with its own total derivative by `p`).
fn total_diff(pool: &mut Pool, e: Id, p: Id, chain: &[(Id, Id)]) -> Id {
    let mut terms = vec![pool.diff(e, p)];
    for &(q, dq) in chain {
        if dq == Pool::ZERO {
            continue;
        }
        let de = pool.diff(e, q);
        if de != Pool::ZERO {
            terms.push(pool.mul(&[de, dq]));
        }
    }
    pool.add(&terms)
}

impl Sensitivities {
    /// Derives and compiles the sensitivity system of `model` (derived as `d`) to the
    /// parameters `params` and the initial values of the state components `initials`.
    /// `origin` names the model file in errors.
    pub fn new(
        model: &mut Model,
        d: &Derivation,
        params: &[usize],
        initials: &[usize],
        jit: JitMode,
    ) -> Result<Sensitivities, Error> {
        let origin = model.origin.clone();
        let n = d.free.len();
        let dim = 2 * n;
        let Some(sol) = &d.solution else {
            return Err(Error::argument(
                "--free",
                format!(
                    "{origin}: fitting needs the accelerations in closed form, and this model's \
                     are solved numerically at each step (a large or tree-shaped system); \
                     the sensitivity equations are derived from the closed form"
                ),
            ));
        };
        let mut acc = vec![Pool::ZERO; n];
        for (u, &e) in d.unknowns.iter().zip(sol) {
            if let UnknownKind::Acceleration(ci) = u.kind {
                if let Some(i) = d.free.iter().position(|&f| f == ci) {
                    acc[i] = e;
                }
            }
        }
        let mut f: Vec<Id> = d.state[n..].to_vec();
        f.extend(acc);
        let param_ids: Vec<Id> = model.parameters.iter().map(|p| p.id).collect();
        // Initial values as expressions of the parameters (numbers when not given by any).
        model.materialize_initials();
        let mut y0 = vec![Pool::ZERO; dim];
        for (j, &ci) in d.free.iter().enumerate() {
            if let Some(&(_, e, r)) = model.initial_exprs.iter().find(|(k, _, _)| *k == ci) {
                y0[j] = e;
                y0[n + j] = r;
            } else if let CoordinateKind::Free { initial, rate } = model.coordinates[ci].kind {
                y0[j] = model.pool.num(pdyn_expr::Number::Float(initial));
                y0[n + j] = model.pool.num(pdyn_expr::Number::Float(rate));
            }
        }
        let pool = &mut model.pool;
        let k = params.len();
        let cols = k + initials.len();
        let s_syms: Vec<Id> = (0..dim * cols)
            .map(|i| {
                let s = pool.symbol(&format!("__pdyn_fit_S{}_{}", i % dim, i / dim), false);
                pool.sym(s)
            })
            .collect();
        let jac = pool.jacobian(&f, &d.state);
        let mut outputs = f.clone();
        let mut ic_out = y0.clone();
        for c in 0..cols {
            let forcing: Vec<Id> = if c < k {
                let p = param_ids[params[c]];
                // Each derived parameter's total derivative by p, in file order (a
                // definition uses earlier parameters only).
                let mut chain: Vec<(Id, Id)> = Vec::new();
                for par in &model.parameters {
                    if let Some(def) = par.definition {
                        let dq = total_diff(pool, def, p, &chain);
                        chain.push((par.id, dq));
                    }
                }
                let forcing: Vec<Id> = f.iter().map(|&e| total_diff(pool, e, p, &chain)).collect();
                let dy0: Vec<Id> = y0.iter().map(|&e| total_diff(pool, e, p, &chain)).collect();
                if forcing.iter().chain(&dy0).all(|&e| e == Pool::ZERO) {
                    return Err(Error::argument(
                        "--free",
                        format!(
                            "the parameter `{}` does not affect the equations of motion or the \
                             initial conditions of {origin}: its value cannot be fitted",
                            model.parameters[params[c]].name
                        ),
                    ));
                }
                ic_out.extend(dy0);
                forcing
            } else {
                vec![Pool::ZERO; dim]
            };
            for i in 0..dim {
                let mut terms = Vec::new();
                if forcing[i] != Pool::ZERO {
                    terms.push(forcing[i]);
                }
                for l in 0..dim {
                    let a = jac[i * dim + l];
                    if a != Pool::ZERO {
                        terms.push(pool.mul(&[a, s_syms[c * dim + l]]));
                    }
                }
                outputs.push(pool.add(&terms));
            }
        }
        let mut inputs = vec![pool.time()];
        inputs.extend(&d.state);
        inputs.extend(&s_syms);
        inputs.extend(&param_ids);
        let compile_error = |what: &str, e: pdyn_expr::compile::CompileError| Error::Sim {
            origin: origin.clone(),
            context: "",
            error: crate::sim::SimError::Compile {
                what: what.into(),
                error: e,
            },
        };
        let prog = Program::compile(pool, &inputs, &outputs)
            .map_err(|e| compile_error("the sensitivity equations", e))?;
        let ic = Program::compile(pool, &param_ids, &ic_out)
            .map_err(|e| compile_error("the initial conditions' sensitivities", e))?;
        Ok(Sensitivities {
            dim,
            state_names: d.state_names.clone(),
            params: params.to_vec(),
            initials: initials.to_vec(),
            rhs: Evaluator::new(prog, jit),
            ic,
            derived: DerivedParameters::compile(model),
        })
    }

    /// Number of sensitivity columns (free parameters, then free initial values).
    pub fn columns(&self) -> usize {
        self.params.len() + self.initials.len()
    }

    /// The initial state `(y₀, S(0))` for the parameter values `p` (all, derived ones
    /// included) with the free initial values `initial` (as many as [`Self::initials`]).
    pub fn initial_state(&self, p: &[f64], initial: &[f64]) -> Vec<f64> {
        let (dim, k) = (self.dim, self.params.len());
        let mut out = vec![0.0; dim * (1 + k)];
        let mut ws = self.ic.workspace();
        self.ic.eval(p, &mut ws, &mut out);
        let mut z = vec![0.0; dim * (1 + self.columns())];
        z[..out.len()].copy_from_slice(&out);
        for (c, (&j, &v)) in self.initials.iter().zip(initial).enumerate() {
            z[j] = v;
            z[dim * (1 + k + c) + j] = 1.0;
            // A free initial value no longer follows the parameters.
            for cp in 0..k {
                z[dim * (1 + cp) + j] = 0.0;
            }
        }
        z
    }

    /// The system `(y, S)' ` for the parameter values `p`.
    pub fn system<'a>(&'a self, p: &'a [f64]) -> System<'a> {
        let n_in = 1 + self.dim * (1 + self.columns()) + p.len();
        let mut input = vec![0.0; n_in];
        input[n_in - p.len()..].copy_from_slice(p);
        System {
            s: self,
            scratch: RefCell::new((input, self.rhs.workspace())),
        }
    }
}

/// [`Sensitivities`] with parameter values: an [`OdeSystem`] of dimension `dim (1 + columns)`.
pub struct System<'a> {
    s: &'a Sensitivities,
    scratch: RefCell<(Vec<f64>, Vec<f64>)>,
}

impl OdeSystem for System<'_> {
    fn dim(&self) -> usize {
        self.s.dim * (1 + self.s.columns())
    }

    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        let mut sc = self.scratch.borrow_mut();
        let (input, ws) = &mut *sc;
        input[0] = t;
        input[1..1 + y.len()].copy_from_slice(y);
        self.s.rhs.eval(input, ws, dydt);
    }
}
