//! **DOPRI5** — Dormand–Prince 5(4), MATLAB's `ode45` and SciPy's `RK45`.
//!
//! Explicit, adaptive, 7 stages with FSAL (6 new evaluations of `f` per step), order 5
//! propagated (local extrapolation), embedded order 4 for the error estimate, continuous
//! extension of order 4 (Shampine's; coefficients `d` of dopri5.f). Not symplectic.
//!
//! J. R. Dormand, P. J. Prince, *A family of embedded Runge–Kutta formulae*, J. Comput. Appl.
//! Math. 6 (1980) 19–26. Controller, initial step, stiffness detection and dense output as in
//! E. Hairer's dopri5.f (Hairer, Nørsett & Wanner, *Solving ODEs I*, 2nd ed., §II.4–II.6):
//!
//! * error `e = h Σ_i (b_i − b̂_i) k_i`, norm and PI controller of [`crate::controller`] with
//!   `α = 1/5 − 0.75β` (defaults safety 0.9, fac_min 0.2, fac_max 10, β = 0.04);
//! * stiffness indicator `h|λ| ≈ |h|·‖k7 − k6‖ / ‖y1 − ŷ6‖` (stages 6 and 7 both at `t + h`),
//!   stiff when it exceeds 3.25 fifteen times in a row;
//! * dense output `u(t + θh) = y0 + θ(Δ + (1−θ)(B + θ(C + (1−θ)D)))` with `Δ = y1 − y0`,
//!   `B = h k1 − Δ`, `C = Δ − h k7 − B`, `D = h Σ d_i k_i`.
//!
//! Statistics reproduce dopri5.f exactly (Arenstorf orbit, rtol = atol = 1e-7, h0 = 1e-4:
//! 217 accepted, 21 rejected, 1429 evaluations of `f`).

use crate::controller::Controller;
use crate::events::DenseOutput;
use crate::explicit::ExplicitRk;
use crate::problem::OdeSystem;
use crate::solution::Stats;
use crate::tableau::Tableau;
use crate::Method;

/// One-line description for `--method help`.
pub const DOC: &str = "Dormand-Prince 5(4), adaptive explicit RK, FSAL, 4th-order dense output \
(ode45/RK45); Hairer's dopri5.f controller and stiffness detection. Dormand & Prince 1980.";

/// The Dormand–Prince 5(4) tableau.
pub const TABLEAU: Tableau<7> = Tableau {
    a: [
        [0.0; 7],
        [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0, 0.0],
        [
            19372.0 / 6561.0,
            -25360.0 / 2187.0,
            64448.0 / 6561.0,
            -212.0 / 729.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            9017.0 / 3168.0,
            -355.0 / 33.0,
            46732.0 / 5247.0,
            49.0 / 176.0,
            -5103.0 / 18656.0,
            0.0,
            0.0,
        ],
        [
            35.0 / 384.0,
            0.0,
            500.0 / 1113.0,
            125.0 / 192.0,
            -2187.0 / 6784.0,
            11.0 / 84.0,
            0.0,
        ],
    ],
    b: [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
        0.0,
    ],
    b_hat: Some([
        5179.0 / 57600.0,
        0.0,
        7571.0 / 16695.0,
        393.0 / 640.0,
        -92097.0 / 339200.0,
        187.0 / 2100.0,
        1.0 / 40.0,
    ]),
    c: [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0],
    order: 5,
    embedded_order: 4,
    fsal: true,
};

/// Error weights `b − b̂` exactly as dopri5.f writes them (E1, E3, …, E7).
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// Dense-output coefficients `d` of dopri5.f (Shampine 1986).
const D: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];

/// Workspace: stages `k` (stage-major), the stage-6 input `ŷ6`, dense coefficients.
pub(crate) struct Dopri5 {
    n: usize,
    k: Vec<f64>,
    ysti: Vec<f64>,
    cont: Vec<f64>,
    t_old: f64,
    h: f64,
}

/// DOPRI5's continuous extension at `s = (t − t_old)/h` from its coefficients `c` (`5n`).
#[inline]
pub(crate) fn eval_cont(c: &[f64], n: usize, s: f64, out: &mut [f64]) {
    let s1 = 1.0 - s;
    for i in 0..n {
        out[i] =
            c[i] + s * (c[n + i] + s1 * (c[2 * n + i] + s * (c[3 * n + i] + s1 * c[4 * n + i])));
    }
}

impl DenseOutput for Dopri5 {
    #[inline]
    fn interpolate(&self, t: f64, out: &mut [f64]) {
        eval_cont(&self.cont, self.n, (t - self.t_old) / self.h, out);
    }
    fn record(&self, t_from: f64, t_to: f64, into: &mut crate::dense::DenseSolution) {
        use crate::dense::Interpolant;
        into.push(
            t_from,
            t_to,
            Interpolant::Dopri5,
            self.t_old,
            self.h,
            &[&self.cont],
        );
    }
}

impl Dopri5 {
    crate::explicit::avx_attempt!();

