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
/// One row per interior knot, `[1/d, l1, l2, g]` (the `L D Lᵀ` factors and the solution),
/// interleaved: one memory stream instead of four.
#[derive(Default)]
struct Workspace {
    rows: Vec<[[f64; 4]; 1]>,
}

/// The pieces of the Reinsch system that do not depend on λ: the spacings and their
/// reciprocals, from which every coefficient of `Q`, `R` and `QᵀQ` is formed on the fly
/// ([`Setup::coeffs`]), and `Qᵀ y`. Three arrays instead of nine: a GCV score is bound by
/// memory traffic on long records, and recomputing ~12 flops per knot is cheaper than reading
/// six more arrays (the same operations in the same order, so the same bits).
struct Setup {
    n: usize,
    /// `t[i+1] − t[i]`.
    h: Vec<f64>,
    /// `1 / h[i]`.
    ih: Vec<f64>,
    qty: Vec<f64>,
}

/// The coefficients at interior knot `j + 1`: the column of `Q` (`qa`, `qb`, `qc` in rows `j`,
/// `j+1`, `j+2`), the band of `R` (`r0` diagonal, `r1` the next) and of `QᵀQ` (`p0`, `p1`,
/// `p2`).
#[derive(Clone, Copy)]
struct Coeffs {
    qa: f64,
    qb: f64,
    qc: f64,
    r0: f64,
    r1: f64,
    p0: f64,
    p1: f64,
    p2: f64,
}

impl Setup {
    fn new(t: &[f64], y: &[f64]) -> Setup {
        let n = t.len();
        let m = n - 2;
        let h: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
        let ih: Vec<f64> = h.iter().map(|h| 1.0 / h).collect();
        let qty: Vec<f64> = (0..m)
            .map(|j| {
                let (qa, qc) = (ih[j], ih[j + 1]);
                let qb = -qa - qc;
                qa * y[j] + qb * y[j + 1] + qc * y[j + 2]
            })
            .collect();
        Setup { n, h, ih, qty }
    }

    /// [`Coeffs`] at interior knot `j + 1` (`j < n − 2`).
    #[inline(always)]
    fn coeffs(&self, j: usize) -> Coeffs {
        let m = self.n - 2;
        let (qa, qc) = (self.ih[j], self.ih[j + 1]);
        let qb = -qa - qc;
        let (r1, p1, p2) = if j + 1 < m {
            // Column j + 2 of Q: qa' = ih[j+1] = qc, qb' = −qc − ih[j+2], qc' = ih[j+2].
            let qc2 = self.ih[j + 2];
            let qb2 = -qc - qc2;
            let p2 = if j + 2 < m { qc * self.ih[j + 2] } else { 0.0 };
            (self.h[j + 1] * (1.0 / 6.0), qb * qc + qc * qb2, p2)
        } else {
            (0.0, 0.0, 0.0)
        };
        Coeffs {
            qa,
            qb,
            qc,
            r0: (self.h[j] + self.h[j + 1]) * (1.0 / 3.0),
            r1,
            p0: qa * qa + qb * qb + qc * qc,
            p1,
            p2,
        }
    }

