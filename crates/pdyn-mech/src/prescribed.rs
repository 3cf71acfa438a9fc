//! Forces required for a prescribed motion (chapter 3.2), and design criteria.
//!
//! The motion is known — coordinates prescribed as functions of time, or free coordinates given
//! a value, rate and `acceleration` at an instant — so `F = m a` (with `ΣM = 0` for massless
//! frames and the constraints) is a set of equations in the *forces*: reaction magnitudes and
//! the model's `[unknowns]` (a thrust, a bank angle). They are solved
//! - exactly when linear (fraction-free elimination and simplification: MATLAB's `solve` +
//!   `simplify`);
//! - when an unknown angle `α` enters only as `u sin α` and `u cos α` for one other unknown
//!   `u` (a lift force and its bank angle), by solving for `S = u sin α`, `C = u cos α` and
//!   returning `u = √(S² + C²)`, `α = atan2(S, C)` (and the mirror solution `-u`, `α + π`);
//! - when some unknowns enter only through an even power (a conical pendulum's rate `ω` as
//!   `ω²`), by solving the linear system in those powers (the `powers` submodule) and taking
//!   the root: the positive one for a coordinate's rate or a declared non-negative range, the
//!   negative one for a non-positive range, both (listed) otherwise, each choice said in a note;
//! - otherwise numerically, by Newton's method from several starting points in the unknowns'
//!   ranges, keeping every distinct real solution.
//!
//! An unknown may be a free coordinate's `rate` or `initial` value (`rate = "omega"`): the
//! instant's substitution puts it into `F = m a` like any other unknown.
//!
//! `[[checks]]` turn a condition such as `abs(T) = mu*N` (slip) or `N_A = 0` (tip) into the
//! critical value of a parameter: symbolically when the condition is polynomial in a power of
//! the parameter, and numerically (root bracketing and bisection) over an optional range of a
//! coordinate, reporting the smallest and largest critical values and where they occur.

mod powers;

use crate::derive::{newton_equations, Equation};
use crate::model::{CoordinateKind, Model};
use pdyn_expr::linsolve::LinearError;
use pdyn_expr::{Func, Id, Node, Number, Pool, Program};
use rustc_hash::FxHashMap;

/// Knobs of [`solve_forces`].
#[derive(Clone, Debug, Default)]
pub struct ForcesOptions {
    /// The instant: values for `t` and for coordinates (`theta = 0`), overriding the model's
    /// initial values.
    pub at: Vec<(String, f64)>,
}

/// The critical value of a parameter for one check.
#[derive(Clone, Debug)]
pub struct CheckResult {
    /// Check name.
    pub name: String,
    /// The condition as written.
    pub condition: String,
    /// Parameter solved for.
    pub parameter: String,
    /// Exact critical values (may depend on the `over` variable).
    pub symbolic: Vec<Id>,
    /// Smallest critical value over the range (or at the instant), and where.
    pub min: Option<(f64, Option<f64>)>,
    /// Largest critical value over the range, and where.
    pub max: Option<(f64, Option<f64>)>,
    /// Name of the varied quantity.
    pub over: Option<String>,
    /// Unknown forces at the smallest critical value: `(name, value)` (their signs tell which
    /// way a block slides).
    pub forces_at_critical: Vec<(String, f64)>,
    /// Without `over`: every critical value in the range, ascending (a banked curve has a
    /// least and a greatest speed), each with the unknown forces there.
    pub critical: Vec<Critical>,
}

/// One critical value of a check and the forces there.
#[derive(Clone, Debug, PartialEq)]
pub struct Critical {
    /// The parameter's critical value.
    pub value: f64,
    /// Unknown forces there: `(name, value)`.
    pub forces: Vec<(String, f64)>,
}

/// What `pdyn forces` found.
#[derive(Clone, Debug)]
pub struct ForcesResult {
    /// The equations solved, `lhs = rhs`.
    pub equations: Vec<Equation>,
    /// Unknown names.
    pub unknowns: Vec<String>,
    /// Exact solutions, one per unknown (one set; see `numeric` for all real solutions).
    pub symbolic: Option<Vec<Id>>,
    /// Numeric solutions at the instant (several for nonlinear unknowns).
    pub numeric: Vec<Vec<f64>>,
    /// Critical values of the checks.
    pub checks: Vec<CheckResult>,
    /// How the instant was set and how the equations were solved.
    pub notes: Vec<String>,
    /// `t` and coordinate values at the instant.
    pub instant: Vec<(String, f64)>,
}

