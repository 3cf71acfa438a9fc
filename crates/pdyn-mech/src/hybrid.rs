//! Hybrid mechanics: the modes of a model's contacts, each a smooth model of its own.
//!
//! A contact ([`crate::model::Contact`]) is at any instant in one [`ContactMode`]:
//! - **open**: the particle is clear of the surface; no contact force;
//! - **smooth**: touching a frictionless surface: the normal force `N` is an unknown
//!   reaction and the gap `phi = 0` is a constraint (differentiated twice);
//! - **stuck**: touching and not slipping: the friction force along each tangent `t_i` is an
//!   unknown reaction too, and the slip velocity `v_s · t_i = 0` a constraint (differentiated
//!   once) — `pdyn forces`' stick mode;
//! - **sliding**: touching and slipping: friction `-mu_k N v_s/|v_s|`, i.e. `-s mu_k N t_1`
//!   with `s = ±1` where the contact can slip in one direction only (a planar model).
//!
//! [`mode_model`] writes the model of one combination of modes — the model's own loads plus
//! the contact forces and constraints of that combination — for [`crate::derive`]. The same
//! free coordinates are the state in every mode, so a run switches modes without changing
//! its state vector. Held contacts (the coordinates keep the gap zero) are never open.
//!
//! The slip velocity is `v_s = v_A - v_B - v_surface` without its normal part; the tangents
//! are `t_1 = unit(n × a)` and `t_2 = n × t_1`, with `a` the coordinate axis least aligned
//! with the normal at the initial state (ties go to z), so that a planar model's tangent is
//! in its plane; a tangent along which the slip is identically zero is dropped.

use crate::model::{Constraint, Contact, CoordinateKind, Load, Model, Reaction, Target};
use pdyn_expr::{vector, Id, Pool, Program};
use rustc_hash::FxHashMap;

/// The state of one contact.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ContactMode {
    /// Apart: no contact force.
    Open,
    /// Touching, frictionless (or unable to slip).
    Smooth,
    /// Touching and not slipping.
    Stuck,
    /// Touching and slipping: `+1` or `-1` along the only tangent, `0` in a tangent plane
    /// (friction against `v_s/|v_s|`).
    Sliding(i8),
}

impl ContactMode {
    /// Whether the surfaces touch.
    pub fn closed(self) -> bool {
        self != ContactMode::Open
    }

    /// `open`, `smooth`, `stuck`, `sliding +`, `sliding -`, `sliding`.
    pub fn label(self) -> &'static str {
        match self {
            ContactMode::Open => "open",
            ContactMode::Smooth => "in contact",
            ContactMode::Stuck => "stuck",
            ContactMode::Sliding(1) => "sliding +",
            ContactMode::Sliding(-1) => "sliding -",
            ContactMode::Sliding(_) => "sliding",
        }
    }
}

/// What every mode shares about one contact: its tangents and the expressions that decide
/// its switches.
#[derive(Clone, Debug)]
pub struct ContactGeometry {
    /// Unit tangents along which the contact can slip (none for a smooth contact).
    pub tangents: Vec<[Id; 3]>,
    /// The slip velocity along each tangent (`q`, `q'`, `t`).
    pub slip: Vec<Id>,
    /// The gap's rate `d phi/dt`: negative while closing.
    pub gap_rate: Id,
    /// The velocity of A relative to B (or to the surface), whole.
    pub relative_velocity: [Id; 3],
}

/// The contacts' geometry, derived once per model.
#[derive(Clone, Debug)]
pub struct Layout {
    /// Per contact, in model order.
    pub contacts: Vec<ContactGeometry>,
}

/// A model is hybrid when it has contacts or events that change the state.
pub fn is_hybrid(model: &Model) -> bool {
    !model.contacts.is_empty() || model.run.events.iter().any(|e| !e.actions.is_empty())
}

impl Layout {
    /// Tangents, slip velocities and gap rates of every contact of `model`.
    pub fn new(model: &mut Model) -> Layout {
        let initial = initial_values(model);
        let mut contacts = Vec::with_capacity(model.contacts.len());
        for k in 0..model.contacts.len() {
            let c = model.contacts[k].clone();
            let p = &mut model.pool;
            let va = model.particles[c.a].position.map(|x| p.dt(x));
            let mut rel = va;
            if let Some(b) = c.b {
                let vb = model.particles[b].position.map(|x| p.dt(x));
                rel = vector::sub(p, rel, vb);
            }
            let gap_rate = p.dt(c.gap);
            let mut tangents = Vec::new();
            let mut slip = Vec::new();
            if c.friction.is_some() {
                let vs = vector::sub(p, rel, c.surface_velocity);
                let n0 = initial.eval(p, &c.normal);
                // The axis least aligned with the normal; z first among equals.
                let axis = [2usize, 0, 1]
                    .into_iter()
                    .min_by(|&i, &j| n0[i].abs().total_cmp(&n0[j].abs()))
                    .unwrap_or(2);
                let mut a = [Pool::ZERO; 3];
                a[axis] = Pool::ONE;
                let t1 = vector::cross(p, c.normal, a);
                let t1 = vector::unit(p, t1).map(|x| p.simplify(x));
                let t2 = vector::cross(p, c.normal, t1).map(|x| p.simplify(x));
                for t in [t1, t2] {
                    let s = vector::dot(p, vs, t);
                    let s = p.simplify(s);
                    if !p.provably_equal(s, Pool::ZERO) {
                        tangents.push(t);
                        slip.push(s);
                    }
                }
            }
            contacts.push(ContactGeometry {
                tangents,
                slip,
                gap_rate,
                relative_velocity: rel,
            });
        }
        Layout { contacts }
    }
}

