//! The equations of motion in matrix form, `M(q) q'' = f(q, q', t)`, with each entry
//! collected and factored as a textbook (or SymPy's KanesMethod) prints it:
//! `M[1,2] = l1*l2*(m2 + m3)*cos(q1 - q2)`,
//! `f[1] = -g*l1*(m1 + m2 + m3)*sin(q1) - l1*l2*(m2 + m3)*q2'^2*sin(q1 - q2) - …`.
//!
//! This is for reading only (`pdyn derive`, its `--json`, Python's `Derivation`): what runs is
//! the derivation's own `A x = b`. Each entry is simplified when it is small (a product factor
//! by factor, which keeps the mass sums of a chain's entries as they were assembled) and then
//! collected over its factors that depend on the state ([`Pool::collect_terms`]); entries over
//! [`TIDY_NODES`] are left as derived, so the cost is bounded per entry and O(n²) small
//! entries for `n` coordinates: nothing large is simplified or solved just to be printed.

use crate::derive::{Derivation, UnknownKind};
use pdyn_expr::factor::Collected;
use pdyn_expr::{Id, Node, Pool};
use rustc_hash::FxHashMap;
use std::cell::RefCell;

/// Entries with more tree nodes than this are not simplified or collected: their collected
/// form would not print within [`pdyn_expr::budget::PRINT_CHARS`] anyway.
pub const TIDY_NODES: usize = 20_000;
/// Entries with more tree nodes than this are not handed to `simplify` (as in the
/// derivation's own simplification of printed expressions), only expanded and contracted.
const SIMPLIFY_NODES: usize = 4_000;

/// One entry of `M` or `f`.
#[derive(Clone, Debug)]
pub struct Entry {
    /// The entry, equal to the derivation's (simplified when small).
    pub expr: Id,
    /// The entry collected over its state-dependent factors, coefficients factored; `None`
    /// when it is over [`TIDY_NODES`].
    pub collected: Option<Collected>,
}

impl Entry {
    /// [`Entry::render`] as text, sharing `memo`'s texts of long sums (a chain's mass sums)
    /// with the other entries.
    pub fn render_text_memo(&self, p: &mut Pool, memo: &pdyn_expr::print::TextMemo) -> String {
        match &self.collected {
            Some(c) => c.to_text_memo(p, memo),
            None => p.to_text_memo(self.expr, memo),
        }
    }

    /// The entry as text (re-parsable in the model's scope) or LaTeX, whole.
    pub fn render(&self, p: &mut Pool, latex: bool) -> String {
        match (&self.collected, latex) {
            (Some(c), false) => c.to_text(p),
            (Some(c), true) => c.to_latex(p),
            (None, false) => p.to_text(self.expr),
            (None, true) => p.to_latex(self.expr),
        }
    }
}

/// `M q'' = f` of a derivation whose unknowns are all accelerations (the projected form, or
/// Newton's equations without reactions).
#[derive(Clone, Debug)]
pub struct MatrixForm {
    /// Number of coordinates (`M` is `n × n`).
    pub n: usize,
    /// The accelerations, in column order.
    pub accelerations: Vec<Id>,
    /// `M`, row-major; symmetric in the projected form (`M[j,k]` and `M[k,j]` are one entry).
    pub mass: Vec<Entry>,
    /// `f`.
    pub forcing: Vec<Entry>,
    /// Whether `M` is symmetric (every `M[j,k]` is the same node as `M[k,j]`).
    pub symmetric: bool,
}

/// Whether `f` depends on the state or time: the "main" factors entries are collected over.
pub fn depends_on_state(p: &Pool, f: Id) -> bool {
    match p.node(f) {
        Node::Coord(..) | Node::Time => true,
        Node::Sym(_) | Node::Num(_) | Node::Const(_) => false,
        _ => p.any_node(f, &|n| matches!(n, Node::Coord(..) | Node::Time)),
    }
}

/// [`depends_on_state`] remembering its answers for sums and calls: the 100-link chain's
/// entries share a hundred mass sums `m_k + … + m_100` that every term of `f` carries, and
/// walking them again for each term was most of collecting `f`.
struct StateTest(RefCell<FxHashMap<Id, bool>>);

impl StateTest {
    fn new() -> StateTest {
        StateTest(RefCell::new(FxHashMap::default()))
    }

    fn test(&self, p: &Pool, f: Id) -> bool {
        match p.node(f) {
            Node::Coord(..) | Node::Time => true,
            Node::Sym(_) | Node::Num(_) | Node::Const(_) => false,
            _ => {
                if let Some(&known) = self.0.borrow().get(&f) {
                    return known;
                }
                let r = depends_on_state(p, f);
                self.0.borrow_mut().insert(f, r);
                r
            }
        }
    }
}

