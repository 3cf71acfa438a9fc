//! `pdyn kin`: kinematics of a particle from its position (Cartesian or polar) or its path and
//! speed: velocity, acceleration, normal–tangential and polar components, curvature, values at
//! instants and maxima over a range. Computed by [`pdyn::kin`]; printed here.

use super::Format;
use clap::Args;
use pdyn::kin::{kin, value, KinInput, KinInstant, KinMax, KinResult};
use pdyn::Error;
use pdyn_expr::Pool;
use pdyn_mech::kinematics::{Maximum, Quantity};
use serde_json::json;

/// `pdyn kin`.
#[derive(Args, Debug)]
#[command(after_help = "Examples:
  pdyn kin \"[R*cos(omega*t), R*sin(omega*t), 0]\"
  pdyn kin --polar \"r = t/sqrt(pi), theta = t^2\" --at theta=pi
  pdyn kin --path \"y = A*sin(2*pi*x/L)\" --speed V --max \"norm(a)\" --over x=0..L
  pdyn kin --path \"x = R*cos(s), y = R*sin(s)\" --param s --speed \"k*t\" --at \"s=pi, t=2\"")]
pub struct KinArgs {
    /// Cartesian position `[x, y, z]` as functions of `t` (or of coordinates written `x(t)`).
    #[arg(allow_hyphen_values = true)]
    position: Option<String>,
    /// Cylindrical-polar position: `r = ..., theta = ..., z = ...` (z optional).
    #[arg(long, allow_hyphen_values = true)]
    polar: Option<String>,
    /// A planar path: `y = f(x)`, or `x = ..., y = ...` in the parameter given by --param.
    #[arg(long, allow_hyphen_values = true)]
    path: Option<String>,
    /// The parameter of a parametric path.
    #[arg(long, default_value = "s")]
    param: String,
    /// Speed along the path (a constant or a function of t).
    #[arg(long, default_value = "V", allow_hyphen_values = true)]
    speed: String,
    /// Evaluate at an instant: `t=2`, `theta=pi` (solves for t), `x=L/4` (path position),
    /// several assignments separated by commas. Repeat for several instants.
    #[arg(long, allow_hyphen_values = true)]
    at: Vec<String>,
    /// Parameter values, e.g. `--set A=2,L=50`.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    set: Vec<String>,
    /// A scalar to maximise over --over, in the names printed (`norm(a)`, `a_n`, `speed`...).
    #[arg(long, allow_hyphen_values = true)]
    max: Option<String>,
    /// The range for --max: `x=0..L` or `t=0..10`.
    #[arg(long, allow_hyphen_values = true)]
    over: Option<String>,
    /// Parameters that may be negative; every other parameter is assumed positive.
    #[arg(long, value_delimiter = ',')]
    signed: Vec<String>,
    /// Output notation.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    format: Format,
    /// Machine-readable output.
    #[arg(long)]
    json: bool,
}

fn show_q(pool: &Pool, q: Quantity, f: Format) -> String {
    f.show_value(pool, value(q))
}

fn json_q(pool: &Pool, q: Quantity) -> serde_json::Value {
    super::value_json(pool, value(q))
}

/// `pdyn kin ...`.
pub fn run(a: KinArgs) -> Result<String, Error> {
    let input = KinInput {
        position: a.position,
        polar: a.polar,
        path: a.path,
        param: a.param,
        speed: a.speed,
        at: a.at,
        set: a.set,
        max: a.max,
        over: a.over,
        signed: a.signed,
    };
    let r = kin(&input)?;
    Ok(if a.json {
        to_json(&r)
    } else {
        to_text(&r, a.format)
    })
}

fn to_text(r: &KinResult, format: Format) -> String {
    let pool = &r.pool;
    let mut out = String::new();
    for (name, q) in &r.quantities {
        out += &format!("{name} = {}\n", show_q(pool, *q, format));
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
            out += &format!("  {n} = {}{num_text}\n", show_q(pool, *q, format));
        }
        out += &undefined_text(r, i, format);
    }
    if let Some(m) = &r.max {
        out += &max_text(pool, m, format);
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
fn undefined_text(r: &KinResult, i: &KinInstant, format: Format) -> String {
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
                show_q(pool, Quantity::Vector(*dir), format)
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
                pdyn::kin::AT_REST_ORDERS
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
                "exact": json_q(&r.pool, Quantity::Vector(*dir)),
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
        .map(|(n, q)| (n.to_string(), json_q(pool, *q)))
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
                            json!({"exact": json_q(pool, *q), "value": nums}),
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

fn max_text(pool: &Pool, m: &KinMax, format: Format) -> String {
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
            format.show(pool, *value),
            format.show(pool, *at),
            parameters.join(", ")
        ),
    }
}

fn max_json(pool: &Pool, m: &KinMax) -> serde_json::Value {
    let expr = &m.expr;
    match &m.found {
        Maximum::Numeric(e) => json!({"expr": expr, "value": e.value, "at": e.at}),
        Maximum::Exact { at, value, .. } => {
            json!({"expr": expr, "value": super::both(pool, *value), "at": super::both(pool, *at)})
        }
    }
}
