//! Recognising a model of free particles in Cartesian coordinates, and grouping its loads by
//! template.
//!
//! A model qualifies when every coordinate is free and is one Cartesian component of one
//! particle (`position = "[x[i,j], y[i,j], 0]"`: components are a coordinate or constant in
//! time), the masses are constants, there are no constraints, frames, reactions, contacts or
//! given accelerations, and every load acts on a particle and reads only parameters, `t`, and
//! the positions and velocities of particles. Its mass matrix is then diagonal and each
//! acceleration is `Σ loads / m`: no linear system, no symbolic solve.
//!
//! A load reads its own particle and a few others (a spring: one). Its acceleration
//! contribution `F / m` with those particles' coordinates replaced by slot symbols (`#0.x`
//! for its own particle, `#1.x` for the first other, ...) is its template: the members of a
//! `[[forces]]` family give the same template up to hash-consing (the canonical
//! constructors order by name, and the slot names are the same for every member), so a
//! 10,000-particle net has a dozen templates, each compiled once. A two-body force between two
//! particles (a spring) is two loads, equal and opposite: one element whose template has both
//! ends' accelerations, so that the force is evaluated once.

use pdyn_expr::{Id, Node, Pool, SymId};
use pdyn_mech::model::{CoordinateKind, Model, Target};
use rustc_hash::{FxHashMap, FxHashSet};

/// Most particles one load may read: its own and three others. A load reading more (a sum
/// over many particles) is refused, and the model takes the generic path.
pub const MAX_SLOTS: usize = 4;

/// One input of a template: a slot's coordinate, a parameter, or `t`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// A component of one of the element's particles.
    Slot {
        /// Which particle of the element (0: the load's own).
        slot: u8,
        /// x, y, z.
        axis: u8,
        /// Position (0) or velocity (1).
        order: u8,
    },
    /// The parameter with this index in model order.
    Parameter(u32),
    /// Time.
    Time,
}

/// `F / m` of each particle an element pushes, with its slot: `(slot, [x, y, z])`.
pub type ActsOn = Vec<(u8, [Id; 3])>;

/// The loads that share one template.
pub struct Group {
    /// Particles per element: the load's own first, then the others by index.
    pub slots: usize,
    /// `F / m` (x, y, z, over the slot symbols) of each particle the element pushes, with the
    /// slot of that particle: the load's own (slot 0), and for a two-body force between two
    /// particles (a spring: its second load the first's opposite) the other end (slot 1) as
    /// well, so that the force is evaluated once for both ends.
    pub acts_on: ActsOn,
    /// The particles of each element, `slots` per element (indices into `Model::particles`).
    pub particles: Vec<u32>,
}

impl Group {
    /// Every output of the template, `acts_on` in order, x, y, z each.
    pub fn outputs(&self) -> Vec<Id> {
        self.acts_on.iter().flat_map(|(_, t)| *t).collect()
    }
}

/// A model of free particles in Cartesian coordinates, its loads grouped by template.
pub struct Structure {
    /// Per particle, per axis: the index of the free coordinate that is this component (its
    /// position in the state), or `None` for a component constant in time.
    pub axes: Vec<[Option<u32>; 3]>,
    /// The loads, by template, in order of first appearance.
    pub groups: Vec<Group>,
    /// The slot symbols, `[slot][axis]`.
    pub slot_symbols: Vec<[SymId; 3]>,
}

