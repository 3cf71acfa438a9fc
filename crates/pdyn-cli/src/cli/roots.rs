//! `pdyn solve --in x=0..10` and `--start x=1,y=2`: numeric roots of equations without a
//! closed form (`pdyn_mech::numeric_roots`), printed with how each is certified.

use pdyn::Error;
use pdyn_expr::{Id, Node, Pool, Value};
use pdyn_mech::numeric_roots::{self, Certificate};
use serde_json::json;

/// What `pdyn solve` was asked, for the numeric path.
pub struct Request<'a> {
    /// `--for`, as written.
    pub unknown_names: &'a [String],
    /// `--in NAME=LO..HI`.
    pub interval: Option<&'a str>,
    /// `--samples`.
    pub samples: usize,
    /// `--start`, each `x=1,y=2`.
    pub starts: &'a [String],
    /// `--at`, each `name=value`.
    pub at: &'a [String],
    /// `--json`.
    pub json: bool,
}

/// The number an argument's expression evaluates to (`2*pi`), or a located error.
fn number(pool: &mut Pool, text: &str, option: &str) -> Result<f64, Error> {
    number_expr(pool, text, option).map(|(_, x)| x)
}

/// The expression of an argument's number (exact when written so: `3/10`) and its value.
fn number_expr(pool: &mut Pool, text: &str, option: &str) -> Result<(Id, f64), Error> {
    let bad = |why: String| Error::argument(option, format!("{option}: `{text}` {why}"));
    let v = pool
        .parse_scalar(text.trim())
        .map_err(|e| bad(format!("is not an expression: {}", e.message)))?;
    let x = pool
        .eval_const(v)
        .map_err(|e| bad(format!("is not a number ({e})")))?;
    if !x.is_finite() {
        return Err(bad(format!("is not a finite number ({x})")));
    }
    Ok((v, x))
}

/// `name=value` split, the name checked to be a plain name.
fn assignment<'t>(text: &'t str, option: &str) -> Result<(&'t str, &'t str), Error> {
    let (k, v) = text.split_once('=').ok_or_else(|| {
        Error::argument(
            option,
            format!("{option}: expected name=value, got `{text}`"),
        )
    })?;
    Ok((k.trim(), v.trim()))
}

/// The symbol `name` in `pool` (a name not in the equations is still a symbol).
fn symbol(pool: &mut Pool, name: &str, option: &str) -> Result<Id, Error> {
    match pool.parse_value(name) {
        Ok(Value::Scalar(s)) if matches!(pool.node(s), Node::Sym(_) | Node::Coord(..)) => Ok(s),
        _ => Err(Error::argument(
            option,
            format!("{option}: `{name}` is not a variable name"),
        )),
    }
}

/// Solves numerically and renders the result; see the module documentation.
pub fn solve_numerically(
    pool: &mut Pool,
    equations: &[Id],
    unknowns: &[Id],
    r: &Request,
) -> Result<String, Error> {
    // --at: the other names' values, substituted.
    let mut map = Vec::new();
    for kv in r.at {
        let (k, v) = assignment(kv, "--at")?;
        let s = symbol(pool, k, "--at")?;
        if unknowns.contains(&s) {
            return Err(Error::argument(
                "--at",
                format!("--at: `{k}` is an unknown (--for): it cannot also be given a value"),
            ));
        }
        let (n, _) = number_expr(pool, v, "--at")?;
        map.push((s, n));
    }
    let eqs: Vec<Id> = equations
        .iter()
        .map(|&e| pdyn::args::subs_all(pool, e, &map))
        .collect();
    let root_error = |e: numeric_roots::RootsError, option: &str| {
        Error::argument(option, format!("{option}: {e}"))
    };
    if let Some(spec) = r.interval {
        if !r.starts.is_empty() {
            return Err(Error::argument(
                "--start",
                "--start is for systems (Newton's method); --in finds every root of one equation",
            ));
        }
        if eqs.len() != 1 || unknowns.len() != 1 {
            return Err(Error::argument(
                "--in",
                format!(
                    "--in finds the roots of one equation in one unknown; this is {} equation(s) \
                     in {} unknown(s): give a system starts instead (--start x=1,y=2)",
                    eqs.len(),
                    unknowns.len()
                ),
            ));
        }
        let (name, range) = assignment(spec, "--in")?;
        let x = symbol(pool, name, "--in")?;
        if x != unknowns[0] {
            return Err(Error::argument(
                "--in",
                format!(
                    "--in: `{name}` is not the unknown (--for {})",
                    r.unknown_names[0]
                ),
            ));
        }
        let (lo, hi) = range.split_once("..").ok_or_else(|| {
            Error::argument(
                "--in",
                format!("--in: expected NAME=LO..HI (e.g. x=0..10), got `{spec}`"),
            )
        })?;
        let (lo, hi) = (number(pool, lo, "--in")?, number(pool, hi, "--in")?);
        let found = numeric_roots::scalar_roots(pool, eqs[0], x, lo, hi, r.samples)
            .map_err(|e| root_error(e, "--in"))?;
        return Ok(render_scalar(&r.unknown_names[0], lo, hi, &found, r.json));
    }
    let mut starts = Vec::new();
    for s in r.starts {
        let mut point = vec![f64::NAN; unknowns.len()];
        for kv in s.split(',') {
            let (k, v) = assignment(kv, "--start")?;
            let id = symbol(pool, k, "--start")?;
            let Some(i) = unknowns.iter().position(|&u| u == id) else {
                return Err(Error::argument(
                    "--start",
                    format!(
                        "--start: `{k}` is not an unknown (--for {})",
                        r.unknown_names.join(",")
                    ),
                ));
            };
            point[i] = number(pool, v, "--start")?;
        }
        if let Some(i) = point.iter().position(|v| v.is_nan()) {
            return Err(Error::argument(
                "--start",
                format!("--start `{s}` gives no value to `{}`", r.unknown_names[i]),
            ));
        }
        starts.push(point);
    }
    let (found, diverged) = numeric_roots::newton_system(pool, &eqs, unknowns, &starts)
        .map_err(|e| root_error(e, "--start"))?;
    if found.is_empty() {
        let why: Vec<String> = diverged
            .iter()
            .map(|d| format!("start {}: {}", d.start + 1, d.reason))
            .collect();
        return Err(Error::argument(
            "--start",
            format!("no start converged ({})", why.join("; ")),
        ));
    }
    Ok(render_system(r.unknown_names, &found, &diverged, r.json))
}

