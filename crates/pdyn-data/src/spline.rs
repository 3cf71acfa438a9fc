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
//! to the record's length, then refined by Brent's method to 0.005 decade. On records of
//! 131,072 samples or more the grid is searched on a subsample (every `s`-th sample, about
//! 65,536 of them) and the full record is scored only around the minimum it predicts, which
//! the full record's scores must bracket (else the full grid is searched).
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
    /// Sweeps over the knots so far (one per [`Setup::score_lanes`] call), for tests.
    #[cfg(test)]
    sweeps: std::cell::Cell<usize>,
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
        Setup {
            n,
            h,
            ih,
            qty,
            #[cfg(test)]
            sweeps: std::cell::Cell::new(0),
        }
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
        #[cfg(test)]
        self.sweeps.set(self.sweeps.get() + 1);
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
        Smoothing::Gcv => (gcv_lambda(&setup, &mut ws, t, y, name)?, true),
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

/// From this many samples on, GCV's basin is first located on a subsample ([`gcv_lambda`]).
const SUBSAMPLE_FROM: usize = 1 << 17;
/// The subsample's length, about: every `n / SUBSAMPLE_LEN`-th sample.
const SUBSAMPLE_LEN: usize = 1 << 16;
/// Brent's tolerance on `log10 λ`: 0.005 decade (a bracket of twice this), 1.2 % in λ.
const LOG_LAMBDA_TOL: f64 = 0.0025;

/// λ minimising GCV. On long records ([`SUBSAMPLE_FROM`] samples or more) the basin is located
/// on every `s`-th sample first ([`basin_from_subsample`]) and the full record's score is
/// evaluated only around it: a dozen scores of 10⁶ knots become three or four (and the grid's
/// on 65,536 knots). When that does not give a bracket, and on shorter records, the grid
/// search of [`gcv_grid`].
fn gcv_lambda(
    setup: &Setup,
    ws: &mut Workspace,
    t: &[f64],
    y: &[f64],
    name: &str,
) -> Result<f64, DataError> {
    gcv_lambda_from(setup, ws, t, y, name, SUBSAMPLE_FROM, LOG_LAMBDA_TOL)
}

/// [`gcv_lambda`] with the subsampling threshold and the tolerance as arguments (tests run the
/// subsampled path on short records).
fn gcv_lambda_from(
    setup: &Setup,
    ws: &mut Workspace,
    t: &[f64],
    y: &[f64],
    name: &str,
    subsample_from: usize,
    tol: f64,
) -> Result<f64, DataError> {
    let n = t.len();
    let span = t[n - 1] - t[0];
    let h = span / (n - 1) as f64;
    let (lo, hi) = gcv_range(h, span);
    if n >= subsample_from {
        let stride = (n / SUBSAMPLE_LEN.min(subsample_from / 2)).max(2);
        if let Some(p) = basin_from_subsample(t, y, stride, name) {
            if let Some(lam) = refine_near(setup, ws, p, (lo, hi), tol) {
                return Ok(lam);
            }
        }
    }
    gcv_grid(setup, ws, (lo, hi), name, tol)
}

/// The range of `log10 λ` searched: cut-off frequencies `ω_c = (λ h)^(−1/4)` from a decade
/// above π/h (no smoothing) to a decade below 2π/span (a straight line).
fn gcv_range(h: f64, span: f64) -> (f64, f64) {
    use std::f64::consts::PI;
    let lo = libm::log10(h.powi(3) / PI.powi(4)) - 1.0;
    let hi = libm::log10((span / (2.0 * PI)).powi(4) / h) + 1.0;
    (lo, hi)
}

/// The full record's `log10 λ` predicted from GCV on every `stride`-th sample, or `None` when
/// the subsample has no usable minimum. With the noise variance per sample unchanged, a
/// subsample has `stride` times the noise per unit time; for a smooth signal the optimal
/// smoothing `μ = λ h` of the filter `1/(1 + μ ω⁴)` balances its bias (∝ μ) against its noise
/// (∝ N₀ μ^(−1/4), `N₀ = σ² h`), so `μ ∝ N₀^(4/9)` and `λ = μ/h` scales as `stride^(−5/9)`. The
/// prediction only centres the full record's search, which checks it.
fn basin_from_subsample(t: &[f64], y: &[f64], stride: usize, name: &str) -> Option<f64> {
    let ts: Vec<f64> = t.iter().step_by(stride).copied().collect();
    let ys: Vec<f64> = y.iter().step_by(stride).copied().collect();
    if ts.len() < 8 {
        return None;
    }
    let setup = Setup::new(&ts, &ys);
    let mut ws = Workspace::default();
    let lam = gcv_lambda_from(&setup, &mut ws, &ts, &ys, name, usize::MAX, 0.05).ok()?;
    (lam > 0.0).then(|| libm::log10(lam) + 5.0 / 9.0 * libm::log10(stride as f64))
}

