//! Linear equations in chosen unknowns: extraction of `A x = b`, and exact solution.
//!
//! Equations of motion are linear in the accelerations and the reaction magnitudes. Given the
//! equations (each `lhs - rhs`, meaning `= 0`) and the unknowns (leaves such as `x''` or `N`),
//! [`Pool::linear_system`] returns `A = ∂eq/∂x` and `b = -eq|_{x=0}`, checking linearity.
//! [`Pool::solve_linear`] solves small systems exactly: the entries become polynomials over
//! a shared atom table, Bareiss' fraction-free elimination (Bareiss, *Math. Comp.* 22, 1968)
//! gives `x_i = y_i / det(A)` with polynomial `y_i`, and each quotient is simplified (which
//! applies the Pythagorean identity and cancels common factors). Larger systems are compiled
//! and solved numerically at evaluation time (see [`crate::compile::CompiledLinearSystem`]).

use crate::poly::{gcd, Poly};
use crate::pool::{Id, Pool};
use crate::simplify::RationalForm;
use rustc_hash::FxHashMap;

/// `A x = b` with symbolic entries; `a` is row-major, `equations × unknowns`.
#[derive(Clone, Debug)]
pub struct LinearSystem {
    /// The unknowns, in column order.
    pub unknowns: Vec<Id>,
    /// Coefficients, row-major.
    pub a: Vec<Id>,
    /// Right-hand sides.
    pub b: Vec<Id>,
}

impl LinearSystem {
    /// Number of equations.
    pub fn rows(&self) -> usize {
        self.b.len()
    }
    /// Number of unknowns.
    pub fn cols(&self) -> usize {
        self.unknowns.len()
    }
    /// Coefficient of unknown `j` in equation `i`.
    pub fn coeff(&self, i: usize, j: usize) -> Id {
        self.a[i * self.cols() + j]
    }
}

/// Why a linear system could not be formed or solved.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum LinearError {
    /// Equation `equation` is not linear in `unknown` (its coefficient involves an unknown).
    NotLinear {
        /// Index of the equation.
        equation: usize,
        /// The unknown whose coefficient is not constant.
        unknown: Id,
    },
    /// Fewer independent equations than unknowns: no equation determines these unknowns.
    Underdetermined {
        /// Unknowns left without a pivot.
        free: Vec<Id>,
    },
    /// More independent equations than unknowns, and they contradict each other.
    Inconsistent {
        /// Index of an equation that the others' solution violates.
        equation: usize,
    },
    /// The exact solution exceeded the work budget; solve numerically instead.
    TooLarge,
}

impl std::fmt::Display for LinearError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LinearError::NotLinear { equation, .. } => {
                write!(f, "equation {} is not linear in the unknowns", equation + 1)
            }
            LinearError::Underdetermined { free } => {
                write!(
                    f,
                    "{} unknown(s) are not determined by the equations",
                    free.len()
                )
            }
            LinearError::Inconsistent { equation } => {
                write!(f, "equation {} contradicts the others", equation + 1)
            }
            LinearError::TooLarge => write!(
                f,
                "system too large to solve symbolically (over the work budget of exact \
                 elimination): solve it numerically instead"
            ),
        }
    }
}

impl std::error::Error for LinearError {}

/// Work budget for exact elimination (polynomial term operations).
const SOLVE_BUDGET: u64 = 4_000_000;

impl Pool {
    /// Writes `eqs` (each meaning `= 0`) as `A x = b` in `unknowns` (leaf expressions).
    pub fn linear_system(
        &mut self,
        eqs: &[Id],
        unknowns: &[Id],
    ) -> Result<LinearSystem, LinearError> {
        let zero: FxHashMap<Id, Id> = unknowns.iter().map(|&u| (u, Pool::ZERO)).collect();
        let wanted: rustc_hash::FxHashSet<Id> = unknowns.iter().copied().collect();
        let column: FxHashMap<Id, usize> =
            unknowns.iter().enumerate().map(|(j, &u)| (u, j)).collect();
        let mut a = vec![Pool::ZERO; eqs.len() * unknowns.len()];
        let mut b = Vec::with_capacity(eqs.len());
        for (i, &eq) in eqs.iter().enumerate() {
            // Only the unknowns the equation contains have a coefficient other than zero: an
            // equation of a net's particle holds its own three accelerations of the 3N
            // (differentiating by all of them made assembly quadratic).
            let mut present: Vec<usize> = self
                .occurring(eq, &wanted)
                .iter()
                .map(|u| column[u])
                .collect();
            present.sort_unstable();
            for j in present {
                let u = unknowns[j];
                let c = self.diff(eq, u);
                if !self.occurring(c, &wanted).is_empty() {
                    return Err(LinearError::NotLinear {
                        equation: i,
                        unknown: u,
                    });
                }
                a[i * unknowns.len() + j] = c;
            }
            let rest = self.subs(eq, &zero);
            b.push(self.neg(rest));
        }
        Ok(LinearSystem {
            unknowns: unknowns.to_vec(),
            a,
            b,
        })
    }

