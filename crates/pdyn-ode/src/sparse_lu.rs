//! Sparse LU of the implicit methods' iteration matrices `c·I − J` (real `c`, and complex
//! `c = α + iβ` for Radau5's second system), for Jacobians whose pattern is known: a net of
//! 10^4 particles has 6·10^4 states, whose dense matrices would take 29 GB.
//!
//! * Ordering: nested dissection ([`crate::ordering`]) of the pattern made symmetric.
//! * Symbolic analysis, once per pattern: the elimination tree (Liu's algorithm with path
//!   compression) and, for each row `k`, the columns `j < k` where `L(k, j)` (and `U(j, k)`)
//!   may be nonzero: the row subtree of `k` (Davis, *Direct Methods for Sparse Linear Systems*,
//!   SIAM 2006, §4.2), sorted ascending, which is an order of elimination.
//! * Numeric factorization, up-looking, row `k` at a time: `U(:, k)` by a sparse forward
//!   solve with the columns of `L` computed so far, `L(k, :)` by a sparse forward solve with
//!   `Uᵀ`, on the symmetric pattern. No pivoting: these matrices are dominated by `c·I` for
//!   small steps, and for a mechanical system `c²M + cC + K` with `K`, `C` symmetric positive
//!   semidefinite (for the real `c`) or with a positive definite imaginary part (for the
//!   complex one), whose elimination without pivoting does not break down. A pivot that is
//!   zero, not finite, or below `PIVOT_FLOOR` of its row's largest entry is reported as
//!   singular; Radau5 then shrinks the step, as it does for a singular dense matrix.
//!
//! Entries of the factors are bounded before they are allocated ([`MAX_FACTOR_ENTRIES`]).

use crate::ordering::{nested_dissection, Graph};
use std::ops::{Add, Div, Mul, Sub};

/// Most entries `L` may have below its diagonal (as many in `U` above): each costs 72 bytes
/// (three indices of the analysis, `L` and `U` in real and in complex numbers), ~2.9 GB at
/// this bound. A pattern that would fill more is refused while it is analysed, before the
/// numeric arrays are allocated.
pub const MAX_FACTOR_ENTRIES: usize = 40_000_000;

/// A pivot smaller than this fraction of its row's largest entry makes the factorization
/// unreliable without pivoting: reported as singular.
const PIVOT_FLOOR: f64 = 1e-13;

/// Why a sparse factorization was not made.
#[derive(Debug, Clone, PartialEq)]
pub enum SparseLuError {
    /// The factors would hold more than [`MAX_FACTOR_ENTRIES`] entries.
    TooMuchFill {
        /// Entries of `L` (as many in `U`).
        entries: usize,
    },
    /// A pivot was zero, not finite or negligible (row `row` of the permuted matrix).
    Singular {
        /// The row of the permuted matrix.
        row: usize,
    },
}

impl std::fmt::Display for SparseLuError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SparseLuError::TooMuchFill { entries } => write!(
                f,
                "the sparse LU factors would hold {entries} entries (at most {MAX_FACTOR_ENTRIES})"
            ),
            SparseLuError::Singular { row } => {
                write!(f, "the iteration matrix is singular (pivot {row})")
            }
        }
    }
}

/// The pattern of a square matrix in compressed rows: row `i`'s columns are
/// `cols[start[i]..start[i + 1]]`. The diagonal must be present in every row (the iteration
/// matrices `c·I − J` have it); values are given in this order.
#[derive(Debug, Clone, PartialEq)]
pub struct Pattern {
    /// Row starts, `n + 1` of them.
    pub start: Vec<usize>,
    /// Column of each entry, row after row.
    pub cols: Vec<usize>,
}

impl Pattern {
    /// The dimension.
    pub fn dim(&self) -> usize {
        self.start.len() - 1
    }
    /// Number of entries.
    pub fn nnz(&self) -> usize {
        self.cols.len()
    }
    /// Index of the entry `(i, j)`, if present.
    pub fn find(&self, i: usize, j: usize) -> Option<usize> {
        (self.start[i]..self.start[i + 1]).find(|&p| self.cols[p] == j)
    }
}

