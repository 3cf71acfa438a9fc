//! Closed-form solution of linear ODEs with constant coefficients, and the 1-D integration
//! rules of straight-line motion (Bower, *Dynamics*, 3.1.3 and 3.3.2).
//!
//! # The mathematics
//!
//! A system `Σ_k A_k q^(k)(t) = f(t)` (square, constant matrices `A_k`) has the solution
//! `q = q_h + q_p`. Every component of `q_h` is a quasi-polynomial built on the roots `λ` of the
//! characteristic polynomial `χ(λ) = det Σ_k A_k λ^k`: a root of multiplicity `m` contributes
//! `t^j e^{λt}`, `j < m`; a complex pair `α ± iβ` contributes `t^j e^{αt} cos βt` and
//! `t^j e^{αt} sin βt`. The forcing is split into groups `e^{at} P(t) cos bt + e^{at} Q(t) sin bt`
//! (polynomial, exponential, sine/cosine and their products; products and powers of sines and
//! cosines are first turned into sums by the product-to-sum identities, `sinh`/`cosh` into
//! exponentials); by superposition each group has a
//! particular solution of the same form with polynomials of degree `deg P + m`, where `m` is the
//! multiplicity of `a + ib` as a root of `χ` (`m > 0` is resonance).
//!
//! Three solvers implement this:
//! - **exact** (one coordinate, characteristic polynomial of degree ≤ 2 after removing exact
//!   rational roots; symbolic parameters allowed). Roots by the quadratic formula on the monic
//!   polynomial `λ² + c₁λ + c₀`: with `α = -c₁/2` and `Δ = c₁²/4 - c₀`, the homogeneous basis is
//!   `e^{αt}{cosh, sinh}(√Δ t)` for `Δ > 0` (plain exponentials when `√Δ` is rational),
//!   `e^{αt}{1, t}` for `Δ = 0` and `e^{αt}{cos, sin}(√-Δ t)` for `Δ < 0`. When the sign of a
//!   symbolic `Δ` is unknown (the damped oscillator with symbolic `ζ`), every case is returned
//!   with its condition. The particular solution is found by undetermined coefficients after the
//!   exponential shift `L[e^{at} w] = e^{at} Σ_k c_k (D + a)^k w`, and the constants from the
//!   initial conditions by exact linear solution. A biquadratic `λ⁴ + bλ² + c` (undamped two
//!   degrees of freedom) is a quadratic in `λ²`, with cases by the sign of `b² - 4c`.
//! - **elimination** (coupled systems of 2 or 3 coordinates, symbolic coefficients allowed):
//!   each coordinate obeys `det P(D) q_j = Σ_i adj P(D)_{ji} f_i`; its initial derivatives come
//!   from the equations solved for the highest derivatives, and the exact solver does the rest.
//!   Uncoupled equations (the projectile) are solved one by one.
//! - **modal** (second-order systems `M q'' + C q' + K q = f` with numeric, symmetric or
//!   symmetrisable `M`, `K`, classical damping, any number of coordinates): the symmetric
//!   eigen-decomposition of `L⁻¹ K L⁻ᵀ` (`M = L Lᵀ`) decouples the modes, each solved by the
//!   exact scalar solver; see `modal.rs`.
//! - **numeric** (systems, or numeric equations whose characteristic polynomial has irrational
//!   roots of degree ≥ 3): `χ` is interpolated from `det Σ A_k λ^k` at points on a circle, its
//!   roots found by the Aberth–Ehrlich iteration (simultaneous Newton with repulsion) and grouped
//!   into multiple roots and conjugate pairs; the coefficients of every coordinate on the
//!   quasi-polynomial basis then follow from one least-squares solve of the equations projected on
//!   the basis (the basis is closed under `d/dt`) together with the initial conditions, and the
//!   residual is checked.
//!
//! The formulas are exact but not always evaluable: near a resonance (or two nearby roots)
//! they subtract huge, nearly equal terms. [`propagator`] evaluates the same solution at
//! numeric coefficients as `exp(𝒜 t) z(0)`, stable at every forcing frequency (see
//! `propagator.rs`); `pdyn run --method exact` and `pdyn check` use it.
//!
//! # Use from derived equations of motion
//!
//! [`solve_system`] takes equations as expressions (each meaning `= 0`), the coordinates and the
//! initial conditions; the [`ClosedForm`] gives one expression in `t` per coordinate and compiles
//! to a [`Program`] evaluating each coordinate and its rate:
//!
//! ```
//! use pdyn_expr::Pool;
//! use pdyn_mech::dsolve::solve_system;
//! let mut pool = Pool::new();
//! let eq = pool.parse_scalar("x'' + 4*x").unwrap(); // x'' + 4x = 0
//! let x = pool.find_symbol("x").unwrap();
//! let (at0, rate0) = (pool.coord(x, 0), pool.coord(x, 1));
//! let one = pool.int(1);
//! let cf = solve_system(&mut pool, &[eq], &[x], &[(at0, one), (rate0, Pool::ZERO)]).unwrap();
//! assert_eq!(pool.to_text(cf.unique().unwrap()[0]), "cos(2*t)");
//! let prog = cf.compile(&mut pool, 0, &[]).unwrap(); // inputs [t], outputs [x, x']
//! let (mut ws, mut out) = (prog.workspace(), [0.0; 2]);
//! prog.eval(&[0.5], &mut ws, &mut out);
//! assert!((out[0] - 1f64.cos()).abs() < 1e-15 && (out[1] + 2.0 * 1f64.sin()).abs() < 1e-15);
//! ```
//!
//! Anything else (a coefficient that depends on `t` or on the coordinates, forcing that is not a
//! sum of such products) is answered with [`DsolveError::NoClosedForm`], which suggests
//! `pdyn run`. Every step has a fixed work bound, so every call returns in bounded time.

