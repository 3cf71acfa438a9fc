//! Equilibrium and modes of large systems with sparse matrices: the same mathematics as
//! [`crate::equilibrium`] and [`crate::modes`], with `M`, `K`, `C` kept sparse
//! ([`crate::linearization::Linearizer::at_sparse`]), where the dense path needs `n²` memory
//! and `n³` work.
//!
//! - **Equilibrium**: Newton–Levenberg–Marquardt as in [`crate::equilibrium::solve`], each step
//!   `(K_s + μ D) δq = f` with `K_s = (K + Kᵀ)/2` (Newton's exact step for conservative forces,
//!   whose `K` is symmetric, taken where it lowers `|f|` or the energy; for others a
//!   quasi-Newton step, taken only where it lowers `|f|`: `damped_newton.rs`). Each step is
//!   solved by the supernodal multifrontal LU of pdyn-sparse in nested-dissection order,
//!   analysed once (the pattern of `K_s + D` does not change from step to step): on a 2-D mesh
//!   `O(n^{3/2})` work per step where the envelope `L D Lᵀ` of reverse Cuthill–McKee
//!   ([`crate::sparse::EnvelopeLdlt`]) takes `O(n b²)`, `b ~ √n` (the 100 × 100 cloth: ~300);
//!   the envelope remains for a pattern the LU refuses as too large.
//! - **Modes**: the `count` lowest of `K_s φ = ω² M φ` by shift-invert Lanczos
//!   ([`crate::lanczos::nearest`], shift 0, or just below 0 when `K` is singular).
//! - **Free directions** (a mechanism, a neutral equilibrium): the eigenvectors of
//!   `K_s φ = λ D φ` with `|λ| ≤ 10⁻⁹ max_i |K_ii| / D_ii`, the lowest six looked at.

use crate::damped_newton::TrialEnd;
use crate::equilibrium::{EquilibriumError, EquilibriumOptions, FreeDirection};
use crate::lanczos::{nearest, LanczosError, LanczosOptions};
use crate::linearization::{Linearize, SparseLinearization};
use crate::modes::{Mode, Modes, ModesError};
use crate::sparse::{envelope_size, rcm, Csr, EnvelopeLdlt, SparseError};
use pdyn_sparse::sparse_lu::{Pattern, SparseLu, Symbolic};
use std::cell::RefCell;

/// Coordinates from which the front ends choose the sparse path by default: below it the
/// dense one (all modes, `O(n³)`) takes under half a second.
pub const SPARSE_FROM: usize = 300;

/// Modes the sparse path finds when no count is asked for.
pub const DEFAULT_SPARSE_COUNT: usize = 20;

/// An equilibrium found by [`solve`].
#[derive(Clone, Debug)]
pub struct SparseEquilibrium {
    /// The free coordinates at equilibrium.
    pub q: Vec<f64>,
    /// `|f|` there.
    pub residual: f64,
    /// The force scale the tolerance is relative to.
    pub scale: f64,
    /// Newton steps taken.
    pub steps: usize,
    /// The linearization there.
    pub linearization: SparseLinearization,
    /// Directions along which the equilibrium is neutral.
    pub neutral: Vec<FreeDirection>,
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The equilibrium nearest `start` (default: the initial values), sparse.
pub fn solve<L: Linearize + ?Sized>(
    lin: &L,
    start: Option<&[f64]>,
    opts: &EquilibriumOptions,
) -> Result<SparseEquilibrium, EquilibriumError> {
    let q: Vec<f64> = start.unwrap_or(lin.initial()).to_vec();
    let at = lin.at_sparse(&q);
    let kd = at.stiffness.diag();
    let stiff = kd.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let length = q.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    let scale = norm(&at.force).max(stiff * length).max(f64::MIN_POSITIVE);
    let target = opts.tolerance * scale;
    let diag: Vec<f64> = at
        .mass
        .diag()
        .iter()
        .map(|x| x.abs().max(f64::MIN_POSITIVE))
        .collect();
    let dmax = diag.iter().fold(0.0f64, |m, x| m.max(*x));
    let ratio = stiff.max(f64::MIN_POSITIVE) / dmax;
    let mirror = Mirror::of(&at.stiffness);
    let at = SparseAt::new(at, mirror.as_ref());
    let sparse = Sparse {
        lin,
        solver: RefCell::new(StepSolver::new(&at.ks.add(1.0, &Csr::diagonal(&diag), 1.0))),
        diag: &diag,
        mirror,
    };
    let end = crate::damped_newton::solve(&sparse, q, at, &diag, ratio, target, opts)?;
    // The steps' factors freed before the free directions' Lanczos factors its own matrix:
    // the peak memory is the larger of the two, not their sum.
    drop(sparse);
    let (q, SparseAt { at, ks, .. }, residual, steps) = (end.q, end.at, end.residual, end.steps);
    let neutral = if opts.neutral {
        free_directions(lin.names(), &ks, &diag)
    } else {
        Vec::new()
    };
    Ok(SparseEquilibrium {
        q,
        residual,
        scale,
        steps,
        linearization: at,
        neutral,
    })
}

/// The sparse path of damped Newton: the symmetric part of `K`, by the solver of its
/// pattern.
struct Sparse<'a, L: ?Sized> {
    lin: &'a L,
    /// Mutable behind `&self` ([`crate::damped_newton::NewtonSystem::step`]): the LU's
    /// storage is reused by every step.
    solver: RefCell<StepSolver>,
    diag: &'a [f64],
    /// The mirror of the start's pattern of `K`, when symmetric.
    mirror: Option<Mirror>,
}

