//! A fill-reducing ordering for the sparse LU of the implicit methods: nested dissection by
//! breadth-first level structures (George 1973; George & Liu, *Computer Solution of Large
//! Sparse Positive Definite Systems*, 1981, ch. 8).
//!
//! A net, a cloth, a lattice of springs couples each particle to its neighbours: the
//! Jacobian's graph is a mesh. Eliminating a mesh in the order its unknowns are numbered
//! (or by reverse Cuthill–McKee) fills a band as wide as the mesh: `O(n · b)` entries and
//! `O(n · b²)` operations, `b ~ √n` on a 2-D mesh. Nested dissection splits the graph by a
//! small separator, orders each part first (recursively) and the separator last, so fill
//! stays inside the parts: `O(n log n)` entries and `O(n^{3/2})` operations on a 2-D mesh.
//!
//! The separator of a part is the middle level of a level structure rooted at a
//! pseudo-peripheral vertex (found by repeated breadth-first searches, George & Liu's
//! algorithm): on a mesh, a line across it. Parts below [`LEAF`] vertices are kept in the
//! breadth-first order they were found in.

/// Parts with at most this many vertices are not split further.
const LEAF: usize = 64;

/// Deepest recursion: a graph that resists splitting (a star, a clique) ends as leaves.
const MAX_DEPTH: usize = 64;

/// An undirected graph in compressed rows: the neighbours of `v` are
/// `adj[start[v]..start[v + 1]]` (no self-loops needed; any present are ignored).
pub struct Graph<'a> {
    /// Row starts, `n + 1` of them.
    pub start: &'a [usize],
    /// Neighbours, row after row.
    pub adj: &'a [usize],
}

impl Graph<'_> {
    fn len(&self) -> usize {
        self.start.len() - 1
    }
    fn neighbours(&self, v: usize) -> &[usize] {
        &self.adj[self.start[v]..self.start[v + 1]]
    }
}

/// The elimination order: `order[k]` is the vertex eliminated `k`-th.
pub fn nested_dissection(g: &Graph) -> Vec<usize> {
    let n = g.len();
    let mut w = Work {
        part: vec![0; n],
        level: vec![usize::MAX; n],
        next_part: 1,
        order: Vec::with_capacity(n),
    };
    let all: Vec<usize> = (0..n).collect();
    for component in w.components(g, &all, 0) {
        w.dissect(g, component, 0);
    }
    w.order
}

struct Work {
    /// The part each vertex belongs to while it is being split.
    part: Vec<usize>,
    /// Scratch: breadth-first levels (`usize::MAX` when unvisited).
    level: Vec<usize>,
    next_part: usize,
    order: Vec<usize>,
}

impl Work {
    fn new_part(&mut self, vertices: &[usize]) -> usize {
        let id = self.next_part;
        self.next_part += 1;
        for &v in vertices {
            self.part[v] = id;
        }
        id
    }

    /// The connected components of `vertices` (all in part `id`), each in breadth-first order.
    fn components(&mut self, g: &Graph, vertices: &[usize], id: usize) -> Vec<Vec<usize>> {
        let mut out = Vec::new();
        for &v in vertices {
            if self.level[v] != usize::MAX {
                continue;
            }
            let levels = self.bfs(g, v, id);
            out.push(levels.into_iter().flatten().collect::<Vec<_>>());
        }
        for &v in vertices {
            self.level[v] = usize::MAX;
        }
        out
    }

    /// The level structure of the component of `root` within part `id`; leaves `level` set
    /// for the vertices reached (the caller resets them).
    fn bfs(&mut self, g: &Graph, root: usize, id: usize) -> Vec<Vec<usize>> {
        let mut levels = vec![vec![root]];
        self.level[root] = 0;
        loop {
            let depth = levels.len();
            let mut next = Vec::new();
            for &v in &levels[depth - 1] {
                for &u in g.neighbours(v) {
                    if self.part[u] == id && self.level[u] == usize::MAX {
                        self.level[u] = depth;
                        next.push(u);
                    }
                }
            }
            if next.is_empty() {
                return levels;
            }
            levels.push(next);
        }
    }

    fn reset(&mut self, levels: &[Vec<usize>]) {
        for &v in levels.iter().flatten() {
            self.level[v] = usize::MAX;
        }
    }

