//! Sparse matrices for the statics of many particles: compressed rows (`Csr`) assembled from
//! triplets, and the envelope (profile, "skyline") factorization `P A Pᵀ = L D Lᵀ` of a
//! symmetric matrix, ordered by reverse Cuthill–McKee.
//!
//! A chain, a net or a truss couples each coordinate to a few neighbours; numbered along the
//! structure (RCM: breadth first from a peripheral coordinate, lowest degree first, reversed)
//! every row's non-zeros lie within a short distance `b` of the diagonal, and `L` fills in only
//! inside that envelope: `O(n b)` memory and `O(n b²)` work (a chain `b = 1`, an `m × m` net
//! `b ≈ 3m`). Row `i` of `L` is kept from its first non-zero column `f(i)` to the diagonal, and
//! the factor is computed row by row (Crout):
//!
//! ```text
//! u_ij = a_ij − Σ_{k = max(f(i), f(j))}^{j−1} u_ik L_jk      (j = f(i) … i−1; u_ik = L_ik d_k)
//! L_ij = u_ij / d_j,     d_i = a_ii − Σ_k u_ik L_ik
//! ```
//!
//! No pivoting: `D` may hold negative pivots (`K − σ M` for a shift `σ` inside the spectrum);
//! a zero pivot is the typed [`SparseError::SingularMatrix`].

/// Why a sparse matrix could not be built or factorized.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum SparseError {
    /// A zero (or non-finite) pivot at this row of the reordered matrix.
    SingularMatrix {
        /// The row, in the reordered numbering.
        pivot: usize,
    },
    /// The factor would hold more entries than the limit.
    TooLarge {
        /// Entries the envelope needs.
        entries: usize,
        /// The limit.
        limit: usize,
    },
    /// A triplet outside the matrix.
    OutOfBounds {
        /// Row of the triplet.
        row: usize,
        /// Column of the triplet.
        col: usize,
        /// The matrix's order.
        n: usize,
    },
}

impl std::fmt::Display for SparseError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SparseError::SingularMatrix { pivot } => {
                write!(f, "the matrix is singular (zero pivot at row {pivot})")
            }
            SparseError::TooLarge { entries, limit } => write!(
                f,
                "the sparse factor would hold {entries} entries, more than the limit {limit}"
            ),
            SparseError::OutOfBounds { row, col, n } => {
                write!(f, "entry ({row}, {col}) outside a {n} × {n} matrix")
            }
        }
    }
}

impl std::error::Error for SparseError {}

/// Most entries an envelope factor may hold (2 GB of `f64`).
pub const ENVELOPE_LIMIT: usize = 1 << 28;

/// A square sparse matrix in compressed rows, columns sorted within each row, duplicates summed.
#[derive(Clone, Debug, PartialEq)]
pub struct Csr {
    /// Order.
    pub n: usize,
    /// Row `i` is `col[ptr[i]..ptr[i+1]]`, `val[ptr[i]..ptr[i+1]]`.
    pub ptr: Vec<usize>,
    /// Column indices.
    pub col: Vec<usize>,
    /// Values.
    pub val: Vec<f64>,
}

impl Csr {
    /// The `n × n` matrix with these `(row, column, value)` entries (duplicates added; explicit
    /// zeros kept, so that the pattern is the symbolic one).
    pub fn from_triplets(n: usize, entries: &[(usize, usize, f64)]) -> Result<Csr, SparseError> {
        // One way of sorting triplets into rows: an assembly's, used once.
        Assembly::new(n, entries).map(|(_, matrix)| matrix)
    }

    /// The diagonal matrix `diag(d)`.
    pub fn diagonal(d: &[f64]) -> Csr {
        Csr {
            n: d.len(),
            ptr: (0..=d.len()).collect(),
            col: (0..d.len()).collect(),
            val: d.to_vec(),
        }
    }

    /// Stored entries.
    pub fn nnz(&self) -> usize {
        self.col.len()
    }

    /// Row `i` as `(column, value)` pairs.
    pub fn row(&self, i: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let r = self.ptr[i]..self.ptr[i + 1];
        self.col[r.clone()]
            .iter()
            .copied()
            .zip(self.val[r].iter().copied())
    }

