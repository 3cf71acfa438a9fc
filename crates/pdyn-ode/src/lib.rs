//! Integrators for ordinary differential equations: adaptive explicit Runge–Kutta pairs, a
//! stiff implicit solver, symplectic and geometric methods; events, dense output, typed errors.
//!
//! pdyn-ode integrates any Rust function: it knows nothing of symbols and depends on no other
//! pdyn crate but pdyn-sparse (the sparse factorization it shares with the statics).
//!
//! # Quick start
//! ```
//! use pdyn_ode::{solve, FnSystem, Method, Options};
//! // y'' = −y as a first-order system
//! let osc = FnSystem::new(2, |_t, y: &[f64], f: &mut [f64]| {
//!     f[0] = y[1];
//!     f[1] = -y[0];
//! });
//! let opts = Options { rtol: 1e-10.into(), atol: 1e-12.into(), ..Default::default() };
//! let sol = solve(Method::Dop853, &osc, (0.0, 10.0), &[1.0, 0.0], &opts).unwrap();
//! let (_, y) = sol.last().unwrap();
//! assert!((y[0] - 10f64.cos()).abs() < 1e-9);
//! println!("{} accepted steps, {} f-evaluations", sol.stats.accepted, sol.stats.fevals);
//! ```
//!
//! # Layout
//! | file | what |
//! |---|---|
//! | `problem.rs` | [`OdeSystem`] (`M y' = f(t, y)` in place, optional Jacobian and mass matrix), [`SecondOrderSystem`] (`q'' = a(t, q, q')`, `separable` flag), closure wrappers, [`MassInverse`] |
//! | `options.rs` | [`Options`] (`rtol`, `atol`, `h0`, `max_step`, `max_steps`, `t_eval`, …) with documented defaults |
//! | `solution.rs` | [`Solution`] (output times and states, [`Stats`], [`EventHit`]s) |
//! | `dense.rs` | [`DenseSolution`]: every step's own interpolant, when [`Options::dense_output`] is set |
//! | `error.rs` | [`OdeError`]: typed failures carrying `t`, the state and the partial solution |
//! | `controller.rs` | the shared PI step-size controller and initial-step estimate (Hairer) |
//! | `events.rs` | [`Event`]s and the shared locator (Brent's method on the dense output), output at `t_eval` |
//! | `explicit.rs`, `fixed.rs` | drivers shared by the explicit adaptive pairs, and by the fixed-step methods |
//! | `resume.rs` | [`solve_observed`]: an explicit pair watched step by step (outputs taken as they come) and resumed bit for bit from a saved [`ResumeState`] |
//! | `tableau.rs` | Butcher tableaus as data; order-condition checker over rooted trees |
//! | `linalg.rs` | dense real/complex LU with partial pivoting (decsol.f), allocation-free |
//! | [`sparse_lu`] | re-exported from pdyn-sparse (shared with pdyn-mech's statics): sparse real/complex LU on a known pattern (kinematic rows `q' = v` eliminated first, then supernodal multifrontal with dense kernels, no pivoting) in nested-dissection order, for Radau5's iteration matrices ([`LinearSolver`]) |
//! | `methods/dopri5.rs` | **DOPRI5**, Dormand & Prince 1980: 5(4), FSAL, 4th-order dense output, stiffness detection (MATLAB `ode45`) |
//! | `methods/rk23.rs` | **RK23**, Bogacki & Shampine 1989: 3(2), FSAL, cubic Hermite dense output (MATLAB `ode23`) |
//! | `methods/tsit5.rs` | **Tsit5**, Tsitouras 2011: 5(4), FSAL, 4th-order dense output |
//! | `methods/dop853.rs` | **DOP853**, Prince & Dormand 1981 / Hairer: 8(5,3), 7th-order dense output |
//! | `methods/vern9.rs` | **Vern9**, Verner 2010: 9(8), for very tight tolerances (cubic Hermite dense output) |
//! | `methods/rk4.rs` | **RK4**, Kutta 1901: classical order 4, fixed step |
//! | `jacobian.rs` | finite-difference Jacobians of the implicit methods, columns grouped by a [`Sparsity`] pattern (SciPy's `jac_sparsity`) |
//! | `methods/bdf.rs` | **BDF**, Shampine & Reichelt 1997: variable order 1–5, quasi-constant step size, NDF coefficients (MATLAB `ode15s`, SciPy's `BDF`), its own interpolating polynomial as dense output; `methods/bdf_linear.rs` its Jacobian and iteration matrix `I − c·J`, dense or sparse |
//! | `methods/radau5.rs` | **Radau5**, Hairer & Wanner 1996: Radau IIA order 5, stiff, mass matrices / index-1 DAEs; `methods/radau5_linear.rs` its Jacobian and iteration matrices, dense or sparse; `methods/iteration_pattern.rs` the sparse pattern both implicit methods share |
//! | `methods/symplectic.rs` | **Velocity Verlet** (Verlet 1967), **Yoshida 4** (Yoshida 1990), **Kahan–Li 6 / 8** (Kahan & Li 1997): explicit symplectic, fixed step |
//! | `methods/gauss.rs` | **Gauss–Legendre 4 / 6** (Butcher 1964): implicit symplectic for any Hamiltonian, fixed step |
//!
//! `Method::Auto` runs the explicit pair [`Method::auto_explicit`] picks from `rtol` (DOPRI5
//! or DOP853) and switches to Radau5 when that pair's stiffness detector fires.
//! [`METHODS`] is the one table describing the methods (name, aliases, order, kind, symplectic
//! composition weights, description); [`Method::all`], [`Method::name`], [`Method::doc`],
//! [`Method::order`], [`Method::kind`] and [`Method::from_name`] read it. Only `dispatch`
//! (which calls each method's generic code) matches on [`Method`].
//!
//! # Conventions
//! * Tolerances: a step is accepted when the RMS over components of
//!   `err_i / (atol_i + rtol_i · max(|y0_i|, |y1_i|))` is ≤ 1. Defaults `rtol = 1e-6`,
//!   `atol = 1e-9` (tighter than MATLAB's 1e-3 / 1e-6).
//! * Statistics are counted like Hairer's Fortran codes, so that published counts can be
//!   compared exactly (tests reproduce dopri5.f on Arenstorf, dop853.f on Van der Pol and
//!   radau5.f on Robertson).
//! * No allocation inside a step: each solve allocates its workspaces once. Outputs are pushed
//!   to the [`Solution`] (amortised growth).
//! * Fixed-step methods take `N = ⌈|tf − t0| / h0⌉` equal steps of size `(tf − t0)/N`.
#![warn(missing_docs)]
// Numerical kernels index several arrays with one index; iterator chains would obscure the math.
#![allow(clippy::needless_range_loop)]
// Published coefficients are kept with all the digits of their source.
#![allow(clippy::excessive_precision)]