/// The numbers a factorization works in: `f64` and [`C64`].
pub(crate) trait Scalar:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    const ZERO: Self;
    fn magnitude(self) -> f64;
}

impl Scalar for f64 {
    const ZERO: f64 = 0.0;
    fn magnitude(self) -> f64 {
        self.abs()
    }
}

/// A complex number, for Radau5's complex system.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct C64 {
    pub re: f64,
    pub im: f64,
}

impl Add for C64 {
    type Output = C64;
    fn add(self, o: C64) -> C64 {
        C64 {
            re: self.re + o.re,
            im: self.im + o.im,
        }
    }
}
impl Sub for C64 {
    type Output = C64;
    fn sub(self, o: C64) -> C64 {
        C64 {
            re: self.re - o.re,
            im: self.im - o.im,
        }
    }
}
impl Mul for C64 {
    type Output = C64;
    fn mul(self, o: C64) -> C64 {
        C64 {
            re: self.re * o.re - self.im * o.im,
            im: self.re * o.im + self.im * o.re,
        }
    }
}
impl Div for C64 {
    type Output = C64;
    /// Smith's algorithm: no overflow of `|o|²` for large entries.
    fn div(self, o: C64) -> C64 {
        if o.re.abs() >= o.im.abs() {
            let r = o.im / o.re;
            let d = o.re + o.im * r;
            C64 {
                re: (self.re + self.im * r) / d,
                im: (self.im - self.re * r) / d,
            }
        } else {
            let r = o.re / o.im;
            let d = o.re * r + o.im;
            C64 {
                re: (self.re * r + self.im) / d,
                im: (self.im * r - self.re) / d,
            }
        }
    }
}
impl Scalar for C64 {
    const ZERO: C64 = C64 { re: 0.0, im: 0.0 };
    fn magnitude(self) -> f64 {
        libm::hypot(self.re, self.im)
    }
}

/// The analysis of a pattern, shared by every factorization of matrices with that pattern.
#[derive(Debug)]
pub struct Symbolic {
    n: usize,
    /// `perm[k]`: the original index eliminated `k`-th.
    perm: Vec<usize>,
    /// Row `k` of the permuted matrix: (column, index of the value in the pattern's order).
    row_start: Vec<usize>,
    row_entries: Vec<(usize, usize)>,
    /// Column `k` of the permuted matrix, above the diagonal: (row, value index).
    col_start: Vec<usize>,
    col_entries: Vec<(usize, usize)>,
    /// Value index of each diagonal entry, by permuted row.
    diag: Vec<usize>,
    /// For row `k`: the columns `j < k` of `L(k, :)`, ascending (also the rows of `U(:, k)`,
    /// whose values are stored in this order).
    reach_start: Vec<usize>,
    reach: Vec<usize>,
    /// Where `L(k, j)` is stored, for each entry of `reach` (columns of `L` one after the
    /// other, each by increasing row).
    l_slot: Vec<usize>,
    /// Column starts of `L` and the row of each entry.
    l_start: Vec<usize>,
    l_rows: Vec<usize>,
}

impl Symbolic {
    /// Analyses `pattern` (made symmetric for the ordering and the elimination tree).
    pub fn new(pattern: &Pattern) -> Result<Symbolic, SparseLuError> {
        Symbolic::bounded(pattern, MAX_FACTOR_ENTRIES)
    }

