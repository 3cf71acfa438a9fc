//! BDF's Jacobian and its iteration matrix `I − c·J` (`c = h/α`): dense, factored by
//! [`crate::linalg`], or sparse, factored by [`crate::sparse_lu`] when the Jacobian's pattern
//! is known ([`crate::LinearSolver`], the same rule as Radau5's; SciPy's `BDF` factors with
//! `splu` when given `jac_sparsity`). The integrator calls the same three operations either
//! way.

use super::iteration_pattern::{evaluate_jacobian, sparse_pattern, IterationPattern};
use crate::error::OdeError;
use crate::jacobian::{FdJacobian, Sparsity};
use crate::linalg::Lu;
use crate::options::Options;
use crate::problem::OdeSystem;
use crate::solution::Stats;
use crate::sparse_lu::SparseLu;
use std::sync::Arc;

pub(crate) enum BdfMatrix {
    Dense(Box<Dense>),
    Sparse(Box<Sparse>),
}

pub(crate) struct Dense {
    n: usize,
    /// Row-major `∂f_i/∂y_j`.
    jac: Vec<f64>,
    lu: Lu,
}

pub(crate) struct Sparse {
    sparsity: Arc<Sparsity>,
    /// `J`'s entries, column after column (the order of [`Sparsity::column`]).
    jac: Vec<f64>,
    /// The pattern of `I − c·J` (`J`'s and the diagonal), analysed once.
    pattern: IterationPattern,
    values: Vec<f64>,
    lu: SparseLu,
}

impl BdfMatrix {
    /// The dense or sparse form `opts` and the system ask for.
    pub(crate) fn new<S: OdeSystem + ?Sized>(
        sys: &S,
        opts: &Options,
        n: usize,
    ) -> Result<BdfMatrix, OdeError> {
        Ok(match sparse_pattern(sys, opts, n, false, "bdf")? {
            Some(sparsity) => {
                let pattern = IterationPattern::new(&sparsity, n)?;
                BdfMatrix::Sparse(Box::new(Sparse {
                    jac: vec![0.0; sparsity.nnz()],
                    values: vec![0.0; pattern.nnz],
                    lu: SparseLu::new(&pattern.symbolic),
                    sparsity,
                    pattern,
                }))
            }
            None => BdfMatrix::Dense(Box::new(Dense {
                n,
                jac: vec![0.0; n * n],
                lu: Lu::new(n),
            })),
        })
    }

    /// True for the sparse form.
    pub(crate) fn is_sparse(&self) -> bool {
        matches!(self, BdfMatrix::Sparse(_))
    }