pub mod controller;
pub mod dense;
mod error;
pub mod events;
mod explicit;
mod fixed;
pub mod jacobian;
pub mod linalg;
pub mod methods;
mod options;
pub mod problem;
pub mod problems;
pub mod resume;
mod solution;
/// The sparse LU of Radau5's iteration matrices, from pdyn-sparse (shared with the statics).
pub use pdyn_sparse::sparse_lu;
pub mod tableau;

pub use controller::Controller;
pub use dense::{DenseSolution, Interpolant};
pub use error::{FailurePoint, OdeError};
pub use events::{DenseOutput, Event};
pub use jacobian::Sparsity;
pub use methods::iteration_pattern::SPARSE_FROM as IMPLICIT_SPARSE_FROM;
pub use options::{Interrupt, LinearSolver, Options, StiffnessAction, Tolerance};
pub use problem::{
    FirstOrderForm, FnSecondOrder, FnSystem, FnSystemWithJacobian, MassInverse, MassKind,
    OdeSystem, SecondOrderSystem,
};
pub use resume::{solve_observed, Accepted, EventMemory, ResumeState};
pub use solution::{Direction, EventHit, PossibleMiss, Solution, Stats, Status};

/// The integration methods. Everything descriptive about a method (name, aliases, order,
/// kind, documentation) is one row of [`METHODS`]; see [`Method::info`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Method {
    /// Dormand–Prince 5(4) ([`methods::dopri5`]), adaptive; MATLAB's `ode45`.
    Dopri5,
    /// Tsitouras 5(4) ([`methods::tsit5`]), adaptive.
    Tsit5,
    /// Bogacki–Shampine 3(2) ([`methods::rk23`]), adaptive; MATLAB's `ode23`, SciPy's `RK23`.
    Rk23,
    /// Dormand–Prince 8(5,3) ([`methods::dop853`]), adaptive.
    Dop853,
    /// Verner 9(8) ([`methods::vern9`]), adaptive.
    Vern9,
    /// Classical Runge–Kutta 4 ([`methods::rk4`]), fixed step.
    Rk4,
    /// Velocity Verlet ([`methods::symplectic`]), fixed step, symplectic, order 2.
    VelocityVerlet,
    /// Yoshida's composition ([`methods::symplectic`]), fixed step, symplectic, order 4.
    Yoshida4,
    /// Kahan–Li composition ([`methods::symplectic`]), fixed step, symplectic, order 6.
    KahanLi6,
    /// Kahan–Li composition ([`methods::symplectic`]), fixed step, symplectic, order 8.
    KahanLi8,
    /// Gauss–Legendre 2 stages ([`methods::gauss`]), implicit, fixed step, symplectic, order 4.
    Gauss4,
    /// Gauss–Legendre 3 stages ([`methods::gauss`]), implicit, fixed step, symplectic, order 6.
    Gauss6,
    /// Radau IIA order 5 ([`methods::radau5`]), implicit, adaptive, for stiff problems.
    Radau5,
    /// Variable-order (1–5) BDF with NDF coefficients ([`methods::bdf`]), implicit, adaptive,
    /// for stiff problems; MATLAB's `ode15s`, SciPy's `BDF`.
    Bdf,
    /// The explicit pair chosen from `rtol` by [`Method::auto_explicit`] (DOPRI5 at loose
    /// tolerances, DOP853 at tight ones) while the problem is non-stiff, switching to Radau5
    /// for the rest of the integration when that pair's stiffness detector fires (checked every
    /// [`Options::stiffness_check_interval`] accepted steps, then 15 positive checks in a row).
    /// The switch restarts from the last accepted explicit state with Radau5's own first step;
    /// statistics are summed; the occurrence count of `terminal(n)` events restarts at the
    /// switch; [`Stats::stiffness_detected_at`] records where it happened.
    Auto,
}