/// Why the forces of a prescribed motion could not be found.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum ForcesError {
    /// An `--at` name that is neither `t` nor a coordinate.
    UnknownInstantName {
        /// The name given.
        name: String,
        /// The model's coordinates.
        coordinates: Vec<String>,
    },
    /// The model declares no unknown force.
    NothingToSolve,
    /// An equation without unknowns that does not hold: a force is missing.
    EquationFails {
        /// The equation's label.
        label: String,
        /// The unknowns.
        unknowns: Vec<String>,
        /// Its two sides, simplified.
        lhs: String,
        /// See `lhs`.
        rhs: String,
    },
    /// Unknowns that no equation involves.
    Unused {
        /// Their names.
        unknowns: Vec<String>,
    },
    /// Fewer independent equations than unknowns.
    TooFewEquations {
        /// Independent equations.
        equations: usize,
        /// The unknowns.
        unknowns: Vec<String>,
    },
    /// The equations leave some unknowns free.
    Underdetermined {
        /// The free unknowns.
        free: Vec<String>,
    },
    /// An equation contradicts the others.
    Inconsistent {
        /// Its label.
        label: String,
    },
    /// A non-linear system without a real root in the unknowns' ranges.
    NoRealSolution,
    /// An unknown found through an even power of it, which came out negative (`ω² < 0`): no
    /// real value gives the prescribed motion.
    NoRealRoot {
        /// The unknown.
        unknown: String,
        /// The power it enters by.
        degree: i64,
        /// The power's exact value, as text.
        power: String,
        /// Its value.
        value: f64,
    },
    /// A `[[checks]]` entry needs the forces in closed form; they were found numerically.
    CheckNeedsClosedForm {
        /// The check's name.
        check: String,
    },
    /// The linear algebra failed otherwise.
    Linear(String),
    /// Something could not be evaluated (a name without a value).
    Compile {
        /// What (`check `slip``), or empty.
        what: String,
        /// Why.
        error: pdyn_expr::compile::CompileError,
    },
}

impl std::fmt::Display for ForcesError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ForcesError::UnknownInstantName { name, coordinates } => write!(
                f,
                "--at {name}: `{name}` is not t or a coordinate (coordinates: {})",
                coordinates.join(", ")
            ),
            ForcesError::NothingToSolve => f.write_str(
                "nothing to solve for: declare reactions ([[forces]] kind = \"reaction\" or \"friction\") or [unknowns]",
            ),
            ForcesError::EquationFails { label, unknowns, lhs, rhs } => write!(
                f,
                "`{label}` involves none of the unknowns ({}) and does not hold: {lhs} = {rhs}; a force is missing",
                unknowns.join(", ")
            ),
            ForcesError::Unused { unknowns } => {
                write!(f, "no equation involves {}", unknowns.join(", "))
            }
            ForcesError::TooFewEquations { equations, unknowns } => write!(
                f,
                "{equations} independent equations at most for {} unknowns ({}): add an equation (a friction law, a \
                 constraint) or make one of them known",
                unknowns.len(),
                unknowns.join(", ")
            ),
            ForcesError::Underdetermined { free } => write!(
                f,
                "the equations do not determine {}: more unknowns than independent equations",
                free.join(", ")
            ),
            ForcesError::Inconsistent { label } => write!(
                f,
                "`{label}` contradicts the other equations: the prescribed motion is impossible with these forces"
            ),
            ForcesError::NoRealSolution => {
                f.write_str("no real solution found in the unknowns' ranges")
            }
            ForcesError::NoRealRoot { unknown, degree, power, value } => write!(
                f,
                "{unknown}^{degree} = {power} = {value} is negative: no real {unknown} gives this \
                 motion with these parameters"
            ),
            ForcesError::CheckNeedsClosedForm { check } => write!(
                f,
                "check `{check}` needs the forces in closed form, and they were only found numerically"
            ),
            ForcesError::Linear(e) => f.write_str(e),
            ForcesError::Compile { what, error } if what.is_empty() => write!(f, "{error}"),
            ForcesError::Compile { what, error } => write!(f, "{what}: {error}"),
        }
    }
}

impl std::error::Error for ForcesError {}

fn compile_err(error: pdyn_expr::compile::CompileError) -> ForcesError {
    ForcesError::Compile {
        what: String::new(),
        error,
    }
}

/// Evaluates expressions numerically given values for leaves.
struct Env {
    leaves: Vec<Id>,
    values: Vec<f64>,
}

impl Env {
    fn eval(&self, p: &mut Pool, e: &[Id]) -> Result<Vec<f64>, ForcesError> {
        let prog = Program::compile(p, &self.leaves, e).map_err(compile_err)?;
        let mut ws = prog.workspace();
        let mut out = vec![0.0; e.len()];
        prog.eval(&self.values, &mut ws, &mut out);
        Ok(out)
    }
}

