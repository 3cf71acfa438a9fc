//! Typed failures. Numerical failures carry the time, the state and the solution computed so
//! far, so that a caller can inspect or plot what happened before the failure.

use crate::Solution;
use std::fmt;

/// Where a numerical failure happened: time, state, and the partial solution.
///
/// Its `Debug` output summarises the partial solution (number of outputs, statistics) instead
/// of printing every state.
#[derive(Clone, PartialEq)]
pub struct FailurePoint {
    /// Time of the last accepted state.
    pub t: f64,
    /// The last accepted state.
    pub y: Vec<f64>,
    /// Everything computed up to `t` (outputs, events, statistics).
    pub partial: Box<Solution>,
}

impl fmt::Debug for FailurePoint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("FailurePoint")
            .field("t", &self.t)
            .field("y", &self.y)
            .field(
                "partial",
                &format_args!(
                    "Solution {{ {} outputs, {} events, stats: {:?} }}",
                    self.partial.len(),
                    self.partial.events.len(),
                    self.partial.stats
                ),
            )
            .finish()
    }
}

/// Errors of the solvers.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum OdeError {
    /// The options or the initial data are unusable (dimension mismatch, non-finite `y0`,
    /// negative tolerances, unsorted `t_eval`, missing `h0` for a fixed-step method, …).
    InvalidInput {
        /// What is wrong.
        reason: String,
    },
    /// The step size fell below `|t| · 10 · ε` (Hairer's test `0.1|h| ≤ |t|·uround`).
    StepSizeUnderflow {
        /// The step size that was too small.
        h: f64,
        /// Time, state, partial solution.
        at: FailurePoint,
    },
    /// `f` or the new state became non-finite (NaN or ±∞) and reducing the step did not help.
    NonFinite {
        /// Time, state, partial solution.
        at: FailurePoint,
    },
    /// More than `max_steps` step attempts.
    MaxSteps {
        /// The limit that was reached.
        max_steps: usize,
        /// Time, state, partial solution.
        at: FailurePoint,
    },
    /// The explicit method detected stiffness and [`crate::StiffnessAction::Error`] was set.
    Stiff {
        /// Time, state, partial solution.
        at: FailurePoint,
    },
    /// The Newton matrix of an implicit method is singular even after step reductions.
    SingularMatrix {
        /// Time, state, partial solution.
        at: FailurePoint,
    },
    /// A step of the smallest size allowed ([`crate::Options::min_step`]) failed its error
    /// test.
    MinStep {
        /// The limit.
        min_step: f64,
        /// Time, state, partial solution.
        at: FailurePoint,
    },
    /// The nonlinear solve of a fixed-step implicit method did not converge.
    NoConvergence {
        /// Time, state, partial solution.
        at: FailurePoint,
    },
    /// [`crate::Options::interrupt`] was set: stopped at the last accepted step.
    Interrupted {
        /// Time, state, partial solution.
        at: FailurePoint,
    },
}

impl OdeError {
    /// Moves the partial solution out of the error (leaving an empty one), for a caller that
    /// keeps both the error and the solution without copying the solution.
    pub fn take_partial(&mut self) -> Option<Solution> {
        let at = match self {
            OdeError::InvalidInput { .. } => return None,
            OdeError::StepSizeUnderflow { at, .. }
            | OdeError::NonFinite { at }
            | OdeError::MaxSteps { at, .. }
            | OdeError::MinStep { at, .. }
            | OdeError::Stiff { at }
            | OdeError::SingularMatrix { at }
            | OdeError::NoConvergence { at }
            | OdeError::Interrupted { at } => at,
        };
        let empty = Solution::new(at.partial.method, at.partial.n);
        Some(std::mem::replace(&mut *at.partial, empty))
    }

    /// The failure point (time, state, partial solution), for numerical failures.
    pub fn failure_point(&self) -> Option<&FailurePoint> {
        match self {
            OdeError::InvalidInput { .. } => None,
            OdeError::StepSizeUnderflow { at, .. }
            | OdeError::NonFinite { at }
            | OdeError::MaxSteps { at, .. }
            | OdeError::MinStep { at, .. }
            | OdeError::Stiff { at }
            | OdeError::SingularMatrix { at }
            | OdeError::NoConvergence { at }
            | OdeError::Interrupted { at } => Some(at),
        }
    }
}

impl fmt::Display for OdeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            OdeError::InvalidInput { reason } => write!(f, "invalid input: {reason}"),
            OdeError::StepSizeUnderflow { h, at } => {
                write!(f, "step size underflow (h = {h:e}) at t = {}", at.t)
            }
            OdeError::NonFinite { at } => write!(f, "non-finite state at t = {}", at.t),
            OdeError::MaxSteps { max_steps, at } => {
                write!(
                    f,
                    "more than max_steps = {max_steps} steps needed; stopped at t = {}",
                    at.t
                )
            }
            OdeError::MinStep { min_step, at } => write!(
                f,
                "the step size needed is below min_step = {min_step:e} at t = {}",
                at.t
            ),
            OdeError::Stiff { at } => {
                write!(f, "the problem seems to become stiff at t = {}", at.t)
            }
            OdeError::SingularMatrix { at } => {
                write!(f, "singular iteration matrix at t = {}", at.t)
            }
            OdeError::NoConvergence { at } => {
                write!(f, "nonlinear iteration did not converge at t = {}", at.t)
            }
            OdeError::Interrupted { at } => write!(f, "interrupted at t = {}", at.t),
        }
    }
}

impl std::error::Error for OdeError {}

pub(crate) fn invalid(reason: impl Into<String>) -> OdeError {
    OdeError::InvalidInput {
        reason: reason.into(),
    }
}

/// The solve ends here: its solution is moved into the error (not copied: a long run's
/// outputs can be gigabytes, and an interrupted one should stop at once).
pub(crate) fn point(t: f64, y: &[f64], partial: &mut Solution) -> FailurePoint {
    let empty = Solution::new(partial.method, partial.n);
    FailurePoint {
        t,
        y: y.to_vec(),
        partial: Box::new(std::mem::replace(partial, empty)),
    }
}
