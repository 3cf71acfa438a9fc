//! The Kepler drift of many bodies at once: four bodies in lockstep on a fast path, the robust
//! scalar solver ([`crate::kepler::kepler_drift`]) for any body the fast path does not settle.
//!
//! Why a separate path: WHFast spends most of its time in Kepler drifts, and one drift is a
//! chain of dependent floating-point operations (latency-bound, a few hundred cycles). Four
//! independent bodies computed in the same loop overlap, so the chain's latency is paid about
//! once per four bodies. The fast path also does less work per body than the scalar solver,
//! which is written for robustness first:
//!
//! 1. **Guess**: the series reversion of Kepler's equation to fifth order in `u = Δt/r₀`.
//!    With `t(X) = r₀X + η₀X²/2 + ζ₀X³/6 − βη₀X⁴/24 − βζ₀X⁵/120 + …` (the Stumpff series of
//!    `G₂, G₃`), `u = X + a₂X² + a₃X³ + a₄X⁴ + a₅X⁵` with `a₂ = η₀/2r₀`, `a₃ = ζ₀/6r₀`,
//!    `a₄ = −βη₀/24r₀`, `a₅ = −βζ₀/120r₀`, and reversion (Abramowitz & Stegun 3.6.25) gives
//!    `X = u − a₂u² + (2a₂² − a₃)u³ + (5a₂a₃ − 5a₂³ − a₄)u⁴ + (14a₂⁴ − 21a₂²a₃ + 6a₂a₄ + 3a₃² − a₅)u⁵`.
//!    Every `aₖ` vanishes on a circular orbit, so the error is `O(e u⁶)`: about `10⁻⁷ X` for
//!    Jupiter at `Δt = P/20` (the scalar solver's third-order guess: `10⁻⁵`).
//! 2. **Halley steps** (Halley's method, cubic convergence; as in Rein & Tamayo 2015), lanes in
//!    lockstep, a settled lane frozen. The Stumpff functions come from their series (`c₂`,
//!    `c₃` to `z⁸`, truncation below `10⁻¹⁸` for `|z| = |β|X² ≤ 1`, a step of up to ≈ 1/6
//!    of a circular orbit) and `c₀ = 1 − z c₂`, `c₁ = 1 − z c₃`; a lane whose `|z|` exceeds
//!    1 goes to the scalar solver (WHFast meets that only in its correctors' long
//!    sub-steps, at the start and end of a run).
//! 3. **Stopping without a confirming evaluation**: the scalar solver stops when an iterate
//!    repeats exactly, which costs one evaluation that changes nothing. Here a lane stops
//!    after a Halley correction `δ` once Halley's asymptotic error of the new iterate,
//!    `|A| |δ|³` with `A = F''²/4F'² − F'''/6F'` (Traub 1964, *Iterative methods for the
//!    solution of equations*, §5), is below `10⁻¹⁷ |X|`, and `δ` is small enough
//!    (`δ²(1/X² + |β|) ≤ 10⁻¹⁰`) for the asymptotic estimate and the shift below to hold.
//! 4. **Shifted G-functions**: `G₁, G₂, G₃` at the final `X + δ` follow from those at `X` by
//!    Taylor series (`dGₖ/dX = Gₖ₋₁`, `dG₀/dX = −βG₁`) to `δ³`; the first term left out is
//!    below `10⁻²⁰` of the value under the bound on `δ`.
//! 5. Gauss's f and g functions as in [`crate::kepler`], applied as increments.
//!
//! A lane goes to the scalar solver (from its untouched initial state) when its input is
//! degenerate, its step exceeds its period (the scalar solver reduces it), the non-linear
//! terms of the guess's series exceed half its linear term, it has not settled
//! after [`HALLEY_MAX_FAST`] steps, or anything is not finite. Every decision depends on the
//! lane's own data only, so a body's result does not depend on which bodies share its batch.
//! The fast path and the scalar solver agree to round-off (tested), not bit for bit.

use std::f64::consts::PI;

use crate::kepler::kepler_drift;

/// Lanes computed in lockstep.
const L: usize = 4;
/// Halley steps tried on the fast path before a lane goes to the scalar solver.
pub const HALLEY_MAX_FAST: usize = 6;
/// `|z| = |β|X²` up to which the fast path runs (its Stumpff series' range): a step of up
/// to ≈ 1/6 of a circular orbit (`z = (2π/6)²`).
const Z_SERIES: f64 = 1.0;
/// `1/k!` for `k = 0..=19`.
const INV_FACT: [f64; 20] = {
    let mut t = [1.0; 20];
    let mut k = 1;
    while k < 20 {
        t[k] = t[k - 1] / k as f64;
        k += 1;
    }
    t
};

