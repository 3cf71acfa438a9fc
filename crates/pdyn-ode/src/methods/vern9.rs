//! **Vern9** — Verner's "most efficient" 9(8) pair.
//!
//! Explicit, adaptive, 16 stages (15 new evaluations of `f` per attempt plus `f(t+h, y1)` after
//! an accepted step, reused as the next first stage), order 9 propagated, embedded order 8 for
//! the error estimate `h Σ (b_i − b̂_i) k_i`. Not symplectic. For very tight tolerances
//! (≲ 1e-10) on smooth problems.
//!
//! J. H. Verner, *Numerically optimal Runge–Kutta pairs with interpolants*, Numer. Algorithms
//! 53 (2010) 383–396; coefficients as tabulated in OrdinaryDiffEq.jl (from Verner's site).
//!
//! Controller: the shared PI controller with the DOP853 settings (safety 0.9, fac_min 0.333,
//! fac_max 6, β = 0) and exponent `α = 1/9`. Dense output (for `t_eval` and events) is the
//! cubic Hermite interpolant of the step ends — it costs no extra evaluations but is only
//! third-order accurate between steps; Verner's 9th-order interpolant (extra stages) is not
//! implemented. No stiffness detection.

use crate::controller::Controller;
use crate::events::DenseOutput;
use crate::explicit::{combine, stage_input, ExplicitRk};
use crate::problem::OdeSystem;
use crate::solution::Stats;
use crate::tableau::Tableau;
use crate::Method;

/// One-line description for `--method help`.
pub const DOC: &str = "Verner 9(8), adaptive explicit RK of order 9 (16 stages); for very tight \
tolerances. Cubic Hermite dense output only. Verner 2010.";

const B: [f64; 16] = [
    0.014611976858423152,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    -0.3915211862331339,
    0.23109325002895065,
    0.12747667699928525,
    0.2246434176204158,
    0.5684352689748513,
    0.058258715572158275,
    0.13643174034822156,
    0.030570139830827976,
    0.0,
];

/// `b − b̂` (OrdinaryDiffEq.jl's `btilde`).
const E: [f64; 16] = [
    -0.005357988290444578,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    -2.583020491182464,
    0.14252253154686625,
    0.013420653512688676,
    -0.02867296291409493,
    2.624999655215792,
    -0.2825509643291537,
    0.13643174034822156,
    0.030570139830827976,
    -0.04834231373823958,
];

const fn b_hat() -> [f64; 16] {
    let mut r = [0.0; 16];
    let mut i = 0;
    while i < 16 {
        r[i] = B[i] - E[i];
        i += 1;
    }
    r
}

/// The Vern9 tableau.
pub const TABLEAU: Tableau<16> = Tableau {
    a: [
        [
            0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
        ],
        [
            0.03462, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
        ],
        [
            -0.03893354388572875,
            0.13595789452450918,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            0.03638413148954267,
            0.0,
            0.10915239446862801,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            2.0257639143939694,
            0.0,
            -7.638023836496291,
            6.173259922102322,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            0.05112275589406061,
            0.0,
            0.0,
            0.17708237945550218,
            0.0008027762409222536,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            0.13160063579752163,
            0.0,
            0.0,
            -0.2957276252669636,
            0.08781378035642955,
            0.6213052975225274,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            0.07166666666666667,
            0.0,
            0.0,
            0.0,
            0.0,
            0.33055335789153195,
            0.2427799754418014,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            0.071806640625,
            0.0,
            0.0,
            0.0,
            0.0,
            0.3294380283228177,
            0.1165190029271823,
            -0.034013671875,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            0.04836757646340646,
            0.0,
            0.0,
            0.0,
            0.0,
            0.03928989925676164,
            0.10547409458903446,
            -0.021438652846483126,
            -0.10412291746271944,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            -0.026645614872014785,
            0.0,
            0.0,
            0.0,
            0.0,
            0.03333333333333333,
            -0.1631072244872467,
            0.03396081684127761,
            0.1572319413814626,
            0.21522674780318796,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            0.03689009248708622,
            0.0,
            0.0,
            0.0,
            0.0,
            -0.1465181576725543,
            0.2242577768172024,
            0.02294405717066073,
            -0.0035850052905728597,
            0.08669223316444385,
            0.43838406519683376,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            -0.4866012215113341,
            0.0,
            0.0,
            0.0,
            0.0,
            -6.304602650282853,
            -0.2812456182894729,
            -2.679019236219849,
            0.5188156639241577,
            1.3653531876033418,
            5.8850910885039465,
            2.8028087862720628,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            0.4185367457753472,
            0.0,
            0.0,
            0.0,
            0.0,
            6.724547581906459,
            -0.42544428016461133,
            3.3432791530012653,
            0.6170816631175374,
            -0.9299661239399329,
            -6.099948804751011,
            -3.002206187889399,
            0.2553202529443446,
            0.0,
            0.0,
            0.0,
        ],
        [
            -0.7793740861228848,
            0.0,
            0.0,
            0.0,
            0.0,
            -13.937342538107776,
            1.2520488533793563,
            -14.691500408016868,
            -0.494705058533141,
            2.2429749091462368,
            13.367893803828643,
            14.396650486650687,
            -0.79758133317768,
            0.4409353709534278,
            0.0,
            0.0,
        ],
        [
            2.0580513374668867,
            0.0,
            0.0,
            0.0,
            0.0,
            22.357937727968032,
            0.9094981099755646,
            35.89110098240264,
            -3.442515027624454,
            -4.865481358036369,
            -18.909803813543427,
            -34.26354448030452,
            1.2647565216956427,
            0.0,
            0.0,
            0.0,
        ],
    ],
    b: B,
    b_hat: Some(b_hat()),
    c: [
        0.0,
        0.03462,
        0.09702435063878045,
        0.14553652595817068,
        0.561,
        0.22900791159048503,
        0.544992088409515,
        0.645,
        0.48375,
        0.06757,
        0.25,
        0.6590650618730999,
        0.8206,
        0.9012,
        1.0,
        1.0,
    ],
    order: 9,
    embedded_order: 8,
    fsal: false,
};

