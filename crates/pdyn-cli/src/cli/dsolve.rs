//! `pdyn dsolve`: closed-form solution of linear constant-coefficient ODEs and systems, and the
//! 1-D rules of straight-line motion (`--rule "a(v) = -c*v^2"`). Computed by
//! [`pdyn::dsolve`]; printed here.

use super::{both, Format};
use clap::Args;
use pdyn::dsolve::{dsolve, DsolveInput, EquationsSolution, RuleResult, Solved, WhenResult};
use pdyn::Error;
use pdyn_expr::{Id, Node, Pool};
use pdyn_mech::dsolve::{ClosedForm, Method, Relation};
use serde_json::json;

/// `pdyn dsolve`.
#[derive(Args, Debug)]
#[command(after_help = "Examples:
  pdyn dsolve \"x'' + 2*zeta*wn*x' + wn^2*x = 0\" --ic \"x(0)=x0, x'(0)=v0\"
  pdyn dsolve \"m*x'' = -k*(x - L0) - m*g\" --ic \"x(0)=L, x'(0)=0\"
  pdyn dsolve \"x'' = 0\" \"y'' = -g\" --ic \"x(0)=0, x'(0)=V*cos(a), y(0)=h, y'(0)=V*sin(a)\"
  pdyn dsolve --rule \"a(v) = -g - c*v^2\" --ic \"x(0)=0, v(0)=v0\"")]
pub struct DsolveArgs {
    /// Equations `lhs = rhs` in coordinates written `x'`, `x''` or `x(t)`, one per argument.
    /// An equation starting with `-` goes after `--`.
    equations: Vec<String>,
    /// Initial conditions, comma separated: `x(0)=x0, x'(0)=v0` (all at the same time).
    #[arg(long, allow_hyphen_values = true)]
    ic: Option<String>,
    /// A 1-D rule of straight-line motion instead of equations: `a(t) = ...`, `v(t) = ...`,
    /// `a(v) = ...` or `a(x) = ...` (initial conditions `x(0)=..., v(0)=...`).
    #[arg(long, allow_hyphen_values = true)]
    rule: Option<String>,
    /// Parameter values substituted before solving, e.g. `--set m=2,k=50` (a numeric damping
    /// ratio picks the under-, critically or over-damped form).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    set: Vec<String>,
    /// Evaluate the solution at these times (or at these values of the independent variable
    /// of a rule), e.g. `--at 0,0.5,1`.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    at: Vec<String>,
    /// Find the first instant t ≥ 0 where a condition holds, e.g. `--when "y = 0"` (landing)
    /// or `--when "y' = 0"` (highest point), and print the state there (exactly when the
    /// instant solves exactly).
    #[arg(long, allow_hyphen_values = true)]
    when: Option<String>,
    /// Parameters that may be negative or zero. Every other parameter of the equations is
    /// assumed positive (masses, stiffnesses, lengths), which decides signs of discriminants.
    #[arg(long, value_delimiter = ',')]
    signed: Vec<String>,
    /// Output notation.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    format: Format,
    /// Machine-readable output.
    #[arg(long)]
    json: bool,
}

fn relation_text(pool: &Pool, expr: Id, rel: Relation, f: Format) -> String {
    // `-1 + zeta^2 < 0` reads better as `zeta^2 < 1`.
    let (lhs, rhs) = match pool.node(expr) {
        Node::Add(ts) if pool.as_num(ts[0]).is_some() && ts.len() == 2 => {
            let c = pool.as_num(ts[0]).unwrap_or(pdyn_expr::Number::ZERO).neg();
            (f.show(pool, ts[1]), c.to_string())
        }
        _ => (f.show(pool, expr), "0".to_string()),
    };
    let op = match (rel, f) {
        (Relation::Positive, _) => ">",
        (Relation::Zero, _) => "=",
        (Relation::Negative, _) => "<",
    };
    format!("{lhs} {op} {rhs}")
}

/// `pdyn dsolve EQUATIONS --ic ...` or `pdyn dsolve --rule ...`.
pub fn run(a: DsolveArgs) -> Result<String, Error> {
    let input = DsolveInput {
        equations: a.equations,
        ic: a.ic,
        rule: a.rule,
        set: a.set,
        at: a.at,
        when: a.when,
        signed: a.signed,
    };
    let r = dsolve(&input)?;
    Ok(match &r.solved {
        Solved::Equations(s) => print_equations(&r.pool, s, a.format, a.json),
        Solved::Rule(s) => print_rule(&r.pool, s, a.format, a.json),
    })
}

fn print_equations(pool: &Pool, s: &EquationsSolution, format: Format, json: bool) -> String {
    let cf = &s.closed_form;
    let (assumed, times, table) = (&s.assumed_positive, &s.times, &s.table);
    let when = s.when.as_ref().map(|w| when_text(pool, w, format));
    if json {
        let mut j = to_json(pool, cf, assumed, times, table);
        if let Some((_, wj)) = &when {
            j["when"] = wj.clone();
        }
        return format!("{j}\n");
    }
    let mut out = String::new();
    for (ci, case) in cf.cases.iter().enumerate() {
        let indent = if case.condition.is_some() { "  " } else { "" };
        if let Some(c) = case.condition {
            out += &format!(
                "case {}:\n",
                relation_text(pool, c.expr, c.relation, format)
            );
        }
        for (j, &q) in case.solution.iter().enumerate() {
            out += &format!(
                "{indent}{}(t) = {}\n",
                pool.name(cf.coords[j]),
                format.show(pool, q)
            );
        }
        if !case.roots.is_empty() {
            out += &format!("{indent}characteristic roots: {}\n", case.roots.join(", "));
        }
        if let Some(rows) = table.get(ci) {
            for (t, vals) in times.iter().zip(rows) {
                let parts: Vec<String> = cf
                    .coords
                    .iter()
                    .zip(vals.chunks(2))
                    .map(|(&c, v)| {
                        format!("{} = {}, {}' = {}", pool.name(c), v[0], pool.name(c), v[1])
                    })
                    .collect();
                out += &format!("{indent}t = {t}: {}\n", parts.join(", "));
            }
        }
    }
    if let Some((text, _)) = &when {
        out += text;
    }
    if cf.method == Method::Numeric {
        out += &format!(
            "(numeric roots and coefficients; relative residual {:.1e})\n",
            cf.residual.unwrap_or(0.0)
        );
    }
    if !assumed.is_empty() {
        out += &format!(
            "assuming {} > 0 (use --signed NAME for a parameter that may be negative)\n",
            assumed.join(", ")
        );
    }
    out
}