/// Solves for the forces of a prescribed motion and evaluates the model's checks.
pub fn solve_forces(model: &mut Model, opts: &ForcesOptions) -> Result<ForcesResult, ForcesError> {
    let mut notes = Vec::new();
    let over_ids: Vec<Id> = model
        .checks
        .iter()
        .filter_map(|c| c.over.as_ref().map(|o| o.0))
        .collect();
    let (_, newton, constraints) = newton_equations(model);
    model.materialize_initials();
    let p = &mut model.pool;

    // The instant: exact values of t and the free coordinates (value, rate, known acceleration).
    let mut t0 = 0.0;
    let mut at: FxHashMap<String, f64> = FxHashMap::default();
    for (k, v) in &opts.at {
        if k == "t" {
            t0 = *v;
        } else if model.coordinates.iter().any(|c| &c.name == k) {
            at.insert(k.clone(), *v);
        } else {
            let names: Vec<&str> = model.coordinates.iter().map(|c| c.name.as_str()).collect();
            return Err(ForcesError::UnknownInstantName {
                name: k.clone(),
                coordinates: names.iter().map(|s| s.to_string()).collect(),
            });
        }
    }
    let mut subs: FxHashMap<Id, Id> = FxHashMap::default();
    let mut instant = vec![("t".to_string(), t0)];
    let t = p.time();
    subs.insert(t, p.num(exact(t0)));
    let mut acc_unknowns = Vec::new();
    for (ci, c) in model.coordinates.iter().enumerate() {
        if let CoordinateKind::Free { initial, .. } = c.kind {
            let q = p.coord(c.sym, 0);
            let (ie, re) = model
                .initial_exprs
                .iter()
                .find(|(k, _, _)| *k == ci)
                .map_or((Pool::ZERO, Pool::ZERO), |&(_, a, b)| (a, b));
            let value = at.get(&c.name).copied();
            let in_unknowns = |key: &str| {
                let found = model.unknown_initials.iter();
                found
                    .filter(|u| u.coordinate == ci && u.key == key)
                    .map(|u| u.text.clone())
                    .next()
            };
            match (value, in_unknowns("initial")) {
                // The value is an unknown being solved for: no number to show.
                (None, Some(u)) => notes.push(format!(
                    "{} at the instant is `{u}`, solved for with the forces",
                    c.name
                )),
                _ => instant.push((c.name.clone(), value.unwrap_or(initial))),
            }
            if let Some(u) = in_unknowns("rate") {
                notes.push(format!(
                    "the rate of {} is `{u}`, solved for with the forces",
                    c.name
                ));
            }
            if !over_ids.contains(&q) {
                let v = match value {
                    Some(x) => p.num(exact(x)),
                    None => ie,
                };
                subs.insert(q, v);
            }
            let qd = p.coord(c.sym, 1);
            subs.insert(qd, re);
            let qdd = p.coord(c.sym, 2);
            match model.known_accelerations.iter().find(|(k, _)| *k == ci) {
                Some(&(_, a)) => {
                    subs.insert(qdd, a);
                }
                None => acc_unknowns.push((format!("{}''", c.name), qdd)),
            }
        }
    }
    // Known accelerations may themselves use the instant's values.
    let keys: Vec<Id> = subs.keys().copied().collect();
    for k in keys {
        let v = subs[&k];
        let v2 = p.subs(v, &subs);
        subs.insert(k, v2);
    }

    let mut unknown_names: Vec<String> = model.reactions.iter().map(|r| r.name.clone()).collect();
    let mut unknown_ids: Vec<Id> = model.reactions.iter().map(|r| r.id).collect();
    for u in &model.unknowns {
        unknown_names.push(u.name.clone());
        unknown_ids.push(u.id);
    }
    for (n, id) in &acc_unknowns {
        unknown_names.push(n.clone());
        unknown_ids.push(*id);
    }
    if unknown_ids.is_empty() {
        return Err(ForcesError::NothingToSolve);
    }

    let mut equations = Vec::new();
    let mut residuals = Vec::new();
    for e in newton.into_iter().chain(constraints) {
        let r = p.sub(e.lhs, e.rhs);
        let r = p.subs(r, &subs);
        if unknown_ids.iter().any(|&u| p.contains(r, u)) {
            residuals.push(r);
            let lhs = p.subs(e.lhs, &subs);
            let rhs = p.subs(e.rhs, &subs);
            equations.push(Equation {
                label: e.label,
                lhs: p.simplify(lhs),
                rhs: p.simplify(rhs),
            });
        } else if !p.provably_equal(r, Pool::ZERO) {
            let (l, r) = (p.simplify(e.lhs), p.simplify(e.rhs));
            return Err(ForcesError::EquationFails {
                label: e.label.clone(),
                unknowns: unknown_names.iter().map(|s| s.to_string()).collect(),
                lhs: p.to_text(l),
                rhs: p.to_text(r),
            });
        }
    }
    let unused: Vec<&str> = unknown_ids
        .iter()
        .zip(&unknown_names)
        .filter(|(u, _)| !residuals.iter().any(|&r| p.contains(r, **u)))
        .map(|(_, n)| n.as_str())
        .collect();
    if !unused.is_empty() {
        return Err(ForcesError::Unused {
            unknowns: unused.iter().map(|s| s.to_string()).collect(),
        });
    }
    if residuals.len() < unknown_ids.len() {
        return Err(ForcesError::TooFewEquations {
            equations: residuals.len(),
            unknowns: unknown_names.iter().map(|s| s.to_string()).collect(),
        });
    }

    // Numeric environment: parameters and the varied coordinates' values at the instant.
    let mut env = Env {
        leaves: model.parameters.iter().map(|q| q.id).collect(),
        values: model.parameters.iter().map(|q| q.value).collect(),
    };
    for &o in &over_ids {
        if let Node::Coord(s, 0) = p.node(o).clone() {
            if let Some(c) = model.coordinates.iter().find(|c| c.sym == s) {
                let v = instant
                    .iter()
                    .find(|(n, _)| *n == c.name)
                    .map_or(0.0, |x| x.1);
                env.leaves.push(o);
                env.values.push(v);
            }
        }
    }

    let (symbolic, numeric) = match p.linear_system(&residuals, &unknown_ids) {
        Ok(sys) => match p.solve_linear(&sys) {
            Ok(sol) => {
                notes.push("the equations are linear in the unknowns: solved exactly".into());
                let vals = env.eval(p, &sol)?;
                (Some(sol), vec![vals])
            }
            Err(LinearError::Underdetermined { free }) => {
                let names: Vec<String> = free.iter().map(|&f| p.to_text(f)).collect();
                return Err(ForcesError::Underdetermined { free: names });
            }
            Err(LinearError::Inconsistent { equation }) => {
                return Err(ForcesError::Inconsistent {
                    label: equations[equation].label.clone(),
                })
            }
            Err(e) => return Err(ForcesError::Linear(e.to_string())),
        },
        Err(LinearError::NotLinear { .. }) => {
            match polar(p, &residuals, &unknown_ids, &unknown_names, &mut notes)? {
                Some(sol) => {
                    let vals = env.eval(p, &sol)?;
                    // The mirror solution (-u, alpha + pi).
                    let mut all = vec![vals.clone()];
                    if let Some((ui, ai)) = notes_mirror(&unknown_names, &notes) {
                        let mut m = vals.clone();
                        m[ui] = -m[ui];
                        m[ai] += if m[ai] > 0.0 {
                            -std::f64::consts::PI
                        } else {
                            std::f64::consts::PI
                        };
                        all.push(m);
                    }
                    // Declared ranges (`alpha = { range = [...] }`) are honoured.
                    let declared: Vec<Option<(f64, f64)>> = unknown_ids
                        .iter()
                        .map(|&u| {
                            model
                                .unknowns
                                .iter()
                                .find(|q| q.id == u)
                                .and_then(|q| q.range)
                        })
                        .collect();
                    let before = all.len();
                    all.retain(|s| {
                        s.iter().zip(&declared).all(|(v, r)| {
                            r.is_none_or(|(lo, hi)| (lo - 1e-12..=hi + 1e-12).contains(v))
                        })
                    });
                    if all.is_empty() {
                        return Err(ForcesError::NoRealSolution);
                    }
                    if all.len() < before {
                        notes.push(format!(
                            "{} solution(s) outside the unknowns' declared ranges left out",
                            before - all.len()
                        ));
                    }
                    (Some(sol), all)
                }
                None => match powers::solve(p, &residuals, &unknown_ids) {
                    // Linear in a power of some unknowns (a rate squared): exact.
                    Some((sol, powers)) => {
                        let declared: Vec<Option<(f64, f64)>> = unknown_ids
                            .iter()
                            .map(|&u| {
                                let q = model.unknowns.iter().find(|q| q.id == u);
                                q.and_then(|q| q.range)
                            })
                            .collect();
                        let rate_of: Vec<Option<String>> = unknown_names
                            .iter()
                            .map(|n| {
                                let mut rates =
                                    model.unknown_initials.iter().filter(|u| u.key == "rate");
                                rates
                                    .find(|u| u.unknowns.contains(n))
                                    .map(|u| u.name.clone())
                            })
                            .collect();
                        let ctx = RootContext {
                            names: &unknown_names,
                            declared: &declared,
                            rate_of: &rate_of,
                        };
                        let (sol, all) = choose_roots(p, &env, &ctx, sol, &powers, &mut notes)?;
                        (Some(sol), all)
                    }
                    None => {
                        notes.push("nonlinear in the unknowns: solved numerically by Newton's method from several starts".into());
                        let ranges: Vec<(f64, f64)> = unknown_ids
                            .iter()
                            .map(|&u| {
                                model
                                    .unknowns
                                    .iter()
                                    .find(|q| q.id == u)
                                    .and_then(|q| q.range)
                                    .unwrap_or((-10.0, 10.0))
                            })
                            .collect();
                        let sols = newton_multistart(p, &residuals, &unknown_ids, &ranges, &env)?;
                        if sols.is_empty() {
                            return Err(ForcesError::NoRealSolution);
                        }
                        (None, sols)
                    }
                },
            }
        }
        Err(e) => return Err(ForcesError::Linear(e.to_string())),
    };

    let mut checks = Vec::new();
    for c in model.checks.clone() {
        checks.push(run_check(
            p,
            &model.parameters,
            &c,
            &unknown_ids,
            &unknown_names,
            symbolic.as_deref(),
            &subs,
        )?);
    }

    Ok(ForcesResult {
        equations,
        unknowns: unknown_names,
        symbolic,
        numeric,
        checks,
        notes,
        instant,
    })
}