/// Workspace: 16 stages (stage-major), stage input, error, `f(t+h, y1)`, Hermite data.
pub(crate) struct Vern9 {
    n: usize,
    k: Vec<f64>,
    ys: Vec<f64>,
    e: Vec<f64>,
    f_new: Vec<f64>,
    herm: Vec<f64>, // y0, f0, y1, f1
    t_old: f64,
    h: f64,
}

impl DenseOutput for Vern9 {
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
            &[&self.herm[..4 * self.n]],
        );
    }
}

impl Vern9 {
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
        for s in 1..16 {
            stage_input(y, &self.k, n, &a[s][..s], h, &mut self.ys);
            let (_, rest) = self.k.split_at_mut(s * n);
            sys.rhs(t + c[s] * h, &self.ys, &mut rest[..n]);
        }
        stats.fevals += 15;
        stage_input(y, &self.k, n, &B, h, y_new);
        combine(&self.k, n, &E, &mut self.e);
        let mut err = 0.0;
        for i in 0..n {
            let e = h * self.e[i];
            let sk = atol[i] + rtol[i] * y[i].abs().max(y_new[i].abs());
            err += (e / sk) * (e / sk);
        }
        (err / n as f64).sqrt()
    }
}

impl ExplicitRk for Vern9 {
    const METHOD: Method = Method::Vern9;
    const ORDER: i32 = 9;
    const STIFF_THRESHOLD: f64 = f64::INFINITY;

    fn default_controller() -> Controller {
        Controller::dop853()
    }

    fn alpha(c: &Controller) -> f64 {
        1.0 / 9.0 - c.beta * 0.2
    }

    fn new(n: usize) -> Self {
        Vern9 {
            n,
            k: vec![0.0; 16 * n],
            ys: vec![0.0; n],
            e: vec![0.0; n],
            f_new: vec![0.0; n],
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
        crate::explicit::dispatch_dim!(
            self,
            S,
            [1, 2, 4, 6],
            (sys, t, y, h, y_new, atol, rtol, stats)
        )
    }

    fn on_accept<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        t_new: f64,
        y_new: &[f64],
        stats: &mut Stats,
    ) {
        sys.rhs(t_new, y_new, &mut self.f_new);
        stats.fevals += 1;
    }

    fn stiffness(&self, _h: f64, _y_new: &[f64]) -> f64 {
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
        self.herm[..n].copy_from_slice(y);
        self.herm[n..2 * n].copy_from_slice(&self.k[..n]);
        self.herm[2 * n..3 * n].copy_from_slice(y_new);
        self.herm[3 * n..].copy_from_slice(&self.f_new);
    }

    fn advance(&mut self) {
        let n = self.n;
        self.k[..n].copy_from_slice(&self.f_new);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tableau::order_residual;

    #[test]
    fn tableau_row_sums_and_order_conditions() {
        assert!(
            TABLEAU.row_sum_residual() < 1e-13,
            "{}",
            TABLEAU.row_sum_residual()
        );
        let a = TABLEAU.a_rows();
        let r9 = order_residual(&a, &TABLEAU.b, 9);
        assert!(r9 < 1e-12, "order 9 residual {r9}");
        assert!(
            order_residual(&a, &TABLEAU.b, 10) > 1e-10,
            "order is exactly 9"
        );
        let r8 = order_residual(&a, &TABLEAU.b_hat.unwrap(), 8);
        assert!(r8 < 1e-12, "embedded order 8 residual {r8}");
    }

    /// A step of a 120-component system by the AVX code where the processor has it: the
    /// baseline build's bits.
    #[test]
    fn avx_steps_give_the_baseline_bits() {
        use crate::explicit::avx_check::{same_bits, Chain};
        same_bits::<Vern9>(|m, t, y, h, y_new, atol, rtol, stats| {
            m.attempt_n::<_, 0>(&Chain, t, y, h, y_new, atol, rtol, stats)
        });
    }
}
