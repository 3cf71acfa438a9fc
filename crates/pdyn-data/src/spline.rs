//! The cubic smoothing spline: the function `f` minimising
//!
//! ```text
//!     Σ_i (y_i − f(t_i))² + λ ∫ f''(t)² dt
//! ```
//!
//! (a natural cubic spline with knots at the samples), computed by Reinsch's algorithm: with
//! `Q` (n × n−2, the second divided differences) and `R` (n−2 × n−2, tridiagonal), the second
//! derivatives `γ` at the interior knots solve the pentadiagonal system
//! `(R + λ QᵀQ) γ = Qᵀ y` and the fitted values are `f = y − λ Q γ` (Green & Silverman 1994,
//! §2.3). One `L D Lᵀ` factorisation costs O(n).
//!
//! The smoothing parameter is chosen, unless given, by **generalized cross-validation**
//! (Craven & Wahba 1979), as SciPy's `make_smoothing_spline` does:
//! `GCV(λ) = n · RSS(λ) / (n − tr A(λ))²`, where `A` is the hat matrix. Since
//! `I − A = λ Q M⁻¹ Qᵀ`, `n − tr A = λ tr(M⁻¹ QᵀQ)` needs only the band of `M⁻¹`
//! (Hutchinson & de Hoog 1985), so each evaluation is O(n). The minimum is found on a grid of
//! one point per two decades of λ spanning every cut-off from the sampling (Nyquist) frequency
//! to the record's length, then refined by Brent's method to 0.005 decade.
//!
//! **Standard errors.** The residual variance is `σ² = RSS / (n − tr A)`. In the interior of
//! a uniform grid (spacing `h`; the mean spacing is used for uneven samples) the spline is a
//! linear filter with a known frequency response (see [`standard_errors`]; for frequencies well
//! below the sampling rate it is `1 / (1 + λ h ω⁴)`, Silverman 1984's equivalent kernel), so
//! white noise of variance `σ²` per sample gives the variance of the value and of the first
//! and second derivative at a knot exactly. These are the noise-induced errors of interior
//! values; they omit the smoothing bias (small for the derivatives when the signal is
//! resolved by many samples per cut-off period) and do not hold within a few cut-off lengths
//! of the ends, where the natural end conditions (`f'' = 0`) bias the fit.

use crate::error::DataError;
#[cfg(test)]
use crate::linalg::Penta;

/// How much to smooth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Smoothing {
    /// λ chosen by generalized cross-validation.
    Gcv,
    /// λ given (units: value² · time³; 0 is interpolation).
    Lambda(f64),
}

/// A fitted smoothing spline, evaluated at its knots (the sample times).
#[derive(Clone, Debug)]
pub struct SmoothingSpline {
    /// The smoothing parameter used.
    pub lambda: f64,
    /// Whether λ came from GCV.
    pub from_gcv: bool,
    /// Fitted values at the sample times.
    pub value: Vec<f64>,
    /// First derivatives at the sample times.
    pub d1: Vec<f64>,
    /// Second derivatives at the sample times (zero at both ends: natural spline).
    pub d2: Vec<f64>,
    /// Effective degrees of freedom `tr A`.
    pub edf: f64,
    /// The residual sum of squares.
    pub rss: f64,
    /// The residual variance `RSS / (n − tr A)`.
    pub sigma2: f64,
    /// GCV score at λ.
    pub gcv: f64,
    /// Mean sample spacing.
    pub h: f64,
    /// Standard errors (from noise) of the value, first and second derivative in the interior.
    pub se: [f64; 3],
}

/// Buffers reused by [`Setup::score`] across the values of λ tried.
#[derive(Default)]
struct Workspace {
    d: Vec<f64>,
    l1: Vec<f64>,
    l2: Vec<f64>,
    g: Vec<f64>,
}

