//! Radau5's Jacobian and its two iteration matrices, `E1 = γ/h · M − J` (real) and
//! `E2 = (α + iβ)/h · M − J` (complex): dense, factored by [`crate::linalg`] (radau5.f's
//! DECSOL), or sparse, factored by [`crate::sparse_lu`] when the Jacobian's pattern is known
//! ([`crate::LinearSolver`]). The integrator calls the same four operations either way.

use crate::error::{invalid, OdeError};
use crate::jacobian::{FdJacobian, Sparsity};
use crate::linalg::{Lu, LuComplex};
use crate::options::{LinearSolver, Options};
use crate::problem::{MassKind, OdeSystem};
use crate::solution::Stats;
use crate::sparse_lu::{Pattern, SparseLu, SparseLuComplex, Symbolic};
use std::sync::Arc;

/// From this many components `LinearSolver::Auto` factors sparsely when the pattern is
/// known: below, a dense LU (`n³/3` operations) costs next to nothing.
pub const SPARSE_FROM: usize = 200;

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
    symbolic: Symbolic,
    /// For each entry of `J`, the index of its value in `E`'s pattern.
    e_of_jac: Vec<usize>,
    /// For each row `i`, the index of `E(i, i)`.
    diag: Vec<usize>,
    /// Whether each entry of `E` is on its diagonal.
    on_diagonal: Vec<bool>,
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
        let sparsity = opts
            .jac_sparsity
            .clone()
            .or_else(|| sys.jacobian_sparsity());
        if let Some(s) = &sparsity {
            if s.dim() != n {
                return Err(invalid(format!(
                    "the Jacobian's sparsity pattern is {0} × {0}, the system has {n} components",
                    s.dim()
                )));
            }
        }
        // An analytic Jacobian given only dense is evaluated dense.
        let analytic_dense_only = sys.has_jacobian() && !sys.has_sparse_jacobian();
        let sparse = match opts.linear_solver {
            LinearSolver::Dense => false,
            LinearSolver::Sparse => {
                if sparsity.is_none() {
                    return Err(invalid(
                        "linear_solver = sparse needs the Jacobian's pattern (jac_sparsity)",
                    ));
                }
                if mass.is_some() || sys.mass_kind() != MassKind::Identity {
                    return Err(invalid(
                        "the sparse linear solver of radau5 takes the identity mass matrix only",
                    ));
                }
                if analytic_dense_only {
                    return Err(invalid(
                        "the sparse linear solver needs a sparse analytic Jacobian \
                         (OdeSystem::sparse_jacobian) or none (finite differences)",
                    ));
                }
                true
            }
            LinearSolver::Auto => {
                sparsity.is_some() && mass.is_none() && n >= SPARSE_FROM && !analytic_dense_only
            }
        };
        match sparsity.filter(|_| sparse) {
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
                if sys.has_jacobian() {
                    sys.jacobian(t, y, &mut d.fjac);
                } else {
                    // The n perturbed states (or one per group of columns of
                    // `jac_sparsity`), evaluated in one batch (one call of a vectorized
                    // right-hand side).
                    fd.eval(
                        sys,
                        opts.jac_sparsity.as_deref(),
                        t,
                        y,
                        f0,
                        &mut d.fjac,
                        stats,
                    );
                }
            }
            Systems::Sparse(s) => {
                if sys.has_sparse_jacobian() {
                    sys.sparse_jacobian(t, y, &mut s.jac);
                } else {
                    fd.eval_sparse(sys, &s.sparsity, t, y, f0, &mut s.jac, stats);
                }
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
                if s.e1.factor(&s.symbolic, &s.values).is_err() {
                    return false;
                }
                s.fill(alphn);
                let on_diagonal = &s.on_diagonal;
                s.e2.factor(&s.symbolic, &s.values, |p| {
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
            Systems::Sparse(s) => s.e1.solve_in_place(&s.symbolic, b),
        }
    }

    /// Overwrites `(br, bi)` with `E2⁻¹ (br + i·bi)`.
    pub(crate) fn solve2(&mut self, br: &mut [f64], bi: &mut [f64]) {
        match self {
            Systems::Dense(d) => d.e2.solve_in_place(br, bi),
            Systems::Sparse(s) => s.e2.solve_in_place(&s.symbolic, br, bi),
        }
    }
}

impl Sparse {
    fn new(sparsity: Arc<Sparsity>, n: usize) -> Result<Sparse, OdeError> {
        // E's pattern in rows: J's entries (given by columns) and the diagonal.
        let mut row_count = vec![1usize; n];
        for j in 0..n {
            for &i in sparsity.column(j) {
                if i != j {
                    row_count[i] += 1;
                }
            }
        }
        let mut start = vec![0usize; n + 1];
        for i in 0..n {
            start[i + 1] = start[i] + row_count[i];
        }
        let mut cols = vec![0usize; start[n]];
        let mut fill = start.clone();
        let mut diag = vec![0usize; n];
        // Column by column, so that each row's entries come out in ascending column order
        // with the diagonal in its place.
        let mut e_of_jac = Vec::with_capacity(sparsity.nnz());
        for j in 0..n {
            let mut diag_done = false;
            for &i in sparsity.column(j) {
                if i == j {
                    diag[j] = fill[i];
                    diag_done = true;
                }
                cols[fill[i]] = j;
                e_of_jac.push(fill[i]);
                fill[i] += 1;
            }
            if !diag_done {
                diag[j] = fill[j];
                cols[fill[j]] = j;
                fill[j] += 1;
            }
        }
        let mut on_diagonal = vec![false; start[n]];
        for &p in &diag {
            on_diagonal[p] = true;
        }
        let pattern = Pattern { start, cols };
        let symbolic = Symbolic::new(&pattern).map_err(|e| invalid(e.to_string()))?;
        let e1 = SparseLu::new(&symbolic);
        let e2 = SparseLuComplex::new(&symbolic);
        Ok(Sparse {
            jac: vec![0.0; sparsity.nnz()],
            values: vec![0.0; pattern.nnz()],
            sparsity,
            symbolic,
            e_of_jac,
            diag,
            on_diagonal,
            e1,
            e2,
        })
    }

    /// `values = c·I − J`.
    fn fill(&mut self, c: f64) {
        self.values.fill(0.0);
        for (&p, &v) in self.e_of_jac.iter().zip(&self.jac) {
            self.values[p] = -v;
        }
        for &p in &self.diag {
            self.values[p] += c;
        }
    }
}
