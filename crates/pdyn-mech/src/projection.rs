//! The projected (Kane) form `M(q) q'' = f(q, q', t)`, assembled term by term.
//!
//! `M_jk = Σ_p m_p ∂r_p/∂q_j·∂r_p/∂q_k` and `f_j = Σ_p (F_p − m_p a_p|_{q''=0})·∂r_p/∂q_j`.
//! Summed particle by particle, a chain of `n` links gives entries with `O(n²)` terms each
//! (`O(n³)` in all) that only an expensive simplification brings back to the textbook's
//! `l1*l2*(m2 + m3)*cos(q1 - q2)`. Instead, every product is keyed by what does not depend
//! on the particle — the pair of partial velocities for `M`, the pair (acceleration or
//! force term, partial-velocity component) for `f` — and the particles' masses are summed
//! per key: `M_jk = Σ_keys (Σ m_p) * dot`, `f_j = Σ_keys (Σ m_p) * term * component`. In a
//! chain every particle below both links shares one key, so the entries come out with `O(n)`
//! terms each, already collected: the work is `O(n³)` hash look-ups and symbol additions
//! and `O(n²)` expression building.
//!
//! For printing (`contract`), each key's product is contracted back into angle differences
//! (`sin(q1)*cos(q2) − cos(q1)*sin(q2)` → `sin(q1 − q2)`) among terms that share everything
//! but their sines and cosines: small sums, linear work. A run leaves them as products,
//! which evaluate with `2n` sines and cosines instead of `n²`.

use crate::derive::{Equation, ParticleKinematics};
use pdyn_expr::{vector, Func, Id, Node, Pool};
use rustc_hash::FxHashMap;

/// The projected form of a model's equations.
pub(crate) struct Projected {
    /// The printable equations `Σ_k M_jk q_k'' = f_j`, one per free coordinate.
    pub equations: Vec<Equation>,
    /// `M`, row-major (symmetric: `M[j,k]` and `M[k,j]` are the same node).
    pub mass: Vec<Id>,
    /// `f`.
    pub forcing: Vec<Id>,
}

