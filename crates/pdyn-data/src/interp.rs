//! Interpolation of samples `(t_i, y_i)`: piecewise linear, natural cubic spline (second
//! derivative zero at both ends, C²), and PCHIP (Fritsch–Carlson monotone cubic, C¹, with
//! SciPy's `PchipInterpolator` end slopes). Outside `[t_0, t_{n-1}]` evaluation is an error:
//! data do not say what happens there.

use crate::error::DataError;
use crate::linalg::solve_tridiagonal;

/// The kind of interpolation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Straight lines between samples.
    Linear,
    /// The natural cubic spline.
    Cubic,
    /// Piecewise cubic Hermite with monotonicity-preserving slopes.
    Pchip,
}

impl Kind {
    /// `linear`, `cubic`, `pchip`.
    pub fn parse(s: &str) -> Option<Kind> {
        match s {
            "linear" => Some(Kind::Linear),
            "cubic" => Some(Kind::Cubic),
            "pchip" => Some(Kind::Pchip),
            _ => None,
        }
    }
}

/// An interpolant of one column of samples.
#[derive(Clone, Debug)]
pub struct Interpolant {
    t: Vec<f64>,
    y: Vec<f64>,
    /// Slopes at the samples (Hermite form); empty for linear.
    d: Vec<f64>,
    name: String,
}

impl Interpolant {
    /// The interpolant of `y` at the strictly increasing times `t` (at least two samples;
    /// [`crate::csv::Series`] guarantees the times). `name` is used in messages.
    pub fn new(kind: Kind, t: &[f64], y: &[f64], name: &str) -> Result<Interpolant, DataError> {
        let n = t.len();
        if n < 2 || y.len() != n {
            return Err(DataError::new(
                name,
                format!(
                    "interpolation needs at least two samples and one value per time ({} times, {} values)",
                    n,
                    y.len()
                ),
            ));
        }
        if let Some(i) = (1..n).find(|&i| !(t[i] > t[i - 1])) {
            return Err(DataError::new(
                name,
                format!("times are not strictly increasing at index {i}"),
            ));
        }
        let h: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
        let delta: Vec<f64> = (0..n - 1).map(|i| (y[i + 1] - y[i]) / h[i]).collect();
        let d = match kind {
            Kind::Linear => Vec::new(),
            Kind::Cubic => natural_slopes(&h, &delta, name)?,
            Kind::Pchip => pchip_slopes(&h, &delta),
        };
        Ok(Interpolant {
            t: t.to_vec(),
            y: y.to_vec(),
            d,
            name: name.to_string(),
        })
    }

    /// The value at `x`, or an error when `x` is outside the samples' time range.
    pub fn eval(&self, x: f64) -> Result<f64, DataError> {
        let n = self.t.len();
        let (t0, t1) = (self.t[0], self.t[n - 1]);
        if !(x >= t0 && x <= t1) {
            return Err(DataError::new(
                &self.name,
                format!("time {x} is outside the data's time range [{t0}, {t1}]"),
            )
            .help("evaluate only between the first and last sample (data say nothing outside)"));
        }
        // The interval [t_i, t_{i+1}] holding x.
        let i = (self.t.partition_point(|&s| s <= x)).clamp(1, n - 1) - 1;
        let h = self.t[i + 1] - self.t[i];
        let s = (x - self.t[i]) / h;
        if self.d.is_empty() {
            return Ok(self.y[i] + s * (self.y[i + 1] - self.y[i]));
        }
        let (h00, h10, h01, h11) = (
            (1.0 + 2.0 * s) * (1.0 - s) * (1.0 - s),
            s * (1.0 - s) * (1.0 - s),
            s * s * (3.0 - 2.0 * s),
            s * s * (s - 1.0),
        );
        Ok(h00 * self.y[i] + h10 * h * self.d[i] + h01 * self.y[i + 1] + h11 * h * self.d[i + 1])
    }
}

impl Interpolant {
    /// The first and last sample times.
    pub fn range(&self) -> (f64, f64) {
        (self.t[0], self.t[self.t.len() - 1])
    }

    /// The highest derivative order that is not identically zero between samples: 1 for
    /// linear interpolation (its derivative is piecewise constant), 3 for the cubics.
    pub fn degree(&self) -> u8 {
        if self.d.is_empty() {
            1
        } else {
            3
        }
    }

