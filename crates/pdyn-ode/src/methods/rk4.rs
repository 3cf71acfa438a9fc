//! **RK4** — the classical fourth-order Runge–Kutta method, fixed step (for teaching and
//! comparison).
//!
//! `k1 = f(t, y)`, `k2 = f(t + h/2, y + h k1/2)`, `k3 = f(t + h/2, y + h k2/2)`,
//! `k4 = f(t + h, y + h k3)`, `y1 = y + h (k1 + 2k2 + 2k3 + k4)/6`. Order 4, 4 evaluations of
//! `f` per step, no error estimate, not symplectic. Kutta, *Beitrag zur näherungsweisen
//! Integration totaler Differentialgleichungen*, Z. Math. Phys. 46 (1901) 435–453.

use crate::fixed::{FixedStepper, StepFailure};
use crate::problem::OdeSystem;
use crate::solution::Stats;
use crate::tableau::Tableau;

/// One-line description for `--method help`.
pub const DOC: &str = "Classical Runge-Kutta, order 4, fixed step h0 (no error control); for \
teaching and comparison. Kutta 1901.";

/// The classical tableau.
pub const TABLEAU: Tableau<4> = Tableau {
    a: [
        [0.0, 0.0, 0.0, 0.0],
        [0.5, 0.0, 0.0, 0.0],
        [0.0, 0.5, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
    ],
    b: [1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0],
    b_hat: None,
    c: [0.0, 0.5, 0.5, 1.0],
    order: 4,
    embedded_order: 0,
    fsal: false,
};

/// Workspace.
pub(crate) struct Rk4 {
    k: Vec<f64>,
    ytmp: Vec<f64>,
}

impl Rk4 {
    pub(crate) fn new(n: usize) -> Self {
        Rk4 {
            k: vec![0.0; 4 * n],
            ytmp: vec![0.0; n],
        }
    }
}

impl<S: OdeSystem + ?Sized> FixedStepper<S> for Rk4 {
    fn step(
        &mut self,
        sys: &S,
        t: f64,
        y: &[f64],
        h: f64,
        y_new: &mut [f64],
        stats: &mut Stats,
    ) -> Result<(), StepFailure> {
        let n = y.len();
        let (k1, rest) = self.k.split_at_mut(n);
        let (k2, rest) = rest.split_at_mut(n);
        let (k3, k4) = rest.split_at_mut(n);
        let yt = &mut self.ytmp;
        sys.rhs(t, y, k1);
        for i in 0..n {
            yt[i] = y[i] + 0.5 * h * k1[i];
        }
        sys.rhs(t + 0.5 * h, yt, k2);
        for i in 0..n {
            yt[i] = y[i] + 0.5 * h * k2[i];
        }
        sys.rhs(t + 0.5 * h, yt, k3);
        for i in 0..n {
            yt[i] = y[i] + h * k3[i];
        }
        sys.rhs(t + h, yt, k4);
        for i in 0..n {
            y_new[i] = y[i] + h / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
        }
        stats.fevals += 4;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tableau::order_residual;

    #[test]
    fn tableau_row_sums_and_order_conditions() {
        assert_eq!(TABLEAU.row_sum_residual(), 0.0);
        assert!(order_residual(&TABLEAU.a_rows(), &TABLEAU.b, 4) < 1e-15);
    }
}