    /// Entry `(i, j)` (zero when not stored).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let r = self.ptr[i]..self.ptr[i + 1];
        match self.col[r.clone()].binary_search(&j) {
            Ok(k) => self.val[r.start + k],
            Err(_) => 0.0,
        }
    }

    /// `y = A x`.
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        for (i, yi) in y.iter_mut().enumerate().take(self.n) {
            *yi = self.row(i).map(|(j, v)| v * x[j]).sum();
        }
    }

    /// `xᵀ A y`.
    pub fn form(&self, x: &[f64], y: &[f64]) -> f64 {
        (0..self.n)
            .map(|i| x[i] * self.row(i).map(|(j, v)| v * y[j]).sum::<f64>())
            .sum()
    }

    /// `Aᵀ`: the entries counted into their columns' rows, which come out sorted since the
    /// rows are visited in order (no sort: damped Newton forms `(K + Kᵀ)/2` at every step).
    pub fn transpose(&self) -> Csr {
        let n = self.n;
        let mut ptr = vec![0usize; n + 1];
        for &j in &self.col {
            ptr[j + 1] += 1;
        }
        for j in 0..n {
            ptr[j + 1] += ptr[j];
        }
        let mut next = ptr[..n].to_vec();
        let mut col = vec![0usize; self.nnz()];
        let mut val = vec![0.0f64; self.nnz()];
        for i in 0..n {
            let r = self.ptr[i]..self.ptr[i + 1];
            for (&j, &v) in self.col[r.clone()].iter().zip(&self.val[r]) {
                let slot = next[j];
                col[slot] = i;
                val[slot] = v;
                next[j] = slot + 1;
            }
        }
        Csr { n, ptr, col, val }
    }

    /// `a A + b B` (the union of the patterns): each row the merge of the two sorted rows, an
    /// entry in both `a A_ij + b B_ij` (as [`Csr::from_triplets`] sums them, in that order).
    pub fn add(&self, a: f64, other: &Csr, b: f64) -> Csr {
        let n = self.n;
        if self.ptr == other.ptr && self.col == other.col {
            // One pattern (`K` and `Kᵀ` of a net, `K` and its refill): entry by entry, the
            // same sums as the merge makes, without it (damped Newton adds at every step).
            let val = self
                .val
                .iter()
                .zip(&other.val)
                .map(|(x, y)| a * x + b * y)
                .collect();
            return Csr {
                n,
                ptr: self.ptr.clone(),
                col: self.col.clone(),
                val,
            };
        }
        let mut ptr = Vec::with_capacity(n + 1);
        let mut col = Vec::with_capacity(self.nnz() + other.nnz());
        let mut val = Vec::with_capacity(self.nnz() + other.nnz());
        ptr.push(0);
        for i in 0..n {
            let (ra, rb) = (self.ptr[i]..self.ptr[i + 1], other.ptr[i]..other.ptr[i + 1]);
            let (ca, va) = (&self.col[ra.clone()], &self.val[ra]);
            let (cb, vb) = (&other.col[rb.clone()], &other.val[rb]);
            let (mut x, mut y) = (0, 0);
            while x < ca.len() || y < cb.len() {
                let (ja, jb) = (
                    ca.get(x).copied().unwrap_or(usize::MAX),
                    cb.get(y).copied().unwrap_or(usize::MAX),
                );
                if ja < jb {
                    col.push(ja);
                    val.push(a * va[x]);
                    x += 1;
                } else if jb < ja {
                    col.push(jb);
                    val.push(b * vb[y]);
                    y += 1;
                } else {
                    col.push(ja);
                    val.push(a * va[x] + b * vb[y]);
                    x += 1;
                    y += 1;
                }
            }
            ptr.push(col.len());
        }
        Csr { n, ptr, col, val }
    }

    /// `max |A_ij − A_ji| / max |A_ij|` (zero for a symmetric or a zero matrix).
    pub fn asymmetry(&self) -> f64 {
        let big = self.val.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if big == 0.0 {
            return 0.0;
        }
        let t = self.transpose();
        let worst = if t.ptr == self.ptr && t.col == self.col {
            // A symmetric pattern: `Aᵀ`'s entry at each position is `A_ji`, no search.
            self.val
                .iter()
                .zip(&t.val)
                .fold(0.0f64, |m, (v, w)| m.max((v - w).abs()))
        } else {
            let mut worst = 0.0f64;
            for i in 0..self.n {
                for (j, v) in self.row(i) {
                    worst = worst.max((v - self.get(j, i)).abs());
                }
            }
            worst
        };
        worst / big
    }

    /// The diagonal.
    pub fn diag(&self) -> Vec<f64> {
        (0..self.n).map(|i| self.get(i, i)).collect()
    }

    /// The matrix in Matrix Market coordinate format (`%%MatrixMarket matrix coordinate real
    /// general`, 1-based indices, every value with the digits that read back to the same
    /// `f64`): for SciPy's `scipy.io.mmread`, MATLAB, Julia.
    pub fn to_matrix_market(&self) -> String {
        use std::fmt::Write;
        let mut s = String::with_capacity(32 * self.nnz() + 64);
        let _ = writeln!(s, "%%MatrixMarket matrix coordinate real general");
        let _ = writeln!(s, "{} {} {}", self.n, self.n, self.nnz());
        for i in 0..self.n {
            for (j, v) in self.row(i) {
                let _ = writeln!(s, "{} {} {v:e}", i + 1, j + 1);
            }
        }
        s
    }

    /// As a dense matrix (tests, small systems).
    pub fn to_dense(&self) -> nalgebra::DMatrix<f64> {
        let mut d = nalgebra::DMatrix::zeros(self.n, self.n);
        for i in 0..self.n {
            for (j, v) in self.row(i) {
                d[(i, j)] += v;
            }
        }
        d
    }
}

