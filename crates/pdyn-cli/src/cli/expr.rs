//! Expression commands: `simplify`, `diff`, `solve`, `eval`.

use super::{value_json, Format};
use clap::Args;
use pdyn::Error;
use pdyn_expr::{ExprError, FreeScope, Id, Pool, Program, Value};
use serde_json::json;

/// Options shared by the expression commands.
#[derive(Args, Debug, Clone)]
pub struct Common {
    /// Names that are functions of time (also inferred from `x'` and `x(t)`), comma separated.
    #[arg(long, value_delimiter = ',')]
    coords: Vec<String>,
    /// Names declared strictly positive (lets `sqrt(m^2)` become `m`), comma separated.
    #[arg(long, value_delimiter = ',')]
    positive: Vec<String>,
    /// Output notation.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    format: Format,
    /// Machine-readable output.
    #[arg(long)]
    json: bool,
}

/// `pdyn simplify`.
#[derive(Args, Debug)]
pub struct SimplifyArgs {
    /// The expression, e.g. "sin(x)^2 + cos(x)^2" or a vector "[a, b, c]".
    #[arg(allow_hyphen_values = true)]
    expr: String,
    /// Expand products and powers instead of simplifying.
    #[arg(long)]
    expand: bool,
    #[command(flatten)]
    common: Common,
}

/// `pdyn diff`.
#[derive(Args, Debug)]
pub struct DiffArgs {
    /// The expression, e.g. "[R*cos(th(t)), R*sin(th(t)), 0]".
    #[arg(allow_hyphen_values = true)]
    expr: String,
    /// Variable: a symbol, a coordinate rate such as `x'`, or `t` for the total time derivative.
    #[arg(long, default_value = "t")]
    wrt: String,
    /// Number of times to differentiate.
    #[arg(short = 'n', long, default_value_t = 1)]
    times: usize,
    /// Simplify the result.
    #[arg(long)]
    simplify: bool,
    #[command(flatten)]
    common: Common,
}

/// `pdyn solve`.
#[derive(Args, Debug)]
pub struct SolveArgs {
    /// Equations `lhs = rhs` (or `lhs == rhs`), one per argument. An equation starting with
    /// `-` goes after `--`: `pdyn solve --for T,N -- "-T*cos(a) = m*x"`.
    #[arg(required = true)]
    equations: Vec<String>,
    /// Unknowns to solve for, comma separated.
    #[arg(long = "for", value_delimiter = ',', required = true)]
    unknowns: Vec<String>,
    /// Every root of one equation in an interval, numerically: `--in x=0..10` (bounds may
    /// be expressions: `E=0..2*pi`). Each root is certified by a sign change (or, for a
    /// double root, a residual bound).
    #[arg(long = "in", value_name = "NAME=LO..HI")]
    interval: Option<String>,
    /// Sampling steps of the `--in` interval: roots closer than a step may be missed in pairs.
    #[arg(long, default_value_t = pdyn_mech::numeric_roots::DEFAULT_SAMPLES)]
    samples: usize,
    /// A start for Newton's method on a system, `--start x=1,y=2` (repeat for several).
    #[arg(long = "start", value_name = "NAME=VALUE,...")]
    starts: Vec<String>,
    /// Values of the other names of the equations, `--at e=0.3,M=1` (numeric roots only).
    #[arg(long, value_delimiter = ',')]
    at: Vec<String>,
    #[command(flatten)]
    common: Common,
}

/// `pdyn eval`.
#[derive(Args, Debug)]
pub struct EvalArgs {
    /// The expression.
    #[arg(allow_hyphen_values = true)]
    expr: String,
    /// Values, e.g. `--at x=1,y=2.5`.
    #[arg(long, value_delimiter = ',')]
    at: Vec<String>,
    #[command(flatten)]
    common: Common,
}

fn scope(c: &Common) -> FreeScope {
    let mut s = FreeScope::with_coordinates(c.coords.iter().map(String::as_str));
    s.positive = c.positive.iter().cloned().collect();
    s
}

