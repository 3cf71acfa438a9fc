//! Which quantities a derived model must conserve — the checks behind the chapter's First Law
//! of Scientific Computing (3.3.3: "a result that violates a conservation law is wrong").
//!
//! - **Energy** `E = Σ ½ mᵢ |vᵢ|² + Σ V`, when every force derives from a potential (or is a
//!   workless reaction: the model is `conservative`), at least one potential exists, and nothing
//!   depends explicitly on `t` (no prescribed motion, no time-varying potential).
//! - Nothing when a given `acceleration` entered the equations as `q'' = a`
//!   ([`Derivation::prescribed_acceleration`]): the motion is driven.
//! - **Angular momentum** about the origin, component `c`, `H_c = Σ (rᵢ × mᵢ vᵢ)_c`, when the
//!   resultant moment `Σ (rᵢ × Fᵢ)_c` is identically zero.
//! - **Linear momentum**, component `c`, `Σ mᵢ vᵢ_c`, when the resultant force component is
//!   identically zero.
//!
//! Momenta are only checked in Newton's form: in the projected form some reactions were never
//! declared (a pendulum's pivot), so the known forces are not all the forces. "Identically zero"
//! is decided by [`Pool::provably_equal`] on expressions below a size bound, so the detection
//! never blows up; a quantity it cannot prove conserved is simply not monitored.

use crate::derive::{Derivation, Form};
use crate::Model;
use pdyn_expr::{vector, Func, Id, Node, Number, Pool};

/// A quantity that the equations of motion conserve, as an expression of the state.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Conserved {
    /// Column name: `energy`, `angular_momentum.z`, `momentum.x`.
    pub name: String,
    /// The quantity.
    pub expr: Id,
    /// Its physical scale at a state, the sum of the magnitudes of its parts: `Σ ½ m v² + Σ |V|`
    /// for energy, `Σ m |r| |v|` for angular momentum, `Σ m |v|` for momentum. A drift is
    /// measured against this, not against the quantity's own value, which may be zero (a
    /// pendulum released from the horizontal has E = 0) or tiny by cancellation, at any
    /// scale of units.
    pub scale: Id,
}

/// Largest expression (in tree nodes) examined when proving a resultant zero.
const PROOF_SIZE_LIMIT: usize = 2000;

/// True when `e` depends on `t` explicitly.
pub fn depends_on_time(pool: &Pool, e: Id) -> bool {
    pool.any_node(e, &|n| matches!(n, Node::Time))
}

/// The parts of a model's mechanical energy, as expressions of the state.
#[derive(Clone, Copy, Debug)]
pub struct Energy {
    /// `Σ ½ m v²`.
    pub kinetic: Id,
    /// `Σ V` of the conservative forces.
    pub potential: Id,
    /// `Σ ½ m v² + Σ |V|`: the physical scale a drift of the energy is measured against.
    pub scale: Id,
}

/// The kinetic and potential energy of `particles` under `potentials`, and their scale.
pub fn energy(
    p: &mut Pool,
    particles: &[crate::derive::ParticleKinematics],
    potentials: &[crate::model::PotentialTerm],
) -> Energy {
    let mut kinetic = Vec::new();
    for pk in particles {
        let v2 = vector::dot(p, pk.v, pk.v);
        let half = p.num(Number::ratio(1, 2));
        kinetic.push(p.mul(&[half, pk.mass, v2]));
    }
    let mut magnitudes = kinetic.clone();
    magnitudes.extend(potentials.iter().map(|v| p.call(Func::Abs, &[v.energy])));
    let potential: Vec<Id> = potentials.iter().map(|v| v.energy).collect();
    Energy {
        kinetic: p.add(&kinetic),
        potential: p.add(&potential),
        scale: p.add(&magnitudes),
    }
}

/// The conserved quantities of a derived model (see the module documentation for the rules).
pub fn conserved_quantities(model: &mut Model, d: &Derivation) -> Vec<Conserved> {
    // A motion prescribed by a given acceleration (`q'' = a` as an equation: a bar turned at
    // a constant rate) is driven by whatever keeps it so: energy and momenta change.
    if d.prescribed_acceleration {
        return Vec::new();
    }
    let mut out: Vec<Conserved> = conserved_energy(model, d).into_iter().collect();
    if d.form != Form::Projected {
        momenta(model, d, &mut out);
    }
    out
}

/// Energy, when the rules of [`conserved_quantities`] say it is conserved.
pub fn conserved_energy(model: &mut Model, d: &Derivation) -> Option<Conserved> {
    if d.prescribed_acceleration {
        return None;
    }
    let p = &mut model.pool;
    let explicit_time = model
        .particles
        .iter()
        .any(|pt| pt.position.iter().any(|&c| depends_on_time(p, c)))
        || model
            .potentials
            .iter()
            .any(|v| depends_on_time(p, v.energy));
    if model.conservative && !explicit_time && !model.potentials.is_empty() {
        let e = energy(p, &d.particles, &model.potentials);
        let expr = p.add(&[e.kinetic, e.potential]);
        return Some(Conserved {
            name: "energy".into(),
            expr,
            scale: e.scale,
        });
    }
    None
}