/// How a fixed sequence of `(row, column)` triplets lands in a [`Csr`]: the pattern and each
/// triplet's entry, found once (sorting each row), then refilled with new values in `O(nnz)`.
/// A linearization whose pattern never changes (a net's elements) assembles `K` at every
/// Newton step: the sort was a third of the time.
#[derive(Clone, Debug)]
pub struct Assembly {
    n: usize,
    /// Each triplet in order, with where it lands (one array: [`AssemblyFill::add`] reads one
    /// entry per term, with one bounds check; the net's `K` has ~50,000 terms per step).
    terms: Vec<Term>,
    ptr: Vec<usize>,
    col: Vec<usize>,
}

impl Assembly {
    /// The assembly of `entries`' pattern, and their matrix (what [`Csr::from_triplets`] gives).
    pub fn new(n: usize, entries: &[(usize, usize, f64)]) -> Result<(Assembly, Csr), SparseError> {
        let mut count = vec![0usize; n + 1];
        for &(r, c, _) in entries {
            if r >= n || c >= n {
                return Err(SparseError::OutOfBounds { row: r, col: c, n });
            }
            count[r + 1] += 1;
        }
        for i in 0..n {
            count[i + 1] += count[i];
        }
        let mut next = count.clone();
        let mut ck = vec![(0usize, 0usize); entries.len()];
        for (k, &(r, c, _)) in entries.iter().enumerate() {
            ck[next[r]] = (c, k);
            next[r] += 1;
        }
        let mut slot = vec![0usize; entries.len()];
        let mut first = vec![false; entries.len()];
        let mut ptr = Vec::with_capacity(n + 1);
        let mut col: Vec<usize> = Vec::with_capacity(entries.len());
        ptr.push(0);
        for i in 0..n {
            let row = &mut ck[count[i]..count[i + 1]];
            // Stable: the triplets of one entry stay in their order.
            row.sort_by_key(|e| e.0);
            for &(c, k) in row.iter() {
                if !(col.len() > ptr[i] && col.last() == Some(&c)) {
                    col.push(c);
                    first[k] = true;
                }
                slot[k] = col.len() - 1;
            }
            ptr.push(col.len());
        }
        let assembly = Assembly {
            n,
            terms: entries
                .iter()
                .zip(slot.iter().zip(&first))
                .map(|(&(row, column, _), (&slot, &first))| Term {
                    row,
                    column,
                    slot,
                    first,
                })
                .collect(),
            ptr,
            col,
        };
        let matrix = assembly.values(entries);
        Ok((assembly, matrix))
    }

    /// The matrix of `entries`, the same as [`Csr::from_triplets`] gives, or `None` when their
    /// `(row, column)` sequence is not this assembly's.
    pub fn fill(&self, entries: &[(usize, usize, f64)]) -> Option<Csr> {
        if entries.len() != self.terms.len()
            || entries
                .iter()
                .zip(&self.terms)
                .any(|(&(r, c, _), t)| r != t.row || c != t.column)
        {
            return None;
        }
        Some(self.values(entries))
    }

    /// The matrix of terms added one at a time ([`AssemblyFill::add`]) in this assembly's
    /// order: what [`Assembly::fill`] gives of the same terms (the same sums in the same
    /// order), without collecting them as triplets first.
    pub fn filler(&self) -> AssemblyFill<'_> {
        AssemblyFill {
            assembly: self,
            val: vec![0.0; self.col.len()],
            next: 0,
            matches: true,
        }
    }

    /// The matrix of `entries`, known to be this assembly's sequence.
    fn values(&self, entries: &[(usize, usize, f64)]) -> Csr {
        let mut val = vec![0.0f64; self.col.len()];
        for (k, &(_, _, v)) in entries.iter().enumerate() {
            let s = self.terms[k].slot;
            if self.terms[k].first {
                val[s] = v;
            } else {
                val[s] += v;
            }
        }
        Csr {
            n: self.n,
            ptr: self.ptr.clone(),
            col: self.col.clone(),
            val,
        }
    }
}

/// A triplet of an [`Assembly`]'s sequence.
#[derive(Clone, Copy, Debug)]
struct Term {
    row: usize,
    column: usize,
    /// The index in `col`/`val` it adds into.
    slot: usize,
    /// Whether it is its entry's first (it sets the value, the others add to it, as
    /// [`Csr::from_triplets`] sums them: the same additions in the same order).
    first: bool,
}

/// A matrix being filled term by term through an [`Assembly`] ([`Assembly::filler`]).
pub struct AssemblyFill<'a> {
    assembly: &'a Assembly,
    val: Vec<f64>,
    /// Terms added so far.
    next: usize,
    /// Whether every term so far was the assembly's next `(row, column)`.
    matches: bool,
}