/// What kind of integrator a method is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MethodKind {
    /// Explicit with error control (uses `rtol`, `atol`, `h0` as first step).
    Adaptive,
    /// Implicit with error control, for stiff problems.
    Stiff,
    /// Fixed step `h0`, not symplectic.
    FixedStep,
    /// Fixed step `h0`, symplectic.
    Symplectic,
}

/// The description of one integration method: one row of [`METHODS`].
#[derive(Debug, Clone, Copy)]
#[non_exhaustive]
pub struct MethodInfo {
    /// The method this row describes.
    pub method: Method,
    /// Short lowercase name (`dopri5`, `tsit5`, …) printed by `--method help`.
    pub name: &'static str,
    /// Other names [`Method::from_name`] accepts (lowercase).
    pub aliases: &'static [&'static str],
    /// Nominal order of the propagated solution.
    pub order: u32,
    /// Kind of method (adaptive, stiff, fixed step, symplectic).
    pub kind: MethodKind,
    /// For explicit symplectic compositions of velocity Verlet: the substep weights. Such a
    /// method integrates only separable second-order systems
    /// ([`solve_second_order`]).
    pub composition: Option<&'static [f64]>,
    /// One-paragraph description: order, adaptivity, symplecticity, paper.
    pub doc: &'static str,
}

impl MethodInfo {
    /// Whether the method controls its step size from an error estimate.
    pub fn adaptive(&self) -> bool {
        matches!(self.kind, MethodKind::Adaptive | MethodKind::Stiff)
    }

    /// Whether the method is symplectic (for Hamiltonian systems).
    pub fn symplectic(&self) -> bool {
        self.kind == MethodKind::Symplectic
    }
}