/// Linear and angular momentum components whose resultant vanishes (Newton's form only), in
/// the order of [`conserved_quantities`].
fn momenta(model: &mut Model, d: &Derivation, out: &mut Vec<Conserved>) {
    let p = &mut model.pool;
    // The resultant force and moment first, from each particle's terms: a sum of every
    // particle's force is formed (and its scale, and the momentum itself) only when it may
    // vanish. On a net of 10^4 particles nothing is conserved, and forming those sums of
    // 10^4 terms (sorting them) took 2 s.
    let mut forces: [Vec<Id>; 3] = Default::default();
    let mut moments: [Vec<Id>; 3] = Default::default();
    for pk in &d.particles {
        let mr = vector::cross(p, pk.r, pk.force);
        for c in 0..3 {
            forces[c].push(pk.force[c]);
            moments[c].push(mr[c]);
        }
    }
    let mut scales: Option<(Id, Id)> = None;
    for (kind, resultants) in [("angular_momentum", &moments), ("momentum", &forces)] {
        for (c, axis) in ["x", "y", "z"].iter().enumerate() {
            if !resultant_vanishes(p, &resultants[c]) {
                continue;
            }
            let mut terms = Vec::with_capacity(d.particles.len());
            for pk in &d.particles {
                let mv = vector::scale(p, pk.mass, pk.v);
                terms.push(if kind == "momentum" {
                    mv[c]
                } else {
                    vector::cross(p, pk.r, mv)[c]
                });
            }
            let quantity = p.add(&terms);
            if quantity == Pool::ZERO {
                continue;
            }
            let (linear, angular) = *scales.get_or_insert_with(|| momentum_scales(p, d));
            out.push(Conserved {
                name: format!("{kind}.{axis}"),
                expr: quantity,
                scale: if kind == "momentum" { linear } else { angular },
            });
        }
    }
}

/// `Σ m |v|` and `Σ m |r| |v|`: the scales of linear and angular momentum.
fn momentum_scales(p: &mut Pool, d: &Derivation) -> (Id, Id) {
    let (mut linear_scale, mut angular_scale) = (Vec::new(), Vec::new());
    for pk in &d.particles {
        let speed = vector::norm(p, pk.v);
        let r = vector::norm(p, pk.r);
        linear_scale.push(p.mul(&[pk.mass, speed]));
        angular_scale.push(p.mul(&[pk.mass, speed, r]));
    }
    (p.add(&linear_scale), p.add(&angular_scale))
}

/// Whether the sum of `terms` is identically zero: proved by [`Pool::provably_equal`] when
/// the sum is below [`PROOF_SIZE_LIMIT`]. The terms are first cancelled against each other by
/// their numeric coefficients (a spring's pull on one end against its pull on the other), as
/// the sum's own collection of like terms would; when what is left is already over the limit
/// the sum is not formed at all.
fn resultant_vanishes(p: &mut Pool, terms: &[Id]) -> bool {
    let vanishes = |p: &mut Pool, e: Id| {
        p.tree_size(e, PROOF_SIZE_LIMIT + 1) < PROOF_SIZE_LIMIT && p.provably_equal(e, Pool::ZERO)
    };
    let mut flat = Vec::with_capacity(terms.len());
    for &t in terms {
        match p.node(t) {
            Node::Add(ts) => flat.extend(ts.iter().copied()),
            _ => flat.push(t),
        }
    }
    let mut size = 0;
    for &t in &flat {
        size += p.tree_size(t, PROOF_SIZE_LIMIT + 1);
        if size > PROOF_SIZE_LIMIT {
            break;
        }
    }
    if size <= PROOF_SIZE_LIMIT {
        let sum = p.add(&flat);
        return vanishes(p, sum);
    }
    // Like terms collected: coefficient by the rest of each term.
    let mut collected: rustc_hash::FxHashMap<Id, Number> = rustc_hash::FxHashMap::default();
    let mut order = Vec::new();
    for &t in &flat {
        let (c, rest) = p.split_coeff(t);
        match collected.get_mut(&rest) {
            Some(sum) => *sum = sum.add(&c),
            None => {
                collected.insert(rest, c);
                order.push(rest);
            }
        }
    }
    let mut left = Vec::new();
    let mut size = 0;
    for rest in order {
        let c = &collected[&rest];
        if c.is_zero() {
            continue;
        }
        size += p.tree_size(rest, PROOF_SIZE_LIMIT + 1);
        if size >= PROOF_SIZE_LIMIT {
            return false;
        }
        left.push((c.clone(), rest));
    }
    let left: Vec<Id> = left
        .into_iter()
        .map(|(c, rest)| {
            let c = p.num(c);
            p.mul2(c, rest)
        })
        .collect();
    let sum = p.add(&left);
    vanishes(p, sum)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{derive, DeriveOptions};

    fn conserved(src: &str) -> Vec<String> {
        let mut m = crate::load(src, "<test>").unwrap();
        let d = derive(&mut m, &DeriveOptions::default()).unwrap();
        conserved_quantities(&mut m, &d)
            .into_iter()
            .map(|c| c.name)
            .collect()
    }

    const ORBIT: &str = r#"
name = "orbit"
[parameters]
mu = 1
m = 1
[coordinates]
x = { initial = 1, rate = 0 }
y = { initial = 0, rate = 1 }
[particles.sat]
mass = "m"
position = "[x, y, 0]"
[points]
O = "[0, 0, 0]"
[[forces]]
kind = "inverse_square"
on = "sat"
to = "O"
strength = "mu*m"
"#;

    #[test]
    fn a_central_force_conserves_energy_and_angular_momentum_not_momentum() {
        assert_eq!(conserved(ORBIT), ["energy", "angular_momentum.z"]);
    }

    #[test]
    fn drag_conserves_nothing() {
        let src =
            ORBIT.to_string() + "[[forces]]\nkind = \"linear_drag\"\non = \"sat\"\nc = \"c\"\n";
        let src = src.replace("m = 1\n", "m = 1\nc = 0.1\n");
        assert_eq!(conserved(&src), Vec::<String>::new());
    }
}