/// How the steps `(K_s + diag(damping)) δq = f` are solved: the analysis of their pattern,
/// done once.
enum StepSolver {
    /// The supernodal LU of pdyn-sparse in nested-dissection order, symmetric (no pivoting:
    /// `K_s + μD` is symmetric, its elimination without pivoting is its `L D Lᵀ`).
    Lu {
        pattern: Pattern,
        /// Where each diagonal entry is in the pattern's values.
        diagonal: Vec<usize>,
        /// Boxed: the analysis and the factors are large beside the envelope's order.
        symbolic: Box<Symbolic>,
        lu: Box<SparseLu>,
    },
    /// The envelope `L D Lᵀ` in one reverse Cuthill–McKee order: for a narrow band (a chain),
    /// and for a pattern whose LU factors the analysis refused as too large (the envelope has
    /// its own limit).
    Envelope { order: Vec<usize> },
}

/// Mean entries per row of the envelope up to which the steps take the envelope without
/// analysing the LU: a chain's band (1) or a narrow one's, where the envelope is already the
/// fill of any order. The nested-dissection analysis alone cost the 10⁴-mass chain's `pdyn
/// modes` 190 M instructions, for a band-1 factor the envelope makes in `O(n)`; the 20 × 20
/// net (rows of ~60) gains from the LU.
const ENVELOPE_UP_TO: usize = 8;

impl StepSolver {
    /// The solver for matrices with the pattern of `a` (every diagonal present).
    fn new(a: &Csr) -> StepSolver {
        let order = rcm(a);
        if envelope_size(a, &order) <= ENVELOPE_UP_TO.saturating_mul(a.n) {
            return StepSolver::Envelope { order };
        }
        let pattern = Pattern {
            start: a.ptr.clone(),
            cols: a.col.clone(),
        };
        let diagonal: Option<Vec<usize>> = (0..a.n)
            .map(|i| {
                let row = &a.col[a.ptr[i]..a.ptr[i + 1]];
                row.binary_search(&i).ok().map(|k| a.ptr[i] + k)
            })
            .collect();
        match (Symbolic::new(&pattern), diagonal) {
            (Ok(symbolic), Some(diagonal)) => {
                let lu = Box::new(SparseLu::new(&symbolic));
                StepSolver::Lu {
                    pattern,
                    diagonal,
                    symbolic: Box::new(symbolic),
                    lu,
                }
            }
            _ => StepSolver::Envelope { order },
        }
    }

    /// `(ks + diag(damping))⁻¹ b`: the damping added on the diagonal of a copy of `ks`'s
    /// values when `ks` has this solver's pattern (no merge of two matrices per trial step),
    /// by [`StepSolver::solve`] otherwise. The same values either way (`x + d`).
    fn solve_damped(&mut self, ks: &Csr, damping: &[f64], b: &[f64]) -> Option<Vec<f64>> {
        if let StepSolver::Lu {
            pattern,
            diagonal,
            symbolic,
            lu,
        } = self
        {
            if ks.ptr == pattern.start && ks.col == pattern.cols {
                let mut values = ks.val.clone();
                for (&k, d) in diagonal.iter().zip(damping) {
                    values[k] += d;
                }
                lu.factor_symmetric(symbolic, &values).ok()?;
                let mut x = b.to_vec();
                lu.solve_in_place(symbolic, &mut x);
                return Some(x);
            }
        }
        self.solve(&ks.add(1.0, &Csr::diagonal(damping), 1.0), b)
    }