mod eliminate;
mod exact;
mod linear;
mod modal;
mod numeric;
mod propagator;
pub mod quad;
mod roots;
pub mod rules;
mod when;

use pdyn_expr::{Id, Node, Pool, Program, SymId};
use std::fmt;

pub(crate) use exact::nice_sqrt;
pub use linear::{analyze, LinearOde};
pub use propagator::{propagator, Propagator, MAX_STATE};
pub use when::{when, StateAt, When};

/// One initial condition: `coord^(order)(time) = value`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct InitialCondition {
    /// The coordinate.
    pub coord: SymId,
    /// Derivative order (0 for the value, 1 for the rate...).
    pub order: u8,
    /// The value.
    pub value: Id,
}

/// A relation between an expression and zero, stating when a case applies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Relation {
    /// `expr > 0`.
    Positive,
    /// `expr = 0`.
    Zero,
    /// `expr < 0`.
    Negative,
}

/// The condition under which a [`Case`] applies: `expr (relation) 0`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Condition {
    /// The expression whose sign decides.
    pub expr: Id,
    /// Its sign in this case.
    pub relation: Relation,
}

/// How the solution was obtained.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Exact symbolic solution.
    Exact,
    /// Exact form with floating-point roots and coefficients (numeric eigen-decomposition).
    Numeric,
}

/// One solution, valid under its condition.
#[derive(Clone, Debug)]
pub struct Case {
    /// When it applies (`None`: always).
    pub condition: Option<Condition>,
    /// One expression in `t` per coordinate, in the order of [`ClosedForm::coords`].
    pub solution: Vec<Id>,
    /// Human-readable characteristic roots, e.g. `-zeta*wn ± wn*sqrt(1 - zeta^2)*i`.
    pub roots: Vec<String>,
    /// Arbitrary constants left in the solution (`C1`, `C2`...) when initial conditions are
    /// missing.
    pub constants: Vec<Id>,
}

/// Closed-form solution of a linear constant-coefficient system.
#[derive(Clone, Debug)]
pub struct ClosedForm {
    /// The coordinates, in the order of each case's `solution`.
    pub coords: Vec<SymId>,
    /// The cases (one, unless the form depends on the sign of a symbolic quantity).
    pub cases: Vec<Case>,
    /// How it was obtained.
    pub method: Method,
    /// For [`Method::Numeric`]: the relative residual of the least-squares fit (a check).
    pub residual: Option<f64>,
}

