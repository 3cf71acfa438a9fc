//! The `pdyn` library behind the command line and Python: [`run`] runs a model file of any
//! kind (mechanics, N-body, MD) from a kind-neutral [`Request`] and returns a typed
//! [`RunOutput`]; below it, running models (integration, monitors, events), sweeps, output
//! files and plots, the computations of `pdyn kin` and `pdyn dsolve` ([`kin`],
//! [`dsolve`], shared with the Python package), and the typed [`Error`] every command
//! returns. The binary (`crates/pdyn-cli`) parses arguments, calls this and the lower crates,
//! and prints.
#![warn(missing_docs)]

pub mod args;
pub mod checkpoint;
pub mod clock;
pub mod data;
pub mod dsolve;
pub mod engine;
pub mod error;
pub mod fit;
pub mod ivp;
pub mod kin;
pub mod md;
pub mod model_file;
pub mod nbody;
pub mod number_rows;
pub mod optimize;
pub mod output;
pub mod params;
#[cfg(feature = "plots")]
pub mod plots;
pub mod report;
pub mod request;
pub mod sim;
pub mod stream;
pub mod summary;

pub use engine::{run, Progress, RunOutput};
pub use error::{Error, Location};
/// How options are named in messages (they live in pdyn-mech, whose messages name some).
pub use pdyn_mech::options;
pub use request::Request;
