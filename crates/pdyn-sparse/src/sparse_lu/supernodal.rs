//! The symbolic analysis of a supernodal multifrontal LU on a pattern made symmetric
//! (Davis, *Direct Methods for Sparse Linear Systems*, SIAM 2006, ch. 4 and 7; Liu, "The
//! multifrontal method for sparse matrix solution", SIAM Review 34, 1992).
//!
//! * Order: nested dissection ([`crate::ordering`]), then a postorder of the elimination
//!   tree (the same fill; each subtree's columns contiguous, so that the fronts' update
//!   matrices live on a stack).
//! * Column counts of `L` by row subtrees; the factors' size is bounded before anything of
//!   that size is allocated.
//! * Supernodes: runs of columns with the same structure below their block (fundamental
//!   supernodes: a column whose parent is the next one and whose count is one more), then
//!   relaxed amalgamation of a child into its parent when the merged front has few explicit
//!   zeros (the thresholds of CHOLMOD's `nrelax`/`zrelax`): a net's three coordinates per
//!   particle, and its separators, become dense blocks.
//! * For each supernode: its rows below the block, where each of the matrix's entries goes in
//!   its front, and where each row of its update matrix goes in its parent's front.

use super::{Pattern, SparseLuError};
use crate::ordering::{nested_dissection, Graph};

const NONE: usize = usize::MAX;

/// The supernodal structure of a pattern's factors.
#[derive(Debug)]
pub(crate) struct Supernodes {
    pub n: usize,
    /// `perm[k]`: the unknown (of the analysed pattern) eliminated `k`-th.
    pub perm: Vec<usize>,
    /// Supernode `s` holds the columns `first[s]..first[s + 1]`.
    pub first: Vec<usize>,
    /// Its rows below the diagonal block: `rows[row_start[s]..row_start[s + 1]]`, ascending.
    pub row_start: Vec<usize>,
    pub rows: Vec<usize>,
    /// Where its factors start in the numeric array: the `m × ns` block of its columns
    /// (column-major; `m = ns + r`), then the `ns × r` block of `U` right of it.
    pub lu_start: Vec<usize>,
    /// Where its factors start in the numeric array of a symmetric factorization, which keeps
    /// only the `ns × m` rows of its pivots (`U`, and `L` in the diagonal block).
    pub sym_start: Vec<usize>,
    /// Each of the pattern's values assembled into supernode `s`'s front:
    /// `assembly[asm_start[s]..asm_start[s + 1]]` = (position in the front, value index).
    pub asm_start: Vec<usize>,
    pub assembly: Vec<(usize, usize)>,
    /// The entries of `s`'s front on and below its diagonal come first in its part of
    /// `assembly`, up to `asm_lower[s]` (a symmetric factorization assembles only those).
    pub asm_lower: Vec<usize>,
    /// The children of `s` (ascending; in the numeric phase their update matrices are the
    /// top of the stack, the last child's on top).
    pub child_start: Vec<usize>,
    pub children: Vec<usize>,
    /// Position in the parent's front of each of `s`'s rows below its block (parallel to
    /// `rows`).
    pub rel: Vec<usize>,
    /// The permuted row of each value (for the rows' largest entries).
    pub value_row: Vec<usize>,
    /// The largest front's side, and the most the update stack holds.
    pub max_front: usize,
    pub max_stack: usize,
    /// Entries of `L` below the diagonal as stored (explicit zeros of amalgamation included).
    pub entries: usize,
    /// Entries of `L` below the diagonal that are structurally nonzero.
    pub fill: usize,
}

impl Supernodes {
    /// Supernode count.
    pub fn len(&self) -> usize {
        self.first.len() - 1
    }