impl AssemblyFill<'_> {
    /// Adds the term `(row, column, value)`, the next of the sequence (a term out of it makes
    /// [`AssemblyFill::finish`] give nothing).
    #[inline]
    pub fn add(&mut self, row: usize, column: usize, value: f64) {
        let k = self.next;
        self.next += 1;
        match self.assembly.terms.get(k) {
            Some(t) if self.matches && t.row == row && t.column == column => {
                if t.first {
                    self.val[t.slot] = value;
                } else {
                    self.val[t.slot] += value;
                }
            }
            // Out of the sequence (or after a term that was).
            _ => self.matches = false,
        }
    }

    /// The matrix, or `None` when the terms were not the assembly's sequence (then a new
    /// [`Assembly`] is needed).
    pub fn finish(self) -> Option<Csr> {
        let a = self.assembly;
        (self.matches && self.next == a.terms.len()).then(|| Csr {
            n: a.n,
            ptr: a.ptr.clone(),
            col: a.col.clone(),
            val: self.val,
        })
    }
}

/// `Σ a_k b_k` in four interleaved sums (the compiler vectorizes them; one running sum it may
/// not reorder): the inner loop of the envelope factorization and its solves.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut s = [0.0f64; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for ((s, x), y) in s.iter_mut().zip(x).zip(y) {
            *s += x * y;
        }
    }
    let mut tail = 0.0;
    for (x, y) in ra.iter().zip(rb) {
        tail += x * y;
    }
    (s[0] + s[1]) + (s[2] + s[3]) + tail
}

/// The pattern of `A + Aᵀ` without the diagonal, each vertex's neighbours sorted, in
/// compressed rows (one array for all: a vector per vertex was an allocation per coordinate).
struct Adjacency {
    start: Vec<usize>,
    to: Vec<usize>,
}

impl Adjacency {
    fn of(&self, v: usize) -> &[usize] {
        &self.to[self.start[v]..self.start[v + 1]]
    }

    fn degree(&self, v: usize) -> usize {
        self.start[v + 1] - self.start[v]
    }
}

fn symmetric_adjacency(a: &Csr) -> Adjacency {
    let n = a.n;
    let mut count = vec![0usize; n + 1];
    for i in 0..n {
        for (j, _) in a.row(i) {
            if i != j {
                count[i + 1] += 1;
                count[j + 1] += 1;
            }
        }
    }
    for i in 0..n {
        count[i + 1] += count[i];
    }
    let mut fill = count.clone();
    let mut all = vec![0usize; count[n]];
    for i in 0..n {
        for (j, _) in a.row(i) {
            if i != j {
                all[fill[i]] = j;
                fill[i] += 1;
                all[fill[j]] = i;
                fill[j] += 1;
            }
        }
    }
    // Sorted, and each neighbour once (an entry and its transpose both list it).
    let mut start = Vec::with_capacity(n + 1);
    let mut to = Vec::with_capacity(all.len());
    start.push(0);
    for i in 0..n {
        let row = &mut all[count[i]..count[i + 1]];
        row.sort_unstable();
        let from = to.len();
        for &j in row.iter() {
            if to.len() == from || to.last() != Some(&j) {
                to.push(j);
            }
        }
        start.push(to.len());
    }
    Adjacency { start, to }
}

/// Reverse Cuthill–McKee order of the symmetric pattern of `a` (of `A + Aᵀ`): `perm[new] = old`.
pub fn rcm(a: &Csr) -> Vec<usize> {
    let n = a.n;
    let adj = symmetric_adjacency(a);
    let degree = |i: usize| adj.degree(i);
    let mut placed = vec![false; n];
    let mut order = Vec::with_capacity(n);
    // `mark[v] == pass` says `v` was reached by the current breadth-first pass: one array for
    // every pass (a fresh copy of `placed` per pass cost `n` per pass, `n²` over a matrix of
    // many components, such as a diagonal one).
    let mut mark = vec![0usize; n];
    let mut pass = 0usize;
    let mut next: Vec<usize> = Vec::new();
    // Breadth-first levels from `s` within the unplaced vertices: (order, last level's vertex of
    // least degree, depth).
    let mut bfs = |s: usize, placed: &[bool]| -> (Vec<usize>, usize, usize) {
        pass += 1;
        let mut out = vec![s];
        mark[s] = pass;
        let mut start = 0;
        let mut depth = 0;
        let mut last = s;
        while start < out.len() {
            let end = out.len();
            let mut best = usize::MAX;
            for k in start..end {
                let v = out[k];
                if best == usize::MAX || degree(v) < degree(best) {
                    best = v;
                }
                next.clear();
                next.extend(
                    adj.of(v)
                        .iter()
                        .copied()
                        .filter(|&w| !placed[w] && mark[w] != pass),
                );
                next.sort_by_key(|&w| (degree(w), w));
                for &w in &next {
                    if mark[w] != pass {
                        mark[w] = pass;
                        out.push(w);
                    }
                }
            }
            last = best;
            start = end;
            depth += 1;
        }
        (out, last, depth)
    };
    for s0 in 0..n {
        if placed[s0] {
            continue;
        }
        // Start from the least-degree vertex of this component, then move to a pseudo-peripheral
        // one (the far end of the deepest level structure; a few passes suffice).
        let (comp, _, _) = bfs(s0, &placed);
        // (The component holds s0 itself, so the minimum exists.)
        let mut s = comp
            .iter()
            .copied()
            .min_by_key(|&v| (degree(v), v))
            .unwrap_or(s0);
        let (mut levels, mut far, mut depth) = bfs(s, &placed);
        for _ in 0..4 {
            let (l2, f2, d2) = bfs(far, &placed);
            if d2 <= depth {
                break;
            }
            s = far;
            levels = l2;
            far = f2;
            depth = d2;
        }
        let _ = s;
        for &v in &levels {
            placed[v] = true;
        }
        order.extend(levels);
    }
    order.reverse();
    order
}