/// The text and JSON of `--when`.
fn when_text(pool: &Pool, w: &WhenResult, format: Format) -> (String, serde_json::Value) {
    let (src, found) = (&w.condition, &w.found);
    let mut text = format!("when {src}: t = {}", format.show(pool, found.t));
    if found.exact && found.value.is_finite() && pool.as_num(found.t).is_none() {
        text += &format!(" ≈ {}", found.value);
    }
    text += "\n";
    let mut state = serde_json::Map::new();
    for s in &found.state {
        let approx = match s.value {
            Some(v) if pool.as_num(s.exact).is_none() => format!("  ≈ {v}"),
            _ => String::new(),
        };
        text += &format!("  {} = {}{approx}\n", s.name, format.show(pool, s.exact));
        state.insert(
            s.name.clone(),
            json!({"exact": both(pool, s.exact), "value": s.value}),
        );
    }
    let tj = json!({
        "t": found.value.is_finite().then_some(found.value),
        "t_exact": found.exact.then(|| both(pool, found.t)),
        "state": state,
    });
    (text, tj)
}

fn to_json(
    pool: &Pool,
    cf: &ClosedForm,
    assumed: &[String],
    times: &[f64],
    table: &[Vec<Vec<f64>>],
) -> serde_json::Value {
    let cases: Vec<serde_json::Value> = cf
        .cases
        .iter()
        .enumerate()
        .map(|(ci, c)| {
            let sol: serde_json::Map<String, serde_json::Value> = cf
                .coords
                .iter()
                .zip(&c.solution)
                .map(|(&q, &e)| (pool.name(q).to_string(), both(pool, e)))
                .collect();
            let cond = c.condition.map(|k| {
                json!({
                    "expr": both(pool, k.expr),
                    "relation": match k.relation {
                        Relation::Positive => ">",
                        Relation::Zero => "=",
                        Relation::Negative => "<",
                    },
                    "rhs": 0
                })
            });
            let values: Vec<serde_json::Value> = table
                .get(ci)
                .map(|rows| {
                    times
                        .iter()
                        .zip(rows)
                        .map(|(t, v)| json!({"t": t, "values": v}))
                        .collect()
                })
                .unwrap_or_default();
            json!({
                "condition": cond,
                "solution": sol,
                "roots": c.roots,
                "constants": c.constants.iter().map(|&k| pool.to_text(k)).collect::<Vec<_>>(),
                "at": values,
            })
        })
        .collect();
    json!({
        "coords": cf.coords.iter().map(|&c| pool.name(c)).collect::<Vec<_>>(),
        "method": match cf.method { Method::Exact => "exact", Method::Numeric => "numeric" },
        "residual": cf.residual,
        "cases": cases,
        "assumed_positive": assumed,
    })
}

fn print_rule(pool: &Pool, s: &RuleResult, format: Format, json: bool) -> String {
    let (rule, indep, params) = (&s.rule, s.variable, &s.assumed_positive);
    let (sol, points, evaluated) = (&s.solution, &s.points, &s.values);
    if json {
        let qs: Vec<serde_json::Value> = sol
            .quantities
            .iter()
            .zip(evaluated)
            .map(|(q, vals)| {
                json!({
                    "name": q.name,
                    "closed_form": q.closed.map(|c| both(pool, c)),
                    "at": points.iter().zip(vals).map(|(s, v)| match v {
                        Ok(v) => json!({"at": s, "value": v.value, "error": v.error}),
                        Err(e) => json!({"at": s, "value": null, "message": e.to_string()}),
                    }).collect::<Vec<_>>(),
                })
            })
            .collect();
        return format!(
            "{}\n",
            json!({"rule": rule, "variable": indep, "quantities": qs, "assumed_positive": params})
        );
    }
    let mut out = String::new();
    for (q, vals) in sol.quantities.iter().zip(evaluated) {
        match q.closed {
            Some(c) => out += &format!("{} = {}\n", q.name, format.show(pool, c)),
            None => {
                out += &format!(
                    "{} = {} (no closed form used: numerical quadrature)\n",
                    q.name,
                    q.describe(pool)
                )
            }
        }
        for (s, v) in points.iter().zip(vals) {
            let v = match v {
                Ok(v) => v,
                Err(e) => {
                    out += &format!("  {indep} = {s}: {e}\n");
                    continue;
                }
            };
            if v.error > 0.0 {
                out += &format!("  {indep} = {s}: {} (± {:.1e})\n", v.value, v.error);
            } else {
                out += &format!("  {indep} = {s}: {}\n", v.value);
            }
        }
    }
    if !params.is_empty() {
        out += &format!(
            "assuming {} > 0 (use --signed NAME for a parameter that may be negative)\n",
            params.join(", ")
        );
    }
    out
}
