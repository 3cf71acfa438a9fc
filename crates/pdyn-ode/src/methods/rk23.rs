//! **RK23** — Bogacki–Shampine 3(2), SciPy's `RK23` and MATLAB's `ode23`.
//!
//! Explicit, adaptive, 4 stages with FSAL (3 new evaluations of `f` per step), order 3
//! propagated (local extrapolation), embedded order 2 for the error estimate:
//! ```text
//!   c = (0, 1/2, 3/4, 1),  a21 = 1/2,  a32 = 3/4,  (a41, a42, a43) = b = (2/9, 1/3, 4/9),
//!   b̂ = (7/24, 1/4, 1/3, 1/8),   e = h Σ_i (b_i − b̂_i) k_i,   k4 = f(t + h, y1).
//! ```
//! Controller: the shared one of [`crate::controller`] with `α = 1/3`, safety 0.9,
//! fac_min 0.2, fac_max 10 and no PI term (SciPy's `RK23` factors). Dense output: the free
//! interpolant of the pair, the cubic Hermite polynomial through `(y0, k1)` and `(y1, k4)`
//! (order 3; SciPy's `RK23` `P` matrix is this polynomial written in the stages). No
//! stiffness detection (the last two stages are not at the same point). Not symplectic.
//!
//! P. Bogacki, L. F. Shampine, *A 3(2) pair of Runge–Kutta formulas*, Appl. Math. Lett. 2
//! (1989) 321–325.

use crate::controller::Controller;
use crate::events::DenseOutput;
use crate::explicit::ExplicitRk;
use crate::problem::OdeSystem;
use crate::solution::Stats;
use crate::tableau::Tableau;
use crate::Method;

/// One-line description for `--method help`.
pub const DOC: &str = "Bogacki-Shampine 3(2), adaptive explicit RK, FSAL, cubic Hermite dense \
output (ode23/RK23); for loose tolerances. Bogacki & Shampine 1989.";

/// The Bogacki–Shampine 3(2) tableau.
pub const TABLEAU: Tableau<4> = Tableau {
    a: [
        [0.0; 4],
        [0.5, 0.0, 0.0, 0.0],
        [0.0, 0.75, 0.0, 0.0],
        [2.0 / 9.0, 1.0 / 3.0, 4.0 / 9.0, 0.0],
    ],
    b: [2.0 / 9.0, 1.0 / 3.0, 4.0 / 9.0, 0.0],
    b_hat: Some([7.0 / 24.0, 0.25, 1.0 / 3.0, 0.125]),
    c: [0.0, 0.5, 0.75, 1.0],
    order: 3,
    embedded_order: 2,
    fsal: true,
};

/// Error weights `b − b̂`.
const E: [f64; 4] = [-5.0 / 72.0, 1.0 / 12.0, 1.0 / 9.0, -0.125];

/// Workspace: stages `k` (stage-major), the stage input, the Hermite data `y0, k1, y1, k4`.
pub(crate) struct Rk23 {
    n: usize,
    k: Vec<f64>,
    ys: Vec<f64>,
    herm: Vec<f64>,
    t_old: f64,
    h: f64,
}

impl DenseOutput for Rk23 {
    fn interpolate(&self, t: f64, out: &mut [f64]) {
        let s = (t - self.t_old) / self.h;
        crate::dense::hermite(&self.herm, self.n, s, self.h, out);
    }
    fn record(&self, t_from: f64, t_to: f64, into: &mut crate::dense::DenseSolution) {
        use crate::dense::Interpolant;
        into.push(
            t_from,
            t_to,
            Interpolant::Hermite,
            self.t_old,
            self.h,
            &[&self.herm],
        );
    }
}

impl ExplicitRk for Rk23 {
    const METHOD: Method = Method::Rk23;
    const ORDER: i32 = 3;
    const STIFF_THRESHOLD: f64 = f64::INFINITY;

    fn default_controller() -> Controller {
        Controller {
            safety: 0.9,
            fac_min: 0.2,
            fac_max: 10.0,
            beta: 0.0,
        }
    }

    fn alpha(c: &Controller) -> f64 {
        1.0 / 3.0 - c.beta * 0.75
    }

    fn new(n: usize) -> Self {
        Rk23 {
            n,
            k: vec![0.0; 4 * n],
            ys: vec![0.0; n],
            herm: vec![0.0; 4 * n],
            t_old: 0.0,
            h: 1.0,
        }
    }

    fn f_start(&mut self) -> &mut [f64] {
        &mut self.k[..self.n]
    }

