//! `pdyn optimize MODEL --maximize MEASURE --over theta=0..pi/2`: the parameter values that
//! maximise (or minimise) one of the model's `[sweep.measures]`, computed by
//! [`pdyn::optimize`]; printed here.

use super::run::{request, RunArgs};
use super::{load_model, set_parameters, Outcome};
use clap::Args;
use pdyn::Error;
use serde_json::json;

/// `pdyn optimize`.
#[derive(Args, Debug)]
#[command(after_help = "Examples:
  pdyn optimize examples/data/launch_angle.toml --maximize range --over theta=0..pi/2
  pdyn optimize examples/data/launch_angle.toml --maximize range --over theta=0..pi/2 --over v0=10..20 --json

The measure is one of the model's [sweep.measures] (name = { of = \"...\", stat = \"...\" }, the
statistics of pdyn sweep). One parameter: Brent's method, then the zero of the measure's slope;
several: Nelder-Mead within the bounds. See docs/data.md.")]
pub struct OptimizeArgs {
    #[command(flatten)]
    run: RunArgs,
    /// The measure to maximise (a name in the model's [sweep.measures]).
    #[arg(
        long,
        value_name = "MEASURE",
        conflicts_with = "minimize",
        required_unless_present = "minimize"
    )]
    maximize: Option<String>,
    /// The measure to minimise.
    #[arg(long, value_name = "MEASURE")]
    minimize: Option<String>,
    /// A parameter and its bounds, `theta=0..pi/2` (repeat for several).
    #[arg(long, value_name = "NAME=LO..HI", required = true)]
    over: Vec<String>,
}

/// A bound: a number or a constant expression (`pi/2`).
fn bound(text: &str, spec: &str) -> Result<f64, Error> {
    let bad = |why: String| Error::argument("--over", format!("--over `{spec}`: {why}"));
    let mut pool = pdyn_expr::Pool::new();
    let e = pool
        .parse_scalar(text.trim())
        .map_err(|e| bad(format!("`{text}` is not an expression: {}", e.message)))?;
    let v = pool
        .eval_const(e)
        .map_err(|e| bad(format!("`{text}` is not a number ({e})")))?;
    if !v.is_finite() {
        return Err(bad(format!("`{text}` is not finite")));
    }
    Ok(v)
}

/// `pdyn optimize MODEL ...`.
pub fn run(a: OptimizeArgs) -> Result<Outcome, Error> {
    let mut model = load_model(&a.run.model)?;
    set_parameters(&mut model, &a.run.set)?;
    let (measure, maximize, option) = match (&a.maximize, &a.minimize) {
        (Some(m), _) => (m.clone(), true, "--maximize"),
        (None, Some(m)) => (m.clone(), false, "--minimize"),
        (None, None) => {
            return Err(Error::argument(
                "--maximize",
                "--maximize MEASURE or --minimize MEASURE is required",
            ))
        }
    };
    let mut over = Vec::new();
    for spec in &a.over {
        let (name, range) = spec.split_once('=').ok_or_else(|| {
            Error::argument(
                "--over",
                format!("--over: expected NAME=LO..HI, got `{spec}`"),
            )
        })?;
        let (lo, hi) = range.split_once("..").ok_or_else(|| {
            Error::argument(
                "--over",
                format!("--over: expected NAME=LO..HI, got `{spec}`"),
            )
        })?;
        over.push((name.trim().to_string(), bound(lo, spec)?, bound(hi, spec)?));
    }
    let goal = pdyn::optimize::goal_of(&model, &measure, maximize, &over, option)?;
    let names: Vec<String> = over.iter().map(|(n, _, _)| n.clone()).collect();
    let best = pdyn::optimize::run(model, &request(&a.run)?, &goal)?;
    let word = if maximize { "maximum" } else { "minimum" };
    let stdout = if a.run.json {
        let x: serde_json::Map<String, serde_json::Value> = names
            .iter()
            .zip(&best.x)
            .map(|(n, &v)| (n.clone(), json!(v)))
            .collect();
        format!(
            "{}\n",
            json!({
                "measure": measure,
                "goal": word,
                "x": x,
                "value": pdyn::output::json_num(best.value),
                "method": best.method,
                "evaluations": best.evaluations,
                "at_bound": best.at_bound,
                "slope_zero_bracket": best.slope_bracket.map(|(l, r)| [l, r]),
            })
        )
    } else {
        let mut out = format!(
            "{word} of {measure} = {:.12e} ({}, {} runs)\n",
            best.value, best.method, best.evaluations
        );
        for (n, v) in names.iter().zip(&best.x) {
            out += &format!("  {n} = {v:.15e}\n");
        }
        if let Some((l, r)) = best.slope_bracket {
            out += &format!("  the measure's slope changes sign on [{l:.15e}, {r:.15e}]\n");
        }
        if best.at_bound {
            out += "  at a bound of the interval: the optimum may lie outside it\n";
        }
        out
    };
    Ok(Outcome {
        stdout,
        stderr: String::new(),
        failure: None,
    })
}
