//! What `pdyn kin` prints for a position given by formulas: the kinematic quantities, their
//! values at instants (and what is undefined there, with the limiting tangent at rest), and
//! maxima over a range, as text in a [`Notation`] or as JSON. Computed by [`crate::kin`].

use super::notation::{both, value_json, Notation};
use crate::kin::{value, KinInstant, KinMax, KinResult};
use pdyn_expr::Pool;
use pdyn_mech::kinematics::Maximum;
use serde_json::json;

/// The report of a kinematics result: JSON (one line) or text in `notation`.
pub fn report(r: &KinResult, notation: Notation, json: bool) -> String {
    if json {
        to_json(r)
    } else {
        to_text(r, notation)
    }
}

fn to_text(r: &KinResult, notation: Notation) -> String {
    let pool = &r.pool;
    let mut out = String::new();
    for (name, q) in &r.quantities {
        out += &format!("{name} = {}\n", notation.show_value(pool, value(*q)));
    }
    if r.straight {
        out += "(straight-line motion: the normal is undefined, shown as 0, and R is infinite)\n";
    }
    for i in &r.instants {
        out += &format!("at {}:\n", i.resolved);
        for (n, q, nums) in &i.values {
            let num_text = match nums {
                Some(v) if v.len() == 1 => format!("  ≈ {}", v[0]),
                Some(v) => format!(
                    "  ≈ [{}]",
                    v.iter().map(f64::to_string).collect::<Vec<_>>().join(", ")
                ),
                None => String::new(),
            };
            out += &format!(
                "  {n} = {}{num_text}\n",
                notation.show_value(pool, value(*q))
            );
        }
        out += &undefined_text(r, i, notation);
    }
    if let Some(m) = &r.max {
        out += &max_text(pool, m, notation);
    }
    if !r.assumed_positive.is_empty() {
        out += &format!(
            "assuming {} > 0 (use --signed NAME for a parameter that may be negative)\n",
            r.assumed_positive.join(", ")
        );
    }
    out
}

/// The quantities undefined at an instant, grouped by reason, and the limiting tangent at rest.
fn undefined_text(r: &KinResult, i: &KinInstant, notation: Notation) -> String {
    let pool = &r.pool;
    let mut out = String::new();
    let mut reasons: Vec<&str> = i.undefined.iter().map(|(_, why)| *why).collect();
    reasons.dedup();
    for why in reasons {
        let names: Vec<&str> = i
            .undefined
            .iter()
            .filter(|(_, w)| *w == why)
            .map(|(n, _)| *n)
            .collect();
        out += &format!("  {}: undefined — {why}\n", names.join(", "));
    }
    let Some(rest) = &i.at_rest else {
        return out;
    };
    let var = &r.variable;
    match (rest.order, &rest.tangent) {
        (Some(k), Some((dir, value))) => {
            let num = value.map_or(String::new(), |v| {
                format!("  ≈ [{}, {}, {}]", v[0], v[1], v[2])
            });
            out += &format!(
                "  limiting tangent as {var} increases to this instant: {}{num} (the direction of \
                 the derivative of r of order {k}, the first that is not zero here)\n",
                notation.show_vector(pool, *dir)
            );
            out += if rest.reverses {
                "  the direction reverses through this instant (a cusp: the point stops and turns back)\n"
            } else {
                "  the direction is the same on both sides of this instant\n"
            };
            if let (Some(at), Some(an)) = (rest.a_t, rest.a_n) {
                out += &format!(
                    "  limits as {var} increases to this instant: a_t → {at}, a_n → {an}\n"
                );
            }
        }
        _ => {
            out += &format!(
                "  no limiting tangent found: the derivatives of r up to order {} are zero here\n",
                crate::kin::AT_REST_ORDERS
            );
        }
    }
    out
}

fn at_rest_json(r: &KinResult, i: &KinInstant) -> serde_json::Value {
    let undefined: serde_json::Map<String, serde_json::Value> = i
        .undefined
        .iter()
        .map(|(n, why)| (n.to_string(), json!(why)))
        .collect();
    let rest = i.at_rest.as_ref().map(|a| {
        json!({
            "order": a.order,
            "tangent": a.tangent.as_ref().map(|(dir, value)| json!({
                "exact": value_json(&r.pool, pdyn_expr::Value::Vector(*dir)),
                "value": value,
            })),
            "reverses": a.reverses,
            "a_t": a.a_t,
            "a_n": a.a_n,
        })
    });
    json!({"undefined": undefined, "at_rest": rest})
}

fn to_json(r: &KinResult) -> String {
    let pool = &r.pool;
    let mut js = serde_json::Map::new();
    let m: serde_json::Map<String, serde_json::Value> = r
        .quantities
        .iter()
        .map(|(n, q)| (n.to_string(), value_json(pool, value(*q))))
        .collect();
    js.insert("variable".into(), json!(r.variable));
    js.insert("straight".into(), json!(r.straight));
    js.insert("quantities".into(), serde_json::Value::Object(m));
    if !r.instants.is_empty() {
        let instants_json: Vec<serde_json::Value> = r
            .instants
            .iter()
            .map(|i| {
                let vals: serde_json::Map<String, serde_json::Value> = i
                    .values
                    .iter()
                    .map(|(n, q, nums)| {
                        (
                            n.to_string(),
                            json!({"exact": value_json(pool, value(*q)), "value": nums}),
                        )
                    })
                    .collect();
                let mut o = json!({"at": i.spec, "resolved": i.resolved, "values": vals});
                if !i.undefined.is_empty() {
                    let extra = at_rest_json(r, i);
                    o["undefined"] = extra["undefined"].clone();
                    o["at_rest"] = extra["at_rest"].clone();
                }
                o
            })
            .collect();
        js.insert("at".into(), json!(instants_json));
    }
    if let Some(m) = &r.max {
        js.insert("max".into(), max_json(pool, m));
    }
    js.insert("assumed_positive".into(), json!(r.assumed_positive));
    format!("{}\n", serde_json::Value::Object(js))
}

fn max_text(pool: &Pool, m: &KinMax, notation: Notation) -> String {
    let (expr, over, var_name) = (&m.expr, &m.over, &m.variable);
    match &m.found {
        Maximum::Numeric(e) => format!(
            "max {expr} over {over}: {} at {var_name} = {}\n",
            e.value, e.at
        ),
        Maximum::Exact {
            at,
            value,
            parameters,
        } => format!(
            "max {expr} over {over}: {} at {var_name} = {}\n  (location found numerically for random values of {} and checked on a third set)\n",
            notation.show(pool, *value),
            notation.show(pool, *at),
            parameters.join(", ")
        ),
    }
}

fn max_json(pool: &Pool, m: &KinMax) -> serde_json::Value {
    let expr = &m.expr;
    match &m.found {
        Maximum::Numeric(e) => json!({"expr": expr, "value": e.value, "at": e.at}),
        Maximum::Exact { at, value, .. } => {
            json!({"expr": expr, "value": both(pool, *value), "at": both(pool, *at)})
        }
    }
}
