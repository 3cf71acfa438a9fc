//! One N-body run as a front end asks for it: the options (`pdyn run`'s flags, Python's
//! keywords) resolved against the `[nbody]` table once, here, with the limits that keep a run
//! within the machine — so the command line and Python refuse and accept the same things.

use super::output::RunInfo;
use super::run::{NbodyResult, RunOptions, Sampling};
use super::spec::{EscapeMode, IntegratorKind, NbodySpec};
use super::{build::Built, load};
use crate::options::{naming, Naming, RunOption};
use crate::{Error, Request};

/// Most per-body rows a run keeps for `trajectory.csv` (about 1 GB in memory).
pub const MAX_TRAJECTORY_ROWS: usize = 10_000_000;

/// Most steps a fixed-step run may ask for: the limit of every fixed-step run
/// ([`crate::sim::MAX_FIXED_STEPS`], hours of computing at a microsecond a step).
pub const MAX_FIXED_STEPS: f64 = crate::sim::MAX_FIXED_STEPS;

/// A run resolved and built, ready to [`Planned::execute`].
pub struct Planned {
    /// The model, with the request applied.
    pub spec: NbodySpec,
    /// What the report prints about the run.
    pub info: RunInfo,
    /// Integration options.
    pub options: RunOptions,
    /// Whether trajectories are kept (and written).
    pub trajectory: bool,
    /// The option the output times came from (named in errors about them).
    pub sampling_option: &'static str,
    built: Built,
}

/// Loads the model `source` (file `origin`) with the request's parameters, applies the
/// request and builds the simulation. Every problem is an [`Error`]: located in the file, or
/// naming the option.
pub fn plan(source: &str, origin: &str, req: &Request) -> Result<Planned, Error> {
    plan_with(source, origin, req, false)
}