/// Every method, in the order `--method help` lists them. Adding a method: a variant of
/// [`Method`], a row here, an arm in `dispatch` (which calls the method's generic code).
pub const METHODS: [MethodInfo; 15] = {
    use methods::*;
    const fn row(
        method: Method,
        name: &'static str,
        order: u32,
        kind: MethodKind,
        doc: &'static str,
    ) -> MethodInfo {
        MethodInfo {
            method,
            name,
            aliases: &[],
            order,
            kind,
            composition: None,
            doc,
        }
    }
    use MethodKind::{Adaptive, FixedStep, Stiff, Symplectic};
    [
        MethodInfo {
            aliases: &["ode45", "rk45"],
            ..row(Method::Dopri5, "dopri5", 5, Adaptive, dopri5::DOC)
        },
        row(Method::Tsit5, "tsit5", 5, Adaptive, tsit5::DOC),
        MethodInfo {
            aliases: &["ode23"],
            ..row(Method::Rk23, "rk23", 3, Adaptive, rk23::DOC)
        },
        row(Method::Dop853, "dop853", 8, Adaptive, dop853::DOC),
        row(Method::Vern9, "vern9", 9, Adaptive, vern9::DOC),
        row(Method::Rk4, "rk4", 4, FixedStep, rk4::DOC),
        MethodInfo {
            aliases: &["leapfrog", "velocity-verlet"],
            composition: Some(&symplectic::VERLET),
            ..row(
                Method::VelocityVerlet,
                "verlet",
                2,
                Symplectic,
                symplectic::DOC_VERLET,
            )
        },
        MethodInfo {
            composition: Some(&symplectic::YOSHIDA4),
            ..row(
                Method::Yoshida4,
                "yoshida4",
                4,
                Symplectic,
                symplectic::DOC_YOSHIDA4,
            )
        },
        MethodInfo {
            composition: Some(&symplectic::KAHAN_LI6),
            ..row(
                Method::KahanLi6,
                "kahanli6",
                6,
                Symplectic,
                symplectic::DOC_KAHAN_LI6,
            )
        },
        MethodInfo {
            composition: Some(&symplectic::KAHAN_LI8),
            ..row(
                Method::KahanLi8,
                "kahanli8",
                8,
                Symplectic,
                symplectic::DOC_KAHAN_LI8,
            )
        },
        row(Method::Gauss4, "gauss4", 4, Symplectic, gauss::DOC_GAUSS4),
        row(Method::Gauss6, "gauss6", 6, Symplectic, gauss::DOC_GAUSS6),
        row(Method::Radau5, "radau5", 5, Stiff, radau5::DOC),
        MethodInfo {
            aliases: &["ode15s"],
            ..row(Method::Bdf, "bdf", 5, Stiff, bdf::DOC)
        },
        row(Method::Auto, "auto", 5, Stiff, AUTO_DOC),
    ]
};

/// The `method` column of [`METHODS`], for [`Method::all`].
const ALL: [Method; METHODS.len()] = {
    let mut all = [Method::Auto; METHODS.len()];
    let mut i = 0;
    while i < METHODS.len() {
        all[i] = METHODS[i].method;
        i += 1;
    }
    all
};