/// Largest number of unknowns whose `M` is laid out entry by entry: 1,200 (the 398-particle
/// net's 1,194 coordinates), 1.4·10⁶ entries. A 10⁴-particle cloth's 29,994 would ask for
/// 9·10⁸ entries (29 GB) to print a matrix nobody reads; its equations are printed as
/// Newton's.
pub const MATRIX_FORM_MAX_UNKNOWNS: usize = 1_200;

/// The matrix form of `d`, or `None` when some unknown is a reaction (then `A x = b` mixes
/// accelerations and forces: Newton's equations are printed as they are) or when there are
/// more than [`MATRIX_FORM_MAX_UNKNOWNS`] unknowns.
pub fn matrix_form(p: &mut Pool, d: &Derivation) -> Option<MatrixForm> {
    if d.system.cols() > MATRIX_FORM_MAX_UNKNOWNS {
        return None;
    }
    if d.unknowns.is_empty()
        || d.unknowns
            .iter()
            .any(|u| !matches!(u.kind, UnknownKind::Acceleration(_)))
        || d.system.rows() != d.system.cols()
    {
        return None;
    }
    let n = d.system.cols();
    let state = StateTest::new();
    let main = |p: &Pool, f: Id| state.test(p, f);
    let mut mass: Vec<Option<Entry>> = vec![None; n * n];
    for j in 0..n {
        for k in 0..n {
            if mass[j * n + k].is_some() {
                continue;
            }
            let e = tidy(p, d.system.coeff(j, k), d.assembled_collected, &main);
            if k > j && d.system.coeff(k, j) == d.system.coeff(j, k) {
                mass[k * n + j] = Some(e.clone());
            }
            mass[j * n + k] = Some(e);
        }
    }
    let symmetric = (0..n).all(|j| (0..j).all(|k| d.system.coeff(j, k) == d.system.coeff(k, j)));
    let forcing = d
        .system
        .b
        .iter()
        .map(|&b| tidy(p, b, d.assembled_collected, &main))
        .collect();
    Some(MatrixForm {
        n,
        accelerations: d.system.unknowns.clone(),
        mass: mass.into_iter().flatten().collect(),
        forcing,
        symmetric,
    })
}

/// Simplifies (when small) and collects one entry; `assembled`: it was collected and
/// contracted as it was assembled (the projected form), so it is only collected here.
/// `main`: [`depends_on_state`].
fn tidy(p: &mut Pool, e: Id, assembled: bool, main: &dyn Fn(&Pool, Id) -> bool) -> Entry {
    if assembled {
        return Entry {
            expr: e,
            collected: Some(p.collect_terms(e, main)),
        };
    }
    if p.tree_size(e, TIDY_NODES + 1) > TIDY_NODES {
        return Entry {
            expr: e,
            collected: None,
        };
    }
    // A product is simplified factor by factor: a chain's `(m2 + m3)*(l1*l2*cos(q1)*cos(q2) +
    // l1*l2*sin(q1)*sin(q2))` becomes `l1*l2*(m2 + m3)*cos(q1 - q2)` without expanding the
    // mass sum into the trigonometric one (n times more terms to contract). Contracting
    // products of sines and cosines is enough for most factors and several times cheaper
    // than `simplify` (which a 100-link chain's 5,050 entries would spend a second on in a
    // debug build); a factor still a sum of trigonometric terms (`l1^2*sin(q1)^2 +
    // l1^2*cos(q1)^2`) is simplified.
    let s = match p.node(e) {
        Node::Mul(fs) => {
            let fs = fs.to_vec();
            let s: Vec<Id> = fs
                .iter()
                .map(|&f| crate::projection::tidy_small(p, f, usize::MAX))
                .collect();
            p.mul(&s)
        }
        // A sum (a forcing term: every particle's contribution, x and y parts apart) is
        // expanded and its sines and cosines contracted, which pairs `cos(q1)*sin(q2)` with
        // `sin(q1)*cos(q2)` across the parts: linear in the expanded size, where `simplify`'s
        // rational normal form gives up past a 10-link chain. Whichever is smaller is kept.
        Node::Add(_) => {
            let simplified = if p.tree_size(e, SIMPLIFY_NODES + 1) <= SIMPLIFY_NODES {
                p.simplify(e)
            } else {
                e
            };
            match p.try_expand(e) {
                Ok(x) => {
                    // Compared once collected: that is what prints.
                    let c = p.contract_trig(x);
                    let collected_size = |p: &mut Pool, id| {
                        let c = p.collect_by(id, main);
                        p.tree_size(c, usize::MAX)
                    };
                    if collected_size(p, c) < collected_size(p, simplified) {
                        c
                    } else {
                        simplified
                    }
                }
                Err(_) => simplified,
            }
        }
        _ => p.simplify(e),
    };
    let collected = p.collect_terms(s, main);
    Entry {
        expr: s,
        collected: Some(collected),
    }
}
