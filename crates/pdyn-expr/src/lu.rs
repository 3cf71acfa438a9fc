//! Dense LU factorisation with partial pivoting, in place and allocation-free, for the small
//! linear systems `A x = b` that equations of motion leave when they are not eliminated
//! symbolically (reactions, constraints). Solved once per right-hand-side evaluation, so the
//! caller owns every buffer.
//!
//! Doolittle elimination `P A = L U` (Golub & Van Loan, *Matrix Computations*, alg. 3.4.1).

/// `A` was singular (or nearly): no pivot larger than `tolerance * max|A|` in column `pivot`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SingularMatrix {
    /// Column (0-based) where elimination found no usable pivot.
    pub pivot: usize,
}

impl std::fmt::Display for SingularMatrix {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "singular matrix (no pivot in column {})", self.pivot)
    }
}

impl std::error::Error for SingularMatrix {}

/// Factorises the row-major `n×n` matrix `a` in place into `L U` (unit lower `L`), recording
/// row swaps in `perm` (length `n`).
pub fn lu_factor_in_place(
    a: &mut [f64],
    n: usize,
    perm: &mut [usize],
) -> Result<(), SingularMatrix> {
    debug_assert_eq!(a.len(), n * n);
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let tiny = scale * 1e-14;
    for (i, p) in perm.iter_mut().enumerate().take(n) {
        *p = i;
    }
    for k in 0..n {
        let mut piv = k;
        let mut best = a[k * n + k].abs();
        for i in k + 1..n {
            let v = a[i * n + k].abs();
            if v > best {
                best = v;
                piv = i;
            }
        }
        if best.is_nan() || best <= tiny {
            return Err(SingularMatrix { pivot: k });
        }
        if piv != k {
            for j in 0..n {
                a.swap(k * n + j, piv * n + j);
            }
            perm.swap(k, piv);
        }
        let inv = 1.0 / a[k * n + k];
        for i in k + 1..n {
            let l = a[i * n + k] * inv;
            a[i * n + k] = l;
            if l != 0.0 {
                for j in k + 1..n {
                    a[i * n + j] -= l * a[k * n + j];
                }
            }
        }
    }
    Ok(())
}

/// Solves `A x = b` given the factors from [`lu_factor_in_place`]; `b` is overwritten by `x`.
/// `work` must have length `n`.
pub fn lu_solve_in_place(lu: &[f64], n: usize, perm: &[usize], b: &mut [f64], work: &mut [f64]) {
    for i in 0..n {
        work[i] = b[perm[i]];
    }
    for i in 0..n {
        let mut s = work[i];
        for j in 0..i {
            s -= lu[i * n + j] * work[j];
        }
        work[i] = s;
    }
    for i in (0..n).rev() {
        let mut s = work[i];
        for j in i + 1..n {
            s -= lu[i * n + j] * work[j];
        }
        work[i] = s / lu[i * n + i];
    }
    b[..n].copy_from_slice(&work[..n]);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_random_systems_against_residual() {
        // Deterministic pseudo-random matrices; check the residual of the solution.
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for n in 1..8 {
            let a: Vec<f64> = (0..n * n).map(|_| rnd()).collect();
            let b: Vec<f64> = (0..n).map(|_| rnd()).collect();
            let mut lu = a.clone();
            let mut perm = vec![0; n];
            lu_factor_in_place(&mut lu, n, &mut perm).unwrap();
            let mut x = b.clone();
            let mut w = vec![0.0; n];
            lu_solve_in_place(&lu, n, &perm, &mut x, &mut w);
            for i in 0..n {
                let r: f64 = (0..n).map(|j| a[i * n + j] * x[j]).sum::<f64>() - b[i];
                assert!(r.abs() < 1e-10, "n={n} residual {r}");
            }
        }
    }

    #[test]
    fn singular_is_reported() {
        let mut a = vec![1.0, 2.0, 2.0, 4.0];
        let mut perm = vec![0; 2];
        assert_eq!(
            lu_factor_in_place(&mut a, 2, &mut perm),
            Err(SingularMatrix { pivot: 1 })
        );
    }
}