    /// Evaluates `J` at `(t, y)`, `f0 = f(t, y)`: analytic when the system has it, else by
    /// finite differences (columns grouped by the pattern when there is one).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn jacobian<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        opts: &Options,
        fd: &mut FdJacobian,
        t: f64,
        y: &[f64],
        f0: &[f64],
        stats: &mut Stats,
    ) {
        match self {
            BdfMatrix::Dense(d) => {
                evaluate_jacobian(sys, opts, fd, None, t, y, f0, &mut d.jac, stats)
            }
            BdfMatrix::Sparse(s) => {
                let pattern = Some(&*s.sparsity);
                evaluate_jacobian(sys, opts, fd, pattern, t, y, f0, &mut s.jac, stats)
            }
        }
    }

    /// Factors `I − c·J`; `false` when it is singular.
    pub(crate) fn factor(&mut self, c: f64) -> bool {
        match self {
            BdfMatrix::Dense(d) => {
                let n = d.n;
                let a = d.lu.matrix_mut();
                for j in 0..n {
                    for i in 0..n {
                        let id = f64::from(u8::from(i == j));
                        a[i + j * n] = id - c * d.jac[i * n + j];
                    }
                }
                d.lu.factor().is_ok()
            }
            BdfMatrix::Sparse(s) => {
                s.values.fill(0.0);
                for (&p, &v) in s.pattern.e_of_jac.iter().zip(&s.jac) {
                    s.values[p] = -(c * v);
                }
                for &p in &s.pattern.diag {
                    s.values[p] += 1.0;
                }
                s.lu.factor(&s.pattern.symbolic, &s.values).is_ok()
            }
        }
    }

    /// Overwrites `b` with `(I − c·J)⁻¹ b` (after [`BdfMatrix::factor`]).
    pub(crate) fn solve_in_place(&mut self, b: &mut [f64]) {
        match self {
            BdfMatrix::Dense(d) => d.lu.solve_in_place(b),
            BdfMatrix::Sparse(s) => s.lu.solve_in_place(&s.pattern.symbolic, b),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::options::LinearSolver;

    /// `y_i' = Σ_j A_ij y_j` with `A` tridiagonal (and one far entry), its sparse Jacobian
    /// analytic: `A`, column by column.
    struct Tridiagonal {
        n: usize,
        sparsity: Arc<Sparsity>,
    }

    impl Tridiagonal {
        fn new(n: usize) -> Tridiagonal {
            let columns = (0..n)
                .map(|j| {
                    let mut rows: Vec<usize> = (j.saturating_sub(1)..(j + 2).min(n)).collect();
                    if j == 0 {
                        rows.push(n - 1);
                    }
                    rows
                })
                .collect();
            Tridiagonal {
                n,
                sparsity: Arc::new(Sparsity::from_columns(n, columns).unwrap()),
            }
        }

        fn entry(i: usize, j: usize) -> f64 {
            if i == j {
                -2.0 - 0.01 * i as f64
            } else {
                1.0 + 0.001 * (i + 3 * j) as f64
            }
        }
    }

    impl OdeSystem for Tridiagonal {
        fn dim(&self) -> usize {
            self.n
        }
        fn rhs(&self, _t: f64, y: &[f64], f: &mut [f64]) {
            f.fill(0.0);
            for j in 0..self.n {
                for &i in self.sparsity.column(j) {
                    f[i] += Tridiagonal::entry(i, j) * y[j];
                }
            }
        }
        fn jacobian_sparsity(&self) -> Option<Arc<Sparsity>> {
            Some(self.sparsity.clone())
        }
        fn has_sparse_jacobian(&self) -> bool {
            true
        }
        fn sparse_jacobian(&self, _t: f64, _y: &[f64], values: &mut [f64]) {
            let mut p = 0;
            for j in 0..self.n {
                for &i in self.sparsity.column(j) {
                    values[p] = Tridiagonal::entry(i, j);
                    p += 1;
                }
            }
        }
    }

    /// The sparse `I − c·J` solves what the matrix, multiplied out by hand, maps back to `b`.
    #[test]
    fn the_sparse_iteration_matrix_solves_i_minus_c_j() {
        let n = 250;
        let sys = Tridiagonal::new(n);
        let opts = Options {
            linear_solver: LinearSolver::Sparse,
            ..Options::default()
        };
        let mut m = BdfMatrix::new(&sys, &opts, n).unwrap();
        assert!(m.is_sparse());
        let y = vec![0.0; n];
        let mut stats = Stats::default();
        m.jacobian(
            &sys,
            &opts,
            &mut FdJacobian::default(),
            0.0,
            &y,
            &y,
            &mut stats,
        );
        let c = 0.37;
        assert!(m.factor(c));
        let b: Vec<f64> = (0..n).map(|i| libm::sin(i as f64 + 0.5)).collect();
        let mut x = b.clone();
        m.solve_in_place(&mut x);
        // (I − c·A) x, entry by entry from the definition of A.
        let mut back = x.clone();
        for j in 0..n {
            for &i in sys.sparsity.column(j) {
                back[i] -= c * Tridiagonal::entry(i, j) * x[j];
            }
        }
        let worst = back
            .iter()
            .zip(&b)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-13, "residual {worst:e}");
    }
}
