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
    let p = &mut model.pool;
    let mut out = Vec::new();
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
        out.push(Conserved {
            name: "energy".into(),
            expr,
            scale: e.scale,
        });
    }
    if d.form == Form::Projected {
        return out;
    }
    let (mut linear_scale, mut angular_scale) = (Vec::new(), Vec::new());
    for pk in &d.particles {
        let speed = vector::norm(p, pk.v);
        let r = vector::norm(p, pk.r);
        linear_scale.push(p.mul(&[pk.mass, speed]));
        angular_scale.push(p.mul(&[pk.mass, speed, r]));
    }
    let linear_scale = p.add(&linear_scale);
    let angular_scale = p.add(&angular_scale);
    // The terms are gathered and each sum formed once: adding particle by particle re-sorted
    // the growing sum at every step, quadratic in the particles of a net.
    let mut terms: [[Vec<Id>; 3]; 4] = Default::default();
    for pk in &d.particles {
        let mv = vector::scale(p, pk.mass, pk.v);
        let hr = vector::cross(p, pk.r, mv);
        let mr = vector::cross(p, pk.r, pk.force);
        for (k, v) in [hr, mr, mv, pk.force].into_iter().enumerate() {
            for c in 0..3 {
                terms[k][c].push(v[c]);
            }
        }
    }
    let [h, moment, momentum, total_force] = terms.map(|t| t.map(|c| p.add(&c)));
    let vanishes = |p: &mut Pool, e: Id| {
        p.tree_size(e, PROOF_SIZE_LIMIT + 1) < PROOF_SIZE_LIMIT && p.provably_equal(e, Pool::ZERO)
    };
    for (kind, quantity, resultant, scale) in [
        ("angular_momentum", h, moment, angular_scale),
        ("momentum", momentum, total_force, linear_scale),
    ] {
        for (c, axis) in ["x", "y", "z"].iter().enumerate() {
            if quantity[c] != Pool::ZERO && vanishes(p, resultant[c]) {
                out.push(Conserved {
                    name: format!("{kind}.{axis}"),
                    expr: quantity[c],
                    scale,
                });
            }
        }
    }
    out
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