/// The model's structure, or `None` when it is not one of free particles in Cartesian
/// coordinates (it then takes the generic path: nothing here is an error).
pub fn recognise(model: &mut Model) -> Option<Structure> {
    if !model.frames.is_empty()
        || !model.constraints.is_empty()
        || !model.reactions.is_empty()
        || !model.contacts.is_empty()
        || !model.known_accelerations.is_empty()
        || !model.friction_power.is_empty()
        || !model.unknowns.is_empty()
        || model.particles.is_empty()
    {
        return None;
    }
    // Every coordinate free; its symbol → its index in the state.
    let mut state_index: FxHashMap<SymId, u32> = FxHashMap::default();
    for (k, c) in model.coordinates.iter().enumerate() {
        if !matches!(c.kind, CoordinateKind::Free { .. }) {
            return None;
        }
        state_index.insert(c.sym, k as u32);
    }
    let p = &model.pool;
    let moves = |e: Id| p.any_node(e, &|n| matches!(n, Node::Coord(..) | Node::Time));
    // Each coordinate one component of one particle.
    let mut owner: FxHashMap<SymId, (u32, u8)> = FxHashMap::default();
    let mut axes = Vec::with_capacity(model.particles.len());
    for (i, part) in model.particles.iter().enumerate() {
        if moves(part.mass) {
            return None;
        }
        let mut a = [None; 3];
        for (c, &e) in part.position.iter().enumerate() {
            match p.node(e) {
                Node::Coord(s, 0) => {
                    let &k = state_index.get(s)?;
                    if owner.insert(*s, (i as u32, c as u8)).is_some() {
                        return None;
                    }
                    a[c] = Some(k);
                }
                _ if moves(e) => return None,
                _ => {}
            }
        }
        axes.push(a);
    }
    if owner.len() != model.coordinates.len() {
        return None;
    }
    let parameters: FxHashSet<SymId> = model
        .parameters
        .iter()
        .filter_map(|q| match p.node(q.id) {
            Node::Sym(s) => Some(*s),
            _ => None,
        })
        .collect();

    let pool = &mut model.pool;
    let slot_symbols: Vec<[SymId; 3]> = (0..MAX_SLOTS)
        .map(|s| ["x", "y", "z"].map(|axis| pool.symbol(&format!("#{s}.{axis}"), false)))
        .collect();
    let mut groups: Vec<Group> = Vec::new();
    let mut by_signature: FxHashMap<(usize, [u128; 3], Id, Option<Id>), usize> =
        FxHashMap::default();
    let mut by_template: FxHashMap<(usize, ActsOn), usize> = FxHashMap::default();
    let mut signer = Signer::default();
    // The first loads of the representatives of deferred families: the group and the
    // particles of their elements.
    let representatives: FxHashMap<usize, usize> = model
        .deferred
        .iter()
        .enumerate()
        .map(|(k, d)| (d.first_load, k))
        .collect();
    let mut joined = 0;
    let loads = &model.loads;
    let mut next = 0;
    while next < loads.len() {
        let first = next;
        let load = &loads[next];
        next += 1;
        let Target::Particle(own) = load.target else {
            return None;
        };
        // The particles the load reads, its own first.
        let mut others: Vec<u32> = Vec::new();
        for n in pool.topo_order(&load.force) {
            match pool.node(n) {
                Node::Coord(s, order) => {
                    let &(i, _) = owner.get(s)?;
                    if *order > 1 {
                        return None;
                    }
                    if i as usize != own && !others.contains(&i) {
                        others.push(i);
                    }
                }
                Node::Sym(s) if !parameters.contains(s) => return None,
                _ => {}
            }
        }
        others.sort_unstable();
        if others.len() + 1 > MAX_SLOTS {
            return None;
        }
        // A two-body force between two particles pushes its opposite on the other end as the
        // next load (`push_pair`): one element acting on both.
        let partner = match (others.as_slice(), loads.get(next)) {
            (&[other], Some(second))
                if second.target == Target::Particle(other as usize)
                    && (0..3).all(|c| second.force[c] == pool.neg(load.force[c])) =>
            {
                next += 1;
                Some(other as usize)
            }
            _ => None,
        };
        let mut members = vec![own as u32];
        members.extend(others);
        signer.slots.clear();
        signer.local.clear();
        for (slot, &i) in members.iter().enumerate() {
            for (axis, &c) in model.particles[i as usize].position.iter().enumerate() {
                if let Node::Coord(s, 0) = *pool.node(c) {
                    signer.slots.push((s, slot as u8, axis as u8));
                }
            }
        }
        // Loads equal up to the renaming of their particles into slots (and the order of
        // terms and factors) have one signature; only the first of each is rewritten over
        // the slot symbols. Rewriting every member was 80 µs a load.
        let signature = load.force.map(|f| signer.sign(pool, f));
        let mass = model.particles[own].mass;
        let partner_mass = partner.map(|b| model.particles[b].mass);
        let key = (members.len(), signature, mass, partner_mass);
        let g = match by_signature.get(&key) {
            Some(&g) => g,
            None => {
                let mut map: FxHashMap<Id, Id> = FxHashMap::default();
                for &(s, slot, axis) in &signer.slots {
                    for order in 0..2 {
                        let from = pool.coord(s, order);
                        let to = pool.coord(slot_symbols[slot as usize][axis as usize], order);
                        map.insert(from, to);
                    }
                }
                let mut acts_on = vec![(
                    0u8,
                    load.force.map(|f| {
                        let a = pool.div(f, mass);
                        pool.subs(a, &map)
                    }),
                )];
                if let Some(m) = partner_mass {
                    let on_partner = load.force.map(|f| {
                        let minus = pool.neg(f);
                        let a = pool.div(minus, m);
                        pool.subs(a, &map)
                    });
                    acts_on.push((1, on_partner));
                }
                // Two signatures may give one template: a difference of two coordinates is
                // ordered by their names (`x[9,0] - x[10,0]` and `x[1,0] - x[2,0]` sign
                // differently), the slots' names are the same for every member.
                let g = *by_template
                    .entry((members.len(), acts_on.clone()))
                    .or_insert_with(|| {
                        groups.push(Group {
                            slots: members.len(),
                            acts_on,
                            particles: Vec::new(),
                        });
                        groups.len() - 1
                    });
                by_signature.insert(key, g);
                g
            }
        };
        groups[g].particles.extend(&members);
        // The members of a deferred family are its representative's element with other
        // particles, in the same slots: their index arrays join its group as they are,
        // right after it, where the expanded model's members stand (the same order of
        // terms, hence the same bits, as the full load).
        if let Some(&k) = representatives.get(&first) {
            let d = &model.deferred[k];
            if next - first != d.loads || members != d.ends || groups[g].slots != d.ends.len() {
                return None;
            }
            groups[g].particles.extend(&d.members);
            joined += 1;
        }
    }
    if joined != model.deferred.len() {
        return None;
    }
    Some(Structure {
        axes,
        groups,
        slot_symbols,
    })
}

