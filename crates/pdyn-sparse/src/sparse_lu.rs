//! Sparse LU of the implicit methods' iteration matrices `c·I − J` (real `c`, and complex
//! `c = α + iβ` for Radau5's second system), for Jacobians whose pattern is known: a net of
//! 10^4 particles has 6·10^4 states, whose dense matrices would take 29 GB.
//!
//! * Kinematic rows first ([`reduce`]): rows `y_i' = a·y_p` (a mechanical system's `q' = v`)
//!   are eliminated by substitution, leaving the Schur complement on the other unknowns
//!   (`c·I − C − K/c` on `v`): half the dimension of a second-order system.
//! * The rest by a supernodal multifrontal LU ([`supernodal`], [`multifrontal`]): nested
//!   dissection ([`crate::ordering`]) of the pattern made symmetric, the elimination tree in
//!   postorder, supernodes (columns with one structure, amalgamated when nearly so) whose
//!   fronts are factored by dense kernels.
//! * No pivoting: these matrices are dominated by `c·I` for small steps, and for a
//!   mechanical system `c²M + cC + K` with `K`, `C` symmetric positive semidefinite (for the
//!   real `c`) or with a positive definite imaginary part (for the complex one), whose
//!   elimination without pivoting does not break down. A pivot that is zero, not finite, or
//!   below `PIVOT_FLOOR` of its row's largest entry (in the reduced matrix) is reported as
//!   singular; Radau5 then shrinks the step, as it does for a singular dense matrix.
//!
//! Entries of the factors are bounded before they are allocated ([`MAX_FACTOR_ENTRIES`]).

mod multifrontal;
mod reduce;
mod scalar;
mod supernodal;

use multifrontal::Numeric;
use reduce::Reduction;
pub(crate) use scalar::{Scalar, C64};
use supernodal::Supernodes;

/// Most entries `L` may have below its diagonal (about as many in `U` above), explicit zeros
/// of amalgamated supernodes included: each costs ~48 bytes (`L` and `U` in real and in
/// complex numbers), ~1.9 GB at this bound. A pattern that would fill more is refused while
/// it is analysed, before the numeric arrays are allocated.
pub const MAX_FACTOR_ENTRIES: usize = 40_000_000;

/// A pivot smaller than this fraction of its row's largest entry makes the factorization
/// unreliable without pivoting: reported as singular.
const PIVOT_FLOOR: f64 = 1e-13;