fn parse(pool: &mut Pool, src: &str, c: &Common, origin: &str) -> Result<Value, Error> {
    let ast = pdyn_expr::syntax::parse(src).map_err(|e| Error::expr(origin, src, e))?;
    let mut sc = scope(c);
    sc.learn(&ast);
    pdyn_expr::lower::lower(pool, &ast, &mut sc).map_err(|e| Error::expr(origin, src, e))
}

fn show_value(pool: &Pool, v: Value, f: Format) -> String {
    f.show_value(pool, v)
}

/// A result that divides by zero (simplification can reveal a zero denominator that lowering
/// did not see: `1/(sin(x)^2 + cos(x)^2 - 1)`) is an error located at the whole expression.
fn refuse_division_by_zero(pool: &Pool, v: Value, src: &str) -> Result<(), Error> {
    let parts = match v {
        Value::Scalar(x) => vec![x],
        Value::Vector(c) => c.to_vec(),
    };
    if parts.iter().any(|&x| pool.divides_by_zero(x)) {
        let e = ExprError::new(
            0..src.len(),
            "division by zero: once simplified, a denominator of this expression is zero",
        )
        .with_help("the expression is undefined everywhere; check the denominator");
        return Err(Error::expr("<expr>", src, e));
    }
    Ok(())
}

/// `pdyn simplify EXPR`.
pub fn simplify(a: SimplifyArgs) -> Result<String, Error> {
    let mut pool = Pool::new();
    let v = parse(&mut pool, &a.expr, &a.common, "<expr>")?;
    let r = if a.expand {
        // Asked for: an expansion over the limit is an error, never the input returned as is.
        let budget = |error| Error::Budget {
            context: "simplify --expand".into(),
            error,
        };
        match v {
            Value::Scalar(x) => Value::Scalar(pool.try_expand(x).map_err(budget)?),
            Value::Vector(c) => {
                let mut out = c;
                for (o, x) in out.iter_mut().zip(c) {
                    *o = pool.try_expand(x).map_err(budget)?;
                }
                Value::Vector(out)
            }
        }
    } else {
        v.map(|x| {
            let e = pool.expand(x);
            pool.simplify(e)
        })
    };
    refuse_division_by_zero(&pool, r, &a.expr)?;
    Ok(if a.common.json {
        format!(
            "{}\n",
            json!({"input": a.expr, "result": value_json(&pool, r)})
        )
    } else {
        format!("{}\n", show_value(&pool, r, a.common.format))
    })
}

/// `pdyn diff EXPR --wrt VAR`.
pub fn diff(a: DiffArgs) -> Result<String, Error> {
    let mut pool = Pool::new();
    let v = parse(&mut pool, &a.expr, &a.common, "<expr>")?;
    let var = if a.wrt == "t" {
        None
    } else {
        match parse(&mut pool, &a.wrt, &a.common, "--wrt")? {
            Value::Scalar(s) if is_leaf(&pool, s) => Some(s),
            _ => {
                return Err(Error::argument(
                    "--wrt",
                    format!(
                    "--wrt: `{}` is not a variable; use a symbol, a coordinate (x, x', x'') or t",
                    a.wrt
                ),
                ))
            }
        }
    };
    // Under a budget: `-n 100000` either finds the derivative (periodic or vanishing ones are
    // cheap) or stops with an error naming the limit, never runs for ever.
    let budget = |error| Error::Budget {
        context: format!("diff -n {}", a.times),
        error,
    };
    let r = match v {
        Value::Scalar(x) => Value::Scalar(pool.try_derivative_n(x, var, a.times).map_err(budget)?),
        Value::Vector(c) => {
            let mut out = c;
            for (o, x) in out.iter_mut().zip(c) {
                *o = pool.try_derivative_n(x, var, a.times).map_err(budget)?;
            }
            Value::Vector(out)
        }
    };
    let mut r = r;
    if a.simplify {
        r = r.map(|x| pool.simplify(x));
    }
    Ok(if a.common.json {
        format!(
            "{}\n",
            json!({"input": a.expr, "wrt": a.wrt, "times": a.times, "result": value_json(&pool, r)})
        )
    } else {
        format!("{}\n", show_value(&pool, r, a.common.format))
    })
}