    /// Analyses `pattern` (every diagonal present), refusing more than `limit` entries of `L`.
    pub fn new(pattern: &Pattern, limit: usize) -> Result<Supernodes, SparseLuError> {
        let n = pattern.dim();
        // The symmetric graph, without the diagonal.
        let mut degree = vec![0usize; n];
        for i in 0..n {
            for &j in &pattern.cols[pattern.start[i]..pattern.start[i + 1]] {
                if i != j {
                    degree[i] += 1;
                    degree[j] += 1;
                }
            }
        }
        let mut gstart = vec![0usize; n + 1];
        for i in 0..n {
            gstart[i + 1] = gstart[i] + degree[i];
        }
        let mut fill = gstart.clone();
        let mut gadj = vec![0usize; gstart[n]];
        for i in 0..n {
            for &j in &pattern.cols[pattern.start[i]..pattern.start[i + 1]] {
                if i != j {
                    gadj[fill[i]] = j;
                    fill[i] += 1;
                    gadj[fill[j]] = i;
                    fill[j] += 1;
                }
            }
        }
        let nd = nested_dissection(&Graph {
            start: &gstart,
            adj: &gadj,
        });
        let parent_nd = etree(&gstart, &gadj, &nd);
        // Postorder: children before parents, each subtree contiguous.
        let post = postorder(&parent_nd);
        let perm: Vec<usize> = post.iter().map(|&k| nd[k]).collect();
        let mut inv = vec![0usize; n];
        for (k, &v) in perm.iter().enumerate() {
            inv[v] = k;
        }
        let parent = etree(&gstart, &gadj, &perm);
        // Lower neighbours of each permuted row.
        let lower = |k: usize| {
            let v = perm[k];
            gadj[gstart[v]..gstart[v + 1]]
                .iter()
                .map(|&u| inv[u])
                .filter(move |&j| j < k)
        };
        // Column counts of L (below the diagonal) by row subtrees.
        let mut count = vec![0usize; n];
        let mut mark = vec![NONE; n];
        let mut total = 0usize;
        for k in 0..n {
            mark[k] = k;
            for mut j in lower(k) {
                while j != NONE && mark[j] != k {
                    mark[j] = k;
                    count[j] += 1;
                    total += 1;
                    j = parent[j];
                }
            }
            if total > limit {
                return Err(SparseLuError::TooMuchFill { entries: total });
            }
        }
        // Fundamental supernodes.
        let mut fund_first = Vec::new();
        for j in 0..n {
            if j == 0 || !(parent[j - 1] == j && count[j - 1] == count[j] + 1) {
                fund_first.push(j);
            }
        }
        fund_first.push(n);
        let nf = fund_first.len() - 1;
        let mut last_of = vec![NONE; n];
        for s in 0..nf {
            last_of[fund_first[s + 1] - 1] = s;
        }
        // The rows below each fundamental supernode: the structure of its last column.
        let mut frows: Vec<Vec<usize>> = vec![Vec::new(); nf];
        mark.fill(NONE);
        for k in 0..n {
            mark[k] = k;
            for mut j in lower(k) {
                while j != NONE && mark[j] != k {
                    mark[j] = k;
                    if last_of[j] != NONE {
                        frows[last_of[j]].push(k);
                    }
                    j = parent[j];
                }
            }
        }
        // Relaxed amalgamation along the postorder: merge the preceding supernode into this
        // one when it is a child of it and the merged block stays nearly dense.
        struct Node {
            first: usize,
            end: usize,
            rows: Vec<usize>,
            zeros: usize,
        }
        let stored = |ns: usize, r: usize| ns * r + ns * (ns - 1) / 2;
        let mut nodes: Vec<Node> = Vec::with_capacity(nf);
        for (s, rows) in frows.into_iter().enumerate() {
            let mut node = Node {
                first: fund_first[s],
                end: fund_first[s + 1],
                rows,
                zeros: 0,
            };
            while let Some(prev) = nodes.last() {
                let p = parent[prev.end - 1];
                if prev.end != node.first || p == NONE || p >= node.end {
                    break;
                }
                let (ns_p, ns_n, r) = (
                    prev.end - prev.first,
                    node.end - node.first,
                    node.rows.len(),
                );
                let ns = ns_p + ns_n;
                let merged = stored(ns, r);
                let zeros = prev.zeros + node.zeros + merged
                    - stored(ns_p, prev.rows.len())
                    - stored(ns_n, r);
                let z = zeros as f64 / merged.max(1) as f64;
                let accept = ns <= 4 || (ns <= 16 && z < 0.8) || (ns <= 48 && z < 0.1) || z < 0.05;
                if !accept {
                    break;
                }
                node.first = prev.first;
                node.zeros = zeros;
                nodes.pop();
            }
            nodes.push(node);
        }
        let ns_count = nodes.len();
        let mut first = Vec::with_capacity(ns_count + 1);
        let mut row_start = vec![0usize];
        let mut rows = Vec::new();
        let mut entries = 0usize;
        let mut lu_start = vec![0usize];
        let mut sym_start = vec![0usize];
        let mut sn_of = vec![0usize; n];
        for (s, node) in nodes.iter().enumerate() {
            first.push(node.first);
            rows.extend_from_slice(&node.rows);
            row_start.push(rows.len());
            let (ns, r) = (node.end - node.first, node.rows.len());
            entries += stored(ns, r);
            lu_start.push(lu_start[s] + (ns + r) * ns + ns * r);
            sym_start.push(sym_start[s] + ns * (ns + r));
            for j in node.first..node.end {
                sn_of[j] = s;
            }
        }
        first.push(n);
        drop(nodes);
        if entries > limit {
            return Err(SparseLuError::TooMuchFill { entries });
        }
        // The supernodal tree.
        let mut sparent = vec![NONE; ns_count];
        let mut nchild = vec![0usize; ns_count + 1];
        for s in 0..ns_count {
            let p = parent[first[s + 1] - 1];
            if p != NONE {
                sparent[s] = sn_of[p];
                nchild[sn_of[p] + 1] += 1;
            }
        }
        for s in 0..ns_count {
            nchild[s + 1] += nchild[s];
        }
        let child_start = nchild;
        let mut cfill = child_start.clone();
        let mut children = vec![0usize; child_start[ns_count]];
        for s in 0..ns_count {
            if sparent[s] != NONE {
                let p = sparent[s];
                children[cfill[p]] = s;
                cfill[p] += 1;
            }
        }
        // Each value goes to the supernode of its smaller permuted index.
        let mut value_row = vec![0usize; pattern.nnz()];
        let mut per_sn = vec![0usize; ns_count + 1];
        for i in 0..n {
            for q in pattern.start[i]..pattern.start[i + 1] {
                let (pi, pj) = (inv[i], inv[pattern.cols[q]]);
                value_row[q] = pi;
                per_sn[sn_of[pi.min(pj)] + 1] += 1;
            }
        }
        for s in 0..ns_count {
            per_sn[s + 1] += per_sn[s];
        }
        let asm_start = per_sn;
        let mut afill = asm_start.clone();
        let mut raw = vec![(0usize, 0usize, 0usize); pattern.nnz()];
        for i in 0..n {
            for q in pattern.start[i]..pattern.start[i + 1] {
                let (pi, pj) = (inv[i], inv[pattern.cols[q]]);
                let s = sn_of[pi.min(pj)];
                raw[afill[s]] = (pi, pj, q);
                afill[s] += 1;
            }
        }
        // Positions in fronts.
        let mut relpos = vec![NONE; n];
        let mut assembly = vec![(0usize, 0usize); pattern.nnz()];
        let mut asm_lower = vec![0usize; ns_count];
        let mut rel = vec![0usize; rows.len()];
        let (mut max_front, mut stack, mut max_stack) = (0usize, 0usize, 0usize);
        for s in 0..ns_count {
            let (f, e) = (first[s], first[s + 1]);
            let ns = e - f;
            let srows = &rows[row_start[s]..row_start[s + 1]];
            let m = ns + srows.len();
            max_front = max_front.max(m);
            for j in f..e {
                relpos[j] = j - f;
            }
            for (a, &i) in srows.iter().enumerate() {
                relpos[i] = ns + a;
            }
            // The lower triangle's entries first, then the upper's (a stable partition: the
            // values landing on one position are still added in the pattern's order).
            let mut t = asm_start[s];
            for upper in [false, true] {
                for &(pi, pj, q) in &raw[asm_start[s]..asm_start[s + 1]] {
                    if (relpos[pi] < relpos[pj]) == upper {
                        assembly[t] = (relpos[pi] + relpos[pj] * m, q);
                        t += 1;
                    }
                }
                if !upper {
                    asm_lower[s] = t;
                }
            }
            for &c in &children[child_start[s]..child_start[s + 1]] {
                for t in row_start[c]..row_start[c + 1] {
                    rel[t] = relpos[rows[t]];
                }
                let rc = row_start[c + 1] - row_start[c];
                stack -= rc * rc;
            }
            let r = srows.len();
            stack += r * r;
            max_stack = max_stack.max(stack);
        }
        Ok(Supernodes {
            n,
            perm,
            first,
            row_start,
            rows,
            lu_start,
            sym_start,
            asm_start,
            assembly,
            asm_lower,
            child_start,
            children,
            rel,
            value_row,
            max_front,
            max_stack,
            entries,
            fill: total,
        })
    }
}