/// Structural signatures of expressions with their particles' coordinates replaced by slots:
/// two expressions have the same signature when they are equal up to that renaming and the
/// order of terms and factors (128 bits of SipHash: a collision, which would give a load
/// another's template, is not a practical possibility). A subexpression without coordinates
/// is its own node: hash-consing makes equal ones one id.
#[derive(Default)]
struct Signer {
    /// The current load's coordinates: `(symbol, slot, axis)`.
    slots: Vec<(SymId, u8, u8)>,
    /// Nodes known to hold no coordinate (for every load).
    constant: FxHashSet<Id>,
    /// Signatures of the current load's nodes that hold coordinates.
    local: FxHashMap<Id, u128>,
}

impl Signer {
    /// The signature of `e` under the current slots.
    fn sign(&mut self, pool: &Pool, e: Id) -> u128 {
        self.slot_dependent(pool, e)
            .unwrap_or_else(|| hash128(&(0u8, e)))
    }

    /// The signature of `e`, or `None` when it holds no coordinate.
    fn slot_dependent(&mut self, pool: &Pool, e: Id) -> Option<u128> {
        if self.constant.contains(&e) {
            return None;
        }
        if let Some(&s) = self.local.get(&e) {
            return Some(s);
        }
        let signature = match pool.node(e) {
            Node::Coord(sym, order) => self
                .slots
                .iter()
                .find(|x| x.0 == *sym)
                .map(|&(_, slot, axis)| hash128(&(1u8, slot, axis, *order)))
                // Not one of the load's particles (cannot happen): itself, and not cached as
                // constant.
                .or_else(|| Some(hash128(&(6u8, e)))),
            Node::Add(xs) | Node::Mul(xs) => {
                let tag = if matches!(pool.node(e), Node::Add(_)) {
                    2u8
                } else {
                    3
                };
                let parts: Vec<Option<u128>> =
                    xs.iter().map(|&x| self.slot_dependent(pool, x)).collect();
                if parts.iter().all(Option::is_none) {
                    None
                } else {
                    // Terms and factors as a multiset: their order follows names.
                    let mut kids: Vec<u128> = parts
                        .iter()
                        .zip(xs.iter())
                        .map(|(s, &x)| s.unwrap_or_else(|| hash128(&(0u8, x))))
                        .collect();
                    kids.sort_unstable();
                    Some(hash128(&(tag, kids)))
                }
            }
            Node::Pow(b, x) => {
                let (b, x) = (*b, *x);
                let (sb, sx) = (self.slot_dependent(pool, b), self.slot_dependent(pool, x));
                if sb.is_none() && sx.is_none() {
                    None
                } else {
                    let sb = sb.unwrap_or_else(|| hash128(&(0u8, b)));
                    let sx = sx.unwrap_or_else(|| hash128(&(0u8, x)));
                    Some(hash128(&(4u8, sb, sx)))
                }
            }
            Node::Call(f, args) => {
                let f = *f;
                let args: Vec<Id> = args.to_vec();
                let parts: Vec<Option<u128>> =
                    args.iter().map(|&x| self.slot_dependent(pool, x)).collect();
                if parts.iter().all(Option::is_none) {
                    None
                } else {
                    let kids: Vec<u128> = parts
                        .iter()
                        .zip(&args)
                        .map(|(s, &x)| s.unwrap_or_else(|| hash128(&(0u8, x))))
                        .collect();
                    Some(hash128(&(5u8, f, kids)))
                }
            }
            _ => None,
        };
        match signature {
            None => {
                self.constant.insert(e);
            }
            Some(s) => {
                self.local.insert(e, s);
            }
        }
        signature
    }
}

