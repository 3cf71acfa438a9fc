//! The eigenvalues of `K φ = λ M φ` nearest a shift `σ`, for large sparse `K`, `M` (`M`
//! symmetric positive definite): shift-invert Lanczos with full reorthogonalization, as SciPy's
//! `eigsh(K, k, M, sigma)` (ARPACK mode 3) does it.
//!
//! With `K − σ M = L D Lᵀ` ([`crate::shifted_factor::ShiftedFactor`]: the envelope or the
//! supernodal LU, whichever is smaller) the operator
//! `OP = (K − σ M)⁻¹ M` is self-adjoint in the `M`-inner product `⟨x, y⟩ = xᵀ M y`, and has the
//! eigenvectors of the pencil with eigenvalues `θ = 1 / (λ − σ)`: the `λ` nearest `σ` become the
//! largest `|θ|`, well separated, found first by Lanczos. The Lanczos basis `Q` (`M`-orthonormal,
//! reorthogonalized against every earlier vector at each step, a second time where the first
//! pass cancelled much: `Problem::reorthogonalize`) reduces `OP` to a
//! tridiagonal `T = Qᵀ M OP Q`; the Ritz pair `(θ, Q s)` of `T s = θ s` has residual
//! `‖OP x − θ x‖_M = |β_m s_m|`, and is accepted when that is at most `tolerance · |θ|`.
//!
//! Lanczos from one start vector sees one vector of each eigenspace: a repeated eigenvalue
//! (symmetry, rigid-body motions) would be found once. So after the wanted pairs converge, the
//! search is run again from a new start vector orthogonal to them: a pair it finds nearer `σ`
//! than the farthest wanted one is taken in, and the search repeated, until a run finds none.

use crate::shifted_factor::ShiftedFactor;
use crate::sparse::{Csr, SparseError};

/// Knobs of [`nearest`].
#[derive(Clone, Debug)]
pub struct LanczosOptions {
    /// Eigenpairs wanted. Default 6.
    pub count: usize,
    /// The shift `σ`: the eigenvalues `λ` nearest it are found. Default 0 (the lowest, for a
    /// positive semi-definite `K`).
    pub shift: f64,
    /// A Ritz pair is accepted when `‖OP x − θ x‖_M ≤ tolerance · |θ|`. Default 1e-11 (the
    /// eigenvalue's error is about the square of that, relative to the gap).
    pub tolerance: f64,
    /// Most Lanczos vectors kept (capped by the order). Default 600.
    pub max_basis: usize,
}

impl Default for LanczosOptions {
    fn default() -> Self {
        LanczosOptions {
            count: 6,
            shift: 0.0,
            tolerance: 1e-11,
            max_basis: 600,
        }
    }
}

/// Why the eigenpairs could not be computed.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum LanczosError {
    /// `K − σ M` could not be factorized (`σ` is an eigenvalue, or the factor is too large).
    Factor(SparseError),
    /// `M` is not positive definite (a vector has `xᵀ M x ≤ 0`).
    MassNotPositiveDefinite,
    /// `K` and `M` have different orders, or `count` is 0 or exceeds the order.
    Size {
        /// Order of `K`.
        stiffness: usize,
        /// Order of `M`.
        mass: usize,
        /// Pairs asked for.
        count: usize,
    },
    /// The basis reached its limit before every wanted pair converged.
    NotConverged {
        /// Lanczos vectors used.
        basis: usize,
        /// Pairs converged.
        converged: usize,
        /// Pairs wanted.
        wanted: usize,
    },
}

impl std::fmt::Display for LanczosError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LanczosError::Factor(e) => write!(f, "cannot factorize K − σM: {e}"),
            LanczosError::MassNotPositiveDefinite => {
                write!(f, "the mass matrix is not positive definite")
            }
            LanczosError::Size {
                stiffness,
                mass,
                count,
            } => write!(
                f,
                "cannot find {count} eigenpairs of a {stiffness} × {stiffness} stiffness with a \
                 {mass} × {mass} mass matrix"
            ),
            LanczosError::NotConverged {
                basis,
                converged,
                wanted,
            } => write!(
                f,
                "Lanczos converged {converged} of {wanted} eigenpairs with {basis} vectors \
                 (raise the basis limit, or ask for fewer modes)"
            ),
        }
    }
}

