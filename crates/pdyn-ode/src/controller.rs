//! The shared step-size controller of the adaptive methods (Hairer's, with PI stabilisation)
//! and the initial-step estimate.
//!
//! # Error norm
//! With `y0` the state at the start of the step, `y1` the proposed new state and `e` the
//! embedded error estimate,
//! ```text
//!   sk_i = atol_i + rtol_i · max(|y0_i|, |y1_i|),     err = sqrt( (1/n) Σ_i (e_i / sk_i)² ).
//! ```
//! A step is accepted when `err ≤ 1`.
//!
//! # Step-size update (Hairer, Nørsett & Wanner I, §II.4; Gustafsson's PI control, as coded in
//! dopri5.f and dop853.f)
//! ```text
//!   fac11 = err^α,        α = 1/k − β·c           (k: order of the error estimate + 1)
//!   fac   = fac11 / facold^β
//!   fac   = clamp(fac / safety, 1/fac_max, 1/fac_min)
//!   h_new = h / fac
//! ```
//! after an accepted step `facold = max(err, 1e-4)`; after a rejected one
//! `h_new = h / min(1/fac_min, fac11/safety)` (no PI term), and the step following a rejection
//! may not grow (`|h_new| ≤ |h|`). `c` is 0.75 in dopri5.f and 0.2 in dop853.f; the defaults
//! below are the published ones of each code, so that the statistics printed by the Fortran
//! codes are reproduced exactly.
//!
//! # Initial step (dopri5.f `HINIT`)
//! `d0 = ‖y0‖`, `d1 = ‖f(t0, y0)‖` (un-averaged weighted 2-norms with `sk_i = atol_i +
//! rtol_i|y0_i|`); `h = 0.01·d0/d1` (or `1e-6` when either is below `1e-5`); one explicit Euler
//! step gives `d2 = ‖f(t0+h, y0+h f0) − f0‖ / h`; then
//! `h1 = (0.01 / max(d1, d2))^(1/p)` and `h0 = min(100 h, h1, h_max)`.

use crate::problem::OdeSystem;

/// Parameters of the PI step-size controller. All fields are dimensionless.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Controller {
    /// Safety factor applied to the optimal step. dopri5.f/dop853.f: `0.9`.
    pub safety: f64,
    /// Smallest step ratio `h_new/h`. dopri5.f: `0.2`; dop853.f: `0.333`.
    pub fac_min: f64,
    /// Largest step ratio `h_new/h`. dopri5.f: `10`; dop853.f: `6`.
    pub fac_max: f64,
    /// PI stabilisation exponent β (0 gives the classical I-controller). dopri5.f: `0.04`;
    /// dop853.f: `0`.
    pub beta: f64,
}

impl Default for Controller {
    /// The DOPRI5 settings (safety 0.9, fac_min 0.2, fac_max 10, β = 0.04).
    fn default() -> Self {
        Controller {
            safety: 0.9,
            fac_min: 0.2,
            fac_max: 10.0,
            beta: 0.04,
        }
    }
}

impl Controller {
    /// dopri5.f defaults (the same as [`Controller::default`]); also used by Tsit5.
    pub fn dopri5() -> Self {
        Controller::default()
    }

    /// dop853.f defaults: safety 0.9, fac_min 0.333, fac_max 6, β = 0.
    pub fn dop853() -> Self {
        Controller {
            safety: 0.9,
            fac_min: 0.333,
            fac_max: 6.0,
            beta: 0.0,
        }
    }

    /// radau5.f defaults: safety 0.9, fac_min 0.2, fac_max 8 (`0.2 ≤ h_new/h ≤ 8`), with
    /// Gustafsson's predictive controller (β is unused by Radau5).
    pub fn radau5() -> Self {
        Controller {
            safety: 0.9,
            fac_min: 0.2,
            fac_max: 8.0,
            beta: 0.0,
        }
    }
}

/// State of the PI controller during one solve.
#[derive(Debug, Clone)]
pub(crate) struct PiState {
    expo1: f64,
    beta: f64,
    safe: f64,
    facc1: f64,
    facc2: f64,
    facold: f64,
}