/// The inverse of `perm` (`perm[new] = old`) and, for each row of the reordered symmetric
/// pattern of `a`, its first column: the envelope.
fn envelope_rows(a: &Csr, perm: &[usize]) -> (Vec<usize>, Vec<usize>) {
    let n = a.n;
    let mut inv = vec![0usize; n];
    for (new, &old) in perm.iter().enumerate() {
        inv[old] = new;
    }
    let mut first: Vec<usize> = (0..n).collect();
    for i in 0..n {
        for (j, _) in a.row(i) {
            let (r, c) = (inv[i], inv[j]);
            let (r, c) = if r >= c { (r, c) } else { (c, r) };
            if c < first[r] {
                first[r] = c;
            }
        }
    }
    (inv, first)
}

/// Entries below the diagonal that the envelope factor of `a` in the order `perm` would hold
/// ([`EnvelopeLdlt::envelope`]), without factorizing.
pub fn envelope_size(a: &Csr, perm: &[usize]) -> usize {
    let (_, first) = envelope_rows(a, perm);
    first
        .iter()
        .enumerate()
        .fold(0usize, |t, (i, &f)| t.saturating_add(i - f))
}

/// `P A Pᵀ = L D Lᵀ` of a symmetric sparse matrix, `L` unit lower triangular kept by rows over
/// their envelopes. The lower triangle of `(A + Aᵀ)/2` is the matrix factorized.
#[derive(Clone, Debug)]
pub struct EnvelopeLdlt {
    /// `perm[new] = old`.
    perm: Vec<usize>,
    /// First stored column of each row (new numbering).
    first: Vec<usize>,
    /// Start of each row in `l`: row `i` holds columns `first[i]..i`.
    start: Vec<usize>,
    /// The strictly lower entries of `L`.
    l: Vec<f64>,
    /// The pivots.
    d: Vec<f64>,
}

impl EnvelopeLdlt {
    /// Orders `a` by RCM and factorizes it.
    pub fn new(a: &Csr) -> Result<EnvelopeLdlt, SparseError> {
        EnvelopeLdlt::with_order(a, rcm(a))
    }

    /// Factorizes `a` in the order `perm` (`perm[new] = old`).
    pub fn with_order(a: &Csr, perm: Vec<usize>) -> Result<EnvelopeLdlt, SparseError> {
        let n = a.n;
        let (inv, first) = envelope_rows(a, &perm);
        let mut start = Vec::with_capacity(n + 1);
        let mut total = 0usize;
        for (i, &fi) in first.iter().enumerate() {
            start.push(total);
            total = total.saturating_add(i - fi);
        }
        start.push(total);
        if total > ENVELOPE_LIMIT {
            return Err(SparseError::TooLarge {
                entries: total,
                limit: ENVELOPE_LIMIT,
            });
        }
        let mut l = vec![0.0f64; total];
        let mut d = vec![0.0f64; n];
        // Scatter the lower triangle of (A + Aᵀ)/2.
        for i in 0..n {
            for (j, v) in a.row(i) {
                let (r, c) = (inv[i], inv[j]);
                if r == c {
                    d[r] += v;
                } else {
                    let (r, c) = if r > c { (r, c) } else { (c, r) };
                    l[start[r] + c - first[r]] += 0.5 * v;
                }
            }
        }
        let scale = d.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for i in 0..n {
            let fi = first[i];
            let (done, row) = l.split_at_mut(start[i]);
            let row = &mut row[..i - fi];
            // u_ij for j = fi..i, in place.
            for j in fi..i {
                let fj = first[j];
                let k0 = fi.max(fj);
                let lj = &done[start[j] + k0 - fj..start[j] + j - fj];
                let ui = &row[k0 - fi..j - fi];
                let s = dot(ui, lj);
                row[j - fi] -= s;
            }
            let mut di = d[i];
            for j in fi..i {
                let u = row[j - fi];
                let lij = u / d[j];
                di -= u * lij;
                row[j - fi] = lij;
            }
            if !di.is_finite() || di == 0.0 || di.abs() <= scale * 1e-300 {
                return Err(SparseError::SingularMatrix { pivot: i });
            }
            d[i] = di;
        }
        Ok(EnvelopeLdlt {
            perm,
            first,
            start,
            l,
            d,
        })
    }

