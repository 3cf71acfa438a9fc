//! The computation of `pdyn dsolve` (and of Python's `pdyn.dsolve`): closed-form solution of
//! linear constant-coefficient ODEs and systems, and the 1-D rules of straight-line motion
//! (`a(v) = -c*v^2`). The command prints a [`DsolveResult`]; Python converts it.

use crate::args::{idents, positive_parameters, split_top, subs_all};
use crate::Error;
use pdyn_expr::{FreeScope, Id, Node, Pool, SymId, Value};
use pdyn_mech::dsolve::rules::{self, Estimate, Given, RuleSolution};
use pdyn_mech::dsolve::{solve_with, ClosedForm, DsolveError, InitialCondition, When};

/// What to solve, as the text of the command's arguments.
#[derive(Clone, Debug, Default)]
pub struct DsolveInput {
    /// Equations `lhs = rhs` in coordinates written `x'`, `x''` or `x(t)`.
    pub equations: Vec<String>,
    /// Initial conditions, comma separated: `x(0)=x0, x'(0)=v0` (all at the same time).
    pub ic: Option<String>,
    /// A 1-D rule of straight-line motion instead of equations: `a(t) = ...`, `v(t) = ...`,
    /// `a(v) = ...` or `a(x) = ...`.
    pub rule: Option<String>,
    /// Parameter values substituted before solving, `name=value`.
    pub set: Vec<String>,
    /// Times (or values of a rule's independent variable) to evaluate the solution at.
    pub at: Vec<String>,
    /// A condition whose first instant t ≥ 0 is wanted, e.g. `y = 0`.
    pub when: Option<String>,
    /// Parameters that may be negative or zero; the others are assumed positive.
    pub signed: Vec<String>,
}

/// The first instant a condition holds (`when`).
#[derive(Clone, Debug)]
pub struct WhenResult {
    /// The condition as given.
    pub condition: String,
    /// The instant and the state there.
    pub found: When,
}

/// The solution of equations.
#[derive(Debug)]
pub struct EquationsSolution {
    /// The closed form: coordinates and cases.
    pub closed_form: ClosedForm,
    /// The parameters assumed positive (those without a value).
    pub assumed_positive: Vec<String>,
    /// The times of `at`, evaluated.
    pub times: Vec<f64>,
    /// Per case, per time: `[q1, q1', q2, q2', ...]` (empty without times).
    pub table: Vec<Vec<Vec<f64>>>,
    /// The instant of `when`.
    pub when: Option<WhenResult>,
}

/// The relations of a 1-D rule.
#[derive(Debug)]
pub struct RuleResult {
    /// The rule as given.
    pub rule: String,
    /// Its independent variable (`t`, `v` or `x`).
    pub variable: &'static str,
    /// The derived quantities (`v(t)`, `x(t)`, ...).
    pub solution: RuleSolution,
    /// The points of `at`, evaluated.
    pub points: Vec<f64>,
    /// Per quantity, per point: the value, or why it has none.
    pub values: Vec<Vec<Result<Estimate, DsolveError>>>,
    /// The parameters assumed positive.
    pub assumed_positive: Vec<String>,
}

/// What `pdyn dsolve` computes.
#[derive(Debug)]
pub enum Solved {
    /// Equations with their initial conditions.
    Equations(EquationsSolution),
    /// A rule of straight-line motion.
    Rule(RuleResult),
}

/// Everything `pdyn dsolve` computes; expressions are ids in `pool`.
#[derive(Debug)]
pub struct DsolveResult {
    /// The pool the expressions live in.
    pub pool: Pool,
    /// The solution.
    pub solved: Solved,
}

/// One parsed initial condition: name, derivative order, time text, value text.
struct RawIc {
    name: String,
    order: u8,
    time: String,
    value: String,
}

fn parse_ic(item: &str) -> Result<RawIc, Error> {
    let (lhs, value) = item.split_once('=').ok_or_else(|| {
        Error::argument("--ic", format!("--ic: expected `x(0)=value`, got `{item}`"))
    })?;
    let lhs = lhs.trim();
    let (head, time) = match lhs.find('(') {
        Some(p) if lhs.ends_with(')') => (&lhs[..p], lhs[p + 1..lhs.len() - 1].trim()),
        _ => (lhs, "0"),
    };
    let order = head.chars().rev().take_while(|&c| c == '\'').count();
    let name = head[..head.len() - order].trim();
    let ok = name
        .chars()
        .next()
        .is_some_and(|c| c.is_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_alphanumeric() || c == '_');
    if !ok {
        return Err(Error::argument(
            "--ic",
            format!("--ic: `{lhs}` is not of the form `x(0)`, `x'(0)` or `x''(t0)`"),
        ));
    }
    if value.trim().is_empty() {
        return Err(Error::argument(
            "--ic",
            format!("--ic: `{item}` has no value after `=`"),
        ));
    }
    Ok(RawIc {
        name: name.to_string(),
        order: order as u8,
        time: time.to_string(),
        value: value.trim().to_string(),
    })
}