/// `M`, `f` and the equations of the projected form; see the module documentation.
/// `contract`: contract sines and cosines for reading.
#[allow(clippy::too_many_arguments)]
pub(crate) fn projected(
    p: &mut Pool,
    parts: &[ParticleKinematics],
    qd: &[Id],
    qdd: &[Id],
    free: &[usize],
    coordinates: &[crate::model::Coordinate],
    reactions: &[crate::model::Reaction],
    contract: bool,
) -> Projected {
    let n = qd.len();
    let jac = partial_velocities(p, parts, qd);
    let zero_acc: FxHashMap<Id, Id> = qdd.iter().map(|&a| (a, Pool::ZERO)).collect();
    // Mass matrix: (j, k) → dot product → masses; forcing: j → (term, component) → weights.
    let mut mass_groups: Vec<Grouped<Id>> = (0..n * n).map(|_| Grouped::default()).collect();
    let mut dots: FxHashMap<([Id; 3], [Id; 3]), Id> = FxHashMap::default();
    let mut force_groups: Vec<Grouped<(Id, Id)>> = (0..n).map(|_| Grouped::default()).collect();
    for (pi, pk) in parts.iter().enumerate() {
        let nz: Vec<usize> = (0..n)
            .filter(|&j| jac[pi][j].iter().any(|&c| c != Pool::ZERO))
            .collect();
        if nz.is_empty() {
            continue;
        }
        for (a_i, &j) in nz.iter().enumerate() {
            for &k in &nz[a_i..] {
                let key = (jac[pi][j], jac[pi][k]);
                let d = match dots.get(&key) {
                    Some(&d) => d,
                    None => {
                        let d = vector::dot(p, key.0, key.1);
                        let d = if contract {
                            tidy_small(p, d, SMALL_NODES)
                        } else {
                            d
                        };
                        dots.insert(key, d);
                        d
                    }
                };
                if d != Pool::ZERO {
                    mass_groups[j * n + k].push(d, pk.mass);
                }
            }
        }
        // The generalized force minus the velocity-dependent part of m a, term by term:
        // `(weight, term)` with `weight * term` the contribution to one component.
        for (c, (&a_c, &force_c)) in pk.a.iter().zip(&pk.force).enumerate() {
            let mut weighted: Vec<(Id, Id)> = Vec::new();
            for t in addends_at_rest(p, a_c, &zero_acc) {
                let minus_t = p.neg(t);
                weighted.push((pk.mass, minus_t));
            }
            for t in addends(p, force_c) {
                weighted.push(split_mass(p, t, pk.mass));
            }
            for &j in &nz {
                let component = jac[pi][j][c];
                if component == Pool::ZERO {
                    continue;
                }
                for &(w, t) in &weighted {
                    force_groups[j].push((t, component), w);
                }
            }
        }
    }
    let mut sums = MassSums::default();
    let mut mass = vec![Pool::ZERO; n * n];
    for j in 0..n {
        for k in j..n {
            let mut g = std::mem::take(&mut mass_groups[j * n + k]).into_groups();
            g.sort_by_key(|(d, _)| *d);
            let terms: Vec<Id> = g
                .into_iter()
                .map(|(d, ms)| {
                    let total = sums.sum(p, ms);
                    p.mul2(total, d)
                })
                .collect();
            let m = p.add(&terms);
            mass[j * n + k] = m;
            mass[k * n + j] = m;
        }
    }
    let mut forcing = Vec::with_capacity(n);
    let mut eqs = Vec::with_capacity(n);
    for (j, groups) in force_groups.into_iter().enumerate() {
        let mut rhs = forcing_entry(p, groups, contract, &mut sums);
        // Reactions that do no work in this direction vanish only after simplification.
        for r in reactions {
            if p.contains(rhs, r.id) {
                let c = p.diff(rhs, r.id);
                if p.provably_equal(c, Pool::ZERO) {
                    rhs = p.subs1(rhs, r.id, Pool::ZERO);
                }
            }
        }
        let lhs_terms: Vec<Id> = (0..n).map(|k| p.mul2(mass[j * n + k], qdd[k])).collect();
        let lhs = p.add(&lhs_terms);
        forcing.push(rhs);
        eqs.push(Equation {
            label: format!("projection on {}", coordinates[free[j]].name),
            lhs,
            rhs,
        });
    }
    Projected {
        equations: eqs,
        mass,
        forcing,
    }
}

/// Partial velocities `∂v_p/∂q_j' = ∂r_p/∂q_j` of every particle, `[particle][j]`: read off
/// the velocity's terms (it is linear in the rates) when it is built that way, differentiated
/// otherwise.
fn partial_velocities(p: &mut Pool, parts: &[ParticleKinematics], qd: &[Id]) -> Vec<Vec<[Id; 3]>> {
    let n = qd.len();
    let mut jac = Vec::with_capacity(parts.len());
    for pk in parts {
        let comps = pk.v.map(|c| p.linear_coefficients(c, qd));
        let mut rows = vec![[Pool::ZERO; 3]; n];
        for (k, comp) in comps.iter().enumerate() {
            for (j, row) in rows.iter_mut().enumerate() {
                row[k] = match comp {
                    Some(cs) => cs[j],
                    None => p.diff(pk.v[k], qd[j]),
                };
            }
        }
        jac.push(rows);
    }
    jac
}

/// Values pushed under keys, all in one list: `O(n³)` pushes for a chain of `n` links into a
/// vector per key (each grown from empty) were a tenth of the projection.
struct Grouped<K> {
    index: FxHashMap<K, u32>,
    keys: Vec<K>,
    items: Vec<(u32, Id)>,
}

impl<K> Default for Grouped<K> {
    fn default() -> Self {
        Grouped {
            index: FxHashMap::default(),
            keys: Vec::new(),
            items: Vec::new(),
        }
    }
}