/// The modes a hybrid model is printed (`pdyn derive`) and prepared in: held contacts
/// touching (stuck where they have friction), the others open.
pub fn reference_modes(model: &Model, layout: &Layout) -> Vec<ContactMode> {
    model
        .contacts
        .iter()
        .zip(&layout.contacts)
        .map(|(c, g)| {
            if c.held {
                closed_modes(g)[0]
            } else {
                ContactMode::Open
            }
        })
        .collect()
}

/// The model of [`reference_modes`], and a note for readers naming each contact's modes.
pub fn reference_model(model: &Model) -> (Model, String) {
    let mut m = model.clone();
    let layout = Layout::new(&mut m);
    let modes = reference_modes(&m, &layout);
    let mut parts = Vec::new();
    for ((c, g), md) in m.contacts.iter().zip(&layout.contacts).zip(&modes) {
        let others: Vec<&str> = closed_modes(g)
            .into_iter()
            .chain((!c.held).then_some(ContactMode::Open))
            .filter(|o| o != md)
            .map(|o| o.label())
            .collect();
        parts.push(format!(
            "`{}` shown {} (also {})",
            c.name,
            md.label(),
            others.join(", ")
        ));
    }
    let note = format!(
        "contacts: {}; `pdyn run` derives each combination of modes when the motion reaches it",
        parts.join("; ")
    );
    let mm = mode_model(&m, &layout, &modes);
    (mm.model, note)
}

/// The modes a contact can be in when it touches.
pub fn closed_modes(geometry: &ContactGeometry) -> Vec<ContactMode> {
    match geometry.tangents.len() {
        0 => vec![ContactMode::Smooth],
        1 => vec![
            ContactMode::Stuck,
            ContactMode::Sliding(1),
            ContactMode::Sliding(-1),
        ],
        _ => vec![ContactMode::Stuck, ContactMode::Sliding(0)],
    }
}

/// One combination of contact modes as a model of its own.
#[derive(Clone, Debug)]
pub struct ModeModel {
    /// The model with the contact forces and constraints of the mode.
    pub model: Model,
    /// The value of each contact force symbol that is not an unknown of this mode (`N` of an
    /// open contact is 0; the friction of a sliding one is `-s mu_k N`).
    pub known: FxHashMap<Id, Id>,
    /// Per contact, the rate of work of the friction force on the slip (`-F_t·v_s`, the
    /// power dissipated: never negative), with `known` substituted.
    pub dissipation: Vec<Id>,
    /// Per contact, the power of the contact force on the particles (`F·(v_A - v_B)`).
    pub power: Vec<Id>,
}