impl PiState {
    /// `alpha` is the I-exponent `1/k − β c`, computed by the method.
    pub(crate) fn new(c: &Controller, alpha: f64) -> Self {
        PiState {
            expo1: alpha,
            beta: c.beta,
            safe: c.safety,
            facc1: 1.0 / c.fac_min,
            facc2: 1.0 / c.fac_max,
            facold: 1e-4,
        }
    }

    /// The memory of the PI term: the error norm of the last accepted step (at least 1e-4).
    pub(crate) fn memory(&self) -> f64 {
        self.facold
    }

    /// Sets the memory of the PI term (a solve resumed from a saved state).
    pub(crate) fn restore(&mut self, facold: f64) {
        self.facold = facold;
    }

    /// Returns `(accepted, h_new)` for error `err` of a step of size `h`.
    #[inline]
    pub(crate) fn propose(&mut self, err: f64, h: f64) -> (bool, f64) {
        let fac11 = libm::pow(err, self.expo1);
        if err <= 1.0 {
            // x^0 = 1 exactly: skip the power for the I-controller (β = 0, DOP853).
            let pi = if self.beta == 0.0 {
                1.0
            } else {
                libm::pow(self.facold, self.beta)
            };
            let fac = fac11 / pi;
            let fac = self.facc2.max(self.facc1.min(fac / self.safe));
            self.facold = err.max(1e-4);
            (true, h / fac)
        } else {
            // f64::min ignores NaN: a non-finite error shrinks by 1/fac_min.
            (false, h / self.facc1.min(fac11 / self.safe))
        }
    }
}

/// SciPy's initial step (`scipy.integrate._ivp.common.select_initial_step`), for the methods
/// that follow SciPy's algorithms (BDF): Hairer's estimate with root-mean-square norms
/// (`‖x‖ = sqrt(Σ (x_i/sk_i)² / n)`, where Hairer sums without dividing by `n`) and the
/// exponent `1/(order + 1)` of the error estimator's `order`, clamped to the interval `span`
/// and `hmax`. Uses one evaluation of `f` (none for an empty system or interval). Positive;
/// the caller applies the direction.
#[allow(clippy::too_many_arguments)]
pub(crate) fn scipy_initial_step<S: OdeSystem + ?Sized>(
    sys: &S,
    t0: f64,
    y0: &[f64],
    f0: &[f64],
    dir: f64,
    order: i32,
    span: f64,
    hmax: f64,
    atol: &[f64],
    rtol: &[f64],
    y1: &mut [f64],
    f1: &mut [f64],
) -> f64 {
    let n = y0.len();
    if n == 0 {
        return hmax.min(span);
    }
    if span == 0.0 {
        return 0.0;
    }
    let rms = |x: &dyn Fn(usize) -> f64| {
        let s: f64 = (0..n).map(|i| x(i) * x(i)).sum();
        (s / n as f64).sqrt()
    };
    let sk = |i: usize| atol[i] + rtol[i] * y0[i].abs();
    let d0 = rms(&|i| y0[i] / sk(i));
    let d1 = rms(&|i| f0[i] / sk(i));
    let h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    };
    let h0 = h0.min(span);
    for i in 0..n {
        y1[i] = y0[i] + h0 * dir * f0[i];
    }
    sys.rhs(t0 + h0 * dir, y1, f1);
    let d2 = rms(&|i| (f1[i] - f0[i]) / sk(i)) / h0;
    let h1 = if d1 <= 1e-15 && d2 <= 1e-15 {
        1e-6_f64.max(h0 * 1e-3)
    } else {
        libm::pow(0.01 / d1.max(d2), 1.0 / (order + 1) as f64)
    };
    let h = (100.0 * h0).min(h1).min(span).min(hmax);
    if !h.is_finite() || h <= 0.0 {
        return 1e-6_f64.min(span);
    }
    h
}

