//! Finite-difference Jacobians for the implicit methods, with the columns grouped by a
//! sparsity pattern when one is given ([`Sparsity`], SciPy's `jac_sparsity`).
//!
//! Forward differences with RADAU5's increments `δ_j = sqrt(u · max(1e-5, |y_j|))`,
//! `u = 1e-16`. Without a pattern every column is its own group: `n` evaluations of `f`, in
//! one batch ([`OdeSystem::rhs_batch`]: one call of a vectorized right-hand side). With a
//! pattern, columns that share no nonzero row are perturbed together (Curtis, Powell & Reid,
//! "On the estimation of sparse Jacobian matrices", J. Inst. Math. Appl. 13, 1974: the
//! grouping SciPy's `num_jac` uses), so a banded or block system costs as many evaluations as
//! it has groups, and entries outside the pattern are zero.

use crate::error::{invalid, OdeError};
use crate::problem::OdeSystem;
use crate::solution::Stats;

/// RADAU5's unit roundoff, which sets the increments.
const UROUND: f64 = 1e-16;

/// Which entries of `∂f/∂y` may be nonzero, and the columns that can be perturbed together.
#[derive(Debug, Clone, PartialEq)]
pub struct Sparsity {
    n: usize,
    /// `rows[j]`: the rows where column `j` may be nonzero, ascending.
    rows: Vec<Vec<usize>>,
    /// Groups of columns, no two of a group sharing a row.
    groups: Vec<Vec<usize>>,
}

impl Sparsity {
    /// The pattern of an `n × n` Jacobian from `nonzero(i, j)`: whether `∂f_i/∂y_j` may be
    /// nonzero. Columns are grouped greedily in order (a column joins the first group whose
    /// rows it does not meet).
    pub fn new(n: usize, nonzero: impl Fn(usize, usize) -> bool) -> Sparsity {
        let rows: Vec<Vec<usize>> = (0..n)
            .map(|j| (0..n).filter(|&i| nonzero(i, j)).collect())
            .collect();
        Sparsity::grouped(n, rows)
    }

    /// The pattern from the rows where each column may be nonzero (`rows[j]`, any order,
    /// repetitions allowed), in time and memory linear in the entries (a many-particle
    /// model's pattern, which [`Sparsity::new`]'s `n²` questions would take too long to
    /// ask). Columns are grouped as by [`Sparsity::new`].
    pub fn from_columns(n: usize, mut rows: Vec<Vec<usize>>) -> Result<Sparsity, OdeError> {
        if rows.len() != n {
            return Err(invalid(format!(
                "the sparsity pattern has {} columns, the system {n} components",
                rows.len()
            )));
        }
        for (j, r) in rows.iter_mut().enumerate() {
            r.sort_unstable();
            r.dedup();
            if let Some(&i) = r.last().filter(|&&i| i >= n) {
                return Err(invalid(format!(
                    "the sparsity pattern names row {i} in column {j}; rows are 0..{n}"
                )));
            }
        }
        Ok(Sparsity::grouped(n, rows))
    }

    /// Groups the columns greedily in order: column `j` joins the first group none of whose
    /// columns shares a row with it (Curtis, Powell & Reid's grouping).
    fn grouped(n: usize, rows: Vec<Vec<usize>>) -> Sparsity {
        // The columns of each row, to find a column's neighbours without scanning groups.
        let mut row_cols: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (j, r) in rows.iter().enumerate() {
            for &i in r {
                row_cols[i].push(j);
            }
        }
        let mut group_of = vec![usize::MAX; n];
        // `blocked[g] == j + 1`: group g has a column sharing a row with column j.
        let mut blocked: Vec<usize> = Vec::new();
        let mut groups: Vec<Vec<usize>> = Vec::new();
        for (j, r) in rows.iter().enumerate() {
            for &i in r {
                for &other in &row_cols[i] {
                    if other < j {
                        blocked[group_of[other]] = j + 1;
                    }
                }
            }
            let g = match blocked.iter().position(|&b| b != j + 1) {
                Some(g) => g,
                None => {
                    groups.push(Vec::new());
                    blocked.push(0);
                    groups.len() - 1
                }
            };
            groups[g].push(j);
            group_of[j] = g;
        }
        Sparsity { n, rows, groups }
    }

    /// Entries of the pattern.
    pub fn nnz(&self) -> usize {
        self.rows.iter().map(Vec::len).sum()
    }

    /// The rows where column `j` may be nonzero, ascending: the order of column `j`'s values
    /// in [`crate::OdeSystem::sparse_jacobian`] (columns one after the other).
    pub fn column(&self, j: usize) -> &[usize] {
        &self.rows[j]
    }

    /// A band: `∂f_i/∂y_j` may be nonzero when `i − lower ≤ j ≤ i + upper` (LSODA's `lband`,
    /// `uband`).
    pub fn banded(n: usize, lower: usize, upper: usize) -> Sparsity {
        Sparsity::new(n, |i, j| j + lower >= i && j <= i + upper)
    }

    /// The dimension.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// Evaluations of `f` one Jacobian costs: the number of groups.
    pub fn groups(&self) -> usize {
        self.groups.len()
    }
}

/// The increment of component `y_j`.
#[inline]
fn increment(yj: f64) -> f64 {
    (UROUND * 1e-5f64.max(yj.abs())).sqrt()
}

/// Workspace of the finite-difference Jacobian (allocated on first use).
#[derive(Default)]
pub(crate) struct FdJacobian {
    states: Vec<f64>,
    out: Vec<f64>,
}