impl std::error::Error for LanczosError {}

/// Eigenpairs of `K φ = λ M φ`, ordered by `λ`.
#[derive(Clone, Debug)]
pub struct EigenPairs {
    /// `λ`, ascending.
    pub values: Vec<f64>,
    /// `φ`, `M`-normalized (`φᵀ M φ = 1`).
    pub vectors: Vec<Vec<f64>>,
    /// `‖OP x − θ x‖_M / |θ|` of each pair.
    pub residuals: Vec<f64>,
    /// Lanczos steps taken in all (each one solve with `K − σ M`).
    pub steps: usize,
    /// Entries of the factor of `K − σ M` below its diagonal.
    pub factor_entries: usize,
}

/// splitmix64 numbers in [-1, 1): the start vectors (fixed seeds, the results reproducible);
/// also the tests' seeded matrices.
pub(crate) struct Start(pub(crate) u64);

impl Start {
    pub(crate) fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// `aᵀ b` in four interleaved partial sums: one running sum makes each addition wait for the
/// last (a 10^4-vector dot is then latency-bound), four let the additions overlap and be
/// vectorized. The rounding differs from the sequential sum's in the last bits.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut s = [0.0f64; 4];
    let (ac, bc) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ar, br) = (ac.remainder(), bc.remainder());
    for (x, y) in ac.zip(bc) {
        for k in 0..4 {
            s[k] += x[k] * y[k];
        }
    }
    let mut tail = 0.0;
    for (x, y) in ar.iter().zip(br) {
        tail += x * y;
    }
    (s[0] + s[1]) + (s[2] + s[3]) + tail
}

fn axpy(a: f64, x: &[f64], y: &mut [f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += a * xi;
    }
}

/// The operator and the vectors every run orthogonalizes against.
struct Problem<'a> {
    m: &'a Csr,
    /// `M`'s diagonal when that is all it holds (free particles in Cartesian coordinates):
    /// `M x` is then one product per entry, the numbers [`Csr::mul_vec`] gives, without its
    /// walk over each row's entries (21 of the 364 million instructions of the 10^4-mass
    /// chain's Lanczos).
    mass_diagonal: Option<Vec<f64>>,
    /// Passes of [`Problem::project_out`] made (the tests check that a Lanczos step takes one).
    passes: std::cell::Cell<usize>,
    factor: ShiftedFactor,
    /// Converged vectors and their `M` products.
    locked: Vec<(Vec<f64>, Vec<f64>)>,
}

impl Problem<'_> {
    /// `y = M x`.
    fn mass_mul(&self, x: &[f64], y: &mut [f64]) {
        match &self.mass_diagonal {
            Some(d) => {
                for ((yi, xi), di) in y.iter_mut().zip(x).zip(d) {
                    *yi = di * xi;
                }
            }
            None => self.m.mul_vec(x, y),
        }
    }

    /// `w −= Σ ⟨w, q⟩ q` over `basis` and the locked vectors, twice.
    fn orthogonalize(&self, basis: &[(Vec<f64>, Vec<f64>)], w: &mut [f64]) {
        for _ in 0..2 {
            self.project_out(basis, w);
        }
    }

    /// One pass of `w −= Σ ⟨w, q⟩ q` over the locked vectors and `basis`.
    fn project_out(&self, basis: &[(Vec<f64>, Vec<f64>)], w: &mut [f64]) {
        self.passes.set(self.passes.get() + 1);
        for (q, mq) in self.locked.iter().chain(basis) {
            let c = dot(w, mq);
            axpy(-c, q, w);
        }
    }

    /// [`Problem::project_out`], repeated only when needed (Daniel, Gragg, Kaufman and
    /// Stewart's test, as ARPACK applies it): a pass that leaves `‖w‖_M ≥ ‖w‖_M before / √2`
    /// removed little, so its own rounding is small against what is left and a second pass
    /// would change `w` by round-off only; a larger drop (cancellation: `w` was nearly in the
    /// span) is followed by a second pass. In a Lanczos step, where the three-term recurrence
    /// already removed nearly everything, one pass is the rule: half the work of always two.
    /// Leaves `M w` in `mw`.
    fn reorthogonalize(&self, basis: &[(Vec<f64>, Vec<f64>)], w: &mut [f64], mw: &mut [f64]) {
        self.mass_mul(w, mw);
        let before = dot(w, mw);
        self.project_out(basis, w);
        self.mass_mul(w, mw);
        let after = dot(w, mw);
        // NaN (an indefinite M) takes the second pass too; the caller reports it.
        if after.is_nan() || before.is_nan() || after < 0.5 * before {
            self.project_out(basis, w);
            self.mass_mul(w, mw);
        }
    }
}