/// 128 bits of SipHash (two keyed passes of the standard library's hasher).
fn hash128<T: std::hash::Hash>(x: &T) -> u128 {
    use std::hash::{BuildHasher, Hasher};
    let lane = |key: u8| {
        let mut h =
            std::hash::BuildHasherDefault::<std::collections::hash_map::DefaultHasher>::default()
                .build_hasher();
        h.write_u8(key);
        x.hash(&mut h);
        h.finish()
    };
    (u128::from(lane(0)) << 64) | u128::from(lane(1))
}

/// The inputs a template reads, in a fixed order: slot coordinates (slot, axis, order),
/// parameters in model order, `t`.
pub fn template_inputs(
    pool: &mut Pool,
    template: &[Id],
    slots: usize,
    slot_symbols: &[[SymId; 3]],
    parameters: &[Id],
) -> (Vec<Id>, Vec<Source>) {
    let present: FxHashSet<Id> = pool.topo_order(template).into_iter().collect();
    let (mut leaves, mut sources) = (Vec::new(), Vec::new());
    for (slot, symbols) in slot_symbols.iter().enumerate().take(slots) {
        for (axis, &s) in symbols.iter().enumerate() {
            for order in 0..2u8 {
                let leaf = pool.coord(s, order);
                if present.contains(&leaf) {
                    leaves.push(leaf);
                    sources.push(Source::Slot {
                        slot: slot as u8,
                        axis: axis as u8,
                        order,
                    });
                }
            }
        }
    }
    for (k, &q) in parameters.iter().enumerate() {
        if present.contains(&q) {
            leaves.push(q);
            sources.push(Source::Parameter(k as u32));
        }
    }
    let t = pool.time();
    if present.contains(&t) {
        leaves.push(t);
        sources.push(Source::Time);
    }
    (leaves, sources)
}
