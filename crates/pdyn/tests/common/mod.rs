//! Helpers shared by the particle-net test files.

/// The largest `|a_i − b_i|`, relative to the largest `|a_i|`.
pub fn max_relative_difference(a: &[f64], b: &[f64]) -> f64 {
    let scale = a.iter().fold(0.0f64, |s, x| s.max(x.abs())).max(1e-300);
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs() / scale)
        .fold(0.0, f64::max)
}