impl FdJacobian {
    /// Writes `∂f/∂y` at `(t, y)` into `jac` (row-major), `f0 = f(t, y)`; counts the
    /// evaluations in `stats` (`fevals` and `jac_fevals`).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn eval<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        sparsity: Option<&Sparsity>,
        t: f64,
        y: &[f64],
        f0: &[f64],
        jac: &mut [f64],
        stats: &mut Stats,
    ) {
        let n = y.len();
        let Some(s) = sparsity else {
            if self.states.len() != n * n {
                self.states = vec![0.0; n * n];
                self.out = vec![0.0; n * n];
            }
            for i in 0..n {
                let row = &mut self.states[i * n..(i + 1) * n];
                row.copy_from_slice(y);
                row[i] = y[i] + increment(y[i]);
            }
            sys.rhs_batch(t, &self.states, &mut self.out);
            for i in 0..n {
                let delt = increment(y[i]);
                for j in 0..n {
                    jac[j * n + i] = (self.out[i * n + j] - f0[j]) / delt;
                }
            }
            stats.fevals += n;
            stats.jac_fevals += n;
            return;
        };
        self.perturb_groups(sys, s, t, y, stats);
        jac.fill(0.0);
        self.differences(s, y, f0, |i, j, _, d| jac[i * n + j] = d);
    }

    /// Writes `∂f/∂y` at `(t, y)` into `values`, the entries of `s` column after column (as
    /// [`OdeSystem::sparse_jacobian`] does), one evaluation of `f` per group of columns.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn eval_sparse<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        s: &Sparsity,
        t: f64,
        y: &[f64],
        f0: &[f64],
        values: &mut [f64],
        stats: &mut Stats,
    ) {
        let n = y.len();
        let mut start = vec![0usize; n + 1];
        for j in 0..n {
            start[j + 1] = start[j] + s.rows[j].len();
        }
        self.perturb_groups(sys, s, t, y, stats);
        self.differences(s, y, f0, |_, j, r, d| values[start[j] + r] = d);
    }

    /// Evaluates `f` at `y` with each group's columns perturbed together (one state per group,
    /// one batch), into `self.out`; counts the evaluations.
    fn perturb_groups<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        s: &Sparsity,
        t: f64,
        y: &[f64],
        stats: &mut Stats,
    ) {
        let n = y.len();
        let k = s.groups.len();
        if self.states.len() != k * n {
            self.states = vec![0.0; k * n];
            self.out = vec![0.0; k * n];
        }
        for (g, cols) in s.groups.iter().enumerate() {
            let row = &mut self.states[g * n..(g + 1) * n];
            row.copy_from_slice(y);
            for &j in cols {
                row[j] = y[j] + increment(y[j]);
            }
        }
        sys.rhs_batch(t, &self.states, &mut self.out);
        stats.fevals += k;
        stats.jac_fevals += k;
    }

    /// The difference quotient of every entry of the pattern from [`Self::perturb_groups`]'s
    /// evaluations: `put(i, j, r, ∂f_i/∂y_j)` with `r` the entry's place in column `j`.
    fn differences(
        &self,
        s: &Sparsity,
        y: &[f64],
        f0: &[f64],
        mut put: impl FnMut(usize, usize, usize, f64),
    ) {
        let n = y.len();
        for (g, cols) in s.groups.iter().enumerate() {
            let out = &self.out[g * n..(g + 1) * n];
            for &j in cols {
                let delt = increment(y[j]);
                for (r, &i) in s.rows[j].iter().enumerate() {
                    put(i, j, r, (out[i] - f0[i]) / delt);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tridiagonal_pattern_needs_three_groups_and_gives_the_dense_result() {
        let n = 10;
        let s = Sparsity::banded(n, 1, 1);
        assert_eq!(s.groups(), 3);
        // f_i = y_{i-1} − 2 y_i + y_{i+1}² (a tridiagonal Jacobian).
        let sys = crate::FnSystem::new(n, |_t, y: &[f64], f: &mut [f64]| {
            for i in 0..y.len() {
                let l = if i > 0 { y[i - 1] } else { 0.0 };
                let r = if i + 1 < y.len() { y[i + 1] } else { 0.0 };
                f[i] = l - 2.0 * y[i] + r * r;
            }
        });
        let y: Vec<f64> = (0..n).map(|i| 1.0 + i as f64).collect();
        let mut f0 = vec![0.0; n];
        sys.rhs(0.0, &y, &mut f0);
        let (mut dense, mut sparse) = (vec![0.0; n * n], vec![0.0; n * n]);
        let mut ws = FdJacobian::default();
        let mut stats = Stats::default();
        ws.eval(&sys, None, 0.0, &y, &f0, &mut dense, &mut stats);
        assert_eq!(stats.fevals, n);
        ws.eval(&sys, Some(&s), 0.0, &y, &f0, &mut sparse, &mut stats);
        assert_eq!(stats.fevals, n + 3);
        for i in 0..n {
            for j in 0..n {
                // The exact Jacobian: 1 below, −2 on, 2 y_{i+1} above the diagonal.
                let exact = match j as i64 - i as i64 {
                    -1 => 1.0,
                    0 => -2.0,
                    1 => 2.0 * y[j],
                    _ => 0.0,
                };
                assert!((sparse[i * n + j] - exact).abs() < 1e-6, "({i}, {j})");
                assert!((dense[i * n + j] - exact).abs() < 1e-6, "({i}, {j})");
            }
        }
    }
}
