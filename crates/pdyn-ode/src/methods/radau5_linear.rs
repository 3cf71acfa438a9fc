//! Radau5's Jacobian and its two iteration matrices, `E1 = γ/h · M − J` (real) and
//! `E2 = (α + iβ)/h · M − J` (complex): dense, factored by [`crate::linalg`] (radau5.f's
//! DECSOL), or sparse, factored by [`crate::sparse_lu`] when the Jacobian's pattern is known
//! ([`crate::LinearSolver`]). The integrator calls the same four operations either way.

use super::iteration_pattern::{evaluate_jacobian, sparse_pattern, IterationPattern};
use crate::error::OdeError;
use crate::jacobian::{FdJacobian, Sparsity};
use crate::linalg::{Lu, LuComplex};
use crate::options::Options;
use crate::problem::OdeSystem;
use crate::solution::Stats;
use crate::sparse_lu::{SparseLu, SparseLuComplex};
use std::sync::Arc;

pub(crate) enum Systems {
    Dense(Box<Dense>),
    Sparse(Box<Sparse>),
}

pub(crate) struct Dense {
    n: usize,
    /// Row-major `∂f_i/∂y_j`.
    fjac: Vec<f64>,
    /// Row-major constant mass matrix, `None` for the identity.
    mass: Option<Vec<f64>>,
    e1: Lu,
    e2: LuComplex,
}

pub(crate) struct Sparse {
    sparsity: Arc<Sparsity>,
    /// `J`'s entries, column after column (the order of [`Sparsity::column`]).
    jac: Vec<f64>,
    /// The pattern of `E = c·I − J` (`J`'s and the diagonal), analysed once.
    pattern: IterationPattern,
    /// `E1`'s values, then `E2`'s real part.
    values: Vec<f64>,
    e1: SparseLu,
    e2: SparseLuComplex,
}

impl Systems {
    /// The dense or sparse form `opts` and the system ask for; `mass` is the constant mass
    /// matrix (row-major), `None` for the identity.
    pub(crate) fn new<S: OdeSystem + ?Sized>(
        sys: &S,
        opts: &Options,
        n: usize,
        mass: Option<Vec<f64>>,
    ) -> Result<Systems, OdeError> {
        let sparse = sparse_pattern(sys, opts, n, mass.is_some(), "radau5")?;
        match sparse {
            Some(s) => Ok(Systems::Sparse(Box::new(Sparse::new(s, n)?))),
            None => Ok(Systems::Dense(Box::new(Dense {
                n,
                fjac: vec![0.0; n * n],
                mass,
                e1: Lu::new(n),
                e2: LuComplex::new(n),
            }))),
        }
    }

    /// True for the sparse form.
    pub(crate) fn is_sparse(&self) -> bool {
        matches!(self, Systems::Sparse(_))
    }

    /// The constant mass matrix, row-major (`None`: the identity).
    pub(crate) fn mass(&self) -> Option<&[f64]> {
        match self {
            Systems::Dense(d) => d.mass.as_deref(),
            Systems::Sparse(_) => None,
        }
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
            Systems::Dense(d) => {
                evaluate_jacobian(sys, opts, fd, None, t, y, f0, &mut d.fjac, stats)
            }
            Systems::Sparse(s) => {
                let pattern = Some(&*s.sparsity);
                evaluate_jacobian(sys, opts, fd, pattern, t, y, f0, &mut s.jac, stats)
            }
        }
    }

    /// Factors `E1 = fac1 · M − J` and `E2 = (alphn + i·betan) · M − J`; `false` when either
    /// is singular.
    pub(crate) fn decompose(&mut self, fac1: f64, alphn: f64, betan: f64) -> bool {
        match self {
            Systems::Dense(d) => {
                let n = d.n;
                let m = |i: usize, j: usize| match &d.mass {
                    None => f64::from(u8::from(i == j)),
                    Some(m) => m[i * n + j],
                };
                let a = d.e1.matrix_mut();
                for j in 0..n {
                    for i in 0..n {
                        a[i + j * n] = fac1 * m(i, j) - d.fjac[i * n + j];
                    }
                }
                if d.e1.factor().is_err() {
                    return false;
                }
                let (ar, ai) = d.e2.matrix_mut();
                for j in 0..n {
                    for i in 0..n {
                        ar[i + j * n] = alphn * m(i, j) - d.fjac[i * n + j];
                        ai[i + j * n] = betan * m(i, j);
                    }
                }
                d.e2.factor().is_ok()
            }
            Systems::Sparse(s) => {
                s.fill(fac1);
                if s.e1.factor(&s.pattern.symbolic, &s.values).is_err() {
                    return false;
                }
                s.fill(alphn);
                let on_diagonal = &s.pattern.on_diagonal;
                s.e2.factor(&s.pattern.symbolic, &s.values, |p| {
                    if on_diagonal[p] {
                        betan
                    } else {
                        0.0
                    }
                })
                .is_ok()
            }
        }
    }

    /// Overwrites `b` with `E1⁻¹ b`.
    pub(crate) fn solve1(&mut self, b: &mut [f64]) {
        match self {
            Systems::Dense(d) => d.e1.solve_in_place(b),
            Systems::Sparse(s) => s.e1.solve_in_place(&s.pattern.symbolic, b),
        }
    }

    /// Overwrites `(br, bi)` with `E2⁻¹ (br + i·bi)`.
    pub(crate) fn solve2(&mut self, br: &mut [f64], bi: &mut [f64]) {
        match self {
            Systems::Dense(d) => d.e2.solve_in_place(br, bi),
            Systems::Sparse(s) => s.e2.solve_in_place(&s.pattern.symbolic, br, bi),
        }
    }
}

impl Sparse {
    fn new(sparsity: Arc<Sparsity>, n: usize) -> Result<Sparse, OdeError> {
        let pattern = IterationPattern::new(&sparsity, n)?;
        let e1 = SparseLu::new(&pattern.symbolic);
        let e2 = SparseLuComplex::new(&pattern.symbolic);
        Ok(Sparse {
            jac: vec![0.0; sparsity.nnz()],
            values: vec![0.0; pattern.nnz],
            sparsity,
            pattern,
            e1,
            e2,
        })
    }

    /// `values = c·I − J`.
    fn fill(&mut self, c: f64) {
        self.values.fill(0.0);
        for (&p, &v) in self.pattern.e_of_jac.iter().zip(&self.jac) {
            self.values[p] = -v;
        }
        for &p in &self.pattern.diag {
            self.values[p] += c;
        }
    }
}