impl Method {
    /// Every method, in the order `--method help` lists them.
    pub fn all() -> &'static [Method] {
        &ALL
    }

    /// This method's row of [`METHODS`].
    pub fn info(self) -> &'static MethodInfo {
        METHODS
            .iter()
            .find(|i| i.method == self)
            .expect("every Method has a row in METHODS")
    }

    /// Short lowercase name (`dopri5`, `tsit5`, …), accepted by [`Method::from_name`].
    pub fn name(self) -> &'static str {
        self.info().name
    }

    /// One-paragraph description: order, adaptivity, symplecticity, paper.
    pub fn doc(self) -> &'static str {
        self.info().doc
    }

    /// Nominal order of the propagated solution.
    pub fn order(self) -> u32 {
        self.info().order
    }

    /// Kind of method.
    pub fn kind(self) -> MethodKind {
        self.info().kind
    }

    /// Parses a name as printed by [`Method::name`] or one of its aliases (case-insensitive;
    /// `ode45`/`rk45` are aliases of `dopri5`, `leapfrog` of `verlet`).
    pub fn from_name(name: &str) -> Option<Method> {
        let lower = name.to_ascii_lowercase();
        METHODS
            .iter()
            .find(|i| i.name == lower || i.aliases.contains(&lower.as_str()))
            .map(|i| i.method)
    }

    /// The explicit pair [`Method::Auto`] integrates with (until stiffness is detected) at
    /// this `rtol` ([`Options::rtol`]): DOPRI5 when every component's `rtol` is above
    /// [`AUTO_DOP853_FROM`], DOP853 otherwise. The tightest component decides, since it sets the
    /// step size.
    ///
    /// Why these two and this threshold: f-evaluations measured with `pdyn run --method M
    /// --rtol R --atol 1e-14` (release build) on examples/satellite.toml,
    /// examples/projectile_drag.toml, examples/pendulum_chain_3.toml and the 16-link chain of
    /// `bench/chain_model.py 16 --example`:
    ///
    /// | rtol | DOPRI5 | DOP853 | Vern9 |
    /// |---|---|---|---|
    /// | 1e-5 | 1922 / 296 / 1052 / 4028 | 1346 / 382 / 935 / 4310 | 2050 / 433 / 1253 / 4847 |
    /// | 1e-6 | 3122 / 416 / 1604 / 6500 | 1754 / 419 / 1203 / 5785 | 2514 / 434 / 1430 / 6246 |
    /// | 1e-7 | 4898 / 608 / 2582 / 9686 | 2306 / 501 / 1511 / 7475 | 3122 / 497 / 1807 / 7641 |
    /// | 1e-9 | 12278 / 1400 / 6338 / 24470 | 4022 / 697 / 2461 / 12976 | 5110 / 625 / 2652 / 12168 |
    /// | 1e-11 | 30986 / 3278 / 15674 / 61592 | 7094 / 1062 / 4014 / 21725 | 8312 / 895 / 3948 / 18602 |
    /// | 1e-13 | 70982 / 6464 / 34910 / 136742 | 12374 / 1539 / 6264 / 33929 | 12498 / 1201 / 5762 / 27263 |
    ///
    /// DOP853 overtakes DOPRI5 between rtol 1e-5 and 1e-6: at 1e-6 it saves 0–44 % on these
    /// four, and at the default tolerances of the model files (rtol 1e-6, `atol` theirs) it
    /// saves 36 % on examples/hanging_net.toml (6,620 → 4,254), 28 % on examples/truss.toml
    /// (2,120 → 1,535), 6 % on the 100 × 100 cloth and **52 % on the 8 s run of the 20 × 20 net**
    /// (35,294 → 17,026: issue 33's case); at 1e-7 18–53 %. So the default rtol 1e-6 takes
    /// DOP853 (until 2026-11-28 it kept DOPRI5 there, for its smaller steps' extra output rows;
    /// rows at given times, `points`, cost nothing extra with either). Only runs of a few steps
    /// pay DOP853's twelve stages for nothing (examples/pulley.toml: 32 → 86). Vern9 saves at
    /// most ~22 % over DOP853 even at 1e-13 (and costs more on the satellite), while it has
    /// neither a stiffness detector (the switch to Radau5 would be lost) nor more than a cubic
    /// Hermite dense output (outputs at `t_eval` and events would be third-order only), so
    /// `auto` never picks it.
    pub fn auto_explicit(rtol: &Tolerance) -> Method {
        // NaN (refused later by the options' check) keeps DOPRI5.
        if rtol.tightest() <= AUTO_DOP853_FROM {
            Method::Dop853
        } else {
            Method::Dopri5
        }
    }

    fn needs_second_order(self) -> bool {
        self.info().composition.is_some()
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Integrates `M y' = f(t, y)` from `t_span.0` to `t_span.1` (either direction) starting at
/// `y0`, with `method` and `opts`.
///
/// ```
/// use pdyn_ode::{solve, FnSystem, Method, Options};
/// let decay = FnSystem::new(1, |_t, y: &[f64], dy: &mut [f64]| dy[0] = -y[0]);
/// let sol = solve(Method::Dopri5, &decay, (0.0, 1.0), &[1.0], &Options::default()).unwrap();
/// let (t, y) = sol.last().unwrap();
/// assert_eq!(t, 1.0);
/// assert!((y[0] - (-1.0f64).exp()).abs() < 1e-7);
/// ```
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
    if method.needs_second_order() {
        return Err(error::invalid(format!(
            "{method} integrates second-order separable systems: use solve_second_order"
        )));
    }
    let mass = sys.mass_kind();
    if mass == MassKind::StateDependent || (mass == MassKind::Constant && method != Method::Radau5)
    {
        return dispatch(method, &MassInverse::new(sys), t_span, y0, opts, events);
    }
    dispatch(method, sys, t_span, y0, opts, events)
}

