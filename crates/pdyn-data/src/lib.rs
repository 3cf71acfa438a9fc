//! `pdyn-data`: measured motion (the chapter's section 3.1.7).
//!
//! - [`csv`]: a time series read from CSV text, every problem located (file, line, column, the
//!   offending text, and what would be valid): [`csv::Table`], [`csv::Series`].
//! - [`parquet`]: the same columns from a Parquet file (pandas, polars, Arrow), and
//!   [`source`]: a data file told CSV or Parquet by its bytes, read by either.
//! - [`interp`]: interpolation of samples: linear, natural cubic spline, PCHIP.
//! - [`spline`]: the cubic smoothing spline (Reinsch's algorithm, banded O(n)), its smoothing
//!   parameter chosen by generalized cross-validation.
//! - [`kinematics`]: velocity, acceleration, speed, tangent, normal, curvature, a_t, a_n and
//!   polar components from sampled positions, with standard errors.
//! - [`integrate`]: sampled acceleration integrated to velocity and position (trapezoid or
//!   fourth-order Simpson-type rule), bias removal, and the growth of the position error.
//! - [`fusion`]: Kalman filter and Rauch–Tung–Striebel smoother of an accelerometer (fast,
//!   biased, noisy) with position fixes (slow, noisy), noise levels given or estimated by
//!   maximum likelihood of the innovations.
//!
//! This crate depends on no other pdyn crate: numbers in, numbers out, typed [`DataError`]s.
#![warn(missing_docs)]
// Numerical kernels index several arrays in step (banded factorisations, 3×3 covariances).
#![allow(clippy::needless_range_loop)]
// `!(x > 0.0)` is how these kernels refuse NaN along with non-positive values, on purpose.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// `DataError` carries its whole location and help (≈150 bytes) by value; errors are the cold
// path and are rendered once.
#![allow(clippy::result_large_err)]

pub mod csv;
pub mod error;
pub mod fusion;
pub mod integrate;
pub mod interp;
pub mod kinematics;
mod linalg;
pub mod minimize;
mod parallel;
#[cfg(not(target_arch = "wasm32"))]
pub mod parquet;
#[cfg(target_arch = "wasm32")]
#[path = "parquet_unavailable.rs"]
pub mod parquet;
pub mod source;
pub mod spline;

pub use error::DataError;