/// `(c₂, c₃)(z)` by their series to `z⁸` (Horner, two independent chains):
/// `c₂ = Σ (−z)^k/(2k+2)!`, `c₃ = Σ (−z)^k/(2k+3)!`; for `|z| ≤ Z_SERIES` the first term
/// left out is below `10⁻¹⁸` of the value.
#[inline(always)]
fn c2_c3_series(z: f64) -> (f64, f64) {
    let mut c2 = INV_FACT[18];
    let mut c3 = INV_FACT[19];
    for k in (0..8).rev() {
        c2 = INV_FACT[2 * k + 2] - z * c2;
        c3 = INV_FACT[2 * k + 3] - z * c3;
    }
    (c2, c3)
}

/// Advances `r[i]`, `v[i]` about `mu[i]` by `dt` (either sign) for all `i`, exactly up to
/// round-off. On failure (degenerate input: `r = 0`, non-finite state, `μ ≤ 0`) returns the
/// index of the first failing body; bodies before it have been advanced.
pub fn kepler_drift_batch(
    mu: &[f64],
    r: &mut [[f64; 3]],
    v: &mut [[f64; 3]],
    dt: f64,
) -> Result<(), usize> {
    let n = mu.len().min(r.len()).min(v.len());
    if dt == 0.0 {
        return Ok(());
    }
    let mut base = 0;
    while base < n {
        let m = (n - base).min(L);
        let ok = drift_lanes(
            &mu[base..base + m],
            &mut r[base..base + m],
            &mut v[base..base + m],
            dt,
        );
        for (l, &lane_ok) in ok.iter().enumerate().take(m) {
            if !lane_ok {
                let i = base + l;
                kepler_drift(mu[i], &mut r[i], &mut v[i], dt).map_err(|_| i)?;
            }
        }
        base += m;
    }
    Ok(())
}

