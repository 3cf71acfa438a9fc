//! The factorization of `K − σ M` that shift-invert Lanczos ([`crate::lanczos`]) solves with at
//! every step: the envelope `L D Lᵀ` in reverse Cuthill–McKee order
//! ([`crate::sparse::EnvelopeLdlt`]) or pdyn-sparse's symmetric supernodal LU in nested-dissection
//! order, whichever is predicted cheaper.
//!
//! Both eliminate without pivoting (`U = D Lᵀ` in the LU's symmetric mode), and both cost, per
//! solve, about two multiply-adds per entry of `L`, but the LU's per entry a little more (its
//! supernodes' gathers, its permutations), and its analysis (ordering, symbolic factorization)
//! costs about as much as the envelope's whole factorization: on the 20 × 20 net (1,194
//! coordinates, factors of about the same size) the LU made Lanczos 26 % dearer. The
//! envelope is `O(n b)` and nested dissection's fill `O(n log n)` on a 2-D mesh, so the LU
//! wins on large meshes only: on a net of `m × m` nodes with three coordinates each and four
//! neighbours, its factor is 1.03 of the envelope's at `m = 20`, 0.66 at 40, 0.52 at 60 and
//! 0.37 at 100 (`tests::net`). So the envelope (known from the RCM order in `O(nnz)`) is kept
//! when its rows average at most [`ANALYSE_FROM`] entries (a chain's: 1), and otherwise the
//! LU is analysed and taken when its factor holds under two thirds of the envelope's entries
//! (a margin for its dearer entries; at `m = 60` its solves read half as many).
//!
//! Singularity is decided as before: a pivot the LU rejects sends the matrix to the envelope,
//! whose [`SparseError::SingularMatrix`] (or success) is the answer callers know (the shift is
//! moved off an eigenvalue on that error).

use crate::sparse::{envelope_size, rcm, Csr, EnvelopeLdlt, SparseError};
use pdyn_sparse::sparse_lu::{Pattern, SparseLu, Symbolic};
use std::cell::RefCell;

/// Mean entries per row of the envelope (its bandwidth, roughly) from which the LU is analysed:
/// below it, the envelope is at most about the LU's size (a net of up to ~35 × 35 nodes).
pub const ANALYSE_FROM: usize = 100;

/// A factorization of a symmetric `A` (the lower triangle of `(A + Aᵀ)/2`, as the envelope
/// takes it), to solve `A x = b` many times.
#[derive(Debug)]
pub enum ShiftedFactor {
    /// The envelope `L D Lᵀ` in RCM order.
    Envelope(EnvelopeLdlt),
    /// The symmetric supernodal LU in nested-dissection order (its solve uses scratch space
    /// inside the factors: behind a `RefCell`, the operator is applied through `&self`).
    Supernodal {
        /// The analysis of the pattern.
        symbolic: Box<Symbolic>,
        /// The factors.
        lu: Box<RefCell<SparseLu>>,
    },
}

impl ShiftedFactor {
    /// Factors `a`, by the factorization predicted to hold fewer entries.
    pub fn new(a: &Csr) -> Result<ShiftedFactor, SparseError> {
        let order = rcm(a);
        let envelope = envelope_size(a, &order);
        if envelope > ANALYSE_FROM.saturating_mul(a.n) {
            if let Some(f) = supernodal(a, envelope) {
                return Ok(f);
            }
        }
        EnvelopeLdlt::with_order(a, order).map(ShiftedFactor::Envelope)
    }

    /// Entries of `L` below its diagonal.
    pub fn entries(&self) -> usize {
        match self {
            ShiftedFactor::Envelope(f) => f.envelope(),
            ShiftedFactor::Supernodal { symbolic, .. } => symbolic.factor_entries(),
        }
    }

    /// Solves `A x = b` in place (`work` of the same length, overwritten by the envelope).
    pub fn solve_in_place(&self, b: &mut [f64], work: &mut [f64]) {
        match self {
            ShiftedFactor::Envelope(f) => f.solve_in_place(b, work),
            ShiftedFactor::Supernodal { symbolic, lu } => {
                lu.borrow_mut().solve_in_place(symbolic, b)
            }
        }
    }
}

