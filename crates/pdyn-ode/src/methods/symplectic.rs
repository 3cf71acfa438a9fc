//! **Velocity Verlet** (leapfrog) and its symmetric compositions: **Yoshida 4**,
//! **Kahan–Li 6**, **Kahan–Li 8**. Explicit, fixed step, symplectic, time-symmetric.
//!
//! For `q'' = a(t, q)` (separable: `a` independent of `q'`), one Verlet step of size `h`
//! (kick–drift–kick) is
//! ```text
//!   v_{1/2} = v_0 + (h/2) a(t, q_0),   q_1 = q_0 + h v_{1/2},   v_1 = v_{1/2} + (h/2) a(t+h, q_1),
//! ```
//! order 2, one evaluation of `a` per step (the last one is reused by the next step). A
//! composition with weights `w_1 … w_s` (`Σ w_i = 1`, symmetric `w_i = w_{s+1−i}`) applies
//! Verlet steps of sizes `w_1 h, …, w_s h`; it is symplectic and symmetric and has order `p`
//! when the weights satisfy the composition order conditions (`Σ w_i³ = 0` for order 4, …).
//! Symplecticity gives a modified Hamiltonian conserved to `O(h^p)` over exponentially long
//! times: the energy error stays bounded, without secular drift. Adaptive steps destroy this,
//! so the step is fixed by design (`h0`).
//!
//! * Verlet: L. Verlet, Phys. Rev. 159 (1967) 98; Störmer 1907.
//! * Yoshida 4 (3 stages): H. Yoshida, *Construction of higher order symplectic integrators*,
//!   Phys. Lett. A 150 (1990) 262–268 (also Forest & Ruth; Suzuki).
//! * Kahan–Li 6 (9 stages) and 8 (17 stages): W. Kahan, R.-C. Li, *Composition constants for
//!   raising the orders of unconventional schemes for ordinary differential equations*,
//!   Math. Comp. 66 (1997) 1089–1099; also Hairer, Lubich & Wanner, *Geometric Numerical
//!   Integration*, §V.3.

use crate::fixed::{FixedStepper, StepFailure};
use crate::problem::SecondOrderSystem;
use crate::solution::Stats;

/// One-line description of velocity Verlet.
pub const DOC_VERLET: &str = "Velocity Verlet / leapfrog (kick-drift-kick), order 2, explicit, \
symplectic, fixed step h0, 1 force evaluation per step; needs a separable second-order system. Verlet 1967.";
/// One-line description of Yoshida 4.
pub const DOC_YOSHIDA4: &str = "Yoshida's 3-stage symmetric composition of Verlet, order 4, \
symplectic, fixed step h0. Yoshida 1990.";
/// One-line description of Kahan–Li 6.
pub const DOC_KAHAN_LI6: &str = "Kahan-Li 9-stage symmetric composition of Verlet, order 6, \
symplectic, fixed step h0. Kahan & Li 1997.";
/// One-line description of Kahan–Li 8.
pub const DOC_KAHAN_LI8: &str = "Kahan-Li 17-stage symmetric composition of Verlet, order 8, \
symplectic, fixed step h0. Kahan & Li 1997.";

/// Verlet itself, as a one-stage composition.
pub const VERLET: [f64; 1] = [1.0];

const Y4_W1: f64 = 1.351207191959657634047687808971460826921999376217144828328; // 1/(2 − 2^{1/3})
/// Yoshida 4: `w1 w0 w1` with `w1 = 1/(2 − 2^{1/3})`, `w0 = 1 − 2 w1`.
pub const YOSHIDA4: [f64; 3] = [Y4_W1, 1.0 - 2.0 * Y4_W1, Y4_W1];

/// Kahan–Li 6 (s = 9).
pub const KAHAN_LI6: [f64; 9] = [
    0.39216144400731413928,
    0.33259913678935943860,
    -0.70624617255763935981,
    0.08221359629355080023,
    0.79854399093482996340,
    0.08221359629355080023,
    -0.70624617255763935981,
    0.33259913678935943860,
    0.39216144400731413928,
];

/// Kahan–Li 8 (s = 17).
pub const KAHAN_LI8: [f64; 17] = [
    0.13020248308889008088,
    0.56116298177510838456,
    -0.38947496264484728641,
    0.15884190655515560090,
    -0.39590389413323757734,
    0.18453964097831570709,
    0.25837438768632204729,
    0.29501172360931029887,
    -0.60550853383003451170,
    0.29501172360931029887,
    0.25837438768632204729,
    0.18453964097831570709,
    -0.39590389413323757734,
    0.15884190655515560090,
    -0.38947496264484728641,
    0.56116298177510838456,
    0.13020248308889008088,
];

/// A symmetric composition of velocity Verlet with weights `w`. Holds the acceleration at
/// the end of the last step (FSAL).
pub(crate) struct Composition {
    w: &'static [f64],
    acc: Vec<f64>,
    acc_at: Option<f64>,
}

impl Composition {
    pub(crate) fn new(w: &'static [f64], n: usize) -> Self {
        Composition {
            w,
            acc: vec![0.0; n],
            acc_at: None,
        }
    }
}

impl<S: SecondOrderSystem + ?Sized> FixedStepper<S> for Composition {
    fn step(
        &mut self,
        sys: &S,
        t: f64,
        y: &[f64],
        h: f64,
        y_new: &mut [f64],
        stats: &mut Stats,
    ) -> Result<(), StepFailure> {
        let n = sys.dim();
        y_new.copy_from_slice(y);
        let (q, v) = y_new.split_at_mut(n);
        let fresh = match self.acc_at {
            Some(ta) => (ta - t).abs() > 4.0 * f64::EPSILON * t.abs().max(h.abs()),
            None => true,
        };
        if fresh {
            sys.accel(t, q, v, &mut self.acc);
            stats.fevals += 1;
        }
        let acc = &mut self.acc;
        let mut tau = 0.0;
        for &w in self.w {
            let hw = h * w;
            let half = 0.5 * hw;
            for i in 0..n {
                v[i] += half * acc[i];
                q[i] += hw * v[i];
            }
            tau += w;
            sys.accel(t + tau * h, q, v, acc);
            for i in 0..n {
                v[i] += half * acc[i];
            }
        }
        stats.fevals += self.w.len();
        self.acc_at = Some(t + h);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(w: &[f64], order_conditions: &[u32]) {
        let s: f64 = w.iter().sum();
        assert!((s - 1.0).abs() < 1e-15, "sum = {s}");
        for i in 0..w.len() {
            assert_eq!(w[i], w[w.len() - 1 - i], "symmetric");
        }
        for &p in order_conditions {
            let r: f64 = w.iter().map(|x| x.powi(p as i32)).sum();
            assert!(r.abs() < 1e-14, "Σ w^{p} = {r}");
        }
    }

    #[test]
    fn composition_weights_satisfy_order_conditions() {
        check(&VERLET, &[]);
        check(&YOSHIDA4, &[3]);
        assert!((Y4_W1 - 1.0 / (2.0 - libm::pow(2f64, 1.0 / 3.0))).abs() < 1e-15);
        // Σ w³ = 0 and Σ w⁵ = 0 are necessary for orders 6 and 8 (the remaining conditions
        // are checked by the convergence-order tests).
        check(&KAHAN_LI6, &[3, 5]);
        check(&KAHAN_LI8, &[3, 5, 7]);
    }
}