    fn attempt<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        y: &[f64],
        h: f64,
        y_new: &mut [f64],
        atol: &[f64],
        rtol: &[f64],
        stats: &mut Stats,
    ) -> f64 {
        let n = self.n;
        let a = &TABLEAU.a;
        let c = &TABLEAU.c;
        let ys = &mut self.ys[..n];
        let (k1, r) = self.k.split_at_mut(n);
        let (k2, r) = r.split_at_mut(n);
        let (k3, k4) = r.split_at_mut(n);
        for i in 0..n {
            ys[i] = y[i] + h * a[1][0] * k1[i];
        }
        sys.rhs(t + c[1] * h, ys, k2);
        for i in 0..n {
            ys[i] = y[i] + h * a[2][1] * k2[i];
        }
        sys.rhs(t + c[2] * h, ys, k3);
        for i in 0..n {
            y_new[i] = y[i] + h * (a[3][0] * k1[i] + a[3][1] * k2[i] + a[3][2] * k3[i]);
        }
        sys.rhs(t + h, &y_new[..n], k4);
        stats.fevals += 3;
        let mut err = 0.0;
        for i in 0..n {
            let e = h * (E[0] * k1[i] + E[1] * k2[i] + E[2] * k3[i] + E[3] * k4[i]);
            let sk = atol[i] + rtol[i] * y[i].abs().max(y_new[i].abs());
            err += (e / sk) * (e / sk);
        }
        (err / n as f64).sqrt()
    }

    fn on_accept<S: OdeSystem + ?Sized>(&mut self, _: &S, _: f64, _: &[f64], _: &mut Stats) {}

    fn stiffness(&self, _: f64, _: &[f64]) -> f64 {
        0.0
    }

    fn prepare_dense<S: OdeSystem + ?Sized>(
        &mut self,
        _: &S,
        t: f64,
        y: &[f64],
        h: f64,
        y_new: &[f64],
        _: &mut Stats,
    ) {
        let n = self.n;
        self.t_old = t;
        self.h = h;
        self.herm[..n].copy_from_slice(&y[..n]);
        self.herm[n..2 * n].copy_from_slice(&self.k[..n]);
        self.herm[2 * n..3 * n].copy_from_slice(&y_new[..n]);
        self.herm[3 * n..].copy_from_slice(&self.k[3 * n..4 * n]);
    }

    fn advance(&mut self) {
        let n = self.n;
        self.k.copy_within(3 * n..4 * n, 0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tableau::order_residual;
    use crate::{solve, FnSystem, Options};

    #[test]
    fn tableau_row_sums_and_order_conditions() {
        assert!(TABLEAU.row_sum_residual() < 1e-15);
        let a = TABLEAU.a_rows();
        assert!(order_residual(&a, &TABLEAU.b, 3) < 1e-15);
        assert!(
            order_residual(&a, &TABLEAU.b, 4) > 1e-3,
            "order is exactly 3"
        );
        let bh = TABLEAU.b_hat.unwrap();
        assert!(order_residual(&a, &bh, 2) < 1e-15);
        assert!(order_residual(&a, &bh, 3) > 1e-3, "embedded order is 2");
        for i in 0..4 {
            assert!((TABLEAU.b[i] - bh[i] - E[i]).abs() < 1e-16);
            assert_eq!(TABLEAU.b[i], TABLEAU.a[3][i], "FSAL: b is the last row");
        }
    }

    /// Global error of a third-order method: 8× smaller per halving of the tolerance's cube
    /// root; here, the harmonic oscillator against cos/sin, and the dense output between
    /// steps within a few times the error at the steps.
    #[test]
    fn oscillator_converges_and_dense_output_is_third_order() {
        let osc = FnSystem::new(2, |_t, y: &[f64], f: &mut [f64]| {
            f[0] = y[1];
            f[1] = -y[0];
        });
        let mut errs = Vec::new();
        for tol in [1e-6, 1e-9] {
            let opts = Options {
                dense_output: true,
                ..Options::with_tol(tol)
            };
            let sol = solve(Method::Rk23, &osc, (0.0, 10.0), &[1.0, 0.0], &opts).unwrap();
            let (t, y) = sol.last().unwrap();
            assert_eq!(t, 10.0);
            let end = (y[0] - libm::cos(10f64)).abs();
            let dense = sol.dense.as_ref().unwrap();
            assert_eq!(dense.len(), sol.len() - 1);
            let mut worst: f64 = 0.0;
            let mut out = [0.0; 2];
            for k in 0..=1000 {
                let t = k as f64 * 0.01;
                dense.eval(t, &mut out);
                worst = worst.max(
                    (out[0] - libm::cos(t))
                        .abs()
                        .max((out[1] + libm::sin(t)).abs()),
                );
            }
            assert!(worst < 100.0 * tol, "tol {tol}: dense error {worst:e}");
            errs.push(end);
        }
        assert!(errs[1] < errs[0] / 100.0, "{errs:?}");
    }
}
