//! Tick placement and tick-label formatting, and the plotters coordinate
//! type that draws exactly the ticks chosen here.

use std::ops::Range;

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};

/// The nice step multipliers, per decade.
const NICE: [f64; 5] = [1.0, 2.0, 2.5, 5.0, 10.0];

/// Ticks of one axis: positions and their labels.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Ticks {
    pub values: Vec<f64>,
    pub labels: Vec<String>,
}

/// Evenly spaced "nice" tick positions (multiples of 1, 2, 2.5 or 5 times a
/// power of ten) inside `lo..=hi`, at most `max_n` of them (at least 2 are
/// asked for), and the step between them.
pub(crate) fn nice_ticks(lo: f64, hi: f64, max_n: usize) -> (Vec<f64>, f64) {
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (hi, lo) };
    let span = hi - lo;
    if span.is_nan() || span <= 0.0 || span.is_infinite() {
        return (vec![lo], 1.0);
    }
    let max_n = max_n.max(2);
    let raw = span / (max_n as f64 - 1.0);
    let mag = libm::pow(10f64, libm::log10(raw).floor());
    let mut step = mag * 10.0;
    'search: for decade in [mag, mag * 10.0] {
        for m in NICE {
            let s = m * decade;
            if count_in(lo, hi, s) <= max_n {
                step = s;
                break 'search;
            }
        }
    }
    let k0 = (lo / step - 1e-9).ceil() as i64;
    let k1 = (hi / step + 1e-9).floor() as i64;
    let values = (k0..=k1)
        .map(|k| {
            let v = k as f64 * step;
            if v.abs() < step * 1e-9 {
                0.0
            } else {
                v
            }
        })
        .collect();
    (values, step)
}

fn count_in(lo: f64, hi: f64, step: f64) -> usize {
    let k0 = (lo / step - 1e-9).ceil();
    let k1 = (hi / step + 1e-9).floor();
    (k1 - k0 + 1.0).max(0.0) as usize
}

/// Smallest number of decimals that writes `step` exactly (up to 15).
fn decimals(step: f64) -> usize {
    for d in 0..=15 {
        let v = step * 10f64.powi(d as i32);
        if (v - v.round()).abs() < 1e-6 * v.abs().max(1e-300) {
            return d;
        }
    }
    15
}

/// Replaces an ASCII hyphen used as minus sign by the typographic minus.
fn minus(s: String) -> String {
    if let Some(rest) = s.strip_prefix('-') {
        format!("\u{2212}{rest}")
    } else {
        s
    }
}

/// Labels for ticks `values` spaced by `step`: plain decimals with just
/// enough digits, or `1.5e−6` style when the numbers are very large or small.
pub(crate) fn format_ticks(values: &[f64], step: f64) -> Vec<String> {
    let max_abs = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let scientific = max_abs >= 1e5 || (max_abs > 0.0 && max_abs < 1e-3);
    if scientific {
        let exp = libm::log10(max_abs).floor() as i32;
        let scale = 10f64.powi(exp);
        let d = decimals(step / scale);
        values
            .iter()
            .map(|&v| {
                if v == 0.0 {
                    "0".to_string()
                } else {
                    let m = minus(format!("{:.*}", d, v / scale));
                    format!("{m}e{}", minus(exp.to_string()))
                }
            })
            .collect()
    } else {
        let d = decimals(step);
        values
            .iter()
            .map(|&v| {
                let s = format!("{:.*}", d, v);
                // "-0.0" can appear from rounding: print as zero.
                if s.trim_start_matches('-')
                    .chars()
                    .all(|c| c == '0' || c == '.')
                {
                    s.trim_start_matches('-').to_string()
                } else {
                    minus(s)
                }
            })
            .collect()
    }
}

/// Ticks for `range` with at most `max_n` positions, labelled.
pub(crate) fn ticks(range: &Range<f64>, max_n: usize) -> Ticks {
    let (values, step) = nice_ticks(range.start, range.end, max_n);
    let labels = format_ticks(&values, step);
    Ticks { values, labels }
}

/// A linear axis for plotters whose key points are exactly our ticks (no
/// minor grid lines).
#[derive(Debug, Clone)]
pub(crate) struct Axis {
    pub lo: f64,
    pub hi: f64,
    pub ticks: Vec<f64>,
}

impl Axis {
    pub fn new(range: &Range<f64>, ticks: &Ticks) -> Self {
        Axis {
            lo: range.start,
            hi: range.end,
            ticks: ticks.values.clone(),
        }
    }
}

/// Maps `v` linearly from `lo..hi` onto the pixels `limit.0..limit.1`.
pub(crate) fn map_linear(v: f64, lo: f64, hi: f64, limit: (i32, i32)) -> f64 {
    let span = hi - lo;
    let t = if span != 0.0 { (v - lo) / span } else { 0.5 };
    limit.0 as f64 + t * (limit.1 - limit.0) as f64
}

impl Ranged for Axis {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let p = map_linear(*value, self.lo, self.hi, limit);
        p.round().clamp(-1e7, 1e7) as i32
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            Vec::new()
        } else {
            self.ticks.clone()
        }
    }

    fn range(&self) -> Range<f64> {
        self.lo..self.hi
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_steps() {
        let (v, s) = nice_ticks(0.0, 10.0, 6);
        assert_eq!(s, 2.0);
        assert_eq!(v, vec![0.0, 2.0, 4.0, 6.0, 8.0, 10.0]);
        let (v, s) = nice_ticks(-1.05, 1.05, 9);
        assert_eq!(s, 0.25);
        assert_eq!(v.len(), 9);
        let (v, _) = nice_ticks(0.3, 0.7, 5);
        assert!(v.len() <= 5 && v.len() >= 2, "{v:?}");
    }

    #[test]
    fn formatting() {
        let (v, s) = nice_ticks(-1.0, 1.0, 5);
        assert_eq!(
            format_ticks(&v, s),
            ["\u{2212}1.0", "\u{2212}0.5", "0.0", "0.5", "1.0"]
        );
        let (v, s) = nice_ticks(0.0, 4e-6, 5);
        assert_eq!(
            format_ticks(&v, s),
            [
                "0",
                "1e\u{2212}6",
                "2e\u{2212}6",
                "3e\u{2212}6",
                "4e\u{2212}6"
            ]
        );
        let (v, s) = nice_ticks(0.0, 3e6, 4);
        assert_eq!(format_ticks(&v, s), ["0", "1e6", "2e6", "3e6"]);
        let (v, s) = nice_ticks(0.0, 100.0, 6);
        assert_eq!(format_ticks(&v, s), ["0", "20", "40", "60", "80", "100"]);
    }

    #[test]
    fn degenerate_ranges_do_not_loop() {
        assert_eq!(nice_ticks(1.0, 1.0, 5).0, vec![1.0]);
        assert_eq!(nice_ticks(f64::NAN, 1.0, 5).0.len(), 1);
        let (v, _) = nice_ticks(1e9, 1e9 + 1.0, 5);
        assert!(!v.is_empty() && v.len() <= 5);
    }
}
