//! Banded symmetric solvers: the smoothing spline's pentadiagonal system and the interpolating
//! spline's tridiagonal one, both O(n).

/// A symmetric positive definite pentadiagonal matrix `M` factored as `L D Lᵀ` (`L` unit lower
/// triangular with two sub-diagonals), with the band of `M⁻¹` on demand. The reference
/// implementation that the smoothing spline's fused one-pass version
/// (`spline::Setup::score`) is tested against.
#[cfg(test)]
pub(crate) struct Penta {
    d: Vec<f64>,
    l1: Vec<f64>,
    l2: Vec<f64>,
}

#[cfg(test)]
impl Penta {
    /// Factors `M` given by its diagonal `m0`, first super-diagonal `m1` (`m1[j] = M[j][j+1]`)
    /// and second `m2`. `None` when a pivot is not positive (the matrix is singular to
    /// working precision: the caller treats that smoothing parameter as unusable).
    pub(crate) fn factor(m0: &[f64], m1: &[f64], m2: &[f64]) -> Option<Penta> {
        let n = m0.len();
        let mut d = vec![0.0; n];
        let mut l1 = vec![0.0; n];
        let mut l2 = vec![0.0; n];
        for j in 0..n {
            let mut dj = m0[j];
            if j >= 1 {
                dj -= l1[j - 1] * l1[j - 1] * d[j - 1];
            }
            if j >= 2 {
                dj -= l2[j - 2] * l2[j - 2] * d[j - 2];
            }
            if !(dj > 0.0) || !dj.is_finite() {
                return None;
            }
            d[j] = dj;
            if j + 1 < n {
                let mut a = m1[j];
                if j >= 1 {
                    a -= l2[j - 1] * d[j - 1] * l1[j - 1];
                }
                l1[j] = a / dj;
            }
            if j + 2 < n {
                l2[j] = m2[j] / dj;
            }
        }
        Some(Penta { d, l1, l2 })
    }

    /// Solves `M x = b` in place.
    pub(crate) fn solve(&self, b: &mut [f64]) {
        let n = b.len();
        for j in 0..n {
            let mut z = b[j];
            if j >= 1 {
                z -= self.l1[j - 1] * b[j - 1];
            }
            if j >= 2 {
                z -= self.l2[j - 2] * b[j - 2];
            }
            b[j] = z;
        }
        for j in 0..n {
            b[j] /= self.d[j];
        }
        for j in (0..n).rev() {
            let mut x = b[j];
            if j + 1 < n {
                x -= self.l1[j] * b[j + 1];
            }
            if j + 2 < n {
                x -= self.l2[j] * b[j + 2];
            }
            b[j] = x;
        }
    }

    /// The band of `M⁻¹` (diagonal, first and second super-diagonals) by the Hutchinson–de Hoog
    /// recursion `Σ = D⁻¹ L⁻¹ + (I − Lᵀ) Σ`, run backwards: O(n), no full inverse.
    pub(crate) fn inverse_band(&self) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let n = self.d.len();
        let mut s0 = vec![0.0; n];
        let mut s1 = vec![0.0; n];
        let mut s2 = vec![0.0; n];
        for j in (0..n).rev() {
            let (a, b) = (self.l1[j], self.l2[j]);
            let s11 = if j + 1 < n { s0[j + 1] } else { 0.0 };
            let s22 = if j + 2 < n { s0[j + 2] } else { 0.0 };
            let s12 = if j + 1 < n { s1[j + 1] } else { 0.0 };
            // Σ[j][j+2] = −l1 Σ[j+1][j+2] − l2 Σ[j+2][j+2]
            if j + 2 < n {
                s2[j] = -a * s12 - b * s22;
            }
            // Σ[j][j+1] = −l1 Σ[j+1][j+1] − l2 Σ[j+2][j+1]
            if j + 1 < n {
                s1[j] = -a * s11 - b * s12;
            }
            s0[j] = 1.0 / self.d[j] - a * s1[j] - b * s2[j];
        }
        (s0, s1, s2)
    }
}

/// Solves a symmetric tridiagonal system (diagonal `d`, off-diagonal `e`, `e[j] = A[j][j+1]`)
/// in place by Thomas' algorithm; `None` on a zero pivot.
pub(crate) fn solve_tridiagonal(d: &[f64], e: &[f64], b: &mut [f64]) -> Option<()> {
    let n = d.len();
    let mut c = vec![0.0; n];
    let mut piv = d.first().copied()?;
    if piv == 0.0 {
        return None;
    }
    b[0] /= piv;
    for j in 1..n {
        c[j - 1] = e[j - 1] / piv;
        piv = d[j] - e[j - 1] * c[j - 1];
        if piv == 0.0 || !piv.is_finite() {
            return None;
        }
        b[j] = (b[j] - e[j - 1] * b[j - 1]) / piv;
    }
    for j in (0..n.saturating_sub(1)).rev() {
        b[j] -= c[j] * b[j + 1];
    }
    Some(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The band of the inverse against a dense Gauss–Jordan inverse of a random SPD
    /// pentadiagonal matrix.
    #[test]
    fn inverse_band_matches_dense_inverse() {
        let n = 9;
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let m1: Vec<f64> = (0..n).map(|_| rnd()).collect();
        let m2: Vec<f64> = (0..n).map(|_| rnd()).collect();
        let m0: Vec<f64> = (0..n).map(|_| 3.0 + rnd()).collect();
        let mut a = vec![vec![0.0; n]; n];
        for j in 0..n {
            a[j][j] = m0[j];
            if j + 1 < n {
                a[j][j + 1] = m1[j];
                a[j + 1][j] = m1[j];
            }
            if j + 2 < n {
                a[j][j + 2] = m2[j];
                a[j + 2][j] = m2[j];
            }
        }
        // Dense inverse.
        let mut aug: Vec<Vec<f64>> = (0..n)
            .map(|i| {
                let mut r = a[i].clone();
                r.extend((0..n).map(|k| if k == i { 1.0 } else { 0.0 }));
                r
            })
            .collect();
        for c in 0..n {
            let p = aug[c][c];
            for k in 0..2 * n {
                aug[c][k] /= p;
            }
            for r in 0..n {
                if r != c {
                    let f = aug[r][c];
                    for k in 0..2 * n {
                        aug[r][k] -= f * aug[c][k];
                    }
                }
            }
        }
        let f = Penta::factor(&m0, &m1, &m2).expect("SPD");
        let (s0, s1, s2) = f.inverse_band();
        for j in 0..n {
            assert!((s0[j] - aug[j][n + j]).abs() < 1e-12);
            if j + 1 < n {
                assert!((s1[j] - aug[j][n + j + 1]).abs() < 1e-12);
            }
            if j + 2 < n {
                assert!((s2[j] - aug[j][n + j + 2]).abs() < 1e-12);
            }
        }
        // And the solve.
        let mut b: Vec<f64> = (0..n).map(|i| i as f64 - 2.0).collect();
        let b0 = b.clone();
        f.solve(&mut b);
        for i in 0..n {
            let r: f64 = (0..n).map(|k| a[i][k] * b[k]).sum();
            assert!((r - b0[i]).abs() < 1e-12);
        }
    }
}