    /// [`Symbolic::new`] refusing factors of more than `limit` entries below the diagonal.
    fn bounded(pattern: &Pattern, limit: usize) -> Result<Symbolic, SparseLuError> {
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
        let perm = nested_dissection(&Graph {
            start: &gstart,
            adj: &gadj,
        });
        let mut inv = vec![0usize; n];
        for (k, &v) in perm.iter().enumerate() {
            inv[v] = k;
        }
        // Rows and columns of the permuted matrix, with the value indices.
        let mut row_start = vec![0usize; n + 1];
        let mut col_count = vec![0usize; n + 1];
        let mut diag = vec![usize::MAX; n];
        for i in 0..n {
            let k = inv[i];
            row_start[k + 1] = pattern.start[i + 1] - pattern.start[i];
            for &j in &pattern.cols[pattern.start[i]..pattern.start[i + 1]] {
                col_count[inv[j] + 1] += 1;
            }
        }
        for k in 0..n {
            row_start[k + 1] += row_start[k];
            col_count[k + 1] += col_count[k];
        }
        let col_start = col_count;
        let mut row_entries = vec![(0, 0); pattern.nnz()];
        let mut col_entries = vec![(0, 0); pattern.nnz()];
        let (mut rf, mut cf) = (row_start.clone(), col_start.clone());
        for i in 0..n {
            let k = inv[i];
            for p in pattern.start[i]..pattern.start[i + 1] {
                let kj = inv[pattern.cols[p]];
                if kj == k {
                    diag[k] = p;
                }
                row_entries[rf[k]] = (kj, p);
                rf[k] += 1;
                col_entries[cf[kj]] = (k, p);
                cf[kj] += 1;
            }
        }
        if let Some(k) = diag.iter().position(|&d| d == usize::MAX) {
            // Every row needs its diagonal (`c·I − J` has it); without it, pivot `k` is zero.
            return Err(SparseLuError::Singular { row: k });
        }
        // Elimination tree of the symmetric pattern (Liu), from the rows' entries left of
        // the diagonal and the columns' above it.
        let mut parent = vec![usize::MAX; n];
        let mut ancestor = vec![usize::MAX; n];
        for k in 0..n {
            let left = row_entries[row_start[k]..row_start[k + 1]]
                .iter()
                .chain(&col_entries[col_start[k]..col_start[k + 1]])
                .map(|&(j, _)| j)
                .filter(|&j| j < k);
            for mut i in left {
                while i != usize::MAX && i < k {
                    let next = ancestor[i];
                    ancestor[i] = k;
                    if next == usize::MAX {
                        parent[i] = k;
                    }
                    i = next;
                }
            }
        }
        // Row subtrees: the reach of row k is the union of the tree paths from its entries
        // left of the diagonal up to k.
        let mut reach_start = vec![0usize; n + 1];
        let mut reach = Vec::new();
        let mut mark = vec![usize::MAX; n];
        let mut l_count = vec![0usize; n];
        for k in 0..n {
            mark[k] = k;
            let from = reach.len();
            let left = row_entries[row_start[k]..row_start[k + 1]]
                .iter()
                .chain(&col_entries[col_start[k]..col_start[k + 1]])
                .map(|&(j, _)| j)
                .filter(|&j| j < k);
            for mut i in left {
                while i != usize::MAX && mark[i] != k {
                    mark[i] = k;
                    reach.push(i);
                    l_count[i] += 1;
                    i = parent[i];
                }
            }
            if reach.len() > limit {
                return Err(SparseLuError::TooMuchFill {
                    entries: reach.len(),
                });
            }
            reach[from..].sort_unstable();
            reach_start[k + 1] = reach.len();
        }
        let mut l_start = vec![0usize; n + 1];
        for j in 0..n {
            l_start[j + 1] = l_start[j] + l_count[j];
        }
        let mut l_fill = l_start.clone();
        let mut l_rows = vec![0usize; reach.len()];
        let mut l_slot = vec![0usize; reach.len()];
        for k in 0..n {
            for r in reach_start[k]..reach_start[k + 1] {
                let j = reach[r];
                l_slot[r] = l_fill[j];
                l_rows[l_fill[j]] = k;
                l_fill[j] += 1;
            }
        }
        Ok(Symbolic {
            n,
            perm,
            row_start,
            row_entries,
            col_start,
            col_entries,
            diag,
            reach_start,
            reach,
            l_slot,
            l_start,
            l_rows,
        })
    }

    /// Entries of `L` below its diagonal (as many in `U` above).
    pub fn factor_entries(&self) -> usize {
        self.reach.len()
    }
}

