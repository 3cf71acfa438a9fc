//! The `pdyn` library behind the command: running models (integration, monitors, events),
//! sweeps, output files and plots, the computations of `pdyn kin` and `pdyn dsolve` ([`kin`],
//! [`dsolve`], shared with the Python package), and the typed [`Error`] every command
//! returns. The binary (`main.rs`, `cli/`) parses arguments, calls this and the lower crates,
//! and prints.
#![warn(missing_docs)]

pub mod args;
pub mod dsolve;
pub mod error;
pub mod ivp;
pub mod kin;
pub mod md;
pub mod model_file;
pub mod nbody;
pub mod output;
pub mod params;
pub mod plots;
pub mod sim;
pub mod summary;

pub use error::{Error, Location};