/// What decides the sign of an unknown found through an even power.
struct RootContext<'a> {
    names: &'a [String],
    /// Declared `range`s of the unknowns.
    declared: &'a [Option<(f64, f64)>],
    /// The coordinate whose `rate` each unknown is, if any.
    rate_of: &'a [Option<String>],
}

/// Which root of `u^g = W` (g even) is kept.
enum Root {
    Positive,
    Negative,
    Both,
}

/// The signs of the roots of the unknowns found through even powers ([`powers`]): positive
/// for a declared non-negative range or a coordinate's rate (the other sign is the same motion
/// turning the other way), negative for a non-positive range, both otherwise (every
/// combination listed); each choice is said in a note. Returns the exact solution with the
/// chosen signs and the numeric solutions.
fn choose_roots(
    p: &mut Pool,
    env: &Env,
    ctx: &RootContext,
    mut sol: Vec<Id>,
    powers: &[powers::Power],
    notes: &mut Vec<String>,
) -> Result<(Vec<Id>, Vec<Vec<f64>>), ForcesError> {
    let values: Vec<Id> = powers.iter().map(|w| w.value).collect();
    let w_num = env.eval(p, &values)?;
    let mut both = Vec::new();
    for (w, &wv) in powers.iter().zip(&w_num) {
        let name = &ctx.names[w.index];
        let g = w.degree;
        let (power_text, root_text) = (p.to_text(w.value), p.to_text(sol[w.index]));
        notes.push(format!(
            "`{name}` enters only as {name}^{g}: solved exactly for {name}^{g} = {power_text}"
        ));
        if wv < 0.0 {
            return Err(ForcesError::NoRealRoot {
                unknown: name.clone(),
                degree: g,
                power: power_text,
                value: wv,
            });
        }
        if wv == 0.0 {
            continue;
        }
        let root = match (ctx.declared[w.index], &ctx.rate_of[w.index]) {
            (Some((lo, _)), _) if lo >= 0.0 => Root::Positive,
            (Some((_, hi)), _) if hi <= 0.0 => Root::Negative,
            (None, Some(_)) => Root::Positive,
            _ => Root::Both,
        };
        match root {
            Root::Positive => notes.push(match &ctx.rate_of[w.index] {
                Some(c) if ctx.declared[w.index].is_none() => format!(
                    "{name} = +{root_text} taken: {name} is the rate of {c}, and -{root_text} is \
                     the same motion turning the other way (with the same forces)"
                ),
                _ => format!("{name} = +{root_text} taken: its declared range is non-negative"),
            }),
            Root::Negative => {
                sol[w.index] = p.neg(sol[w.index]);
                notes.push(format!(
                    "{name} = -{root_text} taken: its declared range is non-positive"
                ));
            }
            Root::Both => {
                both.push(w.index);
                notes.push(format!(
                    "{name} = ±{root_text}: both roots solve the equations (the solution shows \
                     +; declare {name} = {{ range = [0, ...] }} to keep one)"
                ));
            }
        }
    }
    let mut all = vec![env.eval(p, &sol)?];
    for &i in &both {
        let flipped: Vec<Vec<f64>> = all
            .iter()
            .map(|s| {
                let mut m = s.clone();
                m[i] = -m[i];
                m
            })
            .collect();
        // The negative root first, as the numeric solve lists ascending starts.
        all = flipped.into_iter().chain(all).collect();
    }
    let before = all.len();
    all.retain(|s| {
        s.iter()
            .zip(ctx.declared)
            .all(|(v, r)| r.is_none_or(|(lo, hi)| (lo - 1e-12..=hi + 1e-12).contains(v)))
    });
    if all.is_empty() {
        return Err(ForcesError::NoRealSolution);
    }
    if all.len() < before {
        notes.push(format!(
            "{} solution(s) outside the unknowns' declared ranges left out",
            before - all.len()
        ));
    }
    Ok((sol, all))
}