/// The factors `L U` of a matrix with the pattern of a [`Symbolic`], in numbers `T`.
#[derive(Debug)]
pub(crate) struct Factors<T> {
    l: Vec<T>,
    u: Vec<T>,
    u_diag: Vec<T>,
    x: Vec<T>,
    y: Vec<T>,
}

impl<T: Scalar> Factors<T> {
    pub(crate) fn new(s: &Symbolic) -> Self {
        Factors {
            l: vec![T::ZERO; s.reach.len()],
            u: vec![T::ZERO; s.reach.len()],
            u_diag: vec![T::ZERO; s.n],
            x: vec![T::ZERO; s.n],
            y: vec![T::ZERO; s.n],
        }
    }

    /// Factors the matrix whose entries are `value(p)` for the pattern's entry `p`.
    pub(crate) fn factor(
        &mut self,
        s: &Symbolic,
        value: impl Fn(usize) -> T,
    ) -> Result<(), SparseLuError> {
        let (x, y) = (&mut self.x, &mut self.y);
        for k in 0..s.n {
            let mut row_max = 0f64;
            for &(j, p) in &s.row_entries[s.row_start[k]..s.row_start[k + 1]] {
                let v = value(p);
                row_max = row_max.max(v.magnitude());
                if j < k {
                    y[j] = v;
                }
            }
            for &(i, p) in &s.col_entries[s.col_start[k]..s.col_start[k + 1]] {
                if i < k {
                    x[i] = value(p);
                }
            }
            let mut d = value(s.diag[k]);
            let reach = s.reach_start[k]..s.reach_start[k + 1];
            for r in reach.clone() {
                let j = s.reach[r];
                // U(j, k): x_j is final once the columns of L left of j have been applied.
                let u = x[j];
                self.u[r] = u;
                for p in s.l_start[j]..s.l_slot[r] {
                    let i = s.l_rows[p];
                    x[i] = x[i] - self.l[p] * u;
                }
                // L(k, j) = (A(k, j) − Σ_i L(k, i) U(i, j)) / U(j, j), over U's column j.
                let mut lj = y[j];
                for q in s.reach_start[j]..s.reach_start[j + 1] {
                    lj = lj - self.u[q] * y[s.reach[q]];
                }
                lj = lj / self.u_diag[j];
                y[j] = lj;
                self.l[s.l_slot[r]] = lj;
                d = d - lj * u;
            }
            let m = d.magnitude();
            if !(m.is_finite() && m > PIVOT_FLOOR * row_max) {
                for r in reach {
                    x[s.reach[r]] = T::ZERO;
                    y[s.reach[r]] = T::ZERO;
                }
                return Err(SparseLuError::Singular { row: k });
            }
            self.u_diag[k] = d;
            for r in reach {
                x[s.reach[r]] = T::ZERO;
                y[s.reach[r]] = T::ZERO;
            }
        }
        Ok(())
    }

    /// Solves `A z = b` for `z` in the permuted order (`z[k]` is unknown `perm[k]`).
    pub(crate) fn solve_permuted(&self, s: &Symbolic, z: &mut [T]) {
        for j in 0..s.n {
            let zj = z[j];
            for p in s.l_start[j]..s.l_start[j + 1] {
                let i = s.l_rows[p];
                z[i] = z[i] - self.l[p] * zj;
            }
        }
        for k in (0..s.n).rev() {
            let zk = z[k] / self.u_diag[k];
            z[k] = zk;
            for r in s.reach_start[k]..s.reach_start[k + 1] {
                let j = s.reach[r];
                z[j] = z[j] - self.u[r] * zk;
            }
        }
    }
}

/// A real sparse LU: factor once, solve many times.
#[derive(Debug)]
pub struct SparseLu {
    factors: Factors<f64>,
    work: Vec<f64>,
}

impl SparseLu {
    /// Storage for the factors of matrices with `s`'s pattern.
    pub fn new(s: &Symbolic) -> Self {
        SparseLu {
            factors: Factors::new(s),
            work: vec![0.0; s.n],
        }
    }

    /// Factors the matrix with entries `values` (in the pattern's order).
    pub fn factor(&mut self, s: &Symbolic, values: &[f64]) -> Result<(), SparseLuError> {
        self.factors.factor(s, |p| values[p])
    }