impl<K: Copy + Eq + std::hash::Hash> Grouped<K> {
    fn push(&mut self, key: K, value: Id) {
        let next = self.keys.len() as u32;
        let at = *self.index.entry(key).or_insert(next);
        if at == next {
            self.keys.push(key);
        }
        self.items.push((at, value));
    }

    /// Each key (in order of first push) with its values (in order of push).
    fn into_groups(self) -> Vec<(K, Vec<Id>)> {
        let mut counts = vec![0usize; self.keys.len()];
        for &(k, _) in &self.items {
            counts[k as usize] += 1;
        }
        let mut out: Vec<(K, Vec<Id>)> = self
            .keys
            .into_iter()
            .zip(counts)
            .map(|(k, c)| (k, Vec::with_capacity(c)))
            .collect();
        for (k, v) in self.items {
            out[k as usize].1.push(v);
        }
        out
    }
}

/// Sums of particle masses, memoised: in a chain the same suffix sums `m_k + … + m_n` weigh
/// `O(n²)` entries, and building each anew (sorting and interning `O(n)` terms) was most of
/// the projection's time at `n = 100`.
#[derive(Default)]
struct MassSums(FxHashMap<Vec<Id>, Id>);

impl MassSums {
    fn sum(&mut self, p: &mut Pool, weights: Vec<Id>) -> Id {
        if let Some(&s) = self.0.get(&weights) {
            return s;
        }
        let s = p.add(&weights);
        self.0.insert(weights, s);
        s
    }
}

/// The terms of a sum (one term for anything else; none for zero).
fn addends(p: &Pool, e: Id) -> Vec<Id> {
    match p.node(e) {
        Node::Add(ts) => ts.to_vec(),
        _ if e == Pool::ZERO => Vec::new(),
        _ => vec![e],
    }
}

/// The terms of `a` with the accelerations `qdd` set to zero: those of
/// `p.subs(a, zero_acc)`, found without rebuilding the sum (substitution rebuilt each
/// particle's acceleration, `O(n)` terms, a seventh of the projection of a 100-link chain).
/// A term with an acceleration as a factor vanishes; a term that mentions one otherwise
/// (under a function or a power) is left to substitution.
fn addends_at_rest(p: &mut Pool, a: Id, zero_acc: &FxHashMap<Id, Id>) -> Vec<Id> {
    let terms = addends(p, a);
    let mut kept = Vec::with_capacity(terms.len());
    for &t in &terms {
        let factor_is_acceleration = match p.node(t) {
            Node::Mul(fs) => fs.iter().any(|f| zero_acc.contains_key(f)),
            _ => zero_acc.contains_key(&t),
        };
        if factor_is_acceleration {
            continue;
        }
        if mentions_any(p, t, zero_acc) {
            let at_rest = p.subs(a, zero_acc);
            return addends(p, at_rest);
        }
        kept.push(t);
    }
    kept
}

/// Whether a key of `leaves` occurs in `e`: [`Pool::contains_any`] with the set of leaves
/// made once, not for every term (making it was most of the cost on a term of a few nodes).
fn mentions_any(p: &Pool, e: Id, leaves: &FxHashMap<Id, Id>) -> bool {
    let mut seen = rustc_hash::FxHashSet::default();
    let mut stack = vec![e];
    while let Some(x) = stack.pop() {
        if leaves.contains_key(&x) {
            return true;
        }
        if seen.insert(x) {
            p.for_each_child(x, |c| stack.push(c));
        }
    }
    false
}