fn exact(x: f64) -> Number {
    if x.fract() == 0.0 && x.abs() < 1e15 {
        Number::int(x as i64)
    } else {
        Number::Float(x)
    }
}

/// Index pair (u, alpha) recorded by [`polar`] in the notes.
fn notes_mirror(names: &[String], notes: &[String]) -> Option<(usize, usize)> {
    let n = notes.iter().find(|n| n.starts_with("polar:"))?;
    let mut it = n.trim_start_matches("polar:").split(',');
    let u = it.next()?;
    let a = it.next()?;
    Some((
        names.iter().position(|x| x == u)?,
        names.iter().position(|x| x == a)?,
    ))
}

/// The `u sin α`, `u cos α` substitution; returns the exact solution in the original unknowns.
fn polar(
    p: &mut Pool,
    residuals: &[Id],
    unknowns: &[Id],
    names: &[String],
    notes: &mut Vec<String>,
) -> Result<Option<Vec<Id>>, ForcesError> {
    for (ai, &alpha) in unknowns.iter().enumerate() {
        let sin_a = p.call(Func::Sin, &[alpha]);
        let cos_a = p.call(Func::Cos, &[alpha]);
        if !residuals
            .iter()
            .any(|&r| p.contains(r, sin_a) || p.contains(r, cos_a))
        {
            continue;
        }
        for (ui, &u) in unknowns.iter().enumerate() {
            if ui == ai {
                continue;
            }
            let s_sym = p.symbol(&format!("{}_sin_{}", names[ui], names[ai]), false);
            let c_sym = p.symbol(&format!("{}_cos_{}", names[ui], names[ai]), false);
            let (s, c) = (p.sym(s_sym), p.sym(c_sym));
            let mut m = FxHashMap::default();
            let s_over_u = p.div(s, u);
            let c_over_u = p.div(c, u);
            m.insert(sin_a, s_over_u);
            m.insert(cos_a, c_over_u);
            let eqs: Vec<Id> = residuals.iter().map(|&r| p.subs(r, &m)).collect();
            if eqs
                .iter()
                .any(|&e| p.contains(e, u) || p.contains(e, alpha))
            {
                continue;
            }
            let mut unk: Vec<Id> = unknowns.to_vec();
            unk[ui] = s;
            unk[ai] = c;
            let Ok(sys) = p.linear_system(&eqs, &unk) else {
                continue;
            };
            let Ok(sol) = p.solve_linear(&sys) else {
                continue;
            };
            let (sv, cv) = (sol[ui], sol[ai]);
            let s2 = p.powi(sv, 2);
            let c2 = p.powi(cv, 2);
            let r2 = p.add2(s2, c2);
            let r2 = p.simplify(r2);
            let mag = p.sqrt(r2);
            let ang = p.call(Func::Atan2, &[sv, cv]);
            let mut out = sol.clone();
            out[ui] = p.simplify(mag);
            out[ai] = p.simplify(ang);
            notes.push(format!(
                "`{}` enters only as {0}*sin({1}) and {0}*cos({1}): solved exactly for those products; \
                 {0} = ±sqrt(S^2 + C^2), {1} = atan2(S, C) (the other sign flips {0} and adds pi to {1})",
                names[ui], names[ai]
            ));
            notes.push(format!("polar:{},{}", names[ui], names[ai]));
            return Ok(Some(out));
        }
    }
    Ok(None)
}

