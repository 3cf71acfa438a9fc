//! The `pdyn` library behind the command: running models (integration, monitors, events),
//! sweeps, and output files. The binary (`main.rs`) parses arguments and prints.
#![warn(missing_docs)]

pub mod output;
pub mod sim;
