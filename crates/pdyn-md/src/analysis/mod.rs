//! Post-processing: radial distribution function, mean-squared displacement, block averages.

mod blocks;
mod msd;
mod rdf;

pub use blocks::block_means;
pub use msd::Msd;
pub use rdf::{BlockRdf, Rdf};