/// Damped Newton from several starts; distinct real solutions.
fn newton_multistart(
    p: &mut Pool,
    residuals: &[Id],
    unknowns: &[Id],
    ranges: &[(f64, f64)],
    env: &Env,
) -> Result<Vec<Vec<f64>>, ForcesError> {
    let n = unknowns.len();
    let m = residuals.len();
    let mut leaves = env.leaves.clone();
    leaves.extend(unknowns);
    let jac = p.jacobian(residuals, unknowns);
    let mut outs = residuals.to_vec();
    outs.extend(jac);
    let prog = Program::compile(p, &leaves, &outs).map_err(compile_err)?;
    let mut ws = prog.workspace();
    let mut found: Vec<Vec<f64>> = Vec::new();
    let starts = 24;
    for k in 0..starts {
        let frac = (k as f64 + 0.5) / starts as f64;
        let mut x: Vec<f64> = ranges.iter().map(|(a, b)| a + (b - a) * frac).collect();
        let mut ok = false;
        for _ in 0..100 {
            let mut input = env.values.clone();
            input.extend(&x);
            let mut out = vec![0.0; m + m * n];
            prog.eval(&input, &mut ws, &mut out);
            let (f, j) = out.split_at(m);
            let norm: f64 = f.iter().map(|v| v * v).sum::<f64>().sqrt();
            if norm < 1e-10 * (1.0 + x.iter().map(|v| v.abs()).fold(0.0, f64::max)) {
                ok = true;
                break;
            }
            // Least-squares step: solve (J^T J) dx = -J^T f.
            let mut a = vec![0.0; n * n];
            let mut b = vec![0.0; n];
            for r in 0..m {
                for c1 in 0..n {
                    b[c1] -= j[r * n + c1] * f[r];
                    for c2 in 0..n {
                        a[c1 * n + c2] += j[r * n + c1] * j[r * n + c2];
                    }
                }
            }
            let mut perm = vec![0; n];
            if pdyn_expr::lu::lu_factor_in_place(&mut a, n, &mut perm).is_err() {
                break;
            }
            let mut w = vec![0.0; n];
            pdyn_expr::lu::lu_solve_in_place(&a, n, &perm, &mut b, &mut w);
            for (xi, d) in x.iter_mut().zip(&b) {
                *xi += d;
            }
            if x.iter().any(|v| !v.is_finite()) {
                break;
            }
        }
        let inside = x
            .iter()
            .zip(ranges)
            .all(|(v, (a, b))| *v >= *a - 1e-9 && *v <= *b + 1e-9);
        if ok
            && inside
            && !found.iter().any(|s| {
                s.iter()
                    .zip(&x)
                    .all(|(a, b)| (a - b).abs() <= 1e-6 * (1.0 + a.abs()))
            })
        {
            found.push(x);
        }
    }
    Ok(found)
}

