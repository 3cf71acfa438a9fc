//! The sparse form shared by the implicit methods: whether to factor sparsely, the pattern of
//! an iteration matrix `c·I − J` (Radau5) or `I − c·J` (BDF) — `J`'s entries and the whole
//! diagonal — analysed once for every factorization of the run, and `J` evaluated dense or
//! on that pattern.

use crate::error::{invalid, OdeError};
use crate::jacobian::{FdJacobian, Sparsity};
use crate::options::{LinearSolver, Options};
use crate::problem::{MassKind, OdeSystem};
use crate::solution::Stats;
use crate::sparse_lu::{Pattern, Symbolic};
use std::sync::Arc;

/// From this many components `LinearSolver::Auto` factors sparsely when the pattern is
/// known: below, a dense LU (`n³/3` operations) costs next to nothing.
pub const SPARSE_FROM: usize = 200;

/// The Jacobian's pattern when `method` is to factor its iteration matrices sparsely (as
/// `opts.linear_solver` asks and the system allows), `None` for dense; an error when sparse
/// is asked for and impossible, or the pattern does not fit the system. `mass` says whether
/// the method carries a constant mass matrix other than the identity.
pub(crate) fn sparse_pattern<S: OdeSystem + ?Sized>(
    sys: &S,
    opts: &Options,
    n: usize,
    mass: bool,
    method: &str,
) -> Result<Option<Arc<Sparsity>>, OdeError> {
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
            if mass || sys.mass_kind() != MassKind::Identity {
                return Err(invalid(format!(
                    "the sparse linear solver of {method} takes the identity mass matrix only"
                )));
            }
            if analytic_dense_only {
                return Err(invalid(
                    "the sparse linear solver needs a sparse analytic Jacobian \
                     (OdeSystem::sparse_jacobian) or none (finite differences)",
                ));
            }
            true
        }
        LinearSolver::Auto => !mass && n >= SPARSE_FROM && !analytic_dense_only,
    };
    Ok(sparsity.filter(|_| sparse))
}

/// Evaluates `J` at `(t, y)`, `f0 = f(t, y)`, into `jac`: analytic when the system has it,
/// else by finite differences. Dense (`sparse` `None`: row-major `n × n`, the differences
/// grouped by [`Options::jac_sparsity`] when given) or on the pattern `sparse` (its entries
/// column after column, the differences grouped by it).
#[allow(clippy::too_many_arguments)]
pub(crate) fn evaluate_jacobian<S: OdeSystem + ?Sized>(
    sys: &S,
    opts: &Options,
    fd: &mut FdJacobian,
    sparse: Option<&Sparsity>,
    t: f64,
    y: &[f64],
    f0: &[f64],
    jac: &mut [f64],
    stats: &mut Stats,
) {
    match sparse {
        None if sys.has_jacobian() => sys.jacobian(t, y, jac),
        // The n perturbed states (or one per group of columns of `jac_sparsity`), evaluated
        // in one batch (one call of a vectorized right-hand side).
        None => fd.eval(sys, opts.jac_sparsity.as_deref(), t, y, f0, jac, stats),
        Some(_) if sys.has_sparse_jacobian() => sys.sparse_jacobian(t, y, jac),
        Some(pattern) => fd.eval_sparse(sys, pattern, t, y, f0, jac, stats),
    }
}

/// The pattern of `J` plus the diagonal, analysed for the sparse LU, and where `J`'s entries
/// and the diagonal land in it.
pub(crate) struct IterationPattern {
    pub(crate) symbolic: Symbolic,
    /// For each entry of `J` (column after column, the order of [`Sparsity::column`]), the
    /// index of its value in the iteration matrix's entries.
    pub(crate) e_of_jac: Vec<usize>,
    /// For each row `i`, the index of the entry `(i, i)`.
    pub(crate) diag: Vec<usize>,
    /// Whether each entry is on the diagonal.
    pub(crate) on_diagonal: Vec<bool>,
    /// Number of entries.
    pub(crate) nnz: usize,
}

impl IterationPattern {
    /// The pattern of `c·I − J` for `J`'s `sparsity` (`n × n`).
    pub(crate) fn new(sparsity: &Sparsity, n: usize) -> Result<IterationPattern, OdeError> {
        // The pattern in rows: J's entries (given by columns) and the diagonal.
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
        let nnz = pattern.nnz();
        let symbolic = Symbolic::new(&pattern).map_err(|e| invalid(e.to_string()))?;
        Ok(IterationPattern {
            symbolic,
            e_of_jac,
            diag,
            on_diagonal,
            nnz,
        })
    }
}