/// One Lanczos run: the `want` Ritz pairs of largest `|θ|` once converged (or the basis full).
/// Returns `(θ, x, residual / |θ|)` and the steps taken.
#[allow(clippy::type_complexity)]
fn run(
    p: &Problem<'_>,
    want: usize,
    seed: u64,
    opts: &LanczosOptions,
) -> Result<(Vec<(f64, Vec<f64>, f64)>, usize, bool), LanczosError> {
    let n = p.m.n;
    let room = n - p.locked.len();
    let limit = opts.max_basis.max(want + 1).min(room);
    let mut rng = Start(seed);
    let mut basis: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
    let mut alpha: Vec<f64> = Vec::new();
    let mut beta: Vec<f64> = Vec::new();
    let mut work = vec![0.0; n];
    let mut mw = vec![0.0; n];
    let mass_scale = p.m.diag().iter().fold(0.0f64, |a, b| a.max(b.abs()));
    // A new M-unit vector orthogonal to everything kept; None when there is no room.
    let fresh = |basis: &[(Vec<f64>, Vec<f64>)],
                 rng: &mut Start,
                 mw: &mut Vec<f64>|
     -> Result<Option<(Vec<f64>, Vec<f64>)>, LanczosError> {
        for _ in 0..3 {
            let mut r: Vec<f64> = (0..n).map(|_| rng.next()).collect();
            p.orthogonalize(basis, &mut r);
            p.mass_mul(&r, mw);
            let norm2 = dot(&r, mw);
            if norm2.is_nan() || norm2 < 0.0 {
                return Err(LanczosError::MassNotPositiveDefinite);
            }
            let raw: f64 = dot(&r, &r);
            if norm2 > 0.0 && norm2 > 1e-20 * raw * mass_scale {
                let s = 1.0 / norm2.sqrt();
                r.iter_mut().for_each(|x| *x *= s);
                let mq: Vec<f64> = mw.iter().map(|x| x * s).collect();
                return Ok(Some((r, mq)));
            }
        }
        Ok(None)
    };
    let Some(first) = fresh(&basis, &mut rng, &mut mw)? else {
        return Ok((Vec::new(), 0, true));
    };
    basis.push(first);
    let mut next_check = (2 * want + 20).min(limit);
    loop {
        let j = basis.len() - 1;
        // w = OP q_j = (K − σM)⁻¹ M q_j.
        let mut w = basis[j].1.clone();
        p.factor.solve_in_place(&mut w, &mut work);
        let a = dot(&w, &basis[j].1);
        axpy(-a, &basis[j].0, &mut w);
        if j > 0 {
            axpy(-beta[j - 1], &basis[j - 1].0, &mut w);
        }
        p.reorthogonalize(&basis, &mut w, &mut mw);
        let b2 = dot(&w, &mw);
        if b2.is_nan() || b2 < 0.0 {
            return Err(LanczosError::MassNotPositiveDefinite);
        }
        alpha.push(a);
        let b = b2.sqrt();
        let m = basis.len();
        if m >= next_check || m >= limit {
            let (eig, idx) = ritz(&alpha, &beta, m, want);
            let full = m >= limit;
            let rel: Vec<f64> = idx
                .iter()
                .map(|&i| {
                    let th = eig.eigenvalues[i];
                    // An invariant subspace (m = the room left) is exact.
                    let r = if m == room {
                        0.0
                    } else {
                        (b * eig.eigenvectors[(m - 1, i)]).abs()
                    };
                    r / th.abs().max(f64::MIN_POSITIVE)
                })
                .collect();
            let done = rel.iter().all(|&r| r <= opts.tolerance);
            if done || full {
                let pairs = idx
                    .iter()
                    .zip(&rel)
                    .map(|(&i, &r)| (eig.eigenvalues[i], ritz_vector(&basis, &eig, i, n), r))
                    .collect();
                return Ok((pairs, m, done));
            }
            next_check = (m + want.max(10)).min(limit);
        }
        // The next Lanczos vector, or a fresh start where the Krylov space closed.
        let scale = a.abs().max(beta.last().copied().unwrap_or(0.0));
        if b > 1e-10 * scale && b > 0.0 {
            let s = 1.0 / b;
            w.iter_mut().for_each(|x| *x *= s);
            let mq: Vec<f64> = mw.iter().map(|x| x * s).collect();
            beta.push(b);
            basis.push((w, mq));
        } else {
            match fresh(&basis, &mut rng, &mut mw)? {
                Some(v) => {
                    beta.push(0.0);
                    basis.push(v);
                }
                // Nothing left to explore: the basis spans an invariant subspace.
                None => return run_exact_tail(&basis, &alpha, &beta, want, n),
            }
        }
    }
}

