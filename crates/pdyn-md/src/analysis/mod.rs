//! Post-processing: radial distribution function and mean-squared displacement.

mod msd;
mod rdf;

pub use msd::Msd;
pub use rdf::{BlockRdf, Rdf};
