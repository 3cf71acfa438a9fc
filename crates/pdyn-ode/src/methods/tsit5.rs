//! **Tsit5** — Tsitouras 5(4).
//!
//! Explicit, adaptive, 7 stages with FSAL (6 new evaluations of `f` per step), order 5
//! propagated, embedded order 4, continuous extension of order 4 (`u(t + θh) = y0 + h Σ_i
//! b_i(θ) k_i` with quartic `b_i(θ)`). Not symplectic. Derived by relaxing the simplifying
//! assumptions of Dormand–Prince (only the first column condition is kept), which gives smaller
//! principal error coefficients: usually fewer steps than DOPRI5 at equal error.
//!
//! Ch. Tsitouras, *Runge–Kutta pairs of order 5(4) satisfying only the first column simplifying
//! assumption*, Comput. Math. Appl. 62 (2011) 770–775. Coefficients as tabulated in
//! OrdinaryDiffEq.jl. Controller, initial step and stiffness test are those of DOPRI5 (shared).

use crate::controller::Controller;
use crate::events::DenseOutput;
use crate::explicit::{combine, stage_input, ExplicitRk};
use crate::problem::OdeSystem;
use crate::solution::Stats;
use crate::tableau::Tableau;
use crate::Method;

/// One-line description for `--method help`.
pub const DOC: &str = "Tsitouras 5(4), adaptive explicit RK, FSAL, 4th-order dense output; \
usually cheaper than DOPRI5 at equal error. Tsitouras 2011.";

const B: [f64; 7] = [
    0.09646076681806523,
    0.01,
    0.4798896504144996,
    1.379008574103742,
    -3.290069515436081,
    2.324710524099774,
    0.0,
];

/// `b̂ − b` (OrdinaryDiffEq.jl's `btilde`); the error estimate is `h Σ_i E_i k_i`.
const E: [f64; 7] = [
    -0.00178001105222577714,
    -0.0008164344596567469,
    0.007880878010261995,
    -0.1447110071732629,
    0.5823571654525552,
    -0.45808210592918697,
    1.0 / 66.0,
];

