//! The singular value decomposition of a tall matrix by one-sided Jacobi rotations
//! (Hestenes 1958; Demmel & Veselić 1992): plane rotations of pairs of columns of `A` until
//! every pair is orthogonal, accumulated in `V`, so that `A V = U Σ` with orthogonal columns
//! whose norms are the singular values. Accurate to high relative precision for the small
//! singular values, which is what the rank test and the standard errors of a fit need; the
//! cost, `O(m n²)` per sweep, is nothing beside the integrations for the few columns (free
//! parameters) of a fit's Jacobian.

/// `A = U Σ Vᵀ` of an `m × n` matrix, `m ≥ n`, without `U`: `AV` (its columns `σ_i u_i`).
#[derive(Clone, Debug)]
pub struct Svd {
    /// Rows `m` and columns `n`.
    pub m: usize,
    /// Columns.
    pub n: usize,
    /// Singular values, in the order of the columns of `v` (not sorted).
    pub sigma: Vec<f64>,
    /// `V`, row-major `n × n`: column `k` is the right singular vector of `sigma[k]`.
    pub v: Vec<f64>,
    /// `A V`, column-major `m × n`: column `k` is `σ_k u_k`.
    pub av: Vec<f64>,
}

impl Svd {
    /// The decomposition of `a`, given column-major (`a[j * m + i]` = `A_ij`).
    pub fn new(a: &[f64], m: usize, n: usize) -> Svd {
        let mut av = a.to_vec();
        let mut v = vec![0.0; n * n];
        for k in 0..n {
            v[k * n + k] = 1.0;
        }
        for _sweep in 0..60 {
            let mut rotated = false;
            for p in 0..n {
                for q in p + 1..n {
                    let (mut alpha, mut beta, mut gamma) = (0.0, 0.0, 0.0);
                    for i in 0..m {
                        let (x, y) = (av[p * m + i], av[q * m + i]);
                        alpha += x * x;
                        beta += y * y;
                        gamma += x * y;
                    }
                    if gamma == 0.0 || gamma.abs() <= f64::EPSILON * (alpha * beta).sqrt() {
                        continue;
                    }
                    rotated = true;
                    let zeta = (beta - alpha) / (2.0 * gamma);
                    let t = zeta.signum() / (zeta.abs() + (1.0 + zeta * zeta).sqrt());
                    let t = if zeta == 0.0 { 1.0 } else { t };
                    let c = 1.0 / (1.0 + t * t).sqrt();
                    let s = c * t;
                    for i in 0..m {
                        let (x, y) = (av[p * m + i], av[q * m + i]);
                        av[p * m + i] = c * x - s * y;
                        av[q * m + i] = s * x + c * y;
                    }
                    for i in 0..n {
                        let (x, y) = (v[i * n + p], v[i * n + q]);
                        v[i * n + p] = c * x - s * y;
                        v[i * n + q] = s * x + c * y;
                    }
                }
            }
            if !rotated {
                break;
            }
        }
        let sigma = (0..n)
            .map(|k| {
                av[k * m..(k + 1) * m]
                    .iter()
                    .map(|x| x * x)
                    .sum::<f64>()
                    .sqrt()
            })
            .collect();
        Svd { m, n, sigma, v, av }
    }

    /// The largest singular value.
    pub fn max(&self) -> f64 {
        self.sigma.iter().fold(0.0, |a: f64, &b| a.max(b))
    }

    /// `x = −V diag(1/(σ² + λ)) (AV)ᵀ r`: the minimiser of `|A x + r|² + λ |x|²` (for
    /// `λ = 0`, the minimum-norm least-squares solution, singular values below `cut`
    /// dropped).
    pub fn damped_solve(&self, r: &[f64], lambda: f64, cut: f64) -> Vec<f64> {
        let (m, n) = (self.m, self.n);
        let mut x = vec![0.0; n];
        for k in 0..n {
            let s = self.sigma[k];
            if s <= cut {
                continue;
            }
            let proj: f64 = self.av[k * m..(k + 1) * m]
                .iter()
                .zip(r)
                .map(|(a, b)| a * b)
                .sum();
            let c = proj / (s * s + lambda);
            for (i, xi) in x.iter_mut().enumerate() {
                *xi -= self.v[i * n + k] * c;
            }
        }
        x
    }

    /// `(AᵀA)⁺ = V diag(1/σ²) Vᵀ`, row-major, singular values below `cut` dropped.
    pub fn normal_inverse(&self, cut: f64) -> Vec<f64> {
        let n = self.n;
        let mut c = vec![0.0; n * n];
        for k in 0..n {
            let s = self.sigma[k];
            if s <= cut {
                continue;
            }
            for i in 0..n {
                for j in 0..n {
                    c[i * n + j] += self.v[i * n + k] * self.v[j * n + k] / (s * s);
                }
            }
        }
        c
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reconstructs_a_matrix_and_finds_known_singular_values() {
        // A = U diag(3, 2, 1e-9) Vᵀ with a Householder U and V.
        let (m, n) = (5, 3);
        let house = |u: &[f64], k: usize| -> Vec<f64> {
            let nn: f64 = u.iter().map(|x| x * x).sum();
            let mut h = vec![0.0; k * k];
            for i in 0..k {
                for j in 0..k {
                    h[i * k + j] = f64::from(u8::from(i == j)) - 2.0 * u[i] * u[j] / nn;
                }
            }
            h
        };
        let u = house(&[1.0, -2.0, 0.5, 3.0, 1.0], m);
        let v = house(&[2.0, 1.0, -1.0], n);
        let s = [3.0, 2.0, 1e-9];
        let mut a = vec![0.0; m * n];
        for i in 0..m {
            for j in 0..n {
                a[j * m + i] = (0..n).map(|k| u[i * m + k] * s[k] * v[j * n + k]).sum();
            }
        }
        let d = Svd::new(&a, m, n);
        let mut got = d.sigma.clone();
        got.sort_by(|a, b| b.total_cmp(a));
        assert!((got[0] - 3.0).abs() < 1e-14 && (got[1] - 2.0).abs() < 1e-14);
        assert!((got[2] - 1e-9).abs() < 1e-15, "{}", got[2]);
        // Least squares of a well-posed part: the damped solve with λ = 0 minimises |Ax + r|.
        let r = [1.0, 2.0, -1.0, 0.5, 0.25];
        let x = d.damped_solve(&r, 0.0, 1e-6);
        // The residual is orthogonal to the retained columns of A V.
        for k in 0..n {
            if d.sigma[k] > 1e-6 {
                let res: f64 = (0..m)
                    .map(|i| {
                        let ax: f64 = (0..n).map(|j| a[j * m + i] * x[j]).sum();
                        (ax + r[i]) * d.av[k * m + i]
                    })
                    .sum();
                assert!(res.abs() < 1e-12, "{res}");
            }
        }
    }
}