    /// Solves `sys` exactly; returns one simplified expression per unknown.
    pub fn solve_linear(&mut self, sys: &LinearSystem) -> Result<Vec<Id>, LinearError> {
        self.solve_linear_with(sys, true)
    }

    /// Like [`Pool::solve_linear`]; with `check_consistency = false`, equations beyond the rank
    /// are assumed to hold (they are consequences of the others, e.g. F = ma components already
    /// satisfied by accelerations from the projected equations) instead of being proved zero.
    pub fn solve_linear_with(
        &mut self,
        sys: &LinearSystem,
        check_consistency: bool,
    ) -> Result<Vec<Id>, LinearError> {
        self.solve_linear_budgeted(sys, check_consistency, SOLVE_BUDGET)
    }

    /// Like [`Pool::solve_linear_with`], giving up with [`LinearError::TooLarge`] after
    /// `budget` polynomial term operations (a caller that can solve numerically instead, like
    /// `pdyn run`, wants exact elimination only when it is cheap).
    pub fn solve_linear_budgeted(
        &mut self,
        sys: &LinearSystem,
        check_consistency: bool,
        budget: u64,
    ) -> Result<Vec<Id>, LinearError> {
        self.solve_exact(sys, check_consistency, budget, false)
    }

    /// Like [`Pool::solve_linear_budgeted`], with the simplification of the quotients
    /// `y_i / det` paid from what is left of the same `budget`: [`LinearError::TooLarge`]
    /// when the two together do not fit. For a caller that prints the solution, and prints
    /// it only when it is short (`pdyn derive`): the 3-link chain's elimination fits the
    /// cheap budget, but simplifying its result cost five times as much, which made `pdyn
    /// derive` of 3 links slower than of 4 or 8 (whose elimination gives up or is not tried)
    /// for accelerations then printed by reference.
    pub fn solve_linear_within(
        &mut self,
        sys: &LinearSystem,
        check_consistency: bool,
        budget: u64,
    ) -> Result<Vec<Id>, LinearError> {
        self.solve_exact(sys, check_consistency, budget, true)
    }

    /// Bareiss elimination and back substitution; `within`: see [`Pool::solve_linear_within`].
    fn solve_exact(
        &mut self,
        sys: &LinearSystem,
        check_consistency: bool,
        budget: u64,
        within: bool,
    ) -> Result<Vec<Id>, LinearError> {
        let (m, n) = (sys.rows(), sys.cols());
        let mut rf = RationalForm::new(budget, false);
        // Rows of [A | b] as polynomials, each multiplied through by its common denominator.
        let mut rows: Vec<Vec<Poly>> = Vec::with_capacity(m);
        for i in 0..m {
            let mut fr = Vec::with_capacity(n + 1);
            for j in 0..=n {
                let e = if j < n { sys.coeff(i, j) } else { sys.b[i] };
                fr.push(rf.convert(self, e).ok_or(LinearError::TooLarge)?);
            }
            let mut l = Poly::constant(crate::number::Rational::ONE);
            for (_, d) in &fr {
                let g = gcd(&l, d, &mut rf.budget).ok_or(LinearError::TooLarge)?;
                let q = d
                    .div_exact(&g, &mut rf.budget)
                    .ok_or(LinearError::TooLarge)?;
                l = l.mul(&q, &mut rf.budget).ok_or(LinearError::TooLarge)?;
            }
            let mut row = Vec::with_capacity(n + 1);
            for (num, den) in fr {
                let k = l
                    .div_exact(&den, &mut rf.budget)
                    .ok_or(LinearError::TooLarge)?;
                row.push(num.mul(&k, &mut rf.budget).ok_or(LinearError::TooLarge)?);
            }
            rows.push(row);
        }
        let mut origin: Vec<usize> = (0..m).collect();
        let mut prev = Poly::constant(crate::number::Rational::ONE);
        let mut free = Vec::new();
        let mut pivot_cols = Vec::new();
        let mut r = 0;
        for k in 0..n {
            let mut found = None;
            for (i, row) in rows.iter().enumerate().skip(r) {
                if !self.poly_is_zero(&mut rf, &row[k], within)? {
                    found = Some(i);
                    break;
                }
            }
            let Some(piv) = found else {
                free.push(sys.unknowns[k]);
                continue;
            };
            rows.swap(r, piv);
            origin.swap(r, piv);
            let budget = &mut rf.budget;
            for i in r + 1..m {
                for j in k + 1..=n {
                    let t1 = rows[r][k]
                        .mul(&rows[i][j], budget)
                        .ok_or(LinearError::TooLarge)?;
                    let t2 = rows[i][k]
                        .mul(&rows[r][j], budget)
                        .ok_or(LinearError::TooLarge)?;
                    let d = t1.sub(&t2, budget).ok_or(LinearError::TooLarge)?;
                    rows[i][j] = d.div_exact(&prev, budget).ok_or(LinearError::TooLarge)?;
                }
                rows[i][k] = Poly::zero();
            }
            prev = rows[r][k].clone();
            pivot_cols.push(k);
            r += 1;
        }
        if !free.is_empty() {
            return Err(LinearError::Underdetermined { free });
        }
        for i in n..m {
            if check_consistency && !self.poly_is_zero(&mut rf, &rows[i][n], within)? {
                return Err(LinearError::Inconsistent {
                    equation: origin[i],
                });
            }
        }
        if n == 0 {
            // No unknowns (every coordinate prescribed): nothing to solve.
            return Ok(Vec::new());
        }
        // Fraction-free back substitution: x_i = y_i / det.
        let det = rows[n - 1][n - 1].clone();
        let mut y: Vec<Poly> = vec![Poly::zero(); n];
        for i in (0..n).rev() {
            let b = &mut rf.budget;
            let mut acc = det.mul(&rows[i][n], b).ok_or(LinearError::TooLarge)?;
            for j in i + 1..n {
                let t = rows[i][j].mul(&y[j], b).ok_or(LinearError::TooLarge)?;
                acc = acc.sub(&t, b).ok_or(LinearError::TooLarge)?;
            }
            y[i] = if i == n - 1 {
                rows[i][n].clone()
            } else {
                acc.div_exact(&rows[i][i], b).ok_or(LinearError::TooLarge)?
            };
        }
        let det_e = rf.to_expr(self, &det);
        let quotients: Vec<Id> = y
            .iter()
            .map(|yi| {
                let ye = rf.to_expr(self, yi);
                self.div(ye, det_e)
            })
            .collect();
        if !within {
            return Ok(quotients.iter().map(|&q| self.simplify(q)).collect());
        }
        let mut left = rf.budget.0;
        quotients
            .iter()
            .map(|&q| {
                self.simplify_within(q, &mut left)
                    .ok_or(LinearError::TooLarge)
            })
            .collect()
    }

