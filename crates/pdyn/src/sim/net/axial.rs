//! Every spring's and damper's tension at rest in a model loaded with deferred force families
//! (`pdyn equilibrium` on a net, issue 33), without expanding them: a deferred member's
//! tension is its family representative's expression with the member's coordinates in place
//! of the representative's, so that expression is compiled once and evaluated per member with
//! the member's numbers written into the representative's inputs.
//!
//! The values are those of the expanded model's expressions (the same expression of other
//! inputs). A deferred member is labelled `FAMILY (A, B)` (as
//! [`pdyn_mech::Model::materialize_deferred`] labels it: the member's indices are not kept by
//! deferral) and listed right after its family's representative; the other tensions keep
//! their labels and order.

use pdyn_expr::{Id, Node, Program, SymId};
use pdyn_mech::equilibrium;
use pdyn_mech::linearization::LinearizationError;
use pdyn_mech::Model;
use rustc_hash::FxHashMap;

/// The tension of every spring and damper at rest at `q` (t = 0, rates zero): the built ones
/// as [`equilibrium::axial_forces`], each deferred family's members after its representative.
/// `state` is `[q; q']` as ids, in the order of `q`.
pub fn axial_forces(
    model: &mut Model,
    state: &[Id],
    q: &[f64],
) -> Result<Vec<(String, f64)>, LinearizationError> {
    let built = equilibrium::axial_forces(model, state, q)?;
    if !model.has_deferred() {
        return Ok(built);
    }
    let n = q.len();
    let index: FxHashMap<SymId, usize> = model
        .coordinates
        .iter()
        .enumerate()
        .map(|(k, c)| (c.sym, k))
        .collect();
    // Per particle, the state index of each of its position's coordinates (by axis).
    let slots = |model: &Model, particle: u32| -> Vec<(usize, usize)> {
        model.particles[particle as usize]
            .position
            .iter()
            .enumerate()
            .filter_map(|(axis, &c)| match *model.pool.node(c) {
                Node::Coord(s, 0) => index.get(&s).map(|&k| (axis, k)),
                _ => None,
            })
            .collect()
    };
    let values: Vec<f64> = model.parameters.iter().map(|p| p.value).collect();
    let mut inputs = vec![model.pool.time()];
    inputs.extend(state);
    inputs.extend(model.parameters.iter().map(|p| p.id));
    let mut input = vec![0.0; inputs.len()];
    input[1..1 + n].copy_from_slice(q);
    input[1 + 2 * n..].copy_from_slice(&values);
    // After which built tension each family's members go.
    let mut after: FxHashMap<usize, Vec<(String, f64)>> = FxHashMap::default();
    for d in model.deferred.clone() {
        let Some(k) = d.axial else { continue };
        let tension = model.axial[k].tension;
        let prog = Program::compile(&mut model.pool, &inputs, &[tension])
            .map_err(|e| LinearizationError::Compile(e.to_string()))?;
        let mut ws = prog.workspace();
        let rep: Vec<Vec<(usize, usize)>> = d.ends.iter().map(|&p| slots(model, p)).collect();
        let mut out = [0.0];
        let mut members = Vec::with_capacity(d.len());
        for member in d.each() {
            for (slot, &p) in member.iter().enumerate() {
                // Same shape as the representative's particle: the same axes are coordinates.
                for (&(_, to), (_, from)) in rep[slot].iter().zip(slots(model, p)) {
                    input[1 + to] = q[from];
                }
            }
            prog.eval(&input, &mut ws, &mut out);
            let names: Vec<&str> = member
                .iter()
                .map(|&p| model.particles[p as usize].name.as_str())
                .collect();
            members.push((format!("{} ({})", d.family, names.join(", ")), out[0]));
        }
        // The representative's own inputs back to its values.
        for ends in &rep {
            for &(_, k) in ends {
                input[1 + k] = q[k];
            }
        }
        after.entry(k).or_default().extend(members);
    }
    let mut all = Vec::with_capacity(built.len() + after.values().map(Vec::len).sum::<usize>());
    for (k, t) in built.into_iter().enumerate() {
        all.push(t);
        if let Some(members) = after.remove(&k) {
            all.extend(members);
        }
    }
    Ok(all)
}
