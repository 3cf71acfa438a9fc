//! Watching an integration step by step, and continuing one from where it was saved.
//!
//! [`solve_observed`] runs an explicit adaptive pair (DOPRI5, Tsit5, RK23, DOP853, Vern9) as
//! [`crate::solve_with_events`] does and calls an observer after every accepted step, with
//! the outputs produced so far (which it may take out of the [`Solution`], keeping memory
//! bounded) and, on demand, the integrator's whole state between two steps
//! ([`Accepted::state`]). Started again from that [`ResumeState`] with the same system,
//! span, options and events, the solve takes the same steps and produces the same outputs,
//! bit for bit, as the solve that was never stopped: the state holds everything the next
//! step reads — `t`, `y`, the proposed step, the PI controller's memory (`facold`), the first
//! stage (FSAL), the counters and statistics, the stiffness detector's counts, the event
//! locator's last values and occurrence counts, the index of the next output time.
//!
//! Why only the explicit pairs: their state between steps is small and plain. Radau5 and BDF
//! carry Jacobians, factorizations and difference tables; the fixed-step methods do not need
//! it as much. Those are refused by name. `Auto` is observed and resumable while it runs its
//! explicit pair ([`crate::Method::auto_explicit`]); when the stiffness detector fires it
//! continues with Radau5 to the end unobserved (no more observer calls: that part's outputs
//! are in the returned solution), as the unobserved `Auto` does at the same step.

use crate::error::invalid;
use crate::events::{Event, EventState};
use crate::problem::{MassInverse, MassKind, OdeSystem};
use crate::solution::{Solution, Stats};
use crate::{explicit, methods, Method, OdeError, Options};
use std::ops::ControlFlow;

/// The methods [`solve_observed`] runs.
pub const RESUMABLE: [Method; 5] = [
    Method::Dopri5,
    Method::Tsit5,
    Method::Rk23,
    Method::Dop853,
    Method::Vern9,
];

/// The state of an explicit adaptive integration between two accepted steps: what
/// [`solve_observed`] needs to continue it exactly. Every field is plain data, so a caller
/// can save it (as the bit patterns of its numbers) and build it again.
#[derive(Clone, Debug, PartialEq)]
pub struct ResumeState {
    /// The method that produced it (a resume with another is refused).
    pub method: Method,
    /// Time reached.
    pub t: f64,
    /// State at `t`.
    pub y: Vec<f64>,
    /// The next step to attempt (signed).
    pub h: f64,
    /// The PI controller's memory: the error norm of the last accepted step (at least 1e-4).
    pub facold: f64,
    /// `f(t, y)` as the method holds it: the first stage of the next step (FSAL).
    pub first_stage: Vec<f64>,
    /// Step attempts so far (the `max_steps` count).
    pub attempts: usize,
    /// The statistics so far.
    pub stats: Stats,
    /// The stiffness detector: consecutive positive checks, consecutive negative ones, and
    /// accepted steps until the next check.
    pub stiffness: [usize; 3],
    /// Consecutive attempts with a non-finite error estimate.
    pub non_finite_in_row: usize,
    /// The event locator's memory.
    pub events: EventMemory,
    /// Index into `t_eval` of the next output time.
    pub next_output: usize,
}

/// The event locator's memory between steps: each event function's value at the start of the
/// next step and of the step before (the dip detector fits a parabola through three values),
/// those two times, and how many zeros of each were found (for `terminal(n)`).
#[derive(Clone, Debug, PartialEq)]
pub struct EventMemory {
    /// `g` at `t_prev`, per event.
    pub g_prev: Vec<f64>,
    /// `g` at `t_prev2`, per event.
    pub g_prev2: Vec<f64>,
    /// Start of the next step.
    pub t_prev: f64,
    /// Start of the step before (NaN before the second step).
    pub t_prev2: f64,
    /// Zeros found so far, per event.
    pub counts: Vec<usize>,
}

/// What the observer of [`solve_observed`] sees after an accepted step.
pub struct Accepted<'a> {
    /// The time reached.
    pub t: f64,
    /// The solution so far: the observer may take the outputs out of `t` and `y` (the
    /// solve keeps appending to them); events, possible misses and statistics accumulate.
    pub solution: &'a mut Solution,
    pub(crate) view: StateView<'a>,
}

/// References to the driver's state, read only when [`Accepted::state`] is called.
pub(crate) struct StateView<'a> {
    pub method: Method,
    pub y: &'a [f64],
    pub first_stage: &'a [f64],
    pub h: f64,
    pub facold: f64,
    pub attempts: usize,
    pub stiffness: [usize; 3],
    pub non_finite_in_row: usize,
    pub events: &'a EventState<'a, 'a>,
    pub next_output: usize,
}

impl Accepted<'_> {
    /// The integrator's state now: [`solve_observed`] started from it continues exactly.
    pub fn state(&self) -> ResumeState {
        let v = &self.view;
        ResumeState {
            method: v.method,
            t: self.t,
            y: v.y.to_vec(),
            h: v.h,
            facold: v.facold,
            first_stage: v.first_stage.to_vec(),
            attempts: v.attempts,
            stats: self.solution.stats.clone(),
            stiffness: v.stiffness,
            non_finite_in_row: v.non_finite_in_row,
            events: v.events.memory(),
            next_output: v.next_output,
        }
    }
}