/// Why a sparse factorization was not made.
#[derive(Debug, Clone, PartialEq)]
pub enum SparseLuError {
    /// The factors would hold more than [`MAX_FACTOR_ENTRIES`] entries.
    TooMuchFill {
        /// Entries of `L` (about as many in `U`).
        entries: usize,
    },
    /// A pivot was zero, not finite or negligible (the unknown `row`, in the matrix's own
    /// numbering).
    Singular {
        /// The unknown whose pivot failed.
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

/// The analysis of a pattern, shared by every factorization of matrices with that pattern.
#[derive(Debug)]
pub struct Symbolic {
    n: usize,
    red: Reduction,
    sn: Supernodes,
}

impl Symbolic {
    /// Analyses `pattern` (made symmetric for the ordering and the elimination tree).
    pub fn new(pattern: &Pattern) -> Result<Symbolic, SparseLuError> {
        Symbolic::bounded(pattern, MAX_FACTOR_ENTRIES)
    }

    /// [`Symbolic::new`] refusing factors of more than `limit` entries below the diagonal.
    fn bounded(pattern: &Pattern, limit: usize) -> Result<Symbolic, SparseLuError> {
        let n = pattern.dim();
        let mut diag = vec![usize::MAX; n];
        for (i, d) in diag.iter_mut().enumerate() {
            match pattern.find(i, i) {
                Some(p) => *d = p,
                // Every row needs its diagonal (`c·I − J` has it); without it, the pivot is
                // zero.
                None => return Err(SparseLuError::Singular { row: i }),
            }
        }
        let red = Reduction::new(pattern, &diag);
        let sn = Supernodes::new(&red.s, limit.saturating_sub(red.through_len()))?;
        Ok(Symbolic { n, red, sn })
    }

    /// Entries of `L` below its diagonal (about as many in `U` above), explicit zeros of
    /// amalgamated supernodes included.
    pub fn factor_entries(&self) -> usize {
        self.red.through_len() + self.sn.entries
    }

    /// Entries of `L` below its diagonal that are structurally nonzero (without the explicit
    /// zeros of amalgamation).
    pub fn fill_entries(&self) -> usize {
        self.red.through_len() + self.sn.fill
    }

    /// The dimension of the matrix factored by supernodes, after the kinematic rows.
    pub fn reduced_dim(&self) -> usize {
        self.sn.n
    }

    /// The number of supernodes and the side of the largest front.
    pub fn supernodes(&self) -> (usize, usize) {
        (self.sn.len(), self.sn.max_front)
    }
}

/// The factors of a matrix with the pattern of a [`Symbolic`], in numbers `T`.
#[derive(Debug)]
pub(crate) struct Factors<T> {
    /// Pivots and off-diagonal entries of the kinematic rows.
    piv: Vec<T>,
    off: Vec<T>,
    /// The entries `E(r, i)` of the kinematic columns.
    through: Vec<T>,
    /// The reduced matrix's values.
    svals: Vec<T>,
    num: Numeric<T>,
    /// Scratch: the reduced right-hand side, it permuted, and a front's rows (twice: the
    /// symmetric solve keeps its pivots' inverses beside them).
    ws: Vec<T>,
    z: Vec<T>,
    t: Vec<T>,
}

impl<T: Scalar> Factors<T> {
    pub(crate) fn new(s: &Symbolic) -> Self {
        let k = s.red.kin.len();
        Factors {
            piv: vec![T::ZERO; k],
            off: vec![T::ZERO; k],
            through: vec![T::ZERO; s.red.through_len()],
            svals: vec![T::ZERO; s.red.s.nnz()],
            num: Numeric::new(&s.sn),
            ws: vec![T::ZERO; s.sn.n],
            z: vec![T::ZERO; s.sn.n],
            t: vec![T::ZERO; 2 * s.sn.max_front],
        }
    }

    /// Factors the matrix whose entries are `value(p)` for the pattern's entry `p`.
    pub(crate) fn factor(
        &mut self,
        s: &Symbolic,
        value: impl Fn(usize) -> T,
        symmetric: bool,
    ) -> Result<(), SparseLuError> {
        s.red
            .values(
                &value,
                PIVOT_FLOOR,
                &mut self.piv,
                &mut self.off,
                &mut self.through,
                &mut self.svals,
            )
            .map_err(|row| SparseLuError::Singular { row })?;
        self.num
            .factor(&s.sn, &self.svals, PIVOT_FLOOR, symmetric)
            .map_err(|k| SparseLuError::Singular {
                row: s.red.orig[s.sn.perm[k]],
            })
    }

    /// Overwrites `b` (the matrix's own numbering) with the solution of `A x = b`.
    pub(crate) fn solve(&mut self, s: &Symbolic, b: &mut [T]) {
        debug_assert_eq!(b.len(), s.n);
        s.red.reduce_rhs(&self.piv, &self.through, b, &mut self.ws);
        for (k, &v) in s.sn.perm.iter().enumerate() {
            self.z[k] = self.ws[v];
        }
        self.num.solve_permuted(&s.sn, &mut self.z, &mut self.t);
        for (k, &v) in s.sn.perm.iter().enumerate() {
            self.ws[v] = self.z[k];
        }
        s.red.expand(&self.piv, &self.off, &self.ws, b);
    }
}

/// A real sparse LU: factor once, solve many times.
#[derive(Debug)]
pub struct SparseLu {
    factors: Factors<f64>,
}

impl SparseLu {
    /// Storage for the factors of matrices with `s`'s pattern.
    pub fn new(s: &Symbolic) -> Self {
        SparseLu {
            factors: Factors::new(s),
        }
    }

    /// Factors the matrix with entries `values` (in the pattern's order).
    pub fn factor(&mut self, s: &Symbolic, values: &[f64]) -> Result<(), SparseLuError> {
        self.factors.factor(s, |p| values[p], false)
    }

    /// [`SparseLu::factor`] for a symmetric matrix (on a symmetric pattern), in about half the
    /// work: its elimination without pivoting is `L D Lᵀ`, and only the lower triangles of the
    /// fronts are computed. Only the pivots' rows of `U` are kept (the factors' memory about
    /// halved; [`SparseLu::solve_in_place`] forms `L` from them as the elimination did, to the
    /// same bits). Values off that symmetry give a wrong factorization, not an error.
    pub fn factor_symmetric(&mut self, s: &Symbolic, values: &[f64]) -> Result<(), SparseLuError> {
        self.factors.factor(s, |p| values[p], true)
    }

    /// Overwrites `b` with the solution of `A x = b`.
    pub fn solve_in_place(&mut self, s: &Symbolic, b: &mut [f64]) {
        self.factors.solve(s, b);
    }
}

/// A complex sparse LU of `A = Ar + i·Ai` (real and imaginary parts given separately, as
/// pdyn-ode's dense `LuComplex` takes them).
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
        self.factors.factor(
            s,
            |p| C64 {
                re: re[p],
                im: im(p),
            },
            false,
        )
    }