/// [`plan`] for a run whose rows go only to files as it runs (`streaming`): then no limit on
/// the trajectory rows held in memory applies.
pub fn plan_with(
    source: &str,
    origin: &str,
    req: &Request,
    streaming: bool,
) -> Result<Planned, Error> {
    let ias15_accuracy = "IAS15's accuracy is `epsilon` in [nbody]";
    for (given, option, instead) in [
        (
            req.rtol.is_some(),
            RunOption::Rtol,
            ias15_accuracy.to_string(),
        ),
        (
            req.atol.is_some(),
            RunOption::Atol,
            ias15_accuracy.to_string(),
        ),
        (
            req.max_step.is_some(),
            RunOption::MaxStep,
            format!("the fixed-step integrators take {}", RunOption::Dt),
        ),
        (
            req.max_steps.is_some(),
            RunOption::MaxSteps,
            format!("shorten the run with {}", RunOption::TEnd),
        ),
    ] {
        if given {
            return Err(Error::argument(
                option.name(),
                format!("{option} does not apply to N-body models ({instead})"),
            ));
        }
    }
    let mut spec = load(source, origin, &req.params)?;
    if let Some(m) = &req.method {
        spec.integrator = IntegratorKind::from_name(m).ok_or_else(|| {
            let list = match naming() {
                Naming::Flags => " (--method help)",
                Naming::Keywords => "",
            };
            Error::argument(
                RunOption::Method.name(),
                format!(
                    "{}: N-body models take whfast, ias15 or leapfrog{list}",
                    RunOption::Method.with(m)
                ),
            )
        })?;
        if spec.integrator == IntegratorKind::WhFast && spec.tree.is_some() {
            return Err(Error::argument(
                RunOption::Method.name(),
                format!(
                    "{}: WHFast with the tree (gravity = \"tree\") is not supported; use leapfrog",
                    RunOption::Method.with("whfast")
                ),
            ));
        }
    }
    if let Some(dt) = req.dt {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::argument(
                RunOption::Dt.name(),
                format!("{} must be > 0 (got {dt})", RunOption::Dt),
            ));
        }
        spec.dt = Some((dt, 0..0));
    }
    if let Some(t) = req.t_end {
        if !(t.is_finite() && t > 0.0) {
            return Err(Error::argument(
                RunOption::TEnd.name(),
                format!("{} must be > 0 (got {t})", RunOption::TEnd),
            ));
        }
        spec.t_end = Some(t);
    }
    let drift_tolerance = match req.drift_tolerance {
        Some(d) if !(d.is_finite() && d > 0.0) => {
            return Err(Error::argument(
                RunOption::DriftTolerance.name(),
                format!("{} must be > 0 (got {d})", RunOption::DriftTolerance),
            ))
        }
        Some(d) => d,
        None => spec
            .drift_tolerance
            .unwrap_or(crate::sim::DEFAULT_DRIFT_TOLERANCE),
    };
    let Some(t_end) = spec.t_end else {
        return Err(Error::Model {
            error: pdyn_mech::ModelError::new(origin, spec.table_span.clone(), "no end time")
                .help(format!("t_end = ... in [nbody], or {}", RunOption::TEnd)),
            source: source.into(),
        });
    };
    let t_eval = req.t_eval.as_deref().unwrap_or_default();
    let given = [
        req.points.is_some(),
        req.output_dt.is_some(),
        !t_eval.is_empty(),
    ];
    if given.iter().filter(|g| **g).count() > 1 {
        return Err(Error::argument(
            "",
            format!(
                "give only one of {}, {} and {}",
                RunOption::Points,
                RunOption::OutputDt,
                RunOption::TEval
            ),
        ));
    }
    // The option the output times came from, as errors about them name it.
    let (sampling, option) = if let Some(n) = req.points {
        (Sampling::Points(n), RunOption::Points.name())
    } else if let Some(dt) = req.output_dt {
        (Sampling::Every(dt), RunOption::OutputDt.name())
    } else if !t_eval.is_empty() {
        (Sampling::Times(t_eval.to_vec()), RunOption::TEval.name())
    } else if let Some(dt) = spec.output_dt {
        (Sampling::Every(dt), "output_dt")
    } else {
        (Sampling::Points(spec.points.unwrap_or(201)), "points")
    };
    // Counted, not listed (a list of 10⁷ times would be most of a streaming run's memory).
    let n_outputs = super::run::Schedule::new(t_end, &sampling, None)
        .map_err(|m| Error::argument(option, format!("{option}: {m}")))?
        .raw_len();

    // A fixed step absurdly small for the span would run for days: say so instead.
    if let (Some((dt, span)), true) = (&spec.dt, spec.integrator != IntegratorKind::Ias15) {
        let steps = t_end / dt;
        if steps > MAX_FIXED_STEPS {
            let message = format!(
                "t_end/dt = {steps:.3e} steps, more than {MAX_FIXED_STEPS:.0e}: dt = {dt} is far too small for t_end = {t_end}"
            );
            return Err(if span.is_empty() {
                Error::argument(
                    RunOption::Dt.name(),
                    format!("{}: {message}", RunOption::Dt),
                )
            } else {
                Error::Model {
                    error: pdyn_mech::ModelError::new(origin, span.clone(), message),
                    source: source.into(),
                }
            });
        }
    }
    let built = super::build(&spec, source)?;
    let n_bodies = built.sim.len();
    let trajectory = spec
        .trajectory
        .unwrap_or(n_bodies <= super::run::TRAJECTORY_LIMIT);
    // Trajectories are kept in memory until written: refuse what would not fit.
    if trajectory
        && !(streaming && req.out.is_some())
        && n_bodies.saturating_mul(n_outputs) > MAX_TRAJECTORY_ROWS
    {
        return Err(Error::argument(
            option,
            format!(
                "{option}: {n_outputs} outputs of {n_bodies} bodies are more than {MAX_TRAJECTORY_ROWS} trajectory rows; \
                 ask for fewer outputs (or trajectory = false)"
            ),
        ));
    }
    let info = RunInfo {
        integrator: spec.integrator.name(),
        dt: built.config.dt,
        t_end,
        gravity: match spec.tree {
            None => "direct".into(),
            Some(t) => format!(
                "tree (theta = {}, {})",
                t.theta,
                if t.quadrupole {
                    "quadrupole"
                } else {
                    "monopole"
                }
            ),
        },
        n_bodies,
        drift_tolerance,
    };
    let options = RunOptions {
        t_end,
        sampling,
        drift_tolerance,
        trajectory,
        integrator: spec.integrator,
        collisions: spec.collisions,
        escape: spec.escape.map_or(EscapeMode::Stop, |(_, m)| m),
        interrupt: req.interrupt.clone(),
    };
    Ok(Planned {
        spec,
        info,
        options,
        trajectory,
        sampling_option: option,
        built,
    })
}

impl Planned {
    /// The steps the run will take (for IAS15, `t_end` over the first step: a guess).
    pub fn estimated_steps(&self) -> u64 {
        let n = self.options.t_end / self.info.dt;
        if n.is_finite() && n > 0.0 {
            n.ceil().min(u64::MAX as f64) as u64
        } else {
            0
        }
    }

    /// Integrates. A run that stops early (a collision, an escape, a failed step) is a result
    /// with its `failure` set; an error here is about the output times only.
    pub fn execute(self) -> Result<(NbodySpec, RunInfo, NbodyResult), Error> {
        self.execute_with(None, &mut |_| {}, None, None)
    }

    /// Integrates, appending rows to `stream` as they are recorded and telling `steps` the
    /// steps taken at each output; checkpoints and a restart as in [`super::run::run_with`].
    pub fn execute_with(
        self,
        stream: Option<&mut super::output::Stream>,
        steps: &mut dyn FnMut(u64),
        checkpoints: Option<&mut crate::checkpoint::Checkpointer>,
        resume: Option<&serde_json::Value>,
    ) -> Result<(NbodySpec, RunInfo, NbodyResult), Error> {
        let option = self.sampling_option;
        let res = super::run::run_with(
            self.built,
            &self.options,
            stream,
            steps,
            checkpoints,
            resume,
        )
        .map_err(|e| match e {
            super::run::RunError::Sampling(m) => Error::argument(option, m.to_string()),
            super::run::RunError::Write(e) => e,
        })?;
        Ok((self.spec, self.info, res))
    }
}