    /// `A⁻¹ b`, or `None` when `A` cannot be factored (a zero or negligible pivot).
    fn solve(&mut self, a: &Csr, b: &[f64]) -> Option<Vec<f64>> {
        match self {
            StepSolver::Lu {
                pattern,
                symbolic,
                lu,
                ..
            } if a.ptr == pattern.start && a.col == pattern.cols => {
                // `a` is symmetric (`K_s + diag`) on a symmetric pattern.
                lu.factor_symmetric(symbolic, &a.val).ok()?;
                let mut x = b.to_vec();
                lu.solve_in_place(symbolic, &mut x);
                Some(x)
            }
            StepSolver::Lu { .. } => {
                // A linearization whose pattern changed (not one of the kernels' or the
                // symbolic path's, whose patterns are fixed): analysed again.
                *self = StepSolver::new(a);
                self.solve(a, b)
            }
            StepSolver::Envelope { order } => {
                let f = EnvelopeLdlt::with_order(a, order.clone()).ok()?;
                Some(f.solve(b))
            }
        }
    }
}

/// A sparse linearization with the symmetric part of its stiffness.
struct SparseAt {
    at: SparseLinearization,
    ks: Csr,
    /// Whether `K` is symmetric to round-off ([`crate::equilibrium::SYMMETRIC`]), found with
    /// `K_s` from the one transpose (damped Newton asks at every trial step).
    conservative: bool,
}

/// Where each entry's mirror image is in a symmetric pattern (`(j, i)` for `(i, j)`): the
/// transpose of a matrix with this pattern, as values in the same places, without
/// transposing it (damped Newton forms `K_s` at every step taken; the pattern of the net's and
/// of the symbolic path's `K` does not change from step to step).
struct Mirror {
    ptr: Vec<usize>,
    col: Vec<usize>,
    of: Vec<usize>,
}

impl Mirror {
    /// The mirror of `a`'s pattern, when it is symmetric.
    fn of(a: &Csr) -> Option<Mirror> {
        let mut of = Vec::with_capacity(a.col.len());
        for i in 0..a.n {
            for &j in &a.col[a.ptr[i]..a.ptr[i + 1]] {
                let row = &a.col[a.ptr[j]..a.ptr[j + 1]];
                of.push(a.ptr[j] + row.binary_search(&i).ok()?);
            }
        }
        Some(Mirror {
            ptr: a.ptr.clone(),
            col: a.col.clone(),
            of,
        })
    }

    /// `aᵀ`'s values (in `a`'s places) when `a` has this pattern.
    fn transposed_values(&self, a: &Csr) -> Option<Vec<f64>> {
        (a.ptr == self.ptr && a.col == self.col)
            .then(|| self.of.iter().map(|&k| a.val[k]).collect())
    }
}

impl SparseAt {
    /// `at` with `K_s`; `mirror`, when it is the pattern of `K`, gives `Kᵀ` (the numbers of
    /// [`Csr::transpose`]: the same values in the same places).
    fn new(at: SparseLinearization, mirror: Option<&Mirror>) -> SparseAt {
        let k = &at.stiffness;
        let kt = match mirror.and_then(|m| m.transposed_values(k)) {
            Some(val) => Csr {
                n: k.n,
                ptr: k.ptr.clone(),
                col: k.col.clone(),
                val,
            },
            None => k.transpose(),
        };
        let ks = k.add(0.5, &kt, 0.5);
        // max |K_ij − K_ji| / max |K_ij|, as `Csr::asymmetry` (without a search per entry;
        // entry by entry where the pattern is symmetric, as a net's and a truss's are).
        let big = k.val.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let worst = if k.ptr == kt.ptr && k.col == kt.col {
            k.val
                .iter()
                .zip(&kt.val)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
        } else {
            k.add(1.0, &kt, -1.0)
                .val
                .iter()
                .fold(0.0f64, |m, v| m.max(v.abs()))
        };
        let conservative = big == 0.0 || worst <= crate::equilibrium::SYMMETRIC * big;
        SparseAt {
            at,
            ks,
            conservative,
        }
    }
}