/// Parsed `--set` values: (symbol expression, value expression).
fn parse_set(pool: &mut Pool, set: &[String]) -> Result<Vec<(Id, Id)>, Error> {
    let mut out = Vec::new();
    for kv in set {
        let (k, v) = kv.split_once('=').ok_or_else(|| {
            Error::argument("--set", format!("--set: expected name=value, got `{kv}`"))
        })?;
        let k = k.trim();
        if !k.chars().all(|c| c.is_alphanumeric() || c == '_') || k.is_empty() {
            return Err(Error::argument(
                "--set",
                format!("--set: `{k}` is not a parameter name"),
            ));
        }
        let val = pool
            .parse_scalar(v.trim())
            .map_err(|e| Error::expr("--set", v.trim(), e))?;
        let sym = pool.var(k);
        out.push((sym, val));
    }
    Ok(out)
}

fn eval_const(pool: &mut Pool, e: Id, what: &str) -> Result<f64, Error> {
    pool.eval_const(e)
        .map_err(|err| Error::argument(what, format!("{what}: {err}; give it a value with --set")))
}

/// Solves what `a` gives: equations with initial conditions, or a rule.
pub fn dsolve(a: &DsolveInput) -> Result<DsolveResult, Error> {
    if let Some(rule) = &a.rule {
        if !a.equations.is_empty() {
            return Err(Error::argument(
                "",
                "give either equations or --rule, not both",
            ));
        }
        return run_rule(a, rule);
    }
    if a.equations.is_empty() {
        return Err(Error::argument(
            "",
            "no equation given; e.g. pdyn dsolve \"x'' + x = 0\" --ic \"x(0)=1, x'(0)=0\"",
        ));
    }
    let mut pool = Pool::new();
    // Pass 1: learn coordinates and parameter names.
    let mut scope = FreeScope::default();
    let mut asts = Vec::new();
    for (i, src) in a.equations.iter().enumerate() {
        let origin = format!("<equation {}>", i + 1);
        let (l, r) =
            pdyn_expr::syntax::parse_equation(src).map_err(|e| Error::expr(&origin, src, e))?;
        scope.learn(&l);
        if let Some(r) = &r {
            scope.learn(r);
        }
        asts.push((l, r));
    }
    let ics: Vec<RawIc> = match &a.ic {
        Some(s) => split_top(s)
            .iter()
            .map(|item| parse_ic(item))
            .collect::<Result<_, _>>()?,
        None => Vec::new(),
    };
    for ic in &ics {
        scope.coordinates.insert(ic.name.clone());
    }
    let mut names = Vec::new();
    for (l, r) in &asts {
        idents(l, &mut names);
        if let Some(r) = r {
            idents(r, &mut names);
        }
    }
    let params = positive_parameters(names, |n| scope.coordinates.contains(n), &a.signed, &a.set);
    scope.positive = params.iter().cloned().collect();
    // Pass 2: lower.
    let mut eqs = Vec::new();
    for (i, src) in a.equations.iter().enumerate() {
        let origin = format!("<equation {}>", i + 1);
        let v = pool
            .parse_equation_in(src, &mut scope)
            .map_err(|e| Error::expr(&origin, src, e))?;
        match v {
            Value::Scalar(s) => eqs.push(s),
            Value::Vector(c) => eqs.extend(c.into_iter().filter(|&x| x != Pool::ZERO)),
        }
    }
    // Coordinates in order of first appearance.
    let mut coords: Vec<SymId> = Vec::new();
    for &e in &eqs {
        for n in pool.topo_order(&[e]) {
            if let Node::Coord(s, _) = pool.node(n) {
                if !coords.contains(s) {
                    coords.push(*s);
                }
            }
        }
    }
    if coords.is_empty() {
        return Err(Error::argument(
            "",
            "the equations contain no coordinate: write the unknown function as x', x'' or x(t)",
        ));
    }
    let set = parse_set(&mut pool, &a.set)?;
    let eqs: Vec<Id> = eqs.iter().map(|&e| subs_all(&mut pool, e, &set)).collect();
    let mut t0: Option<(String, Id)> = None;
    let mut initial = Vec::new();
    for ic in &ics {
        let coord = pool.symbol(&ic.name, false);
        if !coords.contains(&coord) {
            return Err(Error::argument(
                "--ic",
                format!(
                    "--ic: `{}` does not appear in the equations (coordinates: {})",
                    ic.name,
                    coords
                        .iter()
                        .map(|&c| pool.name(c).to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
        let time = pool
            .parse_in(&ic.time, &mut scope)
            .map_err(|e| Error::expr("--ic", &ic.time, e))?;
        let Value::Scalar(time) = time else {
            return Err(Error::argument(
                "--ic",
                format!("--ic: the time `{}` is a vector", ic.time),
            ));
        };
        let time = subs_all(&mut pool, time, &set);
        match &t0 {
            None => t0 = Some((ic.time.clone(), time)),
            Some((txt, prev)) if *prev != time => {
                return Err(Error::argument(
                    "--ic",
                    format!(
                        "--ic: all initial conditions must be at the same time (`{txt}` and `{}`)",
                        ic.time
                    ),
                ))
            }
            _ => {}
        }
        let v = pool
            .parse_in(&ic.value, &mut scope)
            .map_err(|e| Error::expr("--ic", &ic.value, e))?;
        let Value::Scalar(v) = v else {
            return Err(Error::argument(
                "--ic",
                format!("--ic: the value `{}` is a vector", ic.value),
            ));
        };
        initial.push(InitialCondition {
            coord,
            order: ic.order,
            value: subs_all(&mut pool, v, &set),
        });
    }
    let t0 = t0.map_or(Pool::ZERO, |(_, id)| id);
    let cf = solve_with(&mut pool, &eqs, &coords, &initial, t0).map_err(|error| Error::Dsolve {
        context: String::new(),
        error,
    })?;
    let assumed: Vec<String> = params
        .iter()
        .filter(|p| {
            !a.set
                .iter()
                .any(|kv| kv.split('=').next().map(str::trim) == Some(p))
        })
        .cloned()
        .collect();
    let times = eval_times(&mut pool, &a.at)?;
    let table = match stable_table(&mut pool, &cf, (&eqs, &coords, &initial, t0), &times) {
        Some(rows) => vec![rows],
        None => evaluate(&mut pool, &cf, &times)?,
    };
    let when = match &a.when {
        Some(w) => Some(when(&mut pool, &cf, w, &mut scope, &set)?),
        None => None,
    };
    Ok(DsolveResult {
        pool,
        solved: Solved::Equations(EquationsSolution {
            closed_form: cf,
            assumed_positive: assumed,
            times,
            table,
            when,
        }),
    })
}

/// `--when "lhs = rhs"`: parsed here, found by [`pdyn_mech::dsolve::when`].
fn when(
    pool: &mut Pool,
    cf: &ClosedForm,
    src: &str,
    scope: &mut FreeScope,
    set: &[(Id, Id)],
) -> Result<WhenResult, Error> {
    let eq = match pool
        .parse_equation_in(src, scope)
        .map_err(|e| Error::expr("--when", src, e))?
    {
        Value::Scalar(s) => s,
        Value::Vector(_) => {
            return Err(Error::argument(
                "--when",
                "--when: the condition must be a scalar equation",
            ))
        }
    };
    let eq = subs_all(pool, eq, set);
    let found = pdyn_mech::dsolve::when(pool, cf, eq).map_err(|error| {
        let context = match error {
            pdyn_mech::dsolve::DsolveError::SeveralCases => "--when".to_string(),
            _ => format!("--when {src}"),
        };
        Error::Dsolve { context, error }
    })?;
    Ok(WhenResult {
        condition: src.to_string(),
        found,
    })
}

fn eval_times(pool: &mut Pool, at: &[String]) -> Result<Vec<f64>, Error> {
    at.iter()
        .map(|s| {
            let e = pool
                .parse_scalar(s.trim())
                .map_err(|e| Error::expr("--at", s.trim(), e))?;
            eval_const(pool, e, &format!("--at {s}"))
        })
        .collect()
}

/// The equations, their coordinates, initial conditions and initial time.
type Problem<'a> = (&'a [Id], &'a [SymId], &'a [InitialCondition], Id);

/// Per time, `[q1, q1', q2, q2', ...]` evaluated stably (`exp(𝒜 t) z(0)`, see
/// [`pdyn_mech::dsolve::propagator`]) when everything is a number, there is one case and the
/// initial conditions are at `t = 0`: the formula `(sin Ωt − (Ω/ω) sin ωt)/(ω² − Ω²)` loses
/// its digits as `Ω → ω`. `None` otherwise (the formula is evaluated).
fn stable_table(
    pool: &mut Pool,
    cf: &ClosedForm,
    (eqs, coords, initial, t0): Problem,
    times: &[f64],
) -> Option<Vec<Vec<f64>>> {
    if times.is_empty() || cf.cases.len() != 1 || t0 != Pool::ZERO {
        return None;
    }
    let pairs: Vec<(Id, Id)> = initial
        .iter()
        .map(|ic| (pool.coord(ic.coord, ic.order), ic.value))
        .collect();
    let prop = pdyn_mech::dsolve::propagator(pool, eqs, coords, &pairs).ok()?;
    // The propagator's coordinates are the equations' in the same order as the closed form's.
    if cf.coords != coords {
        return None;
    }
    let width = 2 * coords.len();
    Some(
        prop.sample(times)
            .chunks_exact(width)
            .map(<[f64]>::to_vec)
            .collect(),
    )
}

/// Per case, per time: `[q1, q1', q2, q2', ...]`.
fn evaluate(pool: &mut Pool, cf: &ClosedForm, times: &[f64]) -> Result<Vec<Vec<Vec<f64>>>, Error> {
    if times.is_empty() {
        return Ok(Vec::new());
    }
    let mut all = Vec::new();
    for ci in 0..cf.cases.len() {
        let prog = cf.compile(pool, ci, &[]).map_err(|e| {
            Error::argument(
                "--at",
                format!("--at: {e}; give the parameters values with --set"),
            )
        })?;
        let mut ws = prog.workspace();
        let mut rows = Vec::new();
        for &t in times {
            let mut out = vec![0.0; prog.n_outputs()];
            prog.eval(&[t], &mut ws, &mut out);
            rows.push(out);
        }
        all.push(rows);
    }
    Ok(all)
}

/// `--rule "a(v) = ..."`.
fn run_rule(a: &DsolveInput, rule: &str) -> Result<DsolveResult, Error> {
    let (lhs, rhs) = rule
        .split_once('=')
        .ok_or_else(|| Error::argument("--rule", format!("--rule: expected `a(t) = ...`, `v(t) = ...`, `a(v) = ...` or `a(x) = ...`, got `{rule}`")))?;
    let given = match lhs.replace(' ', "").as_str() {
        "a(t)" => Given::AccelerationOfTime,
        "v(t)" => Given::VelocityOfTime,
        "a(v)" => Given::AccelerationOfSpeed,
        "a(x)" => Given::AccelerationOfPosition,
        other => {
            return Err(Error::argument(
                "--rule",
                format!("--rule: the left side `{other}` must be a(t), v(t), a(v) or a(x)"),
            ))
        }
    };
    let mut pool = Pool::new();
    let src = rhs.trim();
    let ast = pdyn_expr::syntax::parse(src).map_err(|e| Error::expr("--rule", src, e))?;
    let mut names = Vec::new();
    idents(&ast, &mut names);
    let indep = given.variable();
    let params = positive_parameters(names, |n| n == indep, &a.signed, &a.set);
    let mut scope = FreeScope {
        positive: params.iter().cloned().collect(),
        ..Default::default()
    };
    let law = match pdyn_expr::lower::lower(&mut pool, &ast, &mut scope)
        .map_err(|e| Error::expr("--rule", src, e))?
    {
        Value::Scalar(s) => s,
        Value::Vector(_) => {
            return Err(Error::argument(
                "--rule",
                "--rule: the law must be a scalar",
            ))
        }
    };
    let set = parse_set(&mut pool, &a.set)?;
    let law = subs_all(&mut pool, law, &set);
    let mut x0 = Pool::ZERO;
    let mut v0 = Pool::ZERO;
    if let Some(s) = &a.ic {
        for item in split_top(s) {
            let ic = parse_ic(&item)?;
            if ic.time != "0" {
                return Err(Error::argument(
                    "--ic",
                    format!("--ic: the rules start at t = 0 (got `{}`)", ic.time),
                ));
            }
            let v = pool
                .parse_scalar(&ic.value)
                .map_err(|e| Error::expr("--ic", &ic.value, e))?;
            let v = subs_all(&mut pool, v, &set);
            match (ic.name.as_str(), ic.order) {
                ("x", 0) => x0 = v,
                ("v", 0) | ("x", 1) => v0 = v,
                _ => {
                    return Err(Error::argument(
                        "--ic",
                        format!("--ic: the rules take x(0) and v(0), not `{}`", item.trim()),
                    ))
                }
            }
        }
    }
    let sol = rules::solve_rule(&mut pool, given, law, x0, v0).map_err(|error| Error::Dsolve {
        context: String::new(),
        error,
    })?;
    let points = eval_times(&mut pool, &a.at)?;
    let mut evaluated = Vec::new();
    for q in &sol.quantities {
        let mut vals = Vec::new();
        for &s in &points {
            vals.push(rules::evaluate(&mut pool, q, s));
        }
        evaluated.push(vals);
    }
    Ok(DsolveResult {
        pool,
        solved: Solved::Rule(RuleResult {
            rule: rule.to_string(),
            variable: indep,
            solution: sol,
            points,
            values: evaluated,
            assumed_positive: params,
        }),
    })
}
