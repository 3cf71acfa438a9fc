//! One mechanics run as a front end asks for it: the options (`pdyn run`'s flags, Python's
//! keywords) merged with the model's `[simulate]` once, here, then the run — numerical or the
//! closed form (`method = "exact"`) — and its failure, including a table that holds NaN. The
//! command line and Python call these and only render what comes back.

use super::measured::NonFinite;
use super::{JitMode, Prepared, RunResult, RunSettings, SimError};
use crate::options::RunOption;
use crate::{Error, Request};
use pdyn_mech::model::spec::SimulateSpec;
use pdyn_mech::Model;

/// A simulation error located in the model file where it has a place there, else with the
/// file's name and what was being attempted (`context`).
pub fn located(model: &Model, context: &'static str, error: SimError) -> Error {
    if let SimError::UnknownInitialCondition(error) = error {
        return Error::Model {
            error: *error,
            source: model.source.as_str().into(),
        };
    }
    Error::Sim {
        origin: model.origin.clone(),
        context,
        error,
    }
}

/// The model's `[simulate]` merged with `req`. A value the runner refuses is shown at its key
/// in the file when it came from there, and names the option otherwise.
pub fn settings(model: &Model, req: &Request) -> Result<RunSettings, Error> {
    // Every command that runs the motion reads its settings first: an initial condition left
    // to `pdyn forces` is the first thing to report, at its place in the file.
    if let Some(error) = model.unknown_initial_error() {
        return Err(located(
            model,
            "",
            SimError::UnknownInitialCondition(Box::new(error)),
        ));
    }
    let s = &model.run.simulate;
    // A method named in the file is checked here, where its place in the file is known.
    if let (None, Some((m, span))) = (&req.method, &s.method) {
        if super::method_by_name(m).is_none() {
            let error = pdyn_mech::ModelError::new(
                &model.origin,
                span.clone(),
                format!("unknown method `{m}`"),
            )
            .help(format!("{} lists them", crate::options::methods_list()));
            return Err(Error::Model {
                error,
                source: model.source.as_str().into(),
            });
        }
    }
    let overrides = SimulateSpec {
        t_end: req.t_end,
        method: req.method.clone().map(|m| (m, 0..0)),
        rtol: req.rtol,
        atol: req.atol,
        dt: req.dt,
        max_step: req.max_step,
        max_steps: req.max_steps,
        points: req.points,
        output_dt: req.output_dt,
        drift_tolerance: req.drift_tolerance,
    };
    let mut file = s.clone();
    if req.t_eval.is_some() || req.points.is_some() || req.output_dt.is_some() {
        // Output times given by the front end replace the file's spacing: the file's `points`
        // would otherwise win over `--output-dt` (points come first in `output_times`).
        file.output_dt = None;
        file.points = None;
    }
    let mut set = RunSettings::resolve(&file, &overrides, req.t_eval.clone())
        .map_err(|e| located(model, "", e))?;
    set.interrupt = req.interrupt.clone();
    file_value_error(model, req, set.validate())?;
    Ok(set)
}

/// A setting the runner refuses that was written in the file, not given by the front end, is
/// shown at its key in `[simulate]` (the runner names the option, with no place).
fn file_value_error(
    model: &Model,
    req: &Request,
    checked: Result<(), SimError>,
) -> Result<(), Error> {
    let Err(error) = checked else { return Ok(()) };
    let (option, message) = match &error {
        SimError::InvalidOption {
            option,
            value,
            requirement,
        } => (*option, format!("must be {requirement}, got {value}")),
        SimError::InvalidEndTime(t) => {
            (RunOption::TEnd, format!("must be a positive time, got {t}"))
        }
        _ => return Err(located(model, "", error)),
    };
    let from_file = match option {
        RunOption::TEnd => req.t_end.is_none(),
        RunOption::Rtol => req.rtol.is_none(),
        RunOption::Atol => req.atol.is_none(),
        RunOption::Dt => req.dt.is_none(),
        RunOption::MaxStep => req.max_step.is_none(),
        RunOption::OutputDt => req.output_dt.is_none(),
        RunOption::Points => req.points.is_none(),
        RunOption::MaxSteps => req.max_steps.is_none(),
        _ => false,
    };
    let key = option.keyword();
    let span = model.run.simulate_spans.iter().find(|(k, _)| *k == key);
    match span {
        Some((_, span)) if from_file => {
            let error = pdyn_mech::ModelError::new(
                &model.origin,
                span.clone(),
                format!("`{key}` in [simulate] {message}"),
            )
            .help(format!(
                "change it in the file, or override it with {option}"
            ));
            Err(Error::Model {
                error,
                source: model.source.as_str().into(),
            })
        }
        _ => Err(located(model, "", error)),
    }
}

