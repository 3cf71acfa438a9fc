//! One integrator family per file; each file opens with its mathematics and its paper.

pub mod bdf;
pub(crate) mod bdf_linear;
pub mod dop853;
pub mod dopri5;
pub mod gauss;
pub(crate) mod iteration_pattern;
pub mod radau5;
pub(crate) mod radau5_linear;
pub mod rk23;
pub mod rk4;
pub mod symplectic;
pub mod tsit5;
pub mod vern9;
