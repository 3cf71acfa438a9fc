//! One integrator family per file; each file opens with its mathematics and its paper.

pub mod dopri5;