    /// Overwrites `b` with the solution of `A x = b`.
    pub fn solve_in_place(&mut self, s: &Symbolic, b: &mut [f64]) {
        for (k, &v) in s.perm.iter().enumerate() {
            self.work[k] = b[v];
        }
        self.factors.solve_permuted(s, &mut self.work);
        for (k, &v) in s.perm.iter().enumerate() {
            b[v] = self.work[k];
        }
    }
}

/// A complex sparse LU of `A = Ar + i·Ai` (real and imaginary parts given separately, as
/// [`crate::linalg::LuComplex`] takes them).
#[derive(Debug)]
pub struct SparseLuComplex {
    factors: Factors<C64>,
    work: Vec<C64>,
}

impl SparseLuComplex {
    /// Storage for the factors of matrices with `s`'s pattern.
    pub fn new(s: &Symbolic) -> Self {
        SparseLuComplex {
            factors: Factors::new(s),
            work: vec![C64::ZERO; s.n],
        }
    }

    /// Factors the matrix with entries `re[p] + i·im(p)` (in the pattern's order).
    pub fn factor(
        &mut self,
        s: &Symbolic,
        re: &[f64],
        im: impl Fn(usize) -> f64,
    ) -> Result<(), SparseLuError> {
        self.factors.factor(s, |p| C64 {
            re: re[p],
            im: im(p),
        })
    }

    /// Overwrites `(br, bi)` with the solution of `A x = b`, `b = br + i·bi`.
    pub fn solve_in_place(&mut self, s: &Symbolic, br: &mut [f64], bi: &mut [f64]) {
        for (k, &v) in s.perm.iter().enumerate() {
            self.work[k] = C64 {
                re: br[v],
                im: bi[v],
            };
        }
        self.factors.solve_permuted(s, &mut self.work);
        for (k, &v) in s.perm.iter().enumerate() {
            br[v] = self.work[k].re;
            bi[v] = self.work[k].im;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic generator (no dependency).
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        }
    }

    /// A random matrix on the pattern of an m × m grid with 3 unknowns per node, coupled to
    /// the node's neighbours (nonsymmetric values), with a dominant diagonal `shift`.
    fn grid_matrix(m: usize, shift: f64, rng: &mut Rng) -> (Pattern, Vec<f64>) {
        let b = 3;
        let n = m * m * b;
        let (mut start, mut cols, mut vals) = (vec![0], Vec::new(), Vec::new());
        for node in 0..m * m {
            let (r, c) = (node / m, node % m);
            let mut nbrs = vec![node];
            if r > 0 {
                nbrs.push(node - m);
            }
            if r + 1 < m {
                nbrs.push(node + m);
            }
            if c > 0 {
                nbrs.push(node - 1);
            }
            if c + 1 < m {
                nbrs.push(node + 1);
            }
            nbrs.sort_unstable();
            for a in 0..b {
                let i = node * b + a;
                for &nb in &nbrs {
                    for bb in 0..b {
                        let j = nb * b + bb;
                        cols.push(j);
                        vals.push(if i == j { shift } else { rng.next() });
                    }
                }
                start.push(cols.len());
            }
        }
        assert_eq!(start.len(), n + 1);
        (Pattern { start, cols }, vals)
    }

    fn mul(p: &Pattern, vals: &[f64], x: &[f64]) -> Vec<f64> {
        (0..p.dim())
            .map(|i| {
                (p.start[i]..p.start[i + 1])
                    .map(|q| vals[q] * x[p.cols[q]])
                    .sum()
            })
            .collect()
    }

