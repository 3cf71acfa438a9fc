//! The universal-variable Kepler solver: exact two-body drift for any conic.
//!
//! For relative position `r₀`, velocity `v₀` and `μ = G(m₁+m₂)`, let `r₀ = |r₀|`,
//! `η₀ = r₀·v₀`, `β = 2μ/r₀ − v₀²` (`= μ/a`, positive for ellipses) and `ζ₀ = μ − β r₀`.
//! With the Stumpff functions `c_k(z)` and `G_k(X) = X^k c_k(βX²)`, the universal anomaly
//! `X` after a time `Δt` solves Kepler's equation
//!
//! ```text
//! F(X) = r₀ X + η₀ G₂(X) + ζ₀ G₃(X) − Δt = 0,    F'(X) = r(X) = r₀ + η₀ G₁ + ζ₀ G₂ > 0,
//! ```
//!
//! after which Gauss's f and g functions give the new state exactly:
//! `r = f r₀ + g v₀`, `v = ḟ r₀ + ġ v₀` with `f = 1 − μG₂/r₀`, `g = Δt − μG₃`,
//! `ḟ = −μG₁/(r r₀)`, `ġ = 1 − μG₂/r`. The updates are applied as increments
//! (`r += (f−1) r₀ + g v₀`), which keeps round-off small.
//!
//! Robustness (following the strategy Rein & Tamayo 2015 describe for WHFast): for ellipses
//! `Δt` is first reduced modulo the period; Halley's method starts from a third-order guess
//! and stops when an iterate repeats exactly (at a root: see `Setup::is_root`); if it has not converged after a few
//! iterations, the Laguerre–Conway iteration (Conway 1986), which converges from almost any
//! start, takes over; bisection on a bracket is the last resort. The Stumpff functions are
//! evaluated by their series for `|z| ≤ 1` and from trigonometric (hyperbolic) closed forms
//! written without cancellation beyond (see [`stumpff`]).

use std::f64::consts::PI;

/// The Kepler solver failed to find the universal anomaly (degenerate or non-finite input).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct KeplerFailure;

/// `1/k!` for `k = 0..=23`.
const INV_FACT: [f64; 24] = {
    let mut t = [1.0; 24];
    let mut k = 1;
    while k < 24 {
        t[k] = t[k - 1] / k as f64;
        k += 1;
    }
    t
};

/// Stumpff functions `[c₀, c₁, c₂, c₃](z)`, for any finite `z` (`z > 0`: ellipse).
///
/// `|z| ≤ 1`: series (6 terms up to `|z| = 0.1`, 9 up to 1; truncation below 1e-18). Otherwise with `s = √|z|`: `c₀ = cos s`, `c₁ = sin s / s`,
/// `c₂ = 2 sin²(s/2)/z` (no cancellation), hyperbolic functions for `z < 0`; `c₃` by its
/// series up to `|z| = 4` (where `s − sin s` would cancel) and `(s − sin s)/s³` beyond.
pub fn stumpff(z: f64) -> [f64; 4] {
    let series = |z: f64, terms: usize| {
        // c₂ = Σ_k (−z)^k/(2k+2)!, c₃ = Σ_k (−z)^k/(2k+3)!.
        let mut c2 = 0.0;
        let mut c3 = 0.0;
        for k in (0..terms).rev() {
            c2 = INV_FACT[2 * k + 2] - z * c2;
            c3 = INV_FACT[2 * k + 3] - z * c3;
        }
        (c2, c3)
    };
    if z.abs() <= 0.1 {
        let (c2, c3) = series(z, 6);
        return [1.0 - z * c2, 1.0 - z * c3, c2, c3];
    }
    if z.abs() <= 1.0 {
        let (c2, c3) = series(z, 9);
        return [1.0 - z * c2, 1.0 - z * c3, c2, c3];
    }
    let s = z.abs().sqrt();
    let (c0, c1, c2, c3_closed) = if z > 0.0 {
        let h = libm::sin(0.5 * s);
        (
            libm::cos(s),
            libm::sin(s) / s,
            2.0 * h * h / z,
            (s - libm::sin(s)) / (z * s),
        )
    } else {
        let h = libm::sinh(0.5 * s);
        (
            libm::cosh(s),
            libm::sinh(s) / s,
            -2.0 * h * h / z,
            (libm::sinh(s) - s) / (-z * s),
        )
    };
    let c3 = if z.abs() <= 4.0 {
        series(z, 11).1
    } else {
        c3_closed
    };
    [c0, c1, c2, c3]
}