fn certificate_json(c: &Certificate) -> serde_json::Value {
    match c {
        Certificate::Exact => json!({"kind": "exact zero"}),
        Certificate::SignChange { lo, hi } => json!({"kind": "sign change", "bracket": [lo, hi]}),
        Certificate::Residual { lo, hi, bound } => json!({
            "kind": "double root (residual bound)",
            "critical_point_bracket": [lo, hi],
            "residual_bound": bound,
        }),
    }
}

fn certificate_text(c: &Certificate) -> String {
    match c {
        Certificate::Exact => "exact zero".into(),
        Certificate::SignChange { lo, hi } => {
            format!("sign change on [{lo:e}, {hi:e}]")
        }
        Certificate::Residual { bound, .. } => {
            format!("double root: f' changes sign, |f| <= {bound:.1e} (rounding bound)")
        }
    }
}

fn render_scalar(
    name: &str,
    lo: f64,
    hi: f64,
    found: &numeric_roots::ScalarRoots,
    json: bool,
) -> String {
    if json {
        let roots: Vec<serde_json::Value> = found
            .roots
            .iter()
            .map(|root| {
                json!({
                    name: root.x,
                    "residual": root.residual,
                    "slope": root.slope,
                    "certificate": certificate_json(&root.certificate),
                })
            })
            .collect();
        let disc: Vec<[f64; 2]> = found.discontinuities.iter().map(|&(a, b)| [a, b]).collect();
        return format!(
            "{}\n",
            json!({
                "interval": {name: [lo, hi]},
                "sampling_step": found.step,
                "undefined_samples": found.undefined,
                "roots": roots,
                "discontinuities": disc,
            })
        );
    }
    let (mut lo_text, mut hi_text) = (String::new(), String::new());
    pdyn::output::push_number(&mut lo_text, lo);
    pdyn::output::push_number(&mut hi_text, hi);
    let mut out = format!(
        "{} root(s) in {name} = {lo_text}..{hi_text} (sampling step {:.3e}: roots closer than it may be missed in pairs)\n",
        found.roots.len(),
        found.step
    );
    if found.undefined > 0 {
        out += &format!(
            "warning: f is not a number at {} of the {} sample points (outside its domain): no root can be found there\n",
            found.undefined, found.sampled
        );
    }
    for root in &found.roots {
        out += &format!(
            "{name} = {:.17e}   f = {:.1e}, f' = {:.3e}; {}\n",
            root.x,
            root.residual,
            root.slope,
            certificate_text(&root.certificate)
        );
    }
    for (a, b) in &found.discontinuities {
        out += &format!("not a root: f changes sign across a pole or jump on [{a:e}, {b:e}]\n");
    }
    out
}

fn render_system(
    names: &[String],
    found: &[numeric_roots::SystemRoot],
    diverged: &[numeric_roots::Diverged],
    json: bool,
) -> String {
    if json {
        let sols: Vec<serde_json::Value> = found
            .iter()
            .map(|s| {
                let mut m: serde_json::Map<String, serde_json::Value> = names
                    .iter()
                    .zip(&s.x)
                    .map(|(n, &v)| (n.clone(), json!(v)))
                    .collect();
                m.insert("residual".into(), json!(s.residual));
                m.insert("last_newton_step".into(), json!(s.last_step));
                m.insert(
                    "from_starts".into(),
                    json!(s.from_starts.iter().map(|k| k + 1).collect::<Vec<_>>()),
                );
                serde_json::Value::Object(m)
            })
            .collect();
        let div: Vec<serde_json::Value> = diverged
            .iter()
            .map(|d| json!({"start": d.start + 1, "reason": d.reason}))
            .collect();
        return format!("{}\n", json!({"solutions": sols, "diverged": div}));
    }
    let mut out = String::new();
    for (k, s) in found.iter().enumerate() {
        let starts: Vec<String> = s.from_starts.iter().map(|k| (k + 1).to_string()).collect();
        out += &format!(
            "solution {} (Newton from start {}; |F| = {:.1e}, last step {:.1e}):\n",
            k + 1,
            starts.join(", "),
            s.residual,
            s.last_step
        );
        for (n, v) in names.iter().zip(&s.x) {
            out += &format!("  {n} = {v:.17e}\n");
        }
    }
    for d in diverged {
        out += &format!("start {}: {}\n", d.start + 1, d.reason);
    }
    out
}
