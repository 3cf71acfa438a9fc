//! Dense LU factorisation with partial pivoting, real and complex, allocation-free after
//! construction.
//!
//! Gaussian elimination with row interchanges (the algorithm of `DEC`/`SOL` and `DECC`/`SOLC`
//! in Hairer's decsol.f, after Moler 1972): for `k = 1 … n−1` choose the pivot row `m` with the
//! largest `|a_mk|` (`|Re| + |Im|` for complex), swap, store the negated multipliers
//! `−a_ik/a_kk` below the diagonal, update the trailing columns. Matrices are stored
//! column-major (`a[i + j n]`). A zero pivot gives [`SingularMatrix`] with its index.
//!
//! pdyn-ode keeps its own ~150 lines here rather than pulling in nalgebra or faer: the matrices
//! are small and dense, the factorisation is refreshed in place every few steps without
//! allocating, and following decsol.f operation by operation lets Radau5 reproduce RADAU5's
//! published statistics. The test compares against a naive solve on seeded random matrices.

/// A zero pivot was met at elimination step `pivot` (0-based).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SingularMatrix {
    /// Column where elimination found only zeros.
    pub pivot: usize,
}

/// Real LU factors (workspace reused across factorisations).
#[derive(Debug, Clone)]
pub struct Lu {
    n: usize,
    a: Vec<f64>,
    ip: Vec<usize>,
}

impl Lu {
    /// Workspace for `n × n` matrices.
    pub fn new(n: usize) -> Self {
        Lu {
            n,
            a: vec![0.0; n * n],
            ip: vec![0; n],
        }
    }

    /// The matrix to factorise, column-major; fill it, then call [`Lu::factor`].
    pub fn matrix_mut(&mut self) -> &mut [f64] {
        &mut self.a
    }

    /// Factorises the matrix in place.
    pub fn factor(&mut self) -> Result<(), SingularMatrix> {
        let n = self.n;
        let a = &mut self.a;
        for k in 0..n.saturating_sub(1) {
            let mut m = k;
            for i in k + 1..n {
                if a[i + k * n].abs() > a[m + k * n].abs() {
                    m = i;
                }
            }
            self.ip[k] = m;
            let mut t = a[m + k * n];
            if m != k {
                a[m + k * n] = a[k + k * n];
                a[k + k * n] = t;
            }
            if t == 0.0 {
                return Err(SingularMatrix { pivot: k });
            }
            t = 1.0 / t;
            for i in k + 1..n {
                a[i + k * n] = -a[i + k * n] * t;
            }
            for j in k + 1..n {
                a.swap(m + j * n, k + j * n);
                let t = a[k + j * n];
                if t != 0.0 {
                    for i in k + 1..n {
                        a[i + j * n] += a[i + k * n] * t;
                    }
                }
            }
        }
        if n > 0 && a[n * n - 1] == 0.0 {
            return Err(SingularMatrix { pivot: n - 1 });
        }
        Ok(())
    }

    /// Solves `A x = b` in place (`b` becomes `x`).
    pub fn solve_in_place(&self, b: &mut [f64]) {
        let n = self.n;
        let a = &self.a;
        if n == 0 {
            return;
        }
        for k in 0..n - 1 {
            let m = self.ip[k];
            b.swap(m, k);
            let t = b[k];
            for i in k + 1..n {
                b[i] += a[i + k * n] * t;
            }
        }
        for k in (1..n).rev() {
            b[k] /= a[k + k * n];
            let t = -b[k];
            for i in 0..k {
                b[i] += a[i + k * n] * t;
            }
        }
        b[0] /= a[0];
    }
}

/// Complex LU factors, real and imaginary parts stored apart.
#[derive(Debug, Clone)]
pub struct LuComplex {
    n: usize,
    ar: Vec<f64>,
    ai: Vec<f64>,
    ip: Vec<usize>,
}

impl LuComplex {
    /// Workspace for `n × n` matrices.
    pub fn new(n: usize) -> Self {
        LuComplex {
            n,
            ar: vec![0.0; n * n],
            ai: vec![0.0; n * n],
            ip: vec![0; n],
        }
    }

    /// Real and imaginary parts of the matrix to factorise (column-major).
    pub fn matrix_mut(&mut self) -> (&mut [f64], &mut [f64]) {
        (&mut self.ar, &mut self.ai)
    }