/// Solves `c = 0` for the parameter `x`: `abs(a) = b` is squared; the numerator is expanded and
/// must be polynomial of degree 1 or 2 in a power `x^k`.
pub fn solve_for_parameter(p: &mut Pool, c: Id, x: Id) -> Vec<Id> {
    let c = square_abs(p, c);
    let c = p.simplify(c);
    let num = numerator(p, c);
    let num = p.expand(num);
    let terms: Vec<Id> = match p.node(num) {
        Node::Add(ts) => ts.to_vec(),
        _ => vec![num],
    };
    let mut coeffs: FxHashMap<i64, Vec<Id>> = FxHashMap::default();
    for tm in terms {
        let k = power_of(p, tm, x);
        let Some(k) = k else { return Vec::new() };
        let xk = p.powi(x, k);
        let coef = p.div(tm, xk);
        if p.contains(coef, x) {
            return Vec::new();
        }
        coeffs.entry(k).or_default().push(coef);
    }
    let mut ks: Vec<i64> = coeffs.keys().copied().filter(|&k| k > 0).collect();
    ks.sort_unstable();
    let Some(&kmax) = ks.last() else {
        return Vec::new();
    };
    let g = ks.iter().fold(0i64, |a, &b| gcd(a, b));
    if coeffs.keys().any(|&k| k < 0 || k % g != 0) {
        return Vec::new();
    }
    let d = kmax / g;
    let coef = |p: &mut Pool, k: i64| -> Id {
        match coeffs.get(&k) {
            Some(v) => p.add(v),
            None => Pool::ZERO,
        }
    };
    let c0 = coef(p, 0);
    let c1 = coef(p, g);
    let ws: Vec<Id> = match d {
        1 => {
            let w = p.div(c0, c1);
            vec![p.neg(w)]
        }
        2 => {
            let c2 = coef(p, 2 * g);
            let c1sq = p.powi(c1, 2);
            let four = p.int(4);
            let prod = p.mul(&[four, c2, c0]);
            let disc = p.sub(c1sq, prod);
            let disc = p.simplify(disc);
            let sq = p.sqrt(disc);
            let nc1 = p.neg(c1);
            let two = p.int(2);
            let den = p.mul2(two, c2);
            let a = p.add2(nc1, sq);
            let b = p.sub(nc1, sq);
            vec![p.div(a, den), p.div(b, den)]
        }
        _ => return Vec::new(),
    };
    let root = p.num(Number::ratio(1, g));
    ws.into_iter()
        .map(|w| {
            let w = p.simplify(w);
            let r = p.pow(w, root);
            p.simplify(r)
        })
        .collect()
}

fn gcd(a: i64, b: i64) -> i64 {
    let g = pdyn_expr::number::gcd(a.unsigned_abs().into(), b.unsigned_abs().into());
    g.min(i64::MAX as u128) as i64
}

/// `abs(a) - b` (either side) becomes `a^2 - b^2`.
fn square_abs(p: &mut Pool, c: Id) -> Id {
    if let Node::Add(ts) = p.node(c).clone() {
        for (i, &t) in ts.iter().enumerate() {
            let (k, rest) = p.split_coeff(t);
            if let Node::Call(Func::Abs, a) = p.node(rest).clone() {
                let others: Vec<Id> = ts
                    .iter()
                    .enumerate()
                    .filter(|(j, _)| *j != i)
                    .map(|(_, &x)| x)
                    .collect();
                let b = p.add(&others);
                let kn = p.num(k);
                let lhs = p.mul2(kn, a[0]);
                let l2 = p.powi(lhs, 2);
                let b2 = p.powi(b, 2);
                return p.sub(l2, b2);
            }
        }
    }
    c
}

/// Numerator of a product with negative powers (a sum is returned as is).
fn numerator(p: &mut Pool, e: Id) -> Id {
    match p.node(e).clone() {
        Node::Mul(fs) => {
            let keep: Vec<Id> = fs
                .iter()
                .copied()
                .filter(|&f| !matches!(p.node(f), Node::Pow(_, x) if p.as_num(*x).is_some_and(|n| n.is_negative())))
                .collect();
            p.mul(&keep)
        }
        Node::Pow(_, x) if p.as_num(x).is_some_and(|n| n.is_negative()) => Pool::ONE,
        _ => e,
    }
}

/// The exponent of `x` in the product `t` (0 if absent), `None` if `x` appears otherwise.
fn power_of(p: &Pool, t: Id, x: Id) -> Option<i64> {
    let factors: Vec<Id> = match p.node(t) {
        Node::Mul(fs) => fs.to_vec(),
        _ => vec![t],
    };
    let mut k = 0;
    for f in factors {
        if f == x {
            k += 1;
        } else if let Node::Pow(b, e) = p.node(f) {
            if *b == x {
                k += p.as_num(*e)?.as_integer()?;
            } else if p.contains(f, x) {
                return None;
            }
        } else if p.contains(f, x) {
            return None;
        }
    }
    Some(k)
}

