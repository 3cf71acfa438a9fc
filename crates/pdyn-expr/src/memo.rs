//! Per-pool caches of pure transformations (expand, simplify, derivatives).
//!
//! Nodes are immutable and hash-consed, so a transformation's result for an id never changes;
//! caching it makes repeated work on shared subexpressions (chains of links, Jacobians) linear
//! in the DAG size instead of the tree size.

use crate::pool::Id;
use rustc_hash::FxHashMap;

/// Smaller sums' content is computed each time (as cheap as looking it up).
pub(crate) const CONTENT_MEMO_TERMS: usize = 8;

#[derive(Clone, Debug, Default)]
pub(crate) struct Memo {
    pub expand: FxHashMap<Id, Id>,
    pub simplify: FxHashMap<Id, Id>,
    /// `factor_terms`: a chain's mass sums recur in `O(n²)` printed entries.
    pub factor: FxHashMap<Id, Id>,
    /// (expression, variable, total time derivative?) → derivative.
    pub diff: FxHashMap<(Id, Id, bool), Id>,
    /// `add_content` of sums of [`CONTENT_MEMO_TERMS`] terms or more: every product with a
    /// sum as a factor asks for it (a 100-link chain's mass sums, in tens of thousands of
    /// products).
    pub content: FxHashMap<Id, Option<(crate::number::Number, Id)>>,
    /// Polynomial work units spent by `simplify`'s rational forms since the pool was made (a
    /// deterministic measure of simplification cost, for regression tests).
    pub simplify_work: u64,
    /// The value of `simplify_work` past which `simplify` stops simplifying, while a
    /// [`Pool::with_simplify_budget`](crate::Pool::with_simplify_budget) runs.
    pub simplify_ceiling: Option<u64>,
    /// Whether `simplify` met the ceiling (and returned an expression unsimplified).
    pub simplify_exceeded: bool,
}