/// Hairer's initial step estimate (see the module docs). Uses one evaluation of `f`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn initial_step<S: OdeSystem + ?Sized>(
    sys: &S,
    t0: f64,
    y0: &[f64],
    f0: &[f64],
    dir: f64,
    order: i32,
    hmax: f64,
    atol: &[f64],
    rtol: &[f64],
    y1: &mut [f64],
    f1: &mut [f64],
) -> f64 {
    let mut dnf = 0.0;
    let mut dny = 0.0;
    for i in 0..y0.len() {
        let sk = atol[i] + rtol[i] * y0[i].abs();
        dnf += (f0[i] / sk) * (f0[i] / sk);
        dny += (y0[i] / sk) * (y0[i] / sk);
    }
    let mut h = if dnf <= 1e-10 || dny <= 1e-10 {
        1e-6
    } else {
        (dny / dnf).sqrt() * 0.01
    };
    h = h.min(hmax);
    h = h.abs() * dir;
    for i in 0..y0.len() {
        y1[i] = y0[i] + h * f0[i];
    }
    sys.rhs(t0 + h, y1, f1);
    let mut der2 = 0.0;
    for i in 0..y0.len() {
        let sk = atol[i] + rtol[i] * y0[i].abs();
        let d = (f1[i] - f0[i]) / sk;
        der2 += d * d;
    }
    der2 = der2.sqrt() / h;
    let der12 = der2.abs().max(dnf.sqrt());
    let h1 = if der12 <= 1e-15 {
        1e-6_f64.max(h.abs() * 1e-3)
    } else {
        libm::pow(0.01 / der12, 1.0 / order as f64)
    };
    let h = (100.0 * h.abs()).min(h1).min(hmax);
    if !h.is_finite() || h <= 0.0 {
        return 1e-6 * dir;
    }
    h * dir
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::FnSystem;

    /// SciPy's estimate on `y' = −λ y` (two equal components), worked by hand: `sk = atol +
    /// rtol`, `d0 = 1/sk`, `d1 = λ/sk`, `h0 = 0.01/λ`, one Euler step gives `f1 = −(1 − 0.01) λ`
    /// so `d2 = 0.01 λ / sk / h0 = λ²/sk`, and `h = min(100 h0, (0.01/d2)^(1/2))`. Root mean
    /// squares: two equal components give what one does (Hairer's sums would be √2 larger).
    #[test]
    fn scipy_s_first_step_on_a_decay_is_the_hand_computed_one() {
        let lambda = 100.0;
        let sys = FnSystem::new(2, move |_t, y: &[f64], f: &mut [f64]| {
            f[0] = -lambda * y[0];
            f[1] = -lambda * y[1];
        });
        let (atol, rtol) = (1e-10, 1e-8);
        let sk = atol + rtol;
        let d2 = lambda * lambda / sk;
        let expected = (100.0 * 0.01 / lambda).min((0.01 / d2).sqrt());
        let y0 = [1.0, 1.0];
        let f0 = [-lambda, -lambda];
        let (mut y1, mut f1) = ([0.0; 2], [0.0; 2]);
        let h = scipy_initial_step(
            &sys,
            0.0,
            &y0,
            &f0,
            1.0,
            1,
            10.0,
            f64::INFINITY,
            &[atol; 2],
            &[rtol; 2],
            &mut y1,
            &mut f1,
        );
        assert!(
            (h - expected).abs() < 1e-12 * expected,
            "{h:e} against {expected:e}"
        );
        // Clamped to the interval and to the largest step.
        let short = scipy_initial_step(
            &sys, 0.0, &y0, &f0, 1.0, 1, 1e-9, 1.0, &[atol; 2], &[rtol; 2], &mut y1, &mut f1,
        );
        assert_eq!(short, 1e-9);
        let capped = scipy_initial_step(
            &sys, 0.0, &y0, &f0, 1.0, 1, 10.0, 1e-8, &[atol; 2], &[rtol; 2], &mut y1, &mut f1,
        );
        assert_eq!(capped, 1e-8);
    }
}