/// Brent's method on the full record around the predicted `log10 λ = p`: the score at `p` and
/// half a decade either side, then half-decade steps downhill until the middle value is the
/// lowest (at most four decades, inside `range`); `None` when no bracket is found that way.
fn refine_near(
    setup: &Setup,
    ws: &mut Workspace,
    p: f64,
    (lo, hi): (f64, f64),
    tol: f64,
) -> Option<f64> {
    const STEP: f64 = 0.5;
    if !(p - STEP > lo && p + STEP < hi) {
        return None;
    }
    let mut score = |p: f64| {
        setup
            .score(libm::pow(10f64, p), ws)
            .map_or(f64::INFINITY, |s| s.0)
    };
    // Three single scores, not a pair and a single: a pair's rows are another 32 bytes per
    // knot of fresh memory, whose page faults cost more than the pair saves.
    let mut bracket = [p - STEP, p, p + STEP].map(|p| (p, score(p)));
    for _ in 0..8 {
        let [(pa, fa), (pb, fb), (pc, fc)] = bracket;
        if !fb.is_finite() {
            return None;
        }
        if fb <= fa && fb <= fc {
            let (p, fp) = crate::minimize::brent_min_bracketed(
                &mut score,
                (pa, fa),
                (pb, fb),
                (pc, fc),
                0.0,
                tol,
            );
            return Some(libm::pow(10f64, if fp <= fb { p } else { pb }));
        }
        // Downhill: the lower end becomes the middle.
        bracket = if fa < fc {
            let q = pa - STEP;
            if q <= lo {
                return None;
            }
            [(q, score(q)), (pa, fa), (pb, fb)]
        } else {
            let q = pc + STEP;
            if q >= hi {
                return None;
            }
            [(pb, fb), (pc, fc), (q, score(q))]
        };
    }
    None
}

/// λ minimising GCV on `range` (of `log10 λ`): a grid of one point per two decades, then
/// Brent's method around the best grid point.
fn gcv_grid(
    setup: &Setup,
    ws: &mut Workspace,
    (lo, hi): (f64, f64),
    name: &str,
    tol: f64,
) -> Result<f64, DataError> {
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
        tol,
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

    /// A seeded noisy record: a sum of sinusoids (or a cubic) on uneven times.
    fn record(n: usize, seed: u64, kind: usize) -> (Vec<f64>, Vec<f64>) {
        let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut t = Vec::with_capacity(n);
        let mut now = 0.0;
        for _ in 0..n {
            t.push(now);
            now += 0.01 * (0.5 + uniform());
        }
        let noise = [0.01, 0.1, 0.001, 0.03][kind % 4];
        let y = t
            .iter()
            .map(|&x| {
                let clean = match kind % 3 {
                    0 => 3.0 * libm::sin(0.7 * x) + libm::cos(2.3 * x),
                    1 => 0.02 * x * x * x - 0.4 * x * x + x,
                    _ => libm::sin(0.05 * x * x),
                };
                clean + noise * (uniform() - 0.5) * 12f64.sqrt()
            })
            .collect();
        (t, y)
    }

    /// On long records GCV's basin is found on a subsample and the full record is scored only
    /// around it: the same minimum as the grid search over the whole range (to the search's
    /// tolerance), in fewer sweeps over the full record. Subsampling is switched on here from
    /// 4,000 samples (10⁵ in use) so that the test runs the same code on short records.
    #[test]
    fn subsampled_search_finds_the_grids_minimum_in_fewer_sweeps() {
        let (mut sub_total, mut grid_total) = (0, 0);
        for seed in 0..8 {
            let (t, y) = record(12_000, seed, seed as usize);
            let setup = Setup::new(&t, &y);
            let mut ws = Workspace::default();
            let grid =
                gcv_lambda_from(&setup, &mut ws, &t, &y, "y", usize::MAX, LOG_LAMBDA_TOL).unwrap();
            let grid_sweeps = setup.sweeps.replace(0);
            let sub = gcv_lambda_from(&setup, &mut ws, &t, &y, "y", 4_000, LOG_LAMBDA_TOL).unwrap();
            let sub_sweeps = setup.sweeps.get();
            let apart = libm::log10(sub / grid).abs();
            assert!(
                apart <= 4.0 * LOG_LAMBDA_TOL,
                "seed {seed}: λ {sub} (subsampled) vs {grid} (grid): {apart} decades apart"
            );
            assert!(
                sub_sweeps < grid_sweeps,
                "seed {seed}: {sub_sweeps} sweeps subsampled, {grid_sweeps} by the grid"
            );
            (sub_total, grid_total) = (sub_total + sub_sweeps, grid_total + grid_sweeps);
        }
        // 81 against 112 when written; the grid's share grows with the record (15 against 10
        // on 10⁶ samples).
        assert!(sub_total + 16 <= grid_total, "{sub_total} vs {grid_total}");
    }

    /// A prediction decades off still ends at the minimum (steps downhill), and one with no
    /// bracket within reach gives `None` (the caller then searches the grid).
    #[test]
    fn refinement_walks_downhill_and_gives_up_beyond_reach() {
        let (t, y) = record(5_000, 11, 0);
        let setup = Setup::new(&t, &y);
        let mut ws = Workspace::default();
        let grid =
            gcv_lambda_from(&setup, &mut ws, &t, &y, "y", usize::MAX, LOG_LAMBDA_TOL).unwrap();
        let span = t[t.len() - 1] - t[0];
        let range = gcv_range(span / (t.len() - 1) as f64, span);
        for off in [-2.2, -0.7, 0.3, 1.9] {
            let p = libm::log10(grid) + off;
            let lam = refine_near(&setup, &mut ws, p, range, LOG_LAMBDA_TOL).unwrap();
            let apart = libm::log10(lam / grid).abs();
            assert!(
                apart <= 4.0 * LOG_LAMBDA_TOL,
                "offset {off}: {apart} decades"
            );
        }
        assert_eq!(
            refine_near(
                &setup,
                &mut ws,
                libm::log10(grid) + 6.0,
                range,
                LOG_LAMBDA_TOL
            ),
            None
        );
    }
}