/// Runs `method` on a system whose mass matrix the method supports.
fn dispatch<S: OdeSystem + ?Sized>(
    method: Method,
    sys: &S,
    t_span: (f64, f64),
    y0: &[f64],
    opts: &Options,
    events: &[Event<'_>],
) -> Result<Solution, OdeError> {
    let (t0, tf) = t_span;
    let n = sys.dim();
    let act = opts.on_stiffness;
    match method {
        Method::Dopri5 => {
            explicit::integrate::<methods::dopri5::Dopri5, S>(sys, t0, tf, y0, opts, events, act)
        }
        Method::Tsit5 => {
            explicit::integrate::<methods::tsit5::Tsit5, S>(sys, t0, tf, y0, opts, events, act)
        }
        Method::Dop853 => {
            explicit::integrate::<methods::dop853::Dop853, S>(sys, t0, tf, y0, opts, events, act)
        }
        Method::Rk23 => {
            explicit::integrate::<methods::rk23::Rk23, S>(sys, t0, tf, y0, opts, events, act)
        }
        Method::Vern9 => {
            explicit::integrate::<methods::vern9::Vern9, S>(sys, t0, tf, y0, opts, events, act)
        }
        Method::Rk4 => fixed::integrate_fixed(
            method,
            sys,
            sys,
            methods::rk4::Rk4::new(n),
            t0,
            tf,
            y0,
            opts,
            events,
        ),
        Method::Gauss4 => fixed::integrate_fixed(
            method,
            sys,
            sys,
            methods::gauss::Gauss::new(&methods::gauss::GAUSS4, n),
            t0,
            tf,
            y0,
            opts,
            events,
        ),
        Method::Gauss6 => fixed::integrate_fixed(
            method,
            sys,
            sys,
            methods::gauss::Gauss::new(&methods::gauss::GAUSS6, n),
            t0,
            tf,
            y0,
            opts,
            events,
        ),
        Method::Radau5 => methods::radau5::integrate(sys, t0, tf, y0, opts, events),
        Method::Bdf => methods::bdf::integrate(sys, t0, tf, y0, opts, events),
        Method::Auto => auto(sys, t0, tf, y0, opts, events),
        Method::VelocityVerlet | Method::Yoshida4 | Method::KahanLi6 | Method::KahanLi8 => {
            Err(error::invalid("unreachable: second-order method"))
        }
    }
}

/// [`Method::Auto`] integrates with DOP853 rather than DOPRI5 when `rtol` is this or tighter
/// (measurements in [`Method::auto_explicit`]).
pub const AUTO_DOP853_FROM: f64 = 1e-6;

const AUTO_DOC: &str =
    "DOPRI5 (rtol above 1e-6) or DOP853 (1e-6 and tighter), with Hairer's stiffness \
detection; switches to Radau5 for the rest of the interval when the problem becomes stiff.";

/// `Method::Auto`: the explicit pair of [`Method::auto_explicit`] until its stiffness detector
/// fires, then Radau5 from that point.
fn auto<S: OdeSystem + ?Sized>(
    sys: &S,
    t0: f64,
    tf: f64,
    y0: &[f64],
    opts: &Options,
    events: &[Event<'_>],
) -> Result<Solution, OdeError> {
    let stop = StiffnessAction::Error;
    let first = match Method::auto_explicit(&opts.rtol) {
        Method::Dop853 => {
            explicit::integrate::<methods::dop853::Dop853, S>(sys, t0, tf, y0, opts, events, stop)
        }
        _ => explicit::integrate::<methods::dopri5::Dopri5, S>(sys, t0, tf, y0, opts, events, stop),
    };
    auto_after_explicit(sys, t0, tf, opts, events, first)
}

/// The rest of [`Method::Auto`] once its explicit pair has returned (run with
/// `StiffnessAction::Error`): its result as it is, or, when it stopped because the problem
/// became stiff, Radau5 from there to `tf`, the two solutions merged. Also the end of an
/// observed `Auto` solve ([`resume::solve_observed`]), whose Radau5 part is not observed.
pub(crate) fn auto_after_explicit<S: OdeSystem + ?Sized>(
    sys: &S,
    t0: f64,
    tf: f64,
    opts: &Options,
    events: &[Event<'_>],
    first: Result<Solution, OdeError>,
) -> Result<Solution, OdeError> {
    let at = match first {
        Err(OdeError::Stiff { at }) => at,
        other => return other,
    };
    let mut sol = *at.partial;
    let ts = at.t;
    let mut o2 = opts.clone();
    if let Some(te) = &opts.t_eval {
        let dir = if tf >= t0 { 1.0 } else { -1.0 };
        o2.t_eval = Some(
            te.iter()
                .copied()
                .filter(|t| (t - ts) * dir > 0.0)
                .collect(),
        );
    }
    o2.h0 = None;
    let rest = methods::radau5::integrate(sys, ts, tf, &at.y, &o2, events);
    let merge = |sol: &mut Solution, mut r: Solution| {
        let skip = usize::from(opts.t_eval.is_none() && r.t.first() == Some(&ts));
        sol.t.extend_from_slice(&r.t[skip..]);
        sol.y.extend_from_slice(&r.y[skip * r.n..]);
        sol.events.append(&mut r.events);
        sol.possible_misses.append(&mut r.possible_misses);
        if let (Some(d), Some(rd)) = (sol.dense.as_mut(), r.dense.as_ref()) {
            d.append(rd);
        }
        // The stiffness detection that caused the switch stays the first one recorded.
        sol.stats.add(&r.stats);
        sol.status = r.status;
        sol.method = Method::Radau5;
    };
    match rest {
        Ok(r) => {
            merge(&mut sol, r);
            Ok(sol)
        }
        Err(mut e) => {
            if let Some(fp) = match &mut e {
                OdeError::StepSizeUnderflow { at, .. }
                | OdeError::NonFinite { at }
                | OdeError::MaxSteps { at, .. }
                | OdeError::MinStep { at, .. }
                | OdeError::SingularMatrix { at }
                | OdeError::Interrupted { at } => Some(at),
                _ => None,
            } {
                let mut full = sol.clone();
                merge(&mut full, (*fp.partial).clone());
                *fp.partial = full;
            }
            Err(e)
        }
    }
}

/// Integrates the second-order system `q'' = a(t, q, q')` from `(q0, v0)`. The solution's
/// state is `y = (q, v)` (length `2 · dim`). Symplectic compositions require
/// [`SecondOrderSystem::separable`]; every other method integrates the first-order form.
pub fn solve_second_order<S: SecondOrderSystem + ?Sized>(
    method: Method,
    sys: &S,
    t_span: (f64, f64),
    q0: &[f64],
    v0: &[f64],
    opts: &Options,
) -> Result<Solution, OdeError> {
    solve_second_order_with_events(method, sys, t_span, q0, v0, opts, &[])
}

/// As [`solve_second_order`], with events (`g` receives `y = (q, v)`).
pub fn solve_second_order_with_events<S: SecondOrderSystem + ?Sized>(
    method: Method,
    sys: &S,
    t_span: (f64, f64),
    q0: &[f64],
    v0: &[f64],
    opts: &Options,
    events: &[Event<'_>],
) -> Result<Solution, OdeError> {
    let n = sys.dim();
    if q0.len() != n || v0.len() != n {
        return Err(error::invalid(format!(
            "q0 and v0 must have {n} components (got {} and {})",
            q0.len(),
            v0.len()
        )));
    }
    let mut y0 = q0.to_vec();
    y0.extend_from_slice(v0);
    let first = FirstOrderForm(sys);
    let Some(w) = method.info().composition else {
        return solve_with_events(method, &first, t_span, &y0, opts, events);
    };
    if !sys.separable() {
        return Err(error::invalid(format!(
            "{method} needs a separable system (acceleration independent of velocity); use gauss4/gauss6"
        )));
    }
    fixed::integrate_fixed(
        method,
        sys,
        &first,
        methods::symplectic::Composition::new(w, n),
        t_span.0,
        t_span.1,
        &y0,
        opts,
        events,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn method_table_has_one_row_per_method_and_unique_names() {
        for (i, info) in METHODS.iter().enumerate() {
            assert_eq!(Method::all()[i], info.method);
            assert_eq!(
                info.method.info().name,
                info.name,
                "{} listed twice",
                info.name
            );
            assert_eq!(Method::from_name(info.name), Some(info.method));
            assert_eq!(
                Method::from_name(&info.name.to_uppercase()),
                Some(info.method)
            );
            for alias in info.aliases {
                assert_eq!(Method::from_name(alias), Some(info.method));
            }
            if info.composition.is_some() {
                assert!(info.symplectic() && !info.adaptive(), "{}", info.name);
            }
        }
        let mut names: Vec<_> = METHODS
            .iter()
            .flat_map(|i| std::iter::once(i.name).chain(i.aliases.iter().copied()))
            .collect();
        let n = names.len();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), n, "a name or alias is used twice");
        assert_eq!(Method::from_name("nope"), None);
    }
}