/// The pieces of the Reinsch system that do not depend on λ.
struct Setup {
    n: usize,
    /// Second divided differences: the column of `Q` for interior knot `j+1` has `qa[j]`,
    /// `qb[j]`, `qc[j]` in rows `j`, `j+1`, `j+2`.
    qa: Vec<f64>,
    qb: Vec<f64>,
    qc: Vec<f64>,
    r0: Vec<f64>,
    r1: Vec<f64>,
    p0: Vec<f64>,
    p1: Vec<f64>,
    p2: Vec<f64>,
    qty: Vec<f64>,
}

impl Setup {
    fn new(t: &[f64], y: &[f64]) -> Setup {
        let n = t.len();
        let m = n - 2;
        let h: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
        let qa: Vec<f64> = (0..m).map(|j| 1.0 / h[j]).collect();
        let qc: Vec<f64> = (0..m).map(|j| 1.0 / h[j + 1]).collect();
        let qb: Vec<f64> = (0..m).map(|j| -qa[j] - qc[j]).collect();
        let r0: Vec<f64> = (0..m).map(|j| (h[j] + h[j + 1]) / 3.0).collect();
        let r1: Vec<f64> = (0..m)
            .map(|j| if j + 1 < m { h[j + 1] / 6.0 } else { 0.0 })
            .collect();
        let mut p0 = vec![0.0; m];
        let mut p1 = vec![0.0; m];
        let mut p2 = vec![0.0; m];
        for j in 0..m {
            p0[j] = qa[j] * qa[j] + qb[j] * qb[j] + qc[j] * qc[j];
            if j + 1 < m {
                p1[j] = qb[j] * qa[j + 1] + qc[j] * qb[j + 1];
            }
            if j + 2 < m {
                p2[j] = qc[j] * qa[j + 2];
            }
        }
        let qty: Vec<f64> = (0..m)
            .map(|j| qa[j] * y[j] + qb[j] * y[j + 1] + qc[j] * y[j + 2])
            .collect();
        Setup {
            n,
            qa,
            qb,
            qc,
            r0,
            r1,
            p0,
            p1,
            p2,
            qty,
        }
    }

    #[cfg(test)]
    fn factor(&self, lam: f64) -> Option<Penta> {
        let m = self.n - 2;
        let m0: Vec<f64> = (0..m).map(|j| self.r0[j] + lam * self.p0[j]).collect();
        let m1: Vec<f64> = (0..m).map(|j| self.r1[j] + lam * self.p1[j]).collect();
        let m2: Vec<f64> = (0..m).map(|j| lam * self.p2[j]).collect();
        Penta::factor(&m0, &m1, &m2)
    }

    /// γ (interior second derivatives) and the fitted values for λ.
    #[cfg(test)]
    fn fit(&self, f: &Penta, lam: f64, y: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let mut gamma = self.qty.clone();
        f.solve(&mut gamma);
        let mut value = y.to_vec();
        for (j, g) in gamma.iter().enumerate() {
            let lg = lam * g;
            value[j] -= lg * self.qa[j];
            value[j + 1] -= lg * self.qb[j];
            value[j + 2] -= lg * self.qc[j];
        }
        (gamma, value)
    }

    /// `n − tr A = λ tr(M⁻¹ QᵀQ)`.
    #[cfg(test)]
    fn residual_dof(&self, f: &Penta, lam: f64) -> f64 {
        let (s0, s1, s2) = f.inverse_band();
        let mut tr = 0.0;
        for j in 0..s0.len() {
            tr += s0[j] * self.p0[j] + 2.0 * (s1[j] * self.p1[j] + s2[j] * self.p2[j]);
        }
        lam * tr
    }