    /// Orders the connected `vertices`: parts first, separator last.
    fn dissect(&mut self, g: &Graph, vertices: Vec<usize>, depth: usize) {
        if vertices.len() <= LEAF || depth >= MAX_DEPTH {
            self.order.extend_from_slice(&vertices);
            return;
        }
        let id = self.new_part(&vertices);
        // A pseudo-peripheral root: restart from a vertex of the last level, of least degree
        // within the part, while the structure gets deeper.
        let mut levels = self.bfs(g, vertices[0], id);
        self.reset(&levels);
        for _ in 0..8 {
            let last = levels.last().map_or(&[][..], |l| &l[..]);
            let degree = |v: usize| {
                g.neighbours(v)
                    .iter()
                    .filter(|&&u| self.part[u] == id)
                    .count()
            };
            let Some(&far) = last.iter().min_by_key(|&&v| degree(v)) else {
                break;
            };
            let deeper = self.bfs(g, far, id);
            self.reset(&deeper);
            if deeper.len() <= levels.len() {
                break;
            }
            levels = deeper;
        }
        if levels.len() < 3 {
            // Too shallow to split by a level (a clique, a star): a leaf.
            self.order.extend_from_slice(&vertices);
            return;
        }
        // The separator: the level where half of the vertices have been passed.
        let half = vertices.len() / 2;
        let mut seen = 0;
        let mut cut = levels.len() / 2;
        for (k, l) in levels.iter().enumerate().skip(1).take(levels.len() - 2) {
            seen += l.len();
            if seen >= half {
                cut = k;
                break;
            }
        }
        let separator = std::mem::take(&mut levels[cut]);
        let before: Vec<usize> = levels[..cut].iter().flatten().copied().collect();
        let after: Vec<usize> = levels[cut + 1..].iter().flatten().copied().collect();
        for side in [before, after] {
            let sid = self.new_part(&side);
            for component in self.components(g, &side, sid) {
                self.dissect(g, component, depth + 1);
            }
        }
        // The separator's vertices leave every part.
        for &v in &separator {
            self.part[v] = 0;
        }
        self.order.extend_from_slice(&separator);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 5-point graph of an `m × m` grid.
    fn grid(m: usize) -> (Vec<usize>, Vec<usize>) {
        let (mut start, mut adj) = (vec![0], Vec::new());
        for i in 0..m {
            for j in 0..m {
                if i > 0 {
                    adj.push((i - 1) * m + j);
                }
                if j > 0 {
                    adj.push(i * m + j - 1);
                }
                if j + 1 < m {
                    adj.push(i * m + j + 1);
                }
                if i + 1 < m {
                    adj.push((i + 1) * m + j);
                }
                start.push(adj.len());
            }
        }
        (start, adj)
    }

    /// Entries of the Cholesky factor's pattern (below the diagonal) for elimination in
    /// `order`, counted by eliminating the graph (each eliminated vertex joins its remaining
    /// neighbours into a clique): independent of the LU code.
    fn fill(start: &[usize], adj: &[usize], order: &[usize]) -> usize {
        use std::collections::BTreeSet;
        let n = start.len() - 1;
        let mut pos = vec![0; n];
        for (k, &v) in order.iter().enumerate() {
            pos[v] = k;
        }
        let mut nb: Vec<BTreeSet<usize>> = (0..n)
            .map(|v| {
                adj[start[v]..start[v + 1]]
                    .iter()
                    .map(|&u| pos[u])
                    .collect()
            })
            .collect();
        let mut nb_by_pos: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); n];
        for v in 0..n {
            nb_by_pos[pos[v]] = std::mem::take(&mut nb[v]);
        }
        let mut total = 0;
        for k in 0..n {
            let later: Vec<usize> = nb_by_pos[k].iter().copied().filter(|&u| u > k).collect();
            total += later.len();
            for &a in &later {
                for &b in &later {
                    if a != b {
                        nb_by_pos[a].insert(b);
                    }
                }
            }
        }
        total
    }

    #[test]
    fn every_vertex_is_ordered_once() {
        for m in [1, 2, 7, 30, 61] {
            let (start, adj) = grid(m);
            let order = nested_dissection(&Graph {
                start: &start,
                adj: &adj,
            });
            let mut seen = order.clone();
            seen.sort_unstable();
            assert_eq!(seen, (0..m * m).collect::<Vec<_>>(), "m = {m}");
        }
    }

    #[test]
    fn disconnected_graphs_and_isolated_vertices_are_ordered() {
        // Two 10 × 10 grids side by side and three isolated vertices.
        let (s, a) = grid(10);
        let mut start = s.clone();
        let mut adj = a.clone();
        for &x in &s[1..] {
            start.push(x + a.len());
        }
        adj.extend(a.iter().map(|&v| v + 100));
        for _ in 0..3 {
            start.push(adj.len());
        }
        let order = nested_dissection(&Graph {
            start: &start,
            adj: &adj,
        });
        let mut seen = order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..203).collect::<Vec<_>>());
    }

    #[test]
    fn a_grid_fills_far_less_than_in_its_natural_order() {
        // On a 40 × 40 grid the natural (row by row) order fills the band: about m entries per
        // row of the factor, ~m³ = 64,000 in all. Nested dissection: O(m² log m), a few times
        // fewer already at this size.
        let m = 40;
        let (start, adj) = grid(m);
        let natural: Vec<usize> = (0..m * m).collect();
        let nd = nested_dissection(&Graph {
            start: &start,
            adj: &adj,
        });
        let (f_nat, f_nd) = (fill(&start, &adj, &natural), fill(&start, &adj, &nd));
        assert!(f_nat > 60_000, "natural order fill {f_nat}");
        assert!(
            f_nd * 2 < f_nat,
            "nested dissection fill {f_nd} vs natural {f_nat}"
        );
    }
}
