//! One molecular-dynamics run as a front end asks for it: the options (`pdyn run`'s flags,
//! Python's keywords) resolved against the `[md]` table once, here, so the command line and
//! Python refuse and accept the same things.

use super::{load, MdSpec};
use crate::options::RunOption;
use crate::{Error, Request};

/// Loads the model `source` (file `origin`) with the request's parameters and applies the
/// request: the spec to build and the drift tolerance of the run. The options of the ODE
/// integrators are refused by name: they have no meaning for fixed-step velocity Verlet.
pub fn plan(source: &str, origin: &str, req: &Request) -> Result<(MdSpec, f64), Error> {
    let meaningless = [
        (RunOption::Method, req.method.is_some()),
        (RunOption::Rtol, req.rtol.is_some()),
        (RunOption::Atol, req.atol.is_some()),
        (RunOption::MaxStep, req.max_step.is_some()),
        (RunOption::MaxSteps, req.max_steps.is_some()),
        (RunOption::Points, req.points.is_some()),
        (RunOption::OutputDt, req.output_dt.is_some()),
        (
            RunOption::TEval,
            req.t_eval.as_ref().is_some_and(|t| !t.is_empty()),
        ),
    ];
    if let Some((opt, _)) = meaningless.iter().find(|(_, given)| *given) {
        return Err(Error::argument(
            opt.name(),
            format!(
                "{opt} has no meaning for a molecular-dynamics model (fixed-step velocity Verlet); \
                 use {}, {} (run length) and the [md] keys steps, thermo_every, dump_every",
                RunOption::Dt,
                RunOption::TEnd
            ),
        ));
    }
    let mut spec = load(source, origin, &req.params)?;
    if let Some(dt) = req.dt {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::argument(
                RunOption::Dt.name(),
                format!("{} must be a positive number, got {dt}", RunOption::Dt),
            ));
        }
        spec.dt.value = dt;
    }
    if let Some(t) = req.t_end {
        let steps = t / spec.dt.value;
        if !(steps.is_finite() && steps >= 0.0 && steps <= super::spec::MAX_STEPS as f64) {
            return Err(Error::argument(
                RunOption::TEnd.name(),
                format!(
                    "{} with dt = {} is not a valid number of steps",
                    RunOption::TEnd.with(t),
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
                RunOption::DriftTolerance.name(),
                format!(
                    "{} must be a positive number, got {d}",
                    RunOption::DriftTolerance
                ),
            ))
        }
        None => crate::sim::DEFAULT_DRIFT_TOLERANCE,
    };
    Ok((spec, drift_tolerance))
}
