//! One molecular-dynamics run as a front end asks for it: the options (`pdyn run`'s flags,
//! Python's keywords) resolved against the `[md]` table once, here, so the command line and
//! Python refuse and accept the same things.

use super::{load, MdSpec};
use crate::Error;

/// The options of one run, each `None` (or empty) when not given: the `[md]` table applies.
/// The options of the ODE integrators are carried only to be refused by name: they have no
/// meaning for fixed-step velocity Verlet.
#[derive(Clone, Debug, Default)]
pub struct Request {
    /// Time step.
    pub dt: Option<f64>,
    /// Run length (`steps = t_end / dt`).
    pub t_end: Option<f64>,
    /// Relative energy drift that is reported.
    pub drift_tolerance: Option<f64>,
    /// Refused (see above).
    pub method: Option<String>,
    /// Refused.
    pub rtol: Option<f64>,
    /// Refused.
    pub atol: Option<f64>,
    /// Refused.
    pub max_step: Option<f64>,
    /// Refused.
    pub max_steps: Option<usize>,
    /// Refused.
    pub points: Option<usize>,
    /// Refused.
    pub output_dt: Option<f64>,
    /// Refused.
    pub t_eval: Vec<f64>,
}

/// Loads the model `source` (file `origin`) with parameters `set` and applies `req`: the spec
/// to build and the drift tolerance of the run.
pub fn plan(
    source: &str,
    origin: &str,
    set: &[(String, f64)],
    req: &Request,
) -> Result<(MdSpec, f64), Error> {
    let meaningless = [
        ("--method", req.method.is_some()),
        ("--rtol", req.rtol.is_some()),
        ("--atol", req.atol.is_some()),
        ("--max-step", req.max_step.is_some()),
        ("--max-steps", req.max_steps.is_some()),
        ("--points", req.points.is_some()),
        ("--output-dt", req.output_dt.is_some()),
        ("--t-eval", !req.t_eval.is_empty()),
    ];
    if let Some((opt, _)) = meaningless.iter().find(|(_, given)| *given) {
        return Err(Error::argument(
            *opt,
            format!(
                "{opt} has no meaning for a molecular-dynamics model (fixed-step velocity Verlet); \
                 use --dt, --t-end (run length) and the [md] keys steps, thermo_every, dump_every"
            ),
        ));
    }
    let mut spec = load(source, origin, set)?;
    if let Some(dt) = req.dt {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::argument(
                "--dt",
                format!("--dt must be a positive number, got {dt}"),
            ));
        }
        spec.dt.value = dt;
    }
    if let Some(t) = req.t_end {
        let steps = t / spec.dt.value;
        if !(steps.is_finite() && steps >= 0.0 && steps <= super::spec::MAX_STEPS as f64) {
            return Err(Error::argument(
                "--t-end",
                format!(
                    "--t-end {t} with dt = {} is not a valid number of steps",
                    spec.dt.value
                ),
            ));
        }
        spec.steps = steps.round() as u64;
    }
    let drift_tolerance = match req.drift_tolerance {
        Some(d) if d.is_finite() && d > 0.0 => d,
        Some(d) => {
            return Err(Error::argument(
                "--drift-tolerance",
                format!("--drift-tolerance must be a positive number, got {d}"),
            ))
        }
        None => crate::sim::DEFAULT_DRIFT_TOLERANCE,
    };
    Ok((spec, drift_tolerance))
}