impl<L: Linearize + ?Sized> crate::damped_newton::NewtonSystem for Sparse<'_, L> {
    type At = SparseAt;
    type Trial = TrialEnd<SparseLinearization>;

    fn trial(&self, q: &[f64]) -> Self::Trial {
        if self.lin.force_alone() {
            TrialEnd::Force(self.lin.force(q))
        } else {
            TrialEnd::Whole(self.lin.at_sparse(q))
        }
    }

    fn trial_residual(&self, trial: &Self::Trial) -> f64 {
        norm(match trial {
            TrialEnd::Force(f) => f,
            TrialEnd::Whole(at) => &at.force,
        })
    }

    fn taken(&self, q: &[f64], trial: Self::Trial) -> SparseAt {
        let at = match trial {
            TrialEnd::Force(f) => self.lin.at_sparse_with(q, f),
            TrialEnd::Whole(at) => at,
        };
        SparseAt::new(at, self.mirror.as_ref())
    }

    fn residual(&self, at: &SparseAt) -> f64 {
        norm(&at.at.force)
    }

    fn step(&self, at: &SparseAt, damping: &[f64]) -> Option<Vec<f64>> {
        self.solver
            .borrow_mut()
            .solve_damped(&at.ks, damping, &at.at.force)
    }

    fn free_directions(&self, at: &SparseAt) -> Vec<FreeDirection> {
        free_directions(self.lin.names(), &at.ks, self.diag)
    }

    fn force(&self, q: &[f64]) -> Vec<f64> {
        self.lin.force(q)
    }

    fn stiffness_mul(&self, at: &SparseAt, v: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; v.len()];
        at.ks.mul_vec(v, &mut out);
        out
    }

    fn conservative(&self, at: &SparseAt) -> bool {
        at.conservative
    }
}

/// `(A + Aᵀ) / 2`.
pub fn symmetric_part(a: &Csr) -> Csr {
    a.add(0.5, &a.transpose(), 0.5)
}

/// The eigenvectors of `K_s φ = λ D φ` with `|λ|` at most 1e-9 of `max |K_ii| / D_ii`: among
/// the lowest six (or `n`).
pub fn free_directions(names: &[String], ks: &Csr, diag: &[f64]) -> Vec<FreeDirection> {
    let n = ks.n;
    let largest = (0..n).fold(0.0f64, |m, i| m.max((ks.get(i, i) / diag[i]).abs()));
    if largest == 0.0 {
        // No stiffness at all: every coordinate is free; name them one by one.
        return names
            .iter()
            .take(6)
            .map(|name| FreeDirection {
                components: vec![(name.clone(), 1.0)],
                moved: 1,
            })
            .collect();
    }
    let d = Csr::diagonal(diag);
    let opts = LanczosOptions {
        count: n.min(6),
        shift: -1e-7 * largest,
        ..LanczosOptions::default()
    };
    let Ok(pairs) = nearest(ks, &d, &opts) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for (lambda, v) in pairs.values.iter().zip(&pairs.vectors) {
        if lambda.abs() > 1e-9 * largest {
            continue;
        }
        // Unit Euclidean length, as the dense path reports them.
        let len = norm(v);
        let v: Vec<f64> = v.iter().map(|x| x / len).collect();
        out.push(FreeDirection::of(&v, names));
    }
    out
}