fn run_check(
    p: &mut Pool,
    parameters: &[crate::model::Parameter],
    c: &crate::model::spec::CheckSpec,
    unknowns: &[Id],
    names: &[String],
    symbolic: Option<&[Id]>,
    instant: &FxHashMap<Id, Id>,
) -> Result<CheckResult, ForcesError> {
    let param = &parameters[c.solve_for];
    let sol = symbolic.ok_or_else(|| ForcesError::CheckNeedsClosedForm {
        check: c.name.clone(),
    })?;
    let mut m: FxHashMap<Id, Id> = unknowns.iter().copied().zip(sol.iter().copied()).collect();
    m.extend(instant.iter().map(|(k, v)| (*k, *v)));
    let cond = p.subs(c.condition, &m);
    let cond = p.subs(cond, instant);
    let exact = solve_for_parameter(p, cond, param.id);
    // Numeric: f(P, over) on a grid, smallest positive root for each sample.
    let mut leaves: Vec<Id> = parameters.iter().map(|q| q.id).collect();
    let mut base: Vec<f64> = parameters.iter().map(|q| q.value).collect();
    let over = c.over.clone();
    if let Some((o, _, _, _)) = &over {
        leaves.push(*o);
        base.push(0.0);
    }
    let involved: Vec<(String, Id)> = names
        .iter()
        .zip(unknowns)
        .zip(sol)
        .filter(|((_, &u), _)| p.contains(c.condition, u))
        .map(|((n, _), &s)| (n.clone(), s))
        .collect::<Vec<_>>()
        .into_iter()
        .map(|(n, s)| (n, p.subs(s, instant)))
        .collect();
    let mut outs = vec![cond];
    outs.extend(involved.iter().map(|(_, e)| *e));
    let prog = Program::compile(p, &leaves, &outs).map_err(|error| ForcesError::Compile {
        what: format!("check `{}`", c.name),
        error,
    })?;
    let mut ws = prog.workspace();
    let mut out = vec![0.0; outs.len()];
    let pi = c.solve_for;
    let (lo, hi) = c.range.unwrap_or((0.0, 100.0 * param.value.abs().max(1.0)));
    let samples: Vec<Option<f64>> = match &over {
        Some((_, _, a, b)) => (0..=360)
            .map(|k| Some(a + (b - a) * k as f64 / 360.0))
            .collect(),
        None => vec![None],
    };
    let mut eval = |pv: f64, ov: Option<f64>, out: &mut [f64]| {
        let mut input = base.clone();
        input[pi] = pv;
        if let Some(v) = ov {
            let last = input.len() - 1;
            input[last] = v;
        }
        prog.eval(&input, &mut ws, out);
    };
    let mut crit: Vec<(f64, Option<f64>)> = Vec::new();
    // Without `over`, every root in the range; with it, the first root at each sample.
    let all_roots = over.is_none();
    for ov in samples {
        let grid = 2000;
        let mut prev: Option<(f64, f64)> = None;
        for k in 0..=grid {
            let pv = lo + (hi - lo) * k as f64 / grid as f64;
            eval(pv, ov, &mut out);
            let f = out[0];
            if !f.is_finite() {
                prev = None;
                continue;
            }
            if f == 0.0 {
                crit.push((pv, ov));
                if all_roots {
                    prev = None;
                    continue;
                }
                break;
            }
            if let Some((pp, pf)) = prev {
                if pf.signum() != f.signum() {
                    // Bisection to machine precision.
                    let (mut a, mut b, mut fa) = (pp, pv, pf);
                    for _ in 0..200 {
                        let mid = 0.5 * (a + b);
                        eval(mid, ov, &mut out);
                        if out[0].signum() == fa.signum() {
                            a = mid;
                            fa = out[0];
                        } else {
                            b = mid;
                        }
                        if (b - a).abs() <= 1e-15 * b.abs().max(1e-300) {
                            break;
                        }
                    }
                    // A sign change through a pole (a denominator crossing zero) is not a
                    // root: there |f| grows instead of vanishing.
                    let root = 0.5 * (a + b);
                    eval(root, ov, &mut out);
                    if out[0].abs() > 1e-6 * pf.abs().max(f.abs()) {
                        prev = Some((pv, f));
                        continue;
                    }
                    crit.push((root, ov));
                    if !all_roots {
                        break;
                    }
                }
            }
            prev = Some((pv, f));
        }
    }
    let min = crit.iter().copied().min_by(|a, b| a.0.total_cmp(&b.0));
    let max = crit.iter().copied().max_by(|a, b| a.0.total_cmp(&b.0));
    let mut forces_at = |pv: f64, ov: Option<f64>| {
        eval(pv, ov, &mut out);
        involved
            .iter()
            .enumerate()
            .map(|(k, (n, _))| (n.clone(), out[1 + k]))
            .collect::<Vec<_>>()
    };
    let forces_at_critical = min.map_or(Vec::new(), |(pv, ov)| forces_at(pv, ov));
    let mut critical: Vec<Critical> = if all_roots {
        crit.iter()
            .map(|&(value, _)| Critical {
                value,
                forces: forces_at(value, None),
            })
            .collect()
    } else {
        Vec::new()
    };
    critical.sort_by(|a, b| a.value.total_cmp(&b.value));
    Ok(CheckResult {
        name: c.name.clone(),
        condition: c.text.clone(),
        parameter: param.name.clone(),
        symbolic: exact,
        min,
        max,
        over: over.map(|o| o.1),
        forces_at_critical,
        critical,
    })
}