    /// Whether `p` is zero, by an identity if need be (`sin^2 + cos^2 - 1`); `within`: the
    /// simplification this takes is paid from `rf`'s budget ([`Pool::solve_linear_within`]),
    /// [`LinearError::TooLarge`] past it (on the 3-link chain these pivot tests cost as much
    /// as the elimination itself).
    fn poly_is_zero(
        &mut self,
        rf: &mut RationalForm,
        p: &Poly,
        within: bool,
    ) -> Result<bool, LinearError> {
        if p.is_zero() {
            return Ok(true);
        }
        if p.as_constant().is_some() {
            return Ok(false);
        }
        // Nonzero as a polynomial, but possibly zero by an identity (sin^2 + cos^2 - 1).
        let e = rf.to_expr(self, p);
        if !within {
            return Ok(self.simplify(e) == Pool::ZERO);
        }
        let mut left = rf.budget.0;
        let s = self
            .simplify_within(e, &mut left)
            .ok_or(LinearError::TooLarge)?;
        rf.budget.0 = left;
        Ok(s == Pool::ZERO)
    }
}

#[cfg(test)]
mod tests {
    use crate::pool::Pool;

    #[test]
    fn two_by_two_numeric() {
        let mut p = Pool::new();
        let e1 = p.parse_scalar("2*x + y - 5").unwrap();
        let e2 = p.parse_scalar("x - y - 1").unwrap();
        let (x, y) = (p.var("x"), p.var("y"));
        let sys = p.linear_system(&[e1, e2], &[x, y]).unwrap();
        let sol = p.solve_linear(&sys).unwrap();
        assert_eq!(sol, vec![p.int(2), p.int(1)]);
    }

    #[test]
    fn errors_name_the_problem() {
        let mut p = Pool::new();
        let e1 = p.parse_scalar("x*y - 5").unwrap();
        let (x, y) = (p.var("x"), p.var("y"));
        assert!(matches!(
            p.linear_system(&[e1], &[x, y]),
            Err(super::LinearError::NotLinear { equation: 0, .. })
        ));
        let e1 = p.parse_scalar("x + y - 5").unwrap();
        let e2 = p.parse_scalar("2*x + 2*y - 10").unwrap();
        let sys = p.linear_system(&[e1, e2], &[x, y]).unwrap();
        assert_eq!(
            p.solve_linear(&sys),
            Err(super::LinearError::Underdetermined { free: vec![y] })
        );
        let e3 = p.parse_scalar("x - y").unwrap();
        let e4 = p.parse_scalar("x - 1").unwrap();
        let sys = p.linear_system(&[e1, e3, e4], &[x, y]).unwrap();
        assert!(matches!(
            p.solve_linear(&sys),
            Err(super::LinearError::Inconsistent { .. })
        ));
    }
}