    /// (GCV, RSS, n − tr A) for λ, or `None` when λ is numerically unusable: the same
    /// numbers as [`Setup::score_reference`] in one pass per stage over reused buffers
    /// (factorisation with the forward solve, back substitution, then the residuals and the
    /// trace with the band of the inverse kept in rolling variables). GCV's search calls this
    /// ~40 times; for 10⁶ samples the allocations of the reference path dominated.
    fn score(&self, lam: f64, ws: &mut Workspace) -> Option<(f64, f64, f64)> {
        let m = self.n - 2;
        ws.d.resize(m, 0.0);
        ws.l1.resize(m, 0.0);
        ws.l2.resize(m, 0.0);
        ws.g.resize(m, 0.0);
        let (d, l1, l2, g) = (&mut ws.d, &mut ws.l1, &mut ws.l2, &mut ws.g);
        for j in 0..m {
            let mut dj = self.r0[j] + lam * self.p0[j];
            let mut z = self.qty[j];
            let mut off = self.r1[j] + lam * self.p1[j];
            if j >= 1 {
                dj -= l1[j - 1] * l1[j - 1] * d[j - 1];
                z -= l1[j - 1] * g[j - 1];
                off -= l2[j - 1] * d[j - 1] * l1[j - 1];
            }
            if j >= 2 {
                dj -= l2[j - 2] * l2[j - 2] * d[j - 2];
                z -= l2[j - 2] * g[j - 2];
            }
            if !(dj > 0.0) || !dj.is_finite() {
                return None;
            }
            d[j] = dj;
            g[j] = z;
            l1[j] = if j + 1 < m { off / dj } else { 0.0 };
            l2[j] = if j + 2 < m {
                lam * self.p2[j] / dj
            } else {
                0.0
            };
        }
        // Back substitution, and in the same reverse sweep the residuals y − f = λ Q γ (row
        // j + 2 is complete once γ_j is known) and tr(M⁻¹ QᵀQ) with the band of M⁻¹
        // (Hutchinson–de Hoog) in rolling variables: s0_1 = Σ[j+1][j+1], s0_2 = Σ[j+2][j+2],
        // s1_1 = Σ[j+1][j+2].
        let (mut g1, mut g2) = (0.0, 0.0);
        let (mut s0_1, mut s0_2, mut s1_1) = (0.0, 0.0, 0.0);
        let (mut rss, mut tr) = (0.0, 0.0);
        for j in (0..m).rev() {
            let (a, b) = (l1[j], l2[j]);
            let gj = g[j] / d[j] - a * g1 - b * g2;
            g[j] = gj;
            let mut r = self.qc[j] * gj;
            if j + 1 < m {
                r += self.qb[j + 1] * g1;
            }
            if j + 2 < m {
                r += self.qa[j + 2] * g2;
            }
            rss += r * r;
            let s2 = -a * s1_1 - b * s0_2;
            let s1 = -a * s0_1 - b * s1_1;
            let s0 = 1.0 / d[j] - a * s1 - b * s2;
            tr += s0 * self.p0[j] + 2.0 * (s1 * self.p1[j] + s2 * self.p2[j]);
            s0_2 = s0_1;
            s0_1 = s0;
            s1_1 = s1;
            g2 = g1;
            g1 = gj;
        }
        // Rows 0 and 1.
        if m >= 1 {
            let r1 = if m > 1 { self.qa[1] * g[1] } else { 0.0 } + self.qb[0] * g[0];
            let r0 = self.qa[0] * g[0];
            rss += r1 * r1 + r0 * r0;
        }
        rss *= lam * lam;
        let dof = lam * tr;
        let gcv = self.n as f64 * rss / (dof * dof);
        (gcv.is_finite() && dof > 0.0).then_some((gcv, rss, dof))
    }

    /// The straightforward (GCV, RSS, n − tr A), kept to test [`Setup::score`] against.
    #[cfg(test)]
    fn score_reference(&self, lam: f64, y: &[f64]) -> Option<(f64, f64, f64)> {
        let f = self.factor(lam)?;
        let (_, value) = self.fit(&f, lam, y);
        let rss: f64 = value.iter().zip(y).map(|(a, b)| (a - b) * (a - b)).sum();
        let dof = self.residual_dof(&f, lam);
        let gcv = self.n as f64 * rss / (dof * dof);
        (gcv.is_finite() && dof > 0.0).then_some((gcv, rss, dof))
    }
}