/// The Tsitouras 5(4) tableau.
pub const TABLEAU: Tableau<7> = Tableau {
    a: [
        [0.0; 7],
        [0.161, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [
            -0.008480655492356989,
            0.335480655492357,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            2.8971530571054935,
            -6.359448489975075,
            4.3622954328695815,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            5.325864828439257,
            -11.748883564062828,
            7.4955393428898365,
            -0.09249506636175525,
            0.0,
            0.0,
            0.0,
        ],
        [
            5.86145544294642,
            -12.92096931784711,
            8.159367898576159,
            -0.071584973281401,
            -0.028269050394068383,
            0.0,
            0.0,
        ],
        B,
    ],
    b: B,
    b_hat: Some([
        B[0] + E[0],
        B[1] + E[1],
        B[2] + E[2],
        B[3] + E[3],
        B[4] + E[4],
        B[5] + E[5],
        B[6] + E[6],
    ]),
    c: [0.0, 0.161, 0.327, 0.9, 0.9800255409045097, 1.0, 1.0],
    order: 5,
    embedded_order: 4,
    fsal: true,
};

/// Dense output: `b_i(θ) = Σ_{m=1..4} R[i][m-1] θ^m`.
const R: [[f64; 4]; 7] = [
    [
        1.0,
        -2.763706197274826,
        2.9132554618219126,
        -1.0530884977290216,
    ],
    [0.0, 0.13169999999999998, -0.2234, 0.1017],
    [
        0.0,
        3.9302962368947516,
        -5.941033872131505,
        2.490627285651253,
    ],
    [
        0.0,
        -12.411077166933676,
        30.33818863028232,
        -16.548102889244902,
    ],
    [0.0, 37.50931341651104, -88.1789048947664, 47.37952196281928],
    [
        0.0,
        -27.896526289197286,
        65.09189467479366,
        -34.87065786149661,
    ],
    [0.0, 1.5, -4.0, 2.5],
];

/// Workspace.
pub(crate) struct Tsit5 {
    n: usize,
    k: Vec<f64>,
    ysti: Vec<f64>,
    e: Vec<f64>,
    y0: Vec<f64>,
    t_old: f64,
    h: f64,
}

/// Tsit5's interpolant at `θ = (t − t_old)/h` from `y0` and the 7 stages `k` (stage-major).
#[inline]
fn eval_parts(y0: &[f64], k: &[f64], n: usize, th: f64, h: f64, out: &mut [f64]) {
    let mut bt = [0.0; 7];
    for (i, r) in R.iter().enumerate() {
        bt[i] = th * (r[0] + th * (r[1] + th * (r[2] + th * r[3])));
    }
    for j in 0..n {
        let mut acc = 0.0;
        for m in 0..7 {
            acc += bt[m] * k[m * n + j];
        }
        out[j] = y0[j] + h * acc;
    }
}

/// Tsit5's interpolant from a recorded block `c = [y0, k1..k7]` (`8n`).
pub(crate) fn eval_cont(c: &[f64], n: usize, th: f64, h: f64, out: &mut [f64]) {
    eval_parts(&c[..n], &c[n..8 * n], n, th, h, out);
}

impl DenseOutput for Tsit5 {
    fn interpolate(&self, t: f64, out: &mut [f64]) {
        let th = (t - self.t_old) / self.h;
        eval_parts(&self.y0, &self.k, self.n, th, self.h, out);
    }
    fn record(&self, t_from: f64, t_to: f64, into: &mut crate::dense::DenseSolution) {
        use crate::dense::Interpolant;
        let parts: [&[f64]; 2] = [&self.y0, &self.k[..7 * self.n]];
        into.push(t_from, t_to, Interpolant::Tsit5, self.t_old, self.h, &parts);
    }
}

impl Tsit5 {
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
        let n = if N > 0 { N } else { self.n };
        let a = &TABLEAU.a;
        let c = &TABLEAU.c;
        for s in 1..6 {
            stage_input(y, &self.k, n, &a[s][..s], h, &mut self.ysti);
            let (_, rest) = self.k.split_at_mut(s * n);
            sys.rhs(t + c[s] * h, &self.ysti, &mut rest[..n]);
        }
        stage_input(y, &self.k, n, &a[6][..6], h, y_new);
        {
            let (_, rest) = self.k.split_at_mut(6 * n);
            sys.rhs(t + h, y_new, &mut rest[..n]);
        }
        stats.fevals += 6;
        combine(&self.k, n, &E, &mut self.e);
        let mut err = 0.0;
        for i in 0..n {
            let e = self.e[i] * h;
            let sk = atol[i] + rtol[i] * y[i].abs().max(y_new[i].abs());
            err += (e / sk) * (e / sk);
        }
        (err / n as f64).sqrt()
    }
}

impl ExplicitRk for Tsit5 {
    const METHOD: Method = Method::Tsit5;
    const ORDER: i32 = 5;
    const STIFF_THRESHOLD: f64 = 3.25;

    fn default_controller() -> Controller {
        Controller::dopri5()
    }

    fn alpha(c: &Controller) -> f64 {
        0.2 - c.beta * 0.75
    }

    fn new(n: usize) -> Self {
        Tsit5 {
            n,
            k: vec![0.0; 7 * n],
            ysti: vec![0.0; n],
            e: vec![0.0; n],
            y0: vec![0.0; n],
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
        _: &[f64],
        _: &mut Stats,
    ) {
        self.t_old = t;
        self.h = h;
        self.y0.copy_from_slice(y);
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
        assert!(TABLEAU.row_sum_residual() < 1e-14);
        let a = TABLEAU.a_rows();
        assert!(order_residual(&a, &TABLEAU.b, 5) < 1e-13);
        assert!(
            order_residual(&a, &TABLEAU.b, 6) > 1e-6,
            "order is exactly 5"
        );
        assert!(order_residual(&a, &TABLEAU.b_hat.unwrap(), 4) < 1e-13);
    }

    #[test]
    fn dense_output_weights_reach_b_at_theta_one() {
        for i in 0..7 {
            let s: f64 = R[i].iter().sum();
            assert!((s - B[i]).abs() < 1e-13, "b_{i}(1) = {s}");
        }
    }

    /// A step of a 120-component system by the AVX code where the processor has it: the
    /// baseline build's bits.
    #[test]
    fn avx_steps_give_the_baseline_bits() {
        use crate::explicit::avx_check::{same_bits, Chain};
        same_bits::<Tsit5>(|m, t, y, h, y_new, atol, rtol, stats| {
            m.attempt_n::<_, 0>(&Chain, t, y, h, y_new, atol, rtol, stats)
        });
    }
}