/// The elimination tree of the symmetric graph `(start, adj)` eliminated in `order` (Liu's
/// algorithm with path compression), in positions of `order`.
fn etree(start: &[usize], adj: &[usize], order: &[usize]) -> Vec<usize> {
    let n = order.len();
    let mut inv = vec![0usize; n];
    for (k, &v) in order.iter().enumerate() {
        inv[v] = k;
    }
    let mut parent = vec![NONE; n];
    let mut ancestor = vec![NONE; n];
    for k in 0..n {
        let v = order[k];
        for &u in &adj[start[v]..start[v + 1]] {
            let mut i = inv[u];
            while i != NONE && i < k {
                let next = ancestor[i];
                ancestor[i] = k;
                if next == NONE {
                    parent[i] = k;
                }
                i = next;
            }
        }
    }
    parent
}

/// A postorder of the forest `parent`: `post[k]` is the node visited `k`-th; children are
/// visited in increasing order.
fn postorder(parent: &[usize]) -> Vec<usize> {
    let n = parent.len();
    let mut head = vec![NONE; n];
    let mut next = vec![NONE; n];
    // Children lists, built backwards so that each list is increasing.
    for j in (0..n).rev() {
        if parent[j] != NONE {
            next[j] = head[parent[j]];
            head[parent[j]] = j;
        }
    }
    let mut post = Vec::with_capacity(n);
    let mut stack = Vec::new();
    for root in 0..n {
        if parent[root] != NONE {
            continue;
        }
        stack.push(root);
        while let Some(&top) = stack.last() {
            let child = head[top];
            if child == NONE {
                stack.pop();
                post.push(top);
            } else {
                head[top] = next[child];
                stack.push(child);
            }
        }
    }
    post
}