/// `[G₀, G₁, G₂, G₃](X)` for the given `β`.
fn g_functions(beta: f64, x: f64) -> [f64; 4] {
    let [c0, c1, c2, c3] = stumpff(beta * x * x);
    let x2 = x * x;
    [c0, x * c1, x2 * c2, x2 * x * c3]
}

/// The quantities of one Kepler problem that the iteration needs.
#[derive(Clone, Copy)]
struct Setup {
    mu: f64,
    r0: f64,
    beta: f64,
    eta0: f64,
    zeta0: f64,
    /// The step, reduced modulo the period for ellipses.
    dt: f64,
}

impl Setup {
    /// `None` for degenerate input (`r = 0`, non-finite state, `μ ≤ 0`).
    fn new(mu: f64, r: &[f64; 3], v: &[f64; 3], dt: f64) -> Option<Self> {
        let [x, y, z] = *r;
        let [vx, vy, vz] = *v;
        let r0 = (x * x + y * y + z * z).sqrt();
        if !(r0 > 0.0 && r0.is_finite() && mu > 0.0 && mu.is_finite() && dt.is_finite()) {
            return None;
        }
        let v2 = vx * vx + vy * vy + vz * vz;
        let beta = 2.0 * mu / r0 - v2;
        let eta0 = x * vx + y * vy + z * vz;
        let zeta0 = mu - beta * r0;
        // Reduce dt modulo the period for ellipses: G₁, G₂ are periodic and μG₃ − Δt is too.
        // |dt| > P ⇔ dt² β³ > (2πμ)² (no square root on the common path).
        let mut dt = dt;
        if beta > 0.0 && dt * dt * beta * beta * beta > 4.0 * PI * PI * mu * mu {
            let period = 2.0 * PI * mu / (beta * beta.sqrt());
            dt -= period * (dt / period).trunc();
        }
        Some(Setup {
            mu,
            r0,
            beta,
            eta0,
            zeta0,
            dt,
        })
    }

    /// `G(X)`, `F(X)`, `F'(X)`, `F''(X)`.
    #[inline]
    fn eval(&self, xx: f64) -> ([f64; 4], f64, f64, f64) {
        let g = g_functions(self.beta, xx);
        let f = self.r0 * xx + self.eta0 * g[2] + self.zeta0 * g[3] - self.dt;
        let fp = self.r0 + self.eta0 * g[1] + self.zeta0 * g[2];
        let fpp = self.eta0 * g[0] + self.zeta0 * g[1];
        (g, f, fp, fpp)
    }

    /// Third-order initial guess for `X`.
    fn guess(&self) -> f64 {
        let dtr = self.dt / self.r0;
        let (r0, eta0, zeta0) = (self.r0, self.eta0, self.zeta0);
        dtr * (1.0 - 0.5 * dtr / r0 * (eta0 - dtr * (eta0 * eta0 / r0 - zeta0 / 3.0)))
    }

    /// Whether `xx`, where an iteration stopped because an iterate repeated, is a root: the
    /// residual of Kepler's equation is small against its terms. Needed because far from
    /// the root (a poor guess: a sizeable part of the orbit from a close pericentre makes
    /// the series guess ~10¹⁶) a correction can round away and the iterate repeat there.
    fn is_root(&self, xx: f64) -> bool {
        let (g, f, _, _) = self.eval(xx);
        let scale = (self.r0 * xx).abs()
            + (self.eta0 * g[2]).abs()
            + (self.zeta0 * g[3]).abs()
            + self.dt.abs();
        f.abs() <= 1e-9 * scale
    }

    /// One Halley step from `xx`: the G-functions at `xx` and the next iterate.
    #[inline]
    fn halley(&self, xx: f64) -> ([f64; 4], f64) {
        let (g, f, fp, fpp) = self.eval(xx);
        (g, xx - 2.0 * f * fp / (2.0 * fp * fp - f * fpp))
    }