/// A force term as `(weight, rest)`: the particle's mass taken out when it is a factor
/// (gravity's `-g*m2` → `(m2, -g)`), so that the particles' weights collect into mass sums
/// like their inertia does; `(1, term)` otherwise.
fn split_mass(p: &mut Pool, t: Id, mass: Id) -> (Id, Id) {
    if p.as_num(mass).is_some() {
        return (Pool::ONE, t);
    }
    if t == mass {
        return (mass, Pool::ONE);
    }
    if let Node::Mul(fs) = p.node(t) {
        if let Some(at) = fs.iter().position(|&f| f == mass) {
            let mut rest = fs.to_vec();
            rest.remove(at);
            return (mass, p.mul(&rest));
        }
    }
    (Pool::ONE, t)
}

/// One entry of `f` from its keyed terms: `Σ (Σ weights) * term * component`, terms with
/// equal total weight gathered, and (for reading) their sines and cosines contracted.
fn forcing_entry(
    p: &mut Pool,
    groups: Grouped<(Id, Id)>,
    contract: bool,
    sums: &mut MassSums,
) -> Id {
    let mut keyed = groups.into_groups();
    keyed.sort_by_key(|(k, _)| *k);
    if !contract {
        return forcing_by_component(p, keyed, sums);
    }
    // Total weight → the products it multiplies.
    let mut weighted = Vec::with_capacity(keyed.len());
    for ((t, component), ws) in keyed {
        let w = sums.sum(p, ws);
        let product = p.mul2(t, component);
        if w != Pool::ZERO && product != Pool::ZERO {
            weighted.push((w, product));
        }
    }
    let mut terms = Vec::new();
    for (w, products) in grouped(weighted) {
        let products = contract_by_rest(p, &products);
        let sum = p.add(&products);
        // Distributed, so that each printed term carries its mass sum:
        // `-g*l2*(m2 + m3)*sin(q2) + l1*l2*(m2 + m3)*q1'^2*sin(q1 - q2)`.
        for t in addends(p, sum) {
            terms.push(p.mul2(w, t));
        }
    }
    p.add(&terms)
}

/// One entry of `f` for evaluation: `Σ_c component_c * Σ_t (Σ weights) * t`, each
/// partial-velocity component multiplied once into the sum of the terms it meets (in a chain
/// `l_j*cos(q_j)` and `l_j*sin(q_j)` for the whole row) rather than into every term (about
/// 8 operations per pair of links instead of 12; `pdyn run` of the 100-link chain 3.4 →
/// 2.85 s on a build without LTO).
fn forcing_by_component(p: &mut Pool, keyed: Vec<((Id, Id), Vec<Id>)>, sums: &mut MassSums) -> Id {
    let mut by_component = Vec::with_capacity(keyed.len());
    for ((t, component), ws) in keyed {
        let w = sums.sum(p, ws);
        let term = p.mul2(w, t);
        if term != Pool::ZERO && component != Pool::ZERO {
            by_component.push((component, term));
        }
    }
    let terms: Vec<Id> = grouped(by_component)
        .into_iter()
        .map(|(c, ts)| {
            let sum = p.add(&ts);
            p.mul2(c, sum)
        })
        .collect();
    p.add(&terms)
}

/// `(key, value)` pairs grouped by key, the keys in the order they first appear: the result
/// depends on the input's order only, never on hashing.
fn grouped(pairs: Vec<(Id, Id)>) -> Vec<(Id, Vec<Id>)> {
    let mut index: FxHashMap<Id, usize> = FxHashMap::default();
    let mut out: Vec<(Id, Vec<Id>)> = Vec::new();
    for (k, v) in pairs {
        match index.get(&k) {
            Some(&i) => out[i].1.push(v),
            None => {
                index.insert(k, out.len());
                out.push((k, vec![v]));
            }
        }
    }
    out
}

/// Whether `f` is a sine or cosine (or a power of one).
fn is_trig(p: &Pool, f: Id) -> bool {
    match p.node(f) {
        Node::Call(Func::Sin | Func::Cos, _) => true,
        Node::Pow(b, _) => matches!(p.node(*b), Node::Call(Func::Sin | Func::Cos, _)),
        _ => false,
    }
}