/// Derives and compiles the model: native code with `jit` where there is a JIT.
pub fn prepare(model: &mut Model, jit: JitMode) -> Result<Prepared, Error> {
    super::prepare_with_jit(model, &super::run_options(), jit).map_err(|e| located(model, "", e))
}

/// Runs `prep` (compiled from `model`) as `set` says: integrates, or evaluates the closed form
/// when the method is `exact`. Returns the result and its failure, if any: the integration's,
/// or output columns that hold NaN or infinity (exit code 1 on the command line).
pub fn execute(
    model: &mut Model,
    prep: &Prepared,
    set: &RunSettings,
) -> Result<(RunResult, Option<Error>), Error> {
    crate::data::reset_data_range(model);
    let res = if set.method == "exact" {
        if prep.initial_overridden {
            return Err(Error::argument(
                RunOption::Initial.name(),
                format!(
                    "{}: the closed form solves for the model's own initial conditions; \
                     change them in the file, or use a numerical method",
                    RunOption::Initial
                ),
            ));
        }
        let exact = super::exact::closed_form(model).map_err(|e| {
            let context = match crate::options::naming() {
                crate::options::Naming::Flags => "--method exact: ",
                crate::options::Naming::Keywords => "method=\"exact\": ",
            };
            located(model, context, SimError::NoClosedForm(e))
        })?;
        super::exact::run_exact(prep, &exact, set).map_err(|e| located(model, "", e))?
    } else {
        super::run(prep, set).map_err(|e| located(model, "", e))?
    };
    let left_data = || crate::data::left_data_range(model);
    let failure = res
        .failure
        .clone()
        .map(|failure| {
            left_data().unwrap_or(Error::Integration {
                origin: model.origin.clone(),
                failure: Box::new(failure),
            })
        })
        .or_else(|| non_finite(&model.origin, &res).map(|(_, e)| left_data().unwrap_or(e)));
    Ok((res, failure))
}

/// The columns of a finished run's table that hold NaN or infinity, with the error they make;
/// `None` when every value is finite.
pub fn non_finite(origin: &str, res: &RunResult) -> Option<(NonFinite, Error)> {
    let nf = NonFinite::of_rows(&res.rows)?;
    let error = nf.error(origin, &res.columns);
    Some((nf, error))
}

/// Starts the run of `prep` (compiled from `model`) from other initial values: `values` names
/// state components (`x`, `x'`, as [`Prepared::state_names`]). An unknown name or a value that
/// is not finite names the option; a state off the model's constraints is refused as the
/// file's own initial values are. The closed form (`method = "exact"`) solves for the file's
/// initial conditions and refuses them (see [`execute`]).
pub fn set_initial(
    model: &mut Model,
    prep: &mut Prepared,
    values: &[(String, f64)],
) -> Result<(), Error> {
    let option = RunOption::Initial;
    for (name, value) in values {
        let Some(i) = prep.state_names.iter().position(|s| s == name) else {
            return Err(Error::argument(
                option.name(),
                format!(
                    "{option}: `{name}` is not a state component (state: {})",
                    prep.state_names.join(", ")
                ),
            ));
        };
        if !value.is_finite() {
            return Err(Error::argument(
                option.name(),
                format!("{option}: `{name}` = {value} is not a finite number"),
            ));
        }
        prep.y0[i] = *value;
    }
    super::check_constraints_at_start(model, &prep.system, &prep.y0)
        .map_err(|e| located(model, "", e))?;
    prep.initial_overridden = !values.is_empty();
    Ok(())
}