    /// Whether a Halley jump from `old` to `new` signals divergence (non-finite, or more
    /// than half a period in X: ΔX² β > π²).
    fn diverged(&self, old: f64, new: f64) -> bool {
        !new.is_finite() || (self.beta > 0.0 && (new - old) * (new - old) * self.beta > PI * PI)
    }

    /// Applies the f and g functions for the converged `xx` (with `g = G(xx)`).
    fn finish(&self, g: [f64; 4], r: &mut [f64; 3], v: &mut [f64; 3]) -> Result<(), KeplerFailure> {
        let Setup {
            mu,
            r0,
            eta0,
            zeta0,
            dt,
            ..
        } = *self;
        let rn = r0 + eta0 * g[1] + zeta0 * g[2];
        if !(rn.is_finite() && rn > 0.0) {
            return Err(KeplerFailure);
        }
        let df = -mu * g[2] / r0;
        let gg = dt - mu * g[3];
        let fd = -mu * g[1] / (r0 * rn);
        let dgd = -mu * g[2] / rn;
        let r_old = *r;
        let v_old = *v;
        for k in 0..3 {
            r[k] += df * r_old[k] + gg * v_old[k];
            v[k] += fd * r_old[k] + dgd * v_old[k];
        }
        Ok(())
    }
}

/// Advances the relative orbit `(r, v)` with gravitational parameter `mu` by `dt` (either
/// sign), exactly up to round-off. Returns an error only for degenerate input (`r = 0`,
/// non-finite state, `mu ≤ 0`).
pub fn kepler_drift(
    mu: f64,
    r: &mut [f64; 3],
    v: &mut [f64; 3],
    dt: f64,
) -> Result<(), KeplerFailure> {
    if dt == 0.0 {
        return Ok(());
    }
    let st = Setup::new(mu, r, v, dt).ok_or(KeplerFailure)?;
    let (beta, dt) = (st.beta, st.dt);
    let f_of = |xx: f64| st.eval(xx);
    let dtr = dt / st.r0;

    // Halley's iteration from a third-order guess; stop when an iterate repeats exactly.
    let mut xx = st.guess();
    let mut converged = false;
    let mut old1 = f64::NAN;
    let mut last: Option<(f64, [f64; 4])> = None;
    for _ in 0..HALLEY_MAX {
        let (g, next) = st.halley(xx);
        last = Some((xx, g));
        let old2 = old1;
        old1 = xx;
        xx = next;
        if xx == old1 || xx == old2 {
            converged = st.is_root(xx);
            break;
        }
        if st.diverged(old1, xx) {
            break;
        }
    }
    // Laguerre–Conway (n = 5) from a linear guess.
    if !converged {
        xx = if beta > 0.0 { beta * dt / st.mu } else { dtr };
        let mut seen = [f64::NAN; 64];
        'outer: for it in 0..64 {
            let (_, f, fp, fpp) = f_of(xx);
            let den = fp + (16.0 * fp * fp - 20.0 * f * fpp).abs().sqrt();
            xx -= 5.0 * f / den;
            if !xx.is_finite() {
                break;
            }
            for s in &seen[..it] {
                if *s == xx {
                    converged = st.is_root(xx);
                    break 'outer;
                }
            }
            seen[it] = xx;
        }
    }
    // Bisection: F is increasing (F' = r > 0); bracket the root by doubling. A non-finite
    // F (G-functions overflowing at a huge hyperbolic X) counts as beyond the root.
    let beyond = |f: f64| {
        if f.is_finite() {
            f * dt.signum() >= 0.0
        } else {
            true
        }
    };
    if !converged {
        let (mut lo, mut hi) = if dt > 0.0 { (0.0, dtr) } else { (dtr, 0.0) };
        let mut k = 0;
        while !beyond(f_of(if dt > 0.0 { hi } else { lo }).1) {
            if dt > 0.0 {
                hi *= 2.0;
            } else {
                lo *= 2.0;
            }
            k += 1;
            if k > 2000 {
                return Err(KeplerFailure);
            }
        }
        for _ in 0..2000 {
            let mid = 0.5 * (lo + hi);
            if mid == lo || mid == hi {
                break;
            }
            if beyond(f_of(mid).1) == (dt > 0.0) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        xx = 0.5 * (lo + hi);
    }
    let g = match last {
        Some((x_last, g)) if x_last == xx => g,
        _ => g_functions(beta, xx),
    };
    st.finish(g, r, v)
}