/// Fits the smoothing spline of `y` at the strictly increasing times `t` (at least 3 samples,
/// finite values; [`crate::csv::Series`] checks both). `name` is used in messages.
pub fn fit(
    t: &[f64],
    y: &[f64],
    smoothing: Smoothing,
    name: &str,
) -> Result<SmoothingSpline, DataError> {
    let n = t.len();
    if n < 3 || y.len() != n {
        return Err(DataError::new(
            name,
            format!("a smoothing spline needs at least 3 samples ({n} given)"),
        ));
    }
    let setup = Setup::new(t, y);
    let span = t[n - 1] - t[0];
    let h = span / (n - 1) as f64;
    let mut ws = Workspace::default();
    let (lam, from_gcv) = match smoothing {
        Smoothing::Lambda(l) if l >= 0.0 && l.is_finite() => (l, false),
        Smoothing::Lambda(l) => {
            return Err(DataError::new(
                name,
                format!("the smoothing parameter λ = {l} must be ≥ 0 and finite"),
            ))
        }
        Smoothing::Gcv => (gcv_lambda(&setup, &mut ws, h, span, name)?, true),
    };
    let (gcv, rss, dof) = setup.score(lam, &mut ws).ok_or_else(|| {
        DataError::new(
            name,
            format!("the smoothing system is singular for λ = {lam}"),
        )
        .help("choose a smaller λ, or let GCV choose it")
    })?;
    let edf = n as f64 - dof;
    let sigma2 = if dof > 0.0 { rss / dof } else { 0.0 };
    let gcv = if dof > 0.0 { gcv } else { f64::INFINITY };
    let mut d2 = vec![0.0; n];
    d2[1..n - 1].copy_from_slice(&ws.g);
    // f = y − λ Q γ.
    let mut value = y.to_vec();
    for (j, g) in ws.g.iter().enumerate() {
        let lg = lam * g;
        value[j] -= lg * setup.qa[j];
        value[j + 1] -= lg * setup.qb[j];
        value[j + 2] -= lg * setup.qc[j];
    }
    let mut d1 = vec![0.0; n];
    for i in 0..n - 1 {
        let hi = t[i + 1] - t[i];
        d1[i] = (value[i + 1] - value[i]) / hi - hi * (2.0 * d2[i] + d2[i + 1]) / 6.0;
    }
    let hl = t[n - 1] - t[n - 2];
    d1[n - 1] = (value[n - 1] - value[n - 2]) / hl + hl * (d2[n - 2] + 2.0 * d2[n - 1]) / 6.0;
    Ok(SmoothingSpline {
        lambda: lam,
        from_gcv,
        value,
        d1,
        d2,
        edf,
        rss,
        sigma2,
        gcv,
        h,
        se: standard_errors(sigma2, lam, h),
    })
}

