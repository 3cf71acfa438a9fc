//! Integrators for ordinary differential equations.
//!
//! pdyn-ode integrates any Rust function: it knows nothing of symbols.
#![warn(missing_docs)]
// Numerical kernels index several arrays with one index; iterator chains would obscure the math.
#![allow(clippy::needless_range_loop)]
// Published coefficients are kept with all the digits of their source.
#![allow(clippy::excessive_precision)]

pub mod controller;
mod error;
pub mod events;
mod explicit;
pub mod methods;
mod options;
pub mod problem;
mod solution;
pub mod tableau;

pub use controller::Controller;
pub use error::{FailurePoint, OdeError};
pub use events::{DenseOutput, Event};
pub use options::{Options, StiffnessAction, Tolerance};
pub use problem::{
    FirstOrderForm, FnSecondOrder, FnSystem, FnSystemWithJacobian, MassKind, OdeSystem,
    SecondOrderSystem,
};
pub use solution::{Direction, EventHit, Solution, Stats, Status};

/// The integration methods.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Method {
    /// Dormand–Prince 5(4) ([`methods::dopri5`]).
    Dopri5,
}

impl Method {
    /// Every method, in the order `--method help` lists them.
    pub fn all() -> &'static [Method] {
        &[Method::Dopri5]
    }

    /// Short lowercase name (`dopri5`, …), accepted by [`Method::from_name`].
    pub fn name(self) -> &'static str {
        match self {
            Method::Dopri5 => "dopri5",
        }
    }

    /// One-paragraph description: order, adaptivity, symplecticity, paper.
    pub fn doc(self) -> &'static str {
        match self {
            Method::Dopri5 => methods::dopri5::DOC,
        }
    }

    /// Parses a name as printed by [`Method::name`] (case-insensitive; `ode45`, `rk45` are
    /// aliases of `dopri5`).
    pub fn from_name(name: &str) -> Option<Method> {
        let lower = name.to_ascii_lowercase();
        match lower.as_str() {
            "ode45" | "rk45" => return Some(Method::Dopri5),
            _ => {}
        }
        Method::all().iter().copied().find(|m| m.name() == lower)
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Integrates `M y' = f(t, y)` from `t_span.0` to `t_span.1` (either direction) starting at
/// `y0`, with `method` and `opts`.
pub fn solve<S: OdeSystem + ?Sized>(
    method: Method,
    sys: &S,
    t_span: (f64, f64),
    y0: &[f64],
    opts: &Options,
) -> Result<Solution, OdeError> {
    solve_with_events(method, sys, t_span, y0, opts, &[])
}

/// As [`solve`], with event functions located on the dense output.
pub fn solve_with_events<S: OdeSystem + ?Sized>(
    method: Method,
    sys: &S,
    t_span: (f64, f64),
    y0: &[f64],
    opts: &Options,
    events: &[Event<'_>],
) -> Result<Solution, OdeError> {
    let (t0, tf) = t_span;
    match method {
        Method::Dopri5 => explicit::integrate::<methods::dopri5::Dopri5, S>(
            sys,
            t0,
            tf,
            y0,
            opts,
            events,
            opts.on_stiffness,
        ),
    }
}