    /// Order.
    pub fn len(&self) -> usize {
        self.d.len()
    }

    /// True for the empty matrix.
    pub fn is_empty(&self) -> bool {
        self.d.is_empty()
    }

    /// Entries stored in `L`.
    pub fn envelope(&self) -> usize {
        self.l.len()
    }

    /// The pivots `D` (reordered numbering).
    pub fn pivots(&self) -> &[f64] {
        &self.d
    }

    /// Negative pivots: by Sylvester's law of inertia, the number of negative eigenvalues of `A`.
    pub fn negative_pivots(&self) -> usize {
        self.d.iter().filter(|&&x| x < 0.0).count()
    }

    /// Solves `A x = b` in place (`work` of the same length, overwritten).
    pub fn solve_in_place(&self, b: &mut [f64], work: &mut [f64]) {
        let n = self.len();
        for (new, &old) in self.perm.iter().enumerate() {
            work[new] = b[old];
        }
        for i in 0..n {
            let fi = self.first[i];
            let row = &self.l[self.start[i]..self.start[i + 1]];
            let s = dot(row, &work[fi..i]);
            work[i] -= s;
        }
        for (w, d) in work.iter_mut().zip(&self.d) {
            *w /= d;
        }
        for i in (0..n).rev() {
            let fi = self.first[i];
            let xi = work[i];
            let row = &self.l[self.start[i]..self.start[i + 1]];
            for (w, l) in work[fi..i].iter_mut().zip(row) {
                *w -= l * xi;
            }
        }
        for (new, &old) in self.perm.iter().enumerate() {
            b[old] = work[new];
        }
    }