/// The observer of [`solve_observed`]: called after every accepted step that does not end the
/// solve; `Break` stops it there with [`OdeError::Interrupted`] (its partial solution holds
/// what the observer left in it).
pub type Observer<'o> = dyn FnMut(&mut Accepted<'_>) -> ControlFlow<()> + 'o;

/// As [`crate::solve_with_events`] for the explicit adaptive pairs ([`RESUMABLE`]), calling
/// `observer` after each accepted step, and starting from `resume` when given (a state from
/// [`Accepted::state`] of a solve of the same system, span, options and events): the
/// continuation's steps, outputs, events and statistics are those of the uninterrupted solve.
/// A resumed solve does not output the initial point again; its statistics count from the
/// saved ones.
#[allow(clippy::too_many_arguments)]
pub fn solve_observed<S: OdeSystem + ?Sized>(
    method: Method,
    sys: &S,
    t_span: (f64, f64),
    y0: &[f64],
    opts: &Options,
    events: &[Event<'_>],
    resume: Option<&ResumeState>,
    observer: &mut Observer<'_>,
) -> Result<Solution, OdeError> {
    if method == Method::Auto {
        let explicit = Method::auto_explicit(&opts.rtol);
        let mut o = opts.clone();
        o.on_stiffness = crate::StiffnessAction::Error;
        let first = solve_observed(explicit, sys, t_span, y0, &o, events, resume, observer);
        return crate::auto_after_explicit(sys, t_span.0, t_span.1, opts, events, first);
    }
    if !RESUMABLE.contains(&method) {
        let names: Vec<&str> = RESUMABLE.iter().map(|m| m.name()).collect();
        return Err(invalid(format!(
            "{method} cannot be observed step by step or resumed: only the explicit adaptive pairs can ({}), and auto while it runs one",
            names.join(", ")
        )));
    }
    if sys.mass_kind() != MassKind::Identity {
        return run(
            method,
            &MassInverse::new(sys),
            t_span,
            y0,
            opts,
            events,
            resume,
            observer,
        );
    }
    run(method, sys, t_span, y0, opts, events, resume, observer)
}

#[allow(clippy::too_many_arguments)]
fn run<S: OdeSystem + ?Sized>(
    method: Method,
    sys: &S,
    (t0, tf): (f64, f64),
    y0: &[f64],
    opts: &Options,
    events: &[Event<'_>],
    resume: Option<&ResumeState>,
    observer: &mut Observer<'_>,
) -> Result<Solution, OdeError> {
    if let Some(r) = resume {
        check(r, method, sys.dim(), events.len(), t0, tf, opts)?;
    }
    let act = opts.on_stiffness;
    let hooks = explicit::Hooks {
        resume,
        observer: Some(observer),
    };
    use methods::*;
    match method {
        Method::Dopri5 => {
            explicit::integrate_with::<dopri5::Dopri5, S>(sys, t0, tf, y0, opts, events, act, hooks)
        }
        Method::Tsit5 => {
            explicit::integrate_with::<tsit5::Tsit5, S>(sys, t0, tf, y0, opts, events, act, hooks)
        }
        Method::Rk23 => {
            explicit::integrate_with::<rk23::Rk23, S>(sys, t0, tf, y0, opts, events, act, hooks)
        }
        Method::Dop853 => {
            explicit::integrate_with::<dop853::Dop853, S>(sys, t0, tf, y0, opts, events, act, hooks)
        }
        _ => explicit::integrate_with::<vern9::Vern9, S>(sys, t0, tf, y0, opts, events, act, hooks),
    }
}

/// A saved state that does not belong to this solve is refused, saying why.
fn check(
    r: &ResumeState,
    method: Method,
    n: usize,
    n_events: usize,
    t0: f64,
    tf: f64,
    opts: &Options,
) -> Result<(), OdeError> {
    let bad = |why: String| Err(invalid(format!("cannot resume: {why}")));
    if r.method != method {
        return bad(format!("the state was saved by {}, not {method}", r.method));
    }
    if r.y.len() != n || r.first_stage.len() != n {
        return bad(format!(
            "the state has {} components and its first stage {}, but the system has {n}",
            r.y.len(),
            r.first_stage.len()
        ));
    }
    let m = &r.events;
    if m.g_prev.len() != n_events || m.g_prev2.len() != n_events || m.counts.len() != n_events {
        return bad(format!(
            "the state has {} event functions, the solve {n_events}",
            m.counts.len()
        ));
    }
    let dir = if tf >= t0 { 1.0 } else { -1.0 };
    if !(r.t.is_finite() && (r.t - t0) * dir >= 0.0 && (tf - r.t) * dir > 0.0) {
        return bad(format!("its time {} is not inside [{t0}, {tf})", r.t));
    }
    if !(r.h.is_finite() && r.h != 0.0) || r.y.iter().any(|v| !v.is_finite()) {
        return bad("its step or state is not finite".into());
    }
    let outputs = opts.t_eval.as_ref().map_or(0, Vec::len);
    if r.next_output > outputs {
        return bad(format!(
            "its next output is number {}, there are {outputs} output times",
            r.next_output
        ));
    }
    Ok(())
}