/// The eigen-decomposition of the `m × m` tridiagonal `T` (`alpha` on the diagonal, `beta`
/// beside it) and the indices of its `want` eigenvalues largest in magnitude (of the
/// shift-inverted problem: nearest the shift), largest first.
fn ritz(
    alpha: &[f64],
    beta: &[f64],
    m: usize,
    want: usize,
) -> (nalgebra::SymmetricEigen<f64, nalgebra::Dyn>, Vec<usize>) {
    let mut t = nalgebra::DMatrix::zeros(m, m);
    for i in 0..m {
        t[(i, i)] = alpha[i];
        if i + 1 < m {
            t[(i, i + 1)] = beta[i];
            t[(i + 1, i)] = beta[i];
        }
    }
    let eig = t.symmetric_eigen();
    let mut idx: Vec<usize> = (0..m).collect();
    idx.sort_by(|&x, &y| {
        eig.eigenvalues[y]
            .abs()
            .total_cmp(&eig.eigenvalues[x].abs())
    });
    idx.truncate(want);
    (eig, idx)
}

/// The Ritz vector of `T`'s eigenvector `i`: `Σ_k v_ik q_k` over the basis.
fn ritz_vector(
    basis: &[(Vec<f64>, Vec<f64>)],
    eig: &nalgebra::SymmetricEigen<f64, nalgebra::Dyn>,
    i: usize,
    n: usize,
) -> Vec<f64> {
    let mut x = vec![0.0; n];
    for (k, (q, _)) in basis.iter().enumerate() {
        axpy(eig.eigenvectors[(k, i)], q, &mut x);
    }
    x
}

/// The Ritz pairs of a basis that spans an invariant subspace (no room for another vector).
#[allow(clippy::type_complexity)]
fn run_exact_tail(
    basis: &[(Vec<f64>, Vec<f64>)],
    alpha: &[f64],
    beta: &[f64],
    want: usize,
    n: usize,
) -> Result<(Vec<(f64, Vec<f64>, f64)>, usize, bool), LanczosError> {
    let m = basis.len();
    let (eig, idx) = ritz(alpha, beta, m, want);
    let pairs = idx
        .iter()
        .map(|&i| (eig.eigenvalues[i], ritz_vector(basis, &eig, i, n), 0.0))
        .collect();
    Ok((pairs, m, true))
}