    #[cfg(test)]
    fn factor(&self, lam: f64) -> Option<Penta> {
        let m = self.n - 2;
        let c: Vec<Coeffs> = (0..m).map(|j| self.coeffs(j)).collect();
        let m0: Vec<f64> = c.iter().map(|c| c.r0 + lam * c.p0).collect();
        let m1: Vec<f64> = c.iter().map(|c| c.r1 + lam * c.p1).collect();
        let m2: Vec<f64> = c.iter().map(|c| lam * c.p2).collect();
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
            let c = self.coeffs(j);
            value[j] -= lg * c.qa;
            value[j + 1] -= lg * c.qb;
            value[j + 2] -= lg * c.qc;
        }
        (gamma, value)
    }

    /// `n − tr A = λ tr(M⁻¹ QᵀQ)`.
    #[cfg(test)]
    fn residual_dof(&self, f: &Penta, lam: f64) -> f64 {
        let (s0, s1, s2) = f.inverse_band();
        let mut tr = 0.0;
        for j in 0..s0.len() {
            let c = self.coeffs(j);
            tr += s0[j] * c.p0 + 2.0 * (s1[j] * c.p1 + s2[j] * c.p2);
        }
        lam * tr
    }

    /// (GCV, RSS, n − tr A) for λ, or `None` when λ is numerically unusable: the same
    /// numbers as [`Setup::score_reference`] in one pass per stage over reused buffers
    /// (factorisation with the forward solve, back substitution, then the residuals and the
    /// trace with the band of the inverse kept in rolling variables).
    fn score(&self, lam: f64, ws: &mut Workspace) -> Option<(f64, f64, f64)> {
        self.score_lanes([lam], &mut ws.rows)[0]
    }

    /// [`Setup::score`] for `K` values of λ in one sweep. Each pass is a recurrence whose
    /// every step waits for the one before (a division on the path): one λ leaves the core
    /// mostly idle, and `K` independent recurrences interleaved cost little more than one.
    /// A λ whose factorisation breaks down (a pivot not positive and finite) gives `None`;
    /// its lane goes on with zeros, and the sweep stops when every lane has broken down.
    fn score_lanes<const K: usize>(
        &self,
        lams: [f64; K],
        rows: &mut Vec<[[f64; 4]; K]>,
    ) -> [Option<(f64, f64, f64)>; K] {
        let m = self.n - 2;
        rows.resize(m, [[0.0; 4]; K]);
        let mut ok = [true; K];
        // The factors of rows j − 1 and j − 2 of each lane, rolled.
        let (mut d1, mut l11, mut l21, mut g1) = ([0.0; K], [0.0; K], [0.0; K], [0.0; K]);
        let (mut d2, mut l22, mut g2) = ([0.0; K], [0.0; K], [0.0; K]);
        let (mut off1, mut lp2) = ([0.0; K], [0.0; K]);
        for (j, row) in rows.iter_mut().enumerate() {
            let c = self.coeffs(j);
            for k in 0..K {
                let lam = lams[k];
                // The terms of row j − 2 first, those of row j − 1 last: the recurrence's
                // critical path runs through row j − 1's factors.
                let mut dj = c.r0 + lam * c.p0;
                let mut z = self.qty[j];
                let mut off = c.r1 + lam * c.p1;
                if j >= 2 {
                    dj -= l22[k] * l22[k] * d2[k];
                    z -= l22[k] * g2[k];
                }
                if j >= 1 {
                    // l1·l1·d = l1·off and l2·d = λ p2 of row j − 1 (its `off1` and `lp2`):
                    // one multiplication on the path instead of two.
                    dj -= l11[k] * (l11[k] * d1[k]);
                    z -= l11[k] * g1[k];
                    off -= (l21[k] * d1[k]) * l11[k];
                }
                ok[k] &= dj > 0.0 && dj.is_finite();
                // One division per knot, off the other passes: the reciprocal is kept for
                // the back substitution and the band of the inverse.
                let lp = if j + 2 < m { lam * c.p2 } else { 0.0 };
                let (e, l1, l2) = if ok[k] {
                    let e = 1.0 / dj;
                    let l1 = if j + 1 < m { off * e } else { 0.0 };
                    (e, l1, lp * e)
                } else {
                    (dj, z, off) = (1.0, 0.0, 0.0);
                    (0.0, 0.0, 0.0)
                };
                off1[k] = if j + 1 < m { off } else { 0.0 };
                lp2[k] = lp;
                row[k] = [e, l1, l2, z];
                [d2[k], l22[k], g2[k]] = [d1[k], l21[k], g1[k]];
                [d1[k], l11[k], l21[k], g1[k]] = [dj, l1, l2, z];
            }
            if !ok.contains(&true) {
                return [None; K];
            }
        }
        // Back substitution, and in the same reverse sweep the residuals y − f = λ Q γ (row
        // j + 2 is complete once γ_j is known) and tr(M⁻¹ QᵀQ) with the band of M⁻¹
        // (Hutchinson–de Hoog) in rolling variables: s0_1 = Σ[j+1][j+1], s0_2 = Σ[j+2][j+2],
        // s1_1 = Σ[j+1][j+2].
        let (mut g1, mut g2) = ([0.0; K], [0.0; K]);
        let (mut s0_1, mut s0_2, mut s1_1) = ([0.0; K], [0.0; K], [0.0; K]);
        let (mut rss, mut tr) = ([0.0; K], [0.0; K]);
        // Q's entries of the two columns to the right: qb of column j + 1, qa of j + 2.
        let (mut qb1, mut qa2) = (0.0, 0.0);
        for j in (0..m).rev() {
            let c = self.coeffs(j);
            for k in 0..K {
                let [e, a, b, zj] = rows[j][k];
                let gj = zj * e - a * g1[k] - b * g2[k];
                rows[j][k][3] = gj;
                let mut r = c.qc * gj;
                if j + 1 < m {
                    r += qb1 * g1[k];
                }
                if j + 2 < m {
                    r += qa2 * g2[k];
                }
                rss[k] += r * r;
                // Newest values last (the critical path): s0_1 is last sweep's s0.
                let s2 = -b * s0_2[k] - a * s1_1[k];
                let s1 = -b * s1_1[k] - a * s0_1[k];
                let s0 = e - b * s2 - a * s1;
                tr[k] += s0 * c.p0 + 2.0 * (s1 * c.p1 + s2 * c.p2);
                s0_2[k] = s0_1[k];
                s0_1[k] = s0;
                s1_1[k] = s1;
                g2[k] = g1[k];
                g1[k] = gj;
            }
            // For j − 1: column j's qb, column j + 1's qa (= 1/h[j+1], this column's qc).
            qb1 = c.qb;
            qa2 = c.qc;
        }
        std::array::from_fn(|k| {
            let mut rss = rss[k];
            // Rows 0 and 1.
            if m >= 1 {
                let c0 = self.coeffs(0);
                let g0 = rows[0][k][3];
                let r1 = if m > 1 {
                    self.coeffs(1).qa * rows[1][k][3]
                } else {
                    0.0
                } + c0.qb * g0;
                let r0 = c0.qa * g0;
                rss += r1 * r1 + r0 * r0;
            }
            let lam = lams[k];
            rss *= lam * lam;
            let dof = lam * tr[k];
            let gcv = self.n as f64 * rss / (dof * dof);
            (ok[k] && gcv.is_finite() && dof > 0.0).then_some((gcv, rss, dof))
        })
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
    for (d, row) in d2[1..n - 1].iter_mut().zip(&ws.rows) {
        *d = row[0][3];
    }
    // f = y − λ Q γ.
    let mut value = y.to_vec();
    for (j, g) in ws.rows.iter().map(|r| r[0][3]).enumerate() {
        let lg = lam * g;
        let c = setup.coeffs(j);
        value[j] -= lg * c.qa;
        value[j + 1] -= lg * c.qb;
        value[j + 2] -= lg * c.qc;
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
    // wider than that; the grid guards against the spurious minimum at λ → 0. The grid's
    // points are scored two at a time ([`Setup::score_lanes`]), in a buffer of their own
    // freed before the refinement.
    let steps = (((hi - lo) / 2.0).ceil() as usize).max(2);
    let grid: Vec<f64> = (0..=steps)
        .map(|k| lo + (hi - lo) * k as f64 / steps as f64)
        .collect();
    let mut values = Vec::with_capacity(grid.len());
    let mut rows = Vec::new();
    for pair in grid.chunks(2) {
        match *pair {
            [p, q] => values.extend(
                setup
                    .score_lanes([libm::pow(10f64, p), libm::pow(10f64, q)], &mut rows)
                    .map(|s| s.map_or(f64::INFINITY, |s| s.0)),
            ),
            _ => values.push(score(pair[0])),
        }
    }
    drop(rows);
    let best = (0..grid.len())
        .filter(|&k| values[k].is_finite())
        .min_by(|&a, &b| values[a].total_cmp(&values[b]));
    let Some(k) = best else {
        return Err(DataError::new(
            name,
            "generalized cross-validation found no usable smoothing (are the values all equal, or the times nearly coincident?)",
        )
        .help("give the smoothing parameter explicitly"));
    };
    let step = (hi - lo) / steps as f64;
    // Brent's method between the best grid point's neighbours, from the three known values
    // (a neighbour off the grid's end, never scored, counts as +∞).
    let at = |i: Option<usize>, p: f64| {
        (
            p,
            i.and_then(|i| values.get(i))
                .copied()
                .unwrap_or(f64::INFINITY),
        )
    };
    let (p, fp) = crate::minimize::brent_min_bracketed(
        &mut score,
        at(k.checked_sub(1), grid[k] - step),
        (grid[k], values[k]),
        at(Some(k + 1), grid[k] + step),
        0.0,
        0.0025,
    );
    Ok(libm::pow(10f64, if fp <= values[k] { p } else { grid[k] }))
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

    /// Scored two at a time, each λ gets exactly the numbers it gets alone, also when the
    /// other lane breaks down (a negative λ makes a pivot negative), and when both do.
    #[test]
    fn lanes_score_as_one_at_a_time() {
        let n = 200;
        let t: Vec<f64> = (0..n)
            .map(|i| i as f64 * 0.1 + 0.02 * ((i * 3) % 7) as f64)
            .collect();
        let y: Vec<f64> = t
            .iter()
            .map(|&x| libm::cos(x) + 0.05 * libm::sin(x * 17.0))
            .collect();
        let setup = Setup::new(&t, &y);
        let mut ws = Workspace::default();
        let mut rows = Vec::new();
        for pair in [[1e-3, 10.0], [0.5, -50.0], [-50.0, 2e-2], [-1.0, -50.0]] {
            let both = setup.score_lanes(pair, &mut rows);
            for (k, lam) in pair.into_iter().enumerate() {
                let alone = setup.score(lam, &mut ws);
                assert_eq!(both[k], alone, "λ = {lam} beside {pair:?}");
                assert_eq!(alone.is_none(), lam < 0.0, "λ = {lam}");
            }
        }
    }
}
