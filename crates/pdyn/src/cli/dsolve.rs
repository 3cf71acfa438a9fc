//! `pdyn dsolve`: closed-form solution of linear constant-coefficient ODEs and systems, and the
//! 1-D rules of straight-line motion (`--rule "a(v) = -c*v^2"`).

use super::{both, idents, split_top, subs_all, Format};
use clap::Args;
use pdyn::Error;
use pdyn_expr::{FreeScope, Id, Node, Pool, SymId, Value};
use pdyn_mech::dsolve::rules::{self, Given};
use pdyn_mech::dsolve::{solve_with, ClosedForm, InitialCondition, Method, Relation};
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
    if let Some(rule) = &a.rule {
        if !a.equations.is_empty() {
            return Err(Error::argument(
                "",
                "give either equations or --rule, not both",
            ));
        }
        return run_rule(&a, rule);
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
    let signed_by_set = super::not_positive_in_set(&a.set);
    let params: Vec<String> = names
        .into_iter()
        .filter(|n| {
            !scope.coordinates.contains(n)
                && n != "t"
                && n != "pi"
                && n != "e"
                && !a.signed.contains(n)
                && !signed_by_set.contains(n)
        })
        .collect();
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
    let table = evaluate(&mut pool, &cf, &times)?;
    let when = match &a.when {
        Some(w) => Some(when(&mut pool, &cf, w, &mut scope, &set, a.format)?),
        None => None,
    };
    if a.json {
        let mut j = to_json(&pool, &cf, &assumed, &times, &table);
        if let Some((_, wj)) = &when {
            j["when"] = wj.clone();
        }
        return Ok(format!("{j}\n"));
    }
    let mut out = String::new();
    for (ci, case) in cf.cases.iter().enumerate() {
        let indent = if case.condition.is_some() { "  " } else { "" };
        if let Some(c) = case.condition {
            out += &format!(
                "case {}:\n",
                relation_text(&pool, c.expr, c.relation, a.format)
            );
        }
        for (j, &q) in case.solution.iter().enumerate() {
            out += &format!(
                "{indent}{}(t) = {}\n",
                pool.name(cf.coords[j]),
                a.format.show(&pool, q)
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
    Ok(out)
}

/// `--when "lhs = rhs"`: parsed here, found by [`pdyn_mech::dsolve::when`], printed here.
fn when(
    pool: &mut Pool,
    cf: &ClosedForm,
    src: &str,
    scope: &mut FreeScope,
    set: &[(Id, Id)],
    format: Format,
) -> Result<(String, serde_json::Value), Error> {
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
    Ok((text, tj))
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

/// `pdyn dsolve --rule "a(v) = ..."`.
fn run_rule(a: &DsolveArgs, rule: &str) -> Result<String, Error> {
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
    let signed_by_set = super::not_positive_in_set(&a.set);
    let params: Vec<String> = names
        .into_iter()
        .filter(|n| {
            n != indep
                && n != "t"
                && n != "pi"
                && n != "e"
                && !a.signed.contains(n)
                && !signed_by_set.contains(n)
        })
        .collect();
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
    let mut seen = Vec::new();
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
            seen.push(ic.name);
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
            vals.push(rules::evaluate(&mut pool, q, s).map_err(|e| e.to_string()));
        }
        evaluated.push(vals);
    }
    if a.json {
        let qs: Vec<serde_json::Value> = sol
            .quantities
            .iter()
            .zip(&evaluated)
            .map(|(q, vals)| {
                json!({
                    "name": q.name,
                    "closed_form": q.closed.map(|c| both(&pool, c)),
                    "at": points.iter().zip(vals).map(|(s, v)| match v {
                        Ok(v) => json!({"at": s, "value": v.value, "error": v.error}),
                        Err(e) => json!({"at": s, "value": null, "message": e}),
                    }).collect::<Vec<_>>(),
                })
            })
            .collect();
        return Ok(format!(
            "{}\n",
            json!({"rule": rule, "variable": indep, "quantities": qs, "assumed_positive": params})
        ));
    }
    let mut out = String::new();
    for (q, vals) in sol.quantities.iter().zip(&evaluated) {
        match q.closed {
            Some(c) => out += &format!("{} = {}\n", q.name, a.format.show(&pool, c)),
            None => {
                out += &format!(
                    "{} = {} (no closed form used: numerical quadrature)\n",
                    q.name,
                    q.describe(&pool)
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
    Ok(out)
}