    /// Overwrites `(br, bi)` with the solution of `A x = b`, `b = br + i·bi`.
    pub fn solve_in_place(&mut self, s: &Symbolic, br: &mut [f64], bi: &mut [f64]) {
        for (w, (&r, &i)) in self.work.iter_mut().zip(br.iter().zip(bi.iter())) {
            *w = C64 { re: r, im: i };
        }
        self.factors.solve(s, &mut self.work);
        for (w, (r, i)) in self.work.iter().zip(br.iter_mut().zip(bi.iter_mut())) {
            *r = w.re;
            *i = w.im;
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

    /// `A⁻¹ b` for the dense `n × n` matrix `a` (column-major) by Gaussian elimination with
    /// partial pivoting: the reference the sparse LU (no pivoting) is checked against.
    fn dense_solve<T: Scalar>(mut a: Vec<T>, mut b: Vec<T>) -> Vec<T> {
        let n = b.len();
        for k in 0..n {
            let p = (k..n)
                .max_by(|&i, &j| {
                    a[i + k * n]
                        .magnitude()
                        .total_cmp(&a[j + k * n].magnitude())
                })
                .unwrap();
            for j in 0..n {
                a.swap(k + j * n, p + j * n);
            }
            b.swap(k, p);
            let d = a[k + k * n];
            // Column by column (contiguous in column-major storage: the reference is the
            // slowest part of these tests otherwise); the multipliers first.
            let l: Vec<T> = (k + 1..n).map(|i| a[i + k * n] / d).collect();
            for j in k + 1..n {
                let akj = a[k + j * n];
                let col = &mut a[j * n + k + 1..(j + 1) * n];
                for (x, &li) in col.iter_mut().zip(&l) {
                    *x = *x - li * akj;
                }
            }
            let bk = b[k];
            for (bi, &li) in b[k + 1..].iter_mut().zip(&l) {
                *bi = *bi - li * bk;
            }
        }
        for k in (0..n).rev() {
            let mut s = b[k];
            for j in k + 1..n {
                s = s - a[k + j * n] * b[j];
            }
            b[k] = s / a[k + k * n];
        }
        b
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
        let mut a = vec![C64::ZERO; n * n];
        for i in 0..n {
            for q in p.start[i]..p.start[i + 1] {
                a[i + p.cols[q] * n] = C64 {
                    re: re[q],
                    im: im(q),
                };
            }
        }
        let (mut br, mut bi): (Vec<f64>, Vec<f64>) =
            (0..n).map(|_| (rng.next(), rng.next())).unzip();
        let d = dense_solve(
            a,
            br.iter()
                .zip(&bi)
                .map(|(&re, &im)| C64 { re, im })
                .collect(),
        );
        lu.solve_in_place(&s, &mut br, &mut bi);
        for i in 0..n {
            assert!(
                (br[i] - d[i].re).abs() < 1e-12 && (bi[i] - d[i].im).abs() < 1e-12,
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
        assert!(s.fill_entries() * 3 < band, "{} entries", s.fill_entries());
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

    /// Solves with the sparse LU (real, and complex with `im` on the diagonal when given) and
    /// with [`dense_solve`] (partial pivoting, an independent code), and
    /// returns the largest difference of the solutions relative to their size.
    fn against_dense(p: &Pattern, re: &[f64], im_diag: Option<f64>, rng: &mut Rng) -> f64 {
        let n = p.dim();
        let s = Symbolic::new(p).unwrap();
        let mut worst = 0f64;
        let b: Vec<f64> = (0..n).map(|_| rng.next()).collect();
        match im_diag {
            None => {
                let mut lu = SparseLu::new(&s);
                lu.factor(&s, re).unwrap();
                let mut a = vec![0.0; n * n];
                for i in 0..n {
                    for q in p.start[i]..p.start[i + 1] {
                        a[i + p.cols[q] * n] += re[q];
                    }
                }
                let mut x = b.clone();
                lu.solve_in_place(&s, &mut x);
                let y = dense_solve(a, b.clone());
                let scale = y.iter().fold(0f64, |m, v| m.max(v.abs()));
                for i in 0..n {
                    worst = worst.max((x[i] - y[i]).abs() / scale);
                }
            }
            Some(beta) => {
                let im = |q: usize| -> f64 {
                    let i = p.start.partition_point(|&st| st <= q) - 1;
                    if p.cols[q] == i {
                        beta
                    } else {
                        0.0
                    }
                };
                let mut lu = SparseLuComplex::new(&s);
                lu.factor(&s, re, im).unwrap();
                let mut a = vec![C64::ZERO; n * n];
                for i in 0..n {
                    for q in p.start[i]..p.start[i + 1] {
                        let x = &mut a[i + p.cols[q] * n];
                        *x = *x
                            + C64 {
                                re: re[q],
                                im: im(q),
                            };
                    }
                }
                let bi: Vec<f64> = (0..n).map(|_| rng.next()).collect();
                let (mut xr, mut xi) = (b.clone(), bi.clone());
                lu.solve_in_place(&s, &mut xr, &mut xi);
                let y = dense_solve(
                    a,
                    b.iter().zip(&bi).map(|(&re, &im)| C64 { re, im }).collect(),
                );
                let (yr, yi): (Vec<f64>, Vec<f64>) = y.iter().map(|c| (c.re, c.im)).unzip();
                let scale = yr.iter().chain(&yi).fold(0f64, |m, v| m.max(v.abs()));
                for i in 0..n {
                    worst = worst.max(libm::hypot(xr[i] - yr[i], xi[i] - yi[i]) / scale);
                }
            }
        }
        worst
    }

    /// A random nonsymmetric pattern of `nodes` nodes of 1 to 8 unknowns each (all of a node's
    /// unknowns coupled), each node coupled to a few random others and to its successor, with
    /// random values and a dominant diagonal: supernodes of many sizes.
    fn random_blocks(nodes: usize, rng: &mut Rng) -> (Pattern, Vec<f64>) {
        let sizes: Vec<usize> = (0..nodes)
            .map(|_| [1, 1, 2, 3, 3, 5, 8][((rng.next() + 1.0) * 3.5) as usize % 7])
            .collect();
        let mut off = vec![0usize];
        for &b in &sizes {
            off.push(off.last().unwrap() + b);
        }
        let n = off[nodes];
        let mut links: Vec<Vec<usize>> = (0..nodes).map(|a| vec![a]).collect();
        for a in 0..nodes {
            if a + 1 < nodes {
                links[a].push(a + 1);
            }
            for _ in 0..2 {
                let b = ((rng.next() + 1.0) * 0.5 * nodes as f64) as usize % nodes;
                // One direction only: the pattern is not symmetric.
                links[a].push(b);
            }
        }
        let (mut start, mut cols, mut vals) = (vec![0], Vec::new(), Vec::new());
        for a in 0..nodes {
            let mut nb = links[a].clone();
            nb.sort_unstable();
            nb.dedup();
            for i in off[a]..off[a + 1] {
                for &b in &nb {
                    for j in off[b]..off[b + 1] {
                        cols.push(j);
                        vals.push(if i == j { 12.0 } else { rng.next() });
                    }
                }
                start.push(cols.len());
            }
        }
        assert_eq!(start.len(), n + 1);
        (Pattern { start, cols }, vals)
    }

    #[test]
    fn random_patterns_with_supernodes_of_several_sizes_solve_as_the_dense_lu() {
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        let mut sizes = std::collections::BTreeSet::new();
        for nodes in [1, 2, 7, 40, 150, 400] {
            let (p, vals) = random_blocks(nodes, &mut rng);
            let s = Symbolic::new(&p).unwrap();
            for sn in 0..s.sn.len() {
                sizes.insert(s.sn.first[sn + 1] - s.sn.first[sn]);
            }
            let real = against_dense(&p, &vals, None, &mut rng);
            assert!(real < 1e-12, "{nodes} nodes: real {real}");
            let complex = against_dense(&p, &vals, Some(3.0), &mut rng);
            assert!(complex < 1e-12, "{nodes} nodes: complex {complex}");
        }
        // Blocks of one, a few and many columns (more than two of `partial_lu`'s blocks) were
        // all exercised.
        assert!(sizes.len() >= 6 && sizes.contains(&1), "{sizes:?}");
        assert!(*sizes.iter().last().unwrap() > 2 * 32, "{sizes:?}");
    }

    /// `c·I − J` for `J = [[0, I], [K, C]]` on `y = (q, v)`, the unknowns of `q` and `v`
    /// interleaved or not: `K` couples each node's 3 unknowns to its grid neighbours', `C`
    /// is diagonal (drag) plus, when `damping`, `K`'s pattern.
    fn second_order(
        m: usize,
        c: f64,
        damping: bool,
        interleave: bool,
        rng: &mut Rng,
    ) -> (Pattern, Vec<f64>) {
        let (kp, kv) = grid_matrix(m, 0.0, rng);
        let h = kp.dim();
        // Position of q_i and v_i.
        let (qi, vi) = if interleave {
            (
                (0..h).map(|i| 2 * i).collect::<Vec<_>>(),
                (0..h).map(|i| 2 * i + 1).collect::<Vec<_>>(),
            )
        } else {
            ((0..h).collect(), (h..2 * h).collect())
        };
        let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); 2 * h];
        for i in 0..h {
            rows[qi[i]].push((qi[i], c));
            rows[qi[i]].push((vi[i], -1.0));
            for q in kp.start[i]..kp.start[i + 1] {
                let j = kp.cols[q];
                // −K: K's off-diagonal values random, its diagonal a stiff restoring term.
                let kij = if i == j { -400.0 } else { 30.0 * kv[q] };
                rows[vi[i]].push((qi[j], -kij));
                if damping && i != j {
                    rows[vi[i]].push((vi[j], -0.5 * kv[q]));
                }
            }
            rows[vi[i]].push((vi[i], c + 2.0));
        }
        let (mut start, mut cols, mut vals) = (vec![0], Vec::new(), Vec::new());
        for mut r in rows {
            r.sort_by_key(|e| e.0);
            for (j, v) in r {
                cols.push(j);
                vals.push(v);
            }
            start.push(cols.len());
        }
        (Pattern { start, cols }, vals)
    }

    #[test]
    fn second_order_systems_factor_on_half_the_unknowns_and_solve_as_the_dense_lu() {
        let mut rng = Rng(77);
        for (m, interleave, damping) in [
            (4, false, false),
            (6, true, false),
            (9, false, true),
            (12, true, true),
        ] {
            for c in [0.5, 40.0] {
                let (p, vals) = second_order(m, c, damping, interleave, &mut rng);
                let s = Symbolic::new(&p).unwrap();
                assert_eq!(s.reduced_dim() * 2, p.dim(), "m = {m}");
                let real = against_dense(&p, &vals, None, &mut rng);
                assert!(real < 1e-11, "m = {m}, c = {c}: real {real}");
                let complex = against_dense(&p, &vals, Some(7.0), &mut rng);
                assert!(complex < 1e-11, "m = {m}, c = {c}: complex {complex}");
            }
        }
    }

    #[test]
    fn singular_pivots_are_reported_in_a_block_and_in_a_kinematic_row() {
        // A full 6 × 6 pattern (one supernode) whose leading 2 × 2 minor is singular.
        let n = 6;
        let p = Pattern {
            start: (0..=n).map(|i| i * n).collect(),
            cols: (0..n * n).map(|k| k % n).collect(),
        };
        let s = Symbolic::new(&p).unwrap();
        assert_eq!(s.supernodes().0, 1);
        let good: Vec<f64> = (0..n * n)
            .map(|k| {
                if k / n == k % n {
                    10.0
                } else {
                    1.0 / (1 + k) as f64
                }
            })
            .collect();
        let mut bad = good.clone();
        let first = s.sn.perm[0];
        let second = s.sn.perm[1];
        // Rows `first` and `second` proportional on columns `first`, `second`.
        bad[first * n + first] = 1.0;
        bad[first * n + second] = 2.0;
        bad[second * n + first] = 2.0;
        bad[second * n + second] = 4.0;
        let mut lu = SparseLu::new(&s);
        assert_eq!(
            lu.factor(&s, &bad),
            Err(SparseLuError::Singular { row: second })
        );
        lu.factor(&s, &good).unwrap();
        let x: Vec<f64> = (0..n).map(|i| i as f64 - 2.5).collect();
        let mut b = mul(&p, &good, &x);
        lu.solve_in_place(&s, &mut b);
        for i in 0..n {
            assert!((b[i] - x[i]).abs() < 1e-14, "{i}");
        }
        // A second-order system with c = 0 in row q_3: its kinematic pivot is zero.
        let mut rng = Rng(5);
        let (p, mut vals) = second_order(3, 2.0, false, false, &mut rng);
        let s = Symbolic::new(&p).unwrap();
        let mut lu = SparseLuComplex::new(&s);
        vals[p.find(3, 3).unwrap()] = 0.0;
        assert_eq!(
            lu.factor(&s, &vals, |_| 0.0),
            Err(SparseLuError::Singular { row: 3 })
        );
    }

    /// `(A + Aᵀ)/2` of a matrix on a pattern (values in the pattern's order), on the pattern
    /// made symmetric.
    fn symmetric_part(p: &Pattern, vals: &[f64]) -> (Pattern, Vec<f64>) {
        let n = p.dim();
        let mut rows: Vec<std::collections::BTreeMap<usize, f64>> = vec![Default::default(); n];
        for i in 0..n {
            for q in p.start[i]..p.start[i + 1] {
                let j = p.cols[q];
                *rows[i].entry(j).or_insert(0.0) += 0.5 * vals[q];
                *rows[j].entry(i).or_insert(0.0) += 0.5 * vals[q];
            }
        }
        let (mut start, mut cols, mut out) = (vec![0], Vec::new(), Vec::new());
        for r in rows {
            for (j, v) in r {
                cols.push(j);
                out.push(v);
            }
            start.push(cols.len());
        }
        (Pattern { start, cols }, out)
    }

    #[test]
    fn symmetric_matrices_factor_in_half_the_work_and_solve_as_the_dense_elimination() {
        // Definite and indefinite symmetric matrices on grids (one large separator: fronts
        // of several of `partial_lu`'s blocks) and on random blocks (supernodes of every
        // size), each solved by `factor_symmetric`, by `factor`, and by dense elimination
        // with partial pivoting.
        let mut rng = Rng(0x5eed);
        let mut cases = Vec::new();
        for (m, shift) in [(3, 20.0), (12, 8.0), (20, -3.0), (25, 0.7)] {
            cases.push(grid_matrix(m, shift, &mut rng));
        }
        for nodes in [1, 9, 120, 300] {
            let (p, mut vals) = random_blocks(nodes, &mut rng);
            // Some negative pivots: the diagonal of every third unknown made −12.
            for i in (0..p.dim()).step_by(3) {
                let q = p.find(i, i).unwrap();
                vals[q] = -vals[q];
            }
            cases.push((p, vals));
        }
        for (k, (p, vals)) in cases.iter().enumerate() {
            let (p, a) = symmetric_part(p, vals);
            let n = p.dim();
            let s = Symbolic::new(&p).unwrap();
            let mut dense = vec![0.0; n * n];
            for i in 0..n {
                for q in p.start[i]..p.start[i + 1] {
                    dense[i + p.cols[q] * n] = a[q];
                }
            }
            let b: Vec<f64> = (0..n).map(|_| rng.next()).collect();
            let y = dense_solve(dense, b.clone());
            let scale = y.iter().fold(0f64, |m, v| m.max(v.abs()));
            let mut lu = SparseLu::new(&s);
            lu.factor_symmetric(&s, &a).unwrap();
            let mut x = b.clone();
            lu.solve_in_place(&s, &mut x);
            lu.factor(&s, &a).unwrap();
            let mut z = b.clone();
            lu.solve_in_place(&s, &mut z);
            for i in 0..n {
                assert!(
                    (x[i] - y[i]).abs() <= 1e-11 * scale,
                    "case {k}, unknown {i}: {} vs {}",
                    x[i],
                    y[i]
                );
                assert!(
                    (x[i] - z[i]).abs() <= 1e-11 * scale,
                    "case {k}, unknown {i}"
                );
            }
        }
    }

    #[test]
    fn a_symmetric_factorization_keeps_only_its_pivots_rows_and_either_layout_follows_the_other() {
        // One factorization object, factored unsymmetric, symmetric, unsymmetric again (the
        // layout of its factors changes each time), each solve against dense elimination.
        let mut rng = Rng(0xfac7);
        let (p, vals) = grid_matrix(12, 8.0, &mut rng);
        let (p, a) = symmetric_part(&p, &vals);
        let n = p.dim();
        let s = Symbolic::new(&p).unwrap();
        let mut dense = vec![0.0; n * n];
        for i in 0..n {
            for q in p.start[i]..p.start[i + 1] {
                dense[i + p.cols[q] * n] = a[q];
            }
        }
        let b: Vec<f64> = (0..n).map(|_| rng.next()).collect();
        let y = dense_solve(dense, b.clone());
        let scale = y.iter().fold(0f64, |m, v| m.max(v.abs()));
        // The sizes from the supernodes: `m × ns` columns plus `ns × r` rows of `U` each, or
        // the `ns × m` rows alone.
        let sn = &s.sn;
        let (mut full, mut half) = (0, 0);
        for k in 0..sn.len() {
            let ns = sn.first[k + 1] - sn.first[k];
            let r = sn.row_start[k + 1] - sn.row_start[k];
            full += (ns + r) * ns + ns * r;
            half += ns * (ns + r);
        }
        let mut lu = SparseLu::new(&s);
        for symmetric in [false, true, false, true] {
            if symmetric {
                lu.factor_symmetric(&s, &a).unwrap();
            } else {
                lu.factor(&s, &a).unwrap();
            }
            let stored = lu.factors.num.stored();
            assert_eq!(stored, if symmetric { half } else { full });
            let mut x = b.clone();
            lu.solve_in_place(&s, &mut x);
            for i in 0..n {
                assert!(
                    (x[i] - y[i]).abs() <= 1e-11 * scale,
                    "symmetric {symmetric}, unknown {i}: {} vs {}",
                    x[i],
                    y[i]
                );
            }
        }
        // Below the supernodes' diagonal blocks the symmetric factors hold nothing: a grid's
        // are well under two thirds of the full ones.
        assert!(3 * half < 2 * full, "{half} of {full}");
    }

    #[test]
    fn a_symmetric_factorization_reads_nothing_of_its_fronts_upper_triangles() {
        // The symmetric factorization neither zeroes nor assembles the upper triangles of its
        // fronts: with every front's scratch NaN beforehand (what an earlier factorization
        // might leave), the solution is still the bits of a factorization from fresh storage.
        let mut rng = Rng(0xbad5);
        for (m, shift) in [(9, 6.0), (20, -3.0)] {
            let (p, vals) = grid_matrix(m, shift, &mut rng);
            let (p, a) = symmetric_part(&p, &vals);
            let n = p.dim();
            let s = Symbolic::new(&p).unwrap();
            let b: Vec<f64> = (0..n).map(|_| rng.next()).collect();
            let mut fresh = SparseLu::new(&s);
            fresh.factor_symmetric(&s, &a).unwrap();
            let mut x = b.clone();
            fresh.solve_in_place(&s, &mut x);
            let mut used = SparseLu::new(&s);
            used.factor(&s, &vals_of(&p, &mut rng)).unwrap();
            used.factors.num.poison_front();
            used.factor_symmetric(&s, &a).unwrap();
            let mut y = b.clone();
            used.solve_in_place(&s, &mut y);
            assert!(x.iter().all(|v| v.is_finite()), "m = {m}");
            assert!(
                x.iter().zip(&y).all(|(u, v)| u.to_bits() == v.to_bits()),
                "m = {m}"
            );
        }
    }

    /// Random values, diagonally dominant, on `p`.
    fn vals_of(p: &Pattern, rng: &mut Rng) -> Vec<f64> {
        (0..p.dim())
            .flat_map(|i| (p.start[i]..p.start[i + 1]).map(move |q| (i, q)))
            .map(|(i, q)| if p.cols[q] == i { 50.0 } else { rng.next() })
            .collect()
    }

    #[test]
    fn an_empty_matrix_factors_and_solves_nothing() {
        let p = Pattern {
            start: vec![0],
            cols: vec![],
        };
        let s = Symbolic::new(&p).unwrap();
        let mut lu = SparseLu::new(&s);
        lu.factor(&s, &[]).unwrap();
        lu.solve_in_place(&s, &mut []);
        let mut lc = SparseLuComplex::new(&s);
        lc.factor(&s, &[], |_| 0.0).unwrap();
        lc.solve_in_place(&s, &mut [], &mut []);
    }
}