/// The `opts.count` eigenpairs of `K φ = λ M φ` nearest `opts.shift`.
pub fn nearest(k: &Csr, m: &Csr, opts: &LanczosOptions) -> Result<EigenPairs, LanczosError> {
    let n = k.n;
    if m.n != n || opts.count == 0 || opts.count > n {
        return Err(LanczosError::Size {
            stiffness: n,
            mass: m.n,
            count: opts.count,
        });
    }
    let shifted = k.add(1.0, m, -opts.shift);
    let factor = ShiftedFactor::new(&shifted).map_err(LanczosError::Factor)?;
    let factor_entries = factor.entries();
    // One entry per row, on the diagonal (a repeated entry would be a sum: left to mul_vec).
    let diagonal = (0..n).all(|i| m.ptr[i + 1] == m.ptr[i] + 1 && m.col[m.ptr[i]] == i);
    let mut p = Problem {
        m,
        mass_diagonal: diagonal.then(|| m.val.clone()),
        passes: std::cell::Cell::new(0),
        factor,
        locked: Vec::new(),
    };
    let mut found: Vec<(f64, Vec<f64>, f64)> = Vec::new();
    let mut steps = 0;
    let mut seed = 0x5eed_u64;
    loop {
        // The first run finds them all; the next ones look for one more copy each.
        let want = if found.is_empty() { opts.count } else { 1 };
        let (pairs, used, done) = run(&p, want, seed, opts)?;
        steps += used;
        seed = seed.wrapping_add(1);
        let converged: Vec<(f64, Vec<f64>, f64)> = pairs
            .into_iter()
            .filter(|(_, _, r)| *r <= opts.tolerance)
            .collect();
        if found.is_empty() {
            if !done || converged.len() < opts.count {
                return Err(LanczosError::NotConverged {
                    basis: used,
                    converged: converged.len(),
                    wanted: opts.count,
                });
            }
            found = converged;
        } else {
            // Pairs nearer σ than the farthest kept: a missed multiplicity.
            let farthest = found
                .iter()
                .map(|f| f.0.abs())
                .fold(f64::INFINITY, f64::min);
            let nearer: Vec<(f64, Vec<f64>, f64)> = converged
                .into_iter()
                .filter(|c| c.0.abs() > farthest * (1.0 + 1e-9))
                .collect();
            if nearer.is_empty() {
                break;
            }
            found.extend(nearer);
            found.sort_by(|a, b| b.0.abs().total_cmp(&a.0.abs()));
            found.truncate(opts.count);
        }
        if found.len() >= n {
            break;
        }
        p.locked = found
            .iter()
            .map(|(_, x, _)| {
                let mut mx = vec![0.0; n];
                p.mass_mul(x, &mut mx);
                (x.clone(), mx)
            })
            .collect();
    }
    let mut out: Vec<(f64, Vec<f64>, f64)> = found
        .into_iter()
        .map(|(theta, mut x, r)| {
            let mut mx = vec![0.0; n];
            p.mass_mul(&x, &mut mx);
            let s = 1.0 / dot(&x, &mx).sqrt();
            x.iter_mut().for_each(|v| *v *= s);
            (opts.shift + 1.0 / theta, x, r)
        })
        .collect();
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(EigenPairs {
        values: out.iter().map(|o| o.0).collect(),
        residuals: out.iter().map(|o| o.2).collect(),
        vectors: out.into_iter().map(|o| o.1).collect(),
        steps,
        factor_entries,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chain(n: usize, k: f64, m: f64) -> (Csr, Csr) {
        let mut t = Vec::new();
        for i in 0..n {
            t.push((i, i, 2.0 * k));
            if i + 1 < n {
                t.push((i, i + 1, -k));
                t.push((i + 1, i, -k));
            }
        }
        (
            Csr::from_triplets(n, &t).unwrap(),
            Csr::diagonal(&vec![m; n]),
        )
    }

    #[test]
    fn the_lowest_of_a_chain_match_the_closed_form() {
        let (n, k, m) = (400, 100.0, 1.0);
        let (kk, mm) = chain(n, k, m);
        let r = nearest(
            &kk,
            &mm,
            &LanczosOptions {
                count: 8,
                ..LanczosOptions::default()
            },
        )
        .unwrap();
        for (j, &l) in r.values.iter().enumerate() {
            let w = 2.0
                * (k / m).sqrt()
                * libm::sin((j + 1) as f64 * std::f64::consts::PI / (2.0 * (n + 1) as f64));
            assert!(
                (l.sqrt() - w).abs() <= 1e-12 * w,
                "mode {}: {} vs {w}",
                j + 1,
                l.sqrt()
            );
        }
    }

    #[test]
    fn a_lanczos_step_projects_once_and_still_meets_the_closed_form() {
        // Full reorthogonalization in one pass per step (two only after cancellation): the
        // start vector takes two, each step one. Always two passes would be 2 per step.
        let (n, k, m, want) = (2000, 100.0, 1.0, 10);
        let (kk, mm) = chain(n, k, m);
        let p = Problem {
            m: &mm,
            factor: ShiftedFactor::new(&kk).unwrap(),
            locked: Vec::new(),
            mass_diagonal: Some(mm.val.clone()),
            passes: std::cell::Cell::new(0),
        };
        let (pairs, steps, done) = run(&p, want, 1, &LanczosOptions::default()).unwrap();
        assert!(done);
        assert!(
            p.passes.get() <= steps + 2,
            "{} passes for {steps} steps",
            p.passes.get()
        );
        let mut omega: Vec<f64> = pairs
            .iter()
            .map(|(theta, _, _)| (1.0 / theta).sqrt())
            .collect();
        omega.sort_by(f64::total_cmp);
        for (j, w) in omega.iter().enumerate() {
            let exact = 2.0
                * (k / m).sqrt()
                * libm::sin((j + 1) as f64 * std::f64::consts::PI / (2.0 * (n + 1) as f64));
            assert!(
                (w - exact).abs() <= 1e-12 * exact,
                "mode {}: {w} vs {exact}",
                j + 1
            );
        }
    }

    #[test]
    fn a_repeated_eigenvalue_is_found_twice() {
        // Two identical, separate chains: every eigenvalue twice.
        let (a, _) = chain(30, 1.0, 1.0);
        let mut t = Vec::new();
        for i in 0..30 {
            for (j, v) in a.row(i) {
                t.push((i, j, v));
                t.push((i + 30, j + 30, v));
            }
        }
        let kk = Csr::from_triplets(60, &t).unwrap();
        let mm = Csr::diagonal(&[1.0; 60]);
        let r = nearest(
            &kk,
            &mm,
            &LanczosOptions {
                count: 4,
                ..LanczosOptions::default()
            },
        )
        .unwrap();
        let exact = |j: usize| 4.0 * libm::sin(j as f64 * std::f64::consts::PI / 62.0).powi(2);
        let want = [exact(1), exact(1), exact(2), exact(2)];
        for (l, w) in r.values.iter().zip(want) {
            assert!((l - w).abs() <= 1e-12 * w, "{l} vs {w}");
        }
    }

    #[test]
    fn everything_of_a_small_pencil_matches_the_dense_eigenvalues() {
        // A random SPD K and a non-diagonal SPD M, all the eigenpairs (the basis fills the space).
        let n = 12;
        let mut s = Start(3);
        let b = nalgebra::DMatrix::from_fn(n, n, |_, _| s.next());
        let kd = &b * b.transpose() + nalgebra::DMatrix::identity(n, n) * 0.5;
        let md = nalgebra::DMatrix::from_fn(n, n, |i, j| {
            if i == j {
                2.0
            } else if i.abs_diff(j) == 1 {
                0.5
            } else {
                0.0
            }
        });
        let trip = |d: &nalgebra::DMatrix<f64>| {
            let mut t = Vec::new();
            for i in 0..n {
                for j in 0..n {
                    if d[(i, j)] != 0.0 {
                        t.push((i, j, d[(i, j)]));
                    }
                }
            }
            Csr::from_triplets(n, &t).unwrap()
        };
        let r = nearest(
            &trip(&kd),
            &trip(&md),
            &LanczosOptions {
                count: n,
                ..LanczosOptions::default()
            },
        )
        .unwrap();
        let l = md.clone().cholesky().unwrap().l();
        let li = l.clone().try_inverse().unwrap();
        let c = &li * &kd * li.transpose();
        let mut ev: Vec<f64> = c.symmetric_eigen().eigenvalues.iter().copied().collect();
        ev.sort_by(f64::total_cmp);
        for (a, b) in r.values.iter().zip(&ev) {
            assert!((a - b).abs() <= 1e-10 * b.abs().max(1.0), "{a} vs {b}");
        }
    }
}
