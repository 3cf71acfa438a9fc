//! The statics commands' entry (`pdyn modes`, `pdyn equilibrium`, Python's `Model.modes`):
//! a model of many free particles is linearized by its kernels
//! ([`super::linearization::NetLinearization`]), any other by the symbolic derivation
//! ([`pdyn_mech::statics::linearize`]); the equilibrium, the eigenproblems and the reports are
//! then the same code ([`pdyn_mech::statics::modes_of`], [`pdyn_mech::equilibrium`],
//! [`pdyn_mech::sparse_statics`]) for both.

use super::linearization::NetLinearization;
use super::NET_FROM;
use pdyn_expr::Id;
use pdyn_jit::JitMode;
use pdyn_mech::equilibrium::{self, EquilibriumError, EquilibriumOptions, FreeDirection};
use pdyn_mech::linearization::Linearize;
use pdyn_mech::sparse_statics::{self, SPARSE_FROM};
use pdyn_mech::statics::{self, ModesReport, ModesRequest, StaticsError};
use pdyn_mech::Model;

/// The modes of `model` as `request` asks ([`pdyn_mech::statics::modes_about`]'s report):
/// by the kernels of a net of at least [`NET_FROM`] free particles, otherwise by the symbolic
/// linearization (a model loaded with deferred families is expanded first).
pub fn modes_about(model: &mut Model, request: &ModesRequest) -> Result<ModesReport, StaticsError> {
    modes_from(model, request, NET_FROM)
}

/// [`modes_about`] taking the net path from `from` particles (tests compare both paths on
/// small nets).
pub fn modes_from(
    model: &mut Model,
    request: &ModesRequest,
    from: usize,
) -> Result<ModesReport, StaticsError> {
    if let Some(lin) = NetLinearization::new(model, JitMode::Auto, from) {
        return statics::modes_of(&lin, request);
    }
    model.expand_deferred()?;
    statics::modes_about(model, request)
}

/// A static equilibrium, with what `pdyn equilibrium` reports of it.
#[derive(Clone, Debug)]
pub struct EquilibriumReport {
    /// The free coordinates' names.
    pub names: Vec<String>,
    /// Their values at equilibrium.
    pub q: Vec<f64>,
    /// `|f|` there.
    pub residual: f64,
    /// The force scale the tolerance is relative to.
    pub scale: f64,
    /// Newton steps taken.
    pub steps: usize,
    /// Directions along which the equilibrium is neutral.
    pub neutral: Vec<FreeDirection>,
    /// The reactions of the supports on the points ([`equilibrium::support_reactions`]).
    pub reactions: Vec<(String, [f64; 3])>,
    /// Every spring's and damper's tension ([`equilibrium::axial_forces`]).
    pub axial: Vec<(String, f64)>,
    /// True when the net's kernels linearized the model (no symbolic derivation).
    pub net: bool,
}

/// The static equilibrium of `model` nearest its initial values, by damped Newton: dense below
/// [`SPARSE_FROM`] coordinates, sparse from there on; linearized by the kernels of a net of at
/// least [`NET_FROM`] particles, symbolically otherwise. A net loaded with deferred families
/// stays compact (its reactions read the loads on points, which are never deferred, and its
/// tensions come from each family's representative: [`super::axial::axial_forces`]); any
/// other model is expanded first.
pub fn equilibrium(
    model: &mut Model,
    opts: &EquilibriumOptions,
) -> Result<EquilibriumReport, StaticsError> {
    equilibrium_from(model, opts, NET_FROM)
}

/// [`equilibrium`] taking the net path from `from` particles.
pub fn equilibrium_from(
    model: &mut Model,
    opts: &EquilibriumOptions,
    from: usize,
) -> Result<EquilibriumReport, StaticsError> {
    if let Some(lin) = NetLinearization::new(model, JitMode::Auto, from) {
        let p = &mut model.pool;
        let mut state: Vec<Id> = model
            .coordinates
            .iter()
            .map(|c| p.coord(c.sym, 0))
            .collect();
        let rates: Vec<Id> = model
            .coordinates
            .iter()
            .map(|c| p.coord(c.sym, 1))
            .collect();
        state.extend(rates);
        let found = solve(&lin, opts)?;
        let reactions = equilibrium::support_reactions(model, &state, &found.q)?;
        let axial = super::axial::axial_forces(model, &state, &found.q)?;
        return Ok(report(found, reactions, axial, true));
    }
    model.expand_deferred()?;
    let (d, lin) = statics::linearize(model)?;
    let found = solve(&lin, opts)?;
    let reactions = equilibrium::support_reactions(model, &d.state, &found.q)?;
    let axial = equilibrium::axial_forces(model, &d.state, &found.q)?;
    Ok(report(found, reactions, axial, false))
}

fn report(
    found: Found,
    reactions: Vec<(String, [f64; 3])>,
    axial: Vec<(String, f64)>,
    net: bool,
) -> EquilibriumReport {
    EquilibriumReport {
        names: found.names,
        q: found.q,
        residual: found.residual,
        scale: found.scale,
        steps: found.steps,
        neutral: found.neutral,
        reactions,
        axial,
        net,
    }
}

/// What either Newton path found.
struct Found {
    names: Vec<String>,
    q: Vec<f64>,
    residual: f64,
    scale: f64,
    steps: usize,
    neutral: Vec<FreeDirection>,
}

/// Damped Newton on `lin`: the envelope `L D Lᵀ` from [`SPARSE_FROM`] coordinates on (the same
/// steps), a dense LU below.
fn solve<L: Linearize>(lin: &L, opts: &EquilibriumOptions) -> Result<Found, EquilibriumError> {
    let names = lin.names().to_vec();
    Ok(if lin.len() >= SPARSE_FROM {
        let e = sparse_statics::solve(lin, None, opts)?;
        Found {
            names,
            q: e.q,
            residual: e.residual,
            scale: e.scale,
            steps: e.steps,
            neutral: e.neutral,
        }
    } else {
        let e = equilibrium::solve(lin, None, opts)?;
        Found {
            names,
            q: e.q,
            residual: e.residual,
            scale: e.scale,
            steps: e.steps,
            neutral: e.neutral,
        }
    })
}