/// `products` with the ones that differ only in their sines, cosines and numeric coefficient
/// summed and contracted: `l1*l2*q1'^2*sin(q1)*cos(q2) − l1*l2*q1'^2*cos(q1)*sin(q2)` →
/// `l1*l2*q1'^2*sin(q1 − q2)`. Each contracted sum is small (the x and y parts of one
/// product), so the work is linear in the number of products.
fn contract_by_rest(p: &mut Pool, products: &[Id]) -> Vec<Id> {
    let mut by_rest = Vec::with_capacity(products.len());
    for &t in products {
        let fs: Vec<Id> = match p.node(t) {
            Node::Mul(fs) => fs.to_vec(),
            _ => vec![t],
        };
        let (trig, rest): (Vec<Id>, Vec<Id>) = fs
            .into_iter()
            .partition(|&f| is_trig(p, f) || p.as_num(f).is_some());
        let rest = p.mul(&rest);
        let trig = p.mul(&trig);
        by_rest.push((rest, trig));
    }
    grouped(by_rest)
        .into_iter()
        .map(|(rest, trig)| {
            let sum = p.add(&trig);
            let sum = if trig.len() > 1 {
                tidy_small(p, sum, SMALL_NODES)
            } else {
                sum
            };
            p.mul2(rest, sum)
        })
        .collect()
}

/// Largest expression the projection hands to `simplify` (a dot product of two partial
/// velocities of a spatial linkage is a few dozen nodes).
const SMALL_NODES: usize = 400;

/// A small trigonometric expression (a dot product of two partial velocities, the x and y
/// parts of one forcing product) contracted, and simplified when a sum of sines and cosines
/// is left (`l^2*sin(q)^2 + l^2*cos(q)^2` → `l^2`) of at most `max_nodes` tree nodes.
pub(crate) fn tidy_small(p: &mut Pool, e: Id, max_nodes: usize) -> Id {
    let c = p.contract_trig(e);
    let trig_sum = matches!(p.node(c), Node::Add(_))
        && p.tree_size(c, max_nodes.saturating_add(1)) <= max_nodes
        && p.any_node(c, &|n| matches!(n, Node::Call(Func::Sin | Func::Cos, _)));
    if trig_sum {
        p.simplify(c)
    } else {
        c
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Dropping the terms with an acceleration factor agrees with substituting zero, and a
    /// term that holds one otherwise goes through substitution.
    #[test]
    fn addends_at_rest_agree_with_substitution() {
        let mut p = Pool::new();
        let q = p.symbol("q", false);
        let (qd, qdd) = (p.coord(q, 1), p.coord(q, 2));
        let zero_acc: FxHashMap<Id, Id> = [(qdd, Pool::ZERO)].into_iter().collect();
        for text in [
            "l*q''*cos(q) - l*q'^2*sin(q)",
            "l*q''*cos(q) - l*q'^2*sin(q) + 3",
            "q''",
            "2*q''^2 + q'",
            "l*q''*cos(q) + sin(q''*q) - q'",
            "g",
            "0",
        ] {
            let a = p.parse_scalar(text).unwrap();
            let by_subs = p.subs(a, &zero_acc);
            let expected = addends(&p, by_subs);
            assert_eq!(addends_at_rest(&mut p, a, &zero_acc), expected, "{text}");
        }
        assert!(mentions_any(&p, qdd, &zero_acc));
        assert!(!mentions_any(&p, qd, &zero_acc));
    }

    #[test]
    fn grouped_keeps_first_appearance_and_push_order() {
        let mut p = Pool::new();
        let ids: Vec<Id> = (0..4).map(|i| p.var(&format!("m{i}"))).collect();
        let mut g: Grouped<u8> = Grouped::default();
        g.push(7, ids[0]);
        g.push(3, ids[1]);
        g.push(7, ids[2]);
        g.push(7, ids[3]);
        assert_eq!(
            g.into_groups(),
            vec![(7, vec![ids[0], ids[2], ids[3]]), (3, vec![ids[1]])]
        );
    }
}
