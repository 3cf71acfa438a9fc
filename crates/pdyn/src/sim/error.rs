//! [`SimError`]: why a model could not be prepared or run, and [`RunFailure`]: where an
//! integration that started stopped early (the partial result is kept).

use crate::options::RunOption;
use pdyn_expr::compile::CompileError;
use pdyn_mech::dsolve::DsolveError;
use pdyn_mech::DeriveError;
use pdyn_ode::OdeError;
use std::fmt;

/// Why a model could not be prepared for running, or a run could not start.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum SimError {
    /// The equations of motion could not be derived.
    Derive(DeriveError),
    /// Something the run needs (equations, an output column, an event, a sweep measure, the
    /// initial conditions) could not be compiled, e.g. it refers to a name without a value.
    Compile {
        /// What was being compiled (`event `hits``, `sweep measure`...); empty for the equations.
        what: String,
        /// Why.
        error: CompileError,
    },
    /// A method name that pdyn does not know.
    UnknownMethod {
        /// The name given.
        name: String,
    },
    /// A fixed-step method without a step.
    NeedsStep {
        /// The method.
        method: String,
    },
    /// No end time in the model or on the command line.
    NoEndTime,
    /// An end time that is not a positive finite number.
    InvalidEndTime(f64),
    /// `t_eval` not increasing or outside `[0, t_end]`.
    InvalidTEval {
        /// The end time.
        t_end: f64,
    },
    /// A symplectic method on accelerations that depend on velocities.
    NotSeparable {
        /// The method.
        method: String,
    },
    /// The integrator refused to start (bad options), before any step.
    Integrator(OdeError),
    /// No closed-form solution for `--method exact` / `pdyn check`.
    NoClosedForm(ClosedFormError),
    /// Parameter values that break a physical requirement (a sweep's run with a mass ≤ 0).
    InvalidValue(pdyn_mech::validity::InvalidValue),
    /// The initial state does not satisfy a constraint.
    InitialStateViolatesConstraint {
        /// The constraint's name (or equation).
        label: String,
        /// `position` (f = 0) or `velocity` (df/dt = 0).
        level: &'static str,
        /// The residual at t = 0.
        residual: f64,
        /// The size of the constraint's terms (what the residual is compared with).
        scale: f64,
    },
    /// A contact that cannot start or go on: penetrated at t = 0, coefficients out of range
    /// after `--set`, modes that contradict their own forces.
    Contact {
        /// What is wrong, naming the contact and the time.
        message: String,
    },
    /// An initial value or rate that names an `[unknowns]` quantity (`rate = "omega"`): only
    /// `pdyn forces` can use it; the error points at it in the model file.
    UnknownInitialCondition(Box<pdyn_mech::ModelError>),
    /// A run setting outside its valid range.
    InvalidOption {
        /// The option (named as the front end names it when shown).
        option: crate::options::RunOption,
        /// The value given.
        value: String,
        /// What would be valid.
        requirement: String,
    },
    /// A `[sweep]` whose combinations of values are more runs than `limit`.
    TooManySweepRuns {
        /// The most runs a sweep may have.
        limit: usize,
    },
}

/// Why a model's equations have no closed form here.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum ClosedFormError {
    /// Derivation failed.
    Derive(DeriveError),
    /// The accelerations were not solved symbolically (too many unknowns).
    NotSolved,
    /// dsolve could not solve them.
    Dsolve(DsolveError),
    /// The solution could not be compiled.
    Compile(CompileError),
    /// The model has contacts or event actions: its motion switches between sets of
    /// equations, and no one closed form describes it.
    Hybrid,
    /// Solving in symbols needed more than `work` units of simplification.
    TooCostly {
        /// The budget that ran out.
        work: u64,
    },
}

