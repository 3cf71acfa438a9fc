//! `pdyn check`'s output: a numerical run against the model's closed-form solution.

use super::Report;
use crate::sim::{self, SimError};
use crate::{Error, Request};

/// Integrates `model` (parameters set) with the options of `req` and compares every column
/// with the closed form; text, or JSON when `json`.
pub fn report(mut model: pdyn_mech::Model, req: &Request, json: bool) -> Result<Report, Error> {
    let set = sim::request::settings(&model, req)?;
    let exact = sim::exact::closed_form(&mut model).map_err(|e| {
        sim::request::located(
            &model,
            "no exact solution to check against: ",
            SimError::NoClosedForm(e),
        )
    })?;
    let prep = sim::request::prepare(&mut model, req.jit)?;
    let rep =
        sim::exact::check(&prep, &exact, &set).map_err(|e| sim::request::located(&model, "", e))?;
    let (scales, relative) = (rep.scales(), rep.relative_errors());
    let worst = relative.iter().copied().fold(0.0, f64::max);
    let failure = rep.run.failure.clone().map(|failure| Error::Integration {
        origin: model.origin.clone(),
        failure: Box::new(failure),
    });
    if json {
        let v = serde_json::json!({
            "model": model.name,
            "method": rep.run.method.to_string(),
            "rows": rep.run.rows.len(),
            "errors": rep.errors.iter().zip(scales.iter().zip(&relative)).map(|((n, e, s), (scale, rel))| serde_json::json!({"name": n, "max_abs_error": e, "max_abs_value": s, "scale": scale, "relative_error": rel})).collect::<Vec<_>>(),
            "max_relative_error": worst,
            "formula_relative_gap": rep.formula_gap,
        });
        return Ok(Report {
            stdout: format!("{v:#}\n"),
            stderr: String::new(),
            failure,
        });
    }
    let mut out = format!(
        "{}\n{} vs the closed form at {} times (t = 0..{}):\n",
        model.name,
        rep.run.method,
        rep.run.rows.len(),
        set.t_end
    );
    for ((n, e, s), rel) in rep.errors.iter().zip(&relative) {
        out += &format!(
            "  {n:<12} max |error| {e:.3e}   (max |value| {s:.3e})   relative {rel:.3e}\n"
        );
    }
    out += &format!(
        "largest error relative to the size of the solution: {worst:.3e}\n\
         (each column against the largest max |value| of its order: coordinates together, rates together)\n"
    );
    if let Some(gap) = rep.formula_gap {
        out += &format!(
            "the exact solution is evaluated stably (matrix exponential); the printed formula \
             evaluated in floating point differs from it by {gap:.3e} relative{}\n",
            if gap > sim::exact::EXACT_AGREEMENT {
                " — near a resonance its terms cancel: do not evaluate it as printed"
            } else {
                ""
            }
        );
    }
    Ok(Report {
        stdout: out,
        stderr: String::new(),
        failure,
    })
}