fn is_leaf(pool: &Pool, id: Id) -> bool {
    matches!(
        pool.node(id),
        pdyn_expr::Node::Sym(_) | pdyn_expr::Node::Coord(..) | pdyn_expr::Node::Time
    )
}

/// `pdyn solve EQ... --for X,Y`.
pub fn solve(a: SolveArgs) -> Result<String, Error> {
    let mut pool = Pool::new();
    let mut sc = scope(&a.common);
    let mut eqs = Vec::new();
    for (i, src) in a.equations.iter().enumerate() {
        let origin = format!("<equation {}>", i + 1);
        let (l, r) =
            pdyn_expr::syntax::parse_equation(src).map_err(|e| Error::expr(&origin, src, e))?;
        sc.learn(&l);
        if let Some(r) = &r {
            sc.learn(r);
        }
        let v = pool
            .parse_equation_in(src, &mut sc)
            .map_err(|e| Error::expr(&origin, src, e))?;
        match v {
            Value::Scalar(s) => eqs.push(s),
            Value::Vector(c) => eqs.extend(c.into_iter().filter(|&x| x != Pool::ZERO)),
        }
    }
    let mut unknowns = Vec::new();
    for u in &a.unknowns {
        match parse(&mut pool, u, &a.common, "--for")? {
            Value::Scalar(s) if is_leaf(&pool, s) => unknowns.push(s),
            _ => {
                return Err(Error::argument(
                    "--for",
                    format!("--for: `{u}` is not a variable name"),
                ))
            }
        }
    }
    if a.interval.is_some() || !a.starts.is_empty() {
        let request = super::roots::Request {
            unknown_names: &a.unknowns,
            interval: a.interval.as_deref(),
            samples: a.samples,
            starts: &a.starts,
            at: &a.at,
            json: a.common.json,
        };
        return super::roots::solve_numerically(&mut pool, &eqs, &unknowns, &request);
    }
    if !a.at.is_empty() {
        return Err(Error::argument(
            "--at",
            "--at gives values for numeric roots: add --in NAME=LO..HI or --start",
        ));
    }
    let solutions = match pool.linear_system(&eqs, &unknowns) {
        // Linear: exact elimination, printed as it always was.
        Ok(sys) => vec![pool
            .solve_linear(&sys)
            .map_err(|e| match e {
                pdyn_expr::linsolve::LinearError::Underdetermined { free } => {
                    let names: Vec<String> = free.iter().map(|&f| pool.to_text(f)).collect();
                    format!(
                        "the equations do not determine {}: add an equation (a constraint?) involving them",
                        names.join(", ")
                    )
                }
                other => other.to_string(),
            })
            .map_err(|message| Error::argument("", message))?],
        // Not linear: substitution, the quadratic formula, real roots of polynomials.
        Err(pdyn_expr::linsolve::LinearError::NotLinear { .. }) => {
            pdyn_mech::algebra::solve(&mut pool, &eqs, &unknowns).map_err(|error| {
                let hint = if matches!(error, pdyn_mech::algebra::AlgebraError::NoClosedForm { .. }) {
                    "\n  help: for numeric roots give an interval (one equation: --in x=0..10) or \
                     starts for Newton's method (--start x=1,y=2)"
                } else {
                    ""
                };
                Error::argument("", format!("{error}{hint}"))
            })?
        }
        Err(e) => return Err(Error::argument("", e.to_string())),
    };
    if solutions.is_empty() {
        return Err(Error::argument("", "no real solution"));
    }
    if a.common.json {
        let one = |sol: &Vec<Id>| -> serde_json::Map<String, serde_json::Value> {
            a.unknowns
                .iter()
                .zip(sol)
                .map(|(u, &s)| (u.clone(), value_json(&pool, Value::Scalar(s))))
                .collect()
        };
        return Ok(if solutions.len() == 1 {
            format!("{}\n", json!({"solution": one(&solutions[0])}))
        } else {
            let all: Vec<_> = solutions.iter().map(one).collect();
            format!(
                "{}\n",
                json!({"solution": one(&solutions[0]), "solutions": all})
            )
        });
    }
    let mut out = String::new();
    for (k, sol) in solutions.iter().enumerate() {
        if solutions.len() > 1 {
            out += &format!("solution {}:\n", k + 1);
        }
        let indent = if solutions.len() > 1 { "  " } else { "" };
        for (u, &s) in a.unknowns.iter().zip(sol) {
            out += &format!("{indent}{u} = {}\n", a.common.format.show(&pool, s));
        }
    }
    Ok(out)
}

