//! Many free particles in Cartesian coordinates (a net, a cloth, a lattice of springs): set-up
//! in time linear in the particles, the way finite-element codes assemble (issue 33).
//!
//! The generic path derives `m a = F` for the whole model symbolically, forms `A x = b`,
//! differentiates every acceleration for the Jacobian and compiles it all as one program:
//! each member of a `[[forces]]` family is a new expression to build, differentiate and
//! compile. Here ([`structure`]) the model is recognised as free particles in Cartesian
//! coordinates (diagonal mass matrix, no constraints), each load's contribution `F/m` is
//! written over slot symbols — its template, the same for every member of a family — and
//! ([`kernels`]) each template is compiled once (a [`pdyn_jit::BatchKernel`]: one native loop
//! over the elements' gathered columns) and its derivatives by the slot inputs once, for the
//! Jacobian of the implicit methods, compiled only when first asked for.
//!
//! The accelerations are those of the generic path to round-off (the sum of the loads is
//! formed in another order, each divided by the mass before summing; a kernel shares
//! reciprocals): checked on nets of 4, 9 and 23 particles by `tests/particle_net.rs`.
//!
//! The same kernels, with their derivatives, linearize a net at rest for `pdyn modes` and
//! `pdyn equilibrium` ([`linearization`], entered by [`statics`]; the tensions of deferred
//! families' members from their representative's, [`axial`]).

pub mod axial;
pub mod kernels;
pub mod linearization;
mod runs;
pub mod statics;
pub mod structure;
mod sums;

use super::compiled::CompiledModel;
use super::SimError;
use kernels::NetKernels;
use pdyn_expr::linsolve::LinearSystem;
use pdyn_expr::{Id, Node, Pool, Program};
use pdyn_jit::JitMode;
use pdyn_mech::conservation::{self, Conserved};
use pdyn_mech::derive::{Form, ParticleKinematics, Unknown, UnknownKind};
use pdyn_mech::model::Target;
use pdyn_mech::{Derivation, Model};

/// Whether the model is a net for its output table: from [`NET_FROM`] particles, every
/// component of every particle's position a coordinate or constant in time. Its position
/// columns `P.x` are then not written for the components that are coordinates (they are the
/// coordinate's own column: a 10^4-particle net's table would hold each of its 3·10^4
/// positions twice), whichever path derives it; smaller models keep every position column.
pub fn positions_are_coordinates(model: &Model) -> bool {
    let p = &model.pool;
    model.particles.len() >= NET_FROM
        && model.particles.iter().all(|pt| {
            pt.position.iter().all(|&c| match p.node(c) {
                Node::Coord(_, 0) => true,
                _ => !p.any_node(c, &|n| matches!(n, Node::Coord(..) | Node::Time)),
            })
        })
}

/// The coordinate that is component `axis` of particle `particle`'s position, by name: the
/// column that holds it when [`positions_are_coordinates`] left out `P.x`.
pub fn position_column(model: &Model, particle: usize, axis: usize) -> Option<String> {
    let c = *model.particles.get(particle)?.position.get(axis)?;
    let Node::Coord(s, 0) = *model.pool.node(c) else {
        return None;
    };
    let coordinate = model.coordinates.iter().find(|q| q.sym == s)?;
    Some(coordinate.name.clone())
}

/// The model with its deferred force families expanded ([`Model::expand_deferred`]), for a
/// path that reads every load.
pub fn expand_deferred(model: &mut Model) -> Result<(), SimError> {
    model.expand_deferred().map_err(SimError::Derive)
}

/// From how many particles a model of free particles in Cartesian coordinates takes this
/// path. Below, the generic derivation is cheap and keeps the exact forms of small models
/// (a projectile, two orbiting bodies) and their examples' numbers to the last bit.
pub const NET_FROM: usize = 8;

/// The model as free particles with per-template kernels: the derivation the rest of
/// `prepare` reads (each particle's kinematics, the state; no equations, no linear system,
/// no resultant forces) and the compiled accelerations. `None` when the model is not
/// of that kind or has fewer than `from` particles ([`NET_FROM`] in a run), or a template
/// cannot be compiled as a kernel: the generic path then runs.
pub fn derive_and_compile(
    model: &mut Model,
    jit: JitMode,
    from: usize,
) -> Option<(Derivation, NetKernels)> {
    if model.particles.len() < from {
        return None;
    }
    let structure = structure::recognise(model)?;
    let n = model.coordinates.len();
    let parameters: Vec<Id> = model.parameters.iter().map(|q| q.id).collect();
    let kernels = NetKernels::compile(&mut model.pool, &structure, n, &parameters, jit).ok()??;
    Some((derivation(model, kernels.len()), kernels))
}