/// The `count` lowest modes of `lin` by shift-invert Lanczos on the sparse `K_s`, `M`.
pub fn lowest_modes(lin: &SparseLinearization, count: usize) -> Result<Modes, ModesError> {
    let m = &lin.mass;
    let n = m.n;
    if m.asymmetry() > 1e-12 {
        return Err(ModesError::MassNotPositiveDefinite);
    }
    if m.diag().iter().any(|&d| d.is_nan() || d <= 0.0) {
        return Err(ModesError::MassNotPositiveDefinite);
    }
    let stiffness_asymmetry = lin.stiffness.asymmetry();
    let ks = symmetric_part(&lin.stiffness);
    let count = count.clamp(1, n);
    let mut opts = LanczosOptions {
        count,
        ..LanczosOptions::default()
    };
    let pairs = match nearest(&ks, m, &opts) {
        // K singular (a free body, a neutral direction): shift just below 0.
        Err(LanczosError::Factor(SparseError::SingularMatrix { .. })) => {
            let largest = (0..n).fold(0.0f64, |a, i| a.max((ks.get(i, i) / m.get(i, i)).abs()));
            opts.shift = -1e-7 * largest.max(f64::MIN_POSITIVE);
            nearest(&ks, m, &opts)
        }
        r => r,
    }
    .map_err(ModesError::Sparse)?;
    let mut modes = Vec::with_capacity(pairs.values.len());
    let mut kphi = vec![0.0; n];
    for (&w2, phi) in pairs.values.iter().zip(&pairs.vectors) {
        let mut phi = phi.clone();
        crate::modes::unit_largest(&mut phi);
        ks.mul_vec(&phi, &mut kphi);
        modes.push(Mode {
            omega_squared: w2,
            omega: if w2 >= 0.0 { w2.sqrt() } else { f64::NAN },
            modal_mass: m.form(&phi, &phi),
            modal_stiffness: phi.iter().zip(&kphi).map(|(a, b)| a * b).sum(),
            shape: phi,
            participation: [f64::NAN; 3],
            effective_mass: [f64::NAN; 3],
        });
    }
    Ok(Modes {
        modes,
        stiffness_asymmetry,
        total_mass: [f64::NAN; 3],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A symmetric `K + diag(d)` on the pattern of an `m × m` grid of nodes with three
    /// coordinates each (a net's), random values from a seeded generator.
    fn grid(m: usize, shift: f64, seed: u64) -> Csr {
        let mut s = seed;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut t = Vec::new();
        for node in 0..m * m {
            let (r, c) = (node / m, node % m);
            for a in 0..3 {
                t.push((3 * node + a, 3 * node + a, shift));
            }
            let mut near = vec![node];
            if c + 1 < m {
                near.push(node + 1);
            }
            if r + 1 < m {
                near.push(node + m);
            }
            for &other in &near {
                for a in 0..3 {
                    for b in 0..3 {
                        let (i, j) = (3 * node + a, 3 * other + b);
                        if i < j || (other != node && i != j) {
                            let v = next();
                            t.push((i, j, v));
                            t.push((j, i, v));
                        }
                    }
                }
            }
        }
        Csr::from_triplets(3 * m * m, &t).unwrap()
    }

    /// `x` is `a⁻¹ b` as nalgebra's dense LU gives it, to `tol` of its largest component.
    fn assert_solves_as_dense(a: &Csr, b: &[f64], x: &[f64], tol: f64, what: &str) {
        let dense = a
            .to_dense()
            .lu()
            .solve(&nalgebra::DVector::from_vec(b.to_vec()))
            .unwrap();
        let big = dense.iter().fold(0.0f64, |s, v| s.max(v.abs()));
        for (u, v) in x.iter().zip(dense.iter()) {
            assert!((u - v).abs() <= tol * big, "{what}: {u} vs {v}");
        }
    }

    #[test]
    fn steps_solve_as_the_dense_lu_definite_or_not_and_after_a_change_of_pattern() {
        for (m, shift, seed) in [(4, 9.0, 1u64), (11, 6.0, 2), (11, -2.5, 3)] {
            let a = grid(m, shift, seed);
            let n = a.n;
            let mut solver = StepSolver::new(&a);
            assert!(matches!(solver, StepSolver::Lu { .. }));
            let b: Vec<f64> = (0..n).map(|i| ((i * 7) % 13) as f64 - 6.0).collect();
            let x = solver.solve(&a, &b).unwrap();
            assert_solves_as_dense(&a, &b, &x, 1e-10, &format!("m = {m}"));
            // Another pattern (the grid one node smaller) is analysed again, not misread.
            let small = grid(m - 1, shift, seed);
            let y = solver.solve(&small, &b[..small.n]).unwrap();
            assert_solves_as_dense(&small, &b[..small.n], &y, 1e-10, &format!("m = {m} − 1"));
        }
    }

    #[test]
    fn a_chain_s_steps_take_the_envelope_without_analysing_the_lu() {
        // A spring chain's stiffness (tridiagonal, shuffled): band 1 in RCM order, the
        // envelope's fill is every order's; the steps solve as the dense LU does.
        let n = 400;
        let at = |k: usize| (k * 7) % n; // a permutation of 0..n (7 is prime to 400)
        let mut t = Vec::new();
        for k in 0..n {
            t.push((at(k), at(k), 2.0 + 0.01 * k as f64));
            if k + 1 < n {
                t.push((at(k), at(k + 1), -1.0));
                t.push((at(k + 1), at(k), -1.0));
            }
        }
        let a = Csr::from_triplets(n, &t).unwrap();
        let mut solver = StepSolver::new(&a);
        assert!(matches!(solver, StepSolver::Envelope { .. }));
        let b: Vec<f64> = (0..n).map(|i| ((i * 5) % 11) as f64 - 5.0).collect();
        let x = solver.solve(&a, &b).unwrap();
        assert_solves_as_dense(&a, &b, &x, 1e-12, "chain");
    }

    #[test]
    fn a_damped_step_is_the_step_of_the_sum() {
        // `ks + diag(d)` by the copy of `ks`'s values and by the merge: the same bits.
        let ks = grid(6, 0.0, 9);
        let d: Vec<f64> = (0..ks.n).map(|i| 3.0 + (i % 5) as f64).collect();
        let b: Vec<f64> = (0..ks.n).map(|i| (i % 4) as f64 - 1.5).collect();
        let sum = ks.add(1.0, &Csr::diagonal(&d), 1.0);
        let mut solver = StepSolver::new(&sum);
        let x = solver.solve_damped(&ks, &d, &b).unwrap();
        let y = solver.solve(&sum, &b).unwrap();
        assert!(x.iter().zip(&y).all(|(u, v)| u.to_bits() == v.to_bits()));
        // A `ks` missing a diagonal entry goes through the merge.
        let t: Vec<(usize, usize, f64)> = (1..ks.n)
            .flat_map(|i| [(i, i, 1.0), (i, i - 1, 0.5), (i - 1, i, 0.5)])
            .collect();
        let sparse = Csr::from_triplets(ks.n, &t).unwrap();
        let z = solver.solve_damped(&sparse, &d, &b).unwrap();
        let dense = sparse
            .add(1.0, &Csr::diagonal(&d), 1.0)
            .to_dense()
            .lu()
            .solve(&nalgebra::DVector::from_vec(b.clone()))
            .unwrap();
        for (u, v) in z.iter().zip(dense.iter()) {
            assert!((u - v).abs() <= 1e-12, "{u} vs {v}");
        }
    }

    #[test]
    fn a_mirror_transposes_as_the_transpose_does() {
        // A grid's pattern is symmetric, its values are not (`grid` mirrors them; changed
        // here entry by entry): `Kᵀ`'s values from the mirror are the transpose's, bit for bit.
        let mut k = grid(5, 2.0, 4);
        for (e, v) in k.val.iter_mut().enumerate() {
            *v += 0.001 * e as f64;
        }
        let mirror = Mirror::of(&k).unwrap();
        let kt = k.transpose();
        assert_eq!((&kt.ptr, &kt.col), (&k.ptr, &k.col));
        let val = mirror.transposed_values(&k).unwrap();
        assert!(val
            .iter()
            .zip(&kt.val)
            .all(|(a, b)| a.to_bits() == b.to_bits()));
        // Another pattern is not read through it; an asymmetric pattern has no mirror.
        assert!(mirror.transposed_values(&grid(4, 2.0, 4)).is_none());
        let upper = Csr::from_triplets(2, &[(0, 0, 1.0), (0, 1, 2.0), (1, 1, 3.0)]).unwrap();
        assert!(Mirror::of(&upper).is_none());
    }

    #[test]
    fn a_singular_step_matrix_is_no_step() {
        // Two coordinates joined by a spring and held by nothing: singular.
        let a =
            Csr::from_triplets(2, &[(0, 0, 1.0), (0, 1, -1.0), (1, 0, -1.0), (1, 1, 1.0)]).unwrap();
        let mut solver = StepSolver::new(&a);
        assert_eq!(solver.solve(&a, &[1.0, 0.0]), None);
        let held = a.add(1.0, &Csr::diagonal(&[1.0, 0.0]), 1.0);
        let x = solver.solve(&held, &[1.0, 0.0]).unwrap();
        // [[2, −1], [−1, 1]] x = [1, 0]: x = [1, 1].
        assert!(
            (x[0] - 1.0).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15,
            "{x:?}"
        );
    }
}