/// The symmetric LU of `(a + aᵀ)/2` when its analysis predicts under two thirds of the entries
/// of the envelope's `envelope` and every pivot is accepted; `None` otherwise (the envelope is used).
fn supernodal(a: &Csr, envelope: usize) -> Option<ShiftedFactor> {
    // The symmetric part on a symmetric pattern: entry by entry where `a`'s pattern is
    // already symmetric (`K_s − σM`: the values are unchanged, `(v + v)/2 = v`).
    let t = a.transpose();
    let sym = if t.ptr == a.ptr && t.col == a.col {
        let val = a
            .val
            .iter()
            .zip(&t.val)
            .map(|(x, y)| 0.5 * (x + y))
            .collect();
        Csr { val, ..t }
    } else {
        a.add(0.5, &t, 0.5)
    };
    // The LU needs every diagonal entry in the pattern.
    if (0..sym.n).any(|i| {
        sym.col[sym.ptr[i]..sym.ptr[i + 1]]
            .binary_search(&i)
            .is_err()
    }) {
        return None;
    }
    let pattern = Pattern {
        start: sym.ptr.clone(),
        cols: sym.col.clone(),
    };
    let symbolic = Symbolic::new(&pattern).ok()?;
    if symbolic.factor_entries().saturating_mul(3) >= envelope.saturating_mul(2) {
        return None;
    }
    let mut lu = SparseLu::new(&symbolic);
    lu.factor_symmetric(&symbolic, &sym.val).ok()?;
    Some(ShiftedFactor::Supernodal {
        symbolic: Box::new(symbolic),
        lu: Box::new(RefCell::new(lu)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// splitmix64 numbers in [-1, 1).
    fn rng(seed: u64) -> impl FnMut() -> f64 {
        let mut s = crate::lanczos::Start(seed);
        move || s.next()
    }

    /// A symmetric matrix on a net's pattern: an `m × m` grid of nodes with three coordinates
    /// each, every node coupled to its four neighbours, `shift` on the diagonal (negative: an
    /// indefinite matrix, as `K − σM` is for a shift inside the spectrum).
    fn net(m: usize, shift: f64, seed: u64) -> Csr {
        let mut r = rng(seed);
        let mut t = Vec::new();
        for node in 0..m * m {
            let (row, col) = (node / m, node % m);
            let mut near = vec![node];
            if col + 1 < m {
                near.push(node + 1);
            }
            if row + 1 < m {
                near.push(node + m);
            }
            for &other in &near {
                for a in 0..3 {
                    for b in 0..3 {
                        let (i, j) = (3 * node + a, 3 * other + b);
                        if i == j {
                            t.push((i, i, shift + r()));
                        } else if other != node || i < j {
                            let v = r();
                            t.push((i, j, v));
                            t.push((j, i, v));
                        }
                    }
                }
            }
        }
        Csr::from_triplets(3 * m * m, &t).unwrap()
    }

    /// `max |x − A⁻¹ b| / max |A⁻¹ b|` with the dense LU's solution.
    fn error_against_dense(a: &Csr, f: &ShiftedFactor, seed: u64) -> f64 {
        let mut r = rng(seed);
        let b: Vec<f64> = (0..a.n).map(|_| r()).collect();
        let mut x = b.clone();
        let mut work = vec![0.0; a.n];
        f.solve_in_place(&mut x, &mut work);
        crate::sparse::tests::error_against_dense(a, b, &x)
    }

    /// `max |A x − b| / max (|A| |x|)`: the solve's backward error, entry by entry.
    fn residual(a: &Csr, f: &ShiftedFactor, seed: u64) -> f64 {
        let mut r = rng(seed);
        let b: Vec<f64> = (0..a.n).map(|_| r()).collect();
        let mut x = b.clone();
        let mut work = vec![0.0; a.n];
        f.solve_in_place(&mut x, &mut work);
        let (mut worst, mut scale) = (0.0f64, 0.0f64);
        for (i, bi) in b.iter().enumerate() {
            let ax: f64 = a.row(i).map(|(j, v)| v * x[j]).sum();
            let size: f64 = a.row(i).map(|(j, v)| (v * x[j]).abs()).sum();
            worst = worst.max((ax - bi).abs());
            scale = scale.max(size);
        }
        worst / scale
    }

    #[test]
    fn a_large_net_is_factored_by_the_supernodal_lu() {
        // 60 × 60 nodes: the envelope's rows average 122 entries, the LU holds 0.52 of them.
        for (seed, shift) in [(1u64, 12.0), (2, -3.0)] {
            let a = net(60, shift, seed);
            let envelope = envelope_size(&a, &rcm(&a));
            let f = ShiftedFactor::new(&a).unwrap();
            assert!(
                matches!(f, ShiftedFactor::Supernodal { .. }),
                "seed {seed}: the envelope ({envelope} entries) was kept"
            );
            assert!(
                3 * f.entries() < 2 * envelope,
                "{} vs {envelope}",
                f.entries()
            );
            let err = residual(&a, &f, seed + 10);
            assert!(err <= 1e-12, "seed {seed}: {err:e}");
        }
    }

    #[test]
    fn a_small_net_keeps_its_envelope_and_solves_as_the_dense_lu() {
        for (seed, shift) in [(1u64, 12.0), (2, -3.0)] {
            let a = net(12, shift, seed);
            let f = ShiftedFactor::new(&a).unwrap();
            assert!(matches!(f, ShiftedFactor::Envelope(_)), "seed {seed}");
            let err = error_against_dense(&a, &f, seed + 10);
            assert!(err <= 1e-10, "seed {seed}: {err:e}");
        }
    }

    #[test]
    fn a_chain_keeps_its_envelope_of_band_one() {
        let n = 300;
        let mut t = Vec::new();
        for i in 0..n {
            t.push((i, i, 2.5));
            if i + 1 < n {
                t.push((i, i + 1, -1.0));
                t.push((i + 1, i, -1.0));
            }
        }
        let a = Csr::from_triplets(n, &t).unwrap();
        let f = ShiftedFactor::new(&a).unwrap();
        assert!(matches!(f, ShiftedFactor::Envelope(_)));
        assert_eq!(f.entries(), n - 1);
        assert!(error_against_dense(&a, &f, 5) <= 1e-12);
    }

    #[test]
    fn a_singular_net_is_the_envelopes_typed_error() {
        // One coordinate coupled to nothing, with a zero diagonal: a zero pivot in any order
        // (the LU rejects it, the envelope reports it).
        let mut a = net(10, 8.0, 3);
        let free = 151;
        for i in 0..a.n {
            for k in a.ptr[i]..a.ptr[i + 1] {
                if i == free || a.col[k] == free {
                    a.val[k] = 0.0;
                }
            }
        }
        assert!(matches!(
            ShiftedFactor::new(&a),
            Err(SparseError::SingularMatrix { .. })
        ));
    }
}