impl fmt::Display for ClosedFormError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ClosedFormError::Derive(e) => write!(f, "{e}"),
            ClosedFormError::NotSolved => {
                f.write_str("the equations were not solved for the accelerations symbolically")
            }
            ClosedFormError::Dsolve(e) => write!(f, "{e}"),
            ClosedFormError::Hybrid => f.write_str(
                "the model has contacts or event actions: its motion switches between sets of \
                 equations at its impacts and mode changes, so no one closed form describes it \
                 (`pdyn run` follows it through the switches)",
            ),
            ClosedFormError::Compile(e) => write!(f, "{e}"),
            ClosedFormError::TooCostly { work } => write!(
                f,
                "solving the equations in symbols exceeds its budget ({work} simplification \
                 units; the solution would be too large to read): `pdyn check` and \
                 `pdyn run --method exact` solve them at the parameter values, and `pdyn \
                 dsolve` on the equations gives the symbolic solution in full"
            ),
        }
    }
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SimError::Derive(e) => write!(f, "{e}"),
            SimError::Compile { what, error } if what.is_empty() => write!(f, "{error}"),
            SimError::Compile { what, error } => write!(f, "{what}: {error}"),
            SimError::UnknownMethod { name } => write!(
                f,
                "unknown method `{name}`; {} lists them",
                crate::options::methods_list()
            ),
            SimError::NeedsStep { method } => write!(
                f,
                "method `{method}` takes fixed steps: give the step with {} (or dt = ... in [simulate])",
                RunOption::Dt
            ),
            SimError::NoEndTime => {
                write!(f, "no end time: add t_end = ... under [simulate] or give {}", RunOption::TEnd)
            }
            SimError::InvalidEndTime(t) => write!(f, "t_end must be a positive time, got {t}"),
            SimError::InvalidTEval { t_end } => {
                write!(f, "t_eval must be increasing times within [0, {t_end}]")
            }
            SimError::NotSeparable { method } => write!(
                f,
                "method `{method}` needs accelerations that do not depend on velocities; this model's do \
                 (drag, dampers, friction...): use gauss4/gauss6 or an adaptive method"
            ),
            SimError::Integrator(e) => write!(f, "cannot integrate: {e}"),
            SimError::NoClosedForm(e) => write!(f, "{e}"),
            SimError::InvalidValue(e) => write!(f, "{e}"),
            SimError::InitialStateViolatesConstraint {
                label,
                level,
                residual,
                scale,
            } => write!(
                f,
                "the initial state violates constraint `{label}` at the {level} level: its \
                 residual is {residual:.3e} (its terms are of size {scale:.3e}); give initial \
                 values and rates that satisfy it"
            ),
            SimError::InvalidOption {
                option,
                value,
                requirement,
            } => write!(f, "{option} must be {requirement}, got {value}"),
            SimError::TooManySweepRuns { limit } => write!(
                f,
                "[sweep] must be at most {limit} runs (every combination of the swept values), got more runs"
            ),
            SimError::Contact { message } => f.write_str(message),
            SimError::UnknownInitialCondition(e) => f.write_str(&e.message),
        }
    }
}

impl std::error::Error for SimError {}

/// An integration that stopped before the end: where, in what state, and why. The rows up to
/// that point are in the [`super::RunResult`].
#[derive(Debug, Clone)]
pub struct RunFailure {
    /// Time of the last accepted state.
    pub t: f64,
    /// The state there, named.
    pub state: Vec<(String, f64)>,
    /// The integrator's error.
    pub error: OdeError,
    /// Where an explicit method's stiffness test fired before the failure (Hairer's test, as
    /// in `dopri5.f`): the likely reason for running out of steps.
    pub stiff_at: Option<f64>,
    /// What is not finite at that state, by name (`x''`, `a.y`, `energy`): where a
    /// non-finite state came from (a division by zero, a function outside its domain).
    pub non_finite: Vec<String>,
}

impl fmt::Display for RunFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let state: Vec<String> = self
            .state
            .iter()
            .map(|(nm, v)| format!("{nm} = {v:.6e}"))
            .collect();
        write!(
            f,
            "integration failed at t = {:.9e}: {}\n  state: {}",
            self.t,
            self.error,
            state.join(", ")
        )?;
        if !self.non_finite.is_empty() {
            write!(
                f,
                "\n  not finite at that state: {} (a division by zero or a function outside \
                 its domain in what defines them)",
                self.non_finite.join(", ")
            )?;
        }
        if let Some(at) = self.stiff_at {
            write!(
                f,
                "\n  the problem seems to have become stiff at t = {at:.6e} (the explicit method's \
                 stiffness test fired): use {}, or {} to switch when it does",
                RunOption::Method.with("radau5"),
                RunOption::Method.with("auto")
            )?;
        }
        Ok(())
    }
}