/// `pdyn eval EXPR --at x=1,y=2`.
pub fn eval(a: EvalArgs) -> Result<super::Outcome, Error> {
    let mut pool = Pool::new();
    let v = parse(&mut pool, &a.expr, &a.common, "<expr>")?;
    let mut inputs = Vec::new();
    let mut values = Vec::new();
    for kv in &a.at {
        let (k, val) = kv.split_once('=').ok_or_else(|| {
            Error::argument("--at", format!("--at: expected name=value, got `{kv}`"))
        })?;
        let x = match parse(&mut pool, k.trim(), &a.common, "--at")? {
            Value::Scalar(s) if is_leaf(&pool, s) => s,
            _ => {
                return Err(Error::argument(
                    "--at",
                    format!("--at: `{k}` is not a variable name"),
                ))
            }
        };
        let num = match parse(&mut pool, val.trim(), &a.common, "--at")? {
            Value::Scalar(s) => pool.simplify(s),
            Value::Vector(_) => {
                return Err(Error::argument(
                    "--at",
                    format!("--at: `{val}` is not a number"),
                ))
            }
        };
        let prog = Program::compile(&mut pool, &[], &[num])
            .map_err(|e| Error::argument("--at", format!("--at {k}: {e}")))?;
        let mut ws = prog.workspace();
        let mut out = [0.0];
        prog.eval(&[], &mut ws, &mut out);
        if !out[0].is_finite() {
            return Err(Error::argument(
                "--at",
                format!("--at {k}: `{val}` is not a finite number ({})", out[0]),
            ));
        }
        inputs.push(x);
        values.push(out[0]);
    }
    let outs: Vec<Id> = match v {
        Value::Scalar(s) => vec![s],
        Value::Vector(c) => c.to_vec(),
    };
    let prog = Program::compile(&mut pool, &inputs, &outs)
        .map_err(|e| Error::argument("", format!("{e}; give it a value with --at")))?;
    let mut ws = prog.workspace();
    let mut out = vec![0.0; outs.len()];
    prog.eval(&values, &mut ws, &mut out);
    // Components that folded to an exact rational print exactly (`2^64 + 1 - 2^64` is 1,
    // `2^100000` has 30,103 digits); the others are evaluated in floating point, and JSON
    // says which is which (`exact` is null for a floating-point value).
    let exact: Vec<Option<String>> = outs
        .iter()
        .map(|&o| match pool.as_num(o) {
            Some(n @ pdyn_expr::Number::Rat(_)) => Some(n.to_string()),
            _ => None,
        })
        .collect();
    let non_finite: Vec<usize> = (0..out.len())
        .filter(|&i| !out[i].is_finite() && exact[i].is_none())
        .collect();
    let failure = (!non_finite.is_empty()).then(|| Error::NonFinite {
        what: format!("`{}`", a.expr),
        components: non_finite.clone(),
    });
    let stdout = if a.common.json {
        let value: Vec<serde_json::Value> =
            out.iter().map(|&x| pdyn::output::json_num(x)).collect();
        format!(
            "{}\n",
            json!({"input": a.expr, "value": value, "exact": exact, "non_finite": non_finite})
        )
    } else {
        let shown: Vec<String> = out
            .iter()
            .zip(&exact)
            .map(|(x, e)| e.clone().unwrap_or_else(|| x.to_string()))
            .collect();
        if shown.len() == 1 {
            match &exact[0] {
                // An exact fraction also shows its floating-point value.
                Some(e) if e.contains('/') && out[0].is_finite() => {
                    format!("{e} ≈ {}\n", out[0])
                }
                _ => format!("{}\n", shown[0]),
            }
        } else {
            format!("[{}]\n", shown.join(", "))
        }
    };
    Ok(super::Outcome {
        stdout,
        stderr: String::new(),
        failure,
    })
}