/// The model of `base` with its contacts in `modes`.
pub fn mode_model(base: &Model, layout: &Layout, modes: &[ContactMode]) -> ModeModel {
    let mut m = base.clone();
    let mut dropped: Vec<usize> = m
        .contacts
        .iter()
        .flat_map(|c| c.replaces_loads.iter().copied())
        .collect();
    dropped.sort_unstable();
    dropped.dedup();
    for &i in dropped.iter().rev() {
        if i < m.loads.len() {
            m.loads.remove(i);
        }
    }
    let mut known = FxHashMap::default();
    let mut dissipation = Vec::new();
    let mut power = Vec::new();
    let contacts = m.contacts.clone();
    for ((c, g), &mode) in contacts.iter().zip(&layout.contacts).zip(modes) {
        let p = &mut m.pool;
        let (n_name, n_id) = c.normal_force.clone();
        let [f1, f2] = c.friction_force.1;
        let mut force = [Pool::ZERO; 3];
        let mut diss = Pool::ZERO;
        if mode == ContactMode::Open {
            known.insert(n_id, Pool::ZERO);
            known.insert(f1, Pool::ZERO);
            known.insert(f2, Pool::ZERO);
        } else {
            if !c.normal_in_model {
                m.reactions.push(Reaction {
                    name: n_name.clone(),
                    id: n_id,
                });
                let nf = vector::scale(p, n_id, c.normal);
                push_on_pair(&mut m.loads, p, c, &format!("normal force {n_name}"), nf);
                if !c.held {
                    m.constraints.push(Constraint {
                        label: format!("contact {}: touching", c.name),
                        equation: c.gap,
                        derivatives: 2,
                        span: c.span.clone(),
                    });
                }
            }
            force = vector::scale(p, n_id, c.normal);
            let symbols = [f1, f2];
            let mu_k = c.friction.map_or(Pool::ZERO, |f| f.1);
            let tangential: Vec<Id> = match mode {
                ContactMode::Stuck => {
                    for (i, (&s, &sym)) in g.slip.iter().zip(&symbols).enumerate() {
                        let name = friction_name(c, i);
                        m.reactions.push(Reaction { name, id: sym });
                        m.constraints.push(Constraint {
                            label: format!("contact {}: not slipping", c.name),
                            equation: s,
                            derivatives: 1,
                            span: c.span.clone(),
                        });
                    }
                    symbols[..g.slip.len()].to_vec()
                }
                ContactMode::Sliding(s) if g.slip.len() == 1 => {
                    let k = p.mul(&[p_num(s), mu_k, n_id]);
                    vec![p.neg(k)]
                }
                ContactMode::Sliding(_) => {
                    let sq: Vec<Id> = g.slip.iter().map(|&s| p.mul2(s, s)).collect();
                    let sum = p.add(&sq);
                    let speed = p.sqrt(sum);
                    g.slip
                        .iter()
                        .map(|&s| {
                            let k = p.mul(&[mu_k, n_id, s]);
                            let k = p.div(k, speed);
                            p.neg(k)
                        })
                        .collect()
                }
                _ => Vec::new(),
            };
            for (i, &sym) in symbols.iter().enumerate() {
                match tangential.get(i) {
                    Some(&v) if v != sym => {
                        known.insert(sym, v);
                    }
                    Some(_) => {}
                    None => {
                        known.insert(sym, Pool::ZERO);
                    }
                }
            }
            if mode != ContactMode::Stuck {
                let mut ft = [Pool::ZERO; 3];
                for (&v, t) in tangential.iter().zip(&g.tangents) {
                    let f = vector::scale(p, v, *t);
                    ft = vector::add(p, ft, f);
                }
                if ft.iter().any(|&x| x != Pool::ZERO) {
                    let label = format!("sliding friction on {}", c.name);
                    push_on_pair(&mut m.loads, p, c, &label, ft);
                }
            } else {
                for (&v, t) in tangential.iter().zip(&g.tangents) {
                    let f = vector::scale(p, v, *t);
                    let label = format!("friction force {}", p.to_text(v));
                    push_on_pair(&mut m.loads, p, c, &label, f);
                }
            }
            for ((&v, t), &s) in tangential.iter().zip(&g.tangents).zip(&g.slip) {
                let f = vector::scale(p, v, *t);
                force = vector::add(p, force, f);
                let d = p.mul2(v, s);
                diss = p.sub(diss, d);
            }
        }
        let p = &mut m.pool;
        let force = force.map(|x| p.subs(x, &known));
        let pw = vector::dot(p, force, g.relative_velocity);
        power.push(pw);
        dissipation.push(p.subs(diss, &known));
    }
    ModeModel {
        model: m,
        known,
        dissipation,
        power,
    }
}

fn p_num(s: i8) -> Id {
    if s < 0 {
        Pool::MINUS_ONE
    } else {
        Pool::ONE
    }
}

/// The name of a contact's friction force along tangent `i`.
pub fn friction_name(c: &Contact, i: usize) -> String {
    if i == 0 {
        c.friction_force.0.clone()
    } else {
        format!("{}_2", c.friction_force.0)
    }
}

/// Pushes `force` on A and its opposite on B.
fn push_on_pair(loads: &mut Vec<Load>, p: &mut Pool, c: &Contact, label: &str, force: [Id; 3]) {
    loads.push(Load {
        label: format!("{label} (contact {})", c.name),
        target: Target::Particle(c.a),
        force,
    });
    if let Some(b) = c.b {
        let neg = force.map(|x| p.neg(x));
        loads.push(Load {
            label: format!("{label} (contact {}, reaction)", c.name),
            target: Target::Particle(b),
            force: neg,
        });
    }
}

/// Values of the coordinates, rates and parameters at t = 0, to evaluate expressions of the
/// initial state.
struct Initial {
    inputs: Vec<Id>,
    values: Vec<f64>,
}

fn initial_values(model: &mut Model) -> Initial {
    let mut inputs = vec![model.pool.time()];
    let mut values = vec![0.0];
    for c in &model.coordinates {
        if let CoordinateKind::Free { initial, rate } = c.kind {
            inputs.push(model.pool.coord(c.sym, 0));
            values.push(initial);
            inputs.push(model.pool.coord(c.sym, 1));
            values.push(rate);
        }
    }
    for par in &model.parameters {
        inputs.push(par.id);
        values.push(par.value);
    }
    Initial { inputs, values }
}

impl Initial {
    fn eval(&self, p: &mut Pool, e: &[Id; 3]) -> [f64; 3] {
        let mut out = [f64::NAN; 3];
        if let Ok(prog) = Program::compile(p, &self.inputs, e) {
            let mut ws = prog.workspace();
            prog.eval(&self.values, &mut ws, &mut out);
        }
        out
    }
}
