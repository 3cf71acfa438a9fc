//! The reference problems (now `pdyn_ode::problems`) and what the tests compare with.
#![allow(dead_code)]

pub use pdyn_ode::problems::*;

/// Max-norm distance.
pub fn max_err(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}