const HALLEY_MAX: usize = 12;

pub use crate::kepler_lanes::kepler_drift_batch;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stumpff_matches_closed_forms() {
        for &z in &[1e-6, 0.05, 0.3, 2.0, 40.0, -0.3, -5.0, -40.0] {
            let c = stumpff(z);
            let (c0, c1, c2, c3) = if z > 0.0 {
                let s = z.sqrt();
                (
                    libm::cos(s),
                    libm::sin(s) / s,
                    (1.0 - libm::cos(s)) / z,
                    (s - libm::sin(s)) / (z * s),
                )
            } else {
                let s = (-z).sqrt();
                (
                    libm::cosh(s),
                    libm::sinh(s) / s,
                    (libm::cosh(s) - 1.0) / -z,
                    (libm::sinh(s) - s) / (-z * s),
                )
            };
            let tol = 1e-12;
            assert!((c[0] - c0).abs() < tol * c0.abs().max(1.0), "c0 z={z}");
            assert!((c[1] - c1).abs() < tol * c1.abs().max(1.0), "c1 z={z}");
            assert!((c[2] - c2).abs() < 1e-9 * c2.abs().max(1e-3), "c2 z={z}");
            assert!((c[3] - c3).abs() < 1e-9 * c3.abs().max(1e-3), "c3 z={z}");
        }
    }

    /// The batch solver (lockstep fast path) agrees with the scalar solver to round-off, for
    /// ellipses, hyperbolae, steps beyond a period (handed to the scalar solver) and a
    /// degenerate body (reported by index).
    #[test]
    fn batch_matches_scalar_to_round_off() {
        let mu = [1.0, 1.5, 0.7, 2.0, 1.0, 1.2];
        let r0 = [
            [1.0, 0.0, 0.0],
            [0.3, 1.1, -0.2],
            [2.0, 0.5, 0.1],
            [0.1, 0.0, 0.05],
            [5.0, -1.0, 0.0],
            [1.0, 1.0, 1.0],
        ];
        let v0 = [
            [0.0, 1.0, 0.0],
            [-0.9, 0.4, 0.1],
            [0.0, 1.2, 0.3],
            [0.0, 6.0, 0.0],
            [0.1, 0.2, 0.0],
            [0.3, -0.2, 0.4],
        ];
        for dt in [0.05, 0.7, 13.0, -2.5] {
            let (mut rb, mut vb) = (r0, v0);
            kepler_drift_batch(&mu, &mut rb, &mut vb, dt).unwrap();
            for i in 0..6 {
                let (mut r, mut v) = (r0[i], v0[i]);
                kepler_drift(mu[i], &mut r, &mut v, dt).unwrap();
                let (sr, sv) = (norm3(r), norm3(v));
                for k in 0..3 {
                    assert!((r[k] - rb[i][k]).abs() <= 1e-13 * sr, "r body {i}, dt {dt}");
                    assert!((v[k] - vb[i][k]).abs() <= 1e-13 * sv, "v body {i}, dt {dt}");
                }
            }
        }
        let mut r = r0;
        r[4] = [0.0; 3];
        let mut v = v0;
        assert_eq!(kepler_drift_batch(&mu, &mut r, &mut v, 0.1), Err(4));
    }

    fn norm3(a: [f64; 3]) -> f64 {
        (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
    }

    #[test]
    fn drift_forward_and_back_returns_home() {
        // A hyperbola and a long ellipse step, forward then backward.
        for (v0, dt) in [([0.0, 1.8, 0.1], 7.3), ([0.0, 0.3, 0.0], 25.0)] {
            let mut r = [1.0, 0.0, 0.0];
            let mut v = v0;
            kepler_drift(1.0, &mut r, &mut v, dt).unwrap();
            kepler_drift(1.0, &mut r, &mut v, -dt).unwrap();
            assert!((r[0] - 1.0).abs() < 1e-10 && r[1].abs() < 1e-10, "{r:?}");
            assert!((v[1] - v0[1]).abs() < 1e-10, "{v:?}");
        }
        assert!(kepler_drift(1.0, &mut [0.0; 3], &mut [1.0, 0.0, 0.0], 1.0).is_err());
    }
}