impl ClosedForm {
    /// The only case's solution, when there is exactly one case.
    pub fn unique(&self) -> Option<&[Id]> {
        match self.cases.as_slice() {
            [c] => Some(&c.solution),
            _ => None,
        }
    }

    /// Compiles case `case` into a program with inputs `[t, params...]` and outputs
    /// `[q_1, q_1', q_2, q_2', ...]` (each coordinate and its rate).
    pub fn compile(
        &self,
        pool: &mut Pool,
        case: usize,
        params: &[Id],
    ) -> Result<Program, DsolveError> {
        let c = self.cases.get(case).ok_or_else(|| {
            DsolveError::Invalid(format!("no case {case} ({} cases)", self.cases.len()))
        })?;
        let t = pool.time();
        let mut inputs = vec![t];
        inputs.extend_from_slice(params);
        let mut outs = Vec::new();
        for &q in &c.solution {
            outs.push(q);
            outs.push(pool.dt(q));
        }
        Program::compile(pool, &inputs, &outs).map_err(|e| DsolveError::Invalid(e.to_string()))
    }
}

/// Why no closed form was produced.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum DsolveError {
    /// Outside the method: non-linear, variable coefficients, unsupported forcing...
    NoClosedForm(String),
    /// The input is malformed (unknown coordinate, inconsistent initial conditions...).
    Invalid(String),
    /// An instant was asked of a solution with several cases (by the sign of a symbolic
    /// quantity): the parameters need values first.
    SeveralCases,
    /// The instant asked for could not be found.
    Instant(crate::kinematics::KinError),
}

/// The advice attached to every "no closed form" answer.
pub const USE_RUN: &str = "no closed form by this method; use `pdyn run` to integrate numerically";

