//! What `pdyn dsolve` prints: the closed-form solution of linear constant-coefficient
//! equations (case by case when a sign decides the form, with characteristic roots, values at
//! times and the instant a condition first holds), or a 1-D rule of straight-line motion, as text
//! in a [`Notation`] or as JSON. Computed by [`crate::dsolve`].

use super::notation::{both, Notation};
use crate::dsolve::{DsolveResult, EquationsSolution, RuleResult, Solved, WhenResult};
use pdyn_expr::{Id, Node, Pool};
use pdyn_mech::dsolve::{ClosedForm, Method, Relation};
use serde_json::json;

/// The report of a `dsolve` result: JSON (one line) or text in `notation`.
pub fn report(r: &DsolveResult, notation: Notation, json: bool) -> String {
    match &r.solved {
        Solved::Equations(s) => print_equations(&r.pool, s, notation, json),
        Solved::Rule(s) => print_rule(&r.pool, s, notation, json),
    }
}

fn relation_text(pool: &Pool, expr: Id, rel: Relation, f: Notation) -> String {
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

fn print_equations(pool: &Pool, s: &EquationsSolution, notation: Notation, json: bool) -> String {
    let cf = &s.closed_form;
    let (assumed, times, table) = (&s.assumed_positive, &s.times, &s.table);
    let when = s.when.as_ref().map(|w| when_text(pool, w, notation));
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
                relation_text(pool, c.expr, c.relation, notation)
            );
        }
        for (j, &q) in case.solution.iter().enumerate() {
            out += &format!(
                "{indent}{}(t) = {}\n",
                pool.name(cf.coords[j]),
                notation.show(pool, q)
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
fn when_text(pool: &Pool, w: &WhenResult, notation: Notation) -> (String, serde_json::Value) {
    let (src, found) = (&w.condition, &w.found);
    let mut text = format!("when {src}: t = {}", notation.show(pool, found.t));
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
        text += &format!("  {} = {}{approx}\n", s.name, notation.show(pool, s.exact));
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

fn print_rule(pool: &Pool, s: &RuleResult, notation: Notation, json: bool) -> String {
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
            Some(c) => out += &format!("{} = {}\n", q.name, notation.show(pool, c)),
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