    /// One step; `N > 0` fixes the dimension at compile time (`N = 0`: use `self.n`).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn attempt_n<S: OdeSystem + ?Sized, const N: usize>(
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
        // The stages written out as in dopri5.f (same summation order, so the same rounding),
        // with the tableau constants folded in by the compiler.
        let n = if N > 0 { N } else { self.n };
        let a = &TABLEAU.a;
        let c = &TABLEAU.c;
        let xph = t + h;
        let (y, y_new, atol, rtol) = (&y[..n], &mut y_new[..n], &atol[..n], &rtol[..n]);
        let ys = &mut self.ysti[..n];
        let (k1, r) = self.k.split_at_mut(n);
        let (k2, r) = r.split_at_mut(n);
        let (k3, r) = r.split_at_mut(n);
        let (k4, r) = r.split_at_mut(n);
        let (k5, r) = r.split_at_mut(n);
        let (k6, k7) = r.split_at_mut(n);
        let k7 = &mut k7[..n];
        let ha21 = h * a[1][0];
        for i in 0..n {
            ys[i] = y[i] + ha21 * k1[i];
        }
        sys.rhs(t + c[1] * h, ys, k2);
        for i in 0..n {
            ys[i] = y[i] + h * (a[2][0] * k1[i] + a[2][1] * k2[i]);
        }
        sys.rhs(t + c[2] * h, ys, k3);
        for i in 0..n {
            ys[i] = y[i] + h * (a[3][0] * k1[i] + a[3][1] * k2[i] + a[3][2] * k3[i]);
        }
        sys.rhs(t + c[3] * h, ys, k4);
        for i in 0..n {
            ys[i] =
                y[i] + h * (a[4][0] * k1[i] + a[4][1] * k2[i] + a[4][2] * k3[i] + a[4][3] * k4[i]);
        }
        sys.rhs(t + c[4] * h, ys, k5);
        for i in 0..n {
            ys[i] = y[i]
                + h * (a[5][0] * k1[i]
                    + a[5][1] * k2[i]
                    + a[5][2] * k3[i]
                    + a[5][3] * k4[i]
                    + a[5][4] * k5[i]);
        }
        sys.rhs(xph, ys, k6);
        for i in 0..n {
            y_new[i] = y[i]
                + h * (a[6][0] * k1[i]
                    + a[6][2] * k3[i]
                    + a[6][3] * k4[i]
                    + a[6][4] * k5[i]
                    + a[6][5] * k6[i]);
        }
        sys.rhs(xph, y_new, k7);
        stats.fevals += 6;
        let mut err = 0.0;
        for i in 0..n {
            let e = (E[0] * k1[i]
                + E[2] * k3[i]
                + E[3] * k4[i]
                + E[4] * k5[i]
                + E[5] * k6[i]
                + E[6] * k7[i])
                * h;
            let sk = atol[i] + rtol[i] * y[i].abs().max(y_new[i].abs());
            err += (e / sk) * (e / sk);
        }
        (err / n as f64).sqrt()
    }
}

impl ExplicitRk for Dopri5 {
    const METHOD: Method = Method::Dopri5;
    const ORDER: i32 = 5;
    const STIFF_THRESHOLD: f64 = 3.25;

    fn default_controller() -> Controller {
        Controller::dopri5()
    }

    fn alpha(c: &Controller) -> f64 {
        0.2 - c.beta * 0.75
    }

    fn new(n: usize) -> Self {
        Dopri5 {
            n,
            k: vec![0.0; 7 * n],
            ysti: vec![0.0; n],
            cont: vec![0.0; 5 * n],
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
        crate::explicit::dispatch_dim!(
            self,
            S,
            [1, 2, 3, 4, 6, 8],
            (sys, t, y, h, y_new, atol, rtol, stats)
        )
    }

    fn on_accept<S: OdeSystem + ?Sized>(&mut self, _: &S, _: f64, _: &[f64], _: &mut Stats) {}

    fn stiffness(&self, h: f64, y_new: &[f64]) -> f64 {
        let n = self.n;
        crate::explicit::stiffness_ratio(
            h,
            &self.k[6 * n..7 * n],
            &self.k[5 * n..6 * n],
            &y_new[..n],
            &self.ysti[..n],
        )
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
        let k = &self.k;
        self.t_old = t;
        self.h = h;
        for i in 0..n {
            let ydiff = y_new[i] - y[i];
            let bspl = h * k[i] - ydiff;
            self.cont[i] = y[i];
            self.cont[n + i] = ydiff;
            self.cont[2 * n + i] = bspl;
            self.cont[3 * n + i] = -h * k[6 * n + i] + ydiff - bspl;
            self.cont[4 * n + i] = h
                * (D[0] * k[i]
                    + D[2] * k[2 * n + i]
                    + D[3] * k[3 * n + i]
                    + D[4] * k[4 * n + i]
                    + D[5] * k[5 * n + i]
                    + D[6] * k[6 * n + i]);
        }
    }

    fn advance(&mut self) {
        let n = self.n;
        self.k.copy_within(6 * n..7 * n, 0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tableau::order_residual;

    #[test]
    fn tableau_row_sums_and_order_conditions() {
        assert!(TABLEAU.row_sum_residual() < 1e-15);
        let a = TABLEAU.a_rows();
        assert!(order_residual(&a, &TABLEAU.b, 5) < 1e-14);
        assert!(
            order_residual(&a, &TABLEAU.b, 6) > 1e-5,
            "order is exactly 5"
        );
        let bh = TABLEAU.b_hat.unwrap();
        assert!(order_residual(&a, &bh, 4) < 1e-14);
        for i in 0..7 {
            assert!((TABLEAU.b[i] - bh[i] - E[i]).abs() < 1e-16);
            assert_eq!(TABLEAU.b[i], TABLEAU.a[6][i], "FSAL: b is the last row");
        }
    }

    /// A step of a 120-component system by the AVX code where the processor has it: the
    /// baseline build's bits.
    #[test]
    fn avx_steps_give_the_baseline_bits() {
        use crate::explicit::avx_check::{same_bits, Chain};
        same_bits::<Dopri5>(|m, t, y, h, y_new, atol, rtol, stats| {
            m.attempt_n::<_, 0>(&Chain, t, y, h, y_new, atol, rtol, stats)
        });
    }
}