    /// Factorises in place.
    pub fn factor(&mut self) -> Result<(), SingularMatrix> {
        let n = self.n;
        let (ar, ai) = (&mut self.ar, &mut self.ai);
        for k in 0..n.saturating_sub(1) {
            let mut m = k;
            for i in k + 1..n {
                if ar[i + k * n].abs() + ai[i + k * n].abs()
                    > ar[m + k * n].abs() + ai[m + k * n].abs()
                {
                    m = i;
                }
            }
            self.ip[k] = m;
            let mut tr = ar[m + k * n];
            let mut ti = ai[m + k * n];
            if m != k {
                ar[m + k * n] = ar[k + k * n];
                ai[m + k * n] = ai[k + k * n];
                ar[k + k * n] = tr;
                ai[k + k * n] = ti;
            }
            if tr.abs() + ti.abs() == 0.0 {
                return Err(SingularMatrix { pivot: k });
            }
            let den = tr * tr + ti * ti;
            tr /= den;
            ti = -ti / den;
            for i in k + 1..n {
                let prodr = ar[i + k * n] * tr - ai[i + k * n] * ti;
                let prodi = ai[i + k * n] * tr + ar[i + k * n] * ti;
                ar[i + k * n] = -prodr;
                ai[i + k * n] = -prodi;
            }
            for j in k + 1..n {
                let tr = ar[m + j * n];
                let ti = ai[m + j * n];
                ar[m + j * n] = ar[k + j * n];
                ai[m + j * n] = ai[k + j * n];
                ar[k + j * n] = tr;
                ai[k + j * n] = ti;
                if tr.abs() + ti.abs() == 0.0 {
                    continue;
                }
                if ti == 0.0 {
                    for i in k + 1..n {
                        ar[i + j * n] += ar[i + k * n] * tr;
                        ai[i + j * n] += ai[i + k * n] * tr;
                    }
                } else if tr == 0.0 {
                    for i in k + 1..n {
                        ar[i + j * n] -= ai[i + k * n] * ti;
                        ai[i + j * n] += ar[i + k * n] * ti;
                    }
                } else {
                    for i in k + 1..n {
                        let prodr = ar[i + k * n] * tr - ai[i + k * n] * ti;
                        let prodi = ai[i + k * n] * tr + ar[i + k * n] * ti;
                        ar[i + j * n] += prodr;
                        ai[i + j * n] += prodi;
                    }
                }
            }
        }
        if n > 0 && ar[n * n - 1].abs() + ai[n * n - 1].abs() == 0.0 {
            return Err(SingularMatrix { pivot: n - 1 });
        }
        Ok(())
    }

    /// Solves `A x = b` in place for complex `b = br + i bi`.
    pub fn solve_in_place(&self, br: &mut [f64], bi: &mut [f64]) {
        let n = self.n;
        let (ar, ai) = (&self.ar, &self.ai);
        if n == 0 {
            return;
        }
        for k in 0..n - 1 {
            let m = self.ip[k];
            let tr = br[m];
            let ti = bi[m];
            br[m] = br[k];
            bi[m] = bi[k];
            br[k] = tr;
            bi[k] = ti;
            for i in k + 1..n {
                let prodr = ar[i + k * n] * tr - ai[i + k * n] * ti;
                let prodi = ai[i + k * n] * tr + ar[i + k * n] * ti;
                br[i] += prodr;
                bi[i] += prodi;
            }
        }
        for k in (0..n).rev() {
            let d = k + k * n;
            let den = ar[d] * ar[d] + ai[d] * ai[d];
            let prodr = br[k] * ar[d] + bi[k] * ai[d];
            let prodi = bi[k] * ar[d] - br[k] * ai[d];
            br[k] = prodr / den;
            bi[k] = prodi / den;
            let tr = -br[k];
            let ti = -bi[k];
            for i in 0..k {
                let prodr = ar[i + k * n] * tr - ai[i + k * n] * ti;
                let prodi = ai[i + k * n] * tr + ar[i + k * n] * ti;
                br[i] += prodr;
                bi[i] += prodi;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// xorshift64*: deterministic pseudo-random numbers in [-1, 1).
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            let v = self.0.wrapping_mul(0x2545F4914F6CDD1D);
            (v >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        }
    }

    #[test]
    fn real_lu_solves_random_systems() {
        let mut rng = Rng(0x9E3779B97F4A7C15);
        for n in 1..9 {
            let a: Vec<f64> = (0..n * n).map(|_| rng.next()).collect();
            let x: Vec<f64> = (0..n).map(|_| rng.next()).collect();
            // naive reference: b = A x
            let b: Vec<f64> = (0..n)
                .map(|i| (0..n).map(|j| a[i + j * n] * x[j]).sum())
                .collect();
            let mut lu = Lu::new(n);
            lu.matrix_mut().copy_from_slice(&a);
            lu.factor().unwrap();
            let mut s = b.clone();
            lu.solve_in_place(&mut s);
            for i in 0..n {
                assert!((s[i] - x[i]).abs() < 1e-9, "n={n}: {s:?} vs {x:?}");
            }
        }
    }

    #[test]
    fn complex_lu_solves_random_systems() {
        let mut rng = Rng(12345);
        for n in 1..9 {
            let ar: Vec<f64> = (0..n * n).map(|_| rng.next()).collect();
            let ai: Vec<f64> = (0..n * n).map(|_| rng.next()).collect();
            let xr: Vec<f64> = (0..n).map(|_| rng.next()).collect();
            let xi: Vec<f64> = (0..n).map(|_| rng.next()).collect();
            let mut br = vec![0.0; n];
            let mut bi = vec![0.0; n];
            for i in 0..n {
                for j in 0..n {
                    br[i] += ar[i + j * n] * xr[j] - ai[i + j * n] * xi[j];
                    bi[i] += ar[i + j * n] * xi[j] + ai[i + j * n] * xr[j];
                }
            }
            let mut lu = LuComplex::new(n);
            {
                let (mr, mi) = lu.matrix_mut();
                mr.copy_from_slice(&ar);
                mi.copy_from_slice(&ai);
            }
            lu.factor().unwrap();
            lu.solve_in_place(&mut br, &mut bi);
            for i in 0..n {
                assert!((br[i] - xr[i]).abs() < 1e-9 && (bi[i] - xi[i]).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn singular_matrix_reports_pivot() {
        let mut lu = Lu::new(2);
        lu.matrix_mut().copy_from_slice(&[1.0, 2.0, 2.0, 4.0]);
        assert_eq!(lu.factor(), Err(SingularMatrix { pivot: 1 }));
    }
}