    #[test]
    fn solves_a_nonsymmetric_grid_system_to_round_off() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let (p, vals) = grid_matrix(25, 20.0, &mut rng);
        let n = p.dim();
        let s = Symbolic::new(&p).unwrap();
        let mut lu = SparseLu::new(&s);
        lu.factor(&s, &vals).unwrap();
        let x: Vec<f64> = (0..n).map(|_| rng.next()).collect();
        let mut b = mul(&p, &vals, &x);
        lu.solve_in_place(&s, &mut b);
        let err = b
            .iter()
            .zip(&x)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-12, "max error {err}");
    }

    #[test]
    fn solves_a_complex_system_as_the_dense_complex_lu_does() {
        let mut rng = Rng(42);
        let (p, re) = grid_matrix(8, 5.0, &mut rng);
        let n = p.dim();
        // Imaginary part: 3 on the diagonal, as Radau5's β/h · I.
        let im = |q: usize| -> f64 {
            let i = p.start.partition_point(|&s| s <= q) - 1;
            if p.cols[q] == i {
                3.0
            } else {
                0.0
            }
        };
        let s = Symbolic::new(&p).unwrap();
        let mut lu = SparseLuComplex::new(&s);
        lu.factor(&s, &re, im).unwrap();
        let mut dense = crate::linalg::LuComplex::new(n);
        {
            let (ar, ai) = dense.matrix_mut();
            for i in 0..n {
                for q in p.start[i]..p.start[i + 1] {
                    ar[i + p.cols[q] * n] = re[q];
                    ai[i + p.cols[q] * n] = im(q);
                }
            }
        }
        dense.factor().unwrap();
        let (mut br, mut bi): (Vec<f64>, Vec<f64>) =
            (0..n).map(|_| (rng.next(), rng.next())).unzip();
        let (mut dr, mut di) = (br.clone(), bi.clone());
        lu.solve_in_place(&s, &mut br, &mut bi);
        dense.solve_in_place(&mut dr, &mut di);
        for i in 0..n {
            assert!(
                (br[i] - dr[i]).abs() < 1e-12 && (bi[i] - di[i]).abs() < 1e-12,
                "{i}"
            );
        }
    }

    #[test]
    fn factors_fill_less_than_the_band() {
        // A 60 × 60 grid with 3 unknowns per node (10,800 unknowns): eliminated row by row
        // the factor fills a band of ~3·60 = 180 columns (~1.9 million entries); nested
        // dissection keeps it several times smaller.
        let (p, _) = grid_matrix(60, 10.0, &mut Rng(7));
        let s = Symbolic::new(&p).unwrap();
        let band = p.dim() * 3 * 60;
        assert!(
            s.factor_entries() * 3 < band,
            "{} entries",
            s.factor_entries()
        );
    }

    #[test]
    fn a_zero_pivot_is_reported_not_divided_by() {
        // [[0, 1], [1, 0]]: nonsingular, but its first pivot is zero without pivoting.
        let p = Pattern {
            start: vec![0, 2, 4],
            cols: vec![0, 1, 0, 1],
        };
        let s = Symbolic::new(&p).unwrap();
        let mut lu = SparseLu::new(&s);
        assert!(matches!(
            lu.factor(&s, &[0.0, 1.0, 1.0, 0.0]),
            Err(SparseLuError::Singular { .. })
        ));
        // And the same factors work again on a good matrix afterwards.
        lu.factor(&s, &[2.0, 1.0, 1.0, 3.0]).unwrap();
        let mut b = [3.0, 4.0];
        lu.solve_in_place(&s, &mut b);
        assert!((b[0] - 1.0).abs() < 1e-15 && (b[1] - 1.0).abs() < 1e-15);
    }

    #[test]
    fn too_much_fill_is_refused_while_analysing() {
        // A full 30 × 30 pattern fills 435 entries below the diagonal.
        let n = 30;
        let p = Pattern {
            start: (0..=n).map(|i| i * n).collect(),
            cols: (0..n * n).map(|k| k % n).collect(),
        };
        assert_eq!(Symbolic::bounded(&p, 435).unwrap().factor_entries(), 435);
        match Symbolic::bounded(&p, 400) {
            Err(SparseLuError::TooMuchFill { entries }) => assert!(entries > 400),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn a_missing_diagonal_is_an_error() {
        let p = Pattern {
            start: vec![0, 1, 2],
            cols: vec![1, 0],
        };
        assert!(matches!(
            Symbolic::new(&p),
            Err(SparseLuError::Singular { .. })
        ));
    }
}