    /// The derivative of order `order` (0: the value) at `x`, `None` outside the samples'
    /// time range. The interval is found by binary search (O(log n)); at a sample time the
    /// piece to its right is used (the last piece at the last sample), which matters only for
    /// the derivatives that jump there (linear's first, the cubics' third). Past the degree
    /// the derivative is zero.
    pub fn derivative(&self, order: u8, x: f64) -> Option<f64> {
        let n = self.t.len();
        if !(x >= self.t[0] && x <= self.t[n - 1]) {
            return None;
        }
        let i = (self.t.partition_point(|&s| s <= x)).clamp(1, n - 1) - 1;
        let h = self.t[i + 1] - self.t[i];
        let s = (x - self.t[i]) / h;
        let (y0, y1) = (self.y[i], self.y[i + 1]);
        if self.d.is_empty() {
            return Some(match order {
                0 => y0 + s * (y1 - y0),
                1 => (y1 - y0) / h,
                _ => 0.0,
            });
        }
        let (d0, d1) = (h * self.d[i], h * self.d[i + 1]);
        // The Hermite basis and its derivatives in s; d/dx = (1/h) d/ds.
        let (b00, b10, b01, b11, scale) = match order {
            0 => (
                (1.0 + 2.0 * s) * (1.0 - s) * (1.0 - s),
                s * (1.0 - s) * (1.0 - s),
                s * s * (3.0 - 2.0 * s),
                s * s * (s - 1.0),
                1.0,
            ),
            1 => (
                6.0 * s * s - 6.0 * s,
                3.0 * s * s - 4.0 * s + 1.0,
                -6.0 * s * s + 6.0 * s,
                3.0 * s * s - 2.0 * s,
                h,
            ),
            2 => (
                12.0 * s - 6.0,
                6.0 * s - 4.0,
                -12.0 * s + 6.0,
                6.0 * s - 2.0,
                h * h,
            ),
            3 => (12.0, 6.0, -12.0, 6.0, h * h * h),
            _ => return Some(0.0),
        };
        Some((b00 * y0 + b10 * d0 + b01 * y1 + b11 * d1) / scale)
    }
}

/// The slopes of the natural cubic spline: the second derivatives `M` solve the tridiagonal
/// system of C² continuity with `M_0 = M_{n−1} = 0`; slopes follow from them.
fn natural_slopes(h: &[f64], delta: &[f64], name: &str) -> Result<Vec<f64>, DataError> {
    let n = h.len() + 1;
    let mut m = vec![0.0; n];
    if n > 2 {
        let k = n - 2;
        let diag: Vec<f64> = (1..n - 1).map(|i| 2.0 * (h[i - 1] + h[i])).collect();
        let off: Vec<f64> = (1..k).map(|i| h[i]).collect();
        let mut rhs: Vec<f64> = (1..n - 1)
            .map(|i| 6.0 * (delta[i] - delta[i - 1]))
            .collect();
        solve_tridiagonal(&diag, &off, &mut rhs).ok_or_else(|| {
            DataError::new(
                name,
                "the cubic spline's system is singular (times too close)",
            )
        })?;
        m[1..n - 1].copy_from_slice(&rhs);
    }
    let mut d = vec![0.0; n];
    for i in 0..n - 1 {
        d[i] = delta[i] - h[i] * (2.0 * m[i] + m[i + 1]) / 6.0;
    }
    d[n - 1] = delta[n - 2] + h[n - 2] * (m[n - 2] + 2.0 * m[n - 1]) / 6.0;
    Ok(d)
}

/// PCHIP slopes: the weighted harmonic mean of neighbouring secants where they have the same
/// sign, zero at a local extremum; SciPy's one-sided three-point formula at the ends.
fn pchip_slopes(h: &[f64], delta: &[f64]) -> Vec<f64> {
    let n = h.len() + 1;
    if n == 2 {
        return vec![delta[0], delta[0]];
    }
    let mut d = vec![0.0; n];
    for i in 1..n - 1 {
        let (a, b) = (delta[i - 1], delta[i]);
        if a * b <= 0.0 {
            d[i] = 0.0;
        } else {
            let w1 = 2.0 * h[i] + h[i - 1];
            let w2 = h[i] + 2.0 * h[i - 1];
            d[i] = (w1 + w2) / (w1 / a + w2 / b);
        }
    }
    let edge = |h0: f64, h1: f64, m0: f64, m1: f64| {
        let d = ((2.0 * h0 + h1) * m0 - h0 * m1) / (h0 + h1);
        if d.signum() != m0.signum() || m0 == 0.0 {
            0.0
        } else if m0.signum() != m1.signum() && d.abs() > 3.0 * m0.abs() {
            3.0 * m0
        } else {
            d
        }
    };
    d[0] = edge(h[0], h[1], delta[0], delta[1]);
    d[n - 1] = edge(h[n - 2], h[n - 3], delta[n - 2], delta[n - 3]);
    d
}