/// The standard errors of `f`, `f'`, `f''` at an interior knot of a uniform grid of spacing
/// `h`, for noise of variance `sigma2` per sample (module documentation): the smoother's
/// frequency response on the infinite grid, `H(θ) = 1/(1 + λ K̂(θ))` with
/// `K̂ = Q̂²/R̂ = 3 (2 − 2 cos θ)² / (h³ (2 + cos θ))`, the second derivatives `Ĝ = Q̂/R̂` and the
/// knot derivative `D̂₁ = (e^{iθ} − 1)/h − h (2 + e^{iθ}) Ĝ / 6`; then
/// `Var f⁽ᵏ⁾ = σ²/π ∫₀^π |D̂ₖ|² H² dθ` (midpoint rule, spectrally accurate for this smooth
/// periodic integrand). For small θ, `K̂ ≈ θ⁴/h³`: the continuous filter `1/(1 + λ h ω⁴)`.
pub fn standard_errors(sigma2: f64, lam: f64, h: f64) -> [f64; 3] {
    const STEPS: usize = 2048;
    let mut acc = [0.0; 3];
    for k in 0..STEPS {
        let th = std::f64::consts::PI * (k as f64 + 0.5) / STEPS as f64;
        let (c, s) = (libm::cos(th), libm::sin(th));
        let q = (2.0 * c - 2.0) / h;
        let r = h * (2.0 + c) / 3.0;
        let g = q / r;
        let hh = 1.0 / (1.0 + lam * q * q / r);
        let re = (c - 1.0) / h - h * (2.0 + c) * g / 6.0;
        let im = s / h - h * s * g / 6.0;
        acc[0] += hh * hh;
        acc[1] += (re * re + im * im) * hh * hh;
        acc[2] += g * g * hh * hh;
    }
    acc.map(|a| (sigma2 * a / STEPS as f64).sqrt())
}

/// λ minimising GCV: a grid of one point per two decades over every cut-off from the Nyquist
/// frequency to the record's length, then Brent's method around the best grid point.
fn gcv_lambda(
    setup: &Setup,
    ws: &mut Workspace,
    h: f64,
    span: f64,
    name: &str,
) -> Result<f64, DataError> {
    use std::f64::consts::PI;
    // Cut-off ω_c = (λ h)^(−1/4): from π/h (no smoothing) to 2π/span (a straight line).
    let lo = libm::log10(h.powi(3) / PI.powi(4)) - 1.0;
    let hi = libm::log10((span / (2.0 * PI)).powi(4) / h) + 1.0;
    let mut score = |p: f64| {
        setup
            .score(libm::pow(10f64, p), ws)
            .map_or(f64::INFINITY, |s| s.0)
    };
    // Two decades per grid point (a factor 3.2 in the cut-off frequency): GCV's basin is
    // wider than that; the grid guards against the spurious minimum at λ → 0.
    let steps = (((hi - lo) / 2.0).ceil() as usize).max(2);
    let mut best = (f64::INFINITY, lo);
    for k in 0..=steps {
        let p = lo + (hi - lo) * k as f64 / steps as f64;
        let s = score(p);
        if s < best.0 {
            best = (s, p);
        }
    }
    if !best.0.is_finite() {
        return Err(DataError::new(
            name,
            "generalized cross-validation found no usable smoothing (are the values all equal, or the times nearly coincident?)",
        )
        .help("give the smoothing parameter explicitly"));
    }
    let step = (hi - lo) / steps as f64;
    let (p, fp) = crate::minimize::brent_min(&mut score, best.1 - step, best.1 + step, 0.0, 0.0025);
    Ok(libm::pow(10f64, if fp <= best.0 { p } else { best.1 }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The one-pass GCV score equals the reference computation (fit, residuals, band of the
    /// inverse) over ten decades of λ on uneven samples.
    #[test]
    fn fast_score_equals_reference() {
        let n = 50;
        let t: Vec<f64> = (0..n)
            .map(|i| i as f64 + 0.3 * ((i * 7) % 5) as f64)
            .collect();
        let y: Vec<f64> = t
            .iter()
            .map(|x| libm::sin(0.3 * x) + 0.1 * (libm::sin(x * 13.0)))
            .collect();
        let setup = Setup::new(&t, &y);
        let mut ws = Workspace::default();
        for k in 0..10 {
            let lam = 10f64.powi(k - 4);
            let a = setup.score(lam, &mut ws).unwrap();
            let b = setup.score_reference(lam, &y).unwrap();
            for (x, r) in [(a.0, b.0), (a.1, b.1), (a.2, b.2)] {
                assert!((x - r).abs() <= 1e-9 * r.abs(), "λ = {lam}: {x} vs {r}");
            }
        }
    }
}