/// The fast path for up to [`L`] bodies; returns which lanes it advanced (the others are
/// left untouched). Lanes beyond `mu.len()` are padded with a copy of lane 0 and discarded.
///
/// Written as loops over `[f64; L]` without branches (a lane's fate is a mask, settled lanes
/// are kept by selects), so that LLVM computes the lanes in vector registers.
#[allow(clippy::needless_range_loop)]
fn drift_lanes(mu: &[f64], r: &mut [[f64; 3]], v: &mut [[f64; 3]], dt: f64) -> [bool; L] {
    let m = mu.len();
    let lane = |l: usize| if l < m { l } else { 0 };
    let mut mu_l = [0.0; L];
    let mut px = [0.0; L];
    let mut py = [0.0; L];
    let mut pz = [0.0; L];
    let mut qx = [0.0; L];
    let mut qy = [0.0; L];
    let mut qz = [0.0; L];
    for l in 0..L {
        let i = lane(l);
        mu_l[l] = mu[i];
        [px[l], py[l], pz[l]] = r[i];
        [qx[l], qy[l], qz[l]] = v[i];
    }

    // Setup: the quantities of `kepler.rs`, and the series guess.
    let mut r0 = [0.0; L];
    let mut r0i = [0.0; L];
    let mut beta = [0.0; L];
    let mut eta0 = [0.0; L];
    let mut zeta0 = [0.0; L];
    let mut x = [0.0; L];
    let mut live = [false; L];
    for l in 0..L {
        let mu = mu_l[l];
        let rr = (px[l] * px[l] + py[l] * py[l] + pz[l] * pz[l]).sqrt();
        let ri = 1.0 / rr;
        let v2 = qx[l] * qx[l] + qy[l] * qy[l] + qz[l] * qz[l];
        let b = 2.0 * mu * ri - v2;
        let e0 = px[l] * qx[l] + py[l] * qy[l] + pz[l] * qz[l];
        let z0 = mu - b * rr;
        let u = dt * ri;
        let a2 = 0.5 * e0 * ri;
        let a3 = z0 * ri * (1.0 / 6.0);
        let a4 = -b * e0 * ri * (1.0 / 24.0);
        let a5 = -b * z0 * ri * (1.0 / 120.0);
        let a22 = a2 * a2;
        let k3 = 2.0 * a22 - a3;
        let k4 = 5.0 * a2 * a3 - 5.0 * a22 * a2 - a4;
        let k5 = 14.0 * a22 * a22 - 21.0 * a22 * a3 + 6.0 * a2 * a4 + 3.0 * a3 * a3 - a5;
        let xx = u * (1.0 + u * (-a2 + u * (k3 + u * (k4 + u * k5))));
        // The series guess is only meaningful while the non-linear terms of u(X) are small
        // at X ≈ u (a small part of the orbit, or far from a close pericentre).
        let u2 = u * u;
        let nonlinear =
            (a2 * u).abs() + (a3 * u2).abs() + (a4 * u2 * u).abs() + (a5 * u2 * u2).abs();
        // A step beyond one period goes to the scalar solver, which reduces it
        // (|dt| > P ⇔ dt²β³ > (2πμ)²). NaN fails the comparisons below.
        let within_period = !(b > 0.0 && dt * dt * b * b * b > 4.0 * PI * PI * mu * mu);
        live[l] = (rr > 0.0)
            & (rr < f64::INFINITY)
            & (mu > 0.0)
            & (mu < f64::INFINITY)
            & (v2 < f64::INFINITY)
            & (dt.abs() < f64::INFINITY)
            & within_period
            & (nonlinear <= 0.5);
        r0[l] = rr;
        r0i[l] = ri;
        beta[l] = b;
        eta0[l] = e0;
        zeta0[l] = z0;
        x[l] = xx;
    }

    // Halley steps in lockstep; a settled lane keeps its X and shifted G-functions.
    let mut done = [false; L];
    let mut g1 = [0.0; L];
    let mut g2 = [0.0; L];
    let mut g3 = [0.0; L];
    for _ in 0..HALLEY_MAX_FAST {
        // The arithmetic of all lanes first, free of branches and masks (so that it runs
        // in vector registers), then the per-lane decisions.
        let mut xn = [0.0; L];
        let mut s = [[0.0; 3]; L];
        let mut in_range = [false; L];
        let mut settles = [false; L];
        for l in 0..L {
            let (xx, b) = (x[l], beta[l]);
            let x2 = xx * xx;
            let z = b * x2;
            let (c2, c3) = c2_c3_series(z);
            let gg0 = 1.0 - z * c2;
            let gg1 = xx * (1.0 - z * c3);
            let gg2 = x2 * c2;
            let gg3 = x2 * xx * c3;
            let f = r0[l] * xx + eta0[l] * gg2 + zeta0[l] * gg3 - dt;
            let fp = r0[l] + eta0[l] * gg1 + zeta0[l] * gg2;
            let fpp = eta0[l] * gg0 + zeta0[l] * gg1;
            let fppp = zeta0[l] * gg0 - b * eta0[l] * gg1;
            let d = -2.0 * f * fp / (2.0 * fp * fp - f * fpp);
            xn[l] = xx + d;
            let d2 = d * d;
            // Halley's error constant times F'², A F'² = F''²/4 − F'''F'/6 (no division).
            let afp2 = 0.25 * fpp * fpp - fppp * fp * (1.0 / 6.0);
            let fp2 = fp * fp;
            // Beyond the series' range the lane goes to the scalar solver.
            in_range[l] = (z.abs() <= Z_SERIES) & (xn[l].abs() < f64::INFINITY) & (fp > 0.0);
            settles[l] = (d2 <= 1e-10 * xn[l] * xn[l])
                & (d2 * b.abs() <= 1e-10)
                // In the asymptotic regime Halley's and Newton's steps agree (|F F''| ≪
                // F'²); without this a huge F'' could shrink a step far from the root.
                & ((f * fpp).abs() <= 1e-4 * fp2)
                & (afp2.abs() * d2 * d.abs() <= 1e-17 * xn[l].abs() * fp2);
            // Taylor shift of the G-functions from xx to xn = xx + δ (to δ³), with
            // G₋₁ = dG₀/dX = −βG₁ and G₋₂ = −βG₀.
            let (h2, h3) = (0.5 * d2, d2 * d * (1.0 / 6.0));
            let (gm1, gm2) = (-b * gg1, -b * gg0);
            s[l] = [
                gg1 + d * gg0 + h2 * gm1 + h3 * gm2,
                gg2 + d * gg1 + h2 * gg0 + h3 * gm1,
                gg3 + d * gg2 + h2 * gg1 + h3 * gg0,
            ];
        }
        // A settled lane is only recomputed, and discarded, while other lanes iterate: its
        // fate must not depend on them.
        let mut pending = false;
        for l in 0..L {
            if done[l] {
                continue;
            }
            live[l] &= in_range[l];
            x[l] = xn[l];
            if settles[l] {
                [g1[l], g2[l], g3[l]] = s[l];
                done[l] = true;
            }
            pending |= live[l] & !done[l];
        }
        if !pending {
            break;
        }
    }

    // f and g functions (increments, as in kepler.rs).
    let mut ok = [false; L];
    let mut out_r = [[0.0; 3]; L];
    let mut out_v = [[0.0; 3]; L];
    for l in 0..L {
        let mu = mu_l[l];
        let rn = r0[l] + eta0[l] * g1[l] + zeta0[l] * g2[l];
        let rni = 1.0 / rn;
        let df = -mu * g2[l] * r0i[l];
        let gg = dt - mu * g3[l];
        let fd = -mu * g1[l] * r0i[l] * rni;
        let dgd = -mu * g2[l] * rni;
        let (ro, vo) = ([px[l], py[l], pz[l]], [qx[l], qy[l], qz[l]]);
        for k in 0..3 {
            out_r[l][k] = ro[k] + (df * ro[k] + gg * vo[k]);
            out_v[l][k] = vo[k] + (fd * ro[k] + dgd * vo[k]);
        }
        ok[l] = live[l] & done[l] & (rn > 0.0) & (rn < f64::INFINITY);
    }
    for l in 0..m {
        if ok[l] {
            r[l] = out_r[l];
            v[l] = out_v[l];
        }
    }
    ok
}