    /// `A⁻¹ b`.
    pub fn solve(&self, b: &[f64]) -> Vec<f64> {
        let mut x = b.to_vec();
        let mut w = vec![0.0; b.len()];
        self.solve_in_place(&mut x, &mut w);
        x
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// `max |x − A⁻¹ b| / max |A⁻¹ b|` with nalgebra's dense LU's `A⁻¹ b`.
    pub(crate) fn error_against_dense(a: &Csr, b: Vec<f64>, x: &[f64]) -> f64 {
        let dense = a
            .to_dense()
            .lu()
            .solve(&nalgebra::DVector::from_vec(b))
            .expect("a regular test matrix");
        let err = x
            .iter()
            .zip(dense.iter())
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        err / dense.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    }

    /// A seeded generator of numbers in [-1, 1) (splitmix64).
    fn rng(seed: u64) -> impl FnMut() -> f64 {
        let mut s = crate::lanczos::Start(seed);
        move || s.next()
    }

    /// A random symmetric matrix with a random sparse pattern, diagonally shifted by `shift`.
    fn random_symmetric(n: usize, per_row: usize, shift: f64, seed: u64) -> Csr {
        let mut r = rng(seed);
        let mut t = Vec::new();
        for i in 0..n {
            t.push((i, i, shift + r()));
            for _ in 0..per_row {
                let j = ((r() + 1.0) * 0.5 * n as f64) as usize % n;
                if j != i {
                    let v = r();
                    t.push((i, j, v));
                    t.push((j, i, v));
                }
            }
        }
        Csr::from_triplets(n, &t).unwrap()
    }

    #[test]
    fn ldlt_solves_like_dense_lu_on_random_symmetric_matrices() {
        for (seed, shift) in [(1u64, 8.0), (2, 0.3), (3, -5.0)] {
            let a = random_symmetric(60, 3, shift, seed);
            let f = EnvelopeLdlt::new(&a).unwrap();
            let mut r = rng(seed + 100);
            let b: Vec<f64> = (0..60).map(|_| r()).collect();
            let x = f.solve(&b);
            let err = error_against_dense(&a, b, &x);
            assert!(err <= 1e-10, "seed {seed}: {err:e}");
            // Sylvester: negative pivots = negative eigenvalues.
            let eig = a.to_dense().symmetric_eigen();
            let neg = eig.eigenvalues.iter().filter(|&&l| l < 0.0).count();
            assert_eq!(f.negative_pivots(), neg, "seed {seed}");
        }
    }

    /// Random triplets, with repeated entries and rows left empty.
    fn random_triplets(n: usize, count: usize, seed: u64) -> Vec<(usize, usize, f64)> {
        let mut r = rng(seed);
        let index = |r: &mut dyn FnMut() -> f64| ((r() + 1.0) * 0.5 * n as f64) as usize % n;
        (0..count)
            .map(|_| {
                let i = index(&mut r);
                // Rows below n/2 only, so that the upper half is empty.
                (i / 2, index(&mut r), r())
            })
            .collect()
    }

    /// Whether two matrices are the same, pattern and values bit for bit.
    fn same_bits(a: &Csr, b: &Csr) -> bool {
        a.n == b.n
            && a.ptr == b.ptr
            && a.col == b.col
            && a.val
                .iter()
                .zip(&b.val)
                .all(|(x, y)| x.to_bits() == y.to_bits())
    }

    /// Each entry is its triplets' values summed in their order (the first sets it), bit for
    /// bit, and each row's columns increase strictly: written from the definition, not from
    /// the assembly.
    fn is_the_sum_in_order(m: &Csr, t: &[(usize, usize, f64)]) -> bool {
        let mut sums: std::collections::HashMap<(usize, usize), f64> = Default::default();
        for &(i, j, v) in t {
            sums.entry((i, j)).and_modify(|s| *s += v).or_insert(v);
        }
        let rows_sorted = (0..m.n).all(|i| {
            m.col[m.ptr[i]..m.ptr[i + 1]]
                .windows(2)
                .all(|w| w[0] < w[1])
        });
        rows_sorted
            && m.nnz() == sums.len()
            && sums
                .iter()
                .all(|(&(i, j), s)| m.get(i, j).to_bits() == s.to_bits())
    }

    #[test]
    fn an_assembly_refills_the_matrix_from_triplets_gives() {
        let n = 40;
        // ~5 triplets per entry: sums of several terms, whose order shows in their bits.
        let t = random_triplets(n, 4000, 11);
        let (assembly, first) = Assembly::new(n, &t).unwrap();
        assert!(is_the_sum_in_order(&first, &t));
        assert!(same_bits(&first, &Csr::from_triplets(n, &t).unwrap()));
        // New values on the same pattern: the same bits as a fresh assembly.
        let mut r = rng(12);
        let u: Vec<(usize, usize, f64)> = t.iter().map(|&(i, j, _)| (i, j, r())).collect();
        let refilled = assembly.fill(&u).unwrap();
        assert!(is_the_sum_in_order(&refilled, &u));
        assert!(same_bits(&refilled, &Csr::from_triplets(n, &u).unwrap()));
        // Another pattern is refused, not misfilled.
        let mut other = u.clone();
        other[3].1 = (other[3].1 + 1) % n;
        assert!(assembly.fill(&other).is_none());
        assert!(assembly.fill(&u[1..]).is_none());
        // An index outside the matrix is an error.
        assert!(Csr::from_triplets(n, &[(0, n, 1.0)]).is_err());
    }

    #[test]
    fn an_assembly_filled_term_by_term_is_the_matrix_from_triplets() {
        let n = 40;
        let t = random_triplets(n, 4000, 13);
        let (assembly, _) = Assembly::new(n, &t).unwrap();
        let mut r = rng(14);
        let u: Vec<(usize, usize, f64)> = t.iter().map(|&(i, j, _)| (i, j, r())).collect();
        let mut fill = assembly.filler();
        for &(i, j, v) in &u {
            fill.add(i, j, v);
        }
        assert!(same_bits(
            &fill.finish().unwrap(),
            &Csr::from_triplets(n, &u).unwrap()
        ));
        // A term out of the sequence, one term short, one too many: nothing.
        let refill = |terms: &[(usize, usize, f64)]| {
            let mut fill = assembly.filler();
            for &(i, j, v) in terms {
                fill.add(i, j, v);
            }
            fill.finish()
        };
        let mut other = u.clone();
        other[3].1 = (other[3].1 + 1) % n;
        assert!(refill(&other).is_none());
        assert!(refill(&u[1..]).is_none());
        assert!(refill(&[&u[..], &u[..1]].concat()).is_none());
    }

    #[test]
    fn transpose_and_add_merge_as_triplets_would() {
        let n = 30;
        let a = Csr::from_triplets(n, &random_triplets(n, 200, 21)).unwrap();
        let b = Csr::from_triplets(n, &random_triplets(n, 150, 22)).unwrap();
        // Aᵀ through triplets, as it was formed before.
        let mut t = Vec::new();
        for i in 0..n {
            t.extend(a.row(i).map(|(j, v)| (j, i, v)));
        }
        assert!(same_bits(
            &a.transpose(),
            &Csr::from_triplets(n, &t).unwrap()
        ));
        let mut t = Vec::new();
        for i in 0..n {
            t.extend(a.row(i).map(|(j, v)| (i, j, 0.5 * v)));
            t.extend(b.row(i).map(|(j, v)| (i, j, -2.0 * v)));
        }
        assert!(same_bits(
            &a.add(0.5, &b, -2.0),
            &Csr::from_triplets(n, &t).unwrap()
        ));
        let dense = a.add(0.5, &b, -2.0).to_dense();
        assert!((dense - (a.to_dense() * 0.5 - b.to_dense() * 2.0)).amax() <= 1e-15);
        // One pattern (entry by entry, no merge): the same bits as the triplets' sums.
        let mut r = rng(23);
        let c = Csr {
            val: a.val.iter().map(|_| r()).collect(),
            ..a.clone()
        };
        let mut t = Vec::new();
        for i in 0..n {
            t.extend(a.row(i).map(|(j, v)| (i, j, 0.5 * v)));
            t.extend(c.row(i).map(|(j, v)| (i, j, -2.0 * v)));
        }
        assert!(same_bits(
            &a.add(0.5, &c, -2.0),
            &Csr::from_triplets(n, &t).unwrap()
        ));
        // The asymmetry of a symmetric pattern (the fast path) and of another, by definition.
        let s = a.add(1.0, &a.transpose(), 1.0);
        let big = s.val.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut skew = s.clone();
        let k = (skew.ptr[3]..skew.ptr[4])
            .find(|&k| skew.col[k] != 3)
            .unwrap();
        skew.val[k] += 0.25 * big;
        let expected = |m: &Csr| {
            let d = m.to_dense();
            (&d - d.transpose()).amax() / d.amax()
        };
        assert_eq!(s.asymmetry(), 0.0);
        assert!(expected(&skew) > 0.1);
        assert_eq!(skew.asymmetry(), expected(&skew));
        assert_eq!(a.asymmetry(), expected(&a));
    }

    #[test]
    fn rcm_keeps_a_shuffled_chain_within_a_band_of_one() {
        // The path graph numbered out of order: RCM recovers a bandwidth of 1, so the envelope
        // holds n − 1 entries.
        let n = 50;
        let mut label: Vec<usize> = (0..n).collect();
        let mut r = rng(7);
        for i in (1..n).rev() {
            let j = ((r() + 1.0) * 0.5 * (i + 1) as f64) as usize % (i + 1);
            label.swap(i, j);
        }
        let mut t = Vec::new();
        for i in 0..n {
            t.push((label[i], label[i], 2.0));
            if i + 1 < n {
                t.push((label[i], label[i + 1], -1.0));
                t.push((label[i + 1], label[i], -1.0));
            }
        }
        let a = Csr::from_triplets(n, &t).unwrap();
        let f = EnvelopeLdlt::new(&a).unwrap();
        assert_eq!(f.envelope(), n - 1);
    }

    /// `perm` holds each of `0..n` once.
    fn is_permutation(perm: &[usize], n: usize) -> bool {
        let mut seen = vec![false; n];
        perm.len() == n
            && perm
                .iter()
                .all(|&v| v < n && !std::mem::replace(&mut seen[v], true))
    }

    #[test]
    fn rcm_orders_a_matrix_of_many_components_in_linear_time() {
        // 200,000 coordinates, nearly all on their own (a diagonal), with a 3-path and a
        // 4-clique among them: every component is numbered together, so the envelope holds
        // the path's 2 entries (band 1) and the clique's 3 + 2 + 1, and nothing else. A copy
        // of an n-entry mark array per component (the old breadth-first search) took
        // 200,000² = 4·10^10 bytes of copying here, tens of seconds; linear work takes
        // milliseconds, so the time bound below separates the two by a wide margin.
        let n = 200_000;
        let mut t: Vec<(usize, usize, f64)> = (0..n).map(|i| (i, i, 4.0)).collect();
        let path = [17, 150_001, 99];
        for w in path.windows(2) {
            t.push((w[0], w[1], -1.0));
            t.push((w[1], w[0], -1.0));
        }
        let clique = [5, 70_000, 123_456, 199_999];
        for &i in &clique {
            for &j in &clique {
                if i != j {
                    t.push((i, j, 0.5));
                }
            }
        }
        let a = Csr::from_triplets(n, &t).unwrap();
        let clock = std::time::Instant::now();
        let order = rcm(&a);
        let took = clock.elapsed();
        assert!(is_permutation(&order, n));
        assert!(
            took < std::time::Duration::from_secs(2),
            "rcm of {n} components took {took:?}"
        );
        let f = EnvelopeLdlt::with_order(&a, order).unwrap();
        assert_eq!(f.envelope(), 2 + 6);
    }

    #[test]
    fn a_singular_matrix_is_a_typed_error() {
        let a =
            Csr::from_triplets(2, &[(0, 0, 1.0), (0, 1, 1.0), (1, 0, 1.0), (1, 1, 1.0)]).unwrap();
        assert!(matches!(
            EnvelopeLdlt::new(&a),
            Err(SparseError::SingularMatrix { .. })
        ));
        assert!(matches!(
            Csr::from_triplets(2, &[(2, 0, 1.0)]),
            Err(SparseError::OutOfBounds { .. })
        ));
    }
}
