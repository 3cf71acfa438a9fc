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

pub mod kernels;
pub mod structure;

use kernels::NetKernels;
use pdyn_expr::linsolve::LinearSystem;
use pdyn_expr::Id;
use pdyn_jit::JitMode;
use pdyn_mech::derive::{Form, ParticleKinematics, Unknown, UnknownKind};
use pdyn_mech::model::Target;
use pdyn_mech::{Derivation, Model};

/// From how many particles a model of free particles in Cartesian coordinates takes this
/// path. Below, the generic derivation is cheap and keeps the exact forms of small models
/// (a projectile, two orbiting bodies) and their examples' numbers to the last bit.
pub const NET_FROM: usize = 8;

/// The model as free particles with per-template kernels: the derivation the rest of
/// `prepare` reads (kinematics and resultant forces of each particle, the state; no
/// equations, no linear system) and the compiled accelerations. `None` when the model is not
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

/// What the rest of `prepare` reads of a derivation: each particle's kinematics and resultant
/// force (for output columns and the conservation laws), the state and its names, the
/// accelerations as unknowns.
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
    // Each particle's loads gathered in one pass (not a pass over all loads per particle).
    let mut terms: Vec<[Vec<Id>; 3]> = vec![Default::default(); model.particles.len()];
    for load in &model.loads {
        if let Target::Particle(i) = load.target {
            for (c, &f) in load.force.iter().enumerate() {
                terms[i][c].push(f);
            }
        }
    }
    let particles = model
        .particles
        .iter()
        .zip(terms)
        .map(|(pt, f)| {
            let r = pt.position;
            let v = r.map(|c| p.dt(c));
            let a = v.map(|c| p.dt(c));
            ParticleKinematics {
                name: pt.name.clone(),
                mass: pt.mass,
                r,
                v,
                a,
                force: f.map(|t| p.add(&t)),
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