/// What the rest of `prepare` reads of a derivation: each particle's kinematics (for output
/// columns and the conservation laws), the state and its names, the accelerations as
/// unknowns.
fn derivation(model: &mut Model, templates: usize) -> Derivation {
    let p = &mut model.pool;
    let free: Vec<usize> = (0..model.coordinates.len()).collect();
    let q: Vec<Id> = model
        .coordinates
        .iter()
        .map(|c| p.coord(c.sym, 0))
        .collect();
    let qd: Vec<Id> = model
        .coordinates
        .iter()
        .map(|c| p.coord(c.sym, 1))
        .collect();
    let qdd: Vec<Id> = model
        .coordinates
        .iter()
        .map(|c| p.coord(c.sym, 2))
        .collect();
    let mut state = q;
    state.extend(&qd);
    let mut state_names: Vec<String> = model.coordinates.iter().map(|c| c.name.clone()).collect();
    state_names.extend(model.coordinates.iter().map(|c| format!("{}'", c.name)));
    let particles = model
        .particles
        .iter()
        .map(|pt| {
            let r = pt.position;
            let v = r.map(|c| p.dt(c));
            let a = v.map(|c| p.dt(c));
            ParticleKinematics {
                name: pt.name.clone(),
                mass: pt.mass,
                r,
                v,
                a,
                // Not formed: sorting each particle's loads into one sum was a third of the
                // set-up, and only the conservation laws read it ([`conserved_quantities`],
                // which forms it when the momenta may be conserved).
                force: [Pool::ZERO; 3],
            }
        })
        .collect();
    let unknowns = model
        .coordinates
        .iter()
        .enumerate()
        .zip(&qdd)
        .map(|((i, c), &id)| Unknown {
            name: format!("{}''", c.name),
            id,
            kind: UnknownKind::Acceleration(i),
        })
        .collect();
    Derivation {
        form: Form::Newton,
        particles,
        equations: Vec::new(),
        unknowns,
        system: LinearSystem {
            unknowns: qdd,
            a: Vec::new(),
            b: Vec::new(),
        },
        solution: None,
        free,
        state,
        state_names,
        notes: vec![format!(
            "free particles in Cartesian coordinates: each acceleration is the sum of its loads \
             over its mass, evaluated by {templates} compiled templates over their elements"
        )],
        recovered: Vec::new(),
        assembled_collected: false,
        prescribed_acceleration: false,
        tree: None,
    }
}

/// The resultant force on each particle, the sum of its loads (one pass over the loads).
fn with_forces(model: &mut Model, d: &Derivation) -> Derivation {
    let mut terms: Vec<[Vec<Id>; 3]> = vec![Default::default(); model.particles.len()];
    for load in &model.loads {
        if let Target::Particle(i) = load.target {
            for (c, &f) in load.force.iter().enumerate() {
                terms[i][c].push(f);
            }
        }
    }
    let mut d = d.clone();
    for (pk, t) in d.particles.iter_mut().zip(terms) {
        pk.force = t.map(|t| model.pool.add(&t));
    }
    d
}

/// Which quantities the motion conserves, by the rules of
/// [`pdyn_mech::conservation::conserved_quantities`] (energy as there). A momentum component
/// is conserved when the resultant force (or moment) vanishes identically, which the generic
/// rule proves on the sum of every particle's force; here the resultants are first evaluated
/// at one state by the kernels: a resultant that is not zero there (beyond round-off) is not
/// identically zero, and a net under gravity, drag or pins needs no symbolic sum at all.
/// Otherwise the sums are formed and the generic rule decides.
pub fn conserved_quantities(
    model: &mut Model,
    d: &Derivation,
    system: &CompiledModel,
) -> Vec<Conserved> {
    let Some(kernels) = system.net_kernels() else {
        return conservation::conserved_quantities(model, d);
    };
    // The energy sums every potential: deferred members' are formed from their
    // representative's (only when the energy may be conserved).
    if model.conservative {
        model.materialize_deferred();
    }
    if !kernels.newton_form() {
        return conservation::conserved_energy(model, d)
            .into_iter()
            .collect();
    }
    let decided = resultants_at_a_state(model, system, kernels).is_some_and(|r| {
        r.iter()
            .all(|&(sum, size)| size > 0.0 && sum.abs() > 1e-9 * size)
    });
    if decided {
        return conservation::conserved_energy(model, d)
            .into_iter()
            .collect();
    }
    model.materialize_deferred();
    let d = with_forces(model, d);
    conservation::conserved_quantities(model, &d)
}

/// [`NetKernels::resultants`] at a state where every coordinate and rate is a different
/// number (deterministic), `t` = 0.3; `None` when a mass or a constant component of a
/// position does not evaluate.
fn resultants_at_a_state(
    model: &mut Model,
    system: &CompiledModel,
    kernels: &NetKernels,
) -> Option<[(f64, f64); 6]> {
    let p = &mut model.pool;
    let parameters: Vec<Id> = model.parameters.iter().map(|q| q.id).collect();
    let values: Vec<f64> = model.parameters.iter().map(|q| q.value).collect();
    let mut exprs = Vec::with_capacity(4 * model.particles.len());
    for pt in &model.particles {
        exprs.push(pt.mass);
        for &c in &pt.position {
            exprs.push(match p.node(c) {
                Node::Coord(..) => Pool::ZERO,
                _ => c,
            });
        }
    }
    let prog = Program::compile(p, &parameters, &exprs).ok()?;
    let mut numbers = vec![0.0; exprs.len()];
    prog.eval(&values, &mut prog.workspace(), &mut numbers);
    let n = system.n;
    let mut input = vec![0.0; 1 + 2 * n + values.len()];
    input[0] = 0.3;
    for (k, x) in input[1..1 + 2 * n].iter_mut().enumerate() {
        *x = libm::sin(1.3 * k as f64 + 0.1);
    }
    input[1 + 2 * n..].copy_from_slice(&values);
    let mass: Vec<f64> = numbers.chunks(4).map(|c| c[0]).collect();
    let mut position: Vec<[f64; 3]> = numbers.chunks(4).map(|c| [c[1], c[2], c[3]]).collect();
    let state_index: rustc_hash::FxHashMap<_, usize> = model
        .coordinates
        .iter()
        .enumerate()
        .map(|(k, c)| (c.sym, k))
        .collect();
    for (r, pt) in position.iter_mut().zip(&model.particles) {
        for (axis, &c) in pt.position.iter().enumerate() {
            if let Node::Coord(s, 0) = *p.node(c) {
                r[axis] = input[1 + *state_index.get(&s)?];
            }
        }
    }
    Some(kernels.resultants(&input, &mass, &position))
}