impl fmt::Display for DsolveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DsolveError::NoClosedForm(why) => write!(f, "{why}: {USE_RUN}"),
            DsolveError::Invalid(why) => write!(f, "{why}"),
            DsolveError::SeveralCases => {
                write!(
                    f,
                    "the solution has several cases; give the parameters with {}",
                    crate::options::RunOption::Set
                )
            }
            DsolveError::Instant(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for DsolveError {}

pub(crate) fn no_closed_form(why: impl Into<String>) -> DsolveError {
    DsolveError::NoClosedForm(why.into())
}

/// Solves `equations` (each meaning `= 0`, linear with constant coefficients in the
/// coordinates `coords` and their derivatives) with initial conditions at `t = 0`.
///
/// `initial` pairs a coordinate leaf (`x`, `x'`, `x''`...) with its value. Missing conditions
/// leave arbitrary constants `C1, C2, ...` (exact solver only).
pub fn solve_system(
    pool: &mut Pool,
    equations: &[Id],
    coords: &[SymId],
    initial: &[(Id, Id)],
) -> Result<ClosedForm, DsolveError> {
    let mut ics = Vec::with_capacity(initial.len());
    for &(lhs, value) in initial {
        match pool.node(lhs) {
            Node::Coord(s, k) => ics.push(InitialCondition {
                coord: *s,
                order: *k,
                value,
            }),
            _ => {
                return Err(DsolveError::Invalid(format!(
                    "initial condition `{} = {}`: the left side must be a coordinate or one of its rates",
                    pool.to_text(lhs),
                    pool.to_text(value)
                )))
            }
        }
    }
    solve_with(pool, equations, coords, &ics, Pool::ZERO)
}

/// Like [`solve_system`], with initial conditions given at time `t0`.
pub fn solve_with(
    pool: &mut Pool,
    equations: &[Id],
    coords: &[SymId],
    initial: &[InitialCondition],
    t0: Id,
) -> Result<ClosedForm, DsolveError> {
    let ode = analyze(pool, equations, coords)?;
    for ic in initial {
        let Some(j) = coords.iter().position(|&c| c == ic.coord) else {
            return Err(DsolveError::Invalid(format!(
                "initial condition on `{}`, which is not a coordinate of the equations",
                pool.name(ic.coord)
            )));
        };
        if ic.order as usize >= ode.orders[j].max(1) {
            return Err(DsolveError::Invalid(format!(
                "initial condition on `{}{}`: the equations are of order {} in `{}`, so give its derivatives below order {}",
                pool.name(ic.coord),
                "'".repeat(ic.order as usize),
                ode.orders[j],
                pool.name(ic.coord),
                ode.orders[j]
            )));
        }
    }
    for (i, a) in initial.iter().enumerate() {
        if initial[..i]
            .iter()
            .any(|b| b.coord == a.coord && b.order == a.order)
        {
            return Err(DsolveError::Invalid(format!(
                "two initial conditions on `{}{}`",
                pool.name(a.coord),
                "'".repeat(a.order as usize)
            )));
        }
    }
    if coords.len() == 1 {
        if let Some(cf) = exact::solve_scalar(pool, &ode, initial, t0, 1)? {
            return Ok(cf);
        }
    } else if let Some(cf) = solve_uncoupled(pool, &ode, initial, t0)? {
        return Ok(cf);
    } else if let Some(cf) = eliminate::solve_by_elimination(pool, &ode, initial, t0)? {
        return Ok(cf);
    }
    // Roots not exact, or a coupled system: by modes when M and K are symmetric (any size),
    // else the general numeric solver.
    if let Some(cf) = modal::solve_modal(pool, &ode, initial, t0)? {
        return Ok(cf);
    }
    numeric::solve_numeric(pool, &ode, initial, t0)
}

/// Most cases kept when uncoupled equations each split into cases.
const MAX_CASES: usize = 27;

/// A system whose equations each involve one coordinate (the projectile: `x'' = 0`,
/// `y'' = -g`) is solved one equation at a time by the exact solver, so symbols are allowed.
fn solve_uncoupled(
    pool: &mut Pool,
    ode: &LinearOde,
    initial: &[InitialCondition],
    t0: Id,
) -> Result<Option<ClosedForm>, DsolveError> {
    let n = ode.coords.len();
    let mut owner = vec![usize::MAX; n];
    for i in 0..n {
        let involved: Vec<usize> = (0..n)
            .filter(|&j| ode.coeffs[i][j].iter().any(|&a| a != Pool::ZERO))
            .collect();
        match involved.as_slice() {
            [j] if owner[*j] == usize::MAX => owner[*j] = i,
            _ => return Ok(None),
        }
    }
    let mut cases: Vec<Case> = vec![Case {
        condition: None,
        solution: Vec::new(),
        roots: Vec::new(),
        constants: Vec::new(),
    }];
    for (j, &i) in owner.iter().enumerate() {
        let sub = LinearOde {
            coords: vec![ode.coords[j]],
            orders: vec![ode.orders[j]],
            coeffs: vec![vec![ode.coeffs[i][j].clone()]],
            forcing: vec![ode.forcing[i]],
        };
        let ics: Vec<InitialCondition> = initial
            .iter()
            .filter(|ic| ic.coord == ode.coords[j])
            .copied()
            .collect();
        let first = 1 + cases[0].constants.len();
        let Some(cf) = exact::solve_scalar(pool, &sub, &ics, t0, first)? else {
            return Ok(None);
        };
        if cases.len() * cf.cases.len() > MAX_CASES
            || (cf.cases.len() > 1 && cases.iter().any(|c| c.condition.is_some()))
        {
            return Ok(None);
        }
        let mut next = Vec::new();
        for c in &cases {
            for sc in &cf.cases {
                let mut solution = c.solution.clone();
                solution.extend_from_slice(&sc.solution);
                let mut roots = c.roots.clone();
                roots.extend(sc.roots.iter().cloned());
                let mut constants = c.constants.clone();
                constants.extend_from_slice(&sc.constants);
                next.push(Case {
                    condition: c.condition.or(sc.condition),
                    solution,
                    roots,
                    constants,
                });
            }
        }
        cases = next;
    }
    Ok(Some(ClosedForm {
        coords: ode.coords.clone(),
        cases,
        method: Method::Exact,
        residual: None,
    }))
}
